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
qacc makes MuJoCo reset the data, which zeroes the counters; while warnings
are errors, the counts of the checked calls are added up instead, so every
warning of a call is seen, the repeat of an earlier one included.
"""

import contextlib
import threading

from ._generated.enums import mjtWarning
from ._support import contract as _contract
from ._support.library import ffi, lib

_NWARNING = int(mjtWarning.mjNWARNING)
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
    if not isinstance(enabled, bool):
        raise TypeError(f"enabled must be a bool, not {type(enabled).__name__}")
    _contract.warnings_as_errors = enabled


def get_warnings_as_errors():
    """Whether new warnings raise MjWarningError (see set_warnings_as_errors)."""
    return _contract.warnings_as_errors


@contextlib.contextmanager
def ignore_warnings():
    """Within this block, on this thread, warnings are only counted, never raised."""
    _local.ignoring = getattr(_local, "ignoring", 0) + 1
    try:
        yield
    finally:
        _local.ignoring -= 1


def before_call(d):
    """Start watching a call: take the counts out of `d`, or return None if no check is due.

    The counters are zeroed for the call and the old counts added back after,
    so a warning raised in the call shows as a non-zero count even when
    MuJoCo's auto-reset clears the counters and counts it again from zero.
    """
    if not _contract.warnings_as_errors or getattr(_local, "ignoring", 0):
        return None
    return take_counts(d)


def take_counts(d):
    """Zero the warning counters of `d` for a call; return the counts to add back."""
    warnings = d._ptr.warning
    before = [warnings[i].number for i in range(_NWARNING)]
    for i in range(_NWARNING):
        warnings[i].number = 0
    return before


def restore(d, before):
    """Add the counts taken by before_call back into `d`; return the call's own counts."""
    warnings = d._ptr.warning
    new = [warnings[i].number for i in range(_NWARNING)]
    for i in range(_NWARNING):
        warnings[i].number = before[i] + new[i]
    return new


def after_call(d, before, error=None):
    """Put the earlier counts back, then raise `error` (MjWarningError by default)
    for a warning of the call.

    If the call itself raised, call `restore` instead, so the counts are kept.
    """
    if before is None:
        return
    new = restore(d, before)
    for i in range(_NWARNING):
        if new[i]:
            raise (error or MjWarningError)(mjtWarning(i), d._ptr.warning[i].lastinfo, new[i])
