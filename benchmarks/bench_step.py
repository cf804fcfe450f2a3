"""Per-call cost of `mj_step` against the official binding.

`mj_step(m, d, nstep=0)` runs no physics, so its time is the binding's whole
call overhead.  On a one-hinge pendulum the C work is small, so the figure
shows the overhead in context; the default scene adds contacts.
"""

import mujoco

import mjcffi
from mjcffi import scenes

from .common import side_by_side



def _namespace(module, xml):
    m = module.MjModel.from_xml_string(xml)
    return {"mj_step": module.mj_step, "m": m, "d": module.MjData(m), "lib": mjcffi.lib}


def _row(label, statement, ours, theirs, rounds, calls, official_statement=None):
    a, b = side_by_side(statement, ours, theirs, calls, rounds, official_statement)
    return f"| {label} | {a * 1e9:.0f} ns | {b * 1e9:.0f} ns | {a / b:.2f} |"


def run(rounds=21, calls=20000):
    ours, theirs = _namespace(mjcffi, scenes.PENDULUM), _namespace(mujoco, scenes.PENDULUM)
    lines = [
        "## `mj_step` per call",
        "",
        f"Median of {rounds} interleaved rounds of {calls:,} calls, timed with `timeit`. "
        "`import mujoco` installs a timer in the shared `mjcb_time`, so in this process "
        "both bindings pay for it on every step; the ratios compare like with like.",
        "",
        "| call | mjcffi | official | ratio |",
        "|---|---:|---:|---:|",
        _row("`mj_step(m, d, 0)`: the call alone, no physics (target ≤ 0.8)",
             "mj_step(m, d, 0)", ours, theirs, rounds, calls),
        _row("`mj_step(m, d)`, one-hinge pendulum", "mj_step(m, d)", ours, theirs, rounds, calls),
        _row("raw `lib.mj_step(m._ptr, d._ptr)` (no guard), pendulum",
             "lib.mj_step(m._ptr, d._ptr)", ours, theirs, rounds, calls, "mj_step(m, d)"),
    ]
    ours, theirs = _namespace(mjcffi, scenes.DEFAULT), _namespace(mujoco, scenes.DEFAULT)
    lines.append(_row("`mj_step(m, d)`, default scene", "mj_step(m, d)", ours, theirs, rounds,
                      calls // 4))
    return lines
