"""MjSim (mujoco-py interface): MjSimPool throughput, and the cost of a substep callback.

MjSimPool: both sides step gymnasium's humanoid: nsims sims with slightly different
starting poses and controls, `nsubsteps` MuJoCo steps per sim per call.  The
serial side calls `sim.step()` on each sim in turn; the pool side calls
`MjSimPool.step()` with 2 threads.  The figures are simulation steps per
second; the results of both sides are checked bit-identical.

Substep callback: `MjSim.step()` with nsubsteps=5 on the humanoid, plain, with a
controller as C `substep_callback` (one C loop, no GIL), and with the same
controller as a Python callable; each call starts from the same state.
"""

import time

import numpy as np

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


def _measure(nsims, nsubsteps, calls, rounds, nthreads=2):
    serial = _sims(nsims, nsubsteps)
    pool = MjSimPool(_sims(nsims, nsubsteps), nsubsteps=nsubsteps, nthreads=nthreads)

    def run_serial():
        start = time.perf_counter()
        for _ in range(calls):
            for sim in serial:
                sim.step()
        return (time.perf_counter() - start) / calls

    def run_pool():
        start = time.perf_counter()
        for _ in range(calls):
            pool.step()
        return (time.perf_counter() - start) / calls

    try:
        medians = interleaved({"serial": run_serial, "pool": run_pool}, rounds)
    finally:
        pool.close()
    for a, b in zip(serial, pool.sims):
        if a.data.qpos.tobytes() != b.data.qpos.tobytes():
            raise AssertionError("MjSimPool and serial MjSim results differ")
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


def run(rounds=11):
    return pool_lines(rounds) + [""] + substep_lines()


def pool_lines(rounds=11):
    """The MjSimPool section of RESULTS.md."""
    cases = [(8, 1, 20), (8, 5, 5), (16, 10, 2)]
    lines = ["## `MjSimPool` (mujoco-py interface) throughput", "",
             f"Median of {rounds} interleaved rounds on gymnasium's humanoid: `MjSimPool.step()` "
             "with 2 threads against `sim.step()` on each of the same number of `MjSim` in turn "
             "(results checked bit-identical). Figures are simulation steps per second "
             "(nsims × nsubsteps per call). Target: speed-up ≥ 1.8 at 2 threads.", "",
             "| nsims × nsubsteps | serial MjSim.step steps/s | MjSimPool.step steps/s (2 threads) "
             "| speed-up |", "|---|---:|---:|---:|"]
    for nsims, nsubsteps, calls in cases:
        medians = _measure(nsims, nsubsteps, calls, rounds)
        steps = nsims * nsubsteps
        lines.append(f"| {nsims} × {nsubsteps} | {_rate(medians['serial'], steps)} | "
                     f"{_rate(medians['pool'], steps)} | "
                     f"{medians['serial'] / medians['pool']:.2f}× |")
    return lines


if __name__ == "__main__":
    print("\n".join(run()))
