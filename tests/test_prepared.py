"""Prepared calls (issue 25): `F.prepare(args)` checks and converts once; `p()` calls.

A prepared call must make the very C call the plain call makes, with the same
outputs bit for bit, the same FatalError, callback errors and mjData claim; keep
what it holds alive; read its input arrays live; refuse at prepare time what the
plain call refuses, and also inputs it would copy; and check again at every call
what can change between calls.  mj_name2id's memo is tested here too.
"""

import gc
import inspect
import pickle
import threading

import numpy as np
import pytest

import mjcffi
from mjcffi._support import prepared as _prepared
from mjcffi import functions as F
from codegen import functions as table

from . import _calls
from .conftest import gymnasium_assets
from .test_fast_path import _fresh, _run
from .test_fatal_error import boxes_xml, pile_up

SCENE = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 .1"/>
    <body name="ball" pos="0 0 .099">
      <freejoint/>
      <geom name="ball" size=".1"/>
      <body name="arm" pos="0 0 .3">
        <joint name="hinge" type="hinge"/>
        <geom type="capsule" size=".05" fromto="0 0 0 0 0 .2"/>
        <site name="tip" pos="0 0 .2"/>
      </body>
    </body>
  </worldbody>
  <actuator><motor name="motor" joint="hinge"/></actuator>
</mujoco>
"""


@pytest.fixture()
def scene():
    m = mjcffi.MjModel.from_xml_string(SCENE)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    return m, d


# ---------------------------------------------------------------- every function

def test_every_function_has_prepare_with_its_signature():
    assert len(F.NAMES) > 500
    for name in F.NAMES:
        function = getattr(mjcffi, name)
        preparer = function.prepare
        assert isinstance(preparer, _prepared.Preparer), name
        assert preparer.function is function, name
        assert inspect.signature(preparer) == inspect.signature(function), name


def _prepared_run(name):
    def call(**kwargs):
        return getattr(F, name).prepare(**kwargs)()
    return call


def test_prepared_calls_give_the_plain_calls_bits():
    """Every generated function with a valid call: plain and prepared, on equal fresh
    copies of the arguments, end in the same outputs, bit for bit (or the same error)."""
    # two pools of the same structs, one per side: calls that change a struct they are
    # given (a VFS, a spec) change each side's alike.  They share one model and data
    # (each call gets a copy of the data): two mjData made apart differ in the arrays no
    # call wrote yet, which hold whatever the memory held.
    pools = _calls.Pool(), _calls.Pool()
    for key in ("m", "d"):
        pools[1].env[key] = pools[0].env[key]
    pools[1].instances.update(mjModel=pools[0].env["m"], mjData=pools[0].env["d"])
    compared, varying = 0, []
    for name in sorted(F.NAMES):
        if not _calls.generated(name) or name in ("mju_standardNormal", "mju_writeLog",
                                                  "mj_printData", "mj_printFormattedData",
                                                  "mju_printMat"):
            continue
        calls = [_calls.full_call(name, pool) for pool in pools]
        if calls[0] is None:
            continue
        plain = _comparable(_run(getattr(F, name), _fresh(calls[0])))
        prepared = _comparable(_run(_prepared_run(name), _fresh(calls[1])))
        again = _comparable(_run(getattr(F, name), _fresh(calls[0])))
        if again != plain:               # MuJoCo read memory no call wrote: kinds only
            varying.append(name)
            plain, prepared = plain[:1], prepared[:1]
        assert prepared == plain, name
        compared += plain[0] == "ok"
    assert compared > 250, compared
    assert len(varying) <= 5, varying


def _comparable(outcome):
    """An outcome with raw addresses left out: each pool's memory lies elsewhere."""
    if outcome[0] == "ok" and outcome[1][0] == "pointer":
        return [outcome[0], ["pointer"], *outcome[2:]]
    return outcome


def test_a_prepared_call_can_be_called_again_and_again(scene):
    m, d = scene
    p = mjcffi.mj_step.prepare(m, d)
    q = mjcffi.MjData(m)
    mjcffi.mj_forward(m, q)
    for _ in range(50):
        p()
        mjcffi.mj_step(m, q)
    assert d.time == q.time > 0
    assert d.qpos.tobytes() == q.qpos.tobytes() and d.qvel.tobytes() == q.qvel.tobytes()


