"""MuJoCo's simulation warnings as Python errors, on request.

MuJoCo counts warnings in `d.warning` (one MjWarningStat per mjtWarning:
`number` and `lastinfo`) and goes on.  As mujoco-py did, mjcffi can turn a
warning that a step raised into an exception instead:

    mjcffi.set_warnings_as_errors(True)
    mjcffi.mj_step(m, d)           # raises MjWarningError if a counter rose

    with mjcffi.ignore_warnings():
        mjcffi.mj_step(m, d)       # counts as usual, raises nothing

The switch is process-wide and off by default; `ignore_warnings` acts on the
calling thread only.  The check compares the counters before and after the
call (mj_step, including all of its `nstep` steps, and mj_forward), so the
data has already been stepped when the error is raised.  A bad qpos, qvel or
qacc makes MuJoCo reset the data, which zeroes the counters before counting
the new warning: a counter that was already 1 then still reads 1, and that
repeat goes unseen.  Reset the data after handling a warning (as after any
instability) and the next one is seen.
"""

import contextlib
import threading

from ._enums import mjtWarning
from ._library import ffi, lib

_NWARNING = int(mjtWarning.mjNWARNING)
_enabled = False
_local = threading.local()     # .ignoring: depth of ignore_warnings() on this thread


class MjWarningError(RuntimeError):
    """A MuJoCo warning was raised during a step while warnings are errors.

    `warning` is the mjtWarning, `info` MuJoCo's extra number for it (such
    as the index of the bad degree of freedom) and `count` how many times it
    was raised during the call.
    """

    def __init__(self, warning, info, count):
        self.warning, self.info, self.count = warning, info, count
        text = ffi.string(lib.mju_warningText(int(warning), info)).decode("utf-8", "replace")
        super().__init__(f"{warning.name}: {text}" + (f" ({count} times)" if count > 1 else ""))


def set_warnings_as_errors(enabled):
    """Make mj_step and mj_forward raise MjWarningError on new warnings (or stop)."""
    global _enabled
    if not isinstance(enabled, bool):
        raise TypeError(f"enabled must be a bool, not {type(enabled).__name__}")
    _enabled = enabled


def get_warnings_as_errors():
    """Whether new warnings raise MjWarningError (see set_warnings_as_errors)."""
    return _enabled


@contextlib.contextmanager
def ignore_warnings():
    """Within this block, on this thread, warnings are only counted, never raised."""
    _local.ignoring = getattr(_local, "ignoring", 0) + 1
    try:
        yield
    finally:
        _local.ignoring -= 1


def before_call(d):
    """The warning counts to compare after a call, or None when no check is due."""
    if not _enabled or getattr(_local, "ignoring", 0):
        return None
    return [d._ptr.warning[i].number for i in range(_NWARNING)]


def after_call(d, before):
    """Raise MjWarningError for the first warning whose count changed since `before`."""
    if before is None:
        return
    for i in range(_NWARNING):
        stat = d._ptr.warning[i]
        if stat.number != before[i]:
            new = stat.number - before[i] if stat.number > before[i] else stat.number
            raise MjWarningError(mjtWarning(i), stat.lastinfo, new)
