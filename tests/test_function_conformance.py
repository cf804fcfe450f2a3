"""The function layer against the official bindings, argument by argument.

Every MuJoCo function that takes numeric arrays gets a valid call
(tests/_calls.py), built from codegen's tables (SHAPES gives each array's
extents) with small sizes that differ per size argument, so that a transposed
matrix is a wrong shape.  Each
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
from mjcffi._support import marshal as _marshal
from mjcffi import functions as F
from mjcffi._generated.funcinfo import FUNCTIONS

from ._calls import XML, array_args, model_env, valid_call

_model_env = model_env


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
        ("mj_multiRay", "geomid"), ("mjv_cameraFrame", "headpos"), ("mjv_cameraFrame", "up"),
        ("mjv_cameraFrame", "right"), ("mjv_cameraFrustum", "zver"),
        ("mjv_cameraFrustum", "zhor"), ("mjv_cameraFrustum", "zclip"),
        ("mjv_initGeom", "size"), ("mjv_initGeom", "pos"), ("mjv_initGeom", "mat"),
        ("mjv_initGeom", "rgba"))},
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
