"""MjSimPool on the C rollout pool: the same bits as each sim stepped alone, whatever the
thread count; an error in one sim stops it alone; Python work falls back to Python threads."""

import numpy as np
import pytest

import mjcffi
from mjcffi.sim import MjSim, MjSimPool, load_model_from_path
from mjcffi.sim import _pool

from .conftest import gymnasium_assets

_CONTROLLER = """
void fun(const mjModel* m, mjData* d) {
  for (int i = 0; i < m->nu; i++) d->ctrl[i] = 0.3 * sin(d->time * (i + 1));
}
"""
_FAILING = """
void fun(const mjModel* m, mjData* d) { if (d->time > 0) mju_error("sim failed on purpose"); }
"""


def _humanoid_path():
    return next(p for p in gymnasium_assets() if p.name == "humanoid.xml")


def _sims(nsims, nsubsteps=1, **kwargs):
    """Humanoids from slightly different poses and controls (sim i from seed i)."""
    sims = []
    for i in range(nsims):
        sim = MjSim(load_model_from_path(_humanoid_path()), nsubsteps=nsubsteps, **kwargs)
        rng = np.random.default_rng(i)
        sim.data.qpos[:] += rng.uniform(-0.05, 0.05, sim.model.nq)
        sim.data.ctrl[:] = rng.uniform(-0.4, 0.4, sim.model.nu)
        sims.append(sim)
    return sims


def _assert_same(ours, alone):
    for i, (a, b) in enumerate(zip(ours, alone)):
        assert a.data.time == b.data.time, i
        for field in ("qpos", "qvel", "act", "qacc_warmstart", "sensordata"):
            assert np.array_equal(getattr(a.data, field), getattr(b.data, field)), (i, field)


@pytest.fixture
def c_only(monkeypatch):
    """Fail the test if the pool falls back to Python threads."""
    def refuse(self, job, sims):
        raise AssertionError("MjSimPool fell back to Python threads")
    monkeypatch.setattr(_pool.MjSimPool, "_run_python", refuse)


@pytest.mark.parametrize("nsims", [8, 16])
@pytest.mark.parametrize("nsubsteps", [1, 5])
def test_step_is_bit_identical_to_sims_alone(c_only, nsims, nsubsteps):
    calls = 6
    pool = MjSimPool(_sims(nsims), nsubsteps=nsubsteps, nthreads=2)
    alone = _sims(nsims, nsubsteps=nsubsteps)
    for _ in range(calls):
        pool.step()
        for sim in alone:
            sim.step()
    assert pool.sims[0].data.time == pytest.approx(calls * nsubsteps * alone[0].model.opt.timestep)
    _assert_same(pool.sims, alone)
    pool.close()


@pytest.mark.parametrize("nthreads", [1, 2, 3, 8, 64])
def test_thread_counts_give_the_same_bits(c_only, nthreads):
    nsims, nsubsteps = 8, 3
    pool = MjSimPool(_sims(nsims), nsubsteps=nsubsteps, nthreads=nthreads)
    assert pool.nthreads == min(nthreads, nsims)
    alone = _sims(nsims, nsubsteps=nsubsteps)
    for _ in range(4):
        pool.step()
        for sim in alone:
            sim.step()
    _assert_same(pool.sims, alone)
    pool.close()


def test_forward_reset_and_nsims(c_only):
    pool = MjSimPool(_sims(5), nsubsteps=2, nthreads=2)
    alone = _sims(5, nsubsteps=2)
    pool.forward()
    for sim in alone:
        sim.forward()
    _assert_same(pool.sims, alone)
    assert np.array_equal(pool.sims[2].data.xpos, alone[2].data.xpos)
    pool.step(nsims=3)
    for sim in alone[:3]:
        sim.step()
    _assert_same(pool.sims, alone)
    assert [s.data.time > 0 for s in pool.sims] == [True] * 3 + [False] * 2
    pool.step(nsims=0)                       # nothing to do
    pool.reset(nsims=2)
    assert [s.data.time == 0 for s in pool.sims] == [True, True, False, True, True]
    pool.close()


