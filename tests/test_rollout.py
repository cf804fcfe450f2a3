"""mjcffi.rollout: the official mujoco.rollout's interface and results, bit for bit.

Both bindings run on the same libmujoco in this process, so every state and
sensor value of a rollout must equal the official one exactly.
"""

import copy
import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import mjcffi
from mjcffi._support import callbacks
from mjcffi import rollout, scenes

from .conftest import gymnasium_assets

FULLPHYSICS = int(mjcffi.mjtState.mjSTATE_FULLPHYSICS)

# actuators with activation, a sensor, a mocap body and an equality constraint
SCENE = """
<mujoco>
  <worldbody>
    <geom type="plane" size="5 5 .1"/>
    <body name="arm" pos="0 0 .1">
      <joint name="yaw" axis="0 0 1"/>
      <joint name="pitch" axis="0 1 0"/>
      <geom type="capsule" size=".02" fromto="0 0 0 1 0 0"/>
      <geom type="box" pos="1 0 0" size=".1 .1 .1"/>
      <site name="tip" pos="1 0 0"/>
    </body>
    <body name="target" mocap="true" pos="0 1 1">
      <geom size=".05" contype="0" conaffinity="0"/>
    </body>
    <body name="ball" pos="0 2 1">
      <freejoint/>
      <geom size=".1"/>
    </body>
  </worldbody>
  <equality><weld body1="ball" body2="target" active="false"/></equality>
  <actuator>
    <general joint="pitch" gainprm="100"/>
    <general joint="yaw" dyntype="filter" dynprm="1" gainprm="100"/>
  </actuator>
  <sensor>
    <accelerometer site="tip"/>
    <framepos objtype="body" objname="ball"/>
  </sensor>
</mujoco>
"""

PENDULUM = scenes.PENDULUM       # one hinge, one motor, one sensor

GYMNASIUM = ["ant.xml", "half_cheetah.xml", "hopper.xml", "humanoid.xml", "pusher.xml",
             "walker2d.xml"]


def _asset(name):
    """The path of one gymnasium model."""
    return next(p for p in gymnasium_assets() if p.name == name)


class Pair:
    """The same model in both bindings, with helpers to make inputs for it."""

    def __init__(self, mujoco, xml=None, path=None):
        self.mujoco = mujoco
        if path is not None:
            self.om = mujoco.MjModel.from_xml_path(str(path))
            self.cm = mjcffi.MjModel.from_xml_path(str(path))
        else:
            self.om = mujoco.MjModel.from_xml_string(xml)
            self.cm = mjcffi.MjModel.from_xml_string(xml)
        self.nstate = mjcffi.mj_stateSize(self.cm, FULLPHYSICS)

    def datas(self, n):
        """(official, ours): n MjData each."""
        return ([self.mujoco.MjData(self.om) for _ in range(n)],
                [mjcffi.MjData(self.cm) for _ in range(n)])

    def rest(self, nbatch):
        """nbatch copies of the model's initial state."""
        d = mjcffi.MjData(self.cm)
        state = np.empty(self.nstate)
        mjcffi.mj_getState(self.cm, d, state, FULLPHYSICS)
        return np.tile(state, (nbatch, 1))

    def initial_states(self, nbatch, seed=0):
        """nbatch states: the model's initial state with qpos and qvel perturbed."""
        states = self.rest(nbatch)
        rng = np.random.default_rng(seed)
        nq, nv = self.cm.nq, self.cm.nv
        states[:, 1:1 + nq] += rng.normal(0, 0.01, (nbatch, nq))
        states[:, 1 + nq:1 + nq + nv] += rng.normal(0, 0.1, (nbatch, nv))
        return states

    def controls(self, nbatch, nstep, seed=0, width=None):
        """Random controls in [-1, 1], (nbatch, nstep, width or nu)."""
        rng = np.random.default_rng(seed + 1)
        return rng.uniform(-1, 1, (nbatch, nstep, self.cm.nu if width is None else width))

    def both(self, *args, nthread=1, **kwargs):
        """(official, ours) results of rollout.rollout on fresh data, `nthread` of them."""
        odata, cdata = self.datas(nthread)
        theirs = self.mujoco.rollout.rollout(self.om, odata, *args, **kwargs)
        ours = rollout.rollout(self.cm, cdata, *args, **kwargs)
        return theirs, ours


