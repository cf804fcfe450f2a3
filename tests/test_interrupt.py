"""Issue 27, finding 7: Ctrl-C stops a long call.

A SIGINT on the main thread stops mj_step(m, d, nstep), a rollout, MjSimPool.step and
mjcffi.tune at the next step boundary (mjcffi/_c/interrupt.c): KeyboardInterrupt
arrives within 0.2 s, the steps already done stay (no torn state), and the pools
work for the next call.  Each case runs in its own process, which signals itself.
"""

import pytest

PRELUDE = """
import os, signal, threading, time
# Ctrl-C as an interactive Python has it: a process started in the background by a shell
# without job control inherits SIGINT ignored (POSIX), and so would ignore the test's own
signal.signal(signal.SIGINT, signal.default_int_handler)
import numpy as np
import mjcffi
XML = '''<mujoco><worldbody><body><joint name="hinge"/><geom size=".1" mass="1"/>
         </body></worldbody><actuator><motor joint="hinge"/></actuator></mujoco>'''
m = mjcffi.MjModel.from_xml_string(XML)
sent = []

def interrupt_in(seconds):
    def fire():
        time.sleep(seconds)
        sent.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)
    threading.Thread(target=fire, daemon=True).start()

def latency():
    return time.perf_counter() - sent[0]
"""


def _run(run_python, body, timeout=120):
    code, out = run_python(PRELUDE + body, timeout=timeout)
    assert code == 0, out
    return out


def test_ctrl_c_stops_mj_step_at_a_step_boundary(run_python):
    out = _run(run_python, """
        mjcffi.mj_step(m, mjcffi.MjData(m))   # warm: the first call imports the functions
        d = mjcffi.MjData(m)
        d.ctrl[0] = 0.5
        interrupt_in(0.5)
        try:
            mjcffi.mj_step(m, d, 10**9)
            while True:              # KeyboardInterrupt as the call returns, at the latest
                pass
        except KeyboardInterrupt:
            print("latency", latency())
        steps = round(d.time / m.opt.timestep)
        again = mjcffi.MjData(m)
        again.ctrl[0] = 0.5
        mjcffi.mj_step(m, again, steps)
        print("steps", steps, "same", again.time == d.time and
              np.array_equal(again.qpos, d.qpos) and np.array_equal(again.qvel, d.qvel))
        """.replace("\n        ", "\n"))
    assert float(out.split("latency ")[1].split()[0]) < 0.2, out
    assert int(out.split("steps ")[1].split()[0]) > 0 and "same True" in out, out


def test_ctrl_c_stops_a_rollout_and_the_pool_works_after(run_python):
    out = _run(run_python, """
        from mjcffi import rollout
        n = mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
        pool = rollout.Rollout(nthread=2)
        datas = [mjcffi.MjData(m) for _ in range(2)]
        interrupt_in(0.5)
        try:
            pool.rollout(m, datas, np.zeros((4, n)), nstep=10**7)
        except KeyboardInterrupt:
            print("latency", latency())
        state, _ = pool.rollout(m, datas, np.ones((3, n)), nstep=4)
        fresh, _ = rollout.rollout(m, mjcffi.MjData(m), np.ones((3, n)), nstep=4)
        print("same", np.array_equal(state, fresh))
        """.replace("\n        ", "\n"))
    assert float(out.split("latency ")[1].split()[0]) < 0.2, out
    assert "same True" in out, out


def test_ctrl_c_stops_an_mjsimpool_step_and_the_pool_works_after(run_python):
    out = _run(run_python, """
        from mjcffi.sim import MjSim, MjSimPool
        pool = MjSimPool([MjSim(m) for _ in range(3)], nsubsteps=10**8, nthreads=2)
        interrupt_in(0.5)
        try:
            pool.step()
        except KeyboardInterrupt:
            print("latency", latency())
        times = [s.data.time for s in pool.sims]
        whole = True
        for sim in pool.sims:           # each at a step boundary: a fresh sim replays it
            again = mjcffi.MjData(m)
            mjcffi.mj_step(m, again, round(sim.data.time / m.opt.timestep))
            whole &= again.time == sim.data.time and np.array_equal(again.qvel, sim.data.qvel)
        pool.nsubsteps = 2
        pool.step()
        print("stepped", all(s.data.time > t for s, t in zip(pool.sims, times)), "whole", whole)
        """.replace("\n        ", "\n"))
    assert float(out.split("latency ")[1].split()[0]) < 0.2, out
    assert "stepped True whole True" in out, out


