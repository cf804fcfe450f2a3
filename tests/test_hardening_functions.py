"""Issue 11 (hardening) for the function layer: the regression tests of its items.

- item 1: a pointer the header marks Nullable that MuJoCo dereferences anyway
  refuses None; every pointer mjcffi takes as None is taken by MuJoCo as NULL;
- item 10 and the object ids: every object id is checked, from the table
  codegen derives (codegen.functions.IDS), and so are the ids an mjvCamera or an
  mjvPerturb holds where MuJoCo follows them unchecked;
- scalar errors name the argument (TypeError for a type, ValueError for a value
  that does not fit), never OverflowError;
- the generated wrappers equal the official bindings by value on valid inputs.

The argument fuzz (every argument of every function, one bad value at a time) is
in test_function_layer.py.  Calls that could crash run in a subprocess.
"""

import json
import math
import pathlib
import subprocess
import sys
import warnings

import numpy as np
import pytest

import mjcffi
from codegen import functions as table
from mjcffi import functions as F
from mjcffi import scenes, structs
from mjcffi._generated.funcinfo import FUNCTIONS

from . import _calls

REPO = pathlib.Path(__file__).resolve().parent.parent


def _run(code, timeout=300):
    """Run `code` in a fresh interpreter at the repository root: (returncode, stdout, stderr)."""
    run = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True,
                         text=True, timeout=timeout)
    return run.returncode, run.stdout, run.stderr


_PRELUDE = """
import numpy as np, mjcffi
from mjcffi import functions as F, scenes, structs
m = mjcffi.MjModel.from_xml_string(scenes.DEFAULT)
d = mjcffi.MjData(m)
F.mj_forward(m, d)
try:
    {call}
except Exception as exc:
    print(type(exc).__name__, "|", exc)
else:
    print("ok")
"""


def _outcome(call):
    """What `call` (a statement over m, d of the default scene) does in a subprocess."""
    code, out, err = _run(_PRELUDE.format(call=call), timeout=120)
    assert code == 0, f"{call}: exit {code}\n{err[-2000:]}"
    return out.strip().splitlines()[-1]


# ------------------------------------------------------------ item 1: Nullable

def test_item1_mjv_cameraFrame_forward_none_raises_type_error():
    result = _outcome("F.mjv_cameraFrame(np.zeros(3), None, np.zeros(3), np.zeros(3), d, "
                      "structs.MjvCamera())")
    assert result.startswith(("TypeError", "ArgumentError")) and "forward" in result
    # the other three are NULL-safe in MuJoCo, and stay Nullable
    result = _outcome("F.mjv_cameraFrame(None, np.zeros(3), None, None, d, structs.MjvCamera())")
    assert result == "ok"


def test_item1_mjv_select_outputs_refuse_none():
    for name in ("geomid", "flexid", "skinid"):
        kwargs = ", ".join(f"{n}={'None' if n == name else 'np.zeros(1, np.int32)'}"
                           for n in ("geomid", "flexid", "skinid"))
        result = _outcome("F.mjv_select(m, d, structs.MjvOption(), 1.0, 0.5, 0.5, "
                          f"structs.MjvScene(m, maxgeom=10), np.zeros(3), {kwargs})")
        assert result.startswith(("TypeError", "ArgumentError")) and name in result, result


def test_item1_not_nullable_table_names_header_nullable_arguments():
    for func, args in table.NOT_NULLABLE.items():
        for name, reason in args.items():
            assert FUNCTIONS[func].args and reason
            assert any(a.name == name and a.nullable for a in FUNCTIONS[func].args), (func, name)
            assert name not in _calls.nullable(func)


# The pointers whose NULL MuJoCo takes only with the others of a group given, or
# whose call needs more than the pool's defaults: (function) -> statement run
# before the call, over `kw` (the call's arguments), `m`, `d` and `F`.
_SETUP = {
    "mj_saveModel": "if kw.get('buffer') is not None: kw['buffer'] = "
                    "bytearray(F.mj_sizeModel(kw['m']))",
    "mj_parseXML": "open('scratch_model.xml', 'w').write(_calls.XML); "
                   "kw['filename'] = 'scratch_model.xml'",
    "mj_parse": "open('scratch_model.xml', 'w').write(_calls.XML); "
                "kw['filename'] = 'scratch_model.xml'",
    "mj_encode": "kw['s'] = F.mj_parseXMLString(_calls.XML); F.mj_compile(kw['s'], None)",
    "mju_boxQP": "kw['lower'] = None if kw['lower'] is None else -np.ones(3); "
                 "kw['H'] = 2 * np.eye(3)",
    "mjv_select": "F.mjv_updateScene(m, d, kw['vopt'], None, structs.MjvCamera(), 7, kw['scn'])",
}

# Functions whose NULL check needs the default scene (the test model has delays).
_DEFAULT_SCENE = ("mjd_transitionFD",)