def assert_same(theirs, ours):
    """(state, sensordata) pairs equal to the last bit, in shape and dtype too."""
    for a, b in zip(theirs, ours):
        assert a.shape == b.shape and a.dtype == b.dtype
        np.testing.assert_array_equal(b, a, strict=True)


@pytest.fixture(scope="module")
def official_rollout(mujoco):
    """The official mujoco.rollout (a submodule that `import mujoco` does not load)."""
    from mujoco import rollout as official
    return official


@pytest.fixture
def scene(mujoco, official_rollout):
    """SCENE in both bindings."""
    return Pair(mujoco, SCENE)


# ------------------------------------------------------------- bit-identical

@pytest.mark.parametrize("name", GYMNASIUM)
@pytest.mark.parametrize("nthread", [1, 2])
def test_gymnasium_models_are_bit_identical(mujoco, official_rollout, name, nthread):
    pair = Pair(mujoco, path=_asset(name))
    nbatch, nstep = 5, 40
    theirs, ours = pair.both(pair.initial_states(nbatch), pair.controls(nbatch, nstep),
                             nthread=nthread)
    assert ours[0].shape == (nbatch, nstep, pair.nstate)
    assert_same(theirs, ours)


@pytest.mark.parametrize("nthread", [1, 2, 3])
def test_scene_with_sensors_activation_mocap_equality(scene, nthread):
    nbatch, nstep = 7, 30
    theirs, ours = scene.both(scene.initial_states(nbatch), scene.controls(nbatch, nstep),
                              nthread=nthread)
    assert ours[1].shape == (nbatch, nstep, scene.cm.nsensordata) and ours[1].any()
    assert_same(theirs, ours)


@pytest.mark.parametrize("nthread", [1, 2])
def test_a_list_of_models_with_other_parameters(mujoco, official_rollout, nthread):
    path = _asset("hopper.xml")
    nbatch, nstep = 4, 30
    omodels = [mujoco.MjModel.from_xml_path(str(path)) for _ in range(nbatch)]
    cmodels = [mjcffi.MjModel.from_xml_path(str(path)) for _ in range(nbatch)]
    for i, (om, cm) in enumerate(zip(omodels, cmodels)):
        om.opt.gravity[2] = cm.opt.gravity[2] = -9.81 * (1 + 0.2 * i)
        om.body_mass[2] = cm.body_mass[2] = cm.body_mass[2] * (1 + 0.3 * i)
    pair = Pair(mujoco, path=path)
    initial, control = pair.initial_states(1), pair.controls(nbatch, nstep)
    odata, cdata = pair.datas(nthread)
    theirs = official_rollout.rollout(omodels, odata, initial, control)
    ours = rollout.rollout(cmodels, cdata, initial, control)
    assert ours[0].shape[0] == nbatch
    assert_same(theirs, ours)
    # the models differ, so the rollouts do too
    assert not np.array_equal(ours[0][0], ours[0][1])


@pytest.mark.parametrize("chunk_size", [1, 2, 3, 11, 100])
def test_chunk_size_does_not_change_the_result(scene, chunk_size):
    nbatch, nstep = 11, 20
    args = (scene.initial_states(nbatch), scene.controls(nbatch, nstep))
    reference = rollout.rollout(scene.cm, mjcffi.MjData(scene.cm), *args)
    theirs, ours = scene.both(*args, nthread=2, chunk_size=chunk_size)
    assert_same(theirs, ours)
    assert_same(reference, ours)


def test_initial_warmstart(scene):
    nbatch, nstep = 3, 10
    warmstart = np.random.default_rng(3).normal(0, 1, (nbatch, scene.cm.nv))
    args = (scene.initial_states(nbatch), scene.controls(nbatch, nstep))
    theirs, ours = scene.both(*args, initial_warmstart=warmstart)
    assert_same(theirs, ours)
    theirs, ours = scene.both(*args, initial_warmstart=warmstart[:1], nthread=2)
    assert_same(theirs, ours)


