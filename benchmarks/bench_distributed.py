"""`mjcffi.distributed.rollout` on one machine against the local `mjcffi.rollout`.

Ray runs a local cluster here; a RolloutCluster of 2 workers (each rolling out on its
share of the cores) against a local `Rollout(nthread=2)`, interleaved, on gymnasium's
humanoid.  The overhead ratio is distributed / local time per call; the fixed cost is the
time of a tiny call (2 rollouts x 1 step) over the local one.  The projection to many
nodes uses the measured per-step cost and Ray's measured per-task overhead; it leaves the
network out (results would cross it: bytes per call are given).
"""

import os
import statistics
import time

import numpy as np

import mjcffi
from mjcffi import distributed, rollout as local_rollout
from mjcffi.evaluation import states

from .bench_rollout import _humanoid_path
from .common import interleaved

NROLL, NSTEP, WORKERS = 256, 100, 2


class Side:
    """One side of a measurement: a pool (local or distributed) and its call."""

    def __init__(self, pool, model, initial, control, calls, data=None):
        self.pool, self.calls = pool, calls
        self.args = (model, data, initial, control) if data is not None else \
            (model, initial, control)
        self.result = None

    def timer(self):
        def run():
            start = time.perf_counter()
            for _ in range(self.calls):
                self.result = self.pool.rollout(*self.args)
            return (time.perf_counter() - start) / self.calls
        return run


def _inputs(m, nroll, nstep):
    rng = np.random.default_rng(0)
    return (states.initial_states(m, nroll, rng),
            rng.uniform(-0.4, 0.4, (nroll, nstep, m.nu)))


def _measure(local, cluster, m, nroll, nstep, calls, rounds):
    """Median seconds per call {local, ray}; the results are checked equal."""
    initial, control = _inputs(m, nroll, nstep)
    datas = [mjcffi.MjData(m) for _ in range(local.nthread)]
    sides = {"local": Side(local, m, initial, control, calls, datas),
             "ray": Side(cluster, m, initial, control, calls)}
    for side in sides.values():
        side.timer()()                         # warm: models cached, threads awake
    medians = interleaved({k: s.timer() for k, s in sides.items()}, rounds)
    for a, b in zip(sides["local"].result, sides["ray"].result):
        if not np.array_equal(a, b):
            raise AssertionError("distributed and local rollouts differ")
    return medians


def _task_overhead(cluster, rounds, calls=50):
    """Median seconds of a round trip of a no-op call on one worker (Ray's per-task cost)."""
    ray, actor = cluster._ray, cluster.workers[0]
    samples = []
    for _ in range(rounds):
        start = time.perf_counter()
        for _ in range(calls):
            ray.get(actor.where.remote())
        samples.append((time.perf_counter() - start) / calls)
    return statistics.median(samples)


def _ms(seconds):
    return f"{seconds * 1e3:.2f} ms"


def projection(step_cost, task_cost, fixed_cost, cores, nroll=NROLL, nstep=NSTEP,
               nodes=(1, 10, 100)):
    """Markdown lines: the time of an nroll x nstep call on n nodes of `cores` cores, on
    paper: fixed_cost + n * task_cost (the driver hands out a shard per node) + the work
    shared by n * cores threads, whole rollouts per thread."""
    lines = ["| nodes | cores | compute | Ray overhead | total | efficiency |",
             "|---:|---:|---:|---:|---:|---:|"]
    for n in nodes:
        per_thread = -(-nroll // (n * cores))            # whole rollouts: the slowest thread
        compute = per_thread * nstep * step_cost
        overhead = fixed_cost + n * task_cost
        ideal = nroll * nstep * step_cost / (n * cores)
        lines.append(f"| {n} | {n * cores} | {_ms(compute)} | {_ms(overhead)} | "
                     f"{_ms(compute + overhead)} | {ideal / (compute + overhead):.0%} |")
    return lines


def break_even(step_cost, task_cost, cores, nstep=NSTEP):
    """Rollouts per shard below which Ray's per-task cost exceeds the shard's compute on a
    node of `cores` cores."""
    return task_cost * cores / (nstep * step_cost)


def run(rounds=7):
    import ray
    started = not ray.is_initialized()
    if started:
        ray.init(include_dashboard=False, log_to_driver=False)
    m = mjcffi.MjModel.from_xml_path(_humanoid_path())
    cores = os.cpu_count() or 1
    try:
        t = time.perf_counter()
        cluster = distributed.RolloutCluster(WORKERS)
        start_cost = time.perf_counter() - t
        with cluster, local_rollout.Rollout(nthread=2) as local:
            big = _measure(local, cluster, m, NROLL, NSTEP, 1, rounds)
            tiny = _measure(local, cluster, m, 2, 1, 20, rounds)
            task = _task_overhead(cluster, rounds)
            threads = cluster.threads()
    finally:
        if started:
            ray.shutdown()
    step_cost = big["local"] * 2 / (NROLL * NSTEP)        # one core's seconds per step
    fixed = tiny["ray"] - tiny["local"]
    nstate = mjcffi.mj_stateSize(m, int(mjcffi.mjtState.mjSTATE_FULLPHYSICS))
    mbytes = NROLL * NSTEP * (nstate + m.nsensordata) * 8 / 1e6
    ratio = big["ray"] / big["local"]
    lines = ["## Distributed rollouts (Ray, one machine)", "",
             f"gymnasium's humanoid, {NROLL} rollouts × {NSTEP} steps per call: a "
             f"`RolloutCluster({WORKERS})` (threads per worker: {threads}) against a local "
             f"`Rollout(nthread=2)`, median of {rounds} interleaved rounds, results checked "
             f"bit-identical. {cores} cores, shared. Starting the cluster (2 actors, "
             f"importing mjcffi) took {start_cost:.2f} s (paid once).", "",
             "| call | local | Ray | ratio |", "|---|---:|---:|---:|",
             f"| {NROLL} × {NSTEP} humanoid | {_ms(big['local'])} | {_ms(big['ray'])} | "
             f"{ratio:.2f} |",
             f"| 2 × 1 humanoid (fixed cost) | {_ms(tiny['local'])} | {_ms(tiny['ray'])} | "
             f"{tiny['ray'] / tiny['local']:.0f} |", "",
             f"Overhead ratio {ratio:.2f} (target ≤ 1.15: "
             f"{'met' if ratio <= 1.15 else 'not met'}); fixed cost of a call "
             f"{_ms(fixed)}; Ray's round trip of a no-op actor call {_ms(task)}. "
             f"One core steps the humanoid in {step_cost * 1e6:.1f} µs.", "",
             f"On paper, the same call on n nodes of {cores} cores (one worker each), from "
             "the figures above: compute is the slowest thread's whole rollouts; overhead is "
             "the fixed cost plus one per-task round trip per node (the driver hands the "
             f"shards out one by one). The network is left out: the results are "
             f"{mbytes:.1f} MB per call.", ""]
    lines += projection(step_cost, task, fixed, cores)
    lines += ["", f"Below about {break_even(step_cost, task, cores):.1f} rollouts of "
              f"{NSTEP} steps per shard (per {cores}-core node), Ray's per-task cost exceeds "
              f"the shard's compute; with 32-core nodes, below "
              f"{break_even(step_cost, task, 32):.1f}.", ""]
    return lines


if __name__ == "__main__":
    print("\n".join(run()))
