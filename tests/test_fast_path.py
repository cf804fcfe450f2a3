"""The fast paths of the generated functions (issue 25): taken, and never looser.

A generated function F tests its arguments inline and calls C directly when
they are exact (codegen/fastpath.py); anything else goes to `_F(args)()`, the
slow path, with its conversions and messages.  So for every call, F and `_F`
(the slow path alone) must do the same thing: the same exception with the same
message, or the same outputs, bit for bit.  The sweep checks that on every
function with a fast path, for its valid call and for every variation of each
array (short, long, transposed, flat, (k, 1), 3-D, another dtype, strided,
Fortran order, read-only, misaligned, a list, None, a scalar) and of each id
(at its bounds).  Arrays sit against guard pages (tests/fuzz/guard.py), so a
fast path that let MuJoCo read or write one element too many faults; the
sweep runs in a subprocess, so that such a fault fails the test instead of
killing pytest.
"""

import copy
import json
import math
import pathlib
import struct
import subprocess
import sys

import numpy as np
import pytest

from codegen import functions as table

REPO = pathlib.Path(__file__).resolve().parent.parent

# The calls of issue 25's table, and the four it adds: each must take its fast path.
ISSUE_CALLS = ("mj_kinematics", "mj_jac", "mj_jacBody", "mj_fullM", "mj_mulM",
               "mj_objectVelocity", "mju_add3", "mju_rotVecQuat", "mju_mulMatVec",
               "mju_norm3", "mj_contactForce", "mj_solveM", "mju_boxQP", "mj_ray")

# Calls whose two runs differ by design, so only their outcome kinds are compared.
NONDETERMINISTIC = {"mju_standardNormal": "draws random numbers",
                    "mju_writeLog": "appends to a log file",
                    "mj_printData": "writes a file", "mj_printFormattedData": "writes a file",
                    "mju_printMat": "prints"}


# ------------------------------------------------------------ the sweep (subprocess)

def _has_fast_path(name):
    import inspect
    from mjcffi import _functions as G
    source = inspect.getsource(getattr(G, name))      # the public F: does it call C itself?
    return f"_lib.mjcffi_guard_{name}(" in source


def _plain(value):
    """An exact, C-contiguous, aligned ndarray: copied against a guard page for each run.
    Any other array (strided, misaligned, a subclass...) is passed itself, its values
    put back before each run, since a copy would not keep its layout."""
    return (type(value) is np.ndarray and value.flags.c_contiguous and value.flags.aligned
            and value.size > 0)


def _fresh(kwargs, where="back", originals=None):
    """The call's arguments, arrays copied against a guard page, the MjData copied."""
    from mjcffi.data import MjData
    from tests.fuzz.guard import guarded
    out = {}
    for name, value in kwargs.items():
        if isinstance(value, MjData):
            out[name] = copy.copy(value)
        elif isinstance(value, np.ndarray) and _plain(value):
            out[name] = guarded(value, front=where == "front",
                                readonly=not value.flags.writeable)
        elif isinstance(value, np.ndarray):
            if value.flags.writeable and originals is not None:
                np.copyto(value, originals[name])
            out[name] = value
        elif isinstance(value, list):
            out[name] = copy.deepcopy(value)
        else:
            out[name] = value
    return out


def _value(result):
    """A result as something comparable bit for bit."""
    from mjcffi import ffi
    if isinstance(result, float):
        return ["float", struct.pack("d", result).hex()]
    if isinstance(result, np.ndarray):
        return ["array", result.tobytes().hex()]
    from mjcffi._support.views import Struct, ValueStruct
    pointer = getattr(result, "_ptr", result)
    if isinstance(result, Struct) and not isinstance(result, ValueStruct):
        return ["struct", type(result).__name__]     # pointers inside: the kind alone
    if isinstance(pointer, ffi.CData):
        if ffi.typeof(pointer).kind == "pointer" and ffi.typeof(pointer).item.kind == "struct":
            return ["struct", ffi.buffer(pointer)[:].hex()]     # a copy, or MuJoCo's own
        return ["pointer", int(ffi.cast("uintptr_t", pointer))]
    return ["value", repr(result)]


