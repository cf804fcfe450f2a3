"""Rollout throughput of `mjcffi.rollout` against the official `mujoco.rollout`.

Each binding rolls out the same model, initial states and controls with a
persistent `Rollout` pool of the same size and preallocated outputs; the
figure is simulation steps per second (nroll x nstep per call).  On gymnasium's
humanoid the physics dominates; on a one-hinge pendulum with short rollouts
the cost of a call (argument checks, waking the threads) does.
"""

import importlib.resources
import os
import time

import mujoco
import numpy as np
from mujoco import rollout as official_rollout

import mjcffi
from mjcffi import rollout as mjcffi_rollout, scenes

from .common import interleaved



def _humanoid_path():
    """gymnasium's humanoid.xml, loaded from the installed package."""
    try:
        assets = importlib.resources.files("gymnasium") / "envs" / "mujoco" / "assets"
    except ModuleNotFoundError:
        raise RuntimeError("the rollout benchmark needs gymnasium's humanoid: "
                           "pip install gymnasium") from None
    return str(assets / "humanoid.xml")


def thread_counts():
    """1, 2, 4, ... up to the machine's cores, and the core count itself."""
    cores = os.cpu_count() or 1
    counts = [1]
    while counts[-1] * 2 <= cores:
        counts.append(counts[-1] * 2)
    if counts[-1] != cores:
        counts.append(cores)
    return counts


class Case:
    """One binding's side of a measurement: model, data, inputs, outputs and pool."""

    def __init__(self, module, rollout_module, load, nthread, nroll, nstep, calls):
        self.model = load(module)
        self.data = [module.MjData(self.model) for _ in range(nthread)]
        nstate = module.mj_stateSize(self.model, int(module.mjtState.mjSTATE_FULLPHYSICS))
        state0 = np.empty(nstate)
        module.mj_getState(self.model, self.data[0], state0,
                           int(module.mjtState.mjSTATE_FULLPHYSICS))
        rng = np.random.default_rng(0)
        self.initial = np.tile(state0, (nroll, 1))
        self.control = rng.uniform(-0.4, 0.4, (nroll, nstep, self.model.nu))
        self.state = np.empty((nroll, nstep, nstate))
        self.sensordata = np.empty((nroll, nstep, self.model.nsensordata))
        # nthread 1 is the calling thread alone, as rollout.rollout does with one MjData
        self.pool = rollout_module.Rollout(nthread=nthread if nthread > 1 else 0)
        self.calls = calls

    def timer(self):
        """A callable returning seconds per rollout call, over `calls` calls."""
        pool, args = self.pool, (self.model, self.data, self.initial, self.control)
        kwargs = {"state": self.state, "sensordata": self.sensordata}

        def run():
            start = time.perf_counter()
            for _ in range(self.calls):
                pool.rollout(*args, **kwargs)
            return (time.perf_counter() - start) / self.calls
        return run

    def close(self):
        """Shut the pool down."""
        self.pool.close()


def _measure(load, nthread, nroll, nstep, calls, rounds):
    """Median seconds per call, {binding: seconds}, and the two results (checked equal)."""
    ours = Case(mjcffi, mjcffi_rollout, load, nthread, nroll, nstep, calls)
    theirs = Case(mujoco, official_rollout, load, nthread, nroll, nstep, calls)
    try:
        medians = interleaved({"mjcffi": ours.timer(), "official": theirs.timer()}, rounds)
        if not (np.array_equal(ours.state, theirs.state) and
                np.array_equal(ours.sensordata, theirs.sensordata)):
            raise AssertionError("mjcffi and official rollouts differ")
    finally:
        ours.close()
        theirs.close()
    return medians


def _rate(seconds, steps):
    """Steps per second, in words."""
    rate = steps / seconds
    return f"{rate / 1e6:.2f} M" if rate >= 1e6 else f"{rate / 1e3:.0f} k"


def run(rounds=11):
    humanoid = _humanoid_path()
    models = [
        ("humanoid", lambda module: module.MjModel.from_xml_path(humanoid), 16, 50, 2),
        ("pendulum, short (per-call cost)", lambda module: module.MjModel.from_xml_string(
            scenes.PENDULUM), 4, 10, 500),
        ("pendulum, long", lambda module: module.MjModel.from_xml_string(scenes.PENDULUM), 64, 100, 5),
    ]
    counts = thread_counts()
    lines = ["## `rollout` throughput", "",
             f"Median of {rounds} interleaved rounds; each round times a few calls of "
             "`Rollout(nthread=n).rollout(model, data, initial_state, control, state=..., "
             "sensordata=...)` with n MjData, the same inputs and preallocated outputs on both "
             "sides (the outputs are checked equal). Figures are simulation steps per second "
             "(nroll × nstep per call); the time ratio is mjcffi / official per call, as "
             "elsewhere in this file (at most 1: mjcffi is at least as fast). Target: time "
             f"ratio ≤ 1 at 1 and 2 threads. {os.cpu_count()} cores. Both bindings run the same C calls "
             "per step (mj_setState, mj_step, mj_getState), so where the physics dominates "
             "the time ratio is 1 within noise; `import mujoco` installs a timer in the shared "
             "`mjcb_time`, which both pay on every step.", "",
             "| model | nroll × nstep | threads | mjcffi steps/s | official steps/s | time ratio |",
             "|---|---|---:|---:|---:|---:|"]
    humanoid_rates = {}
    for label, load, nroll, nstep, calls in models:
        for nthread in counts:
            medians = _measure(load, nthread, nroll, nstep, calls, rounds)
            ours, theirs = medians["mjcffi"], medians["official"]
            steps = nroll * nstep
            if label == "humanoid":
                humanoid_rates[nthread] = (steps / ours, steps / theirs)
            lines.append(f"| {label} | {nroll} × {nstep} | {nthread} | {_rate(ours, steps)} | "
                         f"{_rate(theirs, steps)} | {ours / theirs:.2f} |")
    lines += ["", "Thread scaling on the humanoid, steps/s at n threads over steps/s at 1 "
              "(target for mjcffi at 2 threads: ≥ 1.8):", "",
              "| threads | mjcffi | official |", "|---:|---:|---:|"]
    base_ours, base_theirs = humanoid_rates[1]
    for nthread in counts[1:]:
        ours, theirs = humanoid_rates[nthread]
        lines.append(f"| 1 → {nthread} | {ours / base_ours:.2f}× | "
                     f"{theirs / base_theirs:.2f}× |")
    return lines


if __name__ == "__main__":
    print("\n".join(run()))
