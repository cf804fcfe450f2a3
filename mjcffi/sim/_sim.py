"""MjSim: a model, its data and `nsubsteps` MuJoCo steps per step()."""

import copy
import io
import operator
import os
import threading
import xml.etree.ElementTree as ElementTree

import numpy as np

from .. import _marshal
from .. import warning_errors as _warnings
from .._functions import mj_resetData
from .._overrides import mj_forward, mj_step
from ..model import MjModel
from ..rendering import _simchecks, _simgl
from ..rendering._simrender import MjRenderContext, MjRenderContextOffscreen
from ._model import SimData, SimModel
from ._state import MjSimState, _split_flat
from ._warnings import MujocoException, _local

_INT_MAX = 2**31 - 1            # mj_step's nstep is a C int


class MjSim:
    """A simulation: `model`, `data` and `nsubsteps` MuJoCo steps per `step()`.

    `data` is made for the model (a SimData) unless given.  `udd_callback(sim)`,
    if given, returns a dict of user-defined state: it is called when the sim
    is made or reset and before each step, and its keys and value shapes
    must stay the same.  The result is `sim.udd_state`, saved and restored
    with the state.

    `render_callback(sim, render_context)`, if given, runs before each frame a
    render context draws (it may add markers or overlays).  `render_contexts`
    lists the sim's render contexts; `render()` uses the first offscreen one,
    made on first use.
    """

    def __init__(self, model, data=None, nsubsteps=1, udd_callback=None, render_callback=None):
        if not isinstance(model, MjModel):
            raise TypeError(f"model must be an MjModel, not {type(model).__name__}")
        if data is None:
            data = SimData(model)
        else:
            _marshal.model_data(model, data, "model", "data")     # same sizes, or TypeError
        nsubsteps = _count(nsubsteps, "nsubsteps", 1)
        self.model, self.data, self.nsubsteps = model, data, nsubsteps
        self._pointers = _marshal.model_data(model, data)
        self._udd_callback = udd_callback
        self.udd_state = {}
        self.render_callback = render_callback
        self.render_contexts = []
        self._render_context_offscreen = None
        self._render_context_window = None
        self._step_udd()

    # -- user-defined state

    @property
    def udd_callback(self):
        return self._udd_callback

    def set_udd_callback(self, udd_callback):
        """Use another udd_callback; the udd_state starts again from its first result."""
        self._udd_callback = udd_callback
        self.udd_state = {}
        self._step_udd()

    def _step_udd(self):
        if self._udd_callback is None:
            return
        new = self._udd_callback(self)
        if not isinstance(new, dict):
            raise TypeError(f"udd_callback must return a dict, not {type(new).__name__}")
        old = self.udd_state
        if old:
            if set(new) != set(old):
                raise ValueError("udd_callback changed the keys of udd_state: "
                                 f"{sorted(old)} before, {sorted(new)} now")
            for key, value in new.items():
                if np.shape(value) != np.shape(old[key]):
                    raise ValueError(f"udd_callback changed the shape of udd_state[{key!r}]: "
                                     f"{np.shape(old[key])} before, {np.shape(value)} now")
        self.udd_state = new

    # -- stepping

    def step(self, with_udd=True):
        """Call the udd_callback (if any), then run `nsubsteps` MuJoCo steps in one C loop."""
        if with_udd:
            self._step_udd()
        self._call(mj_step, self.nsubsteps)

    def forward(self):
        """mj_forward: compute the derived quantities of the current state."""
        self._call(mj_forward)

    def _call(self, function, *args):
        d = self.data
        if _warnings._enabled or getattr(_local, "ignoring", 0):
            # the process-wide switch already checks, or warnings are off here
            function(self.model, d, *args)
            return
        before = _warnings.take_counts(d)
        try:
            function(self.model, d, *args)
        except BaseException:
            _warnings.restore(d, before)
            raise
        _warnings.after_call(d, before, MujocoException)

    def reset(self):
        """mj_resetData, and udd_state from the udd_callback again."""
        mj_resetData(self.model, self.data)
        self.udd_state = {}
        self._step_udd()

    # -- state

    def get_state(self):
        """An MjSimState copy of time, qpos, qvel, act and udd_state."""
        d = self.data
        return MjSimState(float(d.time), d.qpos.copy(), d.qvel.copy(),
                          d.act.copy() if self.model.na else None,
                          copy.deepcopy(self.udd_state))

    def set_state(self, value):
        """Write an MjSimState (time, qpos, qvel, act, udd_state) into the sim."""
        if not isinstance(value, MjSimState):
            raise TypeError(f"value must be an MjSimState, not {type(value).__name__}")
        d = self.data
        if np.shape(value.qpos) != (self.model.nq,) or np.shape(value.qvel) != (self.model.nv,):
            raise ValueError("the state's qpos/qvel sizes do not match this model")
        d.time = value.time
        d.qpos[:] = value.qpos
        d.qvel[:] = value.qvel
        if self.model.na and value.act is not None:
            d.act[:] = value.act
        self.udd_state = copy.deepcopy(value.udd_state) if value.udd_state else {}

    def set_state_from_flattened(self, value):
        """Write a flattened state (MjSimState.flatten) straight into the sim.

        The udd_state values are views of `value`, not copies."""
        time, qpos, qvel, act, udd_state = _split_flat(value, self)
        d = self.data
        d.time = time
        d.qpos[:] = qpos
        d.qvel[:] = qvel
        if act is not None:
            d.act[:] = act
        self.udd_state = udd_state

    # -- saving

    def save(self, file, format="xml", keep_inertials=False):
        """Write the model, with the current state as its last keyframe, to an open file.

        format 'xml' writes the model's source MJCF with a <key> added (the
        model must have been loaded from XML); 'mjb' writes the binary model
        compiled from that text.  The key is named 'saved_state' (or
        'saved_state_1', ... if taken): reload and call
        `mj_resetDataKeyframe(m, d, m.key('saved_state').id)` to get the
        state back.
        `keep_inertials` is accepted for mujoco-py's signature: the source
        text is written as it was, so its inertials are those it had.
        """
        if format not in ("xml", "mjb"):
            raise ValueError(f"format must be 'xml' or 'mjb', not {format!r}")
        if not callable(getattr(file, "write", None)):
            raise TypeError(f"file must be a file opened for writing, not {type(file).__name__}")
        text = _xml_with_key(self.model, self.data)
        if format == "xml":
            file.write(text if _is_text(file) else text.encode("utf-8"))
            return
        keyed = SimModel.from_xml_string(text)
        mjb = keyed.to_bytes()
        if _is_text(file):
            raise TypeError("format 'mjb' needs a file opened in binary mode")
        file.write(mjb)

    # -- rendering

    def render(self, width=None, height=None, *, camera_name=None, depth=False,
               mode="offscreen", device_id=-1, segmentation=False):
        """An image of the current state, rendered offscreen, as mujoco-py returned it.

        `width` x `height` pixels (None: the model's offscreen buffer side,
        `model.vis.global_.offwidth/offheight`, which also bounds them), seen by the
        camera `camera_name` (None: the render context's camera, at first a free camera
        looking at the model).  The first call makes `sim._render_context_offscreen`, an
        MjRenderContextOffscreen on EGL device `device_id` (-1: the default), and later
        calls reuse it.

        Returns rgb, a (height, width, 3) uint8 array, or with `depth` the pair (rgb,
        depth), depth a (height, width) float32 array.  As in mujoco-py, rows come in
        OpenGL's order: row 0 is the *bottom* of the picture, so `rgb[::-1]` is the
        picture as an image viewer (or the official `mujoco.Renderer`) shows it.  Depth
        is OpenGL's raw depth buffer: 0 at the near clipping plane, 1 at the far plane
        and where nothing was drawn, not linear in distance; the distance along the
        view axis is `near / (1 - depth * (1 - near / far))`, with
        `near = model.vis.map.znear * model.stat.extent` and `far` from zfar likewise.
        With `segmentation`, the image is (height, width, 2) int32 of (object type,
        object id) per pixel, (-1, -1) for the background.

        ValueError for an unknown camera name, a size that is not positive or does not
        fit the offscreen buffer (MjRenderContextOffscreen.update_offscreen_size grows
        it), or a mode other than 'offscreen' and 'window'.  `mode='window'` draws one
        frame in an interactive window (an MjViewer, made on first use, as mujoco-py
        did) and returns None.
        """
        if mode == "window":
            if self._render_context_window is None:
                from ..viewer._simviewer import MjViewer
                MjViewer(self)          # it becomes sim._render_context_window
            self._render_context_window.render()
            return None
        if mode != "offscreen":
            raise ValueError(f"mode must be 'offscreen' or 'window', not {mode!r}")
        camera_id = _simchecks.camera_name(self.model, camera_name)
        _simgl.device_id(device_id)
        width, height = _simchecks.default_size(width, height, self.model)
        with _render_lock:
            context = self._render_context_offscreen
            if context is None:      # its buffer will be the model's: refuse before making it
                vis = self.model.vis.global_
                _simchecks.image_size(width, height, vis.offwidth, vis.offheight)
                context = MjRenderContextOffscreen(self, device_id=device_id)
        with context._drawing():         # one frame: drawn and read with no other between
            context.render(width, height, camera_id=camera_id, segmentation=segmentation)
            return context.read_pixels(width, height, depth=depth, segmentation=segmentation)

    def add_render_context(self, render_context):
        """Add a render context to `render_contexts`; the first offscreen one becomes the
        one `render()` uses.  (A render context adds itself when made.)"""
        if not isinstance(render_context, MjRenderContext):
            raise TypeError(f"render_context must be an MjRenderContext, not "
                            f"{type(render_context).__name__}")
        if any(context is render_context for context in self.render_contexts):
            return
        self.render_contexts.append(render_context)
        if render_context.offscreen and self._render_context_offscreen is None:
            self._render_context_offscreen = render_context

    def _forget_render_context(self, render_context):
        """A render context was freed or moved to another sim: drop it here."""
        self.render_contexts[:] = [c for c in self.render_contexts if c is not render_context]
        if self._render_context_offscreen is render_context:
            self._render_context_offscreen = next(
                (c for c in self.render_contexts if c.offscreen), None)


