"""mujoco-py's error and warning callbacks: set_error_callback, set_warning_callback,
wrap_mujoco_warning and handle_fatal.

In mjcffi an mju_error never ends the process: it comes out of the call as
mjcffi.FatalError.  mujoco-py's error callback is honoured where that error
reaches mjcffi.sim (mjcffi.sim.functions, MjSim, a wrap_mujoco_warning block):
`handle_fatal(error)` calls it with the message as bytes, as mujoco-py did, and
whatever it raises goes on; if it returns, the error counts as handled.

The warning callback receives each MuJoCo warning's text as bytes, through
mju_user_warning (mjcffi.user_handlers); an exception it raises comes out of the
MuJoCo call that warned, as soon as that call returns.
"""

import contextlib

from .._support import callbacks as _callbacks
from .. import user_handlers as _handlers
from .._support.errors import FatalError

_error_callback = None
_warning_callback = None


def set_error_callback(fn):
    """Call `fn(message: bytes)` for each MuJoCo fatal error that reaches mjcffi.sim.

    None removes it: the FatalError is then raised as it is."""
    global _error_callback
    _error_callback = _checked(fn, "error")


def get_error_callback():
    """The function set_error_callback installed, or None."""
    return _error_callback


def set_warning_callback(fn):
    """Call `fn(message: bytes)` for each MuJoCo warning (mju_user_warning); None removes it."""
    global _warning_callback
    fn = _checked(fn, "warning")
    _handlers.set_mju_user_warning(None if fn is None else _as_bytes(fn))
    _warning_callback = fn


def get_warning_callback():
    """The function set_warning_callback installed, or None."""
    return _warning_callback


def handle_fatal(error):
    """Give `error` (a mjcffi.FatalError) to the error callback, as bytes, and return.

    What the callback raises goes on; with no callback, `error` itself is raised."""
    fn = _error_callback
    if fn is None:
        raise error
    fn(str(error).encode("utf-8"))


@contextlib.contextmanager
def wrap_mujoco_warning():
    """A block of MuJoCo calls as mujoco-py wrapped them.

    A FatalError leaving the block goes to handle_fatal (the error callback, if set),
    and an exception a callback raised but no mjcffi call reported yet (after raw
    `lib` calls) is raised at the end of the block."""
    try:
        yield
    except FatalError as error:
        handle_fatal(error)
    _callbacks.raise_pending_callback_error()


def _checked(fn, what):
    if fn is not None and not callable(fn):
        raise TypeError(f"the {what} callback must be callable or None, not {type(fn).__name__}")
    return fn


def _as_bytes(fn):
    """mju_user_warning's handler, with mujoco-py's bytes for the message."""
    def warning(message):
        fn(message.encode("utf-8"))
    warning.__wrapped__ = fn
    return warning
