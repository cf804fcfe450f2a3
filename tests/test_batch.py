"""mjcffi.batch against the official mujoco.batch, a loop of MjData, and bad input.

Both bindings run the same libmujoco in this process, so every result of a
Batch (state rows, bound outputs, rollouts, Jacobians, rays, named views,
materialized models and data) must equal the official Batch's to the bit.
"""

import copy
import ctypes
import gc
import pathlib
import weakref

import numpy as np
import pytest

import mjcffi
from mjcffi import batch

from .conftest import gymnasium_assets

SCENE = pathlib.Path(__file__).parent / "scenes" / "every_category.xml"
GYM = {path.stem: path for path in gymnasium_assets()}
# a spread of gymnasium models for the heavier matrices; every model for the lighter ones
SOME = [GYM["humanoid"], GYM["ant"], GYM["hopper"], GYM["pusher"], SCENE]
EVERY = [SCENE] + list(GYM.values())
NSIM = 6

CARTPOLE = """
<mujoco>
  <worldbody>
    <geom type="plane" size="2 2 .1"/>
    <body name="cart" pos="0 0 .1">
      <joint name="slide" type="slide" axis="1 0 0"/>
      <geom type="box" size=".1 .1 .05" mass="1"/>
      <body name="pole" pos="0 0 .05">
        <joint name="hinge" axis="0 1 0"/>
        <geom name="pole" type="capsule" fromto="0 0 0 0 0 .5" size=".02" mass=".1"/>
        <site name="tip" pos="0 0 .5"/>
      </body>
    </body>
    <body name="mocap" mocap="true" pos="1 0 1">
      <geom type="sphere" size=".02" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
  <equality>
    <weld name="hold" body1="mocap" body2="pole" active="false"/>
  </equality>
  <actuator>
    <motor name="push" joint="slide" gear="5"/>
    <general name="filtered" joint="hinge" dyntype="filter" dynprm="0.02" gainprm="5"
      biastype="affine" biasprm="0 -5 0"/>
  </actuator>
  <sensor>
    <jointpos name="angle" joint="hinge"/>
    <accelerometer name="accel" site="tip"/>
  </sensor>
  <keyframe>
    <key name="tilted" qpos="0.3 0.5" ctrl="0.1 0.2" act="0.2"/>
    <key name="other" qpos="-0.3 -0.5" ctrl="0.2 0.1" act="0.1"/>
  </keyframe>
</mujoco>
"""

OUTPUTS = ("xpos", "xquat", "qacc", "actuator_force", "sensordata", "cacc", "ncon", "nefc",
           "energy", "qfrc_constraint")
POSITION_OUTPUTS = ("xpos", "xquat", "ncon", "nefc", "sensordata")   # the scene's sensors too


@pytest.fixture(scope="module")
def official(mujoco):
    from mujoco import batch as official_batch
    return official_batch


def _models(mujoco, source):
    """The same model loaded by both bindings, from a path or XML text."""
    if isinstance(source, pathlib.Path):
        return mujoco.MjModel.from_xml_path(str(source)), mjcffi.MjModel.from_xml_path(source)
    return mujoco.MjModel.from_xml_string(source), mjcffi.MjModel.from_xml_string(source)


def _pair(mujoco, official, source, nsim=NSIM, nthread=1, persistent=False):
    om, m = _models(mujoco, source)
    return (om, official.Batch(om, nsim, nthread, persistent)), \
        (m, batch.Batch(m, nsim, nthread, persistent))


def _same(a, b, what=""):
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape and a.dtype == b.dtype, (what, a.shape, b.shape, a.dtype, b.dtype)
    assert np.array_equal(a, b, equal_nan=True), what


# ------------------------------------------------------------- bit identity

@pytest.mark.parametrize("persistent", [False, True], ids=["shared", "persistent"])
@pytest.mark.parametrize("nthread", [1, 2])
@pytest.mark.parametrize("path", SOME, ids=lambda p: p.stem)
def test_step_forward_reset_bit_identical_to_official(mujoco, official, path, nthread,
                                                      persistent):
    (om, ob), (m, b) = _pair(mujoco, official, path, nthread=nthread, persistent=persistent)
    assert (b.nsim, b.nthread, b.persistent, b.nstate) == \
        (ob.nsim, ob.nthread, ob.persistent, ob.nstate)
    theirs = {name: ob.bind(name) for name in OUTPUTS}
    ours = {name: b.bind(name) for name in OUTPUTS}
    rng = np.random.default_rng(1)
    ob.reset()
    b.reset()
    for call in range(24):
        u = rng.uniform(-1, 1, (NSIM, m.nu))
        ob.ctrl, b.ctrl = u, u
        if call == 10:
            key = 0 if m.nkey else -1
            ob.reset([1, 4], keyframe=key)
            b.reset([1, 4], keyframe=key)
        elif call == 15:
            ob.forward(stage=mujoco.mjtStage.mjSTAGE_VEL)
            b.forward(stage=mjcffi.mjtStage.mjSTAGE_VEL)
        else:
            mask = np.arange(NSIM) % 3 != 1 if call % 4 == 3 else None
            stage = call % 4
            ob.step(mask, nstep=2, stage=stage)
            b.step(mask, nstep=2, stage=stage)
        _same(ob.state, b.state, f"state after call {call}")
        _same(ob.warning, b.warning, "warning")
        for name in OUTPUTS:
            if call == 15 and not persistent and name not in POSITION_OUTPUTS:
                continue    # not computed by this call: another simulation's, on either side
            _same(theirs[name], ours[name], name)