# (initial state, control) from full (nbatch, nstate) and (nbatch, nstep, nu) arrays
BROADCASTS = {
    "one 1-d initial state": (lambda s: s[0], lambda c: c),
    "nbatch 1": (lambda s: s[:1], lambda c: c[:1]),
    "one control sequence for all": (lambda s: s, lambda c: c[:1]),
    "one control per rollout, held": (lambda s: s, lambda c: c[:, :1]),
    "one control for everything": (lambda s: s, lambda c: c[0, 0]),
    "one state, held controls": (lambda s: s[:1], lambda c: c[:, :1]),
}


@pytest.mark.parametrize("case", BROADCASTS)
@pytest.mark.parametrize("nthread", [1, 2])
def test_broadcasting_of_leading_dimensions(scene, case, nthread):
    nbatch, nstep = 5, 12
    pick_state, pick_control = BROADCASTS[case]
    initial = pick_state(scene.initial_states(nbatch))
    control = pick_control(scene.controls(nbatch, nstep))
    theirs, ours = scene.both(initial, control, nthread=nthread, nstep=nstep)
    assert ours[0].shape[1:] == (nstep, scene.nstate)
    assert_same(theirs, ours)


def test_scalar_float_control_and_warmstart(mujoco, official_rollout):
    pair = Pair(mujoco, PENDULUM)
    theirs, ours = pair.both(pair.initial_states(1), 0.5, initial_warmstart=0.25, nstep=4)
    assert ours[0].shape == (1, 4, pair.nstate)
    assert_same(theirs, ours)


def test_no_control_and_nstep(scene):
    theirs, ours = scene.both(scene.initial_states(3), nstep=15)
    assert ours[0].shape == (3, 15, scene.nstate)
    assert_same(theirs, ours)


@pytest.mark.parametrize("spec", ["mjSTATE_QFRC_APPLIED", "mjSTATE_CTRL|mjSTATE_XFRC_APPLIED",
                                  "mjSTATE_MOCAP_POS|mjSTATE_MOCAP_QUAT|mjSTATE_EQ_ACTIVE"])
def test_control_spec(scene, spec):
    control_spec = 0
    for bit in spec.split("|"):
        control_spec |= int(getattr(mjcffi.mjtState, bit))
    width = mjcffi.mj_stateSize(scene.cm, control_spec)
    control = scene.controls(4, 10, width=width)
    if "EQ_ACTIVE" in spec:
        control[..., 0] = np.arange(10) % 2      # eq_active comes first: the weld on, off
    theirs, ours = scene.both(scene.initial_states(4), control, control_spec=control_spec,
                              nthread=2)
    assert_same(theirs, ours)


def test_nothing_left_in_the_data_changes_the_result(scene):
    args = (scene.initial_states(3), scene.controls(3, 10))
    d = mjcffi.MjData(scene.cm)
    clean = rollout.rollout(scene.cm, d, *args)
    rng = np.random.default_rng(5)
    for name in ("ctrl", "qfrc_applied", "xfrc_applied", "mocap_pos", "mocap_quat",
                 "qacc_warmstart", "act"):
        getattr(d, name)[:] = rng.normal(size=getattr(d, name).shape)
    d.eq_active[:] = 1
    assert_same(clean, rollout.rollout(scene.cm, d, *args))


def test_skip_checks_gives_the_same_result(scene):
    nbatch, nstep = 4, 10
    initial, control = scene.initial_states(nbatch), scene.controls(nbatch, nstep)
    reference = rollout.rollout(scene.cm, mjcffi.MjData(scene.cm), initial, control)
    state = np.empty((nbatch, nstep, scene.nstate))
    sensordata = np.empty((nbatch, nstep, scene.cm.nsensordata))
    data = [mjcffi.MjData(scene.cm) for _ in range(2)]
    result = rollout.rollout([scene.cm] * nbatch, data, initial, control, nstep=nstep,
                             state=state, sensordata=sensordata, skip_checks=True)
    assert result[0] is state and result[1] is sensordata
    assert_same(reference, result)
    short = np.empty((nbatch, nstep - 1, scene.nstate))
    with pytest.raises(ValueError, match=f"state.size should be {state.size}, got {short.size}"):
        rollout.rollout([scene.cm] * nbatch, data, initial, control, nstep=nstep,
                        state=short, skip_checks=True)


