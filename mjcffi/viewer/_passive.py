"""`launch_passive` and its `Handle`: a viewer on its own thread, the physics the caller's.

The viewer draws private copies of the caller's MjModel and MjData and reads or
writes the caller's only inside `sync()`, under the viewer's lock:

1. GUI to the caller: the panels' edits (options, controls), and the mouse
   perturbation, applied with mjv_applyPerturbPose (mocap bodies) and
   mjv_applyPerturbForce into xfrc_applied.  The viewer zeroes the xfrc_applied
   row of a body it perturbed at the previous sync before applying again, and
   leaves the other rows to the caller.
2. The caller to the GUI: the model and data (or with state_only, the
   mjSTATE_INTEGRATION state, then mj_forward on the copy), user_scn's geoms, and
   its render flags: a flag the caller changed since the last sync goes to the
   viewer, otherwise the viewer's flag (perhaps changed in the GUI) comes back.

The window, its OpenGL context and all drawing live on the viewer's thread;
`close()` and `is_running()` only set and read an event, safe without the lock.

As the official handle, it lays the caller's figures, texts and images over the
scene (`set_figures`, `set_texts`, `set_images` and their `clear_*`, see
`_user_overlays`).  Beyond the official, `history` keeps the state at launch and
at each sync, the last `history.capacity` of them (see `_history`).
"""

import atexit
import contextlib
import copy
import threading
import weakref

import numpy as np

from .._generated.enums import mjtState
from .._functions import (mj_copyData, mj_copyState, mjr_uploadHField, mjr_uploadMesh,
                          mjr_uploadTexture, mjv_applyPerturbForce, mjv_applyPerturbPose)
from ..functions._overrides import mj_copyModel, mj_forward
from .._support.library import ffi
from ..data import MjData
from ..model import MjModel
from ..structs import MjvScene
from . import _user_overlays
from ._history import History
from ._viewer import MAX_GEOM, Viewer
from ._window import report

_GEOM_SIZE = ffi.sizeof("mjvGeom")
_CLOSE_WAIT = 10.0           # seconds close() waits for the window to go
_open_handles: weakref.WeakSet = weakref.WeakSet()   # closed at exit, before the daemon threads die


@atexit.register
def _close_all():
    for handle in list(_open_handles):
        handle.close()


