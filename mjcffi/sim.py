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

import contextlib
import copy
import operator
import os
import threading
import xml.etree.ElementTree as ElementTree
from collections import namedtuple
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from . import _marshal
from . import warning_errors as _warnings
from ._enums import mjtWarning
from .data import MjData
from ._functions import mj_resetData
from ._overrides import mj_forward, mj_step
from ._simgetters import SimDataGetters, SimModelGetters
from .model import MjModel
from .rendering import _simchecks, _simgl
from .rendering._simmodder import MaterialModder, TextureModder
from .rendering._simrender import MjRenderContext, MjRenderContextOffscreen

__all__ = ["SimModel", "SimData", "MjSim", "MjSimState", "MjSimPool", "MujocoException",
           "ignore_mujoco_warnings", "load_model_from_path", "load_model_from_xml",
           "load_model_from_mjb", "MjRenderContext", "MjRenderContextOffscreen",
           "TextureModder", "MaterialModder"]


_VIEWERS = ("MjViewer", "MjViewerBasic")


def __getattr__(name):
    """MjViewer and MjViewerBasic, imported when first asked for (they need glfw)."""
    if name in _VIEWERS:
        from .viewer import _simviewer
        return getattr(_simviewer, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# ------------------------------------------------------------------ model and data

class SimModel(SimModelGetters, MjModel):
    """An MjModel that remembers the XML it was compiled from (`_xml`), for MjSim.save."""

    _xml = None          # the MJCF text, when loaded from XML
    _xml_path = None     # the file it came from, when loaded from a path


class SimData(SimDataGetters, MjData):
    """The MjData that MjSim makes for its model."""


def load_model_from_path(path):
    """A SimModel compiled from an MJCF/URDF file, or loaded from an .mjb file."""
    path = os.fspath(path)
    if str(path).lower().endswith(".mjb"):
        return SimModel.from_binary_path(path)
    model = SimModel.from_xml_path(path)
    with open(path, encoding="utf-8") as f:
        model._xml = f.read()
    model._xml_path = os.path.abspath(path)
    return model


def load_model_from_xml(xml_string):
    """A SimModel compiled from MJCF text; the text is kept as `model._xml`."""
    model = SimModel.from_xml_string(xml_string)
    model._xml = xml_string
    return model


def load_model_from_mjb(mjb):
    """A SimModel from MJB bytes, or from the path of an .mjb file."""
    if isinstance(mjb, (bytes, bytearray, memoryview)):
        return SimModel.from_bytes(mjb)
    return SimModel.from_binary_path(os.fspath(mjb))


# ------------------------------------------------------------------ warnings

class MujocoException(_warnings.MjWarningError):
    """A MuJoCo warning raised during MjSim.step() or MjSim.forward().

    As MjWarningError: `warning` (the mjtWarning), `info` and `count`; the
    message adds what usually causes it.
    """

    def __init__(self, warning, info, count):
        super().__init__(warning, info, count)
        hint = _HINTS.get(warning)
        if hint:
            self.args = (f"{self.args[0]}. {hint}",)


_UNSTABLE = ("The simulation is unstable: try a smaller timestep (<option timestep>), the "
             "implicitfast or implicit integrator, and check the model (masses, inertias, "
             "stiffness, damping, actuator gains, controls)")
_HINTS = {
    mjtWarning.mjWARN_INERTIA: "A body has a mass or inertia too small or non-positive: "
                               "check <inertial> or the geoms' density, or <compiler "
                               "boundmass/boundinertia>",
    mjtWarning.mjWARN_CONTACTFULL: "Too many contacts for the arena: increase <size memory> "
                                   "(or nconmax in older models)",
    mjtWarning.mjWARN_CNSTRFULL: "Too many constraints for the arena: increase <size memory> "
                                 "(or njmax in older models)",
    mjtWarning.mjWARN_BADQPOS: "NaN, Inf or huge value in qpos. " + _UNSTABLE,
    mjtWarning.mjWARN_BADQVEL: "NaN, Inf or huge value in qvel. " + _UNSTABLE,
    mjtWarning.mjWARN_BADQACC: "NaN, Inf or huge value in qacc. " + _UNSTABLE,
    mjtWarning.mjWARN_BADCTRL: "NaN, Inf or huge value in ctrl: check the controls you set",
}
_INT_MAX = 2**31 - 1            # mj_step's nstep is a C int
_local = threading.local()      # .ignoring: depth of ignore_mujoco_warnings() on this thread


@contextlib.contextmanager
def ignore_mujoco_warnings():
    """Within this block, on this thread, MjSim counts warnings but raises no MujocoException."""
    _local.ignoring = getattr(_local, "ignoring", 0) + 1
    try:
        yield
    finally:
        _local.ignoring -= 1


# ------------------------------------------------------------------ state

class MjSimState(namedtuple("MjSimState", "time qpos qvel act udd_state")):
    """A copy of a simulation's state: time, qpos, qvel, act (None when na == 0), udd_state.

    `flatten()` gives one float64 vector, and `MjSimState.from_flattened(v, sim)`
    reads it back with the sizes of `sim` (bit-exact both ways).
    """

    __slots__ = ()

    def flatten(self):
        """time, qpos, qvel, act, then the udd_state values in key order, as one vector."""
        parts = [np.array([self.time], dtype=np.float64), np.ravel(self.qpos),
                 np.ravel(self.qvel)]
        if self.act is not None:
            parts.append(np.ravel(self.act))
        for key in sorted(self.udd_state or {}):
            parts.append(np.ravel(np.asarray(self.udd_state[key], dtype=np.float64)))
        return np.concatenate(parts).astype(np.float64, copy=False)

    @staticmethod
    def from_flattened(array, sim):
        """The MjSimState that `flatten()` gave, read with the sizes of `sim`."""
        time, qpos, qvel, act, udd_state = _split_flat(array, sim)
        return MjSimState(float(time), qpos.copy(), qvel.copy(),
                          None if act is None else act.copy(),
                          {k: (v.copy() if isinstance(v, np.ndarray) else v)
                           for k, v in udd_state.items()})


def _split_flat(array, sim):
    """The parts of a flattened state, as views of `array` (udd scalars as floats)."""
    if not isinstance(sim, MjSim):
        raise TypeError(f"sim must be an MjSim, not {type(sim).__name__}")
    array = np.asarray(array, dtype=np.float64)
    nq, nv, na = sim.model.nq, sim.model.nv, sim.model.na
    udd = [(key, np.shape(sim.udd_state[key])) for key in sorted(sim.udd_state)]
    size = 1 + nq + nv + na + sum(int(np.prod(shape)) for _, shape in udd)
    if array.ndim != 1 or array.size != size:
        raise ValueError(f"a flattened state of this sim has {size} numbers, not {array.size}"
                         + ("" if array.ndim == 1 else f" (shape {array.shape})"))
    qpos = array[1:1 + nq]
    qvel = array[1 + nq:1 + nq + nv]
    at = 1 + nq + nv
    act = None
    if na:
        act, at = array[at:at + na], at + na
    udd_state = {}
    for key, shape in udd:
        if shape == ():
            udd_state[key], at = float(array[at]), at + 1
        else:
            n = int(np.prod(shape))
            udd_state[key], at = array[at:at + n].reshape(shape), at + n
    return array[0], qpos, qvel, act, udd_state


# ------------------------------------------------------------------ MjSim

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
                from .viewer._simviewer import MjViewer
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
    import io
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


# ------------------------------------------------------------------ MjSimPool

class MjSimPool:
    """Many MjSim stepped together on a persistent pool of threads.

    Each thread steps its share of the sims with mjcffi's C loop, which runs
    with the GIL released, so the sims advance in parallel; the results are
    those of stepping each sim alone.  `nsubsteps` is the pool's own count of
    MuJoCo steps per `step()` (the sims' own counts are not used here).  The
    sims must have an MjData each: a sim given twice, or two sims on one
    MjData, would be stepped by two threads at once.  An error in one sim
    (a FatalError, a callback's exception, ...) is raised
    once every other sim has stepped; the first one, in the order of `sims`.
    """

    def __init__(self, sims, nsubsteps=1, nthreads=None):
        try:
            self.sims = list(sims)
        except TypeError:
            raise TypeError(f"sims must be a sequence of MjSim, not {type(sims).__name__}") \
                from None
        _distinct(self.sims)
        self.nsubsteps = _count(nsubsteps, "nsubsteps", 1)
        if nthreads is None:
            nthreads = os.cpu_count() or 1
        nthreads = _count(nthreads, "nthreads", 1)
        self.nthreads = min(nthreads, len(self.sims))
        # the calling thread takes one share, the pool the others
        self._executor = (ThreadPoolExecutor(self.nthreads - 1, thread_name_prefix="MjSimPool")
                          if self.nthreads > 1 else None)
        self._closed = False

    @classmethod
    def create_from_sim(cls, sim, nsims):
        """A pool of `nsims` sims on copies of `sim`'s model, each with its own fresh data."""
        if not isinstance(sim, MjSim):
            raise TypeError(f"sim must be an MjSim, not {type(sim).__name__}")
        nsims = _count(nsims, "nsims", 1)
        sims = [MjSim(copy.copy(sim.model), nsubsteps=sim.nsubsteps,
                      udd_callback=sim.udd_callback) for _ in range(nsims)]
        return cls(sims, nsubsteps=sim.nsubsteps)

    @property
    def nsims(self):
        return len(self.sims)

    def _selected(self, nsims):
        """The first `nsims` sims (all for None), checked: the pool open, each data once."""
        if self._closed:
            raise ValueError("MjSimPool is closed")
        if nsims is None:
            sims = self.sims
        else:
            nsims = _count(nsims, "nsims", 0)
            if nsims > len(self.sims):
                raise ValueError(f"nsims must be at most the pool's {len(self.sims)} sims, "
                                 f"got {nsims}")
            sims = self.sims[:nsims]
        # `sims` is a public list: checked again at each call, in one set on the way
        try:
            distinct = len({sim.data._ptr for sim in sims}) == len(sims)
        except AttributeError:
            distinct = False
        if not distinct and sims:
            _distinct(sims)     # raises, naming the culprit
        return sims

    def _run(self, job, nsims):
        sims = self._selected(nsims)
        if not sims:
            return
        n = min(self.nthreads, len(sims))
        shares = [sims[i::n] for i in range(n)]
        futures = [self._executor.submit(_run_share, job, share, self.nsubsteps)
                   for share in shares[1:]]
        errors = [_run_share(job, shares[0], self.nsubsteps)]
        for future in futures:     # wait for every share, whatever failed
            try:
                errors.append(future.result())
            except BaseException as exc:
                errors.append([(-1, exc)])
        if any(errors):            # the first in the order of `sims`
            raise min(((i * n + k, exc) for k, share_errors in enumerate(errors)
                       for i, exc in share_errors), key=lambda entry: entry[0])[1]

    def step(self, nsims=None):
        """Run `nsubsteps` steps of the first `nsims` sims (all by default), in parallel."""
        self._run(mj_step, nsims)

    def forward(self, nsims=None):
        """mj_forward on the first `nsims` sims (all by default), in parallel."""
        self._run(mj_forward, nsims)

    def reset(self, nsims=None):
        """Reset the first `nsims` sims (all by default)."""
        for sim in self._selected(nsims):
            sim.reset()

    def close(self):
        """Stop the pool's threads (also done when the pool is collected); later calls
        raise ValueError."""
        self._closed = True
        if self._executor is not None:
            self._executor.shutdown(wait=True)
            self._executor = None

    def __del__(self):
        executor = getattr(self, "_executor", None)
        if executor is not None:
            executor.shutdown(wait=False)


def _count(value, name, least):
    """`value` as an int from `least` to INT_MAX (the C loop's), or TypeError / ValueError."""
    if isinstance(value, (bool, np.bool_)) or not hasattr(value, "__index__"):
        raise TypeError(f"{name} must be an int, not {type(value).__name__}")
    value = operator.index(value)
    if not least <= value <= _INT_MAX:
        raise ValueError(f"{name} must be from {least} to {_INT_MAX}, not {value}")
    return value


def _distinct(sims):
    """TypeError unless all are MjSim; ValueError if two are one, or share an MjData."""
    if not sims:
        raise TypeError("sims must be a non-empty sequence of MjSim")
    seen = {}
    for i, sim in enumerate(sims):
        if not isinstance(sim, MjSim):
            raise TypeError(f"sims[{i}] must be an MjSim, not {type(sim).__name__}")
        pointer = getattr(sim.data, "_ptr", None)
        first = seen.setdefault(pointer, i)
        if first != i:
            what = "is" if sims[first] is sim else "shares its MjData with"
            raise ValueError(f"sims[{i}] {what} sims[{first}]: each sim of a pool needs an "
                             "MjData of its own, which one thread steps")


def _run_share(job, sims, nsubsteps):
    """Step (or forward) each sim; [(index in `sims`, exception)] for those that raised."""
    errors = []
    for i, sim in enumerate(sims):
        try:
            if job is mj_step:
                mj_step(sim.model, sim.data, nsubsteps)
            else:
                job(sim.model, sim.data)
        except Exception as exc:
            errors.append((i, exc))
    return errors
