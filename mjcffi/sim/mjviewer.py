"""mujoco-py's viewers, `MjViewerBasic` and `MjViewer`: a window the caller's loop draws.

    sim = MjSim(load_model_from_path(path))
    viewer = MjViewer(sim)
    while True:
        sim.step()
        viewer.render()

There is no viewer thread: the window is made, drawn and polled on the thread
that calls `render()`, as in mujoco-py.  A viewer is one of the sim's render
contexts (in `sim.render_contexts`, and `sim._render_context_window`), with
mujoco-py's `cam`, `vopt`, `scn`, `pert`, `add_marker` and `add_overlay`.  The
window, its input state and the mouse's camera moves are mjcffi.viewer's
(`_window`, `_input`, `_interaction`).

`MjViewerBasic`: left drag rotates the camera, right drag pans it (shift:
horizontally), middle drag and the wheel zoom; ESC closes.  Once the window is
closed, the next `render()` frees the viewer and raises SystemExit(0): mujoco-py
ended the program there, which ends a `while True` loop.

`MjViewer` adds mujoco-py's menu (H hides it) and keys, which act when released,
as mujoco-py's: TAB next camera, SPACE pause (render() draws until unpaused),
RIGHT one step while paused, S/F halve/double the run speed, D render every
frame, C contact points and forces, E body frames, R transparency, M inertia
boxes, 0-4 geom groups, T screenshot, V record video.  Override
`key_callback(window, key, scancode, action, mods)` and call the base's for
the rest.  Not mujoco-py's: R and M toggle MuJoCo's own flags (mjVIS_TRANSPARENT,
mjVIS_INERTIA) where mujoco-py edited `geom_rgba` (M hid mocap bodies there),
and I (ipdb) is not bound.

`render()` paces itself as mujoco-py's did, so that the picture runs at
`_run_speed` times real time: each call adds the simulated time of one step
over the time of one frame to a budget and draws while the budget lasts (none
to several frames a call); `_render_every_frame` (D) draws exactly one.
"""

import contextlib
import ctypes
import sys
import threading
import time

import numpy as np

from .. import functions as _f
from .._generated.enums import mjtCatBit, mjtFont, mjtFontScale, mjtFramebuffer, mjtGridPos, mjtVisFlag
from . import _markers as _simmarker
from ._base import SimBase
from ._render import MAXGEOM, MjRenderContext
from ..structs import MjrContext, MjrRect, MjvScene
from ..viewer import _interaction, _overlay
from ..viewer._input import WindowState
from ..viewer._viewer import window_size
from ..viewer._window import Window, glfw

TITLE = "mjcffi.sim"
PAUSED_FRAME = 1 / 60        # seconds: a paused viewer draws at most 60 frames a second
_WINDOW = int(mjtFramebuffer.mjFB_WINDOW)
_TOPLEFT = int(mjtGridPos.mjGRID_TOPLEFT)
_BOTTOMLEFT = int(mjtGridPos.mjGRID_BOTTOMLEFT)
_BOTTOMRIGHT = int(mjtGridPos.mjGRID_BOTTOMRIGHT)
_CONTACTS = (int(mjtVisFlag.mjVIS_CONTACTPOINT), int(mjtVisFlag.mjVIS_CONTACTFORCE))
_TRANSPARENT = int(mjtVisFlag.mjVIS_TRANSPARENT)
_INERTIA = int(mjtVisFlag.mjVIS_INERTIA)
_GROUP_KEYS = (glfw.KEY_0, glfw.KEY_1, glfw.KEY_2, glfw.KEY_3, glfw.KEY_4)


def _address(window):
    """The address of a GLFW window pointer (None for NULL), to compare two pointers."""
    return ctypes.cast(window, ctypes.c_void_p).value if window else None