# ---------------------------------------------------------------- what it holds

def test_input_arrays_are_read_live(scene):
    m, d = scene
    jacp, point = np.zeros((3, m.nv)), np.zeros(3)
    p = mjcffi.mj_jac.prepare(m, d, jacp, None, point, 2)
    for value in ([0.0, 0.0, 0.0], [0.1, -0.2, 0.5], [1.0, 2.0, 3.0]):
        point[:] = value
        p()
        expected = np.zeros((3, m.nv))
        mjcffi.mj_jac(m, d, expected, None, np.array(value), 2)
        assert jacp.tobytes() == expected.tobytes()


def test_it_keeps_its_model_data_and_arrays_alive():
    def make():
        m = mjcffi.MjModel.from_xml_string(SCENE)
        d = mjcffi.MjData(m)
        mjcffi.mj_forward(m, d)
        return mjcffi.mj_jac.prepare(m, d, np.zeros((3, m.nv)), np.zeros((3, m.nv)),
                                     np.array([0.0, 0.1, 0.2]), 2)
    p = make()
    gc.collect()
    for _ in range(3):
        p()
    m, d = p.arguments["m"], p.arguments["d"]
    expected = np.zeros((3, m.nv))
    mjcffi.mj_jac(m, d, expected, None, np.array([0.0, 0.1, 0.2]), 2)
    assert p.arguments["jacp"].tobytes() == expected.tobytes()
    assert np.any(expected)


def test_repr_names_the_function_and_its_arguments(scene):
    m, d = scene
    p = mjcffi.mj_jac.prepare(m, d, np.zeros((3, m.nv)), None, np.zeros(3), 1)
    text = repr(p)
    assert text.startswith("<function mj_jac.prepare(m=<MjModel>, d=<MjData>,")
    assert f"jacp=<ndarray float64 (3, {m.nv})>" in text and "jacr=None" in text
    assert "body=1)" in text and "rechecked" not in text
    assert "(rechecked)" in repr(mjcffi.mjv_applyPerturbForce.prepare(m, d, mjcffi.MjvPerturb()))
    assert repr(mjcffi.mj_jac.prepare) == "<prepare of mjcffi._functions.mj_jac>"


def test_a_prepared_call_cannot_be_pickled(scene):
    m, d = scene
    with pytest.raises((pickle.PicklingError, AttributeError, TypeError)):
        pickle.dumps(mjcffi.mj_kinematics.prepare(m, d))


# ---------------------------------------------------------------- what it refuses

@pytest.mark.parametrize("point", [[0.0, 0.0, 0.0], np.zeros(3, np.float32),
                                   np.zeros(6)[::2], (0, 0, 0)])
def test_inputs_it_would_copy_are_refused(scene, point):
    m, d = scene
    mjcffi.mj_jac(m, d, np.zeros((3, m.nv)), None, point, 1)        # the plain call takes it
    with pytest.raises(mjcffi.ArgumentError, match="point must be a C-contiguous NumPy array "
                                                   "of dtype float64 to be prepared"):
        mjcffi.mj_jac.prepare(m, d, np.zeros((3, m.nv)), None, point, 1)


class _Sub(np.ndarray):
    pass


def test_a_contiguous_subclass_is_read_in_place_and_taken(scene):
    m, d = scene
    point, jacp = np.zeros(3).view(_Sub), np.zeros((3, m.nv))
    p = mjcffi.mj_jac.prepare(m, d, jacp, None, point, 2)
    point[:] = [0.1, 0.2, 0.3]
    p()
    expected = np.zeros((3, m.nv))
    mjcffi.mj_jac(m, d, expected, None, np.array([0.1, 0.2, 0.3]), 2)
    assert jacp.tobytes() == expected.tobytes()


def test_what_the_plain_call_refuses_prepare_refuses_alike(scene):
    m, d = scene
    cases = [
        ((m, d, np.zeros((m.nv, 3)), None, np.zeros(3), 1), mjcffi.ArgumentError),
        ((m, d, np.zeros((3, m.nv)), None, np.zeros(3), m.nbody), mjcffi.IdError),
        ((m, d, np.zeros((3, m.nv), np.float32), None, np.zeros(3), 1), mjcffi.ArgumentError),
        ((m, "d", np.zeros((3, m.nv)), None, np.zeros(3), 1), TypeError),
    ]
    for args, error in cases:
        with pytest.raises(error) as plain:
            mjcffi.mj_jac(*args)
        with pytest.raises(error) as prepared:
            mjcffi.mj_jac.prepare(*args)
        assert str(prepared.value) == str(plain.value)
    with pytest.raises(TypeError, match="mj_jac.prepare"):
        mjcffi.mj_jac.prepare(m, d)                        # too few arguments