def _nullable_sweep(start):
    """Call every generated function with None in each argument mjcffi takes as None,
    alone and all at once, the others correct; print one JSON line per call."""
    import os
    import tempfile
    os.chdir(tempfile.mkdtemp(prefix="mjcffi-null-"))
    pool, default = _calls.Pool(), _calls.Pool(scenes.DEFAULT)
    cases = []
    for func in FUNCTIONS:
        if not _calls.generated(func) or table.draws(func):
            continue                # drawing needs OpenGL: test_mjr.py passes None under it
        names = [py for py, arg in _calls.params(func)
                 if arg is not None and arg.name in _calls.nullable(func)]
        cases += [(func, [py]) for py in names]
        if len(names) > 1:
            cases.append((func, names))
    for i, (func, nulls) in enumerate(cases):
        if i < start:
            continue
        chosen = default if func in _DEFAULT_SCENE else pool
        kw = _calls.full_call(func, chosen)
        if kw is None:
            print(json.dumps([i, func, nulls, "no call"]), flush=True)
            continue
        kw.update(dict.fromkeys(nulls))
        exec(_SETUP.get(func, ""), {"kw": kw, "m": chosen.env["m"], "d": chosen.env["d"],
                                    "F": F, "np": np, "structs": structs, "_calls": _calls})
        print(json.dumps([i, func, nulls, "start"]), flush=True)
        try:
            getattr(F, func)(**kw)
            result = "ok"
        except Exception as exc:         # noqa: BLE001  (reported)
            result = f"{type(exc).__name__}: {exc}"
        print(json.dumps([i, func, nulls, result]), flush=True)
    print(json.dumps(["done", len(cases)]), flush=True)


def test_item1_every_none_mjcffi_takes_is_null_that_mujoco_takes():
    """No crash: each Nullable pointer, alone and with the others of its function."""
    start, results, crashes = 0, [], []
    while True:
        code, out, err = _run(f"from tests.test_hardening_functions import _nullable_sweep; "
                              f"_nullable_sweep({start})", timeout=600)
        lines = [json.loads(line) for line in out.splitlines() if line.startswith("[")]
        results += [line for line in lines if line[-1] != "start"]
        if code == 0:
            break
        last = [line for line in lines if line[-1] == "start"][-1]
        crashes.append(f"{last[1]} with {last[2]} None: exit {code}")
        start = last[0] + 1
    assert not crashes, crashes
    done = [line for line in results if line[0] == "done"]
    assert done and done[0][1] > 100
    # the calls that fail do so before MuJoCo reads the pointer, with a Python error
    failed = {(r[1], tuple(r[2])): r[3] for r in results
              if r[0] != "done" and r[3] not in ("ok", "no call")}
    allowed = {"mjd_transitionFD", "mj_encode", "mj_parseXML", "mj_parse"}
    assert {func for func, _ in failed} <= allowed, failed
    assert len([r for r in results if r[0] != "done" and r[3] == "ok"]) > 100


# -------------------------------------------------------------- item 10: ids

_MUJOCO_CRASHES = [
    "F.mjc_getSDF(m, -2**31)",
    "F.mjc_getSDF(m, 10**6)",
    "F.mjc_getSDF(m, 0)",                    # a geom without an SDF plugin
    "F.mj_local2Global(d, np.zeros(3), np.zeros(9), np.zeros(3), np.array([1., 0, 0, 0]), "
    "2**31 - 1, 0)",
    "F.mj_rayFlex(m, d, 0, 1, 1, 1, 0, 2**31 - 1, np.zeros(3), np.ones(3), None, None)",
    "cam = structs.MjvCamera(); cam.type = 2; cam.fixedcamid = 10**6\n    "
    "F.mjv_cameraFrame(np.zeros(3), np.zeros(3), None, None, d, cam)",
    "cam = structs.MjvCamera(); cam.type = 1; cam.trackbodyid = 10**7\n    "
    "F.mjv_camera2GLCamera(m, d, cam)",
    "pert = structs.MjvPerturb(); pert.select = 10**6; pert.active = 3\n    "
    "F.mjv_updateScene(m, d, structs.MjvOption(), pert, structs.MjvCamera(), 7, "
    "structs.MjvScene(m, maxgeom=100))",
    "pert = structs.MjvPerturb(); pert.flexselect = 10**6\n    "
    "F.mjv_initPerturb(m, d, structs.MjvScene(m, maxgeom=100), pert)",
]


@pytest.mark.parametrize("call", _MUJOCO_CRASHES)
def test_item10_ids_mujoco_follows_unchecked_raise(call):
    result = _outcome(call)
    assert result.split(" |")[0] in ("IdError", "ValueError"), result


def test_item10_mjc_getSDF_id_is_checked():
    m = mjcffi.MjModel.from_xml_string(scenes.DEFAULT)
    for bad in (-2 ** 31, -1, m.ngeom, 10 ** 6):
        with pytest.raises(mjcffi.IdError, match=r"\bid="):
            F.mjc_getSDF(m, bad)
    with pytest.raises(ValueError, match="no SDF plugin"):
        F.mjc_getSDF(m, 0)


