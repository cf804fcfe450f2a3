"""The official `mujoco._structs` path: the struct classes that module has.

Code names `mujoco._structs.MjModel`, and so do the official bindings' pickles of
MjModel and MjData: under `sys.modules['mujoco'] = mjcffi` those load here, into
mjcffi's classes, whose __setstate__ reads the official format
(mjcffi/_support/official_pickle.py).  Each name is mjcffi's own class, imported on
first use.  The private classes the official module also holds (`_MjContactList`,
the type of `d.contact`, which MJX names; `_MjModelGeomViews`, the type of
`m.geom(0)`; ...) are mjcffi's classes of the same objects.
"""

import importlib

from ._generated.namedinfo import CATEGORIES
from ._support import named as _named
from ._support import views as _views

# the public names of the official mujoco._structs (MuJoCo 4.0)
__all__ = ["MjContact", "MjData", "MjLROpt", "MjLogConfig", "MjLogMessage", "MjModel",
           "MjOption", "MjPreContact", "MjSolverStat", "MjStatistic", "MjTimerStat",
           "MjVisual", "MjWarningStat", "MjrRect", "MjrVertexAttribute", "MjvCamera",
           "MjvFigure", "MjvGLCamera", "MjvGeom", "MjvLight", "MjvOption", "MjvPerturb",
           "MjvScene", "mjv_averageCamera", "mjv_camera2GLCamera"]

# the official private classes: name -> a function that makes (or finds) mjcffi's class
_PRIVATE = {
    "_MjContactList": lambda: _views._live_class(_struct("MjContact")),   # d.contact
    **{f"_{name}List": (lambda name=name: _views._array_class(_struct(name)))
       for name in ("MjSolverStat", "MjTimerStat", "MjWarningStat")},     # d.solver, ...
    **{_named.accessor_class(side, category).__name__:
       (lambda side=side, category=category: _named.accessor_class(side, category))
       for category, info in CATEGORIES.items() for side in ("model", "data")
       if getattr(info, side)},                                           # m.geom(0), ...
}


def _struct(name):
    return getattr(importlib.import_module(__package__), name)


def __getattr__(name):
    if name in __all__:
        value = _struct(name)
    elif name in _PRIVATE:
        value = _PRIVATE[name]()
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__) | set(_PRIVATE))