def test_ctrl_c_stops_tune(run_python):
    out = _run(run_python, """
        from gymnasium.envs.mujoco import __file__ as where
        hopper = mjcffi.MjModel.from_xml_path(os.path.join(os.path.dirname(where),
                                                           "assets", "hopper.xml"))
        interrupt_in(1.0)
        try:
            mjcffi.tune(hopper, budget="original", progress=False)
            print("finished before the signal")
        except KeyboardInterrupt:
            print("latency", latency())
        """.replace("\n        ", "\n"), timeout=300)
    assert float(out.split("latency ")[1].split()[0]) < 0.2, out


def test_an_ignored_sigint_stops_nothing(run_python):
    out = _run(run_python, """
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        d = mjcffi.MjData(m)
        interrupt_in(0.05)
        mjcffi.mj_step(m, d, 200000)
        print("all steps", round(d.time / m.opt.timestep))
        """.replace("\n        ", "\n"))
    assert "all steps 200000" in out, out


def test_python_still_gets_keyboard_interrupt_outside_mjcffi(run_python):
    """mjcffi's handler forwards every SIGINT to Python's."""
    out = _run(run_python, """
        d = mjcffi.MjData(m)
        mjcffi.mj_step(m, d, 10)          # puts mjcffi's handler in front
        interrupt_in(0.2)
        try:
            time.sleep(30)
        except KeyboardInterrupt:
            print("latency", latency())
        """.replace("\n        ", "\n"))
    assert float(out.split("latency ")[1].split()[0]) < 0.2, out


@pytest.mark.parametrize("nstep", [1, 2])
def test_a_step_off_the_main_thread_is_never_stopped(run_python, nstep):
    """SIGINT is the main thread's: a long call on another thread runs to its end."""
    out = _run(run_python, f"""
        d = mjcffi.MjData(m)
        done = []
        t = threading.Thread(target=lambda: (mjcffi.mj_step(m, d, 100000 * {nstep}),
                                             done.append(1)))
        t.start()
        interrupt_in(0.01)
        try:
            time.sleep(5)
        except KeyboardInterrupt:
            pass
        t.join()
        print("steps", round(d.time / m.opt.timestep))
        """.replace("\n        ", "\n"))
    assert f"steps {100000 * nstep}" in out, out


# MjSimPool on Python threads (a Python substep callback, or a Python mjcb_* callback):
# Ctrl-C stops every share at its next step, not only the calling thread's.
_PYTHON_POOL = """
    from mjcffi.sim import MjSim, MjSimPool
    import collections
    N = {nsubsteps}
    calls, fired = collections.Counter(), []

    def count(*args):              # each step's Python: the SIGINT once both threads ran 1000
        calls[threading.get_ident()] += 1
        if len(calls) == 2 and min(calls.values()) >= 1000 and not fired:
            fired.append(1)
            os.kill(os.getpid(), signal.SIGINT)
    {setup}
    pool = MjSimPool(sims, nsubsteps=2, nthreads=2)
    pool.step()                    # warm: the threads started
    before = sum(round(s.data.time / m.opt.timestep) for s in sims)
    calls.clear()
    pool.nsubsteps = N
    try:
        pool.step()
        print("not interrupted")
    except KeyboardInterrupt:
        pass
    done = sum(round(s.data.time / m.opt.timestep) for s in sims) - before
    print("done", done, "requested", N * len(sims))
    times = [s.data.time for s in sims]
    pool.nsubsteps = 2
    pool.step()
    print("stepped", all(s.data.time > t for s, t in zip(sims, times)))
    """


