"""`Viewer`: one window drawing one model's scene, on the thread that opened it.

A Viewer owns the window, its MjrContext and MjvScene, the camera, options and
perturbation, and `lock` (an RLock) that guards them against other threads.
The thread that calls `open()` (the render thread) is the only one that touches
the window or OpenGL; it runs `frame()` in a loop: process input, draw, swap.
Other threads reach it through `call(fn)`, which runs fn on the render thread
between frames and returns its result.

It draws `model`/`data` as they are: the passive handle gives it private copies
and refreshes them at sync(), the managed loop gives it the simulated ones.
Extra geoms (the passive handle's user_scn) are appended to each scene after
mjv_updateScene; the handle's figures, texts and images (`user_overlays`) are
drawn last, over everything else.
"""

import queue
import threading
import time

import numpy as np

from .._generated.enums import mjtCatBit, mjtFont, mjtFontScale, mjtFramebuffer, mjtGridPos
from .._functions import (mjr_overlay, mjr_render, mjr_setBuffer, mjv_defaultFreeCamera,
                          mjv_updateScene)
from ..functions._overrides import mjr_readPixels
from .._support.library import ffi
from ..structs import MjrContext, MjrRect, MjvCamera, MjvOption, MjvPerturb, MjvScene
from . import _interaction, _overlay, _panels
from ._user_overlays import UserOverlays
from ._input import WindowState
from ._window import Window, report, glfw

MAX_GEOM = 10000             # geoms of the model's scene; as many again for user geoms
FRAME_INTERVAL = 1 / 60      # seconds: frames are paced to at most 60 per second
DEFAULT_SIZE = None          # (width, height) of new windows; None: 2/3 of the screen
_GEOM_SIZE = ffi.sizeof("mjvGeom")