class Handle:
    """The caller's side of a passive viewer (see the module docstring)."""

    def __init__(self, viewer, model, data, thread):
        self._viewer, self._model, self._data, self._thread = viewer, model, data, thread
        self._user_scn = MjvScene(model, MAX_GEOM)
        self._flags_synced = np.array(self._user_scn.flags, copy=True)
        self._perturbed = 0              # body whose xfrc_applied row the viewer set last
        self._history = History(model)
        self._history.record(model, data)        # the caller's: the viewer's thread reads its copy

    # ------------------------------------------------------------ the official names

    @property
    def cam(self):
        return self._viewer.cam

    @property
    def opt(self):
        return self._viewer.opt

    @property
    def perturb(self):
        return self._viewer.pert

    pert = perturb

    @property
    def user_scn(self):
        return self._user_scn

    @property
    def m(self):
        return self._model

    @property
    def d(self):
        return self._data

    @property
    def viewport(self):
        """The 3D view's MjrRect in the window (the window less the panels shown)."""
        with self._viewer.lock:
            return self._viewer.viewport()

    @property
    def history(self):
        """mjcffi's own: the states at launch and at each sync(), the newest last (a
        `History`: len(), [i], states(), times(); at most `history.capacity`, set by
        MAX_STATES and MAX_BYTES in mjcffi.viewer._history).  Read it on the thread
        that calls sync()."""
        return self._history

    def is_running(self):
        return self._viewer.running and self._thread.is_alive()

    def lock(self):
        """The viewer's lock, as a context manager (a no-op one once closed)."""
        return self._viewer.lock if self.is_running() else contextlib.nullcontext()

    def close(self):
        """Close the window; from another thread, wait until it is gone."""
        self._viewer.close()
        if threading.current_thread() is not self._thread:
            self._thread.join(_CLOSE_WAIT)

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc_value, traceback):
        self.close()

    # ------------------------------------------------------------ sync

    def sync(self, state_only=False):
        """Exchange GUI input and physics state with the viewer (see the module)."""
        if not self.is_running():
            return
        viewer, m, d = self._viewer, self._model, self._data
        with viewer.lock:
            if viewer.panels is not None:
                viewer.panels.sync_to(m, d, viewer.opt)
            self._apply_perturbation(m, d)
            if state_only:
                mj_copyState(m, d, viewer.data, mjtState.mjSTATE_INTEGRATION)
                mj_forward(viewer.model, viewer.data)
            else:
                mj_copyModel(viewer.model, m)
                mj_copyData(viewer.data, m, d)
            self._sync_scene()
            if viewer.panels is not None:
                viewer.panels.sync_from(m, d, viewer.opt)
            self._history.record(viewer.model, viewer.data)

    def _apply_perturbation(self, m, d):
        pert = self._viewer.pert
        if self._perturbed > 0:
            d.xfrc_applied[self._perturbed] = 0
            self._perturbed = 0
        if pert.active and pert.select > 0:
            mjv_applyPerturbPose(m, d, pert, 0)      # moves mocap bodies only
            mjv_applyPerturbForce(m, d, pert)
            self._perturbed = pert.select

    def _sync_scene(self):
        viewer, user = self._viewer, self._user_scn
        changed = user.flags != self._flags_synced
        viewer.scene.flags[changed] = user.flags[changed]
        user.flags[:] = viewer.scene.flags
        self._flags_synced[:] = user.flags
        count = min(int(user.ngeom), MAX_GEOM)
        ffi.memmove(viewer._extra, user._ptr.geoms, count * _GEOM_SIZE)
        viewer.extra_count = count

    # ------------------------------------------------------------ overlays

    def set_figures(self, viewports_figures):
        """Draw figures over the scene, each in its viewport, every frame until
        cleared or set again.

        viewports_figures: a tuple (viewport: MjrRect, figure: MjvFigure), or a list
        of them.  The figures are copied now: change one, then set it again to show
        the change.  TypeError or ValueError (naming the entry) for a bad entry.
        """
        self._viewer.user_overlays.figures = _user_overlays.check_figures(viewports_figures)

    def clear_figures(self):
        """Stop drawing the figures of set_figures() (from the next frame)."""
        self._viewer.user_overlays.figures = ()

    def set_texts(self, texts):
        """Draw text over the scene every frame until cleared or set again.

        texts: a tuple (font, gridpos, text1, text2), or a list of them: font an
        mjtFont (None: mjtFontScale.mjFONTSCALE_150, the official default, drawn as
        the normal font), gridpos an mjtGridPos in the 3D view (None: top left),
        text1 and text2 the left and right columns (None: empty).  The texts must be
        ASCII, each line shorter than mjMAXOVERLAY (ValueError otherwise).
        """
        self._viewer.user_overlays.texts = _user_overlays.check_texts(texts)

    def clear_texts(self):
        """Stop drawing the texts of set_texts() (from the next frame)."""
        self._viewer.user_overlays.texts = ()

    def set_images(self, viewports_images):
        """Draw images over the scene, each filling its viewport, every frame until
        cleared or set again.

        viewports_images: a tuple (viewport: MjrRect, image), or a list of them; the
        image an array of shape (viewport.height, viewport.width, 3), uint8 RGB, its
        first row at the top.  The images are copied now.  ValueError for a shape or
        dtype that does not fit, TypeError for an entry of the wrong kind.
        """
        self._viewer.user_overlays.images = _user_overlays.check_images(viewports_images)

    def clear_images(self):
        """Stop drawing the images of set_images() (from the next frame)."""
        self._viewer.user_overlays.images = ()

    # ------------------------------------------------------------ assets

    def _upload(self, upload, index):
        viewer = self._viewer

        def copy_and_upload():
            with viewer.lock:
                mj_copyModel(viewer.model, self._model)
            upload(viewer.model, viewer.con, index)
        if self.is_running():
            viewer.call(copy_and_upload)

    def update_hfield(self, hfieldid):
        self._upload(mjr_uploadHField, hfieldid)

    def update_mesh(self, meshid):
        self._upload(mjr_uploadMesh, meshid)

    def update_texture(self, texid):
        self._upload(mjr_uploadTexture, texid)


def _render_thread(viewer, started):
    """The viewer's thread: open the window, then frames until closed."""
    try:
        viewer.open()
    except BaseException as error:      # noqa: BLE001  (raised again in launch_passive)
        started.put(error)
        return
    started.put(None)
    try:
        while viewer.running:
            viewer.frame()
    except Exception:                   # noqa: BLE001  (reported, then the window goes)
        report("the viewer's render loop")
    finally:
        viewer.destroy()


def launch_passive(model, data, *, key_callback=None, show_left_ui=True, show_right_ui=True):
    """Open a viewer of `model`/`data` on its own thread and return its Handle at once.

    The caller steps the physics and calls `handle.sync()` to show it.  Raises
    TypeError for arguments of the wrong type, RuntimeError when no window can be
    made (no display, no OpenGL).
    """
    import queue

    if not isinstance(model, MjModel):
        raise TypeError(f"model must be an mjcffi.MjModel, got {type(model).__name__}")
    if not isinstance(data, MjData):
        raise TypeError(f"data must be an mjcffi.MjData, got {type(data).__name__}")
    if key_callback is not None and not callable(key_callback):
        raise TypeError(f"key_callback must be callable, got {key_callback!r}")
    mj_forward(model, data)
    private_model = copy.deepcopy(model)
    private_data = MjData(private_model)
    mj_copyData(private_data, model, data)
    viewer = Viewer(private_model, private_data, key_callback=key_callback,
                    show_left_ui=show_left_ui, show_right_ui=show_right_ui)
    started = queue.Queue(1)
    thread = threading.Thread(target=_render_thread, args=(viewer, started),
                              name="mjcffi.viewer", daemon=True)
    thread.start()
    error = started.get()
    if error is not None:
        raise error
    handle = Handle(viewer, model, data, thread)
    _open_handles.add(handle)
    return handle
