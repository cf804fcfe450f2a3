"""Stepping against the physical limit: Python loops, nstep, and a plain C loop.

The C loop is `lib.mjcffi_step(m, d, n)`: mj_step n times in C under one
guard, nothing else, so its time per step is MuJoCo's own.  Each binding's
Python loop and its `mj_step(m, d, nstep=n)` are compared with it.

`ctrl_c` measures what Ctrl-C costs (issue 27): the same C loop with its SIGINT
token taken and a counter polled per step (`lib.mjcffi_step`), against the loop
with neither (`lib.mjcffi_step_loop(..., token=-1)`), interleaved in one process.
"""

import importlib.resources

import mujoco

import mjcffi
from mjcffi import scenes

from .common import interleaved, per_call


def _gymnasium(name):
    folder = importlib.resources.files("gymnasium") / "envs" / "mujoco" / "assets"
    return str(folder / name)


MODELS = [("pendulum", lambda module: module.MjModel.from_xml_string(scenes.PENDULUM), 2000),
          ("humanoid", lambda module: module.MjModel.from_xml_path(_gymnasium("humanoid.xml")),
           200),
          ("ant", lambda module: module.MjModel.from_xml_path(_gymnasium("ant.xml")), 200)]


def _namespace(module, load):
    model = load(module)
    return {"mj_step": module.mj_step, "mj_resetData": module.mj_resetData, "m": model,
            "d": module.MjData(model), "lib": mjcffi.lib}


def run(rounds=11):
    lines = ["## Stepping against a C loop", "",
             f"Time per step, median of {rounds} interleaved rounds; every call starts from "
             "mj_resetData, so each candidate steps the same trajectory. The C loop is "
             "`lib.mjcffi_step(m, d, n)` (mj_step n times in C, nothing else): MuJoCo's own "
             "cost, the limit for any binding. Ratios are over the official binding, and "
             "over the C loop. Machine load varies, so read ratios within ±5%.", "",
             "| model | call | mjcffi | official | ratio | mjcffi / C loop |",
             "|---|---|---:|---:|---:|---:|"]
    for label, load, n in MODELS:
        spaces = {key: _namespace(mjcffi if key != "theirs" else mujoco, load)
                  for key in ("loop", "nstep", "c", "theirs")}
        reset = "mj_resetData(m, d)\n"
        loop = reset + f"for _ in range({n}): mj_step(m, d)"
        nstep = reset + f"mj_step(m, d, {n})"
        medians = interleaved({
            "loop ours": per_call(loop, spaces["loop"], 1),
            "loop theirs": per_call(loop, spaces["theirs"], 1),
            "nstep ours": per_call(nstep, spaces["nstep"], 1),
            "nstep theirs": per_call(nstep, spaces["theirs"], 1),
            "c": per_call(reset + f"lib.mjcffi_step(m._ptr, d._ptr, {n})", spaces["c"], 1)},
            rounds)
        c = medians["c"] / n
        for call, key in (("Python loop of `mj_step(m, d)`", "loop"),
                          (f"`mj_step(m, d, nstep={n})`", "nstep")):
            a, b = medians[f"{key} ours"] / n, medians[f"{key} theirs"] / n
            lines.append(f"| {label} | {call} | {a * 1e6:.2f} µs | {b * 1e6:.2f} µs | "
                         f"{a / b:.2f} | {a / c:.2f} |")
        lines.append(f"| {label} | C loop | {c * 1e6:.2f} µs | | | 1.00 |")
    return lines + [""] + ctrl_c()


def ctrl_c(rounds=15):
    """What making the nstep loop stoppable by Ctrl-C costs: the loop with a SIGINT token
    (a sigaction call to check that mjcffi's handler is in place, one per call, and a
    counter read per step) over the loop without."""
    m = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    d = mjcffi.MjData(m)
    space = {"lib": mjcffi.lib, "m": m._ptr, "d": d._ptr, "NULL": mjcffi.ffi.NULL}
    lines = ["## What Ctrl-C costs", "",
             f"The nstep loop (the pendulum, median of {rounds} interleaved rounds) with the "
             "SIGINT token taken and polled per step, as `mj_step(m, d, nstep)`, rollout and "
             "MjSimPool run it, over the same loop with no token "
             "(`lib.mjcffi_step_loop(..., token=-1)`), both in C on the main thread.", "",
             "| nstep | with Ctrl-C | without | ratio |", "|---:|---:|---:|---:|"]
    for n in (2, 20, 2000):
        medians = interleaved({
            "with": per_call(f"lib.mjcffi_step(m, d, {n})", space, max(1, 2000 // n)),
            "without": per_call(f"lib.mjcffi_step_loop(m, d, {n}, NULL, -1)", space,
                                max(1, 2000 // n))}, rounds)
        a, b = medians["with"], medians["without"]
        lines.append(f"| {n} | {a * 1e6:.2f} µs | {b * 1e6:.2f} µs | {a / b:.3f} |")
    return lines