def test_item10_ids_are_derived_from_the_declarations():
    ids = dict(table.IDS)
    expected = {
        "mj_local2Global": {"body": (0, "m.nbody")},
        "mj_rayFlex": {"flexid": (0, "m.nflex")},
        "mjc_getSDF": {"id": (0, "m.ngeom")},
        "mj_jac": {"body": (0, "m.nbody")},
        "mj_ray": {"bodyexclude": (-1, "m.nbody")},
        "mj_maxContact": {"g1": (0, "m.ngeom"), "g2": (0, "m.ngeom")},
        "mj_readCtrl": {"id": (0, "m.nu")},
        "mj_readSensor": {"id": (0, "m.nsensor")},
        "mj_insideSite": {"siteid": (0, "m.nsite")},
    }
    for func, entry in expected.items():
        assert ids[func] == entry, func
    # ids MuJoCo checks itself: its header states the range, or an exception says why
    assert "mj_resetDataKeyframe" not in ids
    for func, arg in table.ID_EXCEPTIONS:
        assert arg not in ids.get(func, {}) and table.ID_EXCEPTIONS[(func, arg)]
    # every int argument named as an object id, in a function of a model, is covered
    for func, info in FUNCTIONS.items():
        if not _calls.generated(func) or not any(a.elem in ("mjModel", "mjData")
                                                  for a in info.args):
            continue
        for a in info.args:
            if a.ctype == "int" and table._id_object(func, a.name, info.doc) not in (None,):
                covered = a.name in ids.get(func, {}) or (func, a.name) in table.ID_EXCEPTIONS
                stated = f"<= {a.name} <" in info.doc
                assert covered or stated, (func, a.name)


def test_item10_every_derived_id_is_checked_at_its_bounds():
    """In a subprocess: an id at count (or below the lowest) raises IdError, for every
    entry of the derived table, with the other arguments correct."""
    code, out, err = _run("from tests.test_hardening_functions import _id_sweep; _id_sweep()")
    assert code == 0, err[-3000:]
    report = json.loads(out.strip().splitlines()[-1])
    assert not report["wrong"], report["wrong"]
    # nthread, and mjr_uploadTexture's texid (the test model has no texture: test_mjr.py)
    assert report["checked"] >= sum(len(v) for v in table.IDS.values()) - 2


def _id_sweep():
    pool = _calls.Pool()
    wrong, checked = [], 0
    env = {"m": pool.env["m"], "d": pool.env["d"]}
    for func, ids in sorted(table.IDS.items()):
        good = _calls.full_call(func, pool)
        if func == "mjc_getSDF":            # no SDF plugin here: the id check comes first
            good = {"m": pool.env["m"], "id": 0}
        if good is None or func == "mju_threadpool":
            continue
        for arg, (low, count) in ids.items():
            limit = int(eval(count, {}, env))
            py = arg + "_" if arg in ("def", "type") else arg
            checked += 1
            for value in (low - 1, limit, 2 ** 31 - 1, -2 ** 31):
                try:
                    getattr(F, func)(**{**good, py: value})
                except mjcffi.IdError as exc:
                    if py not in str(exc):
                        wrong.append(f"{func}({py}={value}): {exc}")
                except Exception as exc:       # noqa: BLE001  (reported)
                    wrong.append(f"{func}({py}={value}): {type(exc).__name__}: {exc}")
                else:
                    wrong.append(f"{func}({py}={value}) was accepted")
    print(json.dumps({"wrong": wrong, "checked": checked}))


def test_item10_object_id_pairs_use_the_count_of_their_type():
    m = mjcffi.MjModel.from_xml_string(_calls.XML)
    d = mjcffi.MjData(m)
    obj = mjcffi.mjtObj
    for objtype, count in ((obj.mjOBJ_BODY, m.nbody), (obj.mjOBJ_XBODY, m.nbody),
                           (obj.mjOBJ_GEOM, m.ngeom), (obj.mjOBJ_SITE, m.nsite),
                           (obj.mjOBJ_CAMERA, m.ncam)):
        for func in (F.mj_objectVelocity, F.mj_objectAcceleration):
            func(m, d, objtype, count - 1, np.zeros(6), 0)
            with pytest.raises(mjcffi.IdError, match="objid"):
                func(m, d, objtype, count, np.zeros(6), 0)
            with pytest.raises(mjcffi.IdError, match="objid"):
                func(m, d, objtype, -1, np.zeros(6), 0)


def test_item10_id_check_takes_numpy_ints_and_refuses_floats():
    m = mjcffi.MjModel.from_xml_string(scenes.DEFAULT)
    d = mjcffi.MjData(m)
    F.mj_forward(m, d)
    jacp, jacp2 = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    F.mj_jac(m, d, jacp, None, d.xpos[2], np.int64(2))
    F.mj_jac(m, d, jacp2, None, d.xpos[2], 2)
    assert np.array_equal(jacp, jacp2)
    with pytest.raises(TypeError, match="body"):
        F.mj_jac(m, d, jacp, None, d.xpos[2], 2.0)
    with pytest.raises(TypeError, match="body"):
        F.mj_jac(m, d, jacp, None, d.xpos[2], None)


