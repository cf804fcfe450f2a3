"""The function layer (mjcffi/functions/__init__.py): signatures, marshalling, checks, results.

The official bindings, loaded in the same process on the same libmujoco, are
the oracle for results; gymnasium's models are the real-world inputs.
"""

import copy
import inspect
import keyword
import math
import os
import pathlib
import re

import numpy as np
import pytest
import mjcffi
from mjcffi import functions as F
from mjcffi import structs
from mjcffi._generated.funcinfo import FUNCTIONS
from mjcffi.data import MjData
from mjcffi.model import MjModel

from codegen import functions as table
from . import _calls
from .conftest import gymnasium_assets

PENDULUM = """
<mujoco>
  <worldbody>
    <body name="pole">
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom name="rod" type="capsule" size="0.05" fromto="0 0 0 0 0 -1"/>
      <site name="tip" pos="0 0 -1"/>
    </body>
  </worldbody>
  <actuator><motor name="motor" joint="hinge"/></actuator>
  <sensor><jointpos joint="hinge"/></sensor>
</mujoco>
"""

ASSETS = {p.stem: p for p in gymnasium_assets()}


def load(name):
    """(mjcffi model, data, official model, data) of a gymnasium model, forwarded."""
    import mujoco
    path = str(ASSETS[name])
    m, om = MjModel.from_xml_path(path), mujoco.MjModel.from_xml_path(path)
    d, od = MjData(m), mujoco.MjData(om)
    for model, data, lib_ in ((m, d, F), (om, od, mujoco)):
        data.qpos[:] = model.qpos0 + 0.05 * np.sin(np.arange(model.nq))
        data.qvel[:] = 0.1 * np.cos(np.arange(model.nv))
        lib_.mj_forward(model, data)
    return m, d, om, od


@pytest.fixture(scope="module")
def pendulum():
    m = MjModel.from_xml_string(PENDULUM)
    return m, MjData(m)


# ---------------------------------------------------------------- structure

def test_every_function_is_there_with_its_header_doc():
    for name, info in FUNCTIONS.items():
        func = getattr(F, name)
        assert callable(func), name
        # the official shape: the signature line, then the header's doc comment
        signature, _, rest = func.__doc__.partition("\n\n")
        assert signature.startswith(name + "("), name
        assert rest.startswith(info.doc.splitlines()[0] if info.doc
                               else "(no header comment)"), name


def test_python_names_are_the_headers():
    """Parameters keep mujoco.h's names, in order, less deduced sizes and error buffers."""
    for name, info in FUNCTIONS.items():
        if name in table.OVERRIDES:
            continue
        renames = table.RENAMES.get(name, {})
        c_names = [renames.get(a.name, a.name) for a in info.args if a.name != "..."]
        c_names = [n + "_" if keyword.iskeyword(n) else n for n in c_names]
        params = list(inspect.signature(getattr(F, name)).parameters)
        assert params == [n for n in c_names if n in params], name
        assert set(params) <= set(c_names), name


def test_unsupported_functions_say_why():
    for name, reason in table.UNSUPPORTED.items():
        params = inspect.signature(getattr(F, name)).parameters
        with pytest.raises(NotImplementedError, match=name):
            getattr(F, name)(*[None] * len(params))
        assert reason in " ".join(getattr(F, name).__doc__.split())


def test_overrides_keep_header_doc_and_add_python_notes():
    for name in table.OVERRIDES:
        doc = getattr(F, name).__doc__.partition("\n\n")[2]      # after the signature
        assert doc.startswith(FUNCTIONS[name].doc.splitlines()[0]), name
        assert "Python:" in doc, name


# ------------------------------------------------------------ the basic rules

