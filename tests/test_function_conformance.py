"""The function layer against the official bindings, argument by argument.

Every MuJoCo function that takes numeric arrays gets a valid call, built from
codegen's tables (SHAPES gives each array's extents) with small sizes that
differ per size argument, so that a transposed matrix is a wrong shape.  Each
variation then changes one array argument: one element more or fewer, a flat,
(k, 1), (1, k) or 3-D layout, a transposed matrix, a wrong dtype, a read-only
or strided output, a list for an input, None, a scalar.

mjcffi and the official bindings (both on the same libmujoco, in this process)
must then do the same: both succeed, or both raise, mjcffi's exception an
instance of the official's type, with the same message where the official
message is its own (not pybind11's generic "incompatible function arguments").
The few deliberate differences are listed in LENIENT, each with its reason.
"""

import inspect
import os
import warnings

import numpy as np
import pytest

import mjcffi
from codegen import functions as table
from mjcffi import _marshal
from mjcffi import functions as F
from mjcffi._funcinfo import FUNCTIONS

XML = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 .1"/>
    <body name="base" pos="0 0 1">
      <freejoint/>
      <geom name="ball" size=".1" pos="0 0 -.92"/>
      <body name="arm" pos="0 0 .3">
        <joint name="hinge" type="hinge"/>
        <geom name="rod" type="capsule" size=".05" fromto="0 0 0 0 0 .3"/>
        <site name="tip" pos="0 0 .3"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <position name="delayed" joint="hinge" delay="0.01" nsample="4"/>
    <pid name="pid" joint="hinge" kp="10" kv="2" input="pos vel ff" delay="0.01" nsample="3"/>
  </actuator>
  <sensor>
    <accelerometer name="accel" site="tip" delay="0.01" nsample="3"/>
    <jointpos joint="hinge"/>
  </sensor>