def test_a_fatal_error_stops_that_sim_alone(c_only):
    nsims, nsubsteps = 8, 4
    sims = _sims(nsims)
    for i in (5, 2):
        sims[i].set_substep_callback(_FAILING)
    pool = MjSimPool(sims, nsubsteps=nsubsteps, nthreads=2)
    alone = _sims(nsims, nsubsteps=nsubsteps)
    with pytest.raises(mjcffi.FatalError, match="sim failed on purpose") as caught:
        pool.step()
    assert caught.value.failed.tolist() == [2, 5]
    dt = sims[0].model.opt.timestep
    for i, sim in enumerate(sims):
        if i in (2, 5):
            assert sim.data.time == dt       # stopped in its second substep
        else:
            alone[i].step()
            _assert_same([sim], [alone[i]])
    # the pool goes on: the others step again, the failed ones fail again
    for i in (2, 5):
        sims[i].set_substep_callback(None)
        mjcffi.mj_resetData(sims[i].model, sims[i].data)
        mjcffi.mj_resetData(alone[i].model, alone[i].data)
    pool.step()
    for sim in alone:
        sim.step()
    _assert_same(sims, alone)
    pool.close()


def test_c_substep_callback_runs_in_the_c_loop(c_only):
    sims = _sims(6)
    for sim in sims[::2]:
        sim.set_substep_callback(_CONTROLLER)
    alone = _sims(6, nsubsteps=5)
    for sim in alone[::2]:
        sim.set_substep_callback(_CONTROLLER)
    pool = MjSimPool(sims, nsubsteps=5, nthreads=2)
    for _ in range(3):
        pool.step()
        for sim in alone:
            sim.step()
    _assert_same(pool.sims, alone)
    t = sims[0].data.time - sims[0].model.opt.timestep       # the last substep's start
    assert sims[0].data.ctrl[1] == 0.3 * np.sin(t * 2)       # the callback set it
    assert not np.array_equal(sims[0].data.ctrl, sims[1].data.ctrl)
    pool.close()


def test_python_work_falls_back_to_python_threads():
    calls = []

    def controller(model, data):
        calls.append(data.time)
        data.ctrl[:] = 0.1

    sims = _sims(4)
    sims[1].set_substep_callback(controller)
    alone = _sims(4, nsubsteps=3)
    alone[1].set_substep_callback(controller)
    pool = MjSimPool(sims, nsubsteps=3, nthreads=2)
    pool.step()
    for sim in alone:
        sim.step()
    assert len(calls) == 6                   # 3 substeps in the pool, 3 alone
    assert pool._executor is not None        # Python threads ran it
    _assert_same(pool.sims, alone)
    pool.close()


def test_udd_callback_runs_before_each_step(c_only):
    seen = []

    def udd(sim):
        seen.append(sim.data.time)
        return {"time": sim.data.time}

    sims = _sims(3, udd_callback=udd)
    seen.clear()
    pool = MjSimPool(sims, nsubsteps=2, nthreads=2)
    pool.step()
    pool.step()
    dt = sims[0].model.opt.timestep
    assert seen == [0.0] * 3 + [2 * dt] * 3
    assert sims[2].udd_state == {"time": 2 * dt}
    pool.close()


def test_closed_pool_refuses_and_its_threads_stop():
    pool = MjSimPool(_sims(2), nthreads=2)
    pool.step()
    threads = pool._threads
    pool.close()
    assert pool._threads is None and not threads._open
    with pytest.raises(ValueError, match="MjSimPool is closed"):
        pool.step()


def test_warnings_as_errors_fall_back_and_raise():
    sims = _sims(4)
    sims[2].data.qvel[0] = float("nan")      # MuJoCo warns (mjWARN_BADQVEL) and resets
    pool = MjSimPool(sims, nthreads=2)
    mjcffi.set_warnings_as_errors(True)
    try:
        with pytest.raises(mjcffi.MjWarningError, match="mjWARN_BADQVEL"):
            pool.step()
    finally:
        mjcffi.set_warnings_as_errors(False)
    assert pool._executor is not None
    assert all(sim.data.time > 0 for sim in sims)    # every sim stepped
    pool.close()
