"""The state setters of mjcffi.sim check every part of a state before they write any
(issue 27, finding 5): a part that does not fit the model, or is no array of real
numbers, is refused with MjData left bit for bit as it was, and the udd_state too.

Sizes must match exactly (no numpy broadcasting of a length-1 act or qpos); a time
mujoco-py took (an int, a NaN) is still taken.  mj_setState's own checks are tested
at the end: size and signature are refused before anything is written."""

import copy
import math
import threading
import warnings

import numpy as np
import pytest

import mjcffi
from mjcffi._support.library import ffi
from mjcffi.sim import MjSim, MjSimState, load_model_from_path, load_model_from_xml

from .conftest import gymnasium_assets

INTEGRATION = int(mjcffi.mjtState.mjSTATE_INTEGRATION)
NSTATE = int(mjcffi.mjtState.mjNSTATE)

# two hinges with an activation each (filter, integrator: na = 2), a delayed motor
# (a history buffer in `extra`) and a floor the lower link hits (contacts, warm start)
_TWO_ACT = """
<mujoco>
  <worldbody>
    <geom type="plane" size="2 2 .1"/>
    <body pos="0 0 .5">
      <joint name="a" type="hinge" axis="0 1 0"/>
      <geom type="capsule" size=".05" fromto="0 0 0 .3 0 0"/>
      <body pos=".3 0 0">
        <joint name="b" type="hinge" axis="0 1 0"/>
        <geom type="capsule" size=".05" fromto="0 0 0 0 0 -.5"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <general joint="a" dyntype="filter" dynprm=".05" gainprm="5"/>
    <general joint="b" dyntype="integrator" gainprm="2"/>
    <motor joint="b" gear="2" nsample="3" delay=".006"/>
  </actuator>
</mujoco>
"""


def _udd(sim):
    udd = getattr(sim, "udd_state", None)      # none yet when the sim is made
    count = udd["count"] + 1 if udd else 0
    return {"count": count, "trace": np.array([[float(count), sim.data.time]])}


def _two_act_sim():
    sim = MjSim(load_model_from_xml(_TWO_ACT), udd_callback=_udd)
    assert (sim.model.nq, sim.model.nv, sim.model.na) == (2, 2, 2)
    sim.data.ctrl[:] = [0.7, -0.4, 0.3]
    for _ in range(30):
        sim.step()
    assert np.all(sim.data.act != 0) and np.any(sim.data.qacc_warmstart != 0)
    return sim


def _ant_sim():
    path = next(p for p in gymnasium_assets() if p.name == "ant.xml")
    sim = MjSim(load_model_from_path(str(path)))
    assert sim.model.na == 0
    sim.data.ctrl[:] = 0.3
    for _ in range(10):
        sim.step()
    return sim


# -- what "unchanged" means: MjData bit for bit, and the udd_state

def _raw(d):
    """The bytes of d's struct, its buffer and the used part of its arena."""
    p = d._ptr
    return (bytes(ffi.buffer(p, ffi.sizeof("mjData"))), bytes(ffi.buffer(p.buffer, p.nbuffer)),
            bytes(ffi.buffer(p.arena, p.parena)))


def _integration(m, d):
    state = np.empty(mjcffi.mj_stateSize(m, INTEGRATION))
    mjcffi.mj_getState(m, d, state, INTEGRATION)
    return state


def _array(view):
    """A copy of a SimData array (None for an empty one, as in mujoco-py: then empty)."""
    return np.zeros(0) if view is None else view.copy()


def _snapshot(sim):
    d = sim.data
    return {"time": np.float64(d.time).tobytes(), "qpos": d.qpos.copy(), "qvel": d.qvel.copy(),
            "act": _array(d.act), "qacc_warmstart": d.qacc_warmstart.copy(),
            "integration": _integration(sim.model, d), "raw": _raw(d),
            "udd_state": sim.udd_state, "udd_copy": copy.deepcopy(sim.udd_state)}


