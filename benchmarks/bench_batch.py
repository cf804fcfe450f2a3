"""Batch throughput: `mjcffi.batch.Batch.step` against the official `mujoco.batch.Batch`.

Both bindings call the same `mjb_step` of the same libmujoco, so the physics
costs the same; what differs is each binding's work around the call.  On
gymnasium's humanoid the physics dominates; on a one-hinge pendulum with few
simulations the call itself does.  The thread counts are 1, 2 and the
machine's CPU count.
"""

import os

import mujoco
import numpy as np
from mujoco import batch as official_batch

import mjcffi
from mjcffi import batch, scenes

from .common import interleaved, per_call



def _humanoid_path():
    """gymnasium's humanoid.xml, or None without gymnasium (a test extra)."""
    import importlib.resources
    try:
        folder = importlib.resources.files("gymnasium") / "envs" / "mujoco" / "assets"
    except ModuleNotFoundError:
        return None
    return str(folder / "humanoid.xml")


def _thread_counts():
    return sorted({1, 2, os.cpu_count() or 1})


def _pair(source, nsim, nthread):
    """The same batch in both bindings, with the same random controls."""
    if source.lstrip().startswith("<"):
        ours, theirs = mjcffi.MjModel.from_xml_string(source), \
            mujoco.MjModel.from_xml_string(source)
    else:
        ours, theirs = mjcffi.MjModel.from_xml_path(source), mujoco.MjModel.from_xml_path(source)
    b, ob = batch.Batch(ours, nsim, nthread), official_batch.Batch(theirs, nsim, nthread)
    u = np.random.default_rng(0).uniform(-0.4, 0.4, (nsim, ours.nu))
    b.ctrl, ob.ctrl = u, u
    return b, ob


def _row(label, source, nsim, nstep, nthread, rounds, calls):
    b, ob = _pair(source, nsim, nthread)
    statement = f"b.step(None, {nstep})"
    medians = interleaved({"mjcffi": per_call(statement, {"b": b}, calls),
                           "official": per_call(statement, {"b": ob}, calls)}, rounds)
    # both stepped the same trajectories: a free check that they still agree
    same = "yes" if np.array_equal(b.state, ob.state, equal_nan=True) else "NO"
    ours, theirs = medians["mjcffi"], medians["official"]
    steps = nsim * nstep
    return (f"| {label} | {nsim} | {nstep} | {b.nthread} | {steps / ours:,.0f} | "
            f"{steps / theirs:,.0f} | {ours / theirs:.3f} | {same} |")


def run(rounds=15):
    threads = _thread_counts()
    lines = [
        "## Batch throughput (`Batch.step`)",
        "",
        f"Simulation steps per second, median of {rounds} interleaved rounds; one row per "
        f"model, number of simulations, substeps per call and thread count "
        f"({os.cpu_count()} CPUs here). The time ratio is mjcffi / official per call "
        "(at most 1: mjcffi is at least as fast). Both batches step the same controls from "
        "the same state, and the last column says whether their states are still "
        "bit-identical at the end. `import mujoco` installs a timer in the shared "
        "`mjcb_time`, which both bindings then pay for.",
        "",
        "| model | nsim | nstep | threads | mjcffi steps/s | official steps/s | time ratio "
        "| bit-identical |",
        "|---|---:|---:|---:|---:|---:|---:|:---:|",
    ]
    humanoid = _humanoid_path()
    if humanoid is None:
        lines.insert(-3, "gymnasium is not installed (`pip install gymnasium`): no humanoid rows.")
        lines.insert(-3, "")
    else:
        for nthread in threads:
            lines.append(_row("humanoid", humanoid, 64, 1, nthread, rounds, 10))
        for nthread in threads:
            lines.append(_row("humanoid", humanoid, 16, 10, nthread, rounds, 5))
    for nthread in threads:
        lines.append(_row("pendulum", scenes.PENDULUM, 8, 1, nthread, rounds, 2000))
    for nthread in threads:
        lines.append(_row("pendulum", scenes.PENDULUM, 1024, 1, nthread, rounds, 50))
    return lines


if __name__ == "__main__":
    print("\n".join(run()))
