"""MjSim: a model, its data and `nsubsteps` MuJoCo steps per step(), each after an
optional substep callback; its state, ray casting and rendering, as in mujoco-py."""

import copy
import operator
import threading
from numbers import Number

import numpy as np

from .._support import marshal as _marshal
from .._support import contract as _contract
from .._support import official as _official
from .._support import stack as _stack
from .. import warning_errors as _warnings
from .._support.errors import FatalError
from .._functions import (mj_getState, mj_resetData, mj_setConst, mj_setState,
                          mj_stateSize)
from .._support.library import lib
from ..functions._overrides import mj_forward, mj_step
from ..model import MjModel
from . import _render_checks as _simchecks, _render_gl as _simgl
from ._base import SimBase
from ._render import MjRenderContext, MjRenderContextOffscreen
from . import _ray, _substep
from ._save import _is_text, _xml_with_key
from ._callbacks import handle_fatal
from ._model import SimData, SimModel
from ._state import (EXTRA_SIG, MjSimState, _checked_time, _checked_vector,
                     _real_array, _split_flat)
from ._warnings import MujocoException, _local

_INT_MAX = 2**31 - 1            # mj_step's nstep is a C int
_step_substep = lib.mjcffi_step_substep


class UddStateError(AssertionError, ValueError):
    """udd_callback returned a udd_state of another form than before: keys added or
    dropped, a value's shape or kind (number or array) changed.  An AssertionError, as
    mujoco-py raised, and a ValueError, as mjcffi.sim raised before."""