</mujoco>
"""

# Size arguments: distinct small values, so that swapped extents do not match.
SIZES = {"n": 3, "nr": 2, "nc": 4, "r1": 2, "c1": 3, "c2": 4, "r2": 5, "nvec": 2,
         "ntotal": 4, "nband": 2, "ndense": 1, "dim": 2, "nray": 2, "nface": 1, "nvert": 3,
         "nnz": 8}

# Scalar arguments by name; others get 0 (int) or 0.5 (float).
SCALARS = {"body": 1, "objtype": 1, "objid": 1, "bodyexclude": -1, "cutoff": 10.0,
           "time": 0.02, "phase": 0.0, "sig": 4356, "srcsig": 4356, "dstsig": 4356,
           "eps": 1e-6, "scl": 1.0, "mindiag": 1e-9, "flg_static": 1, "diagadd": 0.0,
           "diagmul": 0.0, "base": 2, "index": 1, "flg_centered": 0, "nstep": 1}

# Functions left out, and why.
SKIP = {
    "mj_addBufferVFS": "a byte buffer, not an array",
    "mj_saveModel": "a byte buffer, not an array",
    "mju_strncpy": "a byte buffer, not an array",
    "mju_writeResource": "needs a resource handle",
    "mju_printMat": "prints",
    "mju_printMatSparse": "prints",
    "mju_sparse2dense": "needs a consistent sparse structure",
    "mju_sym2dense": "needs a consistent sparse structure",
    "mj_addM": "only the dense form, with None for the structure",
    "mju_boxQP": "needs a consistent problem; covered by its own tests",
    "mjp_getPlugin": "needs a plugin",
    "mj_rayHfield": "needs a height field",
    "mj_rayMesh": "needs a mesh",
    "mju_threadpool": "makes threads",
    "mju_standardNormal": "the official bindings take num2 as a float, not an output array",
}


def _model_env(module):
    m = module.MjModel.from_xml_string(XML)
    d = module.MjData(m)
    module.mj_forward(m, d)
    return {"m": m, "d": d, "module": module}


class _Flat:
    """A model or data whose array attributes read flat, as the C layout (SHAPES) sees them."""

    def __init__(self, obj):
        self._obj = obj

    def __getattr__(self, name):
        value = getattr(self._obj, name)
        return np.ravel(value) if isinstance(value, np.ndarray) else value


def _extents(func, arg, env):
    """The extents of one array argument in a valid call, or None (not an array)."""
    spec = table.SHAPES.get(func, {}).get(arg.name)
    if spec is None:
        return tuple(arg.extents) if arg.extents else None
    if spec == "*":
        return None
    if arg.name in table.SIZED.get(func, ()):           # flat, as the official bindings take
        spec = " * ".join(f"({d})" for d in table._split_dims(spec))
    names = dict(SCALARS, **SIZES, m=_Flat(env["m"]), d=_Flat(env["d"]), mjNREF=2, mjNIMP=5, mjNGROUP=6,
                 state_size=lambda m, sig, name=None: env["module"].mj_stateSize(m, sig),
                 band_size=lambda t, b, d: (t - d) * b + d * t, id=0)
    return tuple(int(eval(dim, {}, names)) for dim in table._split_dims(spec))


_DTYPES = {"mjtNum": np.float64, "double": np.float64, "float": np.float32, "int": np.int32,
           "mjtByte": np.uint8, "unsigned char": np.uint8, "mjtSize": np.int64,
           "mjtBool": np.bool_}


def _array(name, extents, elem):
    """A valid, well-conditioned array: increasing times, an identity-like matrix, or ones."""
    if name == "times":
        return np.arange(extents[0]) * 0.01
    out = np.ones(extents, _DTYPES[elem])
    if len(extents) == 2 and extents[0] == extents[1] and elem in ("mjtNum", "double"):
        out[:] = np.eye(extents[0]) * 2.0
    return out


def valid_call(func, env):
    """{python name: value} for a call that both bindings accept, or None."""
    if func in SKIP or func in table.UNSUPPORTED or func in table.OVERRIDES \
            or not array_args(func):
        return None
    info = FUNCTIONS[func]
    by_name = {a.name: a for a in info.args}
    kwargs = {}
    for py in inspect.signature(_ours(func)).parameters:
        arg = by_name.get(py) or by_name.get(py.rstrip("_"))
        if arg is None:
            return None
        if arg.elem == "mjModel":
            kwargs[py] = env["m"]
        elif arg.elem == "mjData":
            kwargs[py] = env["d"]
        elif arg.pointer == 0 and not arg.extents:
            if arg.name in SIZES:
                kwargs[py] = SIZES[arg.name]
            elif arg.name in SCALARS:
                kwargs[py] = SCALARS[arg.name]
            elif arg.elem in ("mjtNum", "double", "float"):
                kwargs[py] = 0.5
            else:
                kwargs[py] = 0
        else:
            extents = _extents(func, arg, env)
            if extents is None or arg.elem not in _DTYPES:
                return None
            kwargs[py] = _array(arg.name, extents, arg.elem)
    return kwargs


def _ours(func):
    from mjcffi import functions
    return getattr(functions, func)


def array_args(func):
    """(python name, Arg) of each numeric array argument of `func`."""
    info = FUNCTIONS[func]
    out = []
    for a in info.args:
        if (a.pointer or a.extents) and a.elem in _DTYPES:
            out.append((a.name, a))
    return out


def variations(value, arg):
    """(label, value) pairs, each a variation of one array argument's valid value."""
    dtype = value.dtype
    flat = value.ravel()
    out = [("one more element", np.ones(value.size + 1, dtype)),
           ("flat", flat.copy()),
           ("(k, 1)", flat.reshape(-1, 1).copy()),
           ("(1, k)", flat.reshape(1, -1).copy()),
           ("3-D", flat.reshape(1, -1, 1).copy()),
           ("None", None),
           ("a scalar", 1.0)]
    if value.size:
        out.append(("one element fewer", np.ones(value.size - 1, dtype)))
    if value.ndim == 2 and value.shape[0] != value.shape[1]:
        out.append(("transposed", value.T.copy()))
    wrong = np.int32 if dtype != np.int32 else np.float64
    out.append(("wrong dtype", np.ones(value.shape, wrong)))
    if arg.const:
        out.append(("list", value.tolist()))
        out.append(("strided", np.repeat(value, 2, axis=-1)[..., ::2] if value.ndim else value))
        out.append(("not numbers", np.full(value.shape, "x")))
    else:
        readonly = value.copy()
        readonly.flags.writeable = False
        out.append(("read-only", readonly))
        out.append(("list", value.tolist()))
        if value.size > 1:
            out.append(("strided", np.repeat(value, 2, axis=-1)[..., ::2]))
        if value.ndim == 2 and min(value.shape) > 1:
            out.append(("Fortran order", np.asfortranarray(value)))
    return out