def test_keywords_work(pendulum):
    m, d = pendulum
    F.mj_forward(m=m, d=d)
    jacp = np.zeros((3, m.nv))
    F.mj_jac(m=m, d=d, jacp=jacp, jacr=None, point=d.site_xpos[0], body=1)
    assert jacp.any()
    res = np.zeros(3)
    F.mju_add3(res=res, vec1=[1, 2, 3], vec2=[1, 1, 1])
    assert res.tolist() == [2, 3, 4]
    assert F.mj_name2id(m=m, type=mjcffi.mjtObj.mjOBJ_BODY, name="pole") == 1


def test_sizes_are_deduced_and_outputs_written_in_place():
    res = np.zeros(5)
    assert F.mju_add(res, np.arange(5.0), [1, 1, 1, 1, 1]) is None
    assert res.tolist() == [1, 2, 3, 4, 5]
    assert F.mju_dot(res, res) == 55.0
    mat = np.arange(6.0).reshape(2, 3)
    out = np.zeros(2)
    F.mju_mulMatVec(out, mat, [1, 0, 1])
    assert out.tolist() == [2.0, 8.0]
    prod = np.zeros((2, 2))
    F.mju_mulMatMatT(prod, mat, mat)
    assert np.array_equal(prod, mat @ mat.T)
    transposed = np.zeros((3, 2))
    F.mju_transpose(transposed, mat)
    assert np.array_equal(transposed, mat.T)
    flat = np.zeros(6)                    # flat is a (6, 1) matrix, as in the official
    with pytest.raises(TypeError, match="#columns in res should equal #rows in mat"):
        F.mju_transpose(flat, mat)
    ints = np.array([3, 1, 2], np.int32)
    F.mju_insertionSortInt(ints)
    assert ints.tolist() == [1, 2, 3]
    pyramid = np.zeros(4)
    F.mju_encodePyramid(pyramid, [1.0, 0.2, 0.1], [1.0, 1.0])
    assert np.allclose(pyramid, [0.6, 0.4, 0.0, 0.0])   # dim deduced from mu: 2


def test_inputs_are_converted_outputs_never_copied():
    res = np.zeros(3)
    F.mju_add3(res, np.array([1, 2, 3], np.int32), (1.0, 1.0, 1.0))   # inputs: converted
    assert res.tolist() == [2, 3, 4]
    for bad, error in ((np.zeros(3, np.float32), TypeError), ([0.0, 0.0, 0.0], TypeError),
                       (np.zeros(6)[::2], ValueError)):
        with pytest.raises(error, match="res"):
            F.mju_add3(bad, [1, 2, 3], [1, 1, 1])
    readonly = np.zeros(3)
    readonly.flags.writeable = False
    with pytest.raises(ValueError, match="res.*read-only"):
        F.mju_zero3(readonly)


def test_nullable_arguments(pendulum):
    m, d = pendulum
    F.mj_forward(m, d)
    jacr = np.zeros((3, m.nv))
    F.mj_jac(m, d, None, jacr, [0, 0, 0], 1)             # Nullable: jacp
    assert jacr.any()
    with pytest.raises(TypeError, match="point"):
        F.mj_jac(m, d, None, jacr, None, 1)               # point is not Nullable
    with pytest.raises(TypeError, match="d must be MjData"):
        F.mj_forward(m, None)
    assert isinstance(F.mju_standardNormal(), float)     # num2 defaults to None
    second = np.zeros(1)
    F.mju_standardNormal(second)
    assert second[0] != 0.0


def test_strings(pendulum):
    m, _ = pendulum
    body = mjcffi.mjtObj.mjOBJ_BODY
    assert F.mj_name2id(m, body, "pole") == 1
    assert F.mj_name2id(m, body, b"pole") == 1
    assert F.mj_name2id(m, body, "nothing") == -1
    assert F.mj_id2name(m, body, 1) == "pole"
    assert F.mj_id2name(m, body, 99) is None
    assert F.mju_type2Str(body) == "body"
    with pytest.raises(ValueError, match="name.*NUL"):
        F.mj_name2id(m, body, "po\0le")
    with pytest.raises(TypeError, match="name"):
        F.mj_name2id(m, body, 1)


# ------------------------------------------------- results equal the official

