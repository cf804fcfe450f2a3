"""mujoco-py's render contexts: `MjRenderContext` and `MjRenderContextOffscreen`.

A render context draws one MjSim's model and data offscreen.  It owns:

- a GLContext of MUJOCO_GL's backend (`opengl_context`), made for it;
- an MjrContext (`con`) on MuJoCo's offscreen buffer, whose size is the
  model's `vis.global_.offwidth` x `offheight` until `update_offscreen_size`;
- the scene and view: `scn` (an MjvScene of MAXGEOM geoms), `cam` (a free
  camera looking at the median of the geoms, as mujoco-py's), `vopt`, `pert`;
- mujoco-py's extras: markers (`add_marker`) and text overlays (`add_overlay`)
  drawn into every frame.

Every call that draws makes the GLContext current for its duration only
(`as_current`, restoring what the thread had current) and holds the
context's lock, so one render context serves any thread, one call at a time.
Images come back as OpenGL reads them, as mujoco-py returned them: row 0 is
the *bottom* row of the picture (flip with `image[::-1]` for top-first).
"""

import contextlib
import operator
import threading

import numpy as np

from .. import functions as _f
from .._generated.enums import mjtCamera, mjtCatBit, mjtFont, mjtFontScale, mjtFramebuffer, mjtGridPos, \
    mjtRndFlag
from ..structs import MjrContext, MjrRect, MjvCamera, MjvOption, MjvPerturb, MjvScene
from . import _render_checks as _checks
from ._base import SimBase
from . import _render_gl as _simgl, _markers as _simmarker

MAXGEOM = 10000      # the official Renderer's default; mujoco-py's 1000 drops geoms of big models
_OFFSCREEN = int(mjtFramebuffer.mjFB_OFFSCREEN)
_SEGMENT_FLAGS = (int(mjtRndFlag.mjRND_SEGMENT), int(mjtRndFlag.mjRND_IDCOLOR))
WINDOW_MISSING = ("a render context draws offscreen only: for a window, use "
                  "mjcffi.sim.MjViewer(sim) (or MjViewerBasic), or sim.render(mode='window')")