# ---------------------------------------------------------------- outputs

def test_outputs_are_written_in_place(scene):
    nbatch, nstep = 3, 5
    state = np.full((nbatch, nstep, scene.nstate), -1.0)
    sensordata = np.full((nbatch, nstep, scene.cm.nsensordata), -1.0)
    result = rollout.rollout(scene.cm, mjcffi.MjData(scene.cm), scene.initial_states(nbatch),
                             scene.controls(nbatch, nstep), state=state, sensordata=sensordata)
    assert result[0] is state and result[1] is sensordata
    assert (state[:, :, 0] > 0).all()


def test_a_2d_output_for_one_rollout_is_written_in_place(scene):
    state = np.zeros((6, scene.nstate))
    result, _ = rollout.rollout(scene.cm, mjcffi.MjData(scene.cm), scene.initial_states(1),
                                scene.controls(1, 6), state=state)
    assert result.shape == (1, 6, scene.nstate) and np.shares_memory(result, state)
    assert (state[:, 0] > 0).all()


@pytest.mark.parametrize("nthread", [1, 2])
def test_nstep_zero(scene, nthread):
    state, sensordata = rollout.rollout(scene.cm, scene.datas(nthread)[1],
                                        scene.initial_states(4), nstep=0)
    assert state.shape == (4, 0, scene.nstate)
    assert sensordata.shape == (4, 0, scene.cm.nsensordata)


# ---------------------------------------------------------- divergence, errors

@pytest.mark.parametrize("nthread", [1, 2])
def test_a_nan_control_diverges_that_rollout_only(mujoco, official_rollout, nthread):
    pair = Pair(mujoco, path=_asset("hopper.xml"))
    nbatch, nstep, bad = 5, 30, 2
    initial, control = pair.initial_states(nbatch), pair.controls(nbatch, nstep)
    clean = rollout.rollout(pair.cm, pair.datas(nthread)[1], initial, control)
    control[bad, 10, 0] = np.nan
    theirs, ours = pair.both(initial, control, nthread=nthread)
    assert_same(theirs, ours)
    others = [i for i in range(nbatch) if i != bad]
    np.testing.assert_array_equal(ours[0][others], clean[0][others], strict=True)
    time = ours[0][bad, :, 0]
    # after the bad step, the rollout repeats its last state: time stands still
    assert (np.diff(time[:11]) > 0).all() and (time[11:] == time[10]).all()
    assert (ours[0][bad, 11:] == ours[0][bad, 10]).all()
    np.testing.assert_array_equal(ours[0][bad, :10], clean[0][bad, :10], strict=True)


def test_a_state_that_diverges_by_itself(mujoco, official_rollout):
    pair = Pair(mujoco, SCENE)
    initial = pair.initial_states(3)
    initial[1, 1 + pair.cm.nq:] = 1e12          # huge velocities: a bad qacc warning
    theirs, ours = pair.both(initial, pair.controls(3, 20), nthread=2)
    assert_same(theirs, ours)
    assert (ours[0][1, -1] == ours[0][1, -2]).all()


def _bad_solver(model):
    """A copy of `model` whose constraint solver is not an mjtSolver: mju_error in a step."""
    bad = copy.copy(model)
    bad.opt.solver = 10
    return bad


def _failing_step(model, initial, control):
    """The step at which mj_step raises FatalError, stepping `control` from `initial`."""
    d = mjcffi.MjData(model)
    mjcffi.mj_setState(model, d, initial, FULLPHYSICS)
    for t, row in enumerate(control):
        d.ctrl[:] = row
        try:
            mjcffi.mj_step(model, d)
        except mjcffi.FatalError:
            return t
    raise AssertionError("no step raised")