def test_a_bad_scalar_is_refused_when_prepared(scene):
    m, d = scene
    with pytest.raises(TypeError, match="flg_local") as prepared:
        mjcffi.mj_objectVelocity.prepare(m, d, 1, 1, np.zeros(6), "local")
    with pytest.raises(TypeError) as plain:
        mjcffi.mj_objectVelocity(m, d, 1, 1, np.zeros(6), "local")
    assert str(prepared.value) == str(plain.value)
    with pytest.raises(ValueError, match="nstep"):
        mjcffi.mj_step.prepare(m, d, 2 ** 40)


def test_unsupported_functions_refuse_to_be_prepared(scene):
    m, _ = scene
    with pytest.raises(NotImplementedError, match="mj_deleteModel"):
        mjcffi.mj_deleteModel.prepare(m)


# ------------------------------------------------------------- checked again

def test_sizes_that_change_between_calls_are_checked_at_every_call(scene):
    m, d = scene
    assert d.nefc > 0
    res = np.zeros(d.nefc)
    p = mjcffi.mj_mulJacVec.prepare(m, d, res, np.ones(m.nv))
    assert p.rechecks
    p()
    d.qpos[2] = 3.0                  # lift the ball: no contact, no constraint rows
    mjcffi.mj_forward(m, d)
    assert d.nefc == 0
    with pytest.raises(mjcffi.ArgumentError, match="nefc"):
        p()                          # res no longer fits: refused, not written past


def test_ids_a_struct_holds_are_checked_at_every_call(scene):
    m, d = scene
    pert = mjcffi.MjvPerturb()
    pert.select = 1
    p = mjcffi.mjv_applyPerturbForce.prepare(m, d, pert)
    assert p.rechecks
    p()
    pert.select = m.nbody            # now out of range: MuJoCo would follow it unchecked
    with pytest.raises(mjcffi.IdError, match="select"):
        p()


# --------------------------------------------------- errors, callbacks, claims

def test_fatal_errors_are_raised_as_by_the_plain_call():
    with pytest.raises(mjcffi.FatalError, match="^boom$"):
        mjcffi.mju_error.prepare("boom")()
    m = mjcffi.MjModel.from_xml_string(boxes_xml())
    d = mjcffi.MjData(m)
    pile_up(d)
    p = mjcffi.mj_step.prepare(m, d)
    with pytest.raises(mjcffi.FatalError, match="mj_stackAlloc: out of memory") as prepared:
        p()
    mjcffi.mj_resetData(m, d)
    pile_up(d)
    with pytest.raises(mjcffi.FatalError) as plain:
        mjcffi.mj_step(m, d)
    assert str(prepared.value) == str(plain.value)


def test_a_callback_error_is_raised_after_the_prepared_call(scene):
    m, d = scene
    p = mjcffi.mj_step.prepare(m, d)

    def control(model, data):
        raise ValueError("from the controller")
    mjcffi.set_mjcb_control(control)
    try:
        with pytest.raises(ValueError, match="from the controller"):
            p()
        with pytest.raises(ValueError, match="from the controller"):
            mjcffi.mj_forward.prepare(m, d)()
    finally:
        mjcffi.set_mjcb_control(None)
    p()                              # nothing left pending


def test_the_mjdata_claim_holds_for_prepared_calls(scene):
    m, d = scene
    p = mjcffi.mj_step.prepare(m, d)
    seen = []

    def control(model, data):
        try:
            p()                      # re-enters the step computing this very data
        except RecursionError as error:
            seen.append(error)
    mjcffi.set_mjcb_control(control)
    try:
        mjcffi.mj_step(m, d)
    finally:
        mjcffi.set_mjcb_control(None)
    assert seen and "this mjData is in a MuJoCo call on this thread already" in str(seen[0])

    started, release, errors = threading.Event(), threading.Event(), []

    def hold(model, data):
        started.set()
        release.wait(10)
    mjcffi.set_mjcb_control(hold)
    try:
        worker = threading.Thread(target=lambda: mjcffi.mj_step(m, d))
        worker.start()
        assert started.wait(10)
        try:
            mjcffi.mj_kinematics.prepare(m, d)()
        except ValueError as error:
            errors.append(error)
        release.set()
        worker.join(10)
    finally:
        mjcffi.set_mjcb_control(None)
    assert errors and "another thread" in str(errors[0])


