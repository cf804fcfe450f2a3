"""Stepping against the physical limit: Python loops, nstep, and a plain C loop.

The C loop is `lib.mjcffi_step(m, d, n)`: mj_step n times in C under one
guard, nothing else, so its time per step is MuJoCo's own.  Each binding's
Python loop and its `mj_step(m, d, nstep=n)` are compared with it.
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
    return lines