@pytest.mark.parametrize("setup", [
    "sims = [MjSim(m, substep_callback=count) for _ in range(3)]",
    "sims = [MjSim(m) for _ in range(3)]\n    mjcffi.set_mjcb_control(count)",
], ids=["substep callback", "mjcb callback"])
def test_ctrl_c_stops_every_python_thread_of_an_mjsimpool(run_python, setup):
    """The calling thread sees the SIGINT; the other threads stop at their next step
    instead of finishing their shares (which took 4.5-12 s)."""
    nsubsteps = 10**6
    out = _run(run_python, _PYTHON_POOL.format(nsubsteps=nsubsteps, setup=setup)
               .replace("\n    ", "\n"), timeout=600)
    done = int(out.split("done ")[1].split()[0])
    requested = int(out.split("requested ")[1].split()[0])
    # one thread's share alone is a third of the work: most must be left undone
    assert 0 < done < requested // 10, out
    assert "stepped True" in out, out


# How each long loop of mj_step is called: the hot path, the checked path (d made for
# another MjModel of the same sizes), the prepared call, and MjSim.step's substeps,
# plain and with a C substep callback.  `d` is the data the loop steps.
LOOPS = {
    "mj_step": ("d = mjcffi.MjData(m)", "mjcffi.mj_step(m, d, NSTEP)"),
    "mj_step checked": ("d = mjcffi.MjData(m); twin = mjcffi.MjModel.from_xml_string(XML)",
                        "mjcffi.mj_step(twin, d, NSTEP)"),
    "mj_step prepared": ("d = mjcffi.MjData(m)", "mjcffi.mj_step.prepare(m, d, NSTEP)()"),
    "MjSim.step": ("from mjcffi.sim import MjSim; sim = MjSim(m, nsubsteps=NSTEP); d = sim.data",
                   "sim.step()"),
    "MjSim.step C substeps": (
        "from mjcffi.sim import MjSim; from mjcffi._support.library import ffi, lib; "
        "sim = MjSim(m, nsubsteps=NSTEP, substep_callback=ffi.cast("
        "'mjfGeneric', ffi.addressof(lib, 'mj_energyPos'))); d = sim.data",
        "sim.step()"),
}


@pytest.mark.parametrize("loop", list(LOOPS))
def test_a_sigint_handler_that_does_not_raise_still_stops_the_loop_loudly(run_python, loop):
    """A SIGINT handler of the user's own that raises nothing: the loop stops at a step
    boundary, the handler runs, and KeyboardInterrupt says the steps are not all done
    (the call used to return as if they were)."""
    make, call = LOOPS[loop]
    out = _run(run_python, f"""
        NSTEP = 10**8
        got = []
        signal.signal(signal.SIGINT, lambda signo, frame: got.append(signo))
        {make}
        d.ctrl[0] = 0.5
        mjcffi.mj_step(m, d, 1)                   # warm: the loop below is all stepping
        start = d.time

        def fire():                               # once the loop is under way
            while d.time < start + 100 * m.opt.timestep:
                time.sleep(0.001)
            os.kill(os.getpid(), signal.SIGINT)
        threading.Thread(target=fire, daemon=True).start()
        try:
            {call}
            print("returned normally")
        except KeyboardInterrupt as exc:
            print("interrupted:", exc)
        steps = round(d.time / m.opt.timestep)
        again = mjcffi.MjData(m)
        again.ctrl[0] = 0.5
        mjcffi.mj_step(m, again, steps)
        print("steps", steps, "whole", again.time == d.time and
              np.array_equal(again.qpos, d.qpos) and np.array_equal(again.qvel, d.qvel),
              "handler", got)
        """.replace("\n        ", "\n"))
    assert "interrupted:" in out and "outputs are incomplete" in out, out
    steps = int(out.split("steps ")[1].split()[0])
    assert 100 < steps < 10**8, out
    assert "whole True" in out and "handler [2]" in out, out
