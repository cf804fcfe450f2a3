"""Recording: a trajectory of states rendered to frames, for notebooks and videos.

    frames = render_trajectory(model, qpos, camera="track")     # (n, 240, 320, 3) uint8
    mediapy.show_video(frames, fps=1 / model.opt.timestep)       # inline, in a notebook
    mediapy.write_video("run.mp4", frames, fps=30)               # or to a file

A trajectory is an (n, nq) array of joint positions, or an (n, size) array of
states from mj_getState (mjcffi.rollout's output, say) with `spec` the mjtState
bits they hold (mjSTATE_FULLPHYSICS by default).  Long recordings show a tqdm
progress bar when tqdm is installed (`pip install 'mjcffi[progress]'`); without
it they run silently.  mediapy (`pip install mediapy`) is not a dependency:
any code that takes a list or array of uint8 frames will do.
"""

import numpy as np

from .._support import progress as _progress
from .._generated.enums import mjtState
from ..data import MjData
from .._functions import mj_setState, mj_stateSize
from ..functions._overrides import mj_forward
from .renderer import Renderer

_FULLPHYSICS = int(mjtState.mjSTATE_FULLPHYSICS)


def _states(model, trajectory, spec):
    """(frames, setter): the trajectory as a 2-D float64 array, and how one row goes
    into an MjData."""
    states = np.asarray(trajectory, dtype=np.float64)
    if states.ndim == 1 and states.size == 0:
        states = states.reshape(0, model.nq)
    if states.ndim != 2:
        raise ValueError(f"trajectory must be 2-D, (frames, nq) or (frames, state size), "
                         f"not of shape {states.shape}")
    width = states.shape[1]
    if spec is None and width == model.nq:
        def set_qpos(data, row):
            data.qpos[:] = row
        return states, set_qpos
    spec = _FULLPHYSICS if spec is None else int(spec)
    size = mj_stateSize(model, spec)
    if width != size:
        raise ValueError(f"trajectory rows have {width} values: neither nq ({model.nq}) "
                         f"nor the state size of spec {spec} ({size}); pass spec= the "
                         f"mjtState bits the states were saved with")

    def set_state(data, row):
        mj_setState(model, data, row, spec)
    return states, set_state


def render_trajectory(model, trajectory, *, camera=-1, height=240, width=320,
                      scene_option=None, spec=None, data=None, renderer=None, progress=True):
    """Renders each state of `trajectory` to an image: (frames, height, width, 3) uint8.

    model: the MjModel.  trajectory: (frames, nq) joint positions, or (frames, size)
    states from mj_getState with the mjtState bits `spec` (mjSTATE_FULLPHYSICS when
    the rows are not nq long).  camera: as Renderer.update_scene takes it (-1 the
    free camera, a name, an id or an MjvCamera).  data: an MjData to compute in
    (a new one by default; its state is overwritten).  renderer: a Renderer of
    `model` to reuse (height and width are then its own); by default one is made
    and closed.  progress: show a tqdm progress bar when tqdm is installed.
    """
    states, setter = _states(model, trajectory, spec)
    data = MjData(model) if data is None else data
    own = renderer is None
    if own:
        renderer = Renderer(model, height=height, width=width)
    elif renderer.model is not model:
        raise ValueError("renderer was made for another model than `model`")
    frames = np.empty((len(states), renderer.height, renderer.width, 3), np.uint8)
    bar = _progress.bar(len(states), "rendering", "frame", progress)
    try:
        for i, row in enumerate(states):
            setter(data, row)
            mj_forward(model, data)
            renderer.update_scene(data, camera=camera, scene_option=scene_option)
            renderer.render(out=frames[i])
            bar.update(1)
    finally:
        bar.close()
        if own:
            renderer.close()
    return frames