class MjRenderContext:
    """Renders an MjSim's scene offscreen with MuJoCo's mjr_* functions, as in mujoco-py.

    `MjRenderContext(sim, offscreen=True, device_id=-1, opengl_backend=None, quiet=False)`
    makes the context and adds it to `sim.render_contexts` (the first offscreen one is
    the one `sim.render` uses).  `device_id` picks an EGL device (-1: the default; see
    `mjcffi.sim._render_gl`); `opengl_backend`, if given, must name the backend that
    MUJOCO_GL chose ('egl', 'osmesa', 'glfw'): a process renders with one.
    `offscreen=False` (a window) is refused: MjViewer(sim) is the window.

    `render(width, height, camera_id=None)` draws a frame into the offscreen buffer and
    `read_pixels(width, height, depth=True)` reads it back.  `free()` releases the
    OpenGL context; the render context then refuses every call.
    """

    def __init__(self, sim, offscreen=True, device_id=-1, opengl_backend=None, quiet=False):
        self._gl = None
        if not isinstance(sim, SimBase):
            raise TypeError(f"sim must be an MjSim, not {type(sim).__name__}")
        if not offscreen:
            raise NotImplementedError(WINDOW_MISSING)
        device_id = _simgl.device_id(device_id)
        _simgl.check_backend(opengl_backend)
        self._lock = threading.RLock()
        self.sim, self.offscreen = sim, True
        self._markers, self._overlay = [], {}
        vis = sim.model.vis.global_
        gl = _simgl.gl_context(device_id, vis.offwidth, vis.offheight)
        try:
            sim.forward()            # as mujoco-py: something to draw from the start
            with gl.as_current():
                self._make(sim.model)
        except BaseException:
            gl.free()
            raise
        self._adopt_gl(gl)
        sim.add_render_context(self)

    def _adopt_gl(self, gl):
        """Take `gl` (its MjrContext and scene made) and start the camera, options and
        perturbation as mujoco-py did: what every render context does once made."""
        self._gl = gl
        self.cam, self.vopt, self.pert = MjvCamera(), MjvOption(), MjvPerturb()
        self.pert.active, self.pert.select, self.pert.skinselect = 0, 0, -1
        self._init_camera()

    # ------------------------------------------------------------ setup

    def _make(self, model):
        """The MjrContext on the offscreen buffer and the scene, for `model` (GL current)."""
        con = MjrContext(model, int(mjtFontScale.mjFONTSCALE_150))
        _f.mjr_setBuffer(_OFFSCREEN, con)
        if con.currentBuffer != _OFFSCREEN:
            con.free()
            raise RuntimeError("this OpenGL context offers no offscreen framebuffer to "
                               "MuJoCo (mjr_setBuffer(mjFB_OFFSCREEN) did not take)")
        self.con, self.scn = con, MjvScene(model, MAXGEOM)

    def _init_camera(self):
        """mujoco-py's start: a free camera at the model's extent from the geoms' median."""
        model, data = self.sim.model, self.sim.data
        self.cam.type, self.cam.fixedcamid = int(mjtCamera.mjCAMERA_FREE), -1
        self.cam.lookat[:] = np.median(data.geom_xpos, axis=0) if model.ngeom else \
            model.stat.center
        self.cam.distance = model.stat.extent

    @property
    def opengl_context(self):
        """The GLContext this render context draws in; None once freed.

        To call mjr_* functions on `con` yourself, make it current around them:
        `with ctx.opengl_context.as_current(): ...`."""
        return self._gl

    @contextlib.contextmanager
    def _drawing(self):
        """This context's lock, and its GLContext current on this thread, for a block."""
        with self._lock:
            if self._gl is None:
                raise RuntimeError(f"this {type(self).__name__} was freed: make a new one "
                                   f"(sim.render makes one itself)")
            with self._gl.as_current():
                yield

    # ------------------------------------------------------------ drawing

    def render(self, width, height, camera_id=None, segmentation=False):
        """Draw a frame of `width` x `height` pixels into the offscreen buffer.

        `camera_id`: None keeps `cam` as it is (at first, the free camera), -1 makes it
        the free camera, k >= 0 the model's camera k.  `sim.render_callback(sim, self)`,
        if set, runs first; markers and overlays are drawn on top of the scene.  With
        `segmentation`, geoms are drawn in flat colours that encode their segment ids
        (read them back with `read_pixels(..., segmentation=True)`).
        """
        with self._drawing():
            width, height = _checks.image_size(width, height, self.con.offWidth,
                                                 self.con.offHeight)
            model = self.sim.model
            camera_id = _checks.camera_id(model, camera_id)
            if self.sim.render_callback is not None:
                self.sim.render_callback(self.sim, self)
            if camera_id is not None:
                self.cam.type = int(mjtCamera.mjCAMERA_FREE if camera_id == -1
                                    else mjtCamera.mjCAMERA_FIXED)
                self.cam.fixedcamid = camera_id
            _f.mjv_updateScene(model, self.sim.data, self.vopt, self.pert, self.cam,
                               int(mjtCatBit.mjCAT_ALL), self.scn)
            flags = self.scn.flags
            saved = [int(flags[i]) for i in _SEGMENT_FLAGS]
            try:
                if segmentation:
                    for i in _SEGMENT_FLAGS:
                        flags[i] = 1
                for marker in self._markers:
                    _simmarker.add_to_scene(self.scn, marker)
                rect = MjrRect(0, 0, width, height)
                _f.mjr_render(rect, self.scn, self.con)
                for gridpos, (text1, text2) in self._overlay.items():
                    _f.mjr_overlay(int(mjtFont.mjFONT_NORMAL), gridpos, rect, text1, text2,
                                   self.con)
            finally:
                for i, value in zip(_SEGMENT_FLAGS, saved):
                    flags[i] = value

    def read_pixels(self, width, height, depth=True, segmentation=False):
        """The last frame's bottom-left `width` x `height` pixels, as mujoco-py read them.

        Returns rgb, a (height, width, 3) uint8 array, and with `depth` (the default) a
        pair (rgb, depth), depth a (height, width) float32 array.  Rows are in OpenGL's
        order: row 0 is the bottom of the picture; `rgb[::-1]` is the picture top-first.
        Depth is OpenGL's depth buffer as it is: 0 at the near clipping plane, 1 at the
        far one and where nothing was drawn, not linear in distance.  The distance along
        the view axis is `near / (1 - depth * (1 - near / far))`, with
        `near = model.vis.map.znear * model.stat.extent` and `far` likewise from zfar.
        With `segmentation`, after a `render(..., segmentation=True)`, the image is
        instead (height, width, 2) int32: each pixel's (object type, object id), as
        mujoco-py's (type first), and (-1, -1) where no geom was drawn.
        """
        with self._drawing():
            width, height = _checks.image_size(width, height, self.con.offWidth,
                                                 self.con.offHeight)
            rgb = np.zeros((height, width, 3), np.uint8)
            depth_image = np.zeros((height, width), np.float32) if depth else None
            _f.mjr_readPixels(rgb, depth_image, MjrRect(0, 0, width, height), self.con)
            image = _segments(rgb, self.scn) if segmentation else rgb
        return (image, depth_image) if depth else image

    def read_pixels_depth(self, buffer):
        """Read the depth of the last frame into `buffer`, a (height, width) float32
        C-contiguous array (the raw depth buffer, as read_pixels returns it)."""
        if not isinstance(buffer, np.ndarray) or buffer.dtype != np.float32 \
                or buffer.ndim != 2 or not buffer.flags.c_contiguous \
                or not buffer.flags.writeable:
            raise TypeError("buffer must be a writable C-contiguous (height, width) float32 "
                            "numpy array")
        with self._drawing():
            height, width = buffer.shape
            width, height = _checks.image_size(width, height, self.con.offWidth,
                                                 self.con.offHeight)
            _f.mjr_readPixels(None, buffer, MjrRect(0, 0, width, height), self.con)
        return buffer

    def draw_pixels(self, image, left, bottom):
        """Draw a (height, width, 3) uint8 image into the offscreen buffer, its bottom-left
        corner at pixel (left, bottom); its row 0 is drawn at the bottom."""
        if not isinstance(image, np.ndarray) or image.dtype != np.uint8 or image.ndim != 3 \
                or image.shape[2] != 3:
            raise TypeError("image must be a (height, width, 3) uint8 numpy array")
        left, bottom = _corner(left, "left"), _corner(bottom, "bottom")
        with self._drawing():
            height, width = image.shape[:2]
            if left + width > self.con.offWidth or bottom + height > self.con.offHeight:
                raise ValueError(f"an image of {width}x{height} at ({left}, {bottom}) does not "
                                 f"fit the offscreen buffer of {self.con.offWidth}x"
                                 f"{self.con.offHeight}")
            _f.mjr_drawPixels(np.ascontiguousarray(image), None,
                              MjrRect(left, bottom, width, height), self.con)

    # ------------------------------------------------------------ model edits and view

    def upload_texture(self, tex_id):
        """Send the model's texture `tex_id` (edited in `model.tex_data`) to OpenGL, so
        the next frame shows it."""
        with self._drawing():
            model = self.sim.model
            tex_id = _index(tex_id, "tex_id", model.ntex, "textures")
            _f.mjr_uploadTexture(model, self.con, tex_id)

    def update_offscreen_size(self, width, height):
        """Resize the offscreen buffer, as mujoco-py did: the model's
        `vis.global_.offwidth/offheight` become the new size too."""
        width = _checks.buffer_side(width, "width")
        height = _checks.buffer_side(height, "height")
        with self._drawing():
            if (width, height) == (self.con.offWidth, self.con.offHeight):
                return
            vis = self.sim.model.vis.global_
            vis.offwidth, vis.offheight = width, height
            _f.mjr_resizeOffscreen(width, height, self.con)
            _f.mjr_setBuffer(_OFFSCREEN, self.con)

    def move_camera(self, action, reldx, reldy):
        """Move `cam` as a mouse drag would (mjv_moveCamera; action is an mjtMouse)."""
        with self._lock:
            _f.mjv_moveCamera(self.sim.model, action, reldx, reldy, self.cam)

    def add_marker(self, **marker_params):
        """Draw a decor geom in every later frame; keywords are mjvGeom fields (type,
        size, pos, mat, rgba, label, emission, ...).  Checked here: an unknown field is a
        ValueError, a value of the wrong kind or shape a TypeError or ValueError."""
        marker = _simmarker.make(marker_params)
        with self._lock:
            self._markers.append(marker)

    def add_overlay(self, gridpos, text1, text2):
        """Add a line of text (`text1` on the left, `text2` on the right) at `gridpos`
        (an mjtGridPos) to every later frame; lines at one position accumulate."""
        try:
            gridpos = int(mjtGridPos(gridpos))
        except (TypeError, ValueError):
            raise ValueError(f"gridpos must be an mjtGridPos value, not {gridpos!r}") from None
        for name, text in (("text1", text1), ("text2", text2)):
            if not isinstance(text, str):
                raise TypeError(f"{name} must be a str, not {type(text).__name__}")
            if not text.isascii():
                raise ValueError(f"{name} must be ASCII text: MuJoCo's fonts have 128 "
                                 f"characters")
        with self._lock:
            lines = self._overlay.setdefault(gridpos, ["", ""])
            lines[0] += text1 + "\n"
            lines[1] += text2 + "\n"

    def update_sim(self, new_sim):
        """Render `new_sim` from now on, with a new MjrContext and scene for its model.

        This context moves from the old sim's `render_contexts` to the new one's (mujoco-py
        also added the old sim's other contexts, which still draw the old sim)."""
        if new_sim is self.sim:
            return
        if not isinstance(new_sim, SimBase):
            raise TypeError(f"new_sim must be an MjSim, not {type(new_sim).__name__}")
        with self._drawing():
            old = self.con
            self._make(new_sim.model)
            old.free()
            self.sim._forget_render_context(self)
            self.sim = new_sim
            new_sim.add_render_context(self)

    # ------------------------------------------------------------ lifetime

    def free(self):
        """Release the OpenGL context and MuJoCo's buffers now, and leave the sim's
        render contexts; later calls raise RuntimeError.  Freeing twice does nothing.
        RuntimeError if the GLContext is current on another thread: free it there."""
        with self._lock:
            gl = self._gl
            if gl is None:
                return
            gl.free()                # its OpenGL objects go with it
            self._gl = None
            self.con.free()          # MuJoCo's memory; no OpenGL call without the context
            self.sim._forget_render_context(self)

    def __repr__(self):
        if self._gl is None:
            return f"<{type(self).__name__} (freed)>"
        return (f"<{type(self).__name__} {self.con.offWidth}x{self.con.offHeight} offscreen "
                f"buffer, {self._gl.backend}>")


