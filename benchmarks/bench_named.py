"""Named access against the official bindings, and its O(1) claim."""

import time

import mujoco

import mjcffi

from .common import interleaved, per_call, side_by_side

SCENE = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 .1"/>
    <body name="pole"><joint name="hinge" type="hinge"/><geom name="rod" size=".1"/></body>
  </worldbody>
</mujoco>
"""


def _grid(count):
    """A model of `count` named geoms (static spheres)."""
    geoms = "".join(f'<geom name="g{i}" size=".01" pos="{i % 100} {i // 100} 0"/>'
                    for i in range(count))
    return f"<mujoco><worldbody>{geoms}</worldbody></mujoco>"


def _namespace(module):
    m = module.MjModel.from_xml_string(SCENE)
    return {"m": m, "d": module.MjData(m)}


def _lookups(m, names):
    """Seconds per lookup of each name once (first lookups: accessors are built)."""
    start = time.perf_counter()
    for name in names:
        m.geom(name)
    return (time.perf_counter() - start) / len(names)


def _scaling(rounds):
    small = mjcffi.MjModel.from_xml_string(_grid(10))
    large = mjcffi.MjModel.from_xml_string(_grid(10_000))
    small.geom("g0"), large.geom("g0")            # the name tables are built once
    cached = interleaved({"10": per_call("m.geom('g7')", {"m": small}, 50_000),
                          "10,000": per_call("m.geom('g7777')", {"m": large}, 50_000)}, rounds)
    fresh_small = _lookups(small, [f"g{i}" for i in range(1, 10)])
    fresh_large = _lookups(large, [f"g{i}" for i in range(1, 10_000, 1111)])
    return cached, fresh_small, fresh_large


def run(rounds=15, calls=50_000):
    ours, theirs = _namespace(mjcffi), _namespace(mujoco)
    lines = ["## Named access", "",
             f"Median of {rounds} interleaved rounds of {calls:,} calls (timeit), accessors "
             "warm on both sides.", "",
             "| statement | mjcffi | official | ratio | target |",
             "|---|---:|---:|---:|---:|"]
    for statement in ("d.joint('hinge').qpos", "m.geom('rod').rgba", "m.geom(1).rgba"):
        a, b = side_by_side(statement, ours, theirs, calls, rounds)
        target = "≤ 0.3" if "(1)" not in statement else ""
        lines.append(f"| `{statement}` | {a * 1e9:.0f} ns | {b * 1e9:.0f} ns | {a / b:.2f} "
                     f"| {target} |")
    cached, fresh_small, fresh_large = _scaling(rounds)
    lines += ["",
              "O(1) in the number of elements: `m.geom(name)` on a model of 10 geoms and on "
              "one of 10,000 (target: less than 2x apart).", "",
              "| lookup | 10 geoms | 10,000 geoms | ratio |",
              "|---|---:|---:|---:|",
              f"| cached accessor, median of {rounds} interleaved rounds | "
              f"{cached['10'] * 1e9:.0f} ns | {cached['10,000'] * 1e9:.0f} ns | "
              f"{cached['10,000'] / cached['10']:.2f} |",
              f"| first lookup of a name (accessor built), mean of 9 names | "
              f"{fresh_small * 1e6:.1f} µs | {fresh_large * 1e6:.1f} µs | "
              f"{fresh_large / fresh_small:.2f} |"]
    return lines
