"""Issue 34, findings 3 and 4: mjcffi in a child forked while other threads work.

fork() copies the calling thread alone.  The claim table's mutex (mjcffi/_c/claims.c),
held by another thread at the fork, used to stay held in the child, whose first claiming
call then waited forever; and the claims of threads that do not exist in the child kept
their MjData "in a MuJoCo call on another thread" for good.  A Batch with threads, made
before the fork, waited forever for MuJoCo's threads in the child.

Each case runs in its own process, which forks; every child is waited for with a
deadline, so a deadlock fails the test instead of hanging it.
"""

import os

import pytest

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="needs fork")

PRELUDE = """
import collections, gc, os, signal, sys, threading, time
import numpy as np
import mjcffi
XML = '''<mujoco><worldbody><body><joint name="hinge"/><geom size=".1" mass="1"/>
         </body></worldbody><actuator><motor joint="hinge"/></actuator></mujoco>'''
m = mjcffi.MjModel.from_xml_string(XML)

def wait(pid, seconds=60):
    '''The child's exit status, or "hung" (killed) when it has not ended by the deadline.'''
    end = time.monotonic() + seconds
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return os.waitstatus_to_exitcode(status)
        if time.monotonic() > end:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            return "hung"
        time.sleep(0.002)

def in_child(body):
    '''Fork; the child runs body() and exits 0, or 1 after printing what it raised.'''
    pid = os.fork()
    if pid == 0:
        code = 0
        try:
            body()
        except BaseException as exc:
            os.write(2, f"child: {exc!r}\\n".encode())
            code = 1
        sys.stdout.flush()
        os._exit(code)
    return wait(pid)
"""


def _run(run_python, body, timeout=300):
    code, out = run_python(PRELUDE + body, timeout=timeout)
    assert code == 0, out
    return out


def test_children_forked_beside_a_stepping_thread_can_use_every_mjdata(run_python):
    """A thread steps d while the main thread forks 100 times.  Each child takes claims
    (mj_step of another MjData) and uses d itself after mj_resetData: no child waits
    for the claim table's lock, and none finds d held by a thread it does not have."""
    out = _run(run_python, """
        d, e = mjcffi.MjData(m), mjcffi.MjData(m)
        mjcffi.mj_step(m, d, 1)
        mjcffi.mj_step(m, e, 1)                 # warm
        stop, stepping = threading.Event(), threading.Event()

        def stepper():
            while not stop.is_set():
                mjcffi.mj_step(m, d, 20)        # in MuJoCo most of the time, claiming often
                stepping.set()
        thread = threading.Thread(target=stepper)
        thread.start()
        stepping.wait(60)

        def child():
            mjcffi.mj_step(m, e, 5)
            mjcffi.mj_resetData(m, d)
            mjcffi.mj_step(m, d, 5)
            assert round(d.time / m.opt.timestep) == 5, d.time

        results = collections.Counter(in_child(child) for _ in range(100))
        stop.set()
        thread.join()
        print("children", dict(results))
        """.replace("\n        ", "\n"))
    assert "children {0: 100}" in out, out


def test_a_spec_held_by_another_thread_is_not_held_in_the_child(run_python):
    """A thread compiles a spec over and over while the main thread forks: in each child
    no spec is held (the count that spares element reads a lock is right), and another
    spec compiles."""
    out = _run(run_python, """
        from mjcffi._support.library import ffi, lib
        busy, other = mjcffi.MjSpec.from_string(XML), mjcffi.MjSpec.from_string(XML)
        busy.compile()
        stop, compiling = threading.Event(), threading.Event()

        def compiler():
            while not stop.is_set():
                busy.compile()
                compiling.set()
        thread = threading.Thread(target=compiler)
        thread.start()
        compiling.wait(60)
        holds = ffi.addressof(lib, "mjcffi_spec_holds")

        def child():
            assert holds[0] == 0, f"{holds[0]} specs held"
            assert other.compile().nq == 1

        results = collections.Counter(in_child(child) for _ in range(30))
        stop.set()
        thread.join()
        print("children", dict(results))
        """.replace("\n        ", "\n"))
    assert "children {0: 30}" in out, out


def test_a_batch_with_threads_refuses_in_a_forked_child_and_a_new_one_works(run_python):
    """The child cannot step a Batch(nthread=2) made before the fork: a RuntimeError that
    says to make a new one, instead of waiting forever.  Its state can still be read, it
    can be dropped without waiting to join threads, and a new Batch steps as the
    parent's did."""
    out = _run(run_python, """
        from mjcffi import batch
        b = batch.Batch(m, 4, nthread=2)
        b.ctrl = 0.5
        b.step(nstep=3)
        qpos = b.qpos.copy()

        def child():
            for call in (b.step, b.forward, b.reset):
                try:
                    call()
                    raise AssertionError(f"{call.__name__} ran")
                except RuntimeError as exc:
                    assert "made before os.fork()" in str(exc), exc
                    assert "make a new Batch in the child" in exc.__notes__[0]
            assert np.array_equal(b.qpos, qpos) and b.get_data(1).time == 3 * m.opt.timestep
            fresh = batch.Batch(m, 4, nthread=2)
            fresh.ctrl = 0.5
            fresh.step(nstep=3)
            assert np.array_equal(fresh.qpos, qpos)
            single = batch.Batch(m, 4, nthread=1)     # no threads of its own: runs
            single.ctrl = 0.5
            single.step(nstep=3)
            assert np.array_equal(single.qpos, qpos)
            b.close()
            gc.collect()                  # the old mjBatch is not freed: its threads are gone

        print("child", in_child(child))
        b.step()                          # the parent's Batch still works
        print("parent stepped", b.get_data(0).time == 4 * m.opt.timestep)
        """.replace("\n        ", "\n"))
    assert "child 0" in out and "parent stepped True" in out, out


def test_a_batch_made_in_a_forked_child_works_on_its_threads(run_python):
    """A child with no Batch from before the fork makes its own, with threads."""
    out = _run(run_python, """
        from mjcffi import batch

        def child():
            b = batch.Batch(m, 8, nthread=2)
            b.step(nstep=2)
            assert b.get_data(7).time == 2 * m.opt.timestep

        print("child", in_child(child))
        """.replace("\n        ", "\n"))
    assert "child 0" in out, out


def test_rollout_and_mjsimpool_threads_are_remade_in_a_forked_child(run_python):
    """Rollout pools (and MjSimPool's, which is one) start new threads in the child."""
    out = _run(run_python, """
        from mjcffi import rollout
        from mjcffi.sim import MjSim, MjSimPool
        n = mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
        pool = rollout.Rollout(nthread=2)
        datas = [mjcffi.MjData(m) for _ in range(2)]
        state0, control = np.zeros((6, n)), np.full((6, 5, 1), 0.5)
        expected, _ = pool.rollout(m, datas, state0, control)
        sims = MjSimPool([MjSim(m) for _ in range(3)], nsubsteps=4, nthreads=2)
        sims.step()

        def child():
            state, _ = pool.rollout(m, datas, state0, control)
            assert np.array_equal(state, expected)
            sims.step()
            assert all(round(s.data.time / m.opt.timestep) == 8 for s in sims.sims)
            pool.close()
            sims.close()

        print("child", in_child(child))
        """.replace("\n        ", "\n"))
    assert "child 0" in out, out
