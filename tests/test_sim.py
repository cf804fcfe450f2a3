"""mjcffi.sim, the mujoco-py interface: MjSim, MjSimState, MjSimPool, save, warnings."""

import io

import numpy as np
import pytest

import mjcffi
from mjcffi import scenes
from mjcffi.sim import (MjSim, MjSimPool, MjSimState, MujocoException, SimData, SimModel,
                        ignore_mujoco_warnings, load_model_from_mjb, load_model_from_path,
                        load_model_from_xml)

from .conftest import gymnasium_assets


def _humanoid_path():
    return next(p for p in gymnasium_assets() if p.name == "humanoid.xml")


def _humanoid_sim(seed, nsubsteps=1):
    sim = MjSim(load_model_from_path(_humanoid_path()), nsubsteps=nsubsteps)
    rng = np.random.default_rng(seed)
    sim.data.qpos[:] += rng.uniform(-0.05, 0.05, sim.model.nq)
    sim.data.ctrl[:] = rng.uniform(-0.4, 0.4, sim.model.nu)
    return sim


def test_mujoco_py_script():
    # a mujoco-py example, unchanged but for its import
    MODEL_XML = """
    <?xml version="1.0" ?>
    <mujoco>
        <worldbody>
            <body name="box" pos="0 0 0.2">
                <geom size="0.15 0.15 0.15" type="box"/>
                <joint axis="1 0 0" name="box:x" type="slide"/>
                <joint axis="0 1 0" name="box:y" type="slide"/>
            </body>
            <body name="floor" pos="0 0 0.025">
                <geom size="1.0 1.0 0.02" rgba="0 1 0 1" type="box"/>
            </body>
        </worldbody>
        <actuator>
            <motor gear="2000.0" joint="box:x"/>
            <motor gear="2000.0" joint="box:y"/>
        </actuator>
    </mujoco>
    """.strip()
    model = load_model_from_xml(MODEL_XML)
    sim = MjSim(model)
    t = 0
    start = sim.get_state()
    for _ in range(200):
        sim.data.ctrl[0] = np.cos(t / 10.) * 0.01
        sim.data.ctrl[1] = np.sin(t / 10.) * 0.01
        t += 1
        sim.step()
    assert sim.data.time == pytest.approx(200 * model.opt.timestep)
    assert np.abs(sim.data.qpos).max() > 1e-3
    flat = sim.get_state().flatten()
    sim.set_state(start)
    assert sim.data.time == 0 and not sim.data.qpos.any()
    sim.set_state_from_flattened(flat)
    np.testing.assert_array_equal(sim.get_state().flatten(), flat)
    assert model._xml == MODEL_XML
    assert isinstance(model, SimModel) and isinstance(sim.data, SimData)


def test_loaders(tmp_path):
    model = load_model_from_path(_humanoid_path())
    mjb = model.to_bytes()
    (tmp_path / "h.mjb").write_bytes(mjb)
    for other in (load_model_from_mjb(mjb), load_model_from_mjb(tmp_path / "h.mjb"),
                  load_model_from_path(tmp_path / "h.mjb")):
        assert isinstance(other, SimModel) and other.to_bytes() == mjb


def test_state_round_trip_and_trajectory():
    sim = MjSim(load_model_from_xml(scenes.PENDULUM), nsubsteps=3)
    sim.data.qpos[0] = 1.0
    for _ in range(5):
        sim.step()
    state = sim.get_state()
    flat = state.flatten()
    again = MjSimState.from_flattened(flat, sim)
    assert again.time == state.time and again.act is None
    np.testing.assert_array_equal(again.qpos, state.qpos)
    np.testing.assert_array_equal(again.qvel, state.qvel)
    assert again.flatten().tobytes() == flat.tobytes()
    # the state is a copy
    sim.data.qpos[0] = 7.0
    assert state.qpos[0] != 7.0
    sim.set_state(state)
    uninterrupted = []
    for _ in range(20):
        sim.step()
        uninterrupted.append(sim.get_state().flatten())
    for restore in (lambda: sim.set_state(state), lambda: sim.set_state_from_flattened(flat)):
        restore()
        for expected in uninterrupted:
            sim.step()
            assert sim.get_state().flatten().tobytes() == expected.tobytes()