@pytest.mark.parametrize("name", ["humanoid", "ant", "half_cheetah", "hopper", "walker2d"])
def test_forward_inverse_and_jacobians_match_official(mujoco, name):
    m, d, om, od = load(name)
    for field in ("qacc", "xpos", "xquat", "qfrc_bias", "cacc", "sensordata"):
        assert np.array_equal(getattr(d, field), getattr(od, field)), field
    F.mj_inverse(m, d)
    mujoco.mj_inverse(om, od)
    assert np.array_equal(d.qfrc_inverse, od.qfrc_inverse)
    for body in range(m.nbody):
        ours, theirs = np.zeros((2, 3, m.nv)), np.zeros((2, 3, m.nv))
        F.mj_jac(m, d, ours[0], ours[1], d.xipos[body], body)
        mujoco.mj_jac(om, od, theirs[0], theirs[1], od.xipos[body], body)
        assert np.array_equal(ours, theirs)
        F.mj_jacBodyCom(m, d, ours[0], None, body)
        mujoco.mj_jacBodyCom(om, od, theirs[0], None, body)
        assert np.array_equal(ours[0], theirs[0])
    M, oM = np.zeros((m.nv, m.nv)), np.zeros((m.nv, m.nv))
    F.mj_fullM(m, d, M)
    mujoco.mj_fullM(om, od, oM)
    assert np.array_equal(M, oM)
    vec = np.linspace(-1, 1, m.nv)
    res, ores = np.zeros(m.nv), np.zeros(m.nv)
    F.mj_mulM(m, d, res, vec)
    mujoco.mj_mulM(om, od, ores, vec)
    assert np.array_equal(res, ores)
    assert np.allclose(res, M @ vec)


@pytest.mark.parametrize("name", ["humanoid", "ant"])
def test_names_state_and_rays_match_official(mujoco, name):
    m, d, om, od = load(name)
    for objtype in (mjcffi.mjtObj.mjOBJ_BODY, mjcffi.mjtObj.mjOBJ_JOINT,
                    mjcffi.mjtObj.mjOBJ_GEOM, mjcffi.mjtObj.mjOBJ_ACTUATOR):
        for i in range(8):
            assert F.mj_id2name(m, objtype, i) == mujoco.mj_id2name(om, objtype, i)
            label = mujoco.mj_id2name(om, objtype, i)
            if label:
                assert F.mj_name2id(m, objtype, label) == i
    sig = mjcffi.mjtState.mjSTATE_INTEGRATION
    size = F.mj_stateSize(m, sig)
    assert size == mujoco.mj_stateSize(om, sig)
    state, ostate = np.zeros(size), np.zeros(size)
    F.mj_getState(m, d, state, sig)
    mujoco.mj_getState(om, od, ostate, sig)
    assert np.array_equal(state, ostate)
    fresh = MjData(m)
    F.mj_setState(m, fresh, state, sig)
    assert np.array_equal(fresh.qpos, d.qpos) and np.array_equal(fresh.qvel, d.qvel)
    start = d.xpos[1] + [0, 0, 5.0]
    for direction in ([0, 0, -1.0], [1.0, 0.2, -0.5], [0.3, -1.0, -0.1]):
        geomid, ogeomid = np.zeros(1, np.int32), np.zeros(1, np.int32)
        normal, onormal = np.zeros(3), np.zeros(3)
        dist = F.mj_ray(m, d, start, direction, None, 1, -1, geomid, normal)
        odist = mujoco.mj_ray(om, od, start, direction, None, 1, -1, ogeomid, onormal)
        assert dist == odist and geomid[0] == ogeomid[0] and np.array_equal(normal, onormal)
    group = np.array([1, 0, 1, 0, 0, 0], np.uint8)
    geomid, ogeomid = np.zeros(1, np.int32), np.zeros(1, np.int32)
    assert F.mj_ray(m, d, start, [0, 0, -1.0], group, 0, 1, geomid, None) == \
        mujoco.mj_ray(om, od, start, [0, 0, -1.0], group, 0, 1, ogeomid, None)


