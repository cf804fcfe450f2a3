"""MjSim (mujoco-py interface): MjSimPool throughput, and the cost of a substep callback.

MjSimPool: every side steps gymnasium's humanoid: nsims sims with slightly different
starting poses and controls, `nsubsteps` MuJoCo steps per sim per call.  The
serial side calls `sim.step()` on each sim in turn; the pool side calls
`MjSimPool.step()` with 2 threads (the C rollout pool); a third side runs the
pool's Python-thread path (what MjSimPool falls back to when Python must run
during the steps, and what it used always before).  Each sample starts every
side from the same states.  The figures are simulation steps per second; the
results of all sides are checked bit-identical.

Substep callback: `MjSim.step()` with nsubsteps=5 on the humanoid, plain, with a
controller as C `substep_callback` (one C loop, no GIL), and with the same
controller as a Python callable; each call starts from the same state.
"""

import time

import numpy as np

import mjcffi
from mjcffi.functions._overrides import mj_step
from mjcffi.sim import MjSim, MjSimPool, load_model_from_path

from .bench_rollout import _humanoid_path, _rate
from .common import interleaved


def _sims(nsims, nsubsteps):
    path = _humanoid_path()
    sims = []
    for i in range(nsims):
        sim = MjSim(load_model_from_path(path), nsubsteps=nsubsteps)
        rng = np.random.default_rng(i)
        sim.data.qpos[:] += rng.uniform(-0.02, 0.02, sim.model.nq)
        sim.data.ctrl[:] = rng.uniform(-0.4, 0.4, sim.model.nu)
        sims.append(sim)
    return sims


_STATE = mjcffi.mjtState.mjSTATE_INTEGRATION     # everything a step reads


def _snapshot(sims):
    states = []
    for sim in sims:
        state = np.empty(mjcffi.mj_stateSize(sim.model, _STATE))
        mjcffi.mj_getState(sim.model, sim.data, state, _STATE)
        states.append(state)
    return states


def _restore(sims, states):
    for sim, state in zip(sims, states):
        mjcffi.mj_setState(sim.model, sim.data, state, _STATE)


def _measure(nsims, nsubsteps, calls, rounds, nthreads=2):
    """Median seconds per call of each side.  Every sample starts the sims from the
    same states, so each round times the same physics (a humanoid's step costs more
    once it lies on the floor)."""
    serial = _sims(nsims, nsubsteps)
    pool = MjSimPool(_sims(nsims, nsubsteps), nsubsteps=nsubsteps, nthreads=nthreads)
    python = MjSimPool(_sims(nsims, nsubsteps), nsubsteps=nsubsteps, nthreads=nthreads)
    start = _snapshot(serial)

    def timing(sims, call):
        def run_once():
            _restore(sims, start)
            begin = time.perf_counter()
            for _ in range(calls):
                call()
            return (time.perf_counter() - begin) / calls
        return run_once

    def step_serial():
        for sim in serial:
            sim.step()

    try:
        medians = interleaved({
            "serial": timing(serial, step_serial),
            "pool": timing(pool.sims, pool.step),
            "python": timing(python.sims, lambda: python._run_python(mj_step, python.sims))},
            rounds)
    finally:
        pool.close()
        python.close()
    for sims in (pool.sims, python.sims):
        for a, b in zip(serial, sims):
            for field in ("qpos", "qvel", "act"):
                if not np.array_equal(getattr(a.data, field), getattr(b.data, field)):
                    raise AssertionError(f"MjSimPool and serial MjSim {field} differ")
    return medians


_CONTROLLER_C = """
void fun(const mjModel* m, mjData* d) {
  for (int i = 0; i < m->nu; i++) {
    d->ctrl[i] = 0.2 + 0.0 * d->qvel[6 + i];    // IEEE: computed, and exactly 0.2
  }
}
"""


def _controller_python(model, data):
    data.ctrl[:] = 0.2 + 0.0 * data.qvel[6:6 + model.nu]