class MjRenderContextOffscreen(MjRenderContext):
    """An offscreen render context: `MjRenderContextOffscreen(sim, device_id=-1)`."""

    def __init__(self, sim, device_id=-1):
        super().__init__(sim, offscreen=True, device_id=device_id)


def _segments(rgb, scn):
    """(height, width, 2) int32 of (object type, object id) from a segmentation frame."""
    ids = rgb[..., 0].astype(np.int64) | (rgb[..., 1].astype(np.int64) << 8) \
        | (rgb[..., 2].astype(np.int64) << 16)
    ngeom = scn.ngeom
    table = np.full((ngeom + 1, 2), -1, np.int32)
    if ngeom:
        geoms = scn.geoms[:ngeom]
        segid = np.asarray(geoms.segid)
        shown = (segid >= 0) & (segid < ngeom)
        table[segid[shown] + 1, 0] = np.asarray(geoms.objtype)[shown]
        table[segid[shown] + 1, 1] = np.asarray(geoms.objid)[shown]
    ids[ids > ngeom] = 0
    return table[ids]


def _index(value, name, size, what):
    if isinstance(value, (bool, np.bool_)) or not hasattr(value, "__index__"):
        raise TypeError(f"{name} must be an int, not {type(value).__name__}")
    value = operator.index(value)
    if not 0 <= value < size:
        raise ValueError(f"{name} must be from 0 to {size - 1}, not {value}" if size else
                         f"{name}={value}: the model has no {what}")
    return value


def _corner(value, name):
    if isinstance(value, (bool, np.bool_)) or not hasattr(value, "__index__"):
        raise TypeError(f"{name} must be an int, not {type(value).__name__}")
    value = operator.index(value)
    if value < 0:
        raise ValueError(f"{name} must not be negative, not {value}")
    return value