def outcome(call):
    """'ok', or (exception type, message) of what `call()` raised."""
    try:
        call()
    except Exception as exc:          # noqa: BLE001  (any exception is an outcome)
        return type(exc), str(exc)
    return "ok"


# ------------------------------------------------------------------ the tests

# Where mjcffi takes what the official bindings refuse, on purpose:
# (function, argument, variation) -> why.  No entry loosens a check on an output.
_NULLABLE = "the header says Nullable and MuJoCo takes NULL; the official bindings do not"
_INPUT = ("an input: the official bindings declare it writable, so they refuse lists and "
          "copies; MuJoCo only reads it")
LENIENT = {
    **{("mj_applyFT", arg, "None"): _NULLABLE for arg in ("force", "torque")},
    **{(func, arg, "None"): _NULLABLE for func, arg in (
        ("mju_transformSpatial", "rotnew2old"), ("mjd_quatIntegrate", "Dquat"),
        ("mjd_quatIntegrate", "Dvel"), ("mjd_quatIntegrate", "Dscale"),
        ("mj_multiRay", "geomid"))},
    **{("mj_multiRay", arg, "(1, k)"): "mjcffi takes the rays as (nray, 3), as its docs say, "
       "and so any layout of 3*nray elements" for arg in ("vec", "normal")},
    **{(func, arg, variation): _INPUT
       for func, arg in (("mju_sum", "vec"), ("mju_L1", "vec"), ("mju_norm", "res"),
                         ("mju_isZero", "vec"), ("mju_sqrMatTD", "diag"))
       for variation in ("list", "strided", "wrong dtype", "a scalar")},
}


def _same_type(ours, official):
    """mjcffi's exception stands for the official's: the same class or a subclass."""
    if official.__name__ == "FatalError":
        return ours is mjcffi.FatalError
    return issubclass(ours, official)


def _generic(message):
    return "incompatible function arguments" in message


@pytest.fixture(scope="module")
def envs(mujoco):
    return {"official": _model_env(mujoco), "mjcffi": _model_env(mjcffi)}


# Functions whose valid call the official bindings refuse, so nothing can be
# compared: mju_bandMulMatVec checks res against the wrong extent, and the test
# model has actuator delays, which mjd_transitionFD does not support.
OFFICIAL_REFUSES = {"mju_bandMulMatVec": "res should have ntotal rows",
                    "mjd_transitionFD": "mjd_transitionFD: delays are not supported"}


def _cases():
    env = _model_env(mjcffi)
    return [f for f in FUNCTIONS if valid_call(f, env) is not None and f not in OFFICIAL_REFUSES]


_CASES = _cases()


def test_cases_cover_the_array_functions():
    assert len(_CASES) > 120