class _WindowContext:
    """The window's OpenGL context, in the place of a render context's GLContext."""

    backend = "glfw window"

    def __init__(self, window):
        self.window = window

    @contextlib.contextmanager
    def as_current(self):
        """The window's context current for a block, then the thread's previous one again
        (none, usually): MuJoCo's offscreen contexts on this thread stay undisturbed."""
        handle = self.window._handle
        previous = glfw.get_current_context()
        if _address(previous) == _address(handle):
            yield
            return
        try:
            glfw.make_context_current(handle)     # inside the `try`: see rendering/_base.py
            yield
        finally:
            glfw.make_context_current(previous if previous else None)

    def free(self):
        self.window.destroy()


class MjViewerBasic(MjRenderContext):
    """A window showing an MjSim, drawn by `render()`; the mouse moves the camera."""

    def __init__(self, sim):
        self._gl = None
        if not isinstance(sim, SimBase):
            raise TypeError(f"sim must be an MjSim, not {type(sim).__name__}")
        self._lock = threading.RLock()
        self.sim, self.offscreen = sim, False
        self._markers, self._overlay = [], {}
        self._input = WindowState()
        self._meter = _overlay.Meter()
        sim.forward()                # something to draw from the start, as mujoco-py
        window = Window(window_size, TITLE, self)
        gl = _WindowContext(window)
        try:
            # Window() left its context current: hand the thread back as it was
            glfw.make_context_current(None)
            with gl.as_current():
                self.con = MjrContext(sim.model, int(mjtFontScale.mjFONTSCALE_150))
                _f.mjr_setBuffer(_WINDOW, self.con)
            self.scn = MjvScene(sim.model, MAXGEOM)
        except BaseException:
            gl.free()
            raise
        self._adopt_gl(gl)
        self.on_resize()
        sim.add_render_context(self)
        if sim._render_context_window is None:
            sim._render_context_window = self

    # ------------------------------------------------------------ mujoco-py's names

    @property
    def window(self):
        """The GLFW window (mujoco-py's `viewer.window`); None once closed."""
        return self._gl.window._handle if self._gl is not None else None

    @property
    def model(self):
        return self.sim.model

    @property
    def data(self):
        return self.sim.data

    # ------------------------------------------------------------ drawing

    def render(self):
        """Draw the sim's state into the window and process its events.

        Does nothing once the viewer is freed; after the window was closed (its close
        button, ESC), frees the viewer and raises SystemExit(0), as mujoco-py did."""
        if not self._open():
            return
        with self._drawing():
            self._draw()
            self._frame_drawn()
        self._gl.window.swap()
        self._meter.tick(self.sim.data.time)
        self._gl.window.poll()           # the callbacks (keys, mouse) run now

    def _open(self):
        """False once freed; SystemExit(0) once the window was asked to close."""
        if self._gl is None:
            return False
        if self._gl.window.should_close():
            self._quit()
        return True

    def _draw(self):
        """The scene, the markers and the overlay, into the window's back buffer."""
        if self.sim.render_callback is not None:
            self.sim.render_callback(self.sim, self)
        width, height = self._input.framebuffer_size
        _f.mjv_updateScene(self.sim.model, self.sim.data, self.vopt, self.pert, self.cam,
                           int(mjtCatBit.mjCAT_ALL), self.scn)
        for marker in self._markers:
            _simmarker.add_to_scene(self.scn, marker)
        rect = MjrRect(0, 0, width, height)
        _f.mjr_setBuffer(_WINDOW, self.con)
        _f.mjr_render(rect, self.scn, self.con)
        for gridpos, (text1, text2) in self._overlay.items():
            _f.mjr_overlay(int(mjtFont.mjFONT_NORMAL), gridpos, rect, text1, text2, self.con)

    def _frame_drawn(self):
        """Called with each frame drawn, before it is shown (MjViewer records it)."""

    def capture(self):
        """A freshly drawn frame of the window, (height, width, 3) uint8, top row first.

        The window shows nothing new: the frame stays in its back buffer."""
        with self._drawing():
            self._draw()
            return self._read_window()

    def _read_window(self):
        width, height = self._input.framebuffer_size
        rgb = np.zeros((height, width, 3), dtype=np.uint8)
        _f.mjr_readPixels(rgb, None, MjrRect(0, 0, width, height), self.con)
        return np.flipud(rgb)

    def _read_pixels_as_in_window(self, resolution=None):
        """mujoco-py's screenshot: the window's picture, top row first.  `resolution`
        must be None or the window's framebuffer size (it is read from the window)."""
        if resolution is not None and tuple(resolution) != self._input.framebuffer_size:
            raise ValueError(f"resolution {tuple(resolution)} is not the window's "
                             f"{self._input.framebuffer_size}: the viewer reads its window; "
                             f"render other sizes with sim.render(width, height)")
        return self.capture()

    # ------------------------------------------------------------ window events

    def key_callback(self, window, key, scancode, action, mods):
        """ESC (released) closes the window; override for more keys."""
        if action == glfw.RELEASE and key == glfw.KEY_ESCAPE and self._gl is not None:
            print("Pressed ESC\nQuitting.")
            self._gl.window.request_close()

    def on_key(self, key, scancode, action, mods):
        self._input.key(key, action, mods)
        self.key_callback(self.window, key, scancode, action, mods)

    def on_button(self, button, action, mods):
        self._input.button(button, action, mods)

    def on_move(self, x, y):
        dx, dy = self._input.move(x, y)
        if self._input.dragging:
            with self._lock:
                _interaction.drag(self, self._input.state, dx, dy, self._input.window_size[1])

    def on_scroll(self, sx, sy):
        self._input.scroll(sx, sy)
        with self._lock:
            _interaction.zoom(self, sy)

    def on_resize(self, width=None, height=None):
        if self._gl is not None:
            window = self._gl.window
            self._input.resize(window.window_size(), window.framebuffer_size())

    def on_drop(self, paths):
        """Files dropped on the window are ignored (mujoco-py's viewer took none)."""

    # ------------------------------------------------------------ lifetime

    def free(self):
        """Close the window and free its context; the sim forgets the viewer, and
        render() does nothing from now on.  Freeing twice does nothing."""
        with self._lock:
            gl = self._gl
            if gl is None:
                return
            with gl.as_current():
                self.con.free()
            gl.free()
            self._gl = None
            self.sim._forget_render_context(self)
            if self.sim._render_context_window is self:
                self.sim._render_context_window = None

    close = free

    def _quit(self):
        self.free()
        sys.exit(0)

    def __repr__(self):
        if self._gl is None:
            return f"<{type(self).__name__} (closed)>"
        width, height = self._input.framebuffer_size
        return f"<{type(self).__name__} window {width}x{height}>"