def _substep_medians(calls, rounds, nsubsteps=5):
    model = load_model_from_path(_humanoid_path())
    sims = {"plain": MjSim(model, nsubsteps=nsubsteps),
            "C": MjSim(model, nsubsteps=nsubsteps, substep_callback=_CONTROLLER_C),
            "Python": MjSim(model, nsubsteps=nsubsteps, substep_callback=_controller_python)}
    start_state = sims["plain"].get_state()

    def timing(sim):
        def run_once():
            sim.set_state(start_state)
            sim.data.ctrl[:] = 0.2
            start = time.perf_counter()
            for _ in range(calls):
                sim.step()
            return (time.perf_counter() - start) / calls
        return run_once

    medians = interleaved({label: timing(sim) for label, sim in sims.items()}, rounds)
    plain = sims["plain"].data.qpos.tobytes()
    if any(sim.data.qpos.tobytes() != plain for sim in sims.values()):
        raise AssertionError("the substep callbacks changed the trajectory")
    return medians


def substep_lines(calls=40, rounds=21):
    """The substep-callback section of RESULTS.md."""
    medians = _substep_medians(calls, rounds)
    plain = medians["plain"]
    lines = ["## `MjSim.step()` with a `substep_callback` (mujoco-py interface)", "",
             f"Median of {rounds} interleaved rounds of {calls} calls on gymnasium's humanoid, "
             "nsubsteps=5: plain stepping with ctrl = 0.2, a controller "
             "(`ctrl = 0.2 + 0 · qvel`: computed, so the three do the same physics, checked "
             "bit-identical) compiled from C as `substep_callback` (run before each mj_step "
             "in one C loop, no GIL), and the same controller as a Python callable. Target: C callback overhead "
             "≤ 5 % over plain stepping.", "",
             "| substep callback | µs per step() (5 substeps) | ratio to plain |",
             "|---|---:|---:|"]
    for label in ("plain", "C", "Python"):
        lines.append(f"| {label} | {medians[label] * 1e6:.1f} | {medians[label] / plain:.3f} |")
    return lines


def run(rounds=21):
    return pool_lines(rounds) + [""] + substep_lines()


def pool_lines(rounds=21):
    """The MjSimPool section of RESULTS.md."""
    cases = [(8, 1, 40), (8, 5, 10), (16, 10, 4)]     # (nsims, nsubsteps, calls per sample)
    lines = ["## `MjSimPool` (mujoco-py interface) throughput", "",
             f"Median of {rounds} interleaved rounds on gymnasium's humanoid: `MjSimPool.step()` "
             "with 2 threads on the C rollout pool (GIL released, one guarded call per sim) "
             "against `sim.step()` on each of the same number of `MjSim` in turn, and the "
             "pool's Python-thread path (its fallback when Python runs during the steps) "
             "with 2 threads; each sample starts from the same states (results checked "
             "bit-identical: qpos, qvel, act). Figures are "
             "simulation steps per second (nsims × nsubsteps per call). Target: speed-up "
             "≥ 1.8 at 2 threads.", "",
             "| nsims × nsubsteps | serial MjSim.step steps/s | MjSimPool.step steps/s "
             "(2 threads, C) | speed-up | Python threads steps/s (2 threads) | speed-up |",
             "|---|---:|---:|---:|---:|---:|"]
    for nsims, nsubsteps, calls in cases:
        medians = _measure(nsims, nsubsteps, calls, rounds)
        steps = nsims * nsubsteps
        serial = medians["serial"]
        lines.append(f"| {nsims} × {nsubsteps} | {_rate(serial, steps)} | "
                     f"{_rate(medians['pool'], steps)} | {serial / medians['pool']:.2f}× | "
                     f"{_rate(medians['python'], steps)} | {serial / medians['python']:.2f}× |")
    return lines


if __name__ == "__main__":
    print("\n".join(run()))