# ------------------------------------------------------ scalar errors name it

def test_item_scalar_errors_name_the_argument():
    m = mjcffi.MjModel.from_xml_string(scenes.DEFAULT)
    d = mjcffi.MjData(m)
    cases = [
        (lambda: F.mj_name2id(m, None, "x"), TypeError, "type"),
        (lambda: F.mju_scl3(np.zeros(3), np.zeros(3), None), TypeError, "scl"),
        (lambda: F.mju_Halton(None, 2), TypeError, "index"),
        (lambda: F.mj_stateSize(m, None), TypeError, "sig"),
        (lambda: F.mju_sigmoid(None), TypeError, "x"),
        (lambda: F.mju_sigmoid("1"), TypeError, "x"),
        (lambda: F.mju_sigmoid(10 ** 400), ValueError, "x"),
        (lambda: F.mj_id2name(m, 1, 2 ** 40), ValueError, "id"),
        (lambda: F.mj_id2name(m, 1, 2.5), TypeError, "id"),
        (lambda: F.mj_ray(m, d, np.zeros(3), np.ones(3), None, 2, -1, None, None),
         ValueError, "flg_static"),
        (lambda: F.mj_forwardSkip(m, d, 0, None), TypeError, "skipsensor"),
        (lambda: F.mju_bandDiag(0, 4, None, 1), TypeError, "nband"),
        (lambda: F.mju_cholFactorBand(np.zeros(10), 4, "2", 1, 0.0, 0.0), TypeError, "nband"),
        (lambda: F.mju_raySkin(2 ** 40, 3, [0, 1, 2], np.zeros(9, np.float32), [0, 0, 0],
                               [0, 0, 1], None), ValueError, "nface"),
        (lambda: F.mj_setState(m, d, np.zeros(F.mj_stateSize(m, 1)), 2 ** 40),
         ValueError, "sig"),
    ]
    for i, (call, error, name) in enumerate(cases):
        with pytest.raises(error) as caught:
            call()
        assert not isinstance(caught.value, OverflowError), i
        text = " ".join([str(caught.value), *getattr(caught.value, "__notes__", ())])
        assert name in text, (i, text)


def test_item_an_int_array_input_too_large_for_its_dtype_is_argument_error():
    face = [0, 1, 2 ** 40]
    with pytest.raises(mjcffi.ArgumentError, match="face") as caught:
        F.mju_raySkin(1, 3, face, np.zeros(9, np.float32), [0, 0, 0], [0, 0, 1], None)
    assert not isinstance(caught.value, OverflowError)


# ------------------------------------------- equal to the official by value

# Functions of tests/_calls.py's valid calls that are not compared, and why.
NOT_COMPARED = {
    "mju_bandMulMatVec": "the official bindings refuse its valid call (res checked against "
                         "the wrong extent)",
    "mjd_transitionFD": "the test model has delays, which it refuses in both bindings",
}


def _cases():
    env = _calls.model_env(mjcffi)
    return [f for f in FUNCTIONS if _calls.valid_call(f, env) is not None
            and f not in NOT_COMPARED]


_COMPARED = _cases()


def _equal(a, b):
    """Bit for bit, NaN equal to NaN (MuJoCo may return NaN on these inputs)."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if a.shape != b.shape or a.dtype != b.dtype:
            return False
        if a.dtype.kind == "f":
            return np.array_equal(a.view(f"u{a.itemsize}"), b.view(f"u{b.itemsize}")) or \
                np.array_equal(a, b, equal_nan=True)
        return np.array_equal(a, b)
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    return a == b


def _data_arrays(data):
    """The array fields of an MjData (the official names), timers left out."""
    out = {}
    for name in dir(data):
        if name.startswith("_") or "timer" in name:
            continue
        try:
            value = getattr(data, name)
        except Exception:               # noqa: BLE001  (a field that is not readable here)
            continue
        if isinstance(value, np.ndarray):
            out[name] = value.copy()
    return out


def _struct_fields(obj):
    """The number and array fields of a struct wrapper (nested structs left out); an
    mjvScene's numbers only, its buffers being uninitialized past what MuJoCo wrote."""
    out = {}
    for name in dir(type(obj)):
        if name.startswith("_"):
            continue
        try:
            value = getattr(obj, name)
        except Exception:               # noqa: BLE001  (not readable here)
            continue
        if isinstance(value, np.ndarray):
            if type(obj).__name__ != "MjvScene":
                out[name] = value.copy()
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            out[name] = value
    return out


def _noise():
    """MjData fields that hold leftovers (efc_J_colind in dense mode, ...): they differ
    between two fresh datas forwarded alike, so they are not compared."""
    import mujoco
    first, second = (_data_arrays(_calls.model_env(module)["d"])
                     for module in (mjcffi, mujoco))
    third = _data_arrays(_calls.model_env(mjcffi)["d"])
    noisy = {name for name in first if name not in second
             or not _equal(first[name], second[name]) or not _equal(first[name], third[name])}
    # the sparse structure of the constraint Jacobian, unused (not written) when it is dense
    return noisy | {f"efc_{m}_{f}" for m in ("J", "JT")
                    for f in ("rownnz", "rowadr", "rowsuper", "colind")}