def test_vector_and_quaternion_ops_match_official(mujoco):
    rng = np.random.default_rng(0)
    for _ in range(20):
        a, b = rng.normal(size=3), rng.normal(size=3)
        qa, qb = rng.normal(size=4), rng.normal(size=4)
        qa /= np.linalg.norm(qa)
        qb /= np.linalg.norm(qb)
        for fn, args, shape in (("mju_cross", (a, b), 3), ("mju_add3", (a, b), 3),
                                ("mju_rotVecQuat", (a, qa), 3), ("mju_mulQuat", (qa, qb), 4),
                                ("mju_negQuat", (qa,), 4), ("mju_quat2Mat", (qa,), 9),
                                ("mju_subQuat", (qa, qb), 3), ("mju_quat2Vel", (qa, 0.1), 3),
                                ("mju_axisAngle2Quat", (a, 0.3), 4)):
            ours, theirs = np.zeros(shape), np.zeros(shape)
            getattr(F, fn)(ours, *args)
            getattr(mujoco, fn)(theirs, *args)
            assert np.array_equal(ours, theirs), fn
        for fn in ("mju_dot3", "mju_dist3"):
            assert getattr(F, fn)(a, b) == getattr(mujoco, fn)(a, b)
        n = int(rng.integers(1, 9))
        v1, v2 = rng.normal(size=n), rng.normal(size=n)
        for fn, args in (("mju_add", (v1, v2)), ("mju_sub", (v1, v2)), ("mju_scl", (v1, 0.7)),
                         ("mju_addScl", (v1, v2, 0.3)), ("mju_copy", (v1,))):
            ours, theirs = np.zeros(n), np.zeros(n)
            getattr(F, fn)(ours, *args)
            getattr(mujoco, fn)(theirs, *args)
            assert np.array_equal(ours, theirs), fn
        assert F.mju_dot(v1, v2) == mujoco.mju_dot(v1, v2)
        assert F.mju_norm(v1) == mujoco.mju_norm(v1)
        mat = rng.normal(size=(n, 3))
        ours, theirs = np.zeros(n), np.zeros(n)
        F.mju_mulMatVec(ours, mat, a)
        mujoco.mju_mulMatVec(theirs, mat, a)
        assert np.array_equal(ours, theirs)
    quat = np.zeros(4)
    F.mju_mat2Quat(quat, np.eye(3).ravel())              # mat[9] is flat (or (9, 1))
    with pytest.raises(TypeError):
        F.mju_mat2Quat(quat, np.eye(3))                  # (3, 3): refused, as officially
    assert quat.tolist() == [1, 0, 0, 0]


# ------------------------------------------------------------- bad arguments

