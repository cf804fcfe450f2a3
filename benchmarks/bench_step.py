"""Per-call cost of `mj_step` against the official binding.

`mj_step(m, d, nstep=0)` runs no physics, so its time is the binding's whole
call overhead.  On a one-hinge pendulum the C work is small, so the figure
shows the overhead in context; the default scene adds contacts.
"""

import mujoco

import mjcffi
from mjcffi import scenes

from .common import interleaved, per_call

PENDULUM = """
<mujoco>
  <worldbody>
    <body><joint type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 -1" size=".05"/></body>
  </worldbody>
</mujoco>
"""


def _pair(xml):
    m, om = mjcffi.MjModel.from_xml_string(xml), mujoco.MjModel.from_xml_string(xml)
    return (m, mjcffi.MjData(m)), (om, mujoco.MjData(om))


def _row(label, ours, theirs, rounds, calls):
    medians = interleaved({"mjcffi": per_call(ours, calls),
                           "official": per_call(theirs, calls)}, rounds)
    a, b = medians["mjcffi"], medians["official"]
    return f"| {label} | {a * 1e9:.0f} ns | {b * 1e9:.0f} ns | {a / b:.2f} |"


def run(rounds=21, calls=20000):
    (m, d), (om, od) = _pair(PENDULUM)
    lines = [
        "## `mj_step` per call",
        "",
        f"Median of {rounds} interleaved rounds of {calls:,} calls from a Python loop. "
        "`import mujoco` installs a timer in the shared `mjcb_time`, so in this process "
        "both bindings pay for it on every step; the ratios compare like with like.",
        "",
        "| call | mjcffi | official | ratio |",
        "|---|---:|---:|---:|",
        _row("`mj_step(m, d, nstep=0)`: call overhead alone (target ≤ 0.8)",
             lambda: mjcffi.mj_step(m, d, 0), lambda: mujoco.mj_step(om, od, 0), rounds, calls),
        _row("`mj_step(m, d)`, one-hinge pendulum",
             lambda: mjcffi.mj_step(m, d), lambda: mujoco.mj_step(om, od), rounds, calls),
        _row("raw `lib.mj_step(m._ptr, d._ptr)` (unguarded), pendulum",
             lambda: mjcffi.lib.mj_step(m._ptr, d._ptr), lambda: mujoco.mj_step(om, od),
             rounds, calls),
    ]
    (m2, d2), (om2, od2) = _pair(scenes.DEFAULT)
    lines.append(_row("`mj_step(m, d)`, default scene", lambda: mjcffi.mj_step(m2, d2),
                      lambda: mujoco.mj_step(om2, od2), rounds, calls // 4))
    return lines