@pytest.mark.parametrize("nthread", [1, 2])
def test_a_fatal_error_fails_its_rollout_only(scene, nthread):
    nbatch, nstep = 6, 10
    initial, control = scene.rest(nbatch), scene.controls(nbatch, nstep)   # in contact
    clean = rollout.rollout(scene.cm, mjcffi.MjData(scene.cm), initial, control)
    bad = _bad_solver(scene.cm)
    models = [scene.cm, scene.cm, bad, scene.cm, bad, scene.cm]
    state = np.zeros((nbatch, nstep, scene.nstate))
    sensordata = np.zeros((nbatch, nstep, scene.cm.nsensordata))
    data = scene.datas(nthread)[1]
    with pytest.raises(mjcffi.FatalError) as caught:
        rollout.rollout(models, data, initial, control, state=state, sensordata=sensordata,
                        chunk_size=2)
    assert str(caught.value) == "mj_fwdConstraint: unknown solver type 10"
    assert list(caught.value.failed) == [2, 4]
    good = [0, 1, 3, 5]
    np.testing.assert_array_equal(state[good], clean[0][good], strict=True)
    np.testing.assert_array_equal(sensordata[good], clean[1][good], strict=True)
    for r in (2, 4):
        # good rows up to the step that raised, as mj_step itself raises; NaN from there
        k = _failing_step(bad, initial[r], control[r])
        np.testing.assert_array_equal(state[r, :k], clean[0][r, :k], strict=True)
        assert np.isnan(state[r, k:]).all() and np.isnan(sensordata[r, k:]).all()
    # the data were reset, and roll out as fresh ones do
    assert_same(clean, rollout.rollout(scene.cm, data, initial, control))
    assert mjcffi.lib.mjcffi_take_error() == mjcffi.ffi.NULL


def test_a_fatal_error_matches_the_official_message(scene):
    bad = _bad_solver(scene.cm)
    obad = copy.copy(scene.om)
    obad.opt.solver = 10
    initial, control = scene.rest(1), scene.controls(1, 3)
    with pytest.raises(scene.mujoco.FatalError) as theirs:
        scene.mujoco.rollout.rollout(obad, scene.mujoco.MjData(obad), initial, control)
    with pytest.raises(mjcffi.FatalError) as ours:
        rollout.rollout(bad, mjcffi.MjData(bad), initial, control)
    assert str(ours.value) == str(theirs.value)


# ---------------------------------------------------------------- threads

def test_concurrent_calls_from_python_threads(scene):
    nbatch, nstep, ncall = 6, 15, 8
    inputs = [(scene.initial_states(nbatch, seed=i), scene.controls(nbatch, nstep, seed=i))
              for i in range(ncall)]
    expected = [rollout.rollout(scene.cm, mjcffi.MjData(scene.cm), *args) for args in inputs]
    shared = rollout.Rollout(nthread=2)
    barrier = threading.Barrier(4, timeout=60)

    def call(i):
        if i < 4:
            barrier.wait()          # the first four calls start together
        mode = i % 4
        if mode == 0:               # on the calling thread
            return rollout.rollout(scene.cm, mjcffi.MjData(scene.cm), *inputs[i])
        data = [mjcffi.MjData(scene.cm) for _ in range(mode + 1)]
        if mode == 1:               # the persistent pool, shared: calls take turns
            return rollout.rollout(scene.cm, data, *inputs[i], persistent_pool=True)
        if mode == 2:               # a pool of three threads for this call
            return rollout.rollout(scene.cm, data, *inputs[i])
        return shared.rollout(scene.cm, data[:2], *inputs[i])

    with ThreadPoolExecutor(4) as executor:
        results = list(executor.map(call, range(ncall)))
    shared.close()
    rollout.shutdown_persistent_pool()
    for got, want in zip(results, expected):
        assert_same(want, got)


def test_rollout_object_and_persistent_pool(scene):
    args = (scene.initial_states(5), scene.controls(5, 8))
    reference = rollout.rollout(scene.cm, mjcffi.MjData(scene.cm), *args)
    with rollout.Rollout(nthread=3) as pool:
        data = [mjcffi.MjData(scene.cm) for _ in range(3)]
        for _ in range(3):
            assert_same(reference, pool.rollout(scene.cm, data, *args))
    with pytest.raises(RuntimeError, match="after thread pool shutdown"):
        pool.rollout(scene.cm, data, *args)
    for n in (2, 3, 2):
        data = [mjcffi.MjData(scene.cm) for _ in range(n)]
        assert_same(reference, rollout.rollout(scene.cm, data, *args, persistent_pool=True))
        assert rollout.persistent_rollout.nthread == n
    rollout.shutdown_persistent_pool()
    assert rollout.persistent_rollout is None