def _reference_loop(m, nsim, controls, nstep):
    """One mjcffi MjData per simulation, stepped by mj_step: what a batch must equal."""
    datas = [mjcffi.MjData(m) for _ in range(nsim)]
    qpos = np.empty((nsim, len(controls), m.nq))
    for k, u in enumerate(controls):
        for i, d in enumerate(datas):
            d.ctrl[:] = u[i]
            mjcffi.mj_step(m, d, nstep)
            qpos[i, k] = d.qpos
    return qpos, datas


@pytest.mark.parametrize("path", EVERY, ids=lambda p: p.stem)
def test_every_gymnasium_model_equals_a_loop_of_mjdata(path):
    m = mjcffi.MjModel.from_xml_path(path)
    rng = np.random.default_rng(2)
    controls = rng.uniform(-1, 1, (8, NSIM, m.nu))
    expected, datas = _reference_loop(m, NSIM, controls, 3)
    b = batch.Batch(m, NSIM, 2)
    xpos = b.xpos
    for k, u in enumerate(controls):
        b.ctrl = u
        b.step(nstep=3)
        _same(b.qpos, expected[:, k], f"step {k}")
    state = np.empty(b.nstate)
    for i, d in enumerate(datas):
        _same(xpos[i], d.xpos, "xpos")
        mjcffi.mj_getState(m, d, state, mjcffi.mjtState.mjSTATE_INTEGRATION)
        _same(b.state[i], state, "state")


@pytest.mark.parametrize("path", SOME, ids=lambda p: p.stem)
def test_rollout_bit_identical_to_official(mujoco, official, path):
    (om, ob), (m, b) = _pair(mujoco, official, path, nthread=2)
    rng = np.random.default_rng(3)
    ids = np.array([0, 2, 3])
    control = rng.uniform(-1, 1, (len(ids), 7, m.nu))
    record = ("qpos", "xpos", "sensordata", "ncon", "energy", "eq_active",
              mujoco.mjtState.mjSTATE_FULLPHYSICS)
    theirs = ob.rollout(7, control, record=record, ids=ids)
    ours = b.rollout(7, control, record=record, ids=ids)
    assert list(ours) == list(theirs)
    for item in record:
        _same(theirs[item], ours[item], item)
    _same(ob.state, b.state, "state")
    # no control: the inputs are left as they are; every simulation; into given arrays
    out = {"qvel": np.zeros((NSIM, 4, m.nv))}
    given = out["qvel"]
    ours = b.rollout(4, record=("qvel",), out=out)
    assert ours["qvel"] is given
    _same(ob.rollout(4, record=("qvel",))["qvel"], given, "qvel")
    # a state spec as control, broadcast
    spec = int(mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_QFRC_APPLIED)
    u = rng.uniform(-1, 1, m.nu + m.nv)
    _same(ob.rollout(3, u, spec, record=("qacc",))["qacc"],
          b.rollout(3, u, spec, record=("qacc",))["qacc"], "qacc")


def test_rollout_matches_stepping():
    m = mjcffi.MjModel.from_xml_path(GYM["hopper"])
    control = np.random.default_rng(4).uniform(-1, 1, (NSIM, 5, m.nu))
    b = batch.Batch(m, NSIM, 2)
    qpos = b.rollout(5, control)["qpos"]
    expected, _ = _reference_loop(m, NSIM, control.transpose(1, 0, 2), 1)
    _same(qpos, expected, "qpos")


@pytest.mark.parametrize("persistent", [False, True], ids=["shared", "persistent"])
def test_expand_and_set_const_bit_identical_to_official(mujoco, official, persistent):
    (om, ob), (m, b) = _pair(mujoco, official, GYM["humanoid"], nthread=2,
                             persistent=persistent)
    rng = np.random.default_rng(5)
    for name in ("body_mass", "geom_friction", "opt.gravity", "dof_damping", "opt.timestep"):
        values = b.expand(name)
        theirs = ob.expand(name)
        _same(theirs, values, name)
        assert values.flags.writeable
        new = values * rng.uniform(0.5, 1.5, values.shape)
        theirs[...], values[...] = new, new
    assert b.expand("body_mass") is b.expand("body_mass")     # cached, live
    ob.set_const()
    b.set_const()
    for name in ("body_invweight0", "body_subtreemass", "dof_invweight0"):
        _same(ob.expanded(name), b.expanded(name), name)
        assert not b.expanded(name).flags.writeable
    assert b.expanded("geom_rgba") is None
    iterations = b.expand("opt.iterations")
    assert iterations.shape == (NSIM,) and iterations.dtype == np.int32
    ob.expand("opt.iterations")
    for _ in range(5):
        u = rng.uniform(-1, 1, (NSIM, m.nu))
        ob.ctrl, b.ctrl = u, u
        ob.step(nstep=3)
        b.step(nstep=3)
        _same(ob.state, b.state, "state")
    for sim in (0, NSIM - 1):
        theirs_model, ours_model = ob.get_model(sim), b.get_model(sim)
        for name in ("body_mass", "geom_friction", "body_invweight0"):
            _same(getattr(theirs_model, name), getattr(ours_model, name), name)
        _same(theirs_model.opt.gravity, ours_model.opt.gravity, "gravity")
        assert theirs_model.opt.timestep == ours_model.opt.timestep


def test_expand_bvh_aabb_and_options(mujoco, official):
    (om, ob), (m, b) = _pair(mujoco, official, SCENE)
    _same(ob.expand("bvh_aabb"), b.expand("bvh_aabb"), "bvh_aabb")
    assert b.expand("opt.gravity").shape == (NSIM, 3)
    assert b.expand("opt.timestep").shape == (NSIM,)


