"""MuJoCo's user handlers, the `mju_user_*` globals of mujoco.h, set from Python.

As in the official bindings there is `set_mju_user_foo(handler)` and
`get_mju_user_foo()` for

- mju_user_warning, `void (*)(const char* msg)`: the legacy warning handler,
  called with each warning's text (e.g. "Nan, Inf or huge value in QPOS at DOF
  0. ...") by MuJoCo's default log handler, instead of printing it.  It takes a
  Python callable `f(msg: str)`, a C function pointer, or None.
- mju_user_malloc, `void* (*)(size_t)`, and mju_user_free, `void (*)(void*)`:
  the allocator behind mju_malloc and mju_free (mj_makeData, mjv_makeScene, ...).
  They take C function pointers only, as in the official bindings: a cffi
  pointer of the global's type, or a ctypes `CFUNCTYPE` object (which may wrap
  a Python function; ctypes then takes the GIL per call).  Install both or
  neither, and put back the old pair only once nothing the new one allocated
  is left: memory is freed by the free that is installed when it goes.

None puts MuJoCo's default back (the global set to NULL).  The handlers follow
the rules of mjcffi/_support/callbacks.py: the installed object is kept alive while it is
installed, `get_*` returns it only while the global still holds it
(mju_clearHandlers resets them all), and an exception raised in a Python
warning handler is raised again when the MuJoCo call that warned returns.
These globals belong to the one libmujoco of the process, shared with the
official bindings when both are imported.

mju_user_error is not offered: mjcffi turns every mju_error into FatalError
through a thread-local log handler, which MuJoCo consults before it.
"""

from typing import Any, Callable, Optional

from ._support import callbacks as _cb

__all__ = [
    "set_mju_user_warning", "get_mju_user_warning",
    "set_mju_user_malloc", "get_mju_user_malloc",
    "set_mju_user_free", "get_mju_user_free",
]


def set_mju_user_warning(handler: Optional[Callable[[str], Any]]) -> None:
    """Install `handler(msg: str)` as mju_user_warning; None restores the default."""
    _cb.set_user_handler("mju_user_warning", handler)


def get_mju_user_warning() -> Optional[Callable[..., Any]]:
    """The mju_user_warning that mjcffi installed, while still installed; else None."""
    return _cb.get_user_handler("mju_user_warning")


def set_mju_user_malloc(handler: Any) -> None:
    """Install a C function `void* (size_t)` as mju_user_malloc; None restores malloc."""
    _cb.set_user_handler("mju_user_malloc", handler)


def get_mju_user_malloc() -> Any:
    """The mju_user_malloc that mjcffi installed, while still installed; else None."""
    return _cb.get_user_handler("mju_user_malloc")


def set_mju_user_free(handler: Any) -> None:
    """Install a C function `void (void*)` as mju_user_free; None restores free."""
    _cb.set_user_handler("mju_user_free", handler)


def get_mju_user_free() -> Any:
    """The mju_user_free that mjcffi installed, while still installed; else None."""
    return _cb.get_user_handler("mju_user_free")