@pytest.mark.parametrize("nthread", [1, 2])
def test_python_callbacks_run_on_the_pool_threads(scene, nthread):
    calls = []

    def control(m, d):
        calls.append(threading.get_ident())
        if len(calls) == 7:
            raise KeyError("from the callback")

    args = (scene.initial_states(4), scene.controls(4, 5))
    mjcffi.set_mjcb_control(control)
    try:
        with pytest.raises(KeyError, match="from the callback"):
            rollout.rollout(scene.cm, scene.datas(nthread)[1], *args, chunk_size=1)
    finally:
        mjcffi.set_mjcb_control(None)
    assert len(calls) >= 20
    callbacks.raise_pending_callback_error()        # nothing is left pending


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs fork")
def test_a_pool_works_in_a_forked_child(scene):
    args = (scene.initial_states(6), scene.controls(6, 5))
    data = [mjcffi.MjData(scene.cm) for _ in range(2)]
    with rollout.Rollout(nthread=2) as pool:
        expected = pool.rollout(scene.cm, data, *args)
        pid = os.fork()
        if pid == 0:                  # the child: the pool's threads were not copied
            ok = all(np.array_equal(a, b) for a, b in zip(expected, pool.rollout(scene.cm, data,
                                                                                 *args)))
            os._exit(0 if ok else 1)
        _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0


def test_public_names():
    import importlib
    module = importlib.import_module("mjcffi.rollout")
    assert module is rollout and mjcffi.rollout is rollout
    assert callable(rollout.rollout) and isinstance(rollout.Rollout, type)


# ------------------------------------------------------------- validation

def test_wrong_shapes_name_the_argument(scene):
    d, nstate, nu = mjcffi.MjData(scene.cm), scene.nstate, scene.cm.nu
    initial, control = scene.initial_states(2), scene.controls(2, 3)
    cases = [
        (dict(initial_state=np.zeros((2, nstate + 1))),
         rf"trailing dimension of initial_state must be {nstate}, got {nstate + 1}"),
        (dict(control=np.zeros((2, 3, nu + 1))),
         rf"trailing dimension of control must be {nu}, got {nu + 1}"),
        (dict(initial_warmstart=np.zeros((2, 1))), "trailing dimension of initial_warmstart"),
        (dict(control=np.zeros((3, 3, nu))), "dimension 0 inferred as 2 but control has 3"),
        (dict(state=np.zeros((2, 4, nstate))), "dimension 1 inferred as 3 but state has 4"),
        (dict(state=np.zeros((1, 3, nstate))),
         rf"an output must have the full shape \(nbatch, nstep, {nstate}\) = \(2, 3, {nstate}\)"),
        (dict(sensordata=np.zeros((2, 3, 1))), "trailing dimension of sensordata"),
        (dict(control=np.zeros((2, 3, 4, 5))), "control can have at most 3 dimensions"),
        (dict(control="string"), "control must be a numpy array or float"),
        (dict(nstep=-1), "nstep must be non-negative"),
        (dict(nstep=1.5), "nstep must be an integer"),
        (dict(chunk_size=0), "chunk_size must be a positive integer"),
        (dict(control_spec=int(mjcffi.mjtState.mjSTATE_ACT)),
         "control_spec can only contain bits in mjSTATE_USER"),
    ]
    for change, message in cases:
        kwargs = dict(initial_state=initial, control=control) | change
        with pytest.raises(ValueError, match=message):
            rollout.rollout(scene.cm, d, **kwargs)