def _assert_unchanged(sim, before):
    after = _snapshot(sim)
    assert after["time"] == before["time"]
    for name in ("qpos", "qvel", "act", "qacc_warmstart", "integration"):
        assert np.array_equal(after[name], before[name], equal_nan=True), name
        assert after[name].tobytes() == before[name].tobytes(), name
    assert after["raw"] == before["raw"], "MjData changed"
    assert sim.udd_state is before["udd_state"], "udd_state replaced"
    _assert_same_udd(sim.udd_state, before["udd_copy"])


def _assert_same_udd(udd, expected):
    assert set(udd) == set(expected)
    for key, value in expected.items():
        assert type(udd[key]) is type(value) and np.array_equal(udd[key], value), key


def _refused(sim, call, error, match):
    before = _snapshot(sim)
    with warnings.catch_warnings():
        warnings.simplefilter("error")        # no ComplexWarning standing in for a refusal
        with pytest.raises(error, match=match):
            call()
    _assert_unchanged(sim, before)


class _Uncopyable:
    def __deepcopy__(self, memo):
        raise TypeError("this udd value cannot be copied")


# -- MjSim.set_state: (label, how to spoil a good state, exception, message)

def _with(**parts):
    return lambda state: state._replace(**parts)


def _extra(make):
    return lambda state: MjSimState(*state, extra=make(state.extra))


_BAD_ACT = [
    # the reproducers of finding 5
    ("act too long (time/qpos/qvel were written first)",
     lambda s: s._replace(act=np.r_[s.act, 1.0]), ValueError, r"act.*\(3,\).*\(2,\)"),
    ("act of length 1 broadcast into na=2",
     lambda s: s._replace(act=s.act[:1] + 1), ValueError, r"act.*\(1,\).*\(2,\)"),
    ("act empty", _with(act=np.zeros(0)), ValueError, r"act.*\(0,\).*\(2,\)"),
    ("act 2-D (1, 2)", lambda s: s._replace(act=s.act[None] + 1), ValueError,
     r"act.*\(1, 2\).*\(2,\)"),
    ("act 2-D (2, 1)", lambda s: s._replace(act=s.act[:, None] + 1), ValueError,
     r"act.*\(2, 1\).*\(2,\)"),
    ("act scalar", _with(act=1.0), ValueError, r"act.*\(\).*\(2,\)"),
    ("act None", _with(act=None), ValueError, "no act"),
    ("act of strings", _with(act=np.array(["1", "2"])), TypeError, "act"),
    ("act as a list of strings", _with(act=["1", "2"]), TypeError, "act"),
    ("act complex", lambda s: s._replace(act=s.act + 1j), TypeError, "act"),
    ("act ragged", _with(act=[1.0, [2.0, 3.0]]), ValueError, "act"),
]

_BAD_ANY = [
    ("qpos too short", lambda s: s._replace(qpos=s.qpos[:-1] + 1), ValueError,
     r"qpos.*\(\d+,\).*\(\d+,\)"),
    ("qpos too long", lambda s: s._replace(qpos=np.r_[s.qpos, 1.0]), ValueError, "qpos"),
    ("qpos of length 1", lambda s: s._replace(qpos=s.qpos[:1] + 1), ValueError, "qpos"),
    ("qpos 2-D", lambda s: s._replace(qpos=s.qpos[None] + 1), ValueError, "qpos"),
    ("qvel too short", lambda s: s._replace(qvel=s.qvel[:-1] + 1), ValueError,
     r"qvel.*\(\d+,\).*\(\d+,\)"),
    ("qvel too long", lambda s: s._replace(qvel=np.r_[s.qvel, 1.0]), ValueError, "qvel"),
    ("qvel 2-D", lambda s: s._replace(qvel=s.qvel[:, None] + 1), ValueError, "qvel"),
    ("qpos of strings", lambda s: s._replace(qpos=(s.qpos + 1).astype(str)), TypeError, "qpos"),
    ("qvel of objects", lambda s: s._replace(qvel=[None] * s.qvel.size), TypeError, "qvel"),
    ("qvel complex", lambda s: s._replace(qvel=s.qvel + 0j), TypeError, "qvel"),
    ("qpos None", _with(qpos=None), TypeError, "qpos"),
    ("time a string", _with(time="1.5"), TypeError, "time"),
    ("time complex", _with(time=1 + 1j), TypeError, "time"),
    ("time None", _with(time=None), TypeError, "time"),
    ("time an array of one", _with(time=np.array([1.5])), ValueError, "time"),
    ("time beyond a double", _with(time=10**400), ValueError, "time"),
    ("extra too long", _extra(lambda e: np.r_[e, 1.0]), ValueError, "extra has shape"),
    ("extra too short", _extra(lambda e: e[:-1] + 1), ValueError, "extra has shape"),
    ("extra 2-D", _extra(lambda e: e[None] + 1), ValueError, "extra has shape"),
    ("extra of strings", _extra(lambda e: (e + 1).astype(str)), TypeError, "extra"),
    ("extra complex", _extra(lambda e: e + 1j), TypeError, "extra"),
    ("udd_state a list", _with(udd_state=[1, 2]), TypeError, "udd_state"),
    ("udd_state that cannot be copied", _with(udd_state={"count": _Uncopyable()}),
     TypeError, "cannot be copied"),
]


