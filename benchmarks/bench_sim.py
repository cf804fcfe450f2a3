"""MjSimPool.step() throughput against stepping the same MjSim one after another.

Both sides step gymnasium's humanoid: nsims sims with slightly different
starting poses and controls, `nsubsteps` MuJoCo steps per sim per call.  The
serial side calls `sim.step()` on each sim in turn; the pool side calls
`MjSimPool.step()` with 2 threads.  The figures are simulation steps per
second; the results of both sides are checked bit-identical.
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


def run(rounds=11):
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
