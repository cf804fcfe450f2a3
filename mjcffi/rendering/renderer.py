"""`Renderer`: MuJoCo scenes to NumPy images, offscreen, as the official `mujoco.Renderer`.

    with mjcffi.Renderer(model, height=240, width=320) as renderer:
        renderer.update_scene(data, camera="track")
        pixels = renderer.render()          # (240, 320, 3) uint8, top row first

A Renderer owns an OpenGL context of the backend MUJOCO_GL names (egl, osmesa,
glfw), an MjrContext made in it, and an MjvScene.  `render()` makes its
context current on the calling thread, draws the scene into MuJoCo's offscreen
framebuffer and reads it out: colour, depth in metres, or segmentation (object
id and type per pixel).  The context stays current afterwards, as the
official's does: another thread may render with it only once this one has
given it up (GLContext's rule), and until then gets a RuntimeError.

In a notebook, `mediapy.show_image(renderer.render())` shows a frame inline,
and `mediapy.show_video(frames, fps=30)` a list of them (see `recording`).
"""

import operator
import threading

import numpy as np

from .._generated.enums import mjtCamera, mjtCatBit, mjtDepthMap, mjtFontScale, mjtFramebuffer, \
    mjtObj, mjtRndFlag
from .._support import official as _official
from .._functions import mjr_render, mjr_setBuffer, mjv_defaultFreeCamera, mjv_updateScene
from ..functions._overrides import mj_name2id
from ..model import MjModel
from ..structs import MjrContext, MjrRect, MjvCamera, MjvOption, MjvScene
from . import _readout, context
from ._sizes import pixels

_SEGMENT, _IDCOLOR = int(mjtRndFlag.mjRND_SEGMENT), int(mjtRndFlag.mjRND_IDCOLOR)
_ALL = int(mjtCatBit.mjCAT_ALL)


def _max_geom(value):
    """A non-negative int (MuJoCo would take a negative one as 0)."""
    if isinstance(value, bool):
        raise TypeError("max_geom must be an int, not bool")
    try:
        count = operator.index(value)
    except TypeError:
        raise TypeError(f"max_geom must be an int, not {type(value).__name__}") from None
    if count < 0:
        raise ValueError(f"max_geom must not be negative, got {count}")
    return count


def _fits(size, buffer, name, attribute):
    """ValueError when an image dimension exceeds the model's offscreen framebuffer."""
    if size > buffer:
        raise ValueError(
            f"Image {name} {size} is larger than the model's offscreen framebuffer, "
            f"whose {name} is {buffer} pixels (model.vis.global_.{attribute}). Render a "
            f"smaller image, or make the framebuffer larger in the model's XML:\n"
            f'<visual>\n  <global {attribute}="{size}"/>\n</visual>')


def _gl_context_class():
    """The GLContext class MUJOCO_GL names; RuntimeError where it disables rendering."""
    # chosen, and its library loaded, on the first construction: not on import
    cls = getattr(context, "GLContext", None)
    if cls is None:
        raise RuntimeError("rendering is disabled: the environment variable MUJOCO_GL says "
                           "so; set it to egl, osmesa or glfw before the first render")
    return cls