class MjSim(SimBase):
    """A simulation: `model`, `data` and `nsubsteps` MuJoCo steps per `step()`.

    `data` is made for the model (a SimData) unless given.  `udd_callback(sim)`,
    if given, returns a dict of user-defined state: it is called when the sim
    is made or reset and before each step, and its keys, and the shape of each
    value (a number or a numpy array), must stay the same (else UddStateError).
    The result is `sim.udd_state`, saved and restored with the state.

    `substep_callback` runs before each of the `nsubsteps` mj_step calls of a
    `step()`, as in mujoco-py: it sees the state that substep starts from, with what
    the previous substep computed (contacts, sensors, ...).  It is one of
    - a string of C code defining `void fun(const mjModel* m, mjData* d)`, compiled
      here (see mjcffi/sim/_substep.py; cached per user): the substeps and the calls
      then run in one C loop without the GIL;
    - an int, the address of such a C function (`other_sim.substep_callback_ptr`);
    - a Python callable `f(model, data)`, called with the GIL in the same order;
    - a cffi function pointer of that signature;
    - None: plain steps.
    `substep_callback_ptr` is the C function's address (0 for a Python callable or none).
    `userdata_names`, if given, is passed to `model.set_userdata_names` first; each
    name becomes `#define name d->userdata[i]` for the C code.

    `render_callback(sim, render_context)`, if given, runs before each frame a
    render context draws (it may add markers or overlays).  `render_contexts`
    lists the sim's render contexts; `render()` uses the first offscreen one,
    made on first use.  `extras` is a dict for the caller's own use.

    A MuJoCo warning in step(), forward() or reset() raises MujocoException (see
    ignore_mujoco_warnings); a fatal error (mjcffi.FatalError) goes to the callback of
    `set_error_callback`, if one is set (mjcffi/sim/_callbacks.py).
    """

    def __init__(self, model, data=None, nsubsteps=1, udd_callback=None, substep_callback=None,
                 userdata_names=None, render_callback=None):
        if not isinstance(model, MjModel):
            if _official.is_official(model):
                raise _official.not_accepted("model", "MjModel", model)
            raise TypeError(f"model must be an MjModel, not {type(model).__name__}")
        if data is None:
            data = SimData(model)
        else:
            _marshal.model_data(model, data, "model", "data")     # same sizes, or TypeError
        nsubsteps = _count(nsubsteps, "nsubsteps", 1)
        self.model, self.data, self.nsubsteps = model, data, nsubsteps
        self._pointers = _marshal.model_data(model, data)
        self.render_callback = render_callback
        self.render_contexts = []
        self._render_context_offscreen = None
        self._render_context_window = None
        self.extras = {}
        self.set_substep_callback(substep_callback, userdata_names)
        self.udd_callback = udd_callback

    # -- user-defined state

    @property
    def udd_callback(self):
        """The udd_callback; setting it starts udd_state again from its first result."""
        return self._udd_callback

    @udd_callback.setter
    def udd_callback(self, udd_callback):
        if udd_callback is not None and not callable(udd_callback):
            raise TypeError(f"udd_callback must be callable or None, not "
                            f"{type(udd_callback).__name__}")
        self._udd_callback = udd_callback
        self._step_udd(fresh=True)

    def set_udd_callback(self, udd_callback):
        """Use another udd_callback; the udd_state starts again from its first result."""
        self.udd_callback = udd_callback

    def step_udd(self):
        """Call the udd_callback now, as step() does first; its result becomes udd_state."""
        self._step_udd()

    def _step_udd(self, fresh=False):
        if self._udd_callback is None:
            self.udd_state = {}
            return
        new = self._udd_callback(self)
        if not isinstance(new, dict):
            raise TypeError(f"udd_callback must return a dict, not {type(new).__name__}")
        if not fresh:
            _same_form(self.udd_state, new)
        self.udd_state = new

    # -- substep callback

    def set_substep_callback(self, substep_callback, userdata_names=None):
        """Use another substep callback (C code, a C function's address, a Python
        callable or None: see the class); `userdata_names`, if not None, goes to
        `model.set_userdata_names` first."""
        if userdata_names is not None:
            self.model.set_userdata_names(userdata_names)
        names = getattr(self.model, "userdata_names", None) or []
        self._substep_python, self.substep_callback_ptr = _substep.resolve(substep_callback, names)
        self._substep_fn = _substep.c_pointer(self.substep_callback_ptr)

    def substep_callback(self):
        """Run the substep callback once, now (nothing when there is none)."""
        if self._substep_python is not None:
            self._substep_python(self.model, self.data)
        elif self.substep_callback_ptr:
            self._call(self._c_substeps, 0)

    # -- stepping

    def step(self, with_udd=True):
        """Call the udd_callback (if any), then run `nsubsteps` MuJoCo steps, each after
        the substep callback (if any); without a Python callback, in one C loop."""
        if with_udd:
            self._step_udd()
        if self._substep_python is not None:
            self._call(self._python_substeps, self.nsubsteps)
        elif self.substep_callback_ptr:
            self._call(self._c_substeps, self.nsubsteps)
        else:
            self._call(mj_step, self.nsubsteps)

    def _python_substeps(self, model, data, nstep):
        fn = self._substep_python
        for _ in range(nstep):
            fn(model, data)
            mj_step(model, data)

    def _c_substeps(self, model, data, nstep):
        m, d = self._pointers
        status = _step_substep(m, d, nstep, self._substep_fn)
        if _stack.live:                  # a bad state's reset empties the stack
            _stack.sweep(data)
        if status or _contract.pending:
            _marshal.check_steps(status, "MjSim.step")

    def forward(self):
        """mj_forward: compute the derived quantities of the current state."""
        self._call(mj_forward)

    def set_constants(self):
        """mj_setConst: the model's constant fields for its qpos0."""
        self._call(mj_setConst)

    def _call(self, function, *args):
        """function(model, data, *args) as mujoco-py's wrap_mujoco_warning did: a
        warning raises MujocoException, a fatal error goes to the error callback."""
        try:
            self._call_warned(function, *args)
        except FatalError as error:
            handle_fatal(error)

    def _call_warned(self, function, *args):
        d = self.data
        if _contract.warnings_as_errors or getattr(_local, "ignoring", 0):
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
        self._call(mj_resetData)
        self._step_udd(fresh=True)

    # -- ray casting

    def ray(self, pnt, vec, include_static_geoms=True, exclude_body=-1, group_filter=None):
        """The first geom hit by the ray from `pnt` along `vec` (world frame), by mj_ray.

        Geoms of the world body are skipped unless `include_static_geoms`, and those
        of body `exclude_body` (its own geoms only, not its children's) always;
        `group_filter`, if given, holds mjNGROUP booleans: geoms of a group whose entry
        is false are skipped.  Returns (distance, geom id), distance in units of
        |vec|, or (-1.0, -1) when nothing is hit.  Uses the positions of the last
        forward() or step()."""
        return _ray.ray(self.model, self.data, pnt, vec, include_static_geoms, exclude_body,
                        group_filter)

    # -- state

    def get_state(self):
        """An MjSimState copy of time, qpos, qvel, act and udd_state, with `extra`, the
        solver's warm start and MuJoCo's other physics state, so that set_state() of it
        replays the following steps bit for bit (see MjSimState)."""
        d = self.data
        extra = np.empty(mj_stateSize(self.model, EXTRA_SIG))
        mj_getState(self.model, d, extra, EXTRA_SIG)
        return MjSimState(float(d.time), d.qpos.copy(), d.qvel.copy(),
                          d.act.copy() if self.model.na else None,
                          copy.deepcopy(self.udd_state), extra)

    def set_state(self, value):
        """Write an MjSimState (time, qpos, qvel, act, udd_state, and `extra` when it has
        one) into the sim; nothing is written if a part does not fit this model.

        Every part is checked before any is written: qpos, qvel and act must have
        exactly (nq,), (nv,) and (na,) real numbers (no broadcasting; act None or empty
        when na == 0), time must be a real number (NaN and infinity are taken, as
        mujoco-py took them), udd_state a dict or None (deep-copied first), `extra` the
        size this model's has.  ValueError for a wrong size or shape, TypeError for a
        wrong type (strings, complex numbers, ...); the sim is then as it was.

        With `extra` (a state from get_state), the steps after it are bit-identical to
        those after the get_state, given the same inputs; without (a state made by hand
        or by from_flattened), the sim's warm start stays, as mujoco-py did."""
        if not isinstance(value, MjSimState):
            raise TypeError(f"value must be an MjSimState, not {type(value).__name__}")
        time, qpos, qvel, act, udd_state, extra = self._checked_state(value)
        # every part was checked and copied above: nothing below refuses.  The C call
        # first (its parts are none of the five), then plain stores that cannot fail.
        m, d = self.model, self.data
        if extra is not None:
            mj_setState(self.model, d, extra, EXTRA_SIG)
        d.time = time
        if m.nq:
            d.qpos[:] = qpos
        if m.nv:
            d.qvel[:] = qvel
        if m.na:
            d.act[:] = act
        self.udd_state = udd_state

    def _checked_state(self, value):
        """`value`'s parts checked against this model and copied, ready to write: time
        (a float), qpos, qvel, act (float64 vectors; act None when na == 0), udd_state (a
        deep copy, {} for None) and extra (float64, or None); else ValueError for a
        size or shape, TypeError for a type, naming the part."""
        m = self.model
        time = _checked_time(value.time)
        qpos = _checked_vector(value.qpos, "the state's qpos", m.nq)
        qvel = _checked_vector(value.qvel, "the state's qvel", m.nv)
        if value.act is None:
            if m.na:
                raise ValueError(f"the state has no act, and this model has na={m.na}")
            act = None
        else:
            act = _checked_vector(value.act, "the state's act", m.na)
            act = act if m.na else None
        extra = None
        if value.extra is not None:
            extra = _real_array(value.extra, "the state's extra")
            size = mj_stateSize(m, EXTRA_SIG)
            if extra.shape != (size,):
                raise ValueError(f"the state's extra has shape {extra.shape}, and this "
                                 f"model's has ({size},): a state of another model?")
            extra = np.ascontiguousarray(extra, dtype=np.float64)
        udd_state = value.udd_state
        if udd_state is not None and not isinstance(udd_state, dict):
            raise TypeError(f"the state's udd_state must be a dict or None, not "
                            f"{type(udd_state).__name__}")
        try:
            udd_state = copy.deepcopy(udd_state) if udd_state else {}
        except (TypeError, copy.Error) as exc:
            raise TypeError(f"the state's udd_state cannot be copied: {exc}") from exc
        return time, qpos, qvel, act, udd_state, extra

    def set_state_from_flattened(self, value):
        """Write a flattened state (MjSimState.flatten) straight into the sim.

        Nothing is written unless `value` is one vector of real numbers of exactly
        the size of this sim's state (TypeError, ValueError).  The udd_state values
        are views of `value`, not copies."""
        time, qpos, qvel, act, udd_state = _split_flat(value, self)   # checked: see there
        m, d = self.model, self.data
        d.time = time
        if m.nq:
            d.qpos[:] = qpos
        if m.nv:
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
        `model.vis.global_.offwidth/offheight`; a larger image grows the buffer and
        those sizes, as in mujoco-py), seen by the
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

        ValueError for an unknown camera name, a size that is not positive or larger
        than an OpenGL buffer may be, or a mode other than 'offscreen' and 'window'.
        `mode='window'` draws one frame in an interactive window (an MjViewer, made on first use, as mujoco-py
        did) and returns None.
        """
        if mode == "window":
            if self._render_context_window is None:
                from .mjviewer import MjViewer
                MjViewer(self)          # it becomes sim._render_context_window
            self._render_context_window.render()
            return None
        if mode != "offscreen":
            raise ValueError(f"mode must be 'offscreen' or 'window', not {mode!r}")
        camera_id = _simchecks.camera_name(self.model, camera_name)
        _simgl.device_id(device_id)
        width, height = _simchecks.default_size(width, height, self.model)
        width = _simchecks.buffer_side(width, "width")    # refused before making a context
        height = _simchecks.buffer_side(height, "height")
        with _render_lock:
            context = self._render_context_offscreen
            if context is None:
                context = MjRenderContextOffscreen(self, device_id=device_id)
        with context._drawing():         # one frame: drawn and read with no other between
            _fit_buffer(context, width, height)
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
        if render_context.offscreen:
            if self._render_context_offscreen is None:
                self._render_context_offscreen = render_context
        elif self._render_context_window is None:
            self._render_context_window = render_context

    def _forget_render_context(self, render_context):
        """A render context was freed or moved to another sim: drop it here."""
        self.render_contexts[:] = [c for c in self.render_contexts if c is not render_context]
        if self._render_context_offscreen is render_context:
            self._render_context_offscreen = next(
                (c for c in self.render_contexts if c.offscreen), None)
        if self._render_context_window is render_context:
            self._render_context_window = next(
                (c for c in self.render_contexts if not c.offscreen), None)


def _fit_buffer(context, width, height):
    """Grow the offscreen buffer to hold a width x height image, as mujoco-py's render did
    (the model's offwidth/offheight grow with it)."""
    con = context.con
    if width > con.offWidth or height > con.offHeight:
        vis = context.sim.model.vis.global_
        context.update_offscreen_size(max(width, vis.offwidth), max(height, vis.offheight))


_render_lock = threading.Lock()     # one first render context per sim, whichever thread asks


def _count(value, name, least):
    """`value` as an int from `least` to INT_MAX (the C loop's), or TypeError / ValueError."""
    if isinstance(value, (bool, np.bool_)) or not hasattr(value, "__index__"):
        raise TypeError(f"{name} must be an int, not {type(value).__name__}")
    value = operator.index(value)
    if not least <= value <= _INT_MAX:
        raise ValueError(f"{name} must be from {least} to {_INT_MAX}, not {value}")
    return value


def _same_form(old, new):
    """UddStateError unless `new` has the keys of `old`, and each value the same kind
    (a number or a numpy array) and shape, as mujoco-py asserted."""
    if set(new) != set(old):
        raise UddStateError("udd_callback changed the keys of udd_state: "
                            f"{sorted(old, key=str)} before, {sorted(new, key=str)} now")
    for key, value in new.items():
        before = old[key]
        if isinstance(before, Number):
            if not isinstance(value, Number):
                raise UddStateError(f"udd_state[{key!r}] was a number, and udd_callback "
                                    f"now returned a {type(value).__name__}")
        elif not isinstance(value, np.ndarray):
            raise UddStateError(f"udd_state[{key!r}] was a numpy array, and udd_callback "
                                f"now returned a {type(value).__name__}")
        elif value.shape != np.shape(before):
            raise UddStateError(f"udd_callback changed the shape of udd_state[{key!r}]: "
                                f"{np.shape(before)} before, {value.shape} now")