_render_lock = threading.Lock()     # one first render context per sim, whichever thread asks


SAVED_KEY = "saved_state"


def _is_text(file):
    return isinstance(file, io.TextIOBase)


def _numbers(values):
    return " ".join(repr(float(v)) for v in np.ravel(values))


def _xml_with_key(model, data):
    """The model's MJCF text with one more <key> holding the data's state."""
    source = getattr(model, "_xml", None)
    if source is None:
        raise ValueError("MjSim.save needs a model loaded from XML (load_model_from_xml or "
                         "load_model_from_path); this one has no source text")
    root = ElementTree.fromstring(source)
    if root.tag != "mujoco":
        raise ValueError(f"MjSim.save writes MJCF only, not <{root.tag}>")
    path = getattr(model, "_xml_path", None)
    if path is not None:    # let relative asset paths still resolve from the saved copy
        folder = os.path.dirname(path)
        compiler = root.find("compiler")
        if compiler is None:
            compiler = ElementTree.Element("compiler")
            root.insert(0, compiler)
        for attribute in ("meshdir", "texturedir", "assetdir"):
            if attribute in compiler.attrib and not os.path.isabs(compiler.attrib[attribute]):
                compiler.set(attribute, os.path.join(folder, compiler.attrib[attribute]))
        if "assetdir" not in compiler.attrib:
            compiler.set("assetdir", folder)
    keyframes = root.findall("keyframe")
    keyframe = keyframes[-1] if keyframes else ElementTree.SubElement(root, "keyframe")
    names = {k.get("name") for k in root.iter("key")}
    name, n = SAVED_KEY, 1
    while name in names:
        name, n = f"{SAVED_KEY}_{n}", n + 1
    key = ElementTree.SubElement(keyframe, "key")
    key.set("name", name)
    key.set("time", repr(float(data.time)))
    key.set("qpos", _numbers(data.qpos))
    key.set("qvel", _numbers(data.qvel))
    if model.na:
        key.set("act", _numbers(data.act))
    return ElementTree.tostring(root, encoding="unicode")



def _count(value, name, least):
    """`value` as an int from `least` to INT_MAX (the C loop's), or TypeError / ValueError."""
    if isinstance(value, (bool, np.bool_)) or not hasattr(value, "__index__"):
        raise TypeError(f"{name} must be an int, not {type(value).__name__}")
    value = operator.index(value)
    if not least <= value <= _INT_MAX:
        raise ValueError(f"{name} must be from {least} to {_INT_MAX}, not {value}")
    return value