def test_field_sets_equal_the_official_ones(official):
    assert batch.DATA_FIELDS == official.DATA_FIELDS
    # less the index fields, which mjcffi refuses to expand (test_hardening_runtime.py)
    assert batch.MODEL_FIELDS == official.MODEL_FIELDS - batch.INDEX_FIELDS
    assert batch.INDEX_FIELDS < official.MODEL_FIELDS
    assert {"qpos", "energy", "ncon"} <= batch.RECORD_FIELDS
    assert "time" not in batch.RECORD_FIELDS and "efc_J" not in batch.RECORD_FIELDS


def test_every_field_binds_and_expands_with_official_shapes(mujoco, official):
    (om, ob), (m, b) = _pair(mujoco, official, SCENE)
    b.step()
    ob.step()
    for name in sorted(batch.DATA_FIELDS):
        _same(ob.bind(name), b.bind(name), name)
        assert b.bind(name).flags.writeable == (name in batch._STATE_FIELDS), name
    for name in sorted(batch.MODEL_FIELDS):
        _same(ob.expand(name), b.expand(name), name)


# ------------------------------------------------------------ jac and ray

@pytest.mark.parametrize("persistent", [False, True], ids=["shared", "persistent"])
def test_jac_and_ray_bit_identical_to_official(mujoco, official, persistent):
    (om, ob), (m, b) = _pair(mujoco, official, GYM["humanoid"], nthread=2,
                             persistent=persistent)
    rng = np.random.default_rng(6)
    for bb in (ob, b):
        bb.ctrl = 0.3
        bb.step(nstep=5)
    bodies = rng.integers(1, m.nbody, NSIM)
    points = rng.uniform(-1, 1, (NSIM, 3))
    for got, expected in zip(b.jac(bodies, points), ob.jac(bodies, points)):
        _same(expected, got, "jac")
    ids = [1, 4]
    for got, expected in zip(b.jac(3, [0, 0, 1], ids=ids), ob.jac(3, [0, 0, 1], ids=ids)):
        _same(expected, got, "jac ids")
    pnt = np.array([[0, 0, 3.0], [0.1, 0, 3.0], [5, 5, 5]])
    vec = np.array([0, 0, -1.0])
    for normal in (False, True):
        theirs = ob.ray(pnt, vec, normal=normal, bodyexclude=1)
        ours = b.ray(pnt, vec, normal=normal, bodyexclude=1)
        assert len(ours) == len(theirs)
        for got, expected in zip(ours, theirs):
            _same(expected, got, "ray")
    group = np.array([1, 0, 1, 0, 0, 0], np.uint8)
    for got, expected in zip(b.ray(pnt, vec, group, False, ids=[0, 5]),
                             ob.ray(pnt, vec, group, False, ids=[0, 5])):
        _same(expected, got, "ray group")
    _same(ob.state, b.state, "state untouched")


def _rays(rng, n, nray):
    """Rays from above, pointing down and sideways, at random."""
    pnt = rng.uniform(-1, 1, (n, nray, 3)) + [0, 0, 2]
    vec = rng.uniform(-1, 1, (n, nray, 3)) + [0, 0, -1.5]
    return pnt, vec


@pytest.mark.parametrize("persistent", [False, True], ids=["shared", "persistent"])
def test_jac_and_ray_on_two_threads_equal_one_thread_and_official(mujoco, official,
                                                                  persistent):
    nsim = 16
    (om, ob), (m, two) = _pair(mujoco, official, GYM["humanoid"], nsim=nsim, nthread=2,
                               persistent=persistent)
    one = batch.Batch(m, nsim, 1, persistent)
    assert two.nthread == 2 and one.nthread == 1
    rng = np.random.default_rng(11)
    for _ in range(3):
        u = rng.uniform(-1, 1, (nsim, m.nu))
        for bb in (ob, two, one):
            bb.ctrl = u
            bb.step(nstep=3)
    ids = np.array([2, 5, 6, 11, 15])
    mask = np.zeros(nsim, bool)
    mask[[0, 7, 8, 9]] = True
    for sel in (None, ids, mask):
        n = nsim if sel is None else np.count_nonzero(mask) if sel is mask else len(sel)
        bodies = rng.integers(0, m.nbody, n)
        points = rng.uniform(-1, 1, (n, 3))
        theirs = ob.jac(bodies, points, ids=sel)
        for bb in (two, one):
            for got, expected in zip(bb.jac(bodies, points, ids=sel), theirs):
                _same(expected, got, f"jac {bb!r}")
        pnt, vec = _rays(rng, n, 7)
        exclude = rng.integers(-1, m.nbody, (n, 7))
        theirs = ob.ray(pnt, vec, bodyexclude=exclude, ids=sel, normal=True)
        assert (theirs[1] >= 0).any() and (theirs[1] == -1).any()    # hits and misses
        for bb in (two, one):
            ours = bb.ray(pnt, vec, bodyexclude=exclude, ids=sel, normal=True)
            for got, expected in zip(ours, theirs):
                _same(expected, got, f"ray {bb!r}")
    for bb in (two, one):
        _same(ob.state, bb.state, "state untouched")
        assert not bb.status.any()


