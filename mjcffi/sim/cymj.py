"""mujoco-py's `cymj` path: the names mujoco-py code reaches through `mujoco_py.cymj`.

In mujoco-py, `cymj` was the compiled Cython module that held everything.
Here each name comes from the mjcffi module that implements it:

- the simulation: `MjSim`, `MjSimState`, `load_model_from_*`,
  `ignore_mujoco_warnings`, `MujocoException`;
- MuJoCo's error and warning hooks: `set_error_callback`, `get_error_callback`,
  `set_warning_callback`, `get_warning_callback`, `wrap_mujoco_warning`;
- `set_pid_control`, mujoco-py's PID actuators (C callbacks in mjcffi/_c/sim_pid.c);
- rendering: `MjRenderContext`, `MjRenderContextOffscreen`,
  `MjRenderContextWindow` (a window drawn from the caller's loop: mjcffi's
  `MjViewerBasic`, which is one), `GlfwContext` (the GLFW GLContext);
- the struct wrappers `PyMj*`: `PyMjModel` and `PyMjData` are SimModel and
  SimData, `PyMjVFS` is mujoco-py's VFS, and every other `PyMjX` is mjcffi's
  struct class `MjX` (`PyMjContact` is `mjcffi.MjContact`, ...).

Names are imported on first use, so that importing this module loads neither
glfw nor the rendering backends.  `MjBatchRenderer` (mujoco-py's CUDA
interop renderer) is not provided: asking for it is an AttributeError that
says so.
"""

import importlib

# name -> (module, attribute), imported on first use
_NAMES = {
    "MjSim": ("mjcffi.sim._sim", "MjSim"),
    "MjSimState": ("mjcffi.sim._state", "MjSimState"),
    "MjSimPool": ("mjcffi.sim._pool", "MjSimPool"),
    "load_model_from_path": ("mjcffi.sim._model", "load_model_from_path"),
    "load_model_from_xml": ("mjcffi.sim._model", "load_model_from_xml"),
    "load_model_from_mjb": ("mjcffi.sim._model", "load_model_from_mjb"),
    "ignore_mujoco_warnings": ("mjcffi.sim._warnings", "ignore_mujoco_warnings"),
    "MujocoException": ("mjcffi.sim._warnings", "MujocoException"),
    "set_error_callback": ("mjcffi.sim._callbacks", "set_error_callback"),
    "get_error_callback": ("mjcffi.sim._callbacks", "get_error_callback"),
    "set_warning_callback": ("mjcffi.sim._callbacks", "set_warning_callback"),
    "get_warning_callback": ("mjcffi.sim._callbacks", "get_warning_callback"),
    "wrap_mujoco_warning": ("mjcffi.sim._callbacks", "wrap_mujoco_warning"),
    "set_pid_control": ("mjcffi.sim._pid", "set_pid_control"),
    "MjRenderContext": ("mjcffi.sim._render", "MjRenderContext"),
    "MjRenderContextOffscreen": ("mjcffi.sim._render", "MjRenderContextOffscreen"),
    "MjRenderContextWindow": ("mjcffi.sim.mjviewer", "MjViewerBasic"),
    "GlfwContext": ("mjcffi.glfw", "GLContext"),
    "PyMjModel": ("mjcffi.sim._model", "SimModel"),
    "PyMjData": ("mjcffi.sim._model", "SimData"),
    "PyMjVFS": ("mjcffi.sim._vfs", "PyMjVFS"),
}

# mujoco-py's PyMjX wrappers whose mjcffi class is MjX
_STRUCTS = ("MjLROpt", "MjOption", "MjVisual", "MjStatistic", "MjContact", "MjWarningStat",
            "MjTimerStat", "MjSolverStat", "MjvPerturb", "MjvCamera", "MjvGLCamera", "MjvGeom",
            "MjvLight", "MjvOption", "MjvScene", "MjvFigure", "MjrRect", "MjrContext",
            "MjuiState", "MjuiThemeSpacing", "MjuiThemeColor", "MjuiItem", "MjuiSection",
            "MjUI", "MjuiDef")
_NAMES.update({"Py" + name: ("mjcffi", name) for name in _STRUCTS})

_LEFT_OUT = {
    "MjBatchRenderer": "mujoco-py's MjBatchRenderer (CUDA interop with an EGL context) is not "
                       "provided by mjcffi.sim: render batches with MjRenderPool, or "
                       "mjcffi.Renderer per thread",
}

__all__ = sorted(_NAMES)


def __getattr__(name):
    where = _NAMES.get(name)
    if where is None:
        if name in _LEFT_OUT:
            raise AttributeError(_LEFT_OUT[name])
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(where[0]), where[1])
    globals()[name] = value         # later lookups skip __getattr__
    return value


def __dir__():
    return sorted(set(globals()) | set(_NAMES))