_NOISE = _noise()


def _randomize(call, func, seed):
    """The call with each float input array replaced by seeded normal values."""
    rng = np.random.default_rng(seed)
    out = dict(call)
    for py, arg in _calls.params(func):
        value = call.get(py)
        if (isinstance(value, np.ndarray) and arg is not None and arg.const
                and value.dtype.kind == "f" and arg.name != "times"):
            out[py] = rng.normal(size=value.shape).astype(value.dtype)
    return out


def _run_side(module, func, variant):
    env = _calls.model_env(module)
    call = _calls.valid_call(func, env)
    if variant:
        call = _randomize(call, func, variant)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            result = getattr(module, func)(**call)
        except Exception as exc:         # noqa: BLE001  (compared)
            return ("raised", type(exc).__name__, str(exc)), call, env
    return ("returned", result), call, env


def test_item_by_value_covers_the_valid_calls():
    assert len(_COMPARED) >= 139
    assert len(_NOISE) < 12, sorted(_NOISE)


@pytest.mark.parametrize("func", _COMPARED)
def test_item_generated_wrappers_equal_the_official_by_value(func, mujoco):
    """Equal inputs, fresh on each side: every array argument (outputs), the result and
    the MjData after the call are equal bit for bit; on seeded random inputs too."""
    for variant in (0, 1, 2):
        ours, our_call, our_env = _run_side(mjcffi, func, variant)
        theirs, their_call, their_env = _run_side(mujoco, func, variant)
        if theirs[0] == "raised" or ours[0] == "raised":
            assert ours[0] == theirs[0] and ours[2] == theirs[2], (variant, ours, theirs)
            continue
        assert _equal(ours[1], theirs[1]), (variant, "result", ours[1], theirs[1])
        for py, value in our_call.items():
            if isinstance(value, np.ndarray):
                assert _equal(value, their_call[py]), (variant, py, value, their_call[py])
            elif getattr(value, "_cname", "mjData") not in ("mjModel", "mjData"):  # a struct
                theirs_fields = _struct_fields(their_call[py])
                for name, field in _struct_fields(value).items():
                    if name in theirs_fields:
                        assert _equal(field, theirs_fields[name]), (variant, f"{py}.{name}")
        ours_d, theirs_d = _data_arrays(our_env["d"]), _data_arrays(their_env["d"])
        for name, value in theirs_d.items():
            if name in ours_d and name not in _NOISE:
                assert _equal(ours_d[name], value), (variant, f"d.{name}")


# ------------------------------------- struct arguments: a class, a raw pointer

def test_item_a_struct_class_for_an_instance_is_a_type_error_naming_it():
    m = mjcffi.MjModel.from_xml_string(scenes.DEFAULT)
    d = mjcffi.MjData(m)
    for call, name in ((lambda: F.mj_fwdAcceleration(mjcffi.MjModel, d), "m"),
                       (lambda: F.mj_comPos(m, mjcffi.MjData), "d"),
                       (lambda: F.mjv_cameraFrustum(None, None, None, m, structs.MjvCamera),
                        "cam")):
        with pytest.raises(TypeError, match=rf"^{name} must be .* not the class"):
            call()


def test_item_a_raw_model_pointer_is_checked_against_the_data():
    m = mjcffi.MjModel.from_xml_string(scenes.DEFAULT)
    other = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    d = mjcffi.MjData(m)
    F.mj_checkVel(m._ptr, d)                       # the same sizes: taken
    with pytest.raises(ValueError, match="dest was made for a model of other sizes"):
        F.mj_copyData(mjcffi.MjData(m), other._ptr, d)


# ------------------------------------------- spec handles (mjString *, ...)
#
# mjspec.h declares mjString, mjDoubleVec, ... as `typedef void`: cffi sees them all
# as `void *`, and MuJoCo took any pointer for any of them (another kind, an mjData
# stack pointer, ffi.new memory: SIGSEGV/SIGABRT).  They are typed handles now.

def _handle_functions():
    """(function, C argument, kind) of every argument of a handle type."""
    from mjcffi._support import handles as _handles
    return [(name, a.name, a.elem) for name, func in FUNCTIONS.items() for a in func.args
            if a.elem in _handles.KINDS and a.pointer == 1]


def test_item_handle_kinds_are_the_typedef_void_types_of_the_headers():
    from codegen import headers, parse
    from mjcffi._support import handles as _handles
    decls = parse.parse(headers.mujoco_declarations())
    voids = {name for name, target in decls.typedefs.items() if target.strip() == "void"}
    assert set(_handles.KINDS) == voids and len(voids) == 8
    assert {kind for _, _, kind in _handle_functions()} == voids     # each one is taken
    assert len(_handle_functions()) == 13


