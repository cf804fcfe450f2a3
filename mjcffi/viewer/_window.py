"""`Window`: a visible GLFW window with an OpenGL context, its events turned into calls.

GLFW is used from one thread per window: the thread that makes the window
polls its events, draws into it and destroys it (the viewer's own thread in
passive mode, the caller's thread in managed mode).  On X11 that thread need not
be the main thread.  Each GLFW callback is forwarded to a method of `listener`
(`on_key`, `on_button`, `on_move`, `on_scroll`, `on_resize`, `on_drop`); an
exception there is printed with its traceback and the window carries on, since
GLFW's C code cannot take a Python exception.
"""

import sys
import traceback

try:
    import glfw
except ImportError as _error:
    raise ImportError("the viewer needs the glfw package: pip install 'mjcffi[glfw]' "
                      f"(or pip install glfw) ({_error})") from _error

from .._support import mjr as _mjr


def report(what):
    """Print the exception being handled, with its traceback, naming `what` raised it."""
    print(f"mjcffi.viewer: {what} raised an exception:", file=sys.stderr)
    traceback.print_exc()
    sys.stderr.flush()


def _init():
    """Initialise GLFW (a no-op when already done), or raise RuntimeError saying why."""
    if not glfw.init():
        _, description = glfw.get_error()
        text = description.decode(errors="replace") if description else "no reason given"
        raise RuntimeError(f"GLFW failed to initialise: {text}.  The viewer needs a display "
                           "(DISPLAY or WAYLAND_DISPLAY); without one run under Xvfb "
                           "(xvfb-run python ...)")


class Window:
    """A visible GLFW window whose OpenGL context is current on the thread that made it."""

    def __init__(self, size, title, listener, samples=4):
        """size: a function () -> (width, height), asked once GLFW is initialised."""
        _init()
        width, height = size()
        glfw.default_window_hints()
        glfw.window_hint(glfw.SAMPLES, samples)      # antialiasing, as MuJoCo's offscreen buffer
        glfw.window_hint(glfw.VISIBLE, glfw.TRUE)
        self._handle = glfw.create_window(int(width), int(height), title, None, None)
        if not self._handle:
            _, description = glfw.get_error()
            raise RuntimeError("GLFW failed to make the viewer window: "
                               f"{description.decode(errors='replace') if description else '?'}")
        glfw.make_context_current(self._handle)
        glfw.swap_interval(1)
        self._gl_handle = int(getattr(glfw.get_glx_context(self._handle), "value", 0) or 0) \
            if sys.platform.startswith("linux") else 0
        self._listener = listener
        self._callbacks = self._connect()

    # ------------------------------------------------------------ events

    def _guarded(self, name):
        """A GLFW callback that forwards to listener.`name`, reporting its exceptions."""
        method = getattr(self._listener, name)

        def callback(_window, *args):
            try:
                method(*args)
            except Exception:         # noqa: BLE001  (GLFW's C caller cannot take it)
                report(f"the viewer's {name} handler")
        return callback

    def _connect(self):
        """Install the callbacks; keep them referenced so they outlive this call."""
        callbacks = {
            glfw.set_key_callback: self._guarded("on_key"),
            glfw.set_mouse_button_callback: self._guarded("on_button"),
            glfw.set_cursor_pos_callback: self._guarded("on_move"),
            glfw.set_scroll_callback: self._guarded("on_scroll"),
            glfw.set_framebuffer_size_callback: self._guarded("on_resize"),
            glfw.set_drop_callback: self._guarded("on_drop"),
        }
        for install, callback in callbacks.items():
            install(self._handle, callback)
        return callbacks

    def poll(self):
        """Process pending events: the callbacks run now, on this thread."""
        glfw.poll_events()

    # ------------------------------------------------------------ queries

    def should_close(self):
        return bool(glfw.window_should_close(self._handle))

    def request_close(self):
        glfw.set_window_should_close(self._handle, True)

    def framebuffer_size(self):
        """(width, height) of the drawable area in pixels."""
        return glfw.get_framebuffer_size(self._handle)

    def window_size(self):
        """(width, height) in screen coordinates, those of cursor positions."""
        return glfw.get_window_size(self._handle)

    def modifiers(self):
        """(shift, control, alt) held now."""
        def held(*keys):
            return any(glfw.get_key(self._handle, k) == glfw.PRESS for k in keys)
        return (held(glfw.KEY_LEFT_SHIFT, glfw.KEY_RIGHT_SHIFT),
                held(glfw.KEY_LEFT_CONTROL, glfw.KEY_RIGHT_CONTROL),
                held(glfw.KEY_LEFT_ALT, glfw.KEY_RIGHT_ALT))

    def set_title(self, title):
        glfw.set_window_title(self._handle, title)

    # ------------------------------------------------------------ drawing

    def swap(self):
        glfw.swap_buffers(self._handle)

    def destroy(self):
        """Destroy the window and its context (on the thread that made it)."""
        if self._handle is None:
            return
        glfw.make_context_current(None)
        if self._gl_handle:
            _mjr.forget_context(self._gl_handle)   # MjrContexts made in it are now lost
        glfw.destroy_window(self._handle)
        self._handle = None
        glfw.poll_events()            # let the X server see the window go