class MjViewer(MjViewerBasic):
    """mujoco-py's MjViewer: MjViewerBasic with its menu, pause, speed and recording keys."""

    def __init__(self, sim):
        super().__init__(sim)
        self._ncam = sim.model.ncam
        self._paused = False
        self._advance_by_one_step = False
        self._record_video = False
        self._video_path = "/tmp/video_%07d.mp4"
        self._video_idx = 0
        self._video_writer = None        # an imageio writer while recording, if one opened
        self._video_frames = []          # the frames kept when no writer could be opened
        self._video_frame_count = 0
        self._image_path = "/tmp/frame_%07d.png"
        self._image_idx = 0
        self._run_speed = 1.0
        self._loop_count = 0.0
        self._render_every_frame = False
        self._transparent = False
        self._time_per_render = 1 / 60.0
        self._hide_overlay = False
        self._user_overlay = {}

    # ------------------------------------------------------------ the loop

    def render(self):
        """Draw as many frames as this step's share of real time asks (see the module);
        while paused, draw until SPACE (or RIGHT, for one step) is released."""
        if not self._open():
            return
        # the overlay lines the caller added since the last call, drawn in every frame
        self._user_overlay = {k: list(v) for k, v in self._overlay.items()}
        if self._paused:
            while self._paused and self._gl is not None:
                self._render_frame()
                if self._advance_by_one_step:
                    self._advance_by_one_step = False
                    break
                time.sleep(PAUSED_FRAME)
        else:
            step = self.sim.model.opt.timestep * self.sim.nsubsteps
            self._loop_count += step / (self._time_per_render * self._run_speed)
            if self._render_every_frame:
                self._loop_count = 1
            while self._loop_count > 0 and self._gl is not None:
                self._render_frame()
                self._loop_count -= 1
        # as mujoco-py: markers and overlay are the caller's to add again for each call
        self._markers[:] = []
        self._overlay.clear()

    def _render_frame(self):
        """One frame: the menu (unless hidden), the scene, the window's events."""
        start = time.monotonic()
        self._overlay.clear()
        if not self._hide_overlay:
            for gridpos, lines in self._user_overlay.items():
                self._overlay[gridpos] = list(lines)
            self._create_full_overlay()
        super().render()
        if not self._record_video:   # recording's slowness must not count as drawing time
            spent = max(time.monotonic() - start, 1e-4)
            self._time_per_render = 0.9 * self._time_per_render + 0.1 * spent

    def _frame_drawn(self):
        if self._record_video:
            self._keep_frame(self._read_window())

    def _create_full_overlay(self):
        """mujoco-py's menu: the keys and their states, and the step's figures."""
        def on_off(flag):
            return "On" if flag else "Off"
        add, vopt = self.add_overlay, self.vopt
        if self._render_every_frame:
            add(_TOPLEFT, "", "")
        else:
            add(_TOPLEFT, f"Run speed = {self._run_speed:.3f} x real time", "[S]lower, [F]aster")
        add(_TOPLEFT, "Ren[d]er every frame", on_off(self._render_every_frame))
        add(_TOPLEFT, f"Switch camera (#cams = {self._ncam + 1})",
            f"[Tab] (camera ID = {self.cam.fixedcamid})")
        add(_TOPLEFT, "[C]ontact forces", on_off(vopt.flags[_CONTACTS[1]]))
        add(_TOPLEFT, "Referenc[e] frames", on_off(vopt.frame))
        add(_TOPLEFT, "T[r]ansparent", on_off(vopt.flags[_TRANSPARENT]))
        add(_TOPLEFT, "Inertia boxes [M]", on_off(vopt.flags[_INERTIA]))
        add(_TOPLEFT, "Start" if self._paused else "Stop", "[Space]")
        add(_TOPLEFT, "Advance simulation by one step", "[right arrow]")
        add(_TOPLEFT, "[H]ide Menu", "")
        if self._record_video:
            dots = "." * (int(time.monotonic() * 2) % 4)
            add(_TOPLEFT, f"Record [V]ideo (On) {dots}", "")
        else:
            add(_TOPLEFT, "Record [V]ideo (Off)", "")
        if self._video_idx > 0:
            add(_TOPLEFT, f"   saved as {self._video_path % (self._video_idx - 1)}", "")
        add(_TOPLEFT, "Cap[t]ure frame", "")
        if self._image_idx > 0:
            add(_TOPLEFT, f"   saved as {self._image_path % (self._image_idx - 1)}", "")
        add(_TOPLEFT, "Toggle geomgroup visibility", "0-4")
        add(_BOTTOMLEFT, "FPS", f"{self._meter.fps:.0f}")
        add(_BOTTOMLEFT, "Solver iterations", str(int(self.sim.data.solver_niter[0]) + 1))
        timestep = self.sim.model.opt.timestep
        add(_BOTTOMRIGHT, "Step", str(round(self.sim.data.time / timestep)))
        add(_BOTTOMRIGHT, "timestep", f"{timestep:.5f}")
        add(_BOTTOMRIGHT, "n_substeps", str(self.sim.nsubsteps))

    # ------------------------------------------------------------ keys

    def key_callback(self, window, key, scancode, action, mods):
        """mujoco-py's keys, on release (see the module); then MjViewerBasic's (ESC)."""
        if action != glfw.RELEASE:
            return
        if key == glfw.KEY_TAB:
            _interaction.cycle_camera(self, +1)
        elif key == glfw.KEY_H:
            self._hide_overlay = not self._hide_overlay
        elif key == glfw.KEY_SPACE and self._paused is not None:
            self._paused = not self._paused
        elif key == glfw.KEY_RIGHT and self._paused is not None:
            self._advance_by_one_step = True
            self._paused = True
        elif key == glfw.KEY_V or (key == glfw.KEY_ESCAPE and self._record_video):
            self._toggle_video()
        elif key == glfw.KEY_T:
            self._screenshot()
        elif key == glfw.KEY_S:
            self._run_speed /= 2.0
        elif key == glfw.KEY_F:
            self._run_speed *= 2.0
        elif key == glfw.KEY_C:
            shown = 0 if self.vopt.flags[_CONTACTS[0]] else 1
            for flag in _CONTACTS:
                self.vopt.flags[flag] = shown
        elif key == glfw.KEY_D:
            self._render_every_frame = not self._render_every_frame
        elif key == glfw.KEY_E:
            self.vopt.frame = 1 - self.vopt.frame
        elif key == glfw.KEY_R:
            self._transparent = not self._transparent
            self.vopt.flags[_TRANSPARENT] = int(self._transparent)
        elif key == glfw.KEY_M:
            self.vopt.flags[_INERTIA] = 1 - self.vopt.flags[_INERTIA]
        elif key in _GROUP_KEYS:
            self.vopt.geomgroup[key - glfw.KEY_0] ^= 1
        super().key_callback(window, key, scancode, action, mods)

    # ------------------------------------------------------------ screenshots and video

    def _screenshot(self):
        """T: the window's picture to `_image_path % _image_idx`, a png written by imageio."""
        image = self._read_pixels_as_in_window()
        path = self._image_path % self._image_idx
        imageio = _imageio()
        if imageio is None:
            self._last_screenshot = image
            print("mjcffi.sim viewer: imageio is not installed (pip install imageio): the "
                  "screenshot is kept in viewer._last_screenshot, not written")
            return
        imageio.imwrite(path, image)
        self._image_idx += 1
        print(f"mjcffi.sim viewer: saved a screenshot to {path}")

    def _toggle_video(self):
        """V: start recording, or stop and close the video file."""
        self._record_video = not self._record_video
        if self._record_video:
            self._video_frames, self._video_frame_count = [], 0
            self._video_writer = self._open_video()
            return
        writer, self._video_writer = self._video_writer, None
        if writer is not None:
            writer.close()
            print(f"mjcffi.sim viewer: saved {self._video_frame_count} frames to "
                  f"{self._video_path % self._video_idx}")
            self._video_idx += 1
        else:
            print(f"mjcffi.sim viewer: kept {len(self._video_frames)} frames in "
                  "viewer._video_frames (no video writer)")

    def _open_video(self):
        """An imageio writer at `_video_path % _video_idx`, or None (then frames are kept,
        and why is printed)."""
        path = self._video_path % self._video_idx
        imageio = _imageio()
        if imageio is None:
            print("mjcffi.sim viewer: imageio is not installed (pip install imageio "
                  "imageio-ffmpeg): the frames are kept in viewer._video_frames")
            return None
        fps = max(1.0, 1.0 / self._time_per_render)
        try:
            return imageio.get_writer(path, fps=fps)
        except Exception as error:       # noqa: BLE001  (no plugin for the format, bad path)
            print(f"mjcffi.sim viewer: cannot write {path} ({error}): the frames are kept "
                  "in viewer._video_frames")
            return None

    def _keep_frame(self, frame):
        self._video_frame_count += 1
        if self._video_writer is not None:
            self._video_writer.append_data(frame)
        else:
            self._video_frames.append(frame)

    def free(self):
        """Close the window (and a video being recorded)."""
        if self._record_video:
            self._toggle_video()
        super().free()

    close = free


def _imageio():
    try:
        import imageio
    except ImportError:
        return None
    return imageio
