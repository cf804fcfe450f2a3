"""Issue 27, finding 4: pools refuse re-entry; nothing hangs.

A callback that a Rollout, an MjSimPool or a Batch runs (on any of its threads) may
not call that pool: the pool waits for the callback.  Such a call raises
RecursionError.  A call into a different pool from a callback works, or raises
when that pool is busy; it never waits forever.  Whatever might hang runs in a
subprocess with a timeout.
"""

import threading

import numpy as np
import pytest

import mjcffi
from mjcffi import batch, rollout
from mjcffi.sim import MjSim, MjSimPool

XML = """
<mujoco>
  <worldbody><body><joint name="hinge"/><geom size=".1" mass="1"/></body></worldbody>
  <actuator><motor joint="hinge"/></actuator>
</mujoco>
"""


@pytest.fixture
def m():
    return mjcffi.MjModel.from_xml_string(XML)


@pytest.fixture
def control_callback():
    """install(f): f as mjcb_control, removed at the end of the test."""
    yield mjcffi.set_mjcb_control
    mjcffi.set_mjcb_control(None)


def _initial(m, nbatch):
    return np.zeros((nbatch, mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)))


def _calls_from_callback(call, install):
    """Install a control callback that makes `call` (once per thread); return what each
    attempt gave: 'ok' or the exception's type name."""
    seen, lock = {}, threading.Lock()

    def callback(m, d):
        me = threading.get_ident()
        with lock:
            if me in seen:
                return
            seen[me] = None
        try:
            call()
            seen[me] = "ok"
        except Exception as exc:          # the outer call would raise it: keep it here
            seen[me] = type(exc).__name__
    install(callback)
    return seen


@pytest.mark.parametrize("nthread", [0, 2, 3])
def test_a_rollout_called_from_its_own_callback_raises_recursion_error(
        m, control_callback, nthread):
    pool = rollout.Rollout(nthread=nthread)
    datas = [mjcffi.MjData(m) for _ in range(max(nthread, 1))]
    seen = _calls_from_callback(lambda: pool.rollout(m, datas, _initial(m, 1), nstep=1),
                                control_callback)
    pool.rollout(m, datas, _initial(m, 8), nstep=5)
    assert seen and set(seen.values()) == {"RecursionError"}, seen
    control_callback(None)
    state, _ = pool.rollout(m, datas, _initial(m, 4), nstep=3)     # the pool still works
    assert state.shape[:2] == (4, 3)


def test_another_rollout_from_a_callback_works(m, control_callback):
    outer, inner = rollout.Rollout(nthread=2), rollout.Rollout(nthread=2)
    datas, inner_datas = [mjcffi.MjData(m) for _ in range(2)], [mjcffi.MjData(m) for _ in
                                                                 range(2)]
    lock = threading.Lock()

    def call():
        with lock:                 # one call at a time on `inner`, as it would wait
            inner.rollout(m, inner_datas, _initial(m, 2), nstep=2)

    def install(callback):         # the nested call from outer's steps only: one from
        if callback is None:       # inner's own thread would wait for the lock forever
            return control_callback(None)
        control_callback(lambda m_, d_: None if any(d_ is d for d in inner_datas)
                         else callback(m_, d_))
    seen = _calls_from_callback(call, install)
    outer.rollout(m, datas, _initial(m, 4), nstep=2)
    assert set(seen.values()) == {"ok"}, seen