def _moved(state):
    """The state with every part changed, so that a partial write would show."""
    return MjSimState(state.time + 1, state.qpos + 0.25, state.qvel - 0.5,
                      None if state.act is None else state.act + 1.5,
                      {"count": 99, "trace": np.array([[-1.0, -2.0]])}, state.extra + 1)


@pytest.mark.parametrize("label, spoil, error, match", _BAD_ACT + _BAD_ANY,
                         ids=[case[0] for case in _BAD_ACT + _BAD_ANY])
def test_set_state_refuses_a_bad_part_before_writing_any(label, spoil, error, match):
    sim = _two_act_sim()
    bad = spoil(_moved(sim.get_state()))
    _refused(sim, lambda: sim.set_state(bad), error, match)


_ANT_BAD = [case for case in _BAD_ANY if not case[0].startswith("udd_state that")] + [
    ("act on a model with na=0", _with(act=np.zeros(1)), ValueError, r"act.*\(1,\).*\(0,\)"),
    ("act of strings on na=0", _with(act=np.array(["1"])), TypeError, "act"),
]


@pytest.mark.parametrize("label, spoil, error, match", _ANT_BAD,
                         ids=[case[0] for case in _ANT_BAD])
def test_set_state_refuses_a_bad_part_on_a_gymnasium_model(label, spoil, error, match):
    sim = _ant_sim()
    good = sim.get_state()
    moved = MjSimState(good.time + 1, good.qpos + 0.25, good.qvel - 0.5, None, {},
                       good.extra + 1)
    bad = spoil(moved)
    _refused(sim, lambda: sim.set_state(bad), error, match)


def test_set_state_refuses_what_is_no_state():
    sim = _two_act_sim()
    state = sim.get_state()
    _refused(sim, lambda: sim.set_state(tuple(state)), TypeError, "MjSimState")


def test_reproducer_act_of_wrong_length_wrote_time_qpos_qvel_first():
    sim = _two_act_sim()
    start = _snapshot(sim)
    state = _moved(sim.get_state())
    with pytest.raises(ValueError):
        sim.set_state(state._replace(act=np.zeros(3)))
    assert np.float64(sim.data.time).tobytes() == start["time"], "time was written"
    assert np.array_equal(sim.data.qpos, start["qpos"]), "qpos was written"
    assert np.array_equal(sim.data.qvel, start["qvel"]), "qvel was written"
    _assert_unchanged(sim, start)


def test_reproducer_act_of_length_1_was_broadcast_into_na_2():
    sim = _two_act_sim()
    start = _snapshot(sim)
    state = _moved(sim.get_state())
    with pytest.raises(ValueError):
        sim.set_state(state._replace(act=np.array([5.0])))
    assert not np.all(sim.data.act == 5.0), "act [5.0] was broadcast into both activations"
    _assert_unchanged(sim, start)


# -- what is taken

