"""Bit-exact replay in MjSim: set_state(get_state()) brings back what the next steps
depend on (the solver's warm start, delay buffers), while MjSimState keeps mujoco-py's
five fields, constructor, flat layout and equality."""

import copy
import pickle

import numpy as np
import pytest

from mjcffi.sim import MjSim, MjSimState, load_model_from_path, load_model_from_xml

from .conftest import gymnasium_assets

STEPS = 50

# a box and a capsule on the floor, an activation (filter) actuator and a delayed one:
# contacts, act and a history buffer, all of which the next steps depend on
_ACT_AND_DELAY = """
<mujoco>
  <worldbody>
    <geom type="plane" size="2 2 .1"/>
    <body pos="0 0 .1">
      <freejoint/>
      <geom type="box" size=".1 .1 .1"/>
    </body>
    <body pos=".3 0 .1">
      <joint name="slide" type="slide" axis="1 0 0"/>
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom type="capsule" size=".05" fromto="0 0 0 0 0 .3"/>
    </body>
  </worldbody>
  <actuator>
    <general joint="slide" dyntype="filter" dynprm=".05" gainprm="20"/>
    <motor joint="hinge" gear="5" nsample="3" delay=".006"/>
  </actuator>
</mujoco>
"""


def _humanoid():
    path = next(p for p in gymnasium_assets() if p.name == "humanoid.xml")
    return load_model_from_path(path)


def _model(name):
    return _humanoid() if name == "humanoid" else load_model_from_xml(_ACT_AND_DELAY)


def _controls(model, count, seed=0):
    return np.random.default_rng(seed).uniform(-0.4, 0.4, (count, model.nu))


def _run(sim, controls):
    """Step once per row of controls; each step's qpos, qvel, act and qacc_warmstart,
    as bytes (bit-identical or not)."""
    d = sim.data
    trace = []
    for ctrl in controls:
        d.ctrl[:] = ctrl
        sim.step()
        trace.append(b"".join(np.ascontiguousarray(a).tobytes()
                              for a in (d.time, d.qpos, d.qvel, d.act, d.qacc_warmstart)))
    return trace


def _snapshot_and_reference(model):
    """A sim after 100 steps in contact, its state then, and the 50 uninterrupted steps
    after that state."""
    sim = MjSim(model)
    controls = _controls(model, 100 + STEPS)
    _run(sim, controls[:100])
    assert sim.data.ncon > 0            # the solver and its warm start are in play
    state = sim.get_state()
    return sim, state, controls[100:], _run(sim, controls[100:])


@pytest.mark.parametrize("name", ["humanoid", "act_and_delay"])
def test_set_state_of_get_state_replays_bit_for_bit(name):
    sim, state, controls, reference = _snapshot_and_reference(_model(name))
    assert state.extra is not None and state.extra.dtype == np.float64
    # the sim has moved on (its warm start, act and history with it); go back
    _run(sim, _controls(sim.model, 7, seed=1))
    sim.set_state(state)
    assert _run(sim, controls) == reference


def test_the_extra_is_what_makes_it_exact():
    # the humanoid's extra is its qacc_warmstart (it has no history, plastic or plugin
    # state); the same state without it is not exact: the sim keeps the warm start of
    # where it was, not of the state
    model = _humanoid()
    sim = MjSim(model)
    _run(sim, _controls(model, 100))
    state = sim.get_state()
    assert state.extra.tobytes() == sim.data.qacc_warmstart.tobytes()
    controls = _controls(model, STEPS, seed=2)
    reference = _run(sim, controls)
    bare = MjSimState(*state)
    assert bare.extra is None and bare == state
    sim.set_state(bare)
    assert _run(sim, controls) != reference
    sim.set_state(state)
    assert _run(sim, controls) == reference


@pytest.mark.parametrize("name", ["humanoid", "act_and_delay"])
def test_pickled_state_replays_bit_for_bit_in_a_fresh_sim(name):
    model = _model(name)
    _, state, controls, reference = _snapshot_and_reference(model)
    for again in (pickle.loads(pickle.dumps(state)), copy.deepcopy(state), copy.copy(state)):
        assert type(again) is MjSimState and again == state
        assert again.extra.tobytes() == state.extra.tobytes()
        fresh = MjSim(model)
        fresh.set_state(again)
        assert _run(fresh, controls) == reference


def test_hand_made_state_sets_and_steps_as_before():
    sim, state, controls, _ = _snapshot_and_reference(_humanoid())
    hand = MjSimState(state.time, state.qpos.copy(), state.qvel.copy(), None, {})
    assert hand.extra is None
    warm = sim.data.qacc_warmstart.copy()
    sim.set_state(hand)
    # mujoco-py's set_state: the five fields written, the warm start left as it was
    assert sim.get_state() == hand and sim.data.time == state.time
    np.testing.assert_array_equal(sim.data.qacc_warmstart, warm)
    _run(sim, controls)
    assert np.isfinite(sim.data.qpos).all() and sim.data.time > state.time


def test_flattened_layout_is_mujoco_py_and_not_exact_with_contacts():
    model = _humanoid()
    sim, state, controls, reference = _snapshot_and_reference(model)
    flat = state.flatten()
    # mujoco-py's layout: time, qpos, qvel (act none, udd_state empty); no extra
    assert flat.tobytes() == np.concatenate([[state.time], state.qpos, state.qvel]).tobytes()
    again = MjSimState.from_flattened(flat, sim)
    assert again == state and again.extra is None
    assert again.flatten().tobytes() == flat.tobytes()
    # the flat form lacks the warm start: the replay leaves the uninterrupted run
    # (by the solver's tolerance at first, then as the humanoid's dynamics spread it)
    for restore in (lambda: sim.set_state(again), lambda: sim.set_state_from_flattened(flat)):
        restore()
        assert _run(sim, controls) != reference
    # one step after each: apart, but only by about the solver's tolerance
    exact, rough = MjSim(model), MjSim(model)
    exact.set_state(state)
    rough.set_state_from_flattened(flat)
    for one in (exact, rough):
        one.data.ctrl[:] = controls[0]
        one.step()
    difference = np.abs(exact.data.qpos - rough.data.qpos).max()
    assert 0 < difference < 1e-6


def test_five_fields_repr_and_replace_stay_mujoco_py():
    sim = MjSim(load_model_from_xml(_ACT_AND_DELAY))
    state = sim.get_state()
    assert len(state) == 5 and MjSimState._fields == ("time", "qpos", "qvel", "act", "udd_state")
    time, qpos, qvel, act, udd_state = state
    assert act.shape == (1,) and udd_state == {}
    assert "extra" not in repr(state) and repr(state).startswith("MjSimState(time=")
    moved = state._replace(qpos=state.qpos + 0.01)
    assert moved.extra is None and moved != state
    with pytest.raises(AttributeError):
        state.extra = None              # a state is a value


def test_extra_of_another_model_is_refused_before_anything_is_written():
    sim = MjSim(load_model_from_xml(_ACT_AND_DELAY))
    state = sim.get_state()
    wrong = MjSimState(*state, extra=np.zeros(state.extra.size + 1))
    sim.data.qpos[0] = 0.5
    with pytest.raises(ValueError, match="extra has shape"):
        sim.set_state(wrong)
    assert sim.data.qpos[0] == 0.5
    with pytest.raises(ValueError, match="extra has shape"):
        sim.set_state(MjSimState(*state, extra=np.zeros((1, state.extra.size))))