def test_item_spec_fields_of_handle_types_give_handles_that_keep_the_spec_alive():
    code, out, err = _run("""
import gc
from mjcffi import functions as F
from mjcffi._generated.structinfo import STRUCTS
from mjcffi._support import handles as _handles
from tests.fuzz.env import _SPEC_MAKERS
s = F.mj_makeSpec()
world = F.mjs_findBody(s, "world")
body = F.mjs_addBody(world, None)
fields = refs = 0
kept = []
for cname, make in {"mjSpec": lambda *args: s, **_SPEC_MAKERS}.items():
    obj = make(F, s, world, body)
    for field in STRUCTS[cname]:
        if field.kind != "pointer" or field.extents:
            continue
        if field.elem in _handles.KINDS:     # the attribute is a str, array or list
            value = _handles.handle(obj, field.name)
            assert type(value) is _handles.KINDS[field.elem], (cname, field.name, value)
            assert value == _handles.handle(obj, field.name) and value._root is obj._root
            fields += 1
            kept.append(value)
        elif field.elem.startswith("mjs"):
            value = getattr(obj, field.name)
            assert value._cname == field.elem and value._root is obj._root, (cname, field.name)
            refs += 1
            kept.append(value)
print(fields, refs)
name = F.mjs_getName(body.element)
element = body.element
del s, world, body, obj, value
gc.collect()
F.mjs_setName(element, "kept")                     # the spec lives on in its handles
print(F.mjs_getString(name), F.mjs_getString(F.mjs_getName(element)))
for value in kept:
    repr(value)
print("done")
""")
    assert code == 0, err[-3000:]
    lines = out.split()
    assert int(lines[0]) > 100 and int(lines[1]) >= 40, out     # every mjString ... field
    assert lines[2:] == ["kept", "kept", "done"], out


def _handle_call_outcomes():
    """Every handle argument called with what it must refuse, in a subprocess."""
    code, out, err = _run("""
import json
import numpy as np
import mjcffi
from mjcffi import ffi, functions as F
from mjcffi._support import handles as _handles
s = F.mj_makeSpec()
body = F.mjs_addBody(F.mjs_findBody(s, "world"), None)
texture = F.mjs_addTexture(s, None)
flex = F.mjs_addFlex(s)
mesh = F.mjs_addMesh(s, None)
h = _handles.handle       # the attributes read as str and arrays: the raw handles
handles = {"mjString": h(body, "childclass"), "mjStringVec": h(texture, "cubefiles"),
           "mjDoubleVec": h(body, "userdata"), "mjIntVec": h(flex, "elem"),
           "mjFloatVec": h(mesh, "uservert"), "mjIntVecVec": None, "mjFloatVecVec": None,
           "mjByteVec": h(texture, "data")}
m = mjcffi.MjModel.from_xml_string("<mujoco/>")
d = mjcffi.MjData(m)
others = {"another kind": lambda kind: next(h for k, h in handles.items() if k != kind and h),
          "the right memory, raw": lambda kind: handles[kind] and ffi.cast("void *",
                                                                          handles[kind]._ptr),
          "a stack array": lambda kind: mjcffi.mj_stackAllocNum(d, 3),
          "ffi.new memory": lambda kind: ffi.new("char[]", 64),
          "NULL": lambda kind: ffi.NULL, "None": lambda kind: None, "int": lambda kind: 0}
args = {"text": "abc", "array": None, "i": 0}
results = []
for func, argname, kind in json.loads(%r):
    for label, make in others.items():
        value = make(kind)
        if value is None and label != "None":
            continue
        call = {"mjs_setBuffer": (value, b"ab"), "mjs_setInt": (value, np.zeros(2, np.int32)),
                "mjs_appendIntVec": (value, np.zeros(2, np.int32)),
                "mjs_setFloat": (value, np.zeros(2, np.float32)),
                "mjs_appendFloatVec": (value, np.zeros(2, np.float32)),
                "mjs_setDouble": (value, np.zeros(2)), "mjs_setInStringVec": (value, 0, "a"),
                "mjs_getString": (value,), "mjs_getDouble": (value,),
                "mju_getXMLDependencies": None}.get(func, (value, "abc"))
        if call is None:
            continue
        try:
            getattr(F, func)(*call)
        except Exception as exc:
            results.append([func, argname, kind, label, type(exc).__name__, str(exc)])
        else:
            results.append([func, argname, kind, label, "ok", ""])
print(json.dumps(results))
""" % json.dumps(_handle_functions()))
    assert code == 0, err[-3000:]
    return json.loads(out.strip().splitlines()[-1])


def test_item_every_handle_argument_takes_only_a_handle_of_its_kind():
    outcomes = _handle_call_outcomes()
    assert len({o[0] for o in outcomes}) == 12          # all but mju_getXMLDependencies
    assert len(outcomes) >= 80
    for func, argname, kind, label, exc, message in outcomes:
        assert exc == "TypeError", (func, label, exc, message)
        assert message.startswith(f"{argname} must be an {kind} handle"), (func, message)
        if label == "another kind":
            assert message.endswith(" handle") and f"not an {kind} " not in message
        if label in ("the right memory, raw", "ffi.new memory", "NULL"):
            assert "raw cffi pointer" in message, message
        if label == "a stack array":                      # the stack allocators give arrays
            assert message.endswith("not ndarray"), message


