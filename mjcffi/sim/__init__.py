"""The mujoco-py interface on top of mjcffi: MjSim, MjSimState, MjSimPool.

Code written for mujoco-py runs with `from mjcffi.sim import ...` in place
of `from mujoco_py import ...`:

    model = load_model_from_xml(xml)          # or load_model_from_path(path)
    sim = MjSim(model, nsubsteps=2)
    state = sim.get_state()
    for _ in range(100):
        sim.step()
    print(sim.data.qpos)
    sim.set_state(state)

Nothing here binds MuJoCo again: SimModel and SimData are the MjModel and
MjData of mjcffi, and stepping is mjcffi's C loop (`nsubsteps` steps per
call, the GIL released).  As in mujoco-py, a MuJoCo warning during
`MjSim.step()` or `MjSim.forward()` raises MujocoException, unless inside
`ignore_mujoco_warnings()`.

Rendering is offscreen, in an OpenGL context of the backend MUJOCO_GL names
(egl, osmesa or glfw): `sim.render(width, height, camera_name=...)`, or a
`MjRenderContextOffscreen(sim)` of one's own; `TextureModder` and
`MaterialModder` randomize textures and materials between frames.  The
render contexts are `_render` (their OpenGL context `_render_gl`, their checks
`_render_checks`, the markers `_markers`), the render pool `mjrenderpool`.
mujoco-py's viewers, `MjViewer` and `MjViewerBasic` (a window drawn by
`viewer.render()` in the caller's loop), live in `mjviewer` and are imported
from there on first use, so that importing this module needs no glfw.

This package is the whole mujoco-py face, at mujoco-py's module paths (`const`,
`functions`, `cymj`, `modder`, `mjviewer`, `mjrenderpool`, `generated`, `builder`,
`utils`, `version`; `install_as_mujoco_py()` makes `import mujoco_py` give them): the sim
and its state (`_sim`, `_state`, `_base`, `_pool`, `_substep`, `_pid`, `_ray`,
`_save`), its model and data (`_model`, `_vfs`, the generated getters of
`generated/getters.py` and what they call, `_getter_support`; the generated
`generated/functions.py` and `_function_support`), its error and
warning hooks (`_callbacks`, `_warnings`).  The C of its PID actuators is
mjcffi/_c/sim_pid.c, with the rest of the package's C.
"""

import importlib

from .version import __version__, get_version
from ._install import install_as_mujoco_py
from .modder import MaterialModder, TextureModder
from ._render import MjRenderContext, MjRenderContextOffscreen
from . import const, functions
from ._callbacks import set_error_callback, set_warning_callback, wrap_mujoco_warning
from ._model import SimData, SimModel, load_model_from_mjb, load_model_from_path, \
    load_model_from_xml
from ._pool import MjSimPool
from ._sim import MjSim
from ._state import MjSimState
from ._warnings import MujocoException, ignore_mujoco_warnings

__all__ = ["SimModel", "SimData", "MjSim", "MjSimState", "MjSimPool", "MujocoException",
           "ignore_mujoco_warnings", "load_model_from_path", "load_model_from_xml",
           "load_model_from_mjb", "MjRenderContext", "MjRenderContextOffscreen",
           "MjRenderContextWindow", "MjRenderPool", "MjViewer", "MjViewerBasic",
           "GlfwContext", "TextureModder", "MaterialModder", "const", "functions",
           "set_error_callback", "set_warning_callback", "wrap_mujoco_warning",
           "__version__", "get_version", "install_as_mujoco_py"]


# imported when first asked for: the viewers need glfw, the render pool multiprocessing;
# MjRenderContextWindow and GlfwContext are cymj's (which imports them on use too)
_LAZY = {"MjViewer": (".mjviewer", "MjViewer"),
         "MjViewerBasic": (".mjviewer", "MjViewerBasic"),
         "MjRenderPool": (".mjrenderpool", "MjRenderPool"),
         # mujoco-py's builder.build_callback_fn: C code to a substep_callback address
         "build_callback_fn": ("._substep", "build_callback_fn")}
_FROM_CYMJ = ("MjRenderContextWindow", "GlfwContext")
_SUBMODULES = ("cymj", "modder", "builder", "utils")  # mujoco-py's, reachable as attributes


def __getattr__(name):
    if name in _LAZY:
        module, attribute = _LAZY[name]
        return getattr(importlib.import_module(module, __name__), attribute)
    if name in _FROM_CYMJ:
        return getattr(importlib.import_module(".cymj", __name__), name)
    if name in _SUBMODULES:
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY) | set(_FROM_CYMJ) | set(_SUBMODULES))
