"""The GLFW backend: the OpenGL context of an invisible GLFW window.

It needs a display: an X server (Xvfb on a machine without one: apt-get
install xvfb, then xvfb-run) or Wayland, and the `glfw` package from PyPI
(pip install 'mjcffi[glfw]'), which ships the GLFW library.  GLFW itself loads
libGL or libGLX, where MuJoCo's renderer then finds the OpenGL functions.

GLFW makes and destroys windows on the main thread only, so a GLContext is
made on the main thread (RuntimeError elsewhere); one freed on another thread
is destroyed at the next GLContext made or freed on the main thread.
`make_current()` works on any thread, one at a time.
"""

import os
import threading

try:
    import glfw
except ImportError as _error:
    raise ImportError("the GLFW backend needs the glfw package: pip install 'mjcffi[glfw]' "
                      f"(or pip install glfw) ({_error})") from _error

from . import _current
from ._base import GLContextBase

_pending: list = []              # windows freed off the main thread, destroyed later
_initialized = False


def _on_main_thread():
    return threading.current_thread() is threading.main_thread()


def _last_error():
    """GLFW's description of its last error on this thread."""
    _, description = glfw.get_error()
    return description.decode(errors="replace").strip() if description else "no reason given"


def _init():
    """Initialises GLFW once, or raises RuntimeError saying what is missing."""
    global _initialized
    if _initialized:
        return
    if not glfw.init():
        text = _last_error()
        hint = ""
        if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
            hint = ("  There is no display (DISPLAY is unset): run under Xvfb "
                    "(apt-get install xvfb; xvfb-run python ...), or use MUJOCO_GL=egl "
                    "or MUJOCO_GL=osmesa")
        raise RuntimeError(f"GLFW failed to initialise: {text}.{hint}")
    _initialized = True


def _destroy_pending():
    with _current.LOCK:          # another thread's free() may be appending
        while _pending:
            glfw.destroy_window(_pending.pop())


class GLContext(GLContextBase):
    """The OpenGL context of an invisible GLFW window.

    `GLContext(max_width, max_height)` on the main thread makes a hidden
    max_width x max_height window; `make_current()` before MuJoCo's mjr_*
    functions.  A context is current on one thread at a time; see
    `mjcffi.rendering._base`.
    """

    backend = "glfw"
    max_size = 16384

    def _create(self, width, height):
        if not _on_main_thread():
            raise RuntimeError("GLFW makes windows on the main thread only: make the "
                               "GLContext there (make_current() works on any thread)")
        _init()
        _destroy_pending()
        glfw.window_hint(glfw.VISIBLE, glfw.FALSE)
        try:
            window = glfw.create_window(width, height, "mjcffi", None, None)
        finally:
            glfw.window_hint(glfw.VISIBLE, glfw.TRUE)     # GLFW's default, for later windows
        if not window:
            raise RuntimeError(f"GLFW failed to make a window with an OpenGL context: "
                               f"{_last_error()}")
        return window

    def _bind(self):
        glfw.make_context_current(self._native)

    def _unbind(self):
        glfw.make_context_current(None)

    def _gl_handle(self, native):
        context = glfw.get_glx_context(native)       # a GLXContext: a ctypes pointer
        return int(getattr(context, "value", context) or 0)

    def _destroy(self, native):
        if _on_main_thread():
            _destroy_pending()
            glfw.destroy_window(native)
        else:
            _pending.append(native)