@pytest.mark.parametrize("nthread", [1, 2])
def test_an_error_in_jac_or_ray_fails_only_its_simulations(mujoco, official, nthread):
    nsim = 6
    (om, ob), (m, b) = _pair(mujoco, official, CARTPOLE, nsim=nsim, nthread=nthread,
                             persistent=True)
    rng = np.random.default_rng(12)
    qpos = rng.uniform(-1, 1, (nsim, m.nq))
    for bb in (ob, b):
        bb.qpos = qpos
    state = b.state.copy()
    others = [0, 2, 3, 5]

    def kinematics_ran(sims):
        # a persistent batch keeps each simulation's kinematics of the call
        for i in sims:
            d = mjcffi.MjData(m)
            d.qpos = qpos[i]
            mjcffi.mj_kinematics(m, d)
            _same(d.xpos, b.get_data(i).xpos, f"simulation {i} ran")

    # ray: a zero direction is an mju_error in mj_ray, here in simulations 1 and 4
    pnt, vec = _rays(rng, nsim, 3)
    vec[[1, 4], 1] = 0
    with pytest.raises(official.SimulationError):
        ob.ray(pnt, vec)
    with pytest.raises(batch.SimulationError, match=r"2 of 6 simulations \(1, 4\); "
                       "simulation 1: mj_ray: vector length is too small") as caught:
        b.ray(pnt, vec)
    assert caught.value.ids.tolist() == [1, 4]
    _same(ob.status, b.status, "status")
    _same(np.flatnonzero(b.status), [1, 4], "status")
    assert [b.error(i) for i in range(nsim)] == [ob.error(i) for i in range(nsim)]
    assert all(b.error(i) == "" for i in others)
    kinematics_ran(others)
    _same(state, b.state, "state untouched")
    # a selection reports simulations, not rows
    with pytest.raises(batch.SimulationError) as caught:
        b.ray(pnt[[0, 4]], vec[[0, 4]], ids=[3, 4])
    assert caught.value.ids.tolist() == [4]
    # the next call without the bad rays succeeds and clears the status
    vec[[1, 4], 1] = [0, 0, -1]
    for got, expected in zip(b.ray(pnt, vec), ob.ray(pnt, vec)):
        _same(expected, got, "ray after the error")
    assert not b.status.any() and b.error(1) == ""

    # jac: an unknown joint type is an mju_error in mj_kinematics, here in 0 and 5, on
    # models of their own (jnt_type cannot be expanded: it sets the qpos layout)
    for bb, model in ((ob, om), (b, m)):
        models = [copy.copy(model) for _ in range(nsim)]
        for i in (0, 5):
            models[i].jnt_type[1] = 99
        bb.set_models(models)
    with pytest.raises(official.SimulationError):
        ob.jac(2, [0, 0, 1])
    with pytest.raises(batch.SimulationError, match=r"2 of 6 simulations \(0, 5\); "
                       "simulation 0: mj_kinematics1: unknown joint type 99") as caught:
        b.jac(2, [0, 0, 1])
    assert caught.value.ids.tolist() == [0, 5]
    _same(ob.status, b.status, "status")
    assert [b.error(i) for i in range(nsim)] == [ob.error(i) for i in range(nsim)]
    kinematics_ran([1, 2, 3, 4])
    _same(state, b.state, "state untouched")
    ids = [1, 2, 3, 4]
    for got, expected in zip(b.jac(2, [0, 0, 1], ids=ids), ob.jac(2, [0, 0, 1], ids=ids)):
        _same(expected, got, "jac of the others")
    assert not b.status[ids].any() and b.status[0] and b.status[5]


# ------------------------------------------------------ per-simulation errors

def test_an_error_in_some_simulations_leaves_the_others_running(mujoco, official):
    (om, ob), (m, b) = _pair(mujoco, official, CARTPOLE, nsim=8, nthread=2)
    for bb in (ob, b):
        bb.expand("eq_type")[[3, 6]] = 99          # no such constraint: mj_step raises
        bb.expand("eq_active0")
        bb.eq_active = 1
    time = b.time
    with pytest.raises(batch.SimulationError, match=r"2 of 8 simulations \(3, 6\); "
                       "simulation 3") as caught:
        b.step()
    with pytest.raises(official.SimulationError):
        ob.step()
    assert isinstance(caught.value, RuntimeError)
    assert caught.value.ids.tolist() == [3, 6]
    _same(np.flatnonzero(b.status), [3, 6], "status")
    assert not b.status.flags.writeable
    assert b.error(3) == ob.error(3) and b.error(3)
    assert b.error(0) == ""
    assert time[3] == 0 and time[6] == 0                # they kept their state
    assert np.all(np.delete(time, [3, 6]) > 0)          # the others ran
    _same(ob.state, b.state, "state")
    # a call on other simulations clears nothing of theirs; a fixed model recovers
    b.step([0, 1])
    assert b.status[3]
    b.expand("eq_type")[[3, 6]] = m.eq_type[0]
    b.step()
    assert not b.status.any() and b.error(3) == ""


def test_set_const_errors_name_their_simulations():
    m = mjcffi.MjModel.from_xml_string("""
      <mujoco>
        <worldbody>
          <body><joint type="slide"/><geom size=".1" mass="1" contype="0" conaffinity="0"/></body>
        </worldbody>
      </mujoco>""")
    b = batch.Batch(m, 4, 2)
    b.expand("body_mass")[:, 1] = [0, 1, 0, 1]          # zero mass: mj_setConst raises
    with pytest.raises(batch.SimulationError) as caught:
        b.set_const([0, 1, 3])
    assert caught.value.ids.tolist() == [0]
    assert b.status[2] == 0                             # not run: not recomputed


@pytest.mark.parametrize("field", ["qpos", "ctrl", "qvel"])
def test_nan_in_one_simulation_stays_in_it(mujoco, official, field):
    (om, ob), (m, b) = _pair(mujoco, official, GYM["ant"], nthread=2)
    clean = batch.Batch(m, NSIM, 1)
    rng = np.random.default_rng(7)
    for step in range(12):
        u = rng.uniform(-1, 1, (NSIM, m.nu))
        for bb in (ob, b, clean):
            bb.ctrl = u
        if step == 4:
            ob.bind(field)[2, 0] = np.nan
            b.bind(field)[2, 0] = np.nan
        for bb in (ob, b, clean):
            bb.step(nstep=2)
    _same(ob.state, b.state, "state")                   # the official does the same
    _same(ob.warning, b.warning, "warnings")
    assert b.warning[2, :, 1].sum() > 0                 # MuJoCo warned about simulation 2
    assert b.warning[np.arange(NSIM) != 2].sum() == 0
    others = np.arange(NSIM) != 2
    _same(b.state[others], clean.state[others], "the other simulations")
    assert np.isfinite(b.state).all()                   # simulation 2 was reset, not left NaN
    assert not b.status.any()                           # a warning, not an error


