"""Model editing (MjSpec) against the official bindings: building and compiling a
tree in code, parsing and saving, and element attribute reads and writes.

    python -m benchmarks.bench_spec          # prints the table
"""

import os

import mujoco

import mjcffi

from .common import side_by_side

BODIES = 100


def _build(module, bodies=BODIES):
    """A tree of `bodies` bodies (a binary tree, each with a hinge and a capsule) built
    with keyword add_* calls, as user code builds one."""
    spec = module.MjSpec()
    spec.worldbody.add_geom(type=module.mjtGeom.mjGEOM_PLANE, size=[5, 5, 0.1])
    parents = [spec.worldbody]
    for i in range(bodies):
        parent = parents[(i - 1) // 2 + 1] if i else parents[0]
        body = parent.add_body(name=f"b{i}", pos=[0.1, 0, 0.2])
        body.add_joint(name=f"j{i}", type=module.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0])
        body.add_geom(name=f"g{i}", type=module.mjtGeom.mjGEOM_CAPSULE,
                      size=[0.02, 0.05, 0], rgba=[0.8, 0.3, 0.3, 1])
        parents.append(body)
    return spec


def _humanoid():
    import gymnasium
    path = os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets",
                        "humanoid.xml")
    with open(path, encoding="utf-8") as file:
        return file.read()


def _namespace(module, xml):
    spec = _build(module)
    return {"module": module, "build": _build, "xml": xml, "spec": spec,
            "g": spec.geom("g7"), "b": spec.body("b7"), "size": [0.03, 0.06, 0],
            "parsed": module.MjSpec.from_string(xml)}


STATEMENTS = (
    # (statement, calls, target)
    ("build(module)", 20, ""),
    ("build(module).compile()", 20, "≤ 1.0"),
    ("spec.compile()", 20, ""),
    ("module.MjSpec.from_string(xml)", 20, ""),
    ("parsed.to_xml()", 20, ""),
    ("g.size", 20_000, "≤ 0.5"),
    ("g.size = size", 20_000, "≤ 0.5"),
    ("b.pos[2] = 0.3", 20_000, "≤ 0.5"),
    ("g.name", 20_000, "≤ 0.5"),
    ("g.type", 20_000, "≤ 0.5"),
    ("b.userdata", 20_000, "≤ 0.5"),
    ("spec.geom('g7')", 20_000, ""),
)


def run(rounds=11):
    xml = _humanoid()
    ours, theirs = _namespace(mjcffi, xml), _namespace(mujoco, xml)
    lines = ["## Model editing (MjSpec)", "",
             f"Median of {rounds} interleaved rounds; `build` makes a {BODIES}-body tree "
             "with a hinge and a capsule per body through keyword `add_*` calls; `parsed` "
             "is gymnasium's humanoid. Attribute rows read or write one element of that tree.",
             "", "| statement | mjcffi | official | ratio | target |",
             "|---|---:|---:|---:|---:|"]
    for statement, calls, target in STATEMENTS:
        a, b = side_by_side(statement, ours, theirs, calls, rounds)
        lines.append(f"| `{statement}` | {_time(a)} | {_time(b)} | {a / b:.2f} | {target} |")
    return lines


def _time(seconds):
    if seconds >= 1e-3:
        return f"{seconds * 1e3:.2f} ms"
    if seconds >= 1e-6:
        return f"{seconds * 1e6:.2f} µs"
    return f"{seconds * 1e9:.0f} ns"


if __name__ == "__main__":
    print("\n".join(run()))
