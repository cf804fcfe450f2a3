"""MuJoCo's fatal errors (mju_error) as the Python exception FatalError.

Every MuJoCo function F has a guarded twin `lib.mjcffi_guard_F` (generated in
_guards.c) that catches mju_error on the calling thread instead of letting the
default handler end the process.  A guard of a void F returns 1 when it caught
an error (pass that to `check`); a guard of any other F returns a zero value,
so call `raise_pending` after it.  `lib.mjcffi_step(m, d, nstep)` steps like a
void guard, and returns 2 when a SIGINT stopped it early (see marshal.check_steps).
The error and its message belong to the calling thread only.

A call that writes an mjData holds it while it runs (mjcffi/_c/guard.c): the same
mjData in a call on another thread is a ValueError, and a callback restarting
the computation of the mjData it is called for (mj_step inside mjcb_control) a
RecursionError, both raised before MuJoCo runs.

After a FatalError out of a call that takes an mjData (mj_step, mj_forward,
...), that mjData is left mid-computation: MuJoCo did not release the stack
frames the call had marked, so its stack is smaller by what they held, and its
state is partly updated.  Call mj_resetData (or mj_resetDataKeyframe) before
using it again; it then steps exactly as a fresh mjData would.
"""

from .library import ffi, lib


class FatalError(Exception):
    """MuJoCo raised a fatal error (mju_error) inside a call.

    The message is MuJoCo's, e.g. "mj_stackAlloc: out of memory, ...".  The
    process goes on; an mjData that the call was computing must be reset with
    mj_resetData before it is used again.
    """


class ArgumentError(TypeError, ValueError):
    """An argument of the wrong type, dtype, shape, size or memory layout.

    A TypeError, as in the official bindings, and a ValueError, as mjcffi raised
    before it followed them.  The official message, where the official bindings
    have one of their own, is str(exc); the shape expected is in a note.
    """


class IdError(IndexError, ValueError):
    """An id argument out of range: an IndexError (as the official bindings raise
    for the ids they check), and a ValueError (as mjcffi raised before)."""


def with_note(error, note):
    """`error` with `note` attached (PEP 678): str(error) stays the official message,
    and tracebacks show our detail under it."""
    error.add_note(note)
    return error


def refusal(kind, text):
    """The exception for a call the C helper refused before MuJoCo ran (its mjData or
    its mjSpec held)."""
    if kind == lib.MJCFFI_ERROR_SPEC_BUSY:
        return with_note(RuntimeError(text), "MuJoCo's spec functions keep no lock: two "
                         "threads on one spec crash the process, so mjcffi refuses the second")
    if kind == lib.MJCFFI_ERROR_POOL_REENTRY:
        return with_note(RecursionError(text), "a pool (Rollout, Batch, MjSimPool) waits for "
                         "the callbacks its threads run, so they may not call it; give the "
                         "callback a pool of its own")
    if kind == lib.MJCFFI_ERROR_REENTRY:
        return with_note(RecursionError(text),
                         "a callback may read d and call functions that do not restart "
                         "its computation (mj_jac, mj_stackAllocNum, ...), but not step, "
                         "forward or reset the mjData that MuJoCo is computing")
    return with_note(ValueError(text), "mjcffi holds an mjData for each call that writes "
                     "it; MuJoCo's functions keep no lock of their own")


def taken_error(message):
    """The exception for an error whose message (a `const char *`) was taken already
    with mjcffi_take_error: FatalError, or the refusal of its kind."""
    text = ffi.string(message).decode("utf-8", "replace")
    kind = lib.mjcffi_error_kind()
    return FatalError(text) if kind == lib.MJCFFI_ERROR_FATAL else refusal(kind, text)


def raise_pending():
    """Raise FatalError if the last guarded call on this thread caught an error
    (RecursionError or ValueError if it refused to run: see refusal)."""
    message = lib.mjcffi_take_error()
    if message != ffi.NULL:
        text = ffi.string(message).decode("utf-8", "replace")
        kind = lib.mjcffi_error_kind()
        raise FatalError(text) if kind == lib.MJCFFI_ERROR_FATAL else refusal(kind, text)


def check(status):
    """Raise FatalError if `status`, the result of a void guard, says an error was caught."""
    if status:
        raise_pending()
        raise FatalError("MuJoCo raised a fatal error (its message was already taken)")
