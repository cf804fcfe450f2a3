"""Issue 34, finding 2: a rollout holds its MjData, as mj_step holds its own.

mjcffi takes one call at a time per MjData (mjcffi/_c/claims.c), but the rollout loop
called MuJoCo's mj_step directly and never claimed its data: a control callback could
reset the data being rolled out, and a rollout beside mj_step on the same MjData on
another thread overwrote each other's arena (a segfault).  Now mjcffi_rollout holds every
MjData of the call, and each pool thread takes over the claim of the data it rolls out.

The cases that crash without the claim run in their own process; each waits on events,
never on a clock.
"""

import threading

import numpy as np
import pytest

import mjcffi
from mjcffi import rollout

XML = """<mujoco><worldbody><body><joint name="hinge"/><geom size=".1" mass="1"/>
         </body></worldbody><actuator><motor joint="hinge"/></actuator></mujoco>"""


@pytest.fixture
def control():
    """Install a Python mjcb_control for the test; cleared after it."""
    yield mjcffi.set_mjcb_control
    mjcffi.set_mjcb_control(None)


@pytest.mark.parametrize("nthread", [0, 2])
def test_a_callback_of_a_rollout_may_not_reset_its_data(control, nthread):
    """On the calling thread and on a pool thread alike: mj_resetData of the data being
    rolled out is refused (as under mj_step), while a call that does not restart the
    pipeline (mj_energyPos) nests."""
    m = mjcffi.MjModel.from_xml_string(XML)
    datas = [mjcffi.MjData(m) for _ in range(max(nthread, 1))]
    threads, refused, nested = set(), [], []
    both = threading.Event()

    def callback(model, data):
        threads.add(threading.get_ident())
        if len(threads) >= min(nthread, 2) or nthread < 2:
            both.set()
        both.wait(60)                 # a pool: wait until both threads roll out
        mjcffi.mj_energyPos(model, data)
        nested.append(True)
        try:
            mjcffi.mj_resetData(model, data)
            refused.append(None)
        except RecursionError as exc:
            refused.append(str(exc))

    control(callback)
    n = mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
    with rollout.Rollout(nthread=nthread) as pool:
        pool.rollout(m, datas if nthread else datas[0], np.zeros((2, n)), nstep=3,
                     chunk_size=1)
    assert len(threads) == max(1, min(nthread, 2))
    assert refused and all(r is not None and "mj_resetData" in r for r in refused), refused
    assert len(nested) == len(refused)
    mjcffi.set_mjcb_control(None)
    for d in datas:                   # the claims are gone once the call returns
        mjcffi.mj_resetData(m, d)
        mjcffi.mj_step(m, d, 2)


PRELUDE = """
import threading
import numpy as np
import mjcffi
from mjcffi import rollout
XML = '''<mujoco><worldbody><body><joint name="hinge"/><geom size=".1" mass="1"/>
         </body></worldbody><actuator><motor joint="hinge"/></actuator></mujoco>'''
m = mjcffi.MjModel.from_xml_string(XML)
n = mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)

def outcome(call):
    try:
        call()
        return "ran"
    except ValueError as exc:
        return "refused: " + str(exc)
"""


def _run(run_python, body):
    code, out = run_python(PRELUDE + body, timeout=180)
    assert code == 0, out
    return out


@pytest.mark.parametrize("nthread", [0, 2])
def test_mj_step_on_data_being_rolled_out_is_refused(run_python, nthread):
    """Another thread's mj_step on an MjData that a rollout (paused in its control
    callback) is stepping: a ValueError, never a crash; the rollout then finishes."""
    out = _run(run_python, f"""
        datas = [mjcffi.MjData(m) for _ in range(max({nthread}, 1))]
        target = datas[-1]                 # with a pool: the pool thread's data
        inside, answered, result = threading.Event(), threading.Event(), []

        def control(model, data):
            if threading.current_thread() is thread:
                return                     # the other thread's own step, where it runs
            if data is not target:
                inside.wait(60)            # the caller waits until the pool thread has target
            elif not inside.is_set():
                inside.set()
                answered.wait(60)          # the rollout holds target meanwhile

        def other():
            inside.wait(60)
            result.append(outcome(lambda: mjcffi.mj_step(m, target)))
            answered.set()

        thread = threading.Thread(target=other)
        mjcffi.set_mjcb_control(control)
        thread.start()
        pool = rollout.Rollout(nthread={nthread})
        pool.rollout(m, datas if {nthread} else target, np.zeros((4, n)), nstep=5,
                     chunk_size=1)
        thread.join()
        print("other:", result[0])
        """.replace("\n        ", "\n"))
    assert "other: refused: mj_step: this mjData is in a MuJoCo call on another thread" in out, \
        out


