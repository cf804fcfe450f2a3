"""Issue 27, finding 7: Ctrl-C stops a long call.

A SIGINT on the main thread stops mj_step(m, d, nstep), a rollout, MjSimPool.step and
mjcffi.tune at the next step boundary (mjcffi/_c/interrupt.c): KeyboardInterrupt
arrives within 0.2 s, the steps already done stay (no torn state), and the pools
work for the next call.  Each case runs in its own process, which signals itself.
"""

import pytest

PRELUDE = """
import os, signal, threading, time
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