def test_a_state_round_trips_exactly():
    sim = _two_act_sim()
    state = sim.get_state()
    at_get = _snapshot(sim)
    for _ in range(7):
        sim.step()
    sim.set_state(state)
    after = _snapshot(sim)
    for name in ("time", "qpos", "qvel", "act", "qacc_warmstart"):
        assert np.asarray(after[name]).tobytes() == np.asarray(at_get[name]).tobytes(), name
    # the whole integration state but the caller's inputs, which set_state leaves alone
    assert after["integration"].tobytes() == at_get["integration"].tobytes()
    _assert_same_udd(sim.udd_state, at_get["udd_copy"])
    assert sim.udd_state is not state.udd_state                 # a copy
    assert sim.get_state() == state
    # and the same steps after it
    replay = [sim.step() or sim.data.qpos.tobytes() for _ in range(5)]
    sim.set_state(state)
    assert [sim.step() or sim.data.qpos.tobytes() for _ in range(5)] == replay


def test_a_gymnasium_state_round_trips_exactly():
    sim = _ant_sim()
    state = sim.get_state()
    at_get = _integration(sim.model, sim.data)
    for _ in range(5):
        sim.step()
    sim.set_state(state)
    assert _integration(sim.model, sim.data).tobytes() == at_get.tobytes()
    assert state.act is None


@pytest.mark.parametrize("act", [None, np.zeros(0), [], np.zeros((0,))],
                         ids=["None", "empty array", "empty list", "shape (0,)"])
def test_an_empty_or_missing_act_fits_a_model_without_activations(act):
    sim = _ant_sim()
    state = sim.get_state()
    moved = state._replace(qpos=state.qpos + 0.25, act=act)
    sim.set_state(moved)
    assert sim.data.qpos.tobytes() == moved.qpos.tobytes() and _array(sim.data.act).size == 0


def test_what_mujoco_py_took_is_still_taken():
    sim = _two_act_sim()
    state = sim.get_state()
    # plain lists, ints and float32 arrays of the right sizes; an int time
    sim.set_state(MjSimState(3, [1, 2], np.array([0.5, -0.5], np.float32), [True, 2], None))
    d = sim.data
    assert d.time == 3.0 and d.qpos.tolist() == [1, 2] and d.qvel.tolist() == [0.5, -0.5]
    assert d.act.tolist() == [1.0, 2.0] and sim.udd_state == {}
    # a NaN or infinite time, NaN positions: MuJoCo deals with them, as mujoco-py let it
    sim.set_state(state._replace(time=math.nan, qpos=np.array([np.nan, 0.0])))
    assert math.isnan(d.time) and math.isnan(d.qpos[0])
    sim.set_state(state._replace(time=np.float32(math.inf)))
    assert d.time == math.inf
    sim.set_state(state._replace(time=np.array(2.5)))              # a 0-d array
    assert d.time == 2.5
    sim.set_state(state)
    assert sim.get_state() == state


# -- set_state_from_flattened and MjSimState.from_flattened

_BAD_FLAT = [
    ("one number short", lambda f: f[:-1] + 1, ValueError, r"numbers, not"),
    ("one number long", lambda f: np.r_[f, 1.0] + 1, ValueError, r"numbers, not"),
    ("one number", lambda f: f[:1] + 1, ValueError, r"numbers, not"),
    ("empty", lambda f: f[:0], ValueError, r"numbers, not"),
    ("2-D", lambda f: (f + 1)[None], ValueError, r"numbers, not"),
    ("strings", lambda f: (f + 1).astype(str), TypeError, "flattened state"),
    ("complex", lambda f: f + 1j, TypeError, "flattened state"),
    ("objects", lambda f: np.array([None] * f.size), TypeError, "flattened state"),
]


@pytest.mark.parametrize("label, spoil, error, match", _BAD_FLAT,
                         ids=[case[0] for case in _BAD_FLAT])
def test_set_state_from_flattened_refuses_a_bad_vector_before_writing(label, spoil, error,
                                                                      match):
    sim = _two_act_sim()
    bad = spoil(sim.get_state().flatten())
    _refused(sim, lambda: sim.set_state_from_flattened(bad), error, match)
    _refused(sim, lambda: MjSimState.from_flattened(bad, sim), error, match)


