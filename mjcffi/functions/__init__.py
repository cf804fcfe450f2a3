"""MuJoCo's functions as Python functions: `mjcffi.mj_step`, `mjcffi.mj_jac`, ...

Most are generated (mjcffi/_functions.py); the few whose documented Python
signature differs from C are hand-written (`_overrides`, and `_mjui` for the UI
functions, whose item definitions need checking) and take their place here, with
the docstring in the generated ones' shape: the signature line, the header's doc
comment, then their own notes.  Every function has `prepare`
(mjcffi/_support/prepared.py).  `mjcffi` itself resolves a function name
through this package on first use.
"""

import functools
import inspect

from .. import _functions
from .._generated import funcinfo as _funcinfo
from . import _overrides
from .._support import prepared as _prepared

NAMES = tuple(_funcinfo.FUNCTIONS)


def _document(function, name):
    """A hand-written function's docstring in the generated ones' shape: its
    signature line, the header's doc comment, then its own notes."""
    header = _funcinfo.FUNCTIONS[name].doc
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


for _name in NAMES:
    if hasattr(_overrides, _name):
        globals()[_name] = _document(getattr(_overrides, _name), _name)
    else:
        globals()[_name] = getattr(_functions, _name)
for _name in ("mj_makeSpec", "mj_copySpec", "mj_parseXML", "mj_parseXMLString", "mj_parse"):
    globals()[_name] = _returning_mjspec(globals()[_name])
del _name

__all__ = list(NAMES)
