"""The official `mujoco._structs` path: the struct classes that module has.

Code names `mujoco._structs.MjModel`, and so do the official bindings' pickles of
MjModel and MjData: under `sys.modules['mujoco'] = mjcffi` those load here, into
mjcffi's classes, whose __setstate__ reads the official format
(mjcffi/_support/official_pickle.py).  Each name is mjcffi's own class, imported on
first use.
"""

import importlib

# the public names of the official mujoco._structs (MuJoCo 4.0)
__all__ = ["MjContact", "MjData", "MjLROpt", "MjLogConfig", "MjLogMessage", "MjModel",
           "MjOption", "MjPreContact", "MjSolverStat", "MjStatistic", "MjTimerStat",
           "MjVisual", "MjWarningStat", "MjrRect", "MjrVertexAttribute", "MjvCamera",
           "MjvFigure", "MjvGLCamera", "MjvGeom", "MjvLight", "MjvOption", "MjvPerturb",
           "MjvScene", "mjv_averageCamera", "mjv_camera2GLCamera"]


def __getattr__(name):
    if name not in __all__:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(__package__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