def test_nsubsteps_and_given_data():
    model = load_model_from_xml(scenes.DEFAULT)
    data = mjcffi.MjData(model)
    sim = MjSim(model, data=data, nsubsteps=4)
    assert sim.data is data
    reference = mjcffi.MjData(model)
    sim.step()
    mjcffi.mj_step(model, reference, 4)
    np.testing.assert_array_equal(sim.data.qpos, reference.qpos)
    sim.forward()
    sim.reset()
    assert sim.data.time == 0
    with pytest.raises(ValueError, match="mode must be 'offscreen' or 'window'"):
        sim.render(64, 64, mode="screen")     # offscreen: tests/test_sim_render.py;
    # mode='window' (an MjViewer): tests/test_simviewer.py


def test_pool_matches_single_sims():
    nsims, nsubsteps, calls = 5, 3, 4
    pool = MjSimPool([_humanoid_sim(i) for i in range(nsims)], nsubsteps=nsubsteps)
    alone = [_humanoid_sim(i) for i in range(nsims)]
    for _ in range(calls):
        pool.step()
    for sim in alone:
        for _ in range(calls):
            mjcffi.mj_step(sim.model, sim.data, nsubsteps)
    for ours, ref in zip(pool.sims, alone):
        assert ours.data.time == ref.data.time
        for field in ("qpos", "qvel", "qacc", "sensordata", "qacc_warmstart"):
            assert getattr(ours.data, field).tobytes() == getattr(ref.data, field).tobytes()
    # only the first nsims step
    before = [s.data.time for s in pool.sims]
    pool.step(nsims=2)
    assert [s.data.time > b for s, b in zip(pool.sims, before)] == [True, True, False, False,
                                                                      False]
    pool.forward()
    pool.reset(nsims=3)
    assert [s.data.time for s in pool.sims[:3]] == [0, 0, 0]
    pool.close()


def test_pool_create_from_sim():
    sim = MjSim(load_model_from_xml(scenes.DEFAULT), nsubsteps=2)
    pool = MjSimPool.create_from_sim(sim, 3)
    assert pool.nsims == 3 and pool.nsubsteps == 2
    assert all(s.model is not sim.model and s.model.nq == sim.model.nq for s in pool.sims)
    pool.step()
    times = {s.data.time for s in pool.sims}
    assert times == {2 * sim.model.opt.timestep}
    pool.close()


@pytest.mark.parametrize("source", ["string", "path"])
@pytest.mark.parametrize("fmt", ["xml", "mjb"])
def test_save_and_reload_keyframe(tmp_path, source, fmt):
    if source == "string":
        sim = MjSim(load_model_from_xml(scenes.DEFAULT))
    else:
        sim = _humanoid_sim(3)
    for _ in range(30):
        sim.step()
    assert sim.data.qvel.any()
    target = tmp_path / f"saved.{fmt}"
    with open(target, "w" if fmt == "xml" else "wb") as f:
        sim.save(f, format=fmt)
    model = load_model_from_path(target)
    data = mjcffi.MjData(model)
    mjcffi.mj_resetDataKeyframe(model, data, model.key("saved_state").id)
    assert data.time == sim.data.time
    assert data.qpos.tobytes() == sim.data.qpos.tobytes()
    assert data.qvel.tobytes() == sim.data.qvel.tobytes()
    assert model.nq == sim.model.nq and model.nbody == sim.model.nbody
    np.testing.assert_array_equal(model.body_mass, sim.model.body_mass)