def test_two_rollouts_calling_each_other_from_callbacks_do_not_hang(run_python):
    """Pool a's callback calls pool b while b's callback calls pool a: each would wait
    for the other.  A call from a callback into a busy pool raises instead."""
    code, out = run_python(f"""
        import threading
        import numpy as np
        import mjcffi
        from mjcffi import rollout
        m = mjcffi.MjModel.from_xml_string({XML!r})
        n = mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
        pools = {{"a": rollout.Rollout(nthread=2), "b": rollout.Rollout(nthread=2)}}
        data = {{k: [mjcffi.MjData(m) for _ in range(2)] for k in pools}}
        spare = {{k: [mjcffi.MjData(m) for _ in range(2)] for k in pools}}
        errors = []
        depth = threading.local()

        def callback(m_, d_):
            if getattr(depth, "n", 0):
                return
            depth.n = 1
            try:
                key = "a" if any(d_._ptr == d._ptr for d in data["b"]) else "b"
                pools[key].rollout(m, spare[key], np.zeros((2, n)), nstep=1)
            except RecursionError:
                errors.append(1)
            finally:
                depth.n = 0

        mjcffi.set_mjcb_control(callback)
        threads = [threading.Thread(target=pools[k].rollout,
                                    args=(m, data[k], np.zeros((16, n))), kwargs={{"nstep": 20}})
                   for k in pools]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        mjcffi.set_mjcb_control(None)
        print("done")
        """, timeout=120)
    assert code == 0, out
    assert "done" in out


def test_reproducer_a_rollout_reentered_from_its_callback_does_not_hang(run_python):
    """Finding 4: a Python mjcb_control calling r.rollout(...) on the same persistent
    Rollout(nthread=2) deadlocked the process."""
    code, out = run_python(f"""
        import numpy as np
        import mjcffi
        from mjcffi import rollout
        m = mjcffi.MjModel.from_xml_string({XML!r})
        n = mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
        r = rollout.Rollout(nthread=2)
        datas = [mjcffi.MjData(m) for _ in range(2)]
        mjcffi.set_mjcb_control(lambda m_, d_: r.rollout(m, datas, np.zeros((1, n)), nstep=1))
        try:
            r.rollout(m, datas, np.zeros((8, n)), nstep=5)
        except RecursionError as e:
            print("refused:", e)
        """, timeout=60)
    assert code == 0, out
    assert "refused:" in out


def test_an_mjsimpool_called_from_its_sims_callback_raises_recursion_error(
        m, control_callback):
    pool = MjSimPool([MjSim(m) for _ in range(3)], nthreads=2)
    seen = _calls_from_callback(pool.step, control_callback)
    pool.step()
    assert seen and set(seen.values()) == {"RecursionError"}, seen
    control_callback(None)
    before = [sim.data.time for sim in pool.sims]
    pool.step()
    assert [sim.data.time for sim in pool.sims] > before


def test_an_mjsimpool_refuses_a_call_from_its_c_pool_threads(m):
    """Without Python callbacks the sims step on the C pool; a C substep callback cannot
    call Python, so the C refusal is checked through the pool's own running flag."""
    pool = MjSimPool([MjSim(m) for _ in range(2)], nthreads=2)
    pool._running = True
    with pytest.raises(RecursionError, match="in a call already"):
        pool.step()
    pool._running = False
    pool.step()


def test_a_batch_called_from_a_callback_on_its_threads_raises_recursion_error(m):
    b = batch.Batch(m, 4, nthread=2)
    seen = []

    # every warning tries: the pool's two threads may both warn at once (under load they
    # did, and a "first call only" check raced), and each try must be refused
    def warning(message):
        try:
            b.step()
            seen.append("ok")
        except RecursionError:
            seen.append("RecursionError")

    mjcffi.set_mju_user_warning(warning)
    try:
        b.state[:, 1] = np.nan                     # a bad qpos: MuJoCo warns
        b.step()
    finally:
        mjcffi.set_mju_user_warning(None)
    assert seen and set(seen) == {"RecursionError"}, seen
    b.reset()
    b.step()


def test_a_batch_used_by_another_thread_during_a_call_raises(m):
    """MuJoCo's batch keeps no lock for a second caller, and its status would be
    overwritten: a call while another runs is refused, never waited for."""
    b = batch.Batch(m, 2, nthread=1)
    refused = []
    for nstep in (10**5, 10**6, 10**7):
        started = threading.Event()

        def long_step():
            started.set()
            b.step(nstep=nstep)
        thread = threading.Thread(target=long_step)
        thread.start()
        started.wait()
        threading.Event().wait(0.05)
        try:
            b.forward()
        except RecursionError as exc:
            refused.append(str(exc))
        thread.join()
        if refused:
            break
    assert refused and "in a call already" in refused[0]
    b.step()                                      # free again