class Renderer:
    """Renders MuJoCo scenes offscreen into NumPy arrays."""

    def __init__(self, model, height=240, width=320, max_geom=10000,
                 font_scale=mjtFontScale.mjFONTSCALE_150):
        """A renderer of `model` for images of height x width pixels.

        max_geom bounds the geoms of one scene; font_scale is MuJoCo's font size
        (an mjtFontScale) for text drawn with the context.  Raises ValueError when
        the image is larger than the model's offscreen framebuffer
        (model.vis.global_.offwidth x offheight, 640 x 480 unless the XML sets it),
        ImportError when MUJOCO_GL's backend library is missing.
        """
        # set first, so that close() and __del__ work on a renderer whose __init__ raised
        self._gl_context = None
        self._mjr_context = None
        if not isinstance(model, MjModel):
            if _official.is_official(model):     # both bindings have an MjModel: say which
                raise _official.not_accepted("model", "MjModel", model)
            raise TypeError(f"model must be an mjcffi.MjModel, not {type(model).__name__}")
        height, width = pixels(height, "height"), pixels(width, "width")
        _fits(width, model.vis.global_.offwidth, "width", "offwidth")
        _fits(height, model.vis.global_.offheight, "height", "offheight")
        self._model = model
        self._height, self._width = height, width
        self._scene = MjvScene(model, _max_geom(max_geom))
        self._scene_option = MjvOption()
        self._camera = MjvCamera()
        self._rect = MjrRect(0, 0, width, height)
        self._readout = _readout.Readout(height, width)
        self._depth_rendering = False
        self._segmentation_rendering = False

        self._gl_context = _gl_context_class()(width, height)
        self._gl_context.make_current()
        self._mjr_context = MjrContext(model, int(font_scale))
        mjr_setBuffer(int(mjtFramebuffer.mjFB_OFFSCREEN), self._mjr_context)
        # far at 0: what the depth conversion in _readout inverts
        self._mjr_context.readDepthMap = int(mjtDepthMap.mjDEPTH_ZEROFAR)

    # ------------------------------------------------------------ properties

    @property
    def model(self):
        """The MjModel this renderer draws."""
        return self._model

    @property
    def scene(self):
        """The MjvScene that update_scene fills and render draws."""
        return self._scene

    @property
    def height(self):
        """Image height in pixels."""
        return self._height

    @property
    def width(self):
        """Image width in pixels."""
        return self._width

    # ------------------------------------------------------------ modes

    def enable_depth_rendering(self):
        """render() returns depth in metres, (height, width) float32; ends segmentation."""
        self._segmentation_rendering = False
        self._depth_rendering = True

    def disable_depth_rendering(self):
        """render() no longer returns depth."""
        self._depth_rendering = False

    def enable_segmentation_rendering(self):
        """render() returns (object id, mjtObj type) per pixel, (height, width, 2) int32,
        with (-1, -1) for the background; ends depth rendering."""
        self._segmentation_rendering = True
        self._depth_rendering = False

    def disable_segmentation_rendering(self):
        """render() no longer returns segmentation."""
        self._segmentation_rendering = False

    def _mode(self):
        if self._depth_rendering:
            return "depth"
        return "segmentation" if self._segmentation_rendering else "rgb"

    # ------------------------------------------------------------ scene

    def update_scene(self, data, camera=-1, scene_option=None):
        """Fills the scene from `data` as seen by `camera`.

        camera: -1 for the free camera (mjv_defaultFreeCamera's view of the whole
        model), a camera's name or id in the model, or an MjvCamera of your own
        (a tracking camera, say).  scene_option: an MjvOption, or None for the
        renderer's own (defaults).  Raises ValueError for a camera the model lacks.
        """
        if not isinstance(camera, MjvCamera):
            camera = self._fixed_or_free(camera)
        if scene_option is None:
            scene_option = self._scene_option
        mjv_updateScene(self._model, data, scene_option, None, camera, _ALL, self._scene)

    def _fixed_or_free(self, camera):
        """The renderer's MjvCamera set up for a camera name or id."""
        if isinstance(camera, str):
            camera_id = mj_name2id(self._model, int(mjtObj.mjOBJ_CAMERA), camera)
            if camera_id == -1:
                raise ValueError(f'The camera "{camera}" does not exist in this model; '
                                 f'its cameras: {self._camera_names()}')
        elif isinstance(camera, bool):
            raise TypeError("camera must be an id, a name or an MjvCamera, not bool")
        else:
            try:
                camera_id = operator.index(camera)
            except TypeError:
                raise TypeError(f"camera must be an id, a name or an MjvCamera, not "
                                f"{type(camera).__name__}") from None
            if not -1 <= camera_id < self._model.ncam:
                raise ValueError(f"The camera id {camera_id} is out of range [-1, "
                                 f"{self._model.ncam}): the model has {self._model.ncam} "
                                 f"cameras, and -1 is the free camera")
        view = self._camera
        view.fixedcamid = camera_id
        if camera_id == -1:
            view.type = int(mjtCamera.mjCAMERA_FREE)
            mjv_defaultFreeCamera(self._model, view)
        else:
            view.type = int(mjtCamera.mjCAMERA_FIXED)
        return view

    def _camera_names(self):
        names = [self._model.camera(i).name for i in range(self._model.ncam)]
        return ", ".join(repr(n) for n in names) if names else "none"

    # ------------------------------------------------------------ render

    def render(self, *, out=None):
        """The scene as an image: a new array, or `out` filled and returned.

        Colour: (height, width, 3) uint8; depth: (height, width) float32 metres;
        segmentation: (height, width, 2) int32.  Row 0 is the top of the image.
        `out` must have that shape; another numeric dtype, or a non-contiguous
        array, is filled by a cast copy.  Raises RuntimeError after close(), or
        while the renderer's OpenGL context is current on another thread.
        """
        if self._mjr_context is None:
            raise RuntimeError("render cannot be called after close(): make a new Renderer")
        mode = self._mode()
        shape, dtype = _readout.shape_of(mode, self._height, self._width), \
            _readout.DTYPES[mode]
        target = self._target(out, shape, dtype)
        self._make_current()
        if mode == "rgb":
            mjr_render(self._rect, self._scene, self._mjr_context)
            self._readout.read_rgb(self._rect, self._mjr_context, target)
        else:
            self._render_segmented(mode, target)
        if out is not None and out is not target:
            np.copyto(out, target, casting="unsafe")
            return out
        return target

    def _render_segmented(self, mode, target):
        """Depth or segmentation: drawn with segment colours (flat and unlit; depth is
        then more accurate far away), the scene's flags restored after."""
        flags = self._scene.flags
        saved = flags[_SEGMENT], flags[_IDCOLOR]
        flags[_SEGMENT] = flags[_IDCOLOR] = 1
        try:
            mjr_render(self._rect, self._scene, self._mjr_context)
            if mode == "depth":
                self._readout.read_depth(self._rect, self._mjr_context, target, self._model,
                                         self._scene.camera[0].orthographic)
            else:
                self._readout.read_segmentation(self._rect, self._mjr_context, target,
                                                self._scene)
        finally:
            flags[_SEGMENT], flags[_IDCOLOR] = saved

    def _target(self, out, shape, dtype):
        """The array to read into: `out` itself when it has the mode's dtype and is
        C-contiguous, else a new one (copied into `out` after)."""
        if out is None:
            return np.empty(shape, dtype)
        if not isinstance(out, np.ndarray):
            raise TypeError(f"out must be a NumPy array, not {type(out).__name__}")
        if out.shape != shape:
            raise ValueError(
                f"out has shape {out.shape}; this renderer's images have shape {shape} "
                f"(height {self._height}, width {self._width}, "
                f"{'depth' if len(shape) == 2 else self._mode()} rendering): (height, width) "
                f"for depth, (height, width, 2) for segmentation, (height, width, 3) for "
                f"colour")
        if out.dtype.kind not in "biuf":
            raise TypeError(f"out must have a numeric dtype, not {out.dtype}")
        if not out.flags.writeable:
            raise ValueError("out is read-only")
        if out.dtype == dtype and out.flags.c_contiguous:
            return out
        return np.empty(shape, dtype)

    def _make_current(self):
        """Makes the renderer's OpenGL context current here; RuntimeError if another
        thread holds it."""
        gl = self._gl_context
        try:
            gl.make_current()
        except RuntimeError:
            if gl._native is None:
                raise RuntimeError("this Renderer's OpenGL context was freed (GLContext."
                                   "free()): make a new Renderer") from None
            raise RuntimeError(
                f"this Renderer cannot render on thread {threading.current_thread().name!r}: "
                f"its OpenGL context is {gl._state()}, and a context is current on one "
                f"thread at a time (it stays current after a render, and a thread gives it "
                f"up when it ends).  Render on that thread, or make the Renderer on the "
                f"thread that renders with it") from None

    # ------------------------------------------------------------ lifetime

    def close(self):
        """Frees the OpenGL context and MuJoCo's context; render() then raises.

        A second close() does nothing.  The context current on this thread before
        stays current after.
        """
        gl = self._gl_context
        if gl is not None and gl._native is not None and \
                gl._thread not in (None, threading.get_ident()):
            raise RuntimeError(f"this Renderer's OpenGL context is {gl._state()}: close() "
                               f"the renderer on that thread, which may still be drawing")
        con, self._mjr_context = self._mjr_context, None
        self._gl_context = None
        if con is not None:
            if gl is not None and gl._native is not None:
                with gl.as_current():    # MuJoCo deletes its OpenGL objects in their context
                    con.free()
            else:
                con.free()               # the context is gone, and its objects with it
        if gl is not None:
            gl.free()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc_value, traceback):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:        # noqa: BLE001  (held by a live thread, or interpreter shutdown)
            pass

    def __repr__(self):
        state = "closed" if getattr(self, "_mjr_context", None) is None else self._mode()
        return f"<mjcffi.Renderer {getattr(self, '_width', '?')}x" \
               f"{getattr(self, '_height', '?')}, {state}>"