def test_save_binary_buffer():
    sim = MjSim(load_model_from_xml(scenes.DEFAULT))
    sim.step()
    buffer = io.BytesIO()
    sim.save(buffer, format="mjb")
    model = load_model_from_mjb(buffer.getvalue())
    assert model.nkey == sim.model.nkey + 1
    with pytest.raises(ValueError, match="format"):
        sim.save(buffer, format="json")


def _bad_sim():
    sim = MjSim(load_model_from_xml(scenes.PENDULUM))
    sim.data.qvel[0] = np.nan
    return sim


def test_warning_raises_mujoco_exception():
    sim = _bad_sim()
    with pytest.raises(MujocoException, match="unstable") as info:
        sim.step()
    assert isinstance(info.value, mjcffi.MjWarningError)
    assert info.value.warning == mjcffi.mjtWarning.mjWARN_BADQVEL
    # counted once, as MuJoCo counts it
    assert sim.data.warning[int(mjcffi.mjtWarning.mjWARN_BADQVEL)].number == 1
    sim = _bad_sim()
    sim.data.ctrl[0] = np.nan
    with pytest.raises(MujocoException, match="ctrl"):
        sim.forward()


def test_ignore_mujoco_warnings():
    sim = _bad_sim()
    with ignore_mujoco_warnings():
        sim.step()
        sim.step()
    assert sim.data.warning[int(mjcffi.mjtWarning.mjWARN_BADQVEL)].number == 1
    assert np.isfinite(sim.data.qvel).all()      # MuJoCo reset it
    sim.step()                                    # no new warning: no error


def test_plain_mj_step_does_not_raise():
    sim = _bad_sim()
    mjcffi.mj_step(sim.model, sim.data)          # the switch is per MjSim, not global


def test_udd_callback_and_state():
    calls = []

    def udd(sim):
        calls.append(sim.data.time)
        return {"energy": float(sim.data.qvel @ sim.data.qvel), "hist": sim.data.qpos.copy()}

    sim = MjSim(load_model_from_xml(scenes.PENDULUM), udd_callback=udd)
    assert len(calls) == 1 and set(sim.udd_state) == {"energy", "hist"}
    sim.data.qpos[0] = 0.5
    for _ in range(3):
        sim.step()
    assert len(calls) == 4
    state = sim.get_state()
    flat = state.flatten()
    assert flat.size == 1 + sim.model.nq + sim.model.nv + 1 + sim.model.nq
    again = MjSimState.from_flattened(flat, sim)
    assert again.udd_state["energy"] == state.udd_state["energy"]
    np.testing.assert_array_equal(again.udd_state["hist"], state.udd_state["hist"])
    sim.step()
    sim.set_state(state)
    assert sim.udd_state["energy"] == state.udd_state["energy"]
    assert sim.udd_state is not state.udd_state
    sim.step(with_udd=False)
    assert len(calls) == 5
    sim.reset()
    assert len(calls) == 6 and sim.udd_state["hist"][0] == 0

    def unstable(sim):
        return {"a": 1.0} if sim.data.time == 0 else {"b": 1.0}

    sim = MjSim(load_model_from_xml(scenes.PENDULUM), udd_callback=unstable)
    sim.step()
    with pytest.raises(ValueError, match="keys"):
        sim.step()
    sim = MjSim(load_model_from_xml(scenes.PENDULUM),
                udd_callback=lambda s: {"x": np.zeros(1 + int(s.data.time > 0))})
    sim.step()
    with pytest.raises(ValueError, match="shape"):
        sim.step()


# nq 8 != nv 7 (a free joint and a hinge); na 2 (a filter and an integrator actuator)
_FREE_AND_ACTIVATION = """
<mujoco>
  <worldbody>
    <body name="ball" pos="0 0 .5"><freejoint/><geom size=".1"/></body>
    <body name="arm" pos="1 0 1">
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -.4" size=".04"/>
    </body>
  </worldbody>
  <actuator>
    <general joint="hinge" dyntype="filter" dynprm=".1"/>
    <general joint="hinge" dyntype="integrator"/>
  </actuator>
</mujoco>
"""


