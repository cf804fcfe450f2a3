"""The function layer (mjcffi/functions.py): signatures, marshalling, checks, results.

The official bindings, loaded in the same process on the same libmujoco, are
the oracle for results; gymnasium's models are the real-world inputs.
"""

import copy
import inspect
import keyword
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import mjcffi
from mjcffi import functions as F
from mjcffi import structs
from mjcffi._funcinfo import FUNCTIONS
from mjcffi._views import DTYPES
from mjcffi.data import MjData
from mjcffi.model import MjModel

from codegen import functions as table
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

_STRUCT_OF = {getattr(structs, cls)._cname: cls for cls in structs.MODULES}
_INTS = {"int", "unsigned int", "mjtSize", "size_t", "mjtByte", "unsigned char", "mjtBool",
         "uint64_t", "int64_t"}
_FLOATS = {"mjtNum", "double", "float"}


def _kind(arg):
    if arg.pointer == 0 and not arg.extents:
        if arg.elem in _STRUCT_OF:
            return "struct_value"
        if "(*" in arg.ctype:
            return "callback"
        return "float" if arg.elem in _FLOATS else "int"
    if arg.pointer > 1:
        return "other"
    if arg.elem == "char":
        return "text" if arg.const else "chars"
    if arg.elem == "void":
        return "void"
    if arg.elem in _INTS | _FLOATS:
        return "in" if arg.const else "out"
    if arg.elem in _STRUCT_OF:
        return "struct"
    return "opaque"


class _Pool:
    """Plausible values for every kind of argument, and values that are always wrong."""

    def __init__(self):
        self.m = MjModel.from_xml_string(PENDULUM)
        self.d = MjData(self.m)
        other = MjModel.from_xml_string("<mujoco><worldbody><body><freejoint/>"
                                        "<geom size='1'/></body></worldbody></mujoco>")
        self.alien = MjData(other)
        self.spec = F.mj_makeSpec()
        self.world = F.mjs_findBody(self.spec, "world")
        self.instances = {"mjModel": self.m, "mjData": self.d, "mjSpec": self.spec,
                          "mjsBody": self.world}
        for cname, cls in _STRUCT_OF.items():
            if cname not in self.instances:
                try:
                    self.instances[cname] = getattr(structs, cls)()
                except TypeError:
                    pass

    def good(self, arg, draw):
        """A plausible value: right in kind, of any size (it may still be refused)."""
        kind = _kind(arg)
        if kind in ("struct", "struct_value"):
            return self.instances.get(arg.elem)
        size = draw(st.sampled_from([0, 1, 3, 4, 6, 9]))
        if kind == "in":
            return np.zeros(size)
        if kind == "out":
            return np.zeros(size, DTYPES[arg.elem])
        return draw(st.sampled_from({
            "int": [0, 1, -1, 2], "float": [0.0, 1.5, -2.0], "text": ["x", "body", ""],
            "chars": [bytearray(4)], "void": [None], "opaque": [None]}[kind]))

    def bad(self, func, arg, draw):
        """A value that `func` must refuse for `arg`, whatever the other arguments."""
        kind = _kind(arg)
        options = []
        nullable = arg.nullable or arg.name in table.NULLABLE.get(func, ())
        if not nullable and kind not in ("int", "float"):
            options.append(None)
        if kind in ("struct", "struct_value"):
            wrong = next(v for c, v in self.instances.items() if c != arg.elem)
            options += [object(), 3, "mjModel", wrong]
            if arg.elem == "mjData" and any(a.elem == "mjModel" and not a.nullable
                                            for a in FUNCTIONS[func].args):
                options.append(self.alien)
        elif kind == "int":
            options += ["1", 1.5, [1], 2 ** 80, -2 ** 80, object()]
            limit = table.IDS.get(func, {}).get(arg.name)
            if limit:
                options.append(10 ** 6)
        elif kind == "float":
            options += ["1.0", [1.0], object(), 10 ** 400]
        elif kind == "text":
            options += [12, b"a\0b", ["x"], 1.5]
        elif kind == "in":
            options += ["abc", {"a": 1}, object(), [[1.0, 2.0], [3.0]]]
        elif kind == "out":
            right = DTYPES[arg.elem]
            readonly = np.zeros(3, right)
            readonly.flags.writeable = False
            options += [[0, 0, 0], (0,), "abc", np.zeros(3, np.complex128),
                        np.zeros(6, right)[::2], readonly]
        elif kind == "void" and (arg.name in table.SHAPES.get(func, {})
                                 or func == "mj_loadModelBuffer"):
            options += [12, "text", 1.5] + ([] if arg.const else [b"read-only"])
        elif kind in ("void", "opaque", "chars"):
            options += [12, "text", b"bytes", 1.5]
        return draw(st.sampled_from(options))


def _fuzzable():
    out = []
    for name, info in FUNCTIONS.items():
        if name in table.UNSUPPORTED:
            continue
        params = inspect.signature(getattr(F, name)).parameters
        by_name = {a.name: a for a in info.args}
        args = []
        for p in params:
            arg = by_name.get(p.rstrip("_")) or by_name.get(p)
            if arg is None or _kind(arg) in ("callback", "other"):
                break
            args.append((p, arg))
        else:
            if args:
                out.append((name, args))
    return out


_FUZZABLE = _fuzzable()


def test_fuzz_covers_many_functions():
    assert len(_FUZZABLE) > 350


@pytest.fixture(scope="module")
def scratch_dir(tmp_path_factory):
    """The fuzz runs here: a wrongly accepted call must not write into the repository."""
    import os
    previous = os.getcwd()
    os.chdir(tmp_path_factory.mktemp("fuzz"))
    yield
    os.chdir(previous)


@settings(max_examples=10_000, deadline=None, database=None, derandomize=True,
          suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_fuzz_bad_arguments_raise_type_or_value_error(scratch_dir, data):
    pool = _FUZZ_POOL
    name, args = data.draw(st.sampled_from(_FUZZABLE))
    target = data.draw(st.integers(0, len(args) - 1))
    values = {}
    for i, (py, arg) in enumerate(args):
        values[py] = pool.bad(name, arg, data.draw) if i == target else \
            pool.good(arg, data.draw)
    _FUZZ_CALLS.append(name)
    with pytest.raises((TypeError, ValueError)):
        getattr(F, name)(**values)
        print(f"{name}({values}) did not raise")


def test_fuzz_made_enough_calls():
    """Runs after the fuzz (pytest keeps file order): at least 10,000 calls, many functions."""
    if not _FUZZ_CALLS:
        pytest.skip("the fuzz test did not run")
    assert len(_FUZZ_CALLS) >= 10_000 and len(set(_FUZZ_CALLS)) > 300


_FUZZ_POOL = _Pool()
_FUZZ_CALLS = []


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