def test_a_rollout_of_data_in_mj_step_on_another_thread_is_refused(run_python):
    """The other order: a rollout of an MjData that mj_step (paused in its control
    callback) holds on another thread is refused before it runs."""
    out = _run(run_python, """
        d = mjcffi.MjData(m)
        inside, answered, result = threading.Event(), threading.Event(), []
        stepper = []

        def control(model, data):
            if threading.get_ident() == stepper[0] and not inside.is_set():
                inside.set()
                answered.wait(60)          # mj_step holds d meanwhile

        def step():
            stepper.append(threading.get_ident())
            mjcffi.mj_step(m, d)

        mjcffi.set_mjcb_control(control)
        thread = threading.Thread(target=step)
        thread.start()
        inside.wait(60)
        result.append(outcome(lambda: rollout.rollout(m, d, np.zeros((2, n)), nstep=3)))
        answered.set()
        thread.join()
        print("rollout:", result[0])
        """.replace("\n        ", "\n"))
    assert "rollout: refused: rollout: this mjData is in a MuJoCo call on another thread" in out, \
        out


def test_rollouts_beside_mj_step_on_the_same_data_never_crash(run_python):
    """Free-running: a pool's rollouts on one thread, mj_step on both of its MjData on
    another.  Each call either runs or is refused with the ValueError; the process
    lives, and the data step normally afterwards."""
    out = _run(run_python, """
        datas = [mjcffi.MjData(m) for _ in range(2)]
        pool = rollout.Rollout(nthread=2)
        pool.rollout(m, datas, np.zeros((2, n)), nstep=2)     # warm
        rolling, done, seen = threading.Event(), threading.Event(), {"ran": 0, "refused": 0}
        odd = []

        def note(result):
            kind = result.split(":")[0]
            if kind == "refused" and "another thread" not in result:
                odd.append(result)
            seen[kind] += 1

        def other():
            rolling.wait(60)
            while not done.is_set():
                for d in datas:
                    note(outcome(lambda: mjcffi.mj_step(m, d, 10)))

        thread = threading.Thread(target=other)
        thread.start()
        rolling.set()
        for _ in range(400):             # until the other thread met a rollout a few times
            note(outcome(lambda: pool.rollout(m, datas, np.zeros((8, n)), nstep=200)))
            if seen["refused"] >= 5:
                break
        done.set()
        thread.join()
        for d in datas:
            mjcffi.mj_resetData(m, d)
            mjcffi.mj_step(m, d, 3)
        print("refused", seen["refused"], "odd", odd)
        """.replace("\n        ", "\n"))
    assert "odd []" in out, out
    assert int(out.split("refused ")[1].split()[0]) >= 1, out


def test_mjsimpool_holds_each_sims_data(run_python):
    """MjSimPool's C loop steps each sim through mjcffi_step_loop, which holds its data:
    a sim whose MjData is in mj_step on another thread fails with the ValueError."""
    out = _run(run_python, """
        import os, signal, time
        from mjcffi.sim import MjSim, MjSimPool
        sims = [MjSim(m) for _ in range(2)]
        pool = MjSimPool(sims, nsubsteps=3, nthreads=2)
        pool.step()                                          # warm
        busy = sims[1].data
        start, result = busy.time, []
        signal.signal(signal.SIGINT, lambda signo, frame: None)

        def other():
            while busy.time == start:                        # the main thread is stepping it
                time.sleep(0.001)
            result.append(outcome(pool.step))
            os.kill(os.getpid(), signal.SIGINT)              # ends the long step below
        threading.Thread(target=other).start()
        try:
            mjcffi.mj_step(m, busy, 10**8)
        except KeyboardInterrupt:
            pass
        print("pool:", result[0])
        """.replace("\n        ", "\n"))
    assert "pool: refused: mj_step: this mjData is in a MuJoCo call on another thread" in out, out
