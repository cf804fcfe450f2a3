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

# (label, the call in both bindings' namespaces, the guarded C call with C arguments,
#  whether it takes arrays, the official call where its signature differs)
ROWS = [
    ("mj_step(m, d, 0)", "mj_step(m, d, 0)", "lib.mjcffi_step(cm, cd, 0)", False),
    ("mj_kinematics(m, d)", "mj_kinematics(m, d)", "lib.mjcffi_guard_mj_kinematics(cm, cd)",
     False),
    ("mj_jac(m, d, jacp, jacr, pt, 1)", "mj_jac(m, d, jacp, jacr, pt, 1)",
     "lib.mjcffi_guard_mj_jac(cm, cd, c_jacp, c_jacr, c_pt, 1)", True),
    ("mj_jacBody(m, d, jacp, jacr, 2)", "mj_jacBody(m, d, jacp, jacr, 2)",
     "lib.mjcffi_guard_mj_jacBody(cm, cd, c_jacp, c_jacr, 2)", True),
    ("mj_fullM(m, d, M)", "mj_fullM(m, d, M)", "lib.mjcffi_guard_mj_fullM(cm, cd, c_M)", True),
    ("mj_mulM(m, d, y, x)", "mj_mulM(m, d, y, x)", "lib.mjcffi_guard_mj_mulM(cm, cd, c_y, c_x)",
     True),
    ("mj_objectVelocity(m, d, 1, 1, v6, 0)", "mj_objectVelocity(m, d, 1, 1, v6, 0)",
     "lib.mjcffi_guard_mj_objectVelocity(cm, cd, 1, 1, c_v6, 0)", True),
    ("mj_name2id(m, 1, 'b2')", "mj_name2id(m, 1, 'b2')",
     "lib.mjcffi_guard_mj_name2id(cm, 1, b'b2')", False),
    ("mju_add3(r, a, b)", "mju_add3(r, a, b)", "lib.mjcffi_guard_mju_add3(c_r, c_a, c_b)", True),
    ("mju_rotVecQuat(r, a, q)", "mju_rotVecQuat(r, a, q)",
     "lib.mjcffi_guard_mju_rotVecQuat(c_r, c_a, c_q)", True),
    ("mju_mulMatVec(y6, A, x6) (6×6)", "mju_mulMatVec(y6, A, x6)",
     "lib.mjcffi_guard_mju_mulMatVec(c_y6, c_A, c_x6, 6, 6)", True),
    ("mju_norm3(a)", "mju_norm3(a)", "lib.mjcffi_guard_mju_norm3(c_a)", True),
    ("mj_contactForce(m, d, 0, f6)", "mj_contactForce(m, d, 0, f6)",
     "lib.mjcffi_guard_mj_contactForce(cm, cd, 0, c_f6)", True),
    ("mj_solveM(m, d, X, Y) (1 × nv)", "mj_solveM(m, d, X, Y)",
     "lib.mjcffi_guard_mj_solveM(cm, cd, c_X, c_Y, 1)", True),
    ("mju_boxQP(res, R, index, H, g, lo, hi) (n = 3)", "mju_boxQP(res, R, index, H, g, lo, hi)",
     "lib.mjcffi_guard_mju_boxQP(c_res, c_R, c_index, c_H, c_g, 3, c_lo, c_hi)", True),
    ("mj_ray(m, d, pnt, vec, None, 1, -1, gid)", "mj_ray(m, d, pnt, vec, None, 1, -1, gid)",
     "lib.mjcffi_guard_mj_ray(cm, cd, c_pnt, c_vec, ffi.NULL, 1, -1, c_gid, ffi.NULL)", True),
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
    """The C arguments of `space` (mjcffi's), made once: pointers, from_buffer arrays."""
    c = {"lib": lib, "ffi": ffi, "cm": space["m"]._ptr, "cd": space["d"]._ptr}
    for name in _ARRAYS:
        c["c_" + name] = ffi.from_buffer(_C_TYPES[space[name].dtype], space[name])
    return c


def prepared_namespace(space):
    """One prepared call per row, named p0, p1, ... as ROWS orders them."""
    prepared = {}
    for i, (_, call, _, _) in enumerate(ROWS):
        name, args = call.split("(", 1)
        prepared[f"p{i}"] = eval(f"{name}.prepare({args}", space)   # noqa: S307 (ours)
    return prepared


def measure(rounds=21, calls=20000):
    """{label: (plain, prepared, official, C alone)} in seconds per call."""
    ours, theirs = namespace(mjcffi), namespace(mujoco)
    floor = c_namespace(ours)
    prepared = prepared_namespace(ours)
    results = {}
    for i, (label, call, c_call, _) in enumerate(ROWS):
        medians = interleaved({
            "plain": per_call(call, ours, calls),
            "prepared": per_call(f"p{i}()", prepared, calls),
            "official": per_call(call, theirs, calls),
            "floor": per_call(c_call, floor, calls),
        }, rounds)
        results[label] = (medians["plain"], medians["prepared"], medians["official"],
                          medians["floor"])
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
        "Plain: `mjcffi.F(...)`; prepared: `p = mjcffi.F.prepare(...)` once, then `p()`; "
        "C alone: the guarded C function called from Python with its C arguments made "
        "beforehand, which is what cffi itself costs (the floor of any wrapper). Ratios "
        "are over the official call.",
        "",
        "| call | plain | prepared | official | C alone | plain ratio | prepared ratio |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    for label, (plain, prepared, official, floor) in results.items():
        lines.append(f"| `{label}` | {plain * 1e9:.0f} ns | {prepared * 1e9:.0f} ns | "
                     f"{official * 1e9:.0f} ns | {floor * 1e9:.0f} ns | "
                     f"{plain / official:.2f} | {prepared / official:.2f} |")
    plain = [p / o for p, _, o, _ in results.values()]
    arrays = [q / o for label, (_, q, o, _) in results.items() if takes_arrays[label]]
    model_data = [q / o for label, (_, q, o, _) in results.items()
                  if not takes_arrays[label]]
    lines += [
        "",
        "| summary | value |",
        "|---|---:|",
        f"| plain calls: geometric mean of the ratios | {_gmean(plain):.2f} |",
        f"| plain calls: highest ratio | {max(plain):.2f} |",
        f"| prepared calls taking arrays: geometric mean | {_gmean(arrays):.2f} |",
        f"| prepared calls taking arrays: highest ratio | {max(arrays):.2f} |",
        f"| prepared calls without arrays: highest ratio | {max(model_data):.2f} |",
    ]
    return lines
