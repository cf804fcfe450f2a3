"""MuJoCo's functions as Python functions: `mjcffi.mj_step`, `mjcffi.mj_jac`, ...

Most are generated (mjcffi/_functions/, one module per section of mujoco.h); the few
whose documented Python signature differs from C are hand-written (`_overrides`, and
`_mjui` for the UI functions, whose item definitions need checking) and take their
place here, with the docstring in the generated ones' shape: the signature line, the
header's doc comment, then their own notes.  Every function has `prepare`
(mjcffi/_support/prepared.py).  `mjcffi` itself resolves a function name through this
package on first use.

Names resolve on first use, each importing only the module that defines it, so that a
process without .pyc files compiles only the functions it calls.
"""

import functools
import importlib

from .. import _functions
from .._support import prepared as _prepared

NAMES = _functions.NAMES
_NAMESET = frozenset(NAMES)
# these return the hand-written mjcffi.MjSpec rather than the generated struct class
_RETURNING_MJSPEC = frozenset(("mj_makeSpec", "mj_copySpec", "mj_parseXML",
                               "mj_parseXMLString", "mj_parse"))


def _document(function, name):
    """A hand-written function's docstring in the generated ones' shape: its
    signature line, the header's doc comment, then its own notes."""
    import inspect
    from . import _overrides
    header = _functions.HAND_WRITTEN_DOCS[name]
    own = inspect.cleandoc(function.__doc__ or "")
    function.__doc__ = (_overrides.SIGNATURES[name] + "\n\n" + header + "\n"
                        + ("\n" + own + "\n" if own else ""))
    return function


def _returning_mjspec(function):
    """`function`, returning mjcffi.MjSpec (with element lists, compile, delete...)
    rather than the generated struct class it wraps; its prepare binds the arguments
    (each call makes a new spec)."""
    @functools.wraps(function)
    def call(*args, **kwargs):
        from ..spec import MjSpec        # mjcffi.spec imports this layer
        return MjSpec._of(function(*args, **kwargs))
    call.prepare = _prepared.Preparer(call, None, True)
    return call


def __getattr__(name):
    if name not in _NAMESET:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    if name in _functions._MODULE_OF:
        value = getattr(_functions, name)
    else:
        overrides = importlib.import_module("._overrides", __name__)
        value = _document(getattr(overrides, name), name)
    if name in _RETURNING_MJSPEC:
        value = _returning_mjspec(value)
    globals()[name] = value              # the next lookup is a plain global
    return value


def __dir__():
    return sorted(set(globals()) | _NAMESET)


__all__ = list(NAMES)