def test_item_handles_work_where_mujoco_takes_them():
    from mjcffi._support import handles as _handles
    s = F.mj_makeSpec()
    body = F.mjs_addBody(F.mjs_findBody(s, "world"), None)
    childclass = _handles.handle(body, "childclass")
    F.mjs_setString(childclass, "main")
    assert F.mjs_getString(childclass) == "main" == body.childclass
    F.mjs_setDouble(_handles.handle(body, "userdata"), np.arange(3.0))
    assert F.mjs_getDouble(_handles.handle(body, "userdata")).tolist() == [0, 1, 2]
    F.mjs_setName(body.element, "b")
    name = F.mjs_getName(body.element)
    assert type(name).__name__ == "MjStringHandle" and F.mjs_getString(name) == "b"
    assert name == F.mjs_getName(body.element) and hash(name) == hash(F.mjs_getName(body.element))
    assert name != childclass and "MjStringHandle (mjString *) at 0x" in repr(name)
    with pytest.raises(TypeError, match="has no constructor"):
        type(name)()
    import pickle
    with pytest.raises(TypeError, match="cannot be copied or pickled"):
        pickle.dumps(name)


# ------------------------------------------------- enum-typed arguments

# The arguments MuJoCo 4.0's headers declare as an mjt* enum, and those derive_enums
# checks: the others MuJoCo handles for any value (ENUM_EXCEPTIONS;
# tests/test_enum_strictness.py tests what they take).
_ENUM_DECLARED = {"mjs_findElement": {"type": "mjtObj"}, "mjs_firstChild": {"type": "mjtObj"},
                  "mjs_firstElement": {"type": "mjtObj"},
                  "mjs_makeMesh": {"builtin": "mjtMeshBuiltin"}}
_ENUM_ARGUMENTS = {"mjs_findElement": {"type": "mjtObj"}}
_ENUM_GOOD = {"mjs_findElement": 100}           # mjOBJ_FRAME (101 and 102: CHECKS)


def test_item_enum_arguments_are_derived_from_the_declarations():
    from codegen import headers, parse
    decls = parse.parse(headers.mujoco_declarations())
    found = table.derive_enums(decls, set(table.OVERRIDES) | set(table.UNSUPPORTED))
    assert found == _ENUM_ARGUMENTS
    assert set(table.ENUM_EXCEPTIONS) == {(func, arg) for func, args in _ENUM_DECLARED.items()
                                          for arg in args} - {("mjs_findElement", "type")}


def _enum_calls():
    s = F.mj_makeSpec()
    return s, {"mjs_findElement": lambda v: F.mjs_findElement(s, v, "b")}


@pytest.mark.parametrize("func", sorted(_ENUM_ARGUMENTS))
def test_item_enum_arguments_outside_their_enum_raise_value_error(func):
    (argname, enum), = _ENUM_ARGUMENTS[func].items()
    values = {v.value for v in getattr(mjcffi, enum)}
    _keep, calls = _enum_calls()
    with _calls.stubbed():                 # a value that got through would not reach MuJoCo
        gaps = [v for v in range(max(values)) if v not in values][:3]
        for bad in (10**9, 2**31 - 1, 2**31, 2**64, -1, max(values) + 1, *gaps):
            with pytest.raises(ValueError, match=rf"^{argname}={bad} is not a value of {enum}"):
                calls[func](bad)
        for bad in ("1", 1.0, None):
            with pytest.raises(TypeError, match=rf"^{argname} must be an int \(a value of {enum}"):
                calls[func](bad)
        fine = _ENUM_GOOD[func]
        for good in (fine, getattr(mjcffi, enum)(fine), np.int64(1)):
            with pytest.raises(_calls._Reached):
                calls[func](good)


def test_item_mjs_findElement_with_a_huge_type_raises_instead_of_crashing():
    result = _run("""
from mjcffi import functions as F
s = F.mj_makeSpec()
body = F.mjs_addBody(F.mjs_findBody(s, "world"), None)
F.mjs_setName(body.element, "b")
F.mj_compile(s, None)      # on a compiled spec MuJoCo follows these types out of bounds
for value in (10**9, 2**31 - 1, 101):
    try:
        F.mjs_findElement(s, value, "b")
    except ValueError as exc:
        print("refused", exc)
print(F.mjs_findElement(s, 1, "b").elemtype)
""", timeout=120)
    assert result[0] == 0, result[2][-2000:]
    assert result[1].count("refused type=") == 3 and result[1].split()[-1] == "1", result[1]


# --------------------------------------------- a scene for another model

_SKIN = """
<mujoco>
  <worldbody><body name="b"><geom size=".1"/></body></worldbody>
  <deformable>
    <skin name="s" vertex="0 0 0  1 0 0  0 1 0" face="0 1 2">
      <bone body="b" bindpos="0 0 0" bindquat="1 0 0 0" vertid="0 1 2" vertweight="1 1 1"/>
    </skin>
  </deformable>
</mujoco>
"""