def test_bad_arguments_name_the_argument(pendulum):
    m, d = pendulum
    other = MjModel.from_xml_string("<mujoco><worldbody><body><freejoint/><geom size='1'/>"
                                    "</body></worldbody></mujoco>")
    cases = [
        (lambda: F.mj_jac(m, d, np.zeros((m.nv, 4)), None, [0, 0, 0], 0), ValueError, "jacp"),
        (lambda: F.mj_jac(m, d, np.zeros((3, m.nv), np.float32), None, [0, 0, 0], 0),
         TypeError, "jacp"),
        (lambda: F.mj_jac(m, d, np.zeros((3, m.nv)), None, [0, 0], 0), ValueError, "point"),
        (lambda: F.mj_jac(m, d, np.zeros((3, m.nv)), None, [0, 0, 0], 7), ValueError, "body"),
        (lambda: F.mj_jac(m, d, np.zeros((3, m.nv)), None, [0, 0, 0], "x"), TypeError, "body"),
        (lambda: F.mj_jac(d, d, None, None, [0, 0, 0], 0), TypeError, "m must be MjModel"),
        (lambda: F.mj_fullM(m, d, np.zeros((2, 2))), ValueError, "dst"),
        (lambda: F.mj_forward(m, MjData(other)), ValueError, "d was made"),
        (lambda: F.mj_step(m, MjData(other)), ValueError, "d was made"),
        (lambda: F.mj_step(m, m), TypeError, "d must be MjData"),
        (lambda: F.mj_step(m, d, 1.5), TypeError, "nstep"),
        (lambda: F.mj_step(m, d, 2 ** 40), ValueError, "nstep"),
        (lambda: F.mju_add(np.zeros(3), np.zeros(3), np.zeros(4)), ValueError, "vec2"),
        (lambda: F.mju_add(np.zeros(3), "abc", np.zeros(3)), ValueError, "vec1"),
        (lambda: F.mju_add(np.zeros(3), None, np.zeros(3)), TypeError, "vec1"),
        (lambda: F.mju_mulMatVec(np.zeros(2), np.zeros((3, 2)), np.zeros(3)), ValueError, "mat"),
        (lambda: F.mju_scl3(np.zeros(3), np.zeros(3), "x"), TypeError, "scl"),
        (lambda: F.mj_getState(m, d, np.zeros(1), mjcffi.mjtState.mjSTATE_FULLPHYSICS),
         ValueError, "state"),
        (lambda: F.mj_getState(m, d, np.zeros(1), "x"), TypeError, "sig"),
        (lambda: F.mju_transpose(np.zeros((2, 3)), np.zeros((2, 3))), ValueError, "res"),
        (lambda: F.mju_raySkin(1, 3, [0, 1, 5], np.zeros(9, np.float32), [0, 0, 0],
                               [0, 0, 1], None), ValueError, "face"),
        (lambda: F.mju_sparse2dense(np.zeros((2, 2)), np.zeros(2), [1, 1], [0, 5], [0, 0]),
         ValueError, "rownnz/rowadr"),
        (lambda: F.mj_objectVelocity(m, d, mjcffi.mjtObj.mjOBJ_BODY, 99, np.zeros(6), 0),
         ValueError, "objid"),
        (lambda: F.mjv_updateScene(m, d, structs.MjvOption(), None, structs.MjvOption(),
                                   0, structs.MjvScene()), TypeError, "cam must be MjvCamera"),
        (lambda: F.mju_free(b"bytes"), TypeError, "ptr"),
        (lambda: F.mj_saveModel(m, None, b"read-only"), ValueError, "buffer"),
        (lambda: F.mj_setLengthRange(m, d, 5, structs.MjLROpt()), mjcffi.FatalError,
         "invalid actuator index"),
    ]
    for i, (call, error, match) in enumerate(cases):
        with pytest.raises(error, match=match):
            call()
            print("case", i, "did not raise")


def test_model_data_of_the_same_sizes_are_accepted():
    m = MjModel.from_xml_string(PENDULUM)
    twin = copy.copy(m)
    d = MjData(twin)
    F.mj_step(m, d)
    F.mj_forward(m, d)
    assert d.time > 0


# --------------------------------------------------------------------- fuzz

# Every generated function that tests/_calls.py can call correctly gets that call
# with one argument replaced by a value it must refuse, for every argument and every
# such value of its kind.  The other arguments are right (each good call is first
# run against a stub of the compiled module, to prove that its checks take it), so
# the error must come from the replaced argument: it must be a TypeError,
# ValueError or IndexError whose message (or a note) names that argument.  The fuzz
# runs in a subprocess: a check that is missing would hand MuJoCo the bad value.

_STRUCT_OF = {getattr(structs, cls)._cname: cls for cls in structs.MODULES}
_INTS = {"int", "unsigned int", "mjtSize", "size_t", "mjtByte", "unsigned char", "mjtBool",
         "uint64_t", "int64_t"}
_FLOATS = {"mjtNum", "double", "float"}


