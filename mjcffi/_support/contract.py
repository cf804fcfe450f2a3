"""The run-time error contract: what every mjcffi call checks when MuJoCo returns.

A MuJoCo call can end in three ways besides success, each checked right after it:

- MuJoCo raised a fatal error (mju_error), or mjcffi refused the call before MuJoCo
  ran (its mjData held by another call): the guard's status says so, and
  `raise_pending` (mjcffi/_support/errors.py, re-exported here) raises FatalError,
  or `refusal(kind, text)`'s RecursionError or ValueError;
- a Python callback raised: a Python exception cannot cross MuJoCo's C frames, so
  the callback's trampoline (mjcffi/_support/callbacks.py) calls `stash`, MuJoCo
  gets a neutral value and goes on, and the call's caller, seeing `pending`, calls
  `raise_stashed`, which raises the first exception stashed for it;
- a MuJoCo warning, while `warnings_as_errors` is on (mjcffi/warning_errors.py
  sets it): mj_step and mj_forward raise MjWarningError.

The flags are module attributes, read on every call (a few ns), and written only
here, by callbacks.py and by warning_errors.py:

- `pending`: an exception may be stashed, for some caller;
- `python_callbacks`: a Python callable is installed in some mjcb_* slot (rollout,
  Batch and MjSimPool then claim the exceptions of their worker threads: `scope`);
- `warnings_as_errors`: mjcffi.set_warnings_as_errors(True) is on.

At Python's recursion limit even `stash` cannot run: a trampoline then keeps the
exception in `local.lost`, counts it in `lost_count` and sets `pending`, with
statements that call nothing.

Who a stashed exception is for, whichever thread ran the callback:
- on the calling thread itself: that thread;
- on the threads of rollout or of a Batch call: the thread that made the call,
  which claims them for its duration (`scope`);
- on the threads of an mjThreadPool bound to an mjData: the thread whose mjcffi
  call is on that mjData (found in the mjcffi frames above `raise_stashed`).

Support module: imports only the compiled module and errors.py.
"""

import itertools
import sys
import threading

from .errors import raise_pending, refusal, with_note  # noqa: F401  (re-exported)
from .library import ffi

pending = False               # an exception may be stashed (the fast paths read it)
python_callbacks = False      # a Python callable is installed in some mjcb_* slot
warnings_as_errors = False    # mjcffi.set_warnings_as_errors(True) is on


# _errors maps the caller an exception is for to (order, exception), the first
# stashed for it:
# - a threading.Thread: raised on it, or on threads working for it (scope);
# - an int, the address of an mjData: raised on a thread no scope claims (an
#   mjThreadPool's), for the thread whose mjcffi call is on that mjData;
# - None: raised on such a thread with no mjData to go by.

_lock = threading.Lock()
_errors: dict = {}
_order = itertools.count()     # which exception came first, when one call finds several
# [owner thread, set of mjData addresses or None: all]; changed only by list.append and
# list.remove, each one step under the GIL, so that a caller's `finally` can release its
# claim with no bytecode before the call that could raise (a KeyboardInterrupt)
_scopes: list = []
scopes = _scopes
_Foreign = getattr(threading, "_DummyThread", ())    # threads Python did not start


class _Local(threading.local):
    lost = None     # an exception stash() could not take (at the recursion limit)


local = _Local()
lost_count = 0      # threads with a `lost` exception


def _no_pools():
    return []


_pooled_datas = _no_pools   # the live mjData with a thread pool bound (set_pooled_datas)


def set_pooled_datas(find):
    """The hook of mjcffi/_support/callbacks.py, which keeps the registry of live MjData:
    `find()` gives the mjData roots that have a thread pool bound."""
    global _pooled_datas
    _pooled_datas = find


def raise_pending_callback_error():
    """Raise the exception a Python callback stashed for this caller, if any.

    mjcffi's functions call this after each MuJoCo call that can run
    callbacks; call it yourself after raw `lib` calls (from the frame that
    holds the MjData, for a callback that ran on a thread pool bound to it).
    With nothing pending it costs one test of a module flag.
    """
    if pending:
        _raise(_take(sys._getframe(1)))


def raise_stashed():
    """raise_pending_callback_error for mjcffi's own functions, which call it when
    `pending` is set."""
    _raise(_take(sys._getframe(1)))