def test_rollout_stops_a_simulation_whose_warnings_rise(mujoco, official):
    (om, ob), (m, b) = _pair(mujoco, official, GYM["hopper"])
    control = np.zeros((NSIM, 6, m.nu))
    control[1, 2:] = np.nan
    theirs = ob.rollout(6, control, record=("qpos", "qvel"))
    ours = b.rollout(6, control, record=("qpos", "qvel"))
    _same(theirs["qpos"], ours["qpos"], "qpos")
    _same(ours["qpos"][1, 3], ours["qpos"][1, 5], "repeated records")


def test_bad_stage_or_nstep_is_a_fatal_error_and_leaves_the_batch_usable():
    b = batch.Batch(mjcffi.MjModel.from_xml_string(CARTPOLE), 3)
    for call in (lambda: b.step(stage=7), lambda: b.step(nstep=0), lambda: b.forward(stage=-1),
                 lambda: b.reset(stage=9)):
        with pytest.raises(mjcffi.FatalError, match="mjb_"):
            call()
    b.step()
    assert (b.time > 0).all()


# ------------------------------------------------------------------ named views

KINDS = ("actuator", "body", "camera", "equality", "geom", "joint", "keyframe", "light",
         "material", "numeric", "pair", "sensor", "site", "tendon")
SIZES = {"joint": "njnt", "camera": "ncam", "equality": "neq", "keyframe": "nkey",
         "material": "nmat", "tendon": "ntendon"}


def _outcome(named, attr):
    try:
        value = getattr(named, attr)
    except (AttributeError, ValueError) as exc:
        return type(exc).__name__
    return value


@pytest.mark.parametrize("path", [SCENE, GYM["humanoid"], GYM["pusher"]], ids=lambda p: p.stem)
def test_named_views_equal_the_official_ones(mujoco, official, path):
    (om, ob), (m, b) = _pair(mujoco, official, path, nthread=2)
    for bb in (ob, b):
        bb.expand("geom_size")[...] *= np.linspace(1, 2, NSIM)[:, None, None]
        bb.set_const()
        bb.step(nstep=3)
    od = mujoco.MjData(om)
    compared = 0
    for kind in KINDS:
        for element in range(getattr(m, SIZES.get(kind, "n" + kind))):
            theirs, ours = getattr(ob, kind)(element), getattr(b, kind)(element)
            assert (ours.id, ours.name) == (theirs.id, theirs.name)
            attrs = set()
            for side in (om, od):
                method = getattr(side, kind, None)
                if callable(method):
                    attrs |= {a for a in dir(method(element)) if not a.startswith("_")}
            for attr in sorted(attrs - {"id", "name"}):
                expected, got = _outcome(theirs, attr), _outcome(ours, attr)
                if isinstance(expected, str) or isinstance(got, str):
                    assert expected == got, (kind, element, attr)
                    continue
                _same(expected, got, f"{kind} {element} {attr}")
                assert got.flags.writeable == expected.flags.writeable, (kind, attr)
                compared += 1
            # by name too: the same object's views
            if ours.name:
                assert getattr(b, kind)(ours.name).id == ours.id
    assert compared > 100


def test_named_views_slice_and_write_through():
    m = mjcffi.MjModel.from_xml_string(CARTPOLE)
    b = batch.Batch(m, NSIM, 2)
    hinge = b.joint("hinge")
    assert (hinge.id, hinge.name) == (1, "hinge")
    hinge.qpos = np.arange(NSIM)[:, None] * 0.1          # a view of the state rows
    _same(b.qpos[:, 1], np.arange(NSIM) * 0.1, "qpos")
    b.actuator("push").ctrl[:, 0] = 0.5
    _same(b.ctrl[:, 0], np.full(NSIM, 0.5), "ctrl")
    tip, pole = b.site("tip").xpos, b.body("pole").xpos
    angle = b.sensor("angle").data
    assert tip.shape == (NSIM, 3) and angle.shape == (NSIM, 1)
    b.forward()
    d = mjcffi.MjData(m)
    for i in range(NSIM):
        d.qpos[:] = b.qpos[i]
        d.ctrl[:] = b.ctrl[i]
        mjcffi.mj_forward(m, d)
        _same(tip[i], d.site("tip").xpos, "site xpos")
        _same(pole[i], d.body("pole").xpos, "body xpos")
        _same(angle[i], d.sensor("angle").data, "sensor")
    # model attributes: read without expanding, assignment expands
    mass = b.body("pole").mass
    assert not mass.flags.writeable and "body_mass" not in b._expanded
    b.body("pole").mass = np.arange(1, NSIM + 1)[:, None]
    _same(b.expand("body_mass")[:, m.body("pole").id], np.arange(1.0, NSIM + 1), "mass")
    assert b.body("pole").mass.flags.writeable
    b.joint("hinge").damping = 0.5                       # a joint's dof field
    _same(b.expand("dof_damping")[:, 1], np.full(NSIM, 0.5), "damping")
    b.equality("hold").solref = [0.05, 1]                # model-only categories
    _same(b.get_model(3).eq_solref[0], [0.05, 1], "solref")
    assert "joint" in repr(hinge) and "qpos" in dir(hinge)