@pytest.mark.parametrize("func, message", OFFICIAL_REFUSES.items())
def test_the_official_bindings_still_refuse_the_uncompared_calls(func, message, envs, mujoco):
    """If the official bindings start taking these calls, compare them above."""
    result = outcome(lambda: getattr(mujoco, func)(**valid_call(func, envs["official"])))
    assert result != "ok" and result[1] == message


@pytest.mark.parametrize("func", _CASES)
def test_arguments_are_taken_and_refused_as_the_official_bindings(func, envs, mujoco):
    calls = {side: valid_call(func, env) for side, env in envs.items()}
    official, ours = getattr(mujoco, func), getattr(F, func)
    assert outcome(lambda: official(**calls["official"])) == "ok"
    assert outcome(lambda: ours(**calls["mjcffi"])) == "ok"
    wrong = []
    for py, arg in array_args(func):
        if py not in calls["official"]:
            continue
        theirs_values = variations(valid_call(func, envs["official"])[py], arg)
        our_values = variations(valid_call(func, envs["mjcffi"])[py], arg)
        for (label, theirs_value), (_, our_value) in zip(theirs_values, our_values):
            if label == "None" and not arg.nullable:
                continue                     # some official functions crash on it
            if (func, arg.name, label) in LENIENT:
                continue
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                expected = outcome(lambda: official(**{**calls["official"], py: theirs_value}))
                got = outcome(lambda: ours(**{**calls["mjcffi"], py: our_value}))
            if expected == "ok" or got == "ok":
                same = expected == got
            else:
                same = _same_type(got[0], expected[0]) and (
                    _generic(expected[1]) or got[1] == expected[1])
            if not same:
                wrong.append(f"{py} {label}: official {expected}, mjcffi {got}")
    assert not wrong, "\n".join(wrong)


def test_lenient_entries_name_real_arguments():
    for func, arg, _ in LENIENT:
        assert arg in {a.name for a in FUNCTIONS[func].args}, (func, arg)


# ------------------------------------------------------- the exception classes

def test_argument_errors_are_type_and_value_errors():
    res = np.zeros(4)
    with pytest.raises(TypeError) as caught:
        F.mju_rotVecQuat(res, [1, 0, 0], [1, 0, 0, 0])
    assert isinstance(caught.value, ValueError)            # what mjcffi raised before
    assert "res" in str(caught.value)
    with pytest.raises(ValueError):
        F.mju_add(np.zeros(3), np.zeros(3), np.zeros(4))


def test_official_message_with_the_shape_in_a_note():
    m = mjcffi.MjModel.from_xml_string(XML)
    d = mjcffi.MjData(m)
    with pytest.raises(TypeError) as caught:
        F.mj_jac(m, d, np.zeros((m.nv, 3)), None, np.zeros(3), 1)
    assert str(caught.value) == "jacp should be of shape (3, nv)"
    assert caught.value.__notes__ == [f"jacp must have shape (3, {m.nv}), got ({m.nv}, 3)"]
    state = np.zeros(F.mj_stateSize(m, 1) + 1)
    with pytest.raises(TypeError) as caught:
        F.mj_getState(m, d, state, 1)
    assert str(caught.value) == "state size should equal mj_stateSize(m, sig)"


def test_ids_out_of_range_are_index_and_value_errors():
    m = mjcffi.MjModel.from_xml_string(XML)
    d = mjcffi.MjData(m)
    with pytest.raises(IndexError) as caught:
        F.mj_readCtrl(m, d, m.nu, 0.0, np.zeros(1), 0)
    assert str(caught.value) == "actuator id out of range"
    with pytest.raises(ValueError, match="body"):         # MuJoCo does not check it
        F.mj_jac(m, d, np.zeros((3, m.nv)), None, np.zeros(3), m.nbody)
    assert issubclass(_marshal.IdError, IndexError)