def test_warnings_as_errors_are_read_at_every_call(scene):
    m, d = scene
    p = mjcffi.mj_step.prepare(m, d)
    d.qpos[0] = np.nan
    mjcffi.set_warnings_as_errors(True)
    try:
        with pytest.raises(mjcffi.MjWarningError, match="BADQPOS"):
            p()
    finally:
        mjcffi.set_warnings_as_errors(False)
    d.qpos[0] = np.nan
    p()                              # counted, not raised


# ---------------------------------------------------------------- hand-written

def test_hand_written_functions_bind_their_arguments(tmp_path):
    path = tmp_path / "scene.xml"
    path.write_text(SCENE)
    load = mjcffi.mj_loadXML.prepare(str(path))
    assert load.rechecks
    first, second = load(), load()
    assert isinstance(first, mjcffi.MjModel) and first is not second and first.nv == second.nv
    spec = mjcffi.mj_makeSpec.prepare()()
    assert isinstance(spec, mjcffi.MjSpec)
    with pytest.raises(TypeError, match="mj_loadXML.prepare"):
        mjcffi.mj_loadXML.prepare()


# ---------------------------------------------------------------- mj_name2id

def _names_by_type(m):
    """(mjtObj, name) of every named element, for each type with a count."""
    from mjcffi._support.marshal import COUNT_OF
    found = []
    for objtype, field in COUNT_OF.items():
        for i in range(getattr(m._ptr, field)):
            name = mjcffi.mj_id2name(m, objtype, i)
            if name:
                found.append((objtype, name))
    return found


@pytest.mark.parametrize("path", gymnasium_assets()[:6], ids=lambda p: p.stem)
def test_name2id_answers_as_mujoco_does(path, mujoco):
    m = mjcffi.MjModel.from_xml_path(str(path))
    om = mujoco.MjModel.from_xml_path(str(path))
    questions = _names_by_type(m)
    assert questions
    questions += [(t, "no such name") for t in (1, 3, 5)] + [(1, ""), (0, "world")]
    for _ in range(2):               # asked, then answered from the memo
        for objtype, name in questions:
            expected = mjcffi.lib.mj_name2id(m._ptr, objtype, name.encode())
            assert mjcffi.mj_name2id(m, objtype, name) == expected == \
                mujoco.mj_name2id(om, objtype, name), (objtype, name)
            assert mjcffi.mj_name2id(m, mjcffi.mjtObj(objtype), name) == expected
            assert mjcffi.mj_name2id(m, objtype, name.encode()) == expected
    assert len(m._name2id) == len(set(questions))


def test_name2id_refuses_what_it_refused_and_forgets_a_copied_over_model():
    a = mjcffi.MjModel.from_xml_string("<mujoco><worldbody><body name='x'/><body name='y'/>"
                                       "</worldbody></mujoco>")
    b = mjcffi.MjModel.from_xml_string("<mujoco><worldbody><body name='y'/><body name='x'/>"
                                       "</worldbody></mujoco>")
    assert mjcffi.mj_name2id(a, 1, "x") == 1
    with pytest.raises(TypeError, match="type"):
        mjcffi.mj_name2id(a, 1.0, "x")         # a float equal to a memo key: still refused
    with pytest.raises(ValueError, match="NUL"):
        mjcffi.mj_name2id(a, 1, "x\0y")
    assert mjcffi.mj_name2id(a, True, "x") == 1
    mjcffi.mj_copyModel(a, b)                  # same sizes, the names swapped
    assert mjcffi.mj_name2id(a, 1, "x") == 2 == mjcffi.lib.mj_name2id(a._ptr, 1, b"x")
    assert a.body("x").id == 2                 # named access forgot too
    p = mjcffi.mj_name2id.prepare(a, 1, "y")
    assert p() == 1