def test_named_view_errors():
    m = mjcffi.MjModel.from_xml_string(CARTPOLE)
    b = batch.Batch(m, NSIM)
    with pytest.raises(ValueError, match="computed by every call"):
        b.body("pole").xpos = 0
    with pytest.raises(ValueError, match="structural"):
        b.joint("hinge").qposadr = 0
    with pytest.raises(AttributeError, match="did you mean 'qpos'"):
        _ = b.joint("hinge").qpso
    with pytest.raises(AttributeError, match="not a slice of a field"):
        _ = b.actuator(1).moment
    with pytest.raises(AttributeError, match="not a field of a equality"):
        _ = b.equality("hold").xpos
    with pytest.raises(AttributeError):
        b.joint("hinge").id = 3
    with pytest.raises(KeyError, match="hing"):
        b.joint("hing")
    with pytest.raises(IndexError):
        b.body(99)
    with pytest.raises(TypeError):
        b.body(1.5)
    with pytest.raises(ValueError, match="cannot assign to joint qpos"):
        b.joint("hinge").qpos = np.zeros((NSIM + 1, 1))
    empty = b.body("pole").user                           # nuser_body is 0
    assert empty.shape == (NSIM, 0) and not empty.flags.writeable


# ------------------------------------------- models, data and caller models

@pytest.mark.parametrize("persistent", [False, True], ids=["shared", "persistent"])
def test_get_model_and_get_data_equal_the_official_ones(mujoco, official, persistent):
    (om, ob), (m, b) = _pair(mujoco, official, CARTPOLE, nthread=2, persistent=persistent)
    pole = m.body("pole").id
    for bb in (ob, b):
        bb.expand("body_mass")[:, pole] = np.linspace(0.1, 1, NSIM)
        bb.set_const()
        bb.qpos[:, 1] = np.linspace(-1, 1, NSIM)
        bb.forward()
    for sim in (0, 4):
        theirs, ours = ob.get_model(sim), b.get_model(sim)
        assert isinstance(ours, mjcffi.MjModel)
        for name in ("body_mass", "body_invweight0", "body_subtreemass", "geom_size"):
            _same(getattr(theirs, name), getattr(ours, name), name)
        theirs_data, ours_data = ob.get_data(sim), b.get_data(sim)
        assert isinstance(ours_data, mjcffi.MjData) and ours_data.model is m
        for name in ("qpos", "qvel", "act", "ctrl", "time", "xpos", "qacc"):
            _same(getattr(theirs_data, name), getattr(ours_data, name), name)
        # a copy, not a view: changing it leaves the batch alone
        ours_data.qpos[:] = 7
        assert not (b.qpos[sim] == 7).any()
        mjcffi.mj_forward(ours, b.get_data(sim))
    # into given objects
    given_model, given_data = copy.copy(m), mjcffi.MjData(m)
    assert b.get_model(5, given_model) is given_model
    assert b.get_data(5, given_data) is given_data
    _same(given_data.qpos, b.qpos[5], "qpos")
    with pytest.raises(IndexError, match=f"got {NSIM}"):
        b.get_data(NSIM)
    with pytest.raises(IndexError):
        b.get_model(-1)
    with pytest.raises(TypeError):
        b.get_data(0, given_model)


def test_persistent_data_keeps_derived_fields():
    m = mjcffi.MjModel.from_xml_path(GYM["hopper"])
    shared, persistent = batch.Batch(m, 4, 2), batch.Batch(m, 4, 2, persistent=True)
    for b in (shared, persistent):
        b.ctrl = 0.4
        b.step(nstep=3, stage=mjcffi.mjtStage.mjSTAGE_VEL)
        b.step(nstep=3, stage=mjcffi.mjtStage.mjSTAGE_VEL)
    _same(shared.state, persistent.state, "continuation changes nothing")
    d = persistent.get_data(2)
    _same(d.xpos, persistent.xpos[2], "derived fields of a persistent simulation")


def test_set_models_bit_identical_to_official(mujoco, official):
    (om, ob), (m, b) = _pair(mujoco, official, CARTPOLE, nthread=2)
    pole = m.body("pole").id
    theirs_models, ours_models = [], []
    for i in range(NSIM):
        for base, out in ((om, theirs_models), (m, ours_models)):
            variant = copy.copy(base)
            variant.body_mass[pole] = 0.1 * (i + 1)
            variant.opt.gravity[2] = -i
            out.append(variant)
    ob.set_models(theirs_models)
    b.set_models(ours_models)
    assert b.models == tuple(ours_models)
    for _ in range(4):
        ob.ctrl, b.ctrl = 0.3, 0.3
        ob.step(nstep=3)
        b.step(nstep=3)
    _same(ob.state, b.state, "state")
    _same(b.body("pole").mass[:, 0], 0.1 * np.arange(1, NSIM + 1), "caller masses")
    with pytest.raises(ValueError, match="caller models"):
        b.body("pole").mass = 1
    _same(b.get_model(2).body_mass, ours_models[2].body_mass, "get_model copies")
    with pytest.raises(mjcffi.FatalError, match="caller models"):
        b.expand("body_mass")
    b.set_models(ours_models[0])                        # one model for all
    assert b.models is ours_models[0]
    b.set_models(None)
    assert b.models is None
    b.expand("body_mass")
    with pytest.raises(mjcffi.FatalError, match="per-simulation"):
        b.set_models(ours_models)
    with pytest.raises(ValueError, match="one per simulation"):
        b.set_models(ours_models[:2])
    with pytest.raises(TypeError, match=r"models\[1\]"):
        b.set_models([m, "m"] + [m] * (NSIM - 2))


def test_caller_models_keyframes_and_lifetime():
    m = mjcffi.MjModel.from_xml_string(CARTPOLE)
    b = batch.Batch(m, 2)
    variant = copy.copy(m)
    b.set_models([variant, variant])
    del variant
    gc.collect()                                        # the batch keeps it alive
    b.reset(keyframe=1)
    _same(b.qpos[0], m.key_qpos[1], "keyframe of the caller model")