def test_trailing_dimension_message_is_the_officials_with_the_shape_in_a_note(scene):
    d, nstate, nu = mjcffi.MjData(scene.cm), scene.nstate, scene.cm.nu
    initial, control = scene.initial_states(2), scene.controls(2, 3)
    cases = [
        (dict(initial_state=np.zeros((2, nstate + 1))),
         f"trailing dimension of initial_state must be {nstate}, got {nstate + 1}",
         f"initial_state must have shape ([2 or 1], {nstate})"),
        (dict(control=np.zeros((2, 3, nu + 1))),
         f"trailing dimension of control must be {nu}, got {nu + 1}",
         f"control must have shape ([2 or 1], [3 or 1], {nu})"),
        (dict(sensordata=np.zeros((2, 3, 1))),
         f"trailing dimension of sensordata must be {scene.cm.nsensordata}, got 1",
         f"sensordata must have shape (2, 3, {scene.cm.nsensordata})"),
    ]
    for change, message, note in cases:
        kwargs = dict(initial_state=initial, control=control) | change
        with pytest.raises(ValueError) as caught:
            rollout.rollout(scene.cm, d, **kwargs)
        assert str(caught.value) == message
        assert caught.value.__notes__ == [note]


def test_wrong_data(scene, mujoco):
    initial = scene.initial_states(4)
    d = mjcffi.MjData(scene.cm)
    with pytest.raises(ValueError, match="The list of data instances is empty"):
        rollout.rollout(scene.cm, [], initial)
    with pytest.raises(ValueError, match="Length of data: 1 not equal to nthread: 2"):
        with rollout.Rollout(nthread=2) as pool:
            pool.rollout(scene.cm, d, initial)
    with pytest.raises(ValueError, match="configured to run on main thread"):
        rollout.Rollout().rollout(scene.cm, [d, mjcffi.MjData(scene.cm)], initial)
    with pytest.raises(ValueError, match=r"data\[1\] is data\[0\]"):
        rollout.rollout(scene.cm, [d, d], initial)
    other = mjcffi.MjModel.from_xml_string(PENDULUM)
    with pytest.raises(ValueError, match=r"data\[0\] was made for a model of other sizes"):
        rollout.rollout(scene.cm, mjcffi.MjData(other), initial)
    with pytest.raises(TypeError, match=r"data\[0\] must be an mjcffi\.MjData, not "
                                        r"mujoco\._structs\.MjData: objects of the official"):
        rollout.rollout(scene.cm, scene.mujoco.MjData(scene.om), initial)
    pooled = [mjcffi.MjData(scene.cm) for _ in range(2)]
    mjcffi.mju_threadpool(pooled[1], 2)
    with pytest.raises(ValueError, match=r"data\[1\] has a thread pool installed"):
        rollout.rollout(scene.cm, pooled, initial)


def test_wrong_models(scene):
    initial, d = scene.initial_states(2), mjcffi.MjData(scene.cm)
    with pytest.raises(TypeError, match="model must be an MjModel"):
        rollout.rollout(3, d, initial)
    with pytest.raises(TypeError, match=r"model\[1\] must be an mjcffi\.MjModel, not "
                                        r"mujoco\._structs\.MjModel"):
        rollout.rollout([scene.cm, scene.om], d, initial)
    with pytest.raises(ValueError, match="nbatch inferred as 2 but model is length 3"):
        rollout.rollout([scene.cm] * 3, d, initial)
    other = mjcffi.MjModel.from_xml_string(PENDULUM)
    with pytest.raises(ValueError, match=r"models are not compatible: model\[1\]"):
        rollout.rollout([scene.cm, other], d, initial)


def test_wrong_output_buffers(scene):
    d, nstate = mjcffi.MjData(scene.cm), scene.nstate
    initial = scene.initial_states(2)
    with pytest.raises(TypeError, match="state must have dtype float64, not float32"):
        rollout.rollout(scene.cm, d, initial, nstep=3,
                        state=np.zeros((2, 3, nstate), np.float32))
    with pytest.raises(ValueError, match="state must be C-contiguous"):
        rollout.rollout(scene.cm, d, initial, nstep=3,
                        state=np.zeros((nstate, 3, 2)).transpose())
    readonly = np.zeros((2, 3, scene.cm.nsensordata))
    readonly.flags.writeable = False
    with pytest.raises(ValueError, match="sensordata is read-only"):
        rollout.rollout(scene.cm, d, initial, nstep=3, sensordata=readonly)
    with pytest.raises(TypeError, match="initial_state must be"):
        rollout.rollout(scene.cm, d, None)
    with pytest.raises(TypeError, match="nthread must be an integer"):
        rollout.Rollout(nthread=1.5)