def _kind(arg):
    if arg.pointer == 0 and not arg.extents:
        if "(*" in arg.ctype:
            return "callback"
        if arg.elem in _STRUCT_OF or arg.elem in ("mjModel", "mjData"):
            return "struct_value"
        return "float" if arg.elem in _FLOATS else "int"
    if arg.pointer > 1:
        return "other"
    if arg.elem == "char":
        return "text" if arg.const else "chars"
    if arg.elem == "void":
        return "void"
    if arg.elem in _INTS | _FLOATS:
        return "in" if arg.const else "out"
    if arg.elem in _STRUCT_OF or arg.elem in ("mjModel", "mjData"):
        return "struct"
    return "opaque"


def bad_values(func, py, arg, good, pool):
    """(label, value) pairs that `func` must refuse for `arg`, the others being right."""
    kind = _kind(arg)
    out = []
    if arg.name not in _calls.nullable(func):
        out.append(("None", None))
    if kind in ("struct", "struct_value"):
        wrong = next(v for c, v in pool.instances.items() if c != arg.elem)
        out += [("object()", object()), ("3", 3), ("a str", "mjModel"),
                (f"an {type(wrong).__name__}", wrong)]
        right = pool.instances.get(arg.elem)
        if right is not None and not isinstance(right, type):
            out.append(("the class", type(right)))
        if arg.elem == "mjData" and any(a.elem == "mjModel" and not a.nullable
                                        for a in FUNCTIONS[func].args):
            out.append(("an MjData of another model", pool.alien))
    elif kind == "int":
        out += [("'1'", "1"), ("1.5", 1.5), ("[1]", [1]), ("2**80", 2 ** 80),
                ("-2**80", -2 ** 80), ("object()", object())]
        bounds = table.IDS.get(func, {}).get(arg.name)
        if bounds:
            out += [("low-1", bounds[0] - 1), ("10**6", 10 ** 6), ("2**31-1", 2 ** 31 - 1),
                    ("-2**31", -2 ** 31)]
    elif kind == "float":
        out += [("'1.0'", "1.0"), ("[1.0]", [1.0]), ("object()", object()),
                ("10**400", 10 ** 400)]
    elif kind == "text":
        out += [("12", 12), ("with NUL", "a\0b"), ("['x']", ["x"]), ("1.5", 1.5)]
    elif kind in ("in", "out"):
        value = good[py]
        out += [("a str", "abc"), ("a dict", {"a": 1}), ("object()", object()),
                ("ragged", [[1.0, 2.0], [3.0]])]
        if isinstance(value, np.ndarray):
            out.append(("3-D", np.ones((1, max(value.size, 1), 1), value.dtype)))
            if arg.extents:
                out.append(("one more element", np.ones(value.size + 1, value.dtype)))
            if kind == "out":
                readonly = value.copy()
                readonly.flags.writeable = False
                wrong = np.int32 if value.dtype != np.int32 else np.float64
                out += [("a list", value.tolist()), ("complex", value.astype(np.complex128)),
                        ("wrong dtype", value.astype(wrong)), ("read-only", readonly)]
                if value.size > 1:
                    out.append(("strided", np.repeat(value, 2, axis=-1)[..., ::2]))
    elif kind == "void":
        out += [("12", 12), ("a str", "text"), ("1.5", 1.5)]
        if not arg.const:
            out.append(("read-only bytes", b"read-only"))
    elif kind in ("opaque", "chars"):
        out += [("12", 12), ("a str", "text"), ("bytes", b"bytes"), ("1.5", 1.5)]
    return out


def _names(exc, py):
    """Whether `exc`'s message or notes name the argument `py` (as a word)."""
    text = " ".join([str(exc), *getattr(exc, "__notes__", ())])
    return re.search(rf"(?<![A-Za-z0-9_]){re.escape(py)}(?![A-Za-z0-9_])", text) is not None