def test_a_flattened_state_of_a_gymnasium_model_of_another_size_is_refused():
    ant = _ant_sim()
    other = MjSim(load_model_from_path(
        str(next(p for p in gymnasium_assets() if p.name == "half_cheetah.xml"))))
    flat = other.get_state().flatten()
    _refused(ant, lambda: ant.set_state_from_flattened(flat), ValueError, "numbers, not")
    _refused(ant, lambda: ant.set_state(other.get_state()), ValueError, "qpos")


def test_a_flattened_state_round_trips_exactly():
    sim = _two_act_sim()
    state = sim.get_state()
    flat = state.flatten()
    for _ in range(3):
        sim.step()
    sim.set_state_from_flattened(flat)
    assert sim.get_state() == state
    assert sim.get_state().flatten().tobytes() == flat.tobytes()
    assert MjSimState.from_flattened(flat, sim) == state
    # an int vector is real numbers
    sim.set_state_from_flattened(np.arange(flat.size))
    assert sim.data.time == 0 and sim.data.qpos.tolist() == [1, 2]


# -- mj_setState (the generated function): its own checks, MjData untouched

def _raw_data():
    m = mjcffi.MjModel.from_xml_string(_TWO_ACT)
    d = mjcffi.MjData(m)
    d.ctrl[:] = [0.7, -0.4, 0.3]
    mjcffi.mj_step(m, d, 20)
    return m, d


def _raw_snapshot(m, d):
    return _raw(d), _integration(m, d).tobytes()


_BAD_SET_STATE = [
    ("one short", lambda s: (s[:-1] + 1, INTEGRATION), ValueError),
    ("one long", lambda s: (np.r_[s, 1.0] + 1, INTEGRATION), ValueError),
    ("length 1", lambda s: (s[:1] + 1, INTEGRATION), ValueError),
    ("empty", lambda s: (s[:0], INTEGRATION), ValueError),
    ("2-D", lambda s: ((s + 1)[None], INTEGRATION), (TypeError, ValueError)),
    ("None", lambda s: (None, INTEGRATION), TypeError),
    ("sig with the bit mjNSTATE", lambda s: (s + 1, INTEGRATION | 1 << NSTATE), ValueError),
    ("sig with a bit far beyond", lambda s: (s + 1, 1 << 30), ValueError),
    ("sig negative", lambda s: (s + 1, -1), ValueError),
    ("sig beyond a C int", lambda s: (s + 1, 1 << 40), ValueError),
    ("sig a float", lambda s: (s + 1, float(INTEGRATION)), TypeError),
    ("sig of another size", lambda s: (s + 1, int(mjcffi.mjtState.mjSTATE_PHYSICS)),
     ValueError),
]


@pytest.mark.parametrize("label, args, error", _BAD_SET_STATE,
                         ids=[case[0] for case in _BAD_SET_STATE])
def test_mj_setState_refuses_a_bad_size_or_signature_before_writing(label, args, error):
    m, d = _raw_data()
    before = _raw_snapshot(m, d)
    state, sig = args(_integration(m, d))
    with pytest.raises(error):
        mjcffi.mj_setState(m, d, state, sig)
    assert _raw_snapshot(m, d) == before


def test_mj_setState_of_a_good_state_writes_it_exactly():
    m, d = _raw_data()
    state = _integration(m, d)
    mjcffi.mj_step(m, d, 5)
    mjcffi.mj_setState(m, d, state, INTEGRATION)
    assert _integration(m, d).tobytes() == state.tobytes()


def test_udd_state_is_left_alone_by_a_refused_state_and_kept_by_a_good_one():
    sim = _two_act_sim()
    udd = sim.udd_state
    state = sim.get_state()
    with pytest.raises(ValueError):
        sim.set_state(state._replace(udd_state={"count": 5}, act=np.zeros(1)))
    assert sim.udd_state is udd
    lock = threading.Lock()
    with pytest.raises(TypeError):
        sim.set_state(state._replace(udd_state={"count": lock}))
    assert sim.udd_state is udd
    sim.set_state(state._replace(udd_state=None))
    assert sim.udd_state == {}