def test_item_flatten_layout_is_mujoco_pys_value_by_value():
    # mujoco-py: [time] + qpos + qvel + act + the udd_state values, keys sorted,
    # arrays raveled.  Every value is distinct, so a swap of any two parts shows.
    sim = MjSim(load_model_from_xml(_FREE_AND_ACTIVATION),
                udd_callback=lambda s: {"zeta": np.array([[70.0, 71.0]]), "alpha": 60.0})
    m, d = sim.model, sim.data
    assert (m.nq, m.nv, m.na) == (8, 7, 2)
    d.time = 0.5
    d.qpos[:] = 10 + np.arange(m.nq)
    d.qvel[:] = 20 + np.arange(m.nv)
    d.act[:] = 30 + np.arange(m.na)
    state = sim.get_state()
    flat = state.flatten()
    expected = [0.5,
                10, 11, 12, 13, 14, 15, 16, 17,        # qpos: 7 of the free joint, 1 hinge
                20, 21, 22, 23, 24, 25, 26,            # qvel: 6 + 1
                30, 31,                                # act
                60.0,                                  # udd_state["alpha"]
                70.0, 71.0]                            # udd_state["zeta"], raveled
    assert flat.dtype == np.float64 and flat.tolist() == expected
    again = MjSimState.from_flattened(flat, sim)
    assert again.time == 0.5
    assert again.qpos.tolist() == expected[1:9] and again.qvel.tolist() == expected[9:16]
    assert again.act.tolist() == [30, 31] and again.udd_state["alpha"] == 60.0
    assert again.udd_state["zeta"].tolist() == [[70.0, 71.0]]       # its shape back
    # and into a sim: each part lands in its own field
    d.qpos[:], d.qvel[:], d.act[:], d.time = 0, 0, 0, 0
    sim.set_state_from_flattened(flat)
    assert d.time == 0.5 and d.qpos.tolist() == expected[1:9]
    assert d.qvel.tolist() == expected[9:16] and d.act.tolist() == [30, 31]
    with pytest.raises(ValueError, match="21 numbers, not 20"):
        MjSimState.from_flattened(flat[:-1], sim)


# -- mujoco-py's udd_state rules, state equality and copies

def test_udd_state_must_keep_its_form():
    from mjcffi.sim._sim import UddStateError
    model = load_model_from_xml(scenes.PENDULUM)
    returned = {}
    sim = MjSim(model, udd_callback=lambda s: returned)
    sim.step()                                      # {} after {}: no keys, no change
    assert sim.udd_state == {}
    returned = {"extra": 1.0}
    with pytest.raises(UddStateError, match="keys"):
        sim.step()
    returned = {"n": 10, "v": np.array([1.0, 2.0])}
    sim.udd_callback = lambda s: returned           # a new callback: a new form
    assert sim.udd_state["n"] == 10
    returned = {"n": 11.5, "v": np.array([3.0, 4.0])}       # any number for a number
    sim.step()
    assert sim.udd_state["n"] == 11.5
    bad = [{"n": 1}, {"n": 1, "v": np.zeros(2), "w": 1},
           {"n": 1, "v": np.zeros(3)}, {"n": "haha", "v": np.zeros(2)},
           {"n": 1, "v": [0.0, 0.0]}, {"n": np.zeros(1), "v": np.zeros(2)}]
    for returned in bad:
        with pytest.raises(UddStateError) as info:
            sim.step()
        assert isinstance(info.value, AssertionError) and isinstance(info.value, ValueError)
    returned = {"other": 1.0}
    sim.reset()                                     # reset starts the form again
    assert sim.udd_state == {"other": 1.0}
    sim.udd_callback = None
    assert sim.udd_state == {}
    with pytest.raises(TypeError, match="udd_callback must be callable"):
        sim.udd_callback = 3