def _fuzz_main():
    """Run the fuzz; print one JSON line: calls made, functions, and every failure."""
    import json
    import sys
    import tempfile
    os.chdir(tempfile.mkdtemp(prefix="mjcffi-fuzz-"))   # a call wrongly taken writes here
    pool = _calls.Pool()
    pool.alien = MjData(MjModel.from_xml_string(
        "<mujoco><worldbody><body><freejoint/><geom size='1'/></body></worldbody></mujoco>"))
    failures, calls, funcs, skipped = [], 0, set(), []
    for func in sorted(FUNCTIONS):
        if not _calls.generated(func):
            continue
        good = _calls.full_call(func, pool)
        if good is None:
            skipped.append(func)
            continue
        try:
            if not _calls.reaches_c(func, good):
                failures.append(f"{func}: its good call does not reach C")
                continue
        except Exception as exc:        # noqa: BLE001  (reported)
            failures.append(f"{func}: its good call is refused: {type(exc).__name__}: {exc}")
            continue
        for py, arg in _calls.params(func):
            for label, bad in bad_values(func, py, arg, good, pool):
                sys.stderr.write(f"{func}({py}={label})\n")     # the last line, on a crash
                calls += 1
                funcs.add(func)
                try:
                    getattr(F, func)(**{**good, py: bad})
                except (TypeError, ValueError, IndexError) as exc:
                    if not _names(exc, py):
                        failures.append(f"{func}({py}={label}): {type(exc).__name__} does not "
                                        f"name {py}: {exc}")
                except BaseException as exc:   # noqa: BLE001  (reported)
                    failures.append(f"{func}({py}={label}): {type(exc).__name__}: {exc}")
                else:
                    failures.append(f"{func}({py}={label}) was accepted")
    print(json.dumps({"calls": calls, "functions": len(funcs), "skipped": skipped,
                      "failures": failures}))