def _raise(error):
    if error is not None:
        try:
            raise error
        finally:
            error = None          # no cycle through this frame


def _take(frame=None):
    """The first exception stashed for the caller at `frame` (its caller's by default).

    That is this thread's, and those stashed on pool threads for an mjData
    that the mjcffi frames above `frame` (and `frame` itself) were called with.
    The others found with it came later in the same call: they are dropped.
    """
    global pending, lost_count
    thread = threading.current_thread()
    lost = local.lost
    if lost is not None:
        local.lost = None
    if any(key.__class__ is int or key is None for key in list(_errors)):
        addresses, pooled = _datas_of(frame if frame is not None else sys._getframe(1))
    else:
        addresses, pooled = (), False
    with _lock:
        found = [_errors.pop(key) for key in (thread, *addresses) if key in _errors]
        if pooled and None in _errors:
            found.append(_errors.pop(None))
        for ended in [t for t in _errors if isinstance(t, threading.Thread) and
                      not t.is_alive()]:
            del _errors[ended]    # nobody is left to raise these in
        if lost is not None:
            lost_count -= 1
        pending = bool(_errors) or lost_count > 0
    if lost is not None:
        return lost               # the deepest call's: the first
    return min(found, key=lambda entry: entry[0])[1] if found else None


def _datas_of(frame):
    """The addresses of the mjData that `frame` and the mjcffi frames above it hold,
    and whether one has a thread pool bound."""
    addresses, pooled = set(), False
    package = __name__.partition(".")[0]      # mjcffi: its frames hold the mjData
    for _ in range(6):
        if frame is None:
            break
        for value in frame.f_locals.values():
            if isinstance(value, ffi.CData):
                pointer = value
            elif getattr(value.__class__, "_cname", None) == "mjData":
                pointer = getattr(value, "_ptr", None)
            else:
                continue
            try:
                if ffi.typeof(pointer) is not _DATA_POINTER:
                    continue
            except TypeError:
                continue
            addresses.add(int(ffi.cast("uintptr_t", pointer)))
            pooled = pooled or bool(pointer.threadpool)
        frame = frame.f_back
        if frame is None or not frame.f_globals.get("__name__", "").startswith(package):
            break
    return addresses, pooled


_DATA_POINTER = ffi.typeof("mjData *")


def stash(name, error, data):
    """Keep `error`, raised in the Python `name` callback with mjData `data` (or None),
    for its caller."""
    global pending
    note = (f"(raised in the Python {name} callback, inside a MuJoCo call; "
            f"mjcffi re-raised it when that call returned)")
    thread = threading.current_thread()
    key = _owner(data) if isinstance(thread, _Foreign) else thread
    with _lock:
        first = key not in _errors
    if not first:
        return
    if note not in getattr(error, "__notes__", ()):
        with_note(error, note)
    with _lock:
        _errors.setdefault(key, (next(_order), error))
        pending = True


def _owner(data):
    """Who an exception raised on a thread Python did not start is for (see _errors)."""
    address = None if data is None else int(ffi.cast("uintptr_t", data))
    scopes = list(_scopes)
    for owner, addresses in scopes:
        if addresses is not None and address in addresses:
            return owner
    for owner, addresses in scopes:
        if addresses is None:
            return owner          # a Batch: its mjData are its own
    if scopes and address is None:
        return scopes[0][0]
    if address is not None:
        return address
    pooled = _pooled_datas()
    return int(ffi.cast("uintptr_t", pooled[0])) if len(pooled) == 1 else None


def claim(datas=None):
    """A claim, for the calling thread, of the exceptions of callbacks that run on
    threads working for it (those of rollout or a Batch): on `datas` (C pointers),
    or any (None).  Nothing is claimed until it is in `scopes`: the caller appends
    it inside its `try` and, in the `finally`, removes it if it is there."""
    return [threading.current_thread(),
            None if datas is None else {int(ffi.cast("uintptr_t", d)) for d in datas}]


def scope(datas=None):
    """Put a new claim (see `claim`) in force until `unscope`; returns it.  A
    KeyboardInterrupt inside leaves nothing in force."""
    new = claim(datas)
    try:
        _scopes.append(new)
    except BaseException:
        if new in _scopes:
            _scopes.remove(new)
        raise
    return new


def unscope(claim):
    """End a claim of `scope` (nothing if it is no longer in force)."""
    if claim in _scopes:
        _scopes.remove(claim)