def test_state_equality_act_and_defensive_copies():
    sim = MjSim(load_model_from_xml(scenes.PENDULUM),
                udd_callback=lambda s: {"a": np.array([1.0, 2.0]), "b": 3})
    state = sim.get_state()
    assert state.act is None and sim.model.na == 0
    assert state == sim.get_state() and not state != sim.get_state()
    assert state != state._replace(udd_state={"a": np.array([1.0, 2.0])})
    assert state != state._replace(udd_state={"a": np.array([1.0, 2.5]), "b": 3})
    assert state != state._replace(qvel=state.qvel + 1)
    assert state != state._replace(act=np.zeros(0))
    assert state.__eq__((1, 2)) is NotImplemented
    with pytest.raises(TypeError):
        hash(state)
    sim.set_state(state)
    state.qpos[0] = -1
    state.udd_state["a"][0] = -1
    assert sim.data.qpos[0] != -1 and sim.udd_state["a"][0] == 1.0
    copy = sim.get_state()
    copy.qpos[0] = -2
    copy.udd_state["a"][1] = -2
    assert sim.data.qpos[0] != -2 and sim.udd_state["a"][1] == 2.0
    flat = sim.get_state().flatten()
    assert flat.tolist() == [0.0, *sim.data.qpos, *sim.data.qvel, 1.0, 2.0, 3.0]
    assert MjSimState.from_flattened(flat, sim) == sim.get_state()


def test_set_state_needs_act_when_the_model_has_some():
    sim = MjSim(load_model_from_xml(_FREE_AND_ACTIVATION))
    state = sim.get_state()
    assert state.act.shape == (2,)
    with pytest.raises(ValueError, match="no act"):
        sim.set_state(state._replace(act=None))


# -- ray casting, as mujoco-py's TestRay

