"""Per-call cost of `mj_step` through raw `lib` against the official binding.

On a one-hinge pendulum the C work is tiny, so the figure is mostly the
binding's per-call overhead; the default scene adds contacts.
"""

import mujoco

from mjcffi import _loading, lib, ffi, scenes

from .common import interleaved, per_call

PENDULUM = """
<mujoco>
  <worldbody>
    <body><joint type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 -1" size=".05"/></body>
  </worldbody>
</mujoco>
"""


def _pair(xml):
    ours = _loading.load_xml_string(xml)
    our_data = ffi.gc(lib.mj_makeData(ours), lib.mj_deleteData)
    theirs = mujoco.MjModel.from_xml_string(xml)
    their_data = mujoco.MjData(theirs)
    return (lambda: lib.mj_step(ours, our_data)), (lambda: mujoco.mj_step(theirs, their_data))


def run(rounds=21, calls=20000):
    lines = [
        "## `mj_step(m, d)` per call, raw `lib` against official",
        "",
        f"Median of {rounds} interleaved rounds of {calls:,} calls from a Python loop; "
        "ratio below 1 means mjcffi is faster.",
        "",
        "| scene | mjcffi µs/step | official µs/step | ratio |",
        "|---|---:|---:|---:|",
    ]
    for name, xml in (("one-hinge pendulum", PENDULUM), ("default scene", scenes.DEFAULT)):
        ours, theirs = _pair(xml)
        medians = interleaved({"mjcffi": per_call(ours, calls),
                               "official": per_call(theirs, calls)}, rounds)
        a, b = medians["mjcffi"], medians["official"]
        lines.append(f"| {name} | {a * 1e6:.2f} | {b * 1e6:.2f} | {a / b:.2f} |")
    return lines