def window_size():
    """DEFAULT_SIZE, or 2/3 of the primary monitor (GLFW initialised)."""
    if DEFAULT_SIZE is not None:
        return DEFAULT_SIZE
    monitor = glfw.get_primary_monitor()
    mode = glfw.get_video_mode(monitor) if monitor else None
    if not mode:
        return 1200, 900
    return max(320, mode.size.width * 2 // 3), max(240, mode.size.height * 2 // 3)


class Viewer:
    """The window, the scene drawn into it, and the input that moves its camera."""

    def __init__(self, model, data, *, title="MuJoCo (mjcffi)", key_callback=None,
                 show_left_ui=True, show_right_ui=True, managed=False):
        self.model, self.data = model, data
        self.cam, self.opt, self.pert = MjvCamera(), MjvOption(), MjvPerturb()
        mjv_defaultFreeCamera(model, self.cam)
        self.lock = threading.RLock()
        self.title, self.managed = title, managed
        self.key_callback = key_callback
        self.key_handler = None          # managed loop: (key, mods) -> True when handled
        self.drop_handler = None         # managed loop: (paths) -> None
        self.action_handler = None       # managed loop: (a panel action: 'pause', ...)
        self.show_ui = [show_left_ui, show_right_ui]
        self.show_info, self.show_help = True, False
        self.paused = None               # managed loop: True / False, shown in the info
        self.message = ""                # a line shown at the top (load errors)
        self.scene = self.con = self.window = self.panels = None
        self.input = WindowState()
        self.meter = _overlay.Meter()
        self.user_overlays = UserOverlays()   # the passive handle's set_figures/texts/images
        self.scrub = 0                   # managed loop: 0, or -k while showing k states back
        self._extra = ffi.new("mjvGeom[]", MAX_GEOM)    # user geoms, copied at sync
        self.extra_count = 0
        self._calls = queue.Queue()
        self._closing = threading.Event()
        self._thread = None
        self._next_frame = 0.0

    # ------------------------------------------------------------ life cycle

    def open(self):
        """Make the window, context and scene on this thread, the render thread from now."""
        self._thread = threading.get_ident()
        self.window = Window(window_size, self.title, self)
        self._make_render_objects()
        self._resized()

    def _make_render_objects(self):
        self.con = MjrContext(self.model, mjtFontScale.mjFONTSCALE_100)
        self.scene = MjvScene(self.model, 2 * MAX_GEOM)
        self.panels = _panels.load(self.model, self.data, *self.show_ui)

    def set_model(self, model, data):
        """Show another model (the managed loop's load): new context, scene, free camera."""
        with self.lock:
            if self.con is not None:
                self.con.free()
            self.model, self.data = model, data
            self.pert.select, self.pert.active = 0, 0
            self.cam = MjvCamera()
            mjv_defaultFreeCamera(model, self.cam)
            self.extra_count = 0
            self._make_render_objects()
            self._resized()

    @property
    def running(self):
        return not self._closing.is_set()

    def close(self):
        """Ask the render thread to close the window (safe from any thread, any time)."""
        self._closing.set()

    def destroy(self):
        """On the render thread, at the end: free the context and the window."""
        self._closing.set()
        self._drain_calls()
        if self.con is not None:
            self.con.free()
            self.con = None
        if self.window is not None:
            self.window.destroy()
            self.window = None

    # ------------------------------------------------------------ other threads

    def call(self, fn, timeout=10.0):
        """Run fn() on the render thread between frames; its result, or its exception."""
        if threading.get_ident() == self._thread:
            return fn()
        done, box = threading.Event(), {}
        self._calls.put((fn, done, box))
        if not done.wait(timeout):
            raise TimeoutError("the viewer's render thread did not answer "
                               f"within {timeout} s" + ("" if self.running else ": it closed"))
        if "error" in box:
            raise box["error"]
        return box.get("value")

    def _drain_calls(self):
        while True:
            try:
                fn, done, box = self._calls.get_nowait()
            except queue.Empty:
                return
            if self.running or self.window is not None:
                try:
                    box["value"] = fn()
                except Exception as error:   # noqa: BLE001  (raised again in the caller)
                    box["error"] = error
            else:
                box["error"] = RuntimeError("the viewer is closed")
            done.set()

    # ------------------------------------------------------------ the frame

    def frame(self):
        """One turn of the render loop: input, calls from other threads, draw, swap."""
        with self.lock:
            self.window.poll()
        if self.window.should_close():
            self._closing.set()
        self._drain_calls()
        if not self.running:
            return
        self.draw()
        self.window.swap()
        self.meter.tick(self.data.time)
        self._pace()

    def _pace(self):
        now = time.monotonic()
        self._next_frame = max(self._next_frame + FRAME_INTERVAL, now)
        if self._next_frame > now:
            time.sleep(self._next_frame - now)

    def viewport(self):
        """The 3D view: the window, less the panels when they are shown."""
        width, height = self.input.framebuffer_size
        rect = (self.panels.view_rect(self.input.state)
                if self.panels is not None and any(self.show_ui) else None)
        if rect is None:
            return MjrRect(0, 0, width, height)
        return MjrRect(rect.left, rect.bottom, rect.width, rect.height)

    def update_scene(self):
        """The scene of the data now, with the extra geoms after the model's."""
        with self.lock:
            mjv_updateScene(self.model, self.data, self.opt, self.pert, self.cam,
                            mjtCatBit.mjCAT_ALL, self.scene)
            scene = self.scene._ptr
            count = min(self.extra_count, scene.maxgeom - scene.ngeom)
            if count > 0:
                ffi.memmove(scene.geoms + scene.ngeom, self._extra, count * _GEOM_SIZE)
                scene.ngeom += count

    def draw(self):
        """Draw the scene, the panels and the overlays into the window's back buffer."""
        self.update_scene()
        viewport = self.viewport()
        mjr_setBuffer(mjtFramebuffer.mjFB_WINDOW, self.con)
        mjr_render(viewport, self.scene, self.con)
        if self.panels is not None and any(self.show_ui):
            self.panels.render(self.con)
        self._draw_overlays(viewport)
        self.user_overlays.draw(viewport, self.con)

    def _draw_overlays(self, viewport):
        if self.show_info:
            names, values = _overlay.info_text(self.data.time, self.meter, self.paused,
                                               self.scrub)
            mjr_overlay(mjtFont.mjFONT_NORMAL, mjtGridPos.mjGRID_BOTTOMLEFT, viewport,
                        names, values, self.con)
        if self.show_help:
            names, values = _overlay.help_text(self.managed)
            mjr_overlay(mjtFont.mjFONT_NORMAL, mjtGridPos.mjGRID_TOPLEFT, viewport,
                        names, values, self.con)
        if self.message:
            mjr_overlay(mjtFont.mjFONT_NORMAL, mjtGridPos.mjGRID_TOP, viewport,
                        self.message, None, self.con)

    def read_pixels(self):
        """The back buffer as a (height, width, 3) uint8 image, top row first."""
        width, height = self.input.framebuffer_size
        rgb = np.zeros((height, width, 3), dtype=np.uint8)
        mjr_readPixels(rgb, None, MjrRect(0, 0, width, height), self.con)
        return np.flipud(rgb)

    def capture(self):
        """A freshly drawn frame of the window, as an image (from any thread)."""
        def draw_and_read():
            self.draw()
            return self.read_pixels()
        return self.call(draw_and_read)

    # ------------------------------------------------------------ window events

    def _resized(self):
        self.input.resize(self.window.window_size(), self.window.framebuffer_size())
        if self.panels is not None:
            self.panels.resize(self.con, *self.input.framebuffer_size)

    def _to_panels(self):
        """Offer the event now in self.input to the panels; True when they consumed it
        (then what the user did there goes to action_handler)."""
        if self.panels is None or not any(self.show_ui):
            return False
        if not self.panels.event(self.input.state):
            return False
        for action in self.panels.take_actions():
            if self.action_handler is not None:
                self.action_handler(action)
        return True

    def on_resize(self, width, height):
        self._resized()
        self._to_panels()

    def on_key(self, key, scancode, action, mods):
        self.input.key(key, action, mods)
        if self._to_panels() or action == glfw.RELEASE:
            return
        if not self._builtin_key(key, mods) and self.key_handler is not None:
            self.key_handler(key, mods)
        if action == glfw.PRESS and self.key_callback is not None:
            try:
                self.key_callback(key)
            except Exception:         # noqa: BLE001  (reported; the viewer goes on)
                report(f"key_callback({key})")

    def _builtin_key(self, key, mods):
        """The viewer's own keys; True when `key` was one of them."""
        if mods & glfw.MOD_CONTROL:
            return False
        if key == glfw.KEY_LEFT_BRACKET:
            _interaction.cycle_camera(self, -1)
        elif key == glfw.KEY_RIGHT_BRACKET:
            _interaction.cycle_camera(self, +1)
        elif key == glfw.KEY_ESCAPE:
            _interaction.set_camera(self, -1)
        elif key == glfw.KEY_TAB:
            side = 1 if mods & glfw.MOD_SHIFT else 0
            self.show_ui[side] = not self.show_ui[side]
        elif key == glfw.KEY_F1:
            self.show_help = not self.show_help
        elif key == glfw.KEY_F2:
            self.show_info = not self.show_info
        else:
            return False
        return True

    def on_button(self, button, action, mods):
        state = self.input.state
        double = self.input.button(button, action, mods)
        if self._to_panels():
            return
        if action != glfw.PRESS:
            if not self.input.dragging:
                _interaction.stop_perturbation(self)
            return
        if double:
            self._double_click(button, bool(mods & glfw.MOD_CONTROL))
        else:
            _interaction.start_perturbation(self, state)

    def _double_click(self, button, control):
        view = self.viewport()
        width, height = max(1, view.width), max(1, view.height)
        relx = (self.input.state.x - view.left) / width
        rely = (self.input.state.y - view.bottom) / height
        if button == glfw.MOUSE_BUTTON_LEFT:
            _interaction.select(self, relx, rely, width / height)
        elif button == glfw.MOUSE_BUTTON_RIGHT:
            _interaction.centre(self, relx, rely, width / height, track=control)

    def on_move(self, x, y):
        dx, dy = self.input.move(x, y)
        if self._to_panels() or not self.input.dragging:
            return
        _interaction.drag(self, self.input.state, dx, dy, self.input.window_size[1])

    def on_scroll(self, sx, sy):
        self.input.scroll(sx, sy)
        if not self._to_panels():
            _interaction.zoom(self, sy)

    def on_drop(self, paths):
        self.input.drop(paths)
        if self.drop_handler is not None and paths:
            self.drop_handler(list(paths))
