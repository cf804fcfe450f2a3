"""The GLContext contract every backend shares.

`GLContext(max_width, max_height)`, `make_current()`, `as_current()`, `free()`,
as in the official bindings, with these rules made explicit:

- sizes are positive ints (TypeError, ValueError otherwise);
- after `free()` the context is spent: `make_current()` raises RuntimeError,
  and a second `free()` does nothing;
- a context is current on one thread at a time.  `make_current()` on a thread
  while another live thread holds the context raises RuntimeError.  A thread
  gives a context up by making another one current, by leaving
  `with ctx.as_current():` (which restores what was current before), by
  `free()`, or by ending.  `free()` from a thread other than the holder raises
  RuntimeError too: the holder may still be drawing with it.
- while a context is current on a thread, that thread keeps it alive, so
  dropping the last name for it frees it only once it is no longer current.

A backend implements `_create`, `_bind`, `_unbind` and `_destroy`.
"""

import contextlib
import threading

from .._support import mjr as _mjr
from . import _current
from ._sizes import pixels

_DESCRIPTION = {"egl": "EGL", "osmesa": "OSMesa", "glfw": "GLFW"}


class GLContextBase:
    """An OpenGL context for MuJoCo's renderer; subclasses bind one C library."""

    backend = ""                 # 'egl', 'osmesa' or 'glfw'
    max_size = 16384             # largest max_width/max_height the backend accepts

    def __init__(self, max_width, max_height):
        """Makes a context whose default framebuffer is max_width x max_height pixels.

        MuJoCo renders offscreen into its own framebuffer, sized by the model's
        visual.global_.offwidth/offheight; these sizes bound the window buffer.
        """
        self._native = None      # the C handle; None before creation and once freed
        self._thread = None      # ident of the thread it is current on, or None
        self._max_width = pixels(max_width, "max_width", self.max_size)
        self._max_height = pixels(max_height, "max_height", self.max_size)
        self._native = self._create(self._max_width, self._max_height)

    # --------------------------------------------------------- backend hooks

    def _create(self, width, height):
        """Makes the C context; returns its handle."""
        raise NotImplementedError

    def _bind(self):
        """Makes the C context current on this thread, or raises RuntimeError."""
        raise NotImplementedError

    def _unbind(self):
        """Leaves no context of this backend current on this thread."""
        raise NotImplementedError

    def _destroy(self, native):
        """Destroys the C context `native`, current on no thread."""
        raise NotImplementedError

    def _gl_handle(self, native):
        """The address that mjcffi_gl_current reports while `native` is current (the
        EGLContext, OSMesaContext or GLXContext), as an int; None if unknown."""
        return None

    def _thread_ended(self, ident):
        """The thread `ident` that held this context ends: release it there."""
        with _current.LOCK:
            if self._thread == ident:
                self._unbind()
                self._thread = None

    # ------------------------------------------------------------ public API

    def make_current(self):
        """Makes this context current on the calling thread; MuJoCo's mjr_* calls draw with it.

        Raises RuntimeError if the context has been freed, or is current on
        another thread that has not given it up.
        """
        ident = threading.get_ident()
        with _current.LOCK:
            self._check_usable(ident)
            self._bind()
            record = _current.slot()
            previous, record.context = record.context, self
            if previous is not None and previous is not self:
                previous._thread = None      # the C call above replaced it on this thread
            self._thread = ident
        del previous                         # may free it: outside the lock is enough

    @contextlib.contextmanager
    def as_current(self):
        """Makes this context current for a `with` block, then restores the previous one.

        With no context current before, none is after: the block releases this
        one, so that another thread may then make it current.
        """
        previous = _current.current()
        if previous is self:
            yield
            return
        try:
            self.make_current()        # inside the `try`: an interrupt cannot leave it held
            yield
        finally:
            if previous is not None and previous._native is not None:
                previous.make_current()
            else:
                self._release()

    def free(self):
        """Frees the C context now; later calls to make_current() raise RuntimeError.

        A second free() does nothing.  Raises RuntimeError if the context is
        current on another thread: free it there.
        """
        ident = threading.get_ident()
        with _current.LOCK:
            if self._native is None:
                return
            if self._thread not in (None, ident):
                raise RuntimeError(f"this GLContext is current on thread "
                                   f"{_current.thread_name(self._thread)}: free it there")
            held = self._release_locked(ident)
            native, self._native = self._native, None
            # MjrContexts made in it are lost, even if the driver reuses its address
            handle = self._gl_handle(native)
            if handle is not None:
                _mjr.forget_context(handle)
            self._destroy(native)
        del held

    def __del__(self):
        try:
            if getattr(self, "_native", None) is not None:
                self.free()
        except Exception:        # held by another thread, or interpreter shutdown: leave it
            pass

    def __repr__(self):
        size = f"{getattr(self, '_max_width', '?')}x{getattr(self, '_max_height', '?')}"
        return f"<{type(self).__module__}.{type(self).__qualname__} " \
               f"({_DESCRIPTION.get(self.backend, self.backend)}) {size}, {self._state()}>"

    # -------------------------------------------------------------- helpers

    def _state(self):
        if getattr(self, "_native", None) is None:
            return "freed"
        thread = self._thread
        if thread is None:
            return "not current"
        if thread == threading.get_ident():
            return "current on this thread"
        return f"current on thread {_current.thread_name(thread)}"

    def _check_usable(self, ident):
        if self._native is None:
            raise RuntimeError("this GLContext has been freed; make a new one")
        if self._thread not in (None, ident):
            raise RuntimeError(
                f"this GLContext is current on thread {_current.thread_name(self._thread)}; "
                "an OpenGL context is current on one thread at a time.  Give it up there "
                "first: make it current only inside `with ctx.as_current():`, make "
                "another context current, free() it, or end that thread")

    def _release(self):
        """Leaves this context current on no thread, if it is current on this one."""
        with _current.LOCK:
            held = self._release_locked(threading.get_ident())
        del held

    def _release_locked(self, ident):
        """As _release, under the lock; returns this thread's reference, to drop unlocked."""
        if self._thread != ident:
            return None
        self._unbind()
        self._thread = None
        record = _current.slot()
        held, record.context = record.context, None
        return held
