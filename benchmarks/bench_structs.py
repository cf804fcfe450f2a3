"""Struct access and life cycle against the official bindings: attribute reads,
MjData construction, copy and pickle."""

import copy
import pickle

import mujoco

import mjcffi
from mjcffi import scenes

from .common import side_by_side


# (label, statement, calls per round, target ratio text)
CASES = [
    ("`d.qpos`", "d.qpos", 200_000, "≤ 0.3"),
    ("`m.opt.timestep`", "m.opt.timestep", 200_000, "≤ 0.3"),
    ("`d.time`", "d.time", 200_000, ""),
    ("`MjData(m)`", "MjData(m)", 1_000, "≤ 0.1"),
    ("`copy.copy(d)`", "copy.copy(d)", 1_000, "≤ 0.1"),
    ("pickle round trip of `d`", "pickle.loads(pickle.dumps(d))", 500, "≤ 0.1"),
]


def _namespace(module):
    m = module.MjModel.from_xml_string(scenes.PENDULUM)
    d = module.MjData(m)
    return {"m": m, "d": d, "MjData": module.MjData, "copy": copy, "pickle": pickle}


def run(rounds=15):
    ours, theirs = _namespace(mjcffi), _namespace(mujoco)
    lines = [
        "## Structs: attribute access and life cycle",
        "",
        f"One-hinge pendulum; each statement timed with `timeit` (loop overhead included "
        f"on both sides), median of {rounds} interleaved rounds.",
        "",
        "| statement | mjcffi | official | ratio | target |",
        "|---|---:|---:|---:|---:|",
    ]
    for label, statement, calls, target in CASES:
        a, b = side_by_side(statement, ours, theirs, calls, rounds)
        lines.append(f"| {label} | {_fmt(a)} | {_fmt(b)} | {a / b:.2f} | {target} |")
    return lines


def _fmt(seconds):
    return f"{seconds * 1e9:.0f} ns" if seconds < 1e-6 else f"{seconds * 1e6:.1f} µs"