def _state(kwargs):
    """What a call may have written: its arrays, and every array and count of its MjData
    (field by field: the padding between arrays is nobody's, and differs between copies)."""
    from mjcffi.data import MjData
    out = {}
    for name, value in kwargs.items():
        if isinstance(value, np.ndarray):
            out[name] = value.tobytes().hex()
        elif isinstance(value, MjData):
            fields = []
            for field in value._fields:
                item = getattr(value, field)
                if isinstance(item, np.ndarray):
                    fields.append(item.tobytes().hex())
                elif isinstance(item, (int, float)):
                    fields.append(repr(item))
            out[name] = fields
    return out


def _run(function, kwargs):
    """('ok', result, state) or ('raised', type, message) of one call."""
    try:
        result = function(**kwargs)
    except Exception as exc:          # noqa: BLE001  (every exception is an outcome)
        return ["raised", type(exc).__name__, str(exc)]
    return ["ok", _value(result), _state(kwargs)]


def _variants(name, base):
    """(label, kwargs): the valid call, each array varied, each id at its bounds."""
    from mjcffi._generated.funcinfo import FUNCTIONS
    from tests.test_function_conformance import variations
    yield "valid", base
    yield "valid, arrays at the front guard", {"__where": "front", **base}
    args = {a.name: a for a in FUNCTIONS[name].args}
    for py, value in base.items():
        arg = args.get(py) or args.get(py.rstrip("_"))
        if not isinstance(value, np.ndarray) or arg is None:
            continue
        for label, varied in variations(value, arg):
            yield f"{py} {label}", {**base, py: varied}
        if value.dtype.itemsize > 1 and value.size:
            raw = np.zeros(value.nbytes + 1, np.uint8)
            misaligned = raw[1:].view(value.dtype).reshape(value.shape)
            misaligned[...] = value
            yield f"{py} misaligned", {**base, py: misaligned}
        yield f"{py} a subclass", {**base, py: value.view(np.matrix) if value.ndim == 2
                                   else np.asarray(value).view(_Sub)}
    m, d = None, None
    for value in base.values():
        m = value if getattr(value, "_cname", None) == "mjModel" else m
        d = value if getattr(value, "_cname", None) == "mjData" else d
    for c_name, (low, count) in table.IDS.get(name, {}).items():
        py = c_name + "_" if c_name in ("type", "id") and c_name + "_" in base else c_name
        if py not in base:
            continue
        limit = int(eval(count, {"m": m, "d": d}))    # noqa: S307  (the table's own)
        for label, value in (("low-1", low - 1), ("low", low), ("count-1", limit - 1),
                             ("count", limit), ("as float", float(low)), ("as bool", True)):
            yield f"{py}={label}", {**base, py: value}


class _Sub(np.ndarray):
    """An ndarray subclass: the fast path leaves it to the slow path."""


def _sweep():
    """Print {function: {case: [fast outcome, slow outcome]}} for every mismatch, and the
    functions whose valid call took the fast path."""
    import mjcffi  # noqa: F401
    from mjcffi import _functions as G
    from tests import _calls
    pool = _calls.Pool()
    mismatches, taken, cases, varying = {}, [], 0, set()
    names = sorted(n for n in table.fast_path_functions())
    for name in names:
        base = _calls.full_call(name, pool)
        if base is None:
            continue
        public, slow = getattr(G, name), getattr(G, "_" + name)
        for label, kwargs in _variants(name, base):
            where = kwargs.pop("__where", "back")
            originals = {py: np.array(v) for py, v in kwargs.items()
                         if isinstance(v, np.ndarray) and not _plain(v)}
            fast = _run(public, _fresh(kwargs, where, originals))
            reference = _run(slow, _fresh(kwargs, where, originals))
            again = _run(slow, _fresh(kwargs, where, originals))
            cases += 1
            if name in NONDETERMINISTIC or reference != again:   # MuJoCo's own variation
                fast, reference = fast[:1], reference[:1]
                varying.add(name)
            if fast != reference:
                mismatches.setdefault(name, {})[label] = [fast, reference]
        setattr(G, "_" + name, _refuse)           # the valid call again: fast or not?
        try:
            public(**_fresh(base))
            taken.append(name)
        except _SlowPathTaken:
            pass
        except Exception:             # noqa: BLE001  (a valid call may still fail in C)
            taken.append(name)
        finally:
            setattr(G, "_" + name, slow)
    print(json.dumps({"mismatches": mismatches, "taken": taken, "names": names,
                      "cases": cases, "varying": sorted(varying)}))