def test_outputs_are_never_silent_copies():
    """Kept stricter than nothing: a read-only, strided or wrong-dtype output raises."""
    readonly = np.zeros(3)
    readonly.flags.writeable = False
    for res in (readonly, np.zeros(6)[::2], np.zeros(3, np.float32), [0.0, 0.0, 0.0]):
        with pytest.raises(TypeError, match="res"):
            F.mju_rotVecQuat(res, [1, 0, 0], [1, 0, 0, 0])


def test_layouts_follow_the_official_bindings():
    res = np.zeros((3, 1))
    F.mju_rotVecQuat(res, [[1], [0], [0]], [1, 0, 0, 0])    # (n, 1) vectors
    assert res.ravel().tolist() == [1, 0, 0]
    for bad in (np.zeros((1, 3)), np.zeros((3, 1, 1))):
        with pytest.raises(TypeError):
            F.mju_rotVecQuat(bad, [1, 0, 0], [1, 0, 0, 0])
    out = np.zeros(6)                                      # (r,) for an (r, 1) matrix
    F.mju_mulMatVec(out, np.ones(6), np.ones(1))
    assert out.tolist() == [1.0] * 6
    face = np.array([[0, 1, 2]], np.int32)                # by size: any 1-D or 2-D shape
    vert = np.array([0, 0, 0, 1, 0, 0, 0, 1, 0], np.float32)
    assert F.mju_raySkin(1, 3, face.ravel(), vert.reshape(3, 3), [0.2, 0.2, 2.0],
                         [0, 0, -1], None) == pytest.approx(2.0)


# ---------------------------------------------------------------- behaviour

def test_read_functions_write_into_result(mujoco):
    for module in (mjcffi, mujoco):
        m = module.MjModel.from_xml_string(XML)
        d = module.MjData(m)
        module.mj_initCtrlHistory(m, d, 0, np.arange(4) * 0.01, np.arange(1.0, 5.0))
        result = np.zeros(1)
        out = module.mj_readCtrl(m, d, 0, 0.02, result, 0)   # an exact match: a pointer
        assert result[0] == 2.0 and np.shares_memory(out, result)
        module.mj_readCtrl(m, d, 0, 0.025, result, 1)       # interpolated: NULL
        assert result[0] == 2.5


def test_xml_dependencies(mujoco):
    path = os.path.join(os.path.dirname(mujoco.__file__), "testdata", "msh.xml")
    found = F.mju_getXMLDependencies(path)
    assert sorted(found) == sorted(mujoco.mju_getXMLDependencies(path))
    assert path in found and len(found) == 2
    with pytest.raises(mjcffi.FatalError, match="missing.xml"):
        F.mju_getXMLDependencies("/nonexistent/missing.xml")
    with pytest.raises(TypeError):
        F.mju_getXMLDependencies(None)          # the official bindings crash here


# --------------------------------------------------------------- docstrings

def test_docstrings_have_the_official_shape(mujoco):
    for name in ("mj_versionString", "mj_Euler", "mj_forward", "mj_name2id", "mj_stateSize",
                 "mju_getXMLDependencies"):
        ours, theirs = getattr(F, name).__doc__, getattr(mujoco, name).__doc__
        first, header = theirs.split("\n")[0], FUNCTIONS[name].doc
        assert ours.split("(")[0] == first.split("(")[0], name
        assert ours.split("\n\n")[1].rstrip("\n") == header, name
        assert ours.endswith("\n"), name
    assert F.mj_Euler.__doc__ == mujoco.mj_Euler.__doc__


def test_every_docstring_starts_with_its_signature_and_header_doc():
    for name, info in FUNCTIONS.items():
        doc = getattr(F, name).__doc__
        signature, _, rest = doc.partition("\n\n")
        assert signature.startswith(name + "(") and " -> " in signature, name
        params = [p for p in inspect.signature(getattr(F, name)).parameters]
        assert [p.split(":")[0].strip() for p in signature[len(name) + 1:].split(" -> ")[0]
                .rstrip(")").split(", ") if p] == params or name in table.OVERRIDES, name
        assert rest.startswith(info.doc), name