@pytest.fixture(scope="module")
def fuzz_report():
    import json
    import subprocess
    import sys
    root = pathlib.Path(__file__).resolve().parent.parent
    run = subprocess.run([sys.executable, "-c",
                          "from tests.test_function_layer import _fuzz_main; _fuzz_main()"],
                         cwd=root, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, (run.returncode, run.stderr[-2000:])
    return json.loads(run.stdout.strip().splitlines()[-1])


def test_item_fuzz_bad_arguments_raise_errors_that_name_them(fuzz_report):
    assert not fuzz_report["failures"], "\n".join(fuzz_report["failures"])


def test_item_fuzz_covers_the_generated_functions(fuzz_report):
    # FULL_SKIP and the functions whose arguments the pool cannot fill (raw handles,
    # C callbacks) are the only ones left out; ~20 more take no argument
    assert fuzz_report["functions"] > 390 and fuzz_report["calls"] > 7_000
    assert len(fuzz_report["skipped"]) < 40, fuzz_report["skipped"]


# ------------------------------------------------------- errors and stepping

def test_mju_error_raises_fatal_error():
    with pytest.raises(mjcffi.FatalError, match="boom %s %d"):
        F.mju_error("boom %s %d")                 # a message, never a format string
    F.mju_warning("a warning is not an error")


def test_mj_step_nstep_is_bit_identical_to_n_calls():
    for name in ("humanoid", "ant", "hopper"):
        m = MjModel.from_xml_path(str(ASSETS[name]))
        a, b = MjData(m), MjData(m)
        for d in (a, b):
            d.qvel[:] = 0.3 * np.sin(np.arange(m.nv))
            d.ctrl[:] = 0.2
        F.mj_step(m, a, nstep=25)
        for _ in range(25):
            F.mj_step(m, b)
        for field in ("qpos", "qvel", "act", "qacc_warmstart", "time"):
            assert np.array_equal(getattr(a, field), getattr(b, field)), (name, field)
        F.mj_step(m, a, 0)                        # zero steps: nothing happens
        assert a.time == b.time


def test_warnings_as_errors_around_step_and_forward(monkeypatch):
    from mjcffi import warning_errors
    m = MjModel.from_xml_string(PENDULUM)
    d = MjData(m)
    d.qvel[0] = float("nan")                 # MuJoCo warns (mjWARN_BADQVEL) and resets
    mjcffi.set_warnings_as_errors(True)
    try:
        with pytest.raises(mjcffi.MjWarningError, match="mjWARN_BADQVEL"):
            F.mj_step(m, d, 3)
        checked = []
        monkeypatch.setattr(warning_errors, "after_call", lambda d, before: checked.append(d))
        F.mj_forward(m, d)
        assert checked == [d]
    finally:
        mjcffi.set_warnings_as_errors(False)
    d.qvel[0] = float("nan")
    F.mj_step(m, d)                           # off: counted only
    assert d.warning[mjcffi.mjtWarning.mjWARN_BADQVEL].number >= 1


def test_mj_step_matches_official(mujoco):
    m, d, om, od = load("walker2d")
    d.ctrl[:] = od.ctrl[:] = 0.5
    F.mj_step(m, d, 50)
    mujoco.mj_step(om, od, 50)
    assert np.array_equal(d.qpos, od.qpos) and np.array_equal(d.qvel, od.qvel)


# ---------------------------------------------------------------- overrides

def test_loading_and_saving(tmp_path, pendulum):
    m, _ = pendulum
    path = tmp_path / "pendulum.xml"
    path.write_text(PENDULUM)
    loaded = F.mj_loadXML(str(path))
    assert isinstance(loaded, MjModel) and loaded.nq == 1
    with pytest.raises(ValueError, match="XML"):
        F.mj_loadXML(str(tmp_path / "missing.xml"))
    F.mj_saveLastXML(str(tmp_path / "saved.xml"), loaded)
    assert "hinge" in (tmp_path / "saved.xml").read_text()
    buffer = np.zeros(F.mj_sizeModel(m), np.uint8)
    F.mj_saveModel(m, None, buffer)
    again = F.mj_loadModelBuffer(buffer)
    assert isinstance(again, MjModel) and again.nbody == m.nbody
    data = F.mj_makeData(again)
    assert isinstance(data, MjData) and data.model is again
    copied = F.mj_copyModel(None, m)
    assert isinstance(copied, MjModel) and copied.nv == m.nv
    assert F.mj_copyModel(copied, m) is copied
    schema = F.mj_printSchema(False, False)
    assert "mujoco" in schema and len(schema) > 10_000


def test_spec_functions():
    spec = F.mj_parseXMLString(PENDULUM)
    world = F.mjs_findBody(spec, "world")
    body = F.mjs_addBody(world, None)
    F.mjs_setName(body.element, "extra")
    geom = F.mjs_addGeom(body, None)
    geom.size[0] = 0.1
    model = F.mj_compile(spec, None)
    assert isinstance(model, MjModel) and model.nbody == 3
    assert F.mj_name2id(model, mjcffi.mjtObj.mjOBJ_BODY, "extra") == 2
    xml = F.mj_saveXMLString(spec)
    assert 'name="extra"' in xml
    with pytest.raises(ValueError):
        F.mj_parseXMLString("<mujoco><bad/></mujoco>")


def test_texture_and_gl_camera(mujoco):
    xml = ('<mujoco><asset><texture name="t" type="2d" builtin="checker" width="4" '
           'height="2" rgb1="1 0 0" rgb2="0 1 0"/></asset><worldbody/></mujoco>')
    m, om = MjModel.from_xml_string(xml), mujoco.MjModel.from_xml_string(xml)
    pixels, colorspace = F.mj_loadTexture(m, 0)
    opixels, ocolorspace = mujoco.mj_loadTexture(om, 0)
    assert np.array_equal(pixels, opixels) and colorspace == ocolorspace
    with pytest.raises(ValueError, match="id"):
        F.mj_loadTexture(m, 1)
    d = MjData(m)
    cam = F.mjv_camera2GLCamera(m=m, d=d, cam=structs.MjvCamera())
    assert isinstance(cam, structs.MjvGLCamera) and math.isfinite(cam.frustum_near)