_RAYS = """
<mujoco>
  <worldbody>
    <geom name="A" type="sphere" size=".1" pos="1 0 0"/>
    <body name="M">
      <body name="N"><geom name="B" type="sphere" size=".1" pos="3 0 0" group="2"/></body>
      <geom name="C" type="sphere" size=".1" pos="5 0 0"/>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.mark.parametrize("options, expected", [
    ({}, "A A B B C C -"),
    ({"exclude_body": 0}, "B B B B C C -"),
    ({"exclude_body": 1}, "A A B B - - -"),
    ({"exclude_body": 2}, "A A C C C C -"),
    ({"include_static_geoms": False}, "B B B B C C -"),
    ({"include_static_geoms": False, "exclude_body": 1}, "B B B B - - -"),
    ({"include_static_geoms": False, "exclude_body": 2}, "C C C C C C -"),
    ({"group_filter": [1, 1, 0, 1, 1, 1]}, "A A C C C C -"),
    ({"group_filter": np.array([0, 0, 1, 0, 0, 0], bool)}, "B B B B - - -"),
])
def test_ray_exclusions_as_mujoco_py(options, expected):
    sim = MjSim(load_model_from_xml(_RAYS))
    sim.forward()
    names = {-1: "-"}
    names.update({i: sim.model.geom(i).name for i in range(sim.model.ngeom)})
    centres = {"A": 1, "B": 3, "C": 5}
    for x, want in enumerate(expected.split()):
        distance, geom = sim.ray([x, 0, 0], np.array([1.0, 0, 0]), **options)
        assert names[geom] == want, (x, options)
        if want == "-":
            assert distance == -1.0
        else:    # from a sphere's centre, its surface is 0.1 ahead
            centre = centres[want]
            assert distance == pytest.approx(centre - 0.1 - x if x < centre else 0.1)
        assert isinstance(distance, float) and isinstance(geom, int)


def test_ray_geom_by_geom_agrees_with_mj_ray():
    from mjcffi.sim._ray import _ray, _ray_each_geom
    sim = MjSim(load_model_from_path(_humanoid_path()))
    sim.forward()
    rng = np.random.default_rng(5)
    hits = 0
    for _ in range(60):
        pnt = rng.uniform(-1, 1, 3) + [0, 0, 1.2]
        vec = rng.normal(size=3)
        body = int(rng.integers(-1, sim.model.nbody))
        groups = None if rng.random() < 0.5 else (rng.random(6) < 0.7).astype(np.uint8)
        expected = _ray(sim.model, sim.data, pnt, vec, groups, body)
        got = _ray_each_geom(sim.model, sim.data, pnt, vec, groups, (body,))
        assert got[1] == expected[1]
        assert got[0] == pytest.approx(expected[0])
        hits += expected[1] >= 0
    assert hits > 10


def test_ray_bad_input_names_the_problem():
    sim = MjSim(load_model_from_xml(_RAYS))
    with pytest.raises(ValueError, match="pnt must be 3 numbers"):
        sim.ray([0, 0], [1, 0, 0])
    with pytest.raises(TypeError, match="vec must be 3 numbers"):
        sim.ray([0, 0, 0], ["x", 0, 0])
    with pytest.raises(ValueError, match="exclude_body must be a body id from 0 to 2"):
        sim.ray([0, 0, 0], [1, 0, 0], exclude_body=3)
    with pytest.raises(TypeError, match="exclude_body must be an int"):
        sim.ray([0, 0, 0], [1, 0, 0], exclude_body=1.0)
    with pytest.raises(ValueError, match="group_filter must hold 6"):
        sim.ray([0, 0, 0], [1, 0, 0], group_filter=[1, 1])
    with pytest.raises(TypeError, match="group_filter must hold booleans"):
        sim.ray([0, 0, 0], [1, 0, 0], group_filter=[0.5] * 6)


# -- mujoco-py's error and warning callbacks

def test_error_callback_gets_bytes_and_may_raise():
    from mjcffi.sim import _callbacks
    got = []

    def keep(message):
        got.append(message)

    try:
        with pytest.raises(mjcffi.FatalError, match="boom"):
            _callbacks.handle_fatal(mjcffi.FatalError("boom"))      # no callback: re-raised
        _callbacks.set_error_callback(keep)
        assert _callbacks.get_error_callback() is keep
        with _callbacks.wrap_mujoco_warning():
            mjcffi.mju_error("error")       # handled: the block goes on
        assert got == [b"error"]

        def fail(message):
            raise RuntimeError(message.decode())

        _callbacks.set_error_callback(fail)
        with pytest.raises(RuntimeError, match="^error$"):
            with _callbacks.wrap_mujoco_warning():
                mjcffi.mju_error("error")
        sim = MjSim(load_model_from_xml(scenes.PENDULUM), substep_callback="""
            void fun(const mjModel* m, mjData* d) { mju_error("from the substep"); }""")
        with pytest.raises(RuntimeError, match="from the substep"):
            sim.step()
        with pytest.raises(TypeError, match="callable or None"):
            _callbacks.set_error_callback("print")
    finally:
        _callbacks.set_error_callback(None)
    with pytest.raises(mjcffi.FatalError, match="from the substep"):
        sim.step()


def test_warning_callback_gets_bytes_and_its_error_comes_out():
    from mjcffi.sim import _callbacks
    got = []

    def keep(message):
        got.append(message)

    try:
        _callbacks.set_warning_callback(keep)
        mjcffi.mju_warning("look out")
        assert got == [b"look out"]
        assert _callbacks.get_warning_callback() is keep

        def fail(message):
            raise RuntimeError(message)

        _callbacks.set_warning_callback(fail)
        with pytest.raises(RuntimeError, match="b'again'"):
            with _callbacks.wrap_mujoco_warning():
                mjcffi.mju_warning("again")
    finally:
        _callbacks.set_warning_callback(None)
    assert _callbacks.get_warning_callback() is None
    assert mjcffi.get_mju_user_warning() is None


def test_add_render_context_needs_a_render_context():
    sim = MjSim(load_model_from_xml(scenes.PENDULUM))
    with pytest.raises(TypeError, match="must be an MjRenderContext"):
        sim.add_render_context(object())
    assert sim.render_contexts == [] and sim.extras == {}
