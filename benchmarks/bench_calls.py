"""The cost of a call: common MuJoCo functions, plain and prepared, against the official.

On a small model (a free body resting on a plane, with a hinged child), each
call is timed four ways, interleaved in every round: mjcffi's plain call,
mjcffi's prepared call (`F.prepare(...)`, then `p()` each time), the
official call, and the guarded C call alone with its C arguments made
beforehand (`lib.mjcffi_guard_F(...)`): what cffi itself costs, the floor under
any Python wrapper of it.
"""

import math

import numpy as np
import mujoco

import mjcffi
from mjcffi import ffi, lib

from .common import interleaved, per_call

SCENE = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 .1"/>
    <body name="b1" pos="0 0 .099">
      <freejoint/>
      <geom name="ball" size=".1"/>
      <body name="b2" pos="0 0 .3">
        <joint name="h" type="hinge"/>
        <geom type="capsule" size=".05" fromto="0 0 0 0 0 .2"/>
      </body>
    </body>
  </worldbody>
  <actuator><motor joint="h"/></actuator>
</mujoco>
"""

# (label, the call in both bindings' namespaces, the guarded C call with {array}
#  placeholders, whether it takes arrays)
ROWS = [
    ("mj_step(m, d, 0)", "mj_step(m, d, 0)", "lib.mjcffi_step(cm, cd, 0)", False),
    ("mj_kinematics(m, d)", "mj_kinematics(m, d)", "lib.mjcffi_guard_mj_kinematics(cm, cd)",
     False),
    ("mj_jac(m, d, jacp, jacr, pt, 1)", "mj_jac(m, d, jacp, jacr, pt, 1)",
     "lib.mjcffi_guard_mj_jac(cm, cd, {jacp}, {jacr}, {pt}, 1)", True),
    ("mj_jacBody(m, d, jacp, jacr, 2)", "mj_jacBody(m, d, jacp, jacr, 2)",
     "lib.mjcffi_guard_mj_jacBody(cm, cd, {jacp}, {jacr}, 2)", True),
    ("mj_fullM(m, d, M)", "mj_fullM(m, d, M)", "lib.mjcffi_guard_mj_fullM(cm, cd, {M})", True),
    ("mj_mulM(m, d, y, x)", "mj_mulM(m, d, y, x)", "lib.mjcffi_guard_mj_mulM(cm, cd, {y}, {x})",
     True),
    ("mj_objectVelocity(m, d, 1, 1, v6, 0)", "mj_objectVelocity(m, d, 1, 1, v6, 0)",
     "lib.mjcffi_guard_mj_objectVelocity(cm, cd, 1, 1, {v6}, 0)", True),
    ("mj_name2id(m, 1, 'b2')", "mj_name2id(m, 1, 'b2')",
     "lib.mjcffi_guard_mj_name2id(cm, 1, b'b2')", False),
    ("mju_add3(r, a, b)", "mju_add3(r, a, b)", "lib.mjcffi_guard_mju_add3({r}, {a}, {b})", True),
    ("mju_rotVecQuat(r, a, q)", "mju_rotVecQuat(r, a, q)",
     "lib.mjcffi_guard_mju_rotVecQuat({r}, {a}, {q})", True),
    ("mju_mulMatVec(y6, A, x6) (6×6)", "mju_mulMatVec(y6, A, x6)",
     "lib.mjcffi_guard_mju_mulMatVec({y6}, {A}, {x6}, 6, 6)", True),
    ("mju_norm3(a)", "mju_norm3(a)", "lib.mjcffi_guard_mju_norm3({a})", True),
    ("mj_contactForce(m, d, 0, f6)", "mj_contactForce(m, d, 0, f6)",
     "lib.mjcffi_guard_mj_contactForce(cm, cd, 0, {f6})", True),
    ("mj_solveM(m, d, X, Y) (1 × nv)", "mj_solveM(m, d, X, Y)",
     "lib.mjcffi_guard_mj_solveM(cm, cd, {X}, {Y}, 1)", True),
    ("mju_boxQP(res, R, index, H, g, lo, hi) (n = 3)", "mju_boxQP(res, R, index, H, g, lo, hi)",
     "lib.mjcffi_guard_mju_boxQP({res}, {R}, {index}, {H}, {g}, 3, {lo}, {hi})", True),
    ("mj_ray(m, d, pnt, vec, None, 1, -1, gid)", "mj_ray(m, d, pnt, vec, None, 1, -1, gid)",
     "lib.mjcffi_guard_mj_ray(cm, cd, {pnt}, {vec}, ffi.NULL, 1, -1, {gid}, ffi.NULL)", True),
]

_ARRAYS = {   # name -> a function of nv making it
    "jacp": lambda nv: np.zeros((3, nv)), "jacr": lambda nv: np.zeros((3, nv)),
    "pt": lambda nv: np.array([0.0, 0.0, 0.2]), "M": lambda nv: np.zeros((nv, nv)),
    "y": lambda nv: np.zeros(nv), "x": lambda nv: np.linspace(0.1, 1.0, nv),
    "v6": lambda nv: np.zeros(6), "r": lambda nv: np.zeros(3),
    "a": lambda nv: np.array([0.3, -0.2, 0.9]), "b": lambda nv: np.array([1.0, 2.0, 3.0]),
    "q": lambda nv: np.array([0.9, 0.1, 0.3, 0.3]) / np.linalg.norm([0.9, 0.1, 0.3, 0.3]),
    "y6": lambda nv: np.zeros(6), "A": lambda nv: np.arange(36.0).reshape(6, 6) / 36,
    "x6": lambda nv: np.linspace(-1.0, 1.0, 6), "f6": lambda nv: np.zeros(6),
    "X": lambda nv: np.zeros((1, nv)), "Y": lambda nv: np.ones((1, nv)),
    "res": lambda nv: np.zeros(3), "R": lambda nv: np.zeros(3 * 10),
    "index": lambda nv: np.zeros(3, np.int32),
    "H": lambda nv: np.array([[4.0, 1.0, 0.0], [1.0, 3.0, 0.5], [0.0, 0.5, 2.0]]),
    "g": lambda nv: np.array([-1.0, 2.0, 0.5]), "lo": lambda nv: -np.ones(3),
    "hi": lambda nv: np.ones(3), "pnt": lambda nv: np.array([0.0, 0.0, 2.0]),
    "vec": lambda nv: np.array([0.0, 0.0, -1.0]), "gid": lambda nv: np.zeros(1, np.int32),
}

_C_TYPES = {np.dtype(np.float64): "double[]", np.dtype(np.int32): "int[]"}


def namespace(module):
    """The model, data and arrays of ROWS for `module`, the functions as globals."""
    m = module.MjModel.from_xml_string(SCENE)
    d = module.MjData(m)
    module.mj_forward(m, d)
    assert d.ncon > 0, "the benchmark scene must have a contact for mj_contactForce"
    space = {name: make(m.nv) for name, make in _ARRAYS.items()}
    space.update(m=m, d=d)
    space.update({name: getattr(module, name) for name in dir(module) if name.startswith("mj")})
    return space


def c_namespace(space):
    """For the C calls of ROWS: mjcffi's model and data pointers, every array as `c_<name>`
    (its from_buffer made once) and as itself, and its cffi type as `T_<name>`."""
    c = {"lib": lib, "ffi": ffi, "fb": ffi.from_buffer, "cm": space["m"]._ptr,
         "cd": space["d"]._ptr}
    for name in _ARRAYS:
        ctype = ffi.typeof(_C_TYPES[space[name].dtype])
        c.update({name: space[name], "T_" + name: ctype,
                  "c_" + name: ffi.from_buffer(ctype, space[name])})
    return c


def c_calls(template):
    """(the C call with its arguments made once, the C call with a from_buffer per array)."""
    names = [name for name in _ARRAYS if "{" + name + "}" in template]
    ready = template.format(**{name: "c_" + name for name in names})
    fresh = template.format(**{name: f"fb(T_{name}, {name})" for name in names})
    return ready, fresh


def prepared_namespace(space):
    """One prepared call per row, named p0, p1, ... as ROWS orders them."""
    prepared = {}
    for i, (_, call, _, _) in enumerate(ROWS):
        name, args = call.split("(", 1)
        prepared[f"p{i}"] = eval(f"{name}.prepare({args}", space)   # noqa: S307 (ours)
    return prepared


def measure(rounds=21, calls=20000):
    """{label: {plain, prepared, official, floor, c}} in seconds per call."""
    ours, theirs = namespace(mjcffi), namespace(mujoco)
    c_space = c_namespace(ours)
    prepared = prepared_namespace(ours)
    results = {}
    for i, (label, call, c_call, _) in enumerate(ROWS):
        ready, fresh = c_calls(c_call)
        results[label] = interleaved({
            "plain": per_call(call, ours, calls),
            "prepared": per_call(f"p{i}()", prepared, calls),
            "official": per_call(call, theirs, calls),
            "floor": per_call(fresh, c_space, calls),
            "c": per_call(ready, c_space, calls),
        }, rounds)
    return results


def _gmean(values):
    values = list(values)
    return math.exp(sum(math.log(v) for v in values) / len(values))


def run(rounds=21, calls=20000):
    results = measure(rounds, calls)
    takes_arrays = {label: arrays for label, _, _, arrays in ROWS}
    lines = [
        "## The cost of a call",
        "",
        f"A free body resting on a plane with a hinged child (nv = 7, one contact); median "
        f"of {rounds} interleaved rounds of {calls:,} calls each, timed with `timeit`. "
        "Plain: `mjcffi.F(...)`. Prepared: `p = mjcffi.F.prepare(...)` once, then `p()`. "
        "Official: the official bindings' `F(...)`. Floor: the guarded C function called "
        "straight from Python with an `ffi.from_buffer` made for each array, and no check "
        "at all: what cffi costs before any wrapper. C alone: the same with every C argument "
        "made beforehand (what a prepared call cannot go below). Ratios are over the "
        "official call.",
        "",
        "| call | plain | prepared | official | floor | C alone | plain ratio | "
        "prepared ratio | floor ratio |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for label, r in results.items():
        lines.append(
            f"| `{label}` | {r['plain'] * 1e9:.0f} ns | {r['prepared'] * 1e9:.0f} ns | "
            f"{r['official'] * 1e9:.0f} ns | {r['floor'] * 1e9:.0f} ns | "
            f"{r['c'] * 1e9:.0f} ns | {r['plain'] / r['official']:.2f} | "
            f"{r['prepared'] / r['official']:.2f} | {r['floor'] / r['official']:.2f} |")
    plain = [r["plain"] / r["official"] for r in results.values()]
    floor = [r["floor"] / r["official"] for r in results.values()]
    arrays = [r["prepared"] / r["official"] for label, r in results.items()
              if takes_arrays[label]]
    others = [r["prepared"] / r["official"] for label, r in results.items()
              if not takes_arrays[label]]
    lines += [
        "",
        "| summary | value |",
        "|---|---:|",
        f"| plain calls: geometric mean of the ratios | {_gmean(plain):.2f} |",
        f"| plain calls: highest ratio | {max(plain):.2f} |",
        f"| floor (no checks): geometric mean of the ratios | {_gmean(floor):.2f} |",
        f"| prepared calls taking arrays: geometric mean | {_gmean(arrays):.2f} |",
        f"| prepared calls taking arrays: highest ratio | {max(arrays):.2f} |",
        f"| prepared calls without arrays: highest ratio | {max(others):.2f} |",
    ]
    return lines
