"""The official `mujoco._constants` path: MuJoCo's #define constants (generated in
mjcffi/_generated/), and the official module's other names: MJTNUM_BYTES and the
string tables (mjDISABLESTRING, ...), made on first use as mjcffi's own are."""

import importlib

from ._generated.constants import *  # noqa: F401,F403

# the official module's names that mjcffi makes on first use: mjcffi.<name> itself
_LAZY = ("MJTNUM_BYTES", "mjDISABLESTRING", "mjENABLESTRING", "mjFRAMESTRING",
         "mjLABELSTRING", "mjRNDSTRING", "mjTIMERSTRING", "mjVISSTRING")


def __getattr__(name):
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = globals()[name] = getattr(importlib.import_module(__package__), name)
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