class _SlowPathTaken(Exception):
    pass


def _refuse(*args, **kwargs):
    raise _SlowPathTaken


@pytest.fixture(scope="module")
def sweep():
    run = subprocess.run([sys.executable, "-c",
                          "from tests.test_fast_path import _sweep; _sweep()"],
                         cwd=REPO, capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, f"exit status {run.returncode}\n{run.stderr[-4000:]}"
    return json.loads(run.stdout.strip().splitlines()[-1])


def test_fast_and_slow_paths_agree_on_every_variation(sweep):
    assert sweep["cases"] > 3000, sweep["cases"]
    # calls whose outputs differ between two slow runs are compared by outcome only
    assert len(sweep["varying"]) <= 10, sweep["varying"]
    assert sweep["mismatches"] == {}, json.dumps(sweep["mismatches"], indent=1)[:6000]


def test_the_issue_calls_take_their_fast_path(sweep):
    missing = [name for name in ISSUE_CALLS if name not in sweep["taken"]]
    assert not missing, missing
    # every function that has a fast path and a valid call in the pool takes it
    assert len(sweep["taken"]) >= 150, len(sweep["taken"])


def test_functions_with_a_fast_path_are_those_codegen_says():
    from mjcffi import _functions as G
    listed = set(table.fast_path_functions())
    assert len(listed) > 150
    for name in listed:
        assert _has_fast_path(name), name
    assert not _has_fast_path("mjv_updateScene")      # a scene argument: slow path only


# ------------------------------------------------------------ in process

@pytest.fixture(scope="module")
def model():
    import mjcffi
    from tests import _calls
    return _calls.model_env(mjcffi)


def test_ids_out_of_range_still_raise_the_slow_path_error(model):
    import mjcffi
    m, d = model["m"], model["d"]
    jacp = np.zeros((3, m.nv))
    for body in (-1, m.nbody, 2 ** 31, 2 ** 80):
        with pytest.raises(mjcffi.IdError, match="body"):
            mjcffi.mj_jac(m, d, jacp, None, np.zeros(3), body)
    with pytest.raises(TypeError, match="body"):
        mjcffi.mj_jac(m, d, jacp, None, np.zeros(3), 1.0)


def test_a_scalar_c_refuses_goes_to_the_slow_path_and_its_message(model):
    import mjcffi
    m, d = model["m"], model["d"]
    with pytest.raises(TypeError, match="flg_local"):
        mjcffi.mj_objectVelocity(m, d, 1, 1, np.zeros(6), "local")
    with pytest.raises(ValueError, match="flg_local"):
        mjcffi.mj_objectVelocity(m, d, 1, 1, np.zeros(6), 2 ** 40)


def test_a_model_of_the_same_sizes_takes_the_slow_path_and_is_accepted(model):
    import mjcffi
    from tests import _calls
    m, d = model["m"], model["d"]
    other = _calls.model_env(mjcffi)["m"]          # same sizes, another object
    jacp = np.zeros((3, m.nv))
    mjcffi.mj_jac(other, d, jacp, None, np.zeros(3), 1)
    expected = np.zeros((3, m.nv))
    mjcffi.mj_jac(m, d, expected, None, np.zeros(3), 1)
    assert jacp.tobytes() == expected.tobytes()


def test_values_that_are_zero_are_still_checked_for_errors():
    # a value-returning guard returns zero on an error, and only then is asked why
    import mjcffi
    assert mjcffi.mju_norm3(np.zeros(3)) == 0.0
    assert mjcffi.mju_norm3(np.array([3.0, 4.0, 0.0])) == 5.0
    assert math.isnan(mjcffi.mju_norm3(np.array([np.nan, 0.0, 0.0])))