# --------------------------------------------------------- threads and modes

def test_results_do_not_depend_on_threads_or_persistence():
    m = mjcffi.MjModel.from_xml_path(GYM["walker2d"])
    batches = [batch.Batch(m, 8, nthread, persistent)
               for nthread in (1, 2) for persistent in (False, True)]
    rng = np.random.default_rng(8)
    for _ in range(10):
        u = rng.uniform(-1, 1, (8, m.nu))
        for b in batches:
            b.ctrl = u
            b.step(nstep=2)
    for b in batches[1:]:
        _same(batches[0].state, b.state, repr(b))
    assert [b.nthread for b in batches] == [1, 1, 2, 2]
    assert [b.persistent for b in batches] == [False, True, False, True]


def test_thread_counts():
    m = mjcffi.MjModel.from_xml_string(CARTPOLE)
    assert batch.Batch(m, 3, 1000).nthread == 3         # at most one per simulation
    assert batch.Batch(m, 3, 0).nthread >= 1            # one per CPU
    assert batch.Batch(m, 3, -1).nthread >= 1


# ------------------------------------------------------------------- lifetimes

def test_views_outlive_the_batch():
    m = mjcffi.MjModel.from_xml_path(GYM["ant"])
    b = batch.Batch(m, NSIM, 2)
    b.step(nstep=3)
    qpos, xpos, state = b.qpos, b.xpos, b.state
    mass, status, warning = b.expand("body_mass"), b.status, b.warning
    hip = b.joint(1).qpos
    expected = qpos.copy(), xpos.copy(), mass.copy(), hip.copy()
    del b
    gc.collect()
    _same(qpos, expected[0], "qpos")
    _same(xpos, expected[1], "xpos")
    _same(mass, expected[2], "mass")
    _same(hip, expected[3], "named")
    qpos[:] = 0                                         # still writable memory
    assert state[:, 1:1 + m.nq].sum() == 0 and status.sum() == 0 and warning.sum() == 0


def test_close():
    m = mjcffi.MjModel.from_xml_string(CARTPOLE)
    with batch.Batch(m, 3) as b:
        qpos = b.qpos
        b.step()
    expected = qpos.copy()
    for call in (b.step, lambda: b.bind("xpos"), lambda: b.error(0), lambda: b.qvel,
                 lambda: b.state):
        with pytest.raises(ValueError, match="closed"):
            call()
    assert "closed" in repr(b)
    gc.collect()
    _same(qpos, expected, "a view outlives close()")


def test_the_batch_is_freed_with_its_last_view():
    # the gc cdata whose destructor is mjb_deleteBatch: gone means freed
    m = mjcffi.MjModel.from_xml_string(CARTPOLE)
    b = batch.Batch(m, 3, 2)
    owner = weakref.ref(b._b._ptr)
    qpos, named, mass = b.qpos, b.joint("hinge").qpos, b.expand("body_mass")
    del b
    gc.collect()
    assert owner() is not None
    del qpos, named
    gc.collect()
    assert owner() is not None
    del mass
    gc.collect()
    assert owner() is None
    b = batch.Batch(m, 3, 2)
    owner = weakref.ref(b._b._ptr)
    b.step()
    b.close()
    gc.collect()
    assert owner() is None                              # no view held: close() frees it


# ------------------------------------------------------------------- bad input

def test_constructor_arguments(mujoco):
    m = mjcffi.MjModel.from_xml_string(CARTPOLE)
    for nsim in (0, -1, 2**31):
        with pytest.raises(ValueError, match="nsim"):
            batch.Batch(m, nsim)
    with pytest.raises(ValueError, match="nthread"):
        batch.Batch(m, 2, 2**40)
    for bad in (1.5, "2", None, True):
        with pytest.raises(TypeError, match="nsim"):
            batch.Batch(m, bad)
        with pytest.raises(TypeError, match="nthread"):
            batch.Batch(m, 2, bad)
    with pytest.raises(TypeError, match="MjModel"):
        batch.Batch(mujoco.MjModel.from_xml_string(CARTPOLE), 2)


def test_bad_ids():
    b = batch.Batch(mjcffi.MjModel.from_xml_string(CARTPOLE), 8)
    time = b.time
    cases = (([2**32], "in \\[0, 8\\)"), ([0.9], "integers"), ([[0]], "one-dimensional"),
             ([8], "got 8"), ([-1], "got -1"), (np.ones(9, bool), "mask"),
             ([3, 1], "got 3 before 1"), ([2, 2], "sorted and unique"),
             (np.array([2, 1], np.uint32), "sorted"), ("a", "one-dimensional"))
    for ids, message in cases:
        for call in (b.step, b.forward, b.reset, b.set_const,
                     lambda i: b.rollout(1, ids=i), lambda i: b.jac(1, [0, 0, 0], ids=i)):
            with pytest.raises(ValueError, match=message):
                call(ids)
    assert not time.any()
    b.step([])                                          # an empty selection runs nothing
    assert b.rollout(2, ids=[])["qpos"].shape == (0, 2, 2)
    assert not time.any()
    b.step(np.arange(8) % 2 == 0)                       # a mask
    _same(time > 0, np.arange(8) % 2 == 0, "mask")
    b.step(np.array([1, 3], np.uint64))
    b.step()
    assert (time > 0).all()


