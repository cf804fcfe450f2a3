"""`WindowState`: the window's mouse and keyboard state, kept as MuJoCo's mjuiState.

The UI panels (mjui_event) read an mjuiState, so the viewer keeps one, in MuJoCo's
convention: framebuffer pixels, y up from the bottom edge, rect[0] the whole
window.  GLFW reports cursor positions in screen coordinates from the top edge;
`to_pixels` converts.  A second press of the same button within DOUBLECLICK
seconds is a double-click.  Modifiers are tracked from the events themselves
(the key of a modifier, or the `mods` GLFW passes with keys and buttons), so
synthetic events drive it exactly as real ones do.
"""

import time

import glfw

from .._generated.enums import mjtButton, mjtEvent
from ..structs import MjuiState

DOUBLECLICK = 0.3            # seconds between two presses of a double-click

_BUTTONS = {glfw.MOUSE_BUTTON_LEFT: mjtButton.mjBUTTON_LEFT,
            glfw.MOUSE_BUTTON_RIGHT: mjtButton.mjBUTTON_RIGHT,
            glfw.MOUSE_BUTTON_MIDDLE: mjtButton.mjBUTTON_MIDDLE}
_SHIFT = (glfw.KEY_LEFT_SHIFT, glfw.KEY_RIGHT_SHIFT)
_CONTROL = (glfw.KEY_LEFT_CONTROL, glfw.KEY_RIGHT_CONTROL)
_ALT = (glfw.KEY_LEFT_ALT, glfw.KEY_RIGHT_ALT)


class WindowState:
    """An mjuiState (`.state`) updated from GLFW events, plus the window's sizes."""

    def __init__(self):
        self.state = MjuiState()
        self.window_size = (1, 1)        # screen coordinates (cursor positions)
        self.framebuffer_size = (1, 1)   # pixels (drawing)
        self._cursor = (0.0, 0.0)        # last cursor position, screen coordinates

    # ------------------------------------------------------------ geometry

    def resize(self, window_size, framebuffer_size):
        self.window_size = tuple(max(1, int(v)) for v in window_size)
        self.framebuffer_size = tuple(max(1, int(v)) for v in framebuffer_size)
        rect = self.state.rect[0]
        rect.left, rect.bottom = 0, 0
        rect.width, rect.height = self.framebuffer_size
        self.state.nrect = max(1, self.state.nrect)
        self.state.type = mjtEvent.mjEVENT_RESIZE

    def to_pixels(self, x, y):
        """Screen coordinates from the top-left to framebuffer pixels from the bottom-left."""
        (ww, wh), (fw, fh) = self.window_size, self.framebuffer_size
        return x * fw / ww, (wh - y) * fh / wh

    def _mouserect(self):
        """The index of the last rect holding the cursor (0, the window, if none other)."""
        s = self.state
        for i in range(s.nrect - 1, 0, -1):
            r = s.rect[i]
            if r.left <= s.x < r.left + r.width and r.bottom <= s.y < r.bottom + r.height:
                return i
        return 0

    # ------------------------------------------------------------ modifiers

    def _set_mods(self, mods):
        s = self.state
        s.shift = int(bool(mods & glfw.MOD_SHIFT))
        s.control = int(bool(mods & glfw.MOD_CONTROL))
        s.alt = int(bool(mods & glfw.MOD_ALT))

    # ------------------------------------------------------------ events

    def key(self, key, action, mods):
        """A key event; modifier keys update the modifiers (GLFW's `mods` lags by one)."""
        s = self.state
        self._set_mods(mods)
        down = action != glfw.RELEASE
        if key in _SHIFT:
            s.shift = int(down)
        elif key in _CONTROL:
            s.control = int(down)
        elif key in _ALT:
            s.alt = int(down)
        s.type = mjtEvent.mjEVENT_KEY if down else mjtEvent.mjEVENT_NONE
        s.key = key if down else 0
        s.keytime = time.monotonic()

    def button(self, button, action, mods):
        """A button event; returns True for the press that completes a double-click."""
        s = self.state
        self._set_mods(mods)
        which = _BUTTONS.get(button, mjtButton.mjBUTTON_NONE)
        pressed = action == glfw.PRESS
        if button == glfw.MOUSE_BUTTON_LEFT:
            s.left = int(pressed)
        elif button == glfw.MOUSE_BUTTON_RIGHT:
            s.right = int(pressed)
        elif button == glfw.MOUSE_BUTTON_MIDDLE:
            s.middle = int(pressed)
        now = time.monotonic()
        double = False
        if pressed:
            double = s.button == which and now - s.buttontime < DOUBLECLICK
            s.button, s.buttontime = which, (0.0 if double else now)  # no triple-click
            s.mouserect = self._mouserect()
            s.dragbutton, s.dragrect = (which, s.mouserect)
        else:
            s.dragbutton = mjtButton.mjBUTTON_NONE
        s.doubleclick = int(double)
        s.type = mjtEvent.mjEVENT_PRESS if pressed else mjtEvent.mjEVENT_RELEASE
        s.dx = s.dy = 0
        return double

    def move(self, x, y):
        """A cursor move; returns (dx, dy) in screen coordinates (y down, GLFW's way)."""
        s = self.state
        dx, dy = x - self._cursor[0], y - self._cursor[1]
        self._cursor = (x, y)
        px, py = self.to_pixels(x, y)
        s.dx, s.dy = px - s.x, py - s.y
        s.x, s.y = px, py
        s.mouserect = self._mouserect()
        s.type = mjtEvent.mjEVENT_MOVE
        return dx, dy

    def place(self, x, y):
        """Set the cursor without a move event (at a press, the position GLFW reports)."""
        self._cursor = (x, y)
        self.state.x, self.state.y = self.to_pixels(x, y)

    def scroll(self, sx, sy):
        s = self.state
        s.sx, s.sy = sx, sy
        s.type = mjtEvent.mjEVENT_SCROLL

    def drop(self, paths):
        self.state.type = mjtEvent.mjEVENT_FILESDROP

    @property
    def dragging(self):
        s = self.state
        return bool(s.left or s.right or s.middle)