def _scene_models():
    flex = mjcffi.MjModel.from_xml_string(_calls.XML)
    skin = mjcffi.MjModel.from_xml_string(_SKIN)
    plain = mjcffi.MjModel.from_xml_string(scenes.DEFAULT)
    assert (flex.nflex, flex.nskin, skin.nflex, skin.nskin, plain.nflex, plain.nskin) == \
        (1, 0, 0, 1, 0, 0)
    return flex, skin, plain


def _scene_calls(m):
    """The calls that write m's flexes and skins into scn (or read them), by name."""
    d = mjcffi.MjData(m)
    opt, cam = structs.MjvOption(), structs.MjvCamera()
    ints = [np.zeros(1, np.int32) for _ in range(3)]
    return {"mjv_updateScene": lambda scn: F.mjv_updateScene(m, d, opt, None, cam, 7, scn),
            "mjv_updateSkin": lambda scn: F.mjv_updateSkin(m, d, scn),
            "mjv_select": lambda scn: F.mjv_select(m, d, opt, 1.0, 0.5, 0.5, scn, np.zeros(3),
                                                   *ints)}


def test_item_scene_checks_are_the_functions_that_write_a_model_into_a_scene():
    assert set(table.SCENES) == {"mjv_updateScene", "mjv_updateSkin", "mjv_select"}
    assert set(_scene_calls(mjcffi.MjModel.from_xml_string(scenes.DEFAULT))) == set(table.SCENES)


@pytest.mark.parametrize("which", ["flex", "skin"])
def test_item_a_scene_made_for_no_model_or_another_raises_value_error_naming_scn(which):
    flex, skin, plain = _scene_models()
    m = flex if which == "flex" else skin
    other = skin if which == "flex" else flex
    with _calls.stubbed():                 # a call that got through would not reach MuJoCo
        for label, scn in (("no model", structs.MjvScene()),
                           ("a model without them", structs.MjvScene(plain, 100)),
                           ("another model", structs.MjvScene(other, 100))):
            for func, call in _scene_calls(m).items():
                with pytest.raises(ValueError, match=r"^scn was made for .*not for this model") \
                        as caught:
                    call(scn)
                assert "mjv_makeScene(m, scn, maxgeom)" in str(caught.value), (label, func)
        freed = structs.MjvScene(m, 100)
        F.mjv_freeScene(freed)
        with pytest.raises(ValueError, match="^scn was made for no model"):
            _scene_calls(m)["mjv_updateScene"](freed)
        with pytest.raises(TypeError, match="^scn must be an MjvScene .* not a raw mjvScene"):
            _scene_calls(m)["mjv_updateScene"](structs.MjvScene(m, 100)._ptr)


def test_item_a_scene_made_for_the_model_or_one_like_it_is_taken():
    flex, skin, plain = _scene_models()
    for m in (flex, skin):
        calls = _scene_calls(m)
        scn = structs.MjvScene(m, 100)
        remade = structs.MjvScene(plain, 10)
        F.mjv_makeScene(m, remade, 100)                    # mjcffi's mjv_makeScene records it
        like = mjcffi.MjModel.from_xml_string(_calls.XML if m is flex else _SKIN)
        for scene in (scn, remade, structs.MjvScene(like, 100)):
            for func, call in calls.items():
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")          # mjv_updateSkin is deprecated
                    call(scene)
        calls["mjv_updateScene"](scn)
        assert scn.ngeom > 0
    # a model without flexes and skins writes nothing there: any scene will do
    calls = _scene_calls(plain)
    for scene in (structs.MjvScene(), structs.MjvScene(flex, 100),
                  structs.MjvScene(plain, 100)._ptr):
        calls["mjv_updateScene"](scene)


def test_item_a_scene_remade_or_rewritten_outside_mjcffi_is_refused():
    flex, skin, plain = _scene_models()
    call = _scene_calls(flex)["mjv_updateScene"]
    with _calls.stubbed():
        scn = structs.MjvScene(flex, 100)
        scn.flexfaceadr[0] = 10**6                          # MuJoCo writes faces there
        with pytest.raises(ValueError, match=r"^scn's buffers were changed outside mjcffi"):
            call(scn)
        scn = structs.MjvScene(flex, 100)
        mjcffi.lib.mjv_makeScene(flex._ptr, scn._ptr, 10)  # raw: new buffers, not recorded
        scn._remade()
        with pytest.raises(ValueError, match=r"^scn's buffers were changed outside mjcffi"):
            call(scn)


def test_item_the_scene_check_costs_little():
    """Measured against the call: a model without flexes and skins pays two reads."""
    import timeit
    from mjcffi._support import checks as _checks
    flex, skin, plain = _scene_models()
    for m, limit in ((plain, 2e-6), (flex, 2e-5)):
        scn = structs.MjvScene(m, 100)
        _checks.scene(m._ptr, scn, scn._ptr)
        cost = min(timeit.repeat(lambda: _checks.scene(m._ptr, scn, scn._ptr), number=2000,
                                 repeat=3)) / 2000
        assert cost < limit, (m.nflex, cost)