def test_bad_shapes_name_the_argument_and_the_shape():
    m = mjcffi.MjModel.from_xml_string(CARTPOLE)
    b = batch.Batch(m, 4)
    with pytest.raises(ValueError, match=r"control must have shape \(4, 3, 2\).*\(4, 3, 5\)"):
        b.rollout(3, np.zeros((4, 3, 5)))
    with pytest.raises(ValueError, match=r"control must have shape \(2, 3, 2\)"):
        b.rollout(3, np.zeros((4, 3, 2)), ids=[0, 1])
    with pytest.raises(ValueError, match=r"out\['qpos'\].*\(4, 3, 2\)"):
        b.rollout(3, out={"qpos": np.zeros((4, 3, 3))})
    with pytest.raises(ValueError, match=r"out\['qpos'\]"):
        b.rollout(3, out={"qpos": np.zeros((4, 3, 2), np.float32)})
    with pytest.raises(ValueError, match="nstep"):
        b.rollout(0)
    with pytest.raises(ValueError, match="control_spec"):
        b.rollout(1, np.zeros(3), control_spec=mjcffi.mjtState.mjSTATE_QPOS)
    with pytest.raises(ValueError, match="spec"):
        b.rollout(1, record=(1 << 20,))
    with pytest.raises(ValueError, match=r"point must have shape \(4, 3\)"):
        b.jac(1, np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"geomgroup must have shape \(6,\)"):
        b.ray([0, 0, 0], [0, 0, 1], geomgroup=[1, 1])
    with pytest.raises(ValueError, match="body must be in"):
        b.jac(m.nbody, [0, 0, 0])
    with pytest.raises(ValueError, match="bodyexclude"):
        b.ray([0, 0, 0], [0, 0, 1], bodyexclude=-2)
    for key in (2**32, 0.5, m.nkey, -2):
        with pytest.raises(ValueError, match="keyframe"):
            b.reset(keyframe=key)
    with pytest.raises(ValueError, match=r"keyframe must broadcast to shape \(4,\)"):
        b.reset(keyframe=[0, 1])
    with pytest.raises(ValueError, match=r"cannot assign to ctrl of shape \(4, 2\)"):
        b.ctrl = np.zeros((3, 2))
    with pytest.raises(IndexError, match="got 4"):
        b.error(4)
    with pytest.raises(TypeError):
        b.error("0")


def test_field_name_errors():
    b = batch.Batch(mjcffi.MjModel.from_xml_string(CARTPOLE), 4)
    cases = ((lambda: b.bind("body_mass"), "use expand\\('body_mass'\\)"),
             (lambda: b.bind("timestep"), "use expand\\('opt.timestep'\\)"),
             (lambda: b.bind("efc_force"), "arena"),
             (lambda: b.bind("qpso"), "did you mean 'qpos'"),
             (lambda: b.bind("maxuse_stack"), "scalars bind\\(\\) accepts: nA"),
             (lambda: b.expand("xpos"), "use bind\\('xpos'\\)"),
             (lambda: b.expand("timestep"), "use expand\\('opt.timestep'\\)"),
             (lambda: b.expand("tex_data"), "asset data"),
             (lambda: b.expand("body_mas"), "did you mean 'body_mass'"),
             (lambda: b.expanded("qpos"), "use bind"),
             (lambda: b.rollout(1, record=("qpso",)), "did you mean 'qpos'"),
             (lambda: b.rollout(1, record=("time",)), "mjSTATE_TIME"),
             (lambda: b.rollout(1, record=("efc_J",)), "arena"))
    for call, message in cases:
        with pytest.raises(ValueError, match=message):
            call()
    with pytest.raises(ValueError, match="computed by every call"):
        b.xpos = 0
    with pytest.raises(ValueError, match="read-only"):
        b.xpos[0, 0, 0] = 1
    with pytest.raises(AttributeError, match="use expand\\('body_mass'\\)"):
        _ = b.body_mass
    with pytest.raises(AttributeError):
        _ = b.contact
    with pytest.raises(TypeError):
        b.bind(3)


# -------------------------------------------------------------------- callbacks

def test_python_callbacks_are_refused_and_c_callbacks_run():
    m = mjcffi.MjModel.from_xml_string(CARTPOLE)
    b = batch.Batch(m, 4, 2)
    mjcffi.set_mjcb_control(lambda m, d: None)
    try:
        for call in (b.step, b.forward, b.reset, lambda: b.rollout(1),
                     lambda: b.jac(1, [0, 0, 0]), lambda: batch.Batch(m, 2)):
            with pytest.raises(ValueError, match="mjcb_control"):
                call()
    finally:
        mjcffi.set_mjcb_control(None)
    b.step()
    calls = []
    thunk = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p)(
        lambda m, d: calls.append(1))
    mjcffi.set_mjcb_control(thunk)
    try:
        b.step()
    finally:
        mjcffi.set_mjcb_control(None)
    assert len(calls) == 4


def test_attributes_and_properties():
    m = mjcffi.MjModel.from_xml_string(CARTPOLE)
    b = batch.Batch(m, 4)
    assert b.model is m
    assert b.qpos is b.qpos                              # bound once, then a plain attribute
    assert np.shares_memory(b.qpos, b.state)
    assert b.bind("time").shape == (4,)
    assert b.bind("mocap_quat").shape == (4, 1, 4)
    assert b.bind("xmat").shape == (4, m.nbody, 9)
    assert b.bind("ncon").shape == (4,) and b.bind("ncon").dtype == np.int32
    assert b.eq_active.dtype == np.float64                # rows hold mjtNum
    recorded = b.rollout(1, record=("eq_active",))["eq_active"]
    assert recorded.dtype == mjcffi.MjData(m).eq_active.dtype       # MjData's, in records
    assert b.warning.shape == (4, mjcffi.mjtWarning.mjNWARNING, 2)
    b.ctrl = 0.5
    _same(b.bind("ctrl"), np.full((4, 2), 0.5), "ctrl")
    with pytest.raises(AttributeError):
        b.nsim = 3
    assert "nsim=4" in repr(b)
    with pytest.raises(ValueError, match="read-only"):
        b.status[0] = 1
