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
render contexts live in mjcffi/rendering/_sim*.py.  mujoco-py's viewers,
`MjViewer` and `MjViewerBasic` (a window drawn by `viewer.render()` in the
caller's loop), live in mjcffi/viewer/_simviewer.py and are imported from there
on first use, so that importing this module needs no glfw.
"""

from ..rendering._simmodder import MaterialModder, TextureModder
from ..rendering._simrender import MjRenderContext, MjRenderContextOffscreen
from ._model import SimData, SimModel, load_model_from_mjb, load_model_from_path, \
    load_model_from_xml
from ._pool import MjSimPool
from ._sim import MjSim
from ._state import MjSimState
from ._warnings import MujocoException, ignore_mujoco_warnings

__all__ = ["SimModel", "SimData", "MjSim", "MjSimState", "MjSimPool", "MujocoException",
           "ignore_mujoco_warnings", "load_model_from_path", "load_model_from_xml",
           "load_model_from_mjb", "MjRenderContext", "MjRenderContextOffscreen",
           "TextureModder", "MaterialModder"]


_VIEWERS = ("MjViewer", "MjViewerBasic")


def __getattr__(name):
    """MjViewer and MjViewerBasic, imported when first asked for (they need glfw)."""
    if name in _VIEWERS:
        from ..viewer import _simviewer
        return getattr(_simviewer, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
