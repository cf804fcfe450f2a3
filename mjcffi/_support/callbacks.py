"""MuJoCo's callbacks, the `mjcb_*` globals of mujoco.h, set from Python.

For each global `mjcb_foo` there is `set_mjcb_foo(callback)` and
`get_mjcb_foo()`, as in the official bindings.  `callback` is one of:

- a Python callable.  MuJoCo then calls a cffi `extern "Python"` trampoline
  (declared in _callbacks.h), which takes the GIL and calls it with the Python
  wrappers: `f(model, data, ...)`.  `model` and `data` are the very MjModel
  and MjData objects the program made, found by address in a registry of live
  wrappers (which model.py and data.py fill through `_track`; they also hand
  their classes down through `_register_class`, so that this module imports
  nothing from the layer above).  Memory that
  no live mjcffi wrapper owns (an mjData made by another binding, or by raw
  `lib` calls) arrives as a *borrowed* wrapper, made for this call only: it
  does not keep the memory alive, so do not keep it, or its arrays, after the
  callback returns.  Making one builds all its eager views: some 15 us per
  call, against about 0.2 us for finding a registered wrapper.
- a C function pointer: a cffi cdata of the global's function type (from
  `mjcffi.ffi` or from another cffi module declaring the same structs), or a
  ctypes function pointer (`CDLL` function or `CFUNCTYPE` object).  Its
  address is stored in the global itself, so MuJoCo calls it with no Python
  and no GIL in between (a `CFUNCTYPE` wrapping a Python function takes the
  GIL itself, through ctypes).  A cffi pointer of another function type is a
  TypeError; a ctypes signature cannot always be checked and is trusted.
  For a function of a cffi API-mode module, pass `ffi.addressof(lib, "f")`:
  `lib.f` itself is a Python callable, and would be called as one.
- None: the global is set back to NULL (MuJoCo's default behavior).

Anything else is a TypeError, with the official message as its text
("callback is not an Optional[Callable]") and what is accepted in a note.

While installed, the object is referenced here, so the memory behind a
trampoline, a `ffi.callback` or a `CFUNCTYPE` cannot go away; replacing or
clearing it drops that reference.  Do not replace a callback while another
thread is inside MuJoCo: a thread that has already read the old pointer could
still call it.

The globals belong to the one libmujoco of the process, shared with the
official bindings when both are imported: a callback set through either
binding runs under both, and `import mujoco` itself puts a timer of its own in
`mjcb_time`, which MuJoCo's profiler then calls dozens of times per step under
both bindings (`set_mjcb_time(None)` removes it).  `get_mjcb_foo()` only knows
what mjcffi installed: it returns that object while the global still holds it,
and None otherwise, whatever the global then holds.

The timer.  MuJoCo's profiler fills `d.timer` from mjcb_time; with the global
NULL (mjcffi's default) it counts calls but measures no time.  The official
bindings install a timer at import; mjcffi does not, because the profiler calls
it 32 times per step on a one-hinge pendulum (114 on the humanoid), which made
that step about 1.8 times as slow (some 620 ns more; about 2 % on the humanoid).
`install_timer()` installs mjcffi's own C timer (CLOCK_MONOTONIC, in seconds,
no Python and no GIL per call), with which `d.timer` durations are filled as
under the official bindings.

Exceptions.  A Python exception cannot cross MuJoCo's C frames.  When a Python
callback raises (or returns a value of the wrong type: a TypeError with the
official text, such as "mjcb_time callback did not return a number"), MuJoCo
receives a neutral value instead: nothing for the void callbacks, 0 ("keep this pair") for
mjcb_contactfilter, 0.0 for mjcb_time and mjcb_act_*.  The MuJoCo call goes
on to its end, calling the callback again as needed, and the *first* such
exception is stashed for the caller of that call; later ones are dropped.
mjcffi's functions re-raise it, with the callback's traceback, as soon as the
call returns (`raise_pending_callback_error`).  After raw `lib` calls, call
`raise_pending_callback_error()` yourself, or the exception comes out of the
next mjcffi call that checks.  (The official bindings abort the MuJoCo call at
the callback instead, leaving the mjData mid-step; here the call completes,
with the neutral values, and the state stays consistent.)

The caller of a call is found whichever thread ran the callback:
- on the calling thread itself: that thread;
- on the threads of `mjcffi.rollout` or of a `mjcffi.batch.Batch` call: the
  thread that made the call, which registers them for its duration (contract.scope);
- on the threads of an mjThreadPool bound to an mjData (`mju_threadpool`): the
  thread whose mjcffi call was on that mjData (the mjData the callback
  received, or for mjcb_time the only live mjData with a pool bound).
So each exception reaches exactly one caller, once, and never a later call.
(With several such calls running at once, an exception that came with no
mjData, from mjcb_time or mju_user_warning, goes to one of them; with several
mjData holding a pool, to the next call on one of them.)
A callback that re-enters MuJoCo (mj_step from mjcb_control on the same data)
works until Python's recursion limit is near, then raises RecursionError, which
reaches the outermost call like any other exception.
"""

import operator
import sys
import threading
import weakref

from . import contract as _contract
from .contract import raise_pending_callback_error  # noqa: F401  (mjcffi's public name)
from .errors import with_note
from .library import ffi, lib

__all__ = [
    "set_mjcb_passive", "get_mjcb_passive", "set_mjcb_control", "get_mjcb_control",
    "set_mjcb_contactfilter", "get_mjcb_contactfilter", "set_mjcb_sensor", "get_mjcb_sensor",
    "set_mjcb_time", "get_mjcb_time", "set_mjcb_act_dyn", "get_mjcb_act_dyn",
    "set_mjcb_act_gain", "get_mjcb_act_gain", "set_mjcb_act_bias", "get_mjcb_act_bias",
    "raise_pending_callback_error", "install_timer",
]


# ------------------------------------------------------- wrappers by address
#
# Root cdata -> weak reference to the owning MjModel / MjData wrapper.  cffi
# pointers hash and compare by address, so the `mjData *` a callback receives
# finds the gc-owned root of the wrapper.  An entry lives as long as its
# wrapper, and the wrapper keeps the root's memory alive: an address in here
# is never stale.

_MODELS: dict = {}
_DATAS: dict = {}
_CLASSES: dict = {}     # "mjModel" / "mjData" -> the wrapper class, for borrowed wrappers


def _register_class(cls):
    """The hook of mjcffi/model.py and mjcffi/data.py: `cls` wraps the pointers
    of its `_cname` that no live wrapper owns.  (This support module does not
    import the layer above: that layer hands its classes down.)"""
    _CLASSES[cls._cname] = cls
    return cls


def _track(wrapper):
    """Register a new owning MjModel or MjData so that callbacks receive it.

    The hook of mjcffi/model.py and mjcffi/data.py, called once per wrapper
    that owns its memory (`wrapper._root`).
    """
    registry = _DATAS if wrapper._cname == "mjData" else _MODELS
    key = wrapper._root

    def forget(ref):
        if registry.get(key) is ref:
            del registry[key]
    registry[key] = weakref.ref(wrapper, forget)


def _load_classes():
    """Make sure MjModel and MjData have registered, before a Python callable is
    installed: it may be called with pointers no mjcffi wrapper owns (an
    official binding's).  The package's public attributes load them."""
    if len(_CLASSES) < 2:
        package = sys.modules[__name__.partition(".")[0]]
        package.MjModel, package.MjData     # noqa: B018  (loading registers them)


_active = 0         # Python callbacks running (one inside the other, or on other threads)
_DEEP = 8           # beyond this many, each callback checks the room left on its stack
_ROOM = 60          # frames kept free for stashing and re-raising
_contract.set_pooled_datas(lambda: [root for root in list(_DATAS) if root.threadpool])


def _wrappers(m, d):
    """The MjModel and MjData wrappers of the pointers a callback received."""
    ref = _MODELS.get(m)
    model = ref() if ref is not None else None
    if model is None:
        model = _CLASSES["mjModel"]._wrap(m, m)     # borrowed: valid during this call only
    ref = _DATAS.get(d)
    data = ref() if ref is not None else None
    if data is None:
        data = _CLASSES["mjData"]._wrap(d, d, _model=model)
    return model, data


def _stasher(name):
    """The cffi `onerror` of a trampoline: a backstop for what the body did not catch."""
    def stash(kind, error, traceback):
        _contract.stash(name, error.with_traceback(traceback), None)
    return stash


def _room(name):
    """RecursionError when Python's recursion limit leaves fewer than _ROOM calls free.

    Measured by making them: a frame count would miss the C calls that also
    count (each trip through cffi and MuJoCo adds some).
    """
    try:
        _descend(_ROOM)
    except RecursionError:
        raise with_note(RecursionError("maximum recursion depth exceeded while calling a "
                                       "Python object"),
                        f"the Python {name} callback re-entered MuJoCo, one call inside "
                        f"the other, until Python's recursion limit was near") from None


def _descend(n):
    return n and _descend(n - 1)


# ---------------------------------------------------------------- the slots

_SLOTS: list = []


class _Slot:
    """One global function pointer of libmujoco (an mjcb_* callback, an mju_user_*
    handler): its type, its trampoline, what mjcffi put there.  A slot made with
    python=False takes C function pointers only (mju_user_malloc: a Python
    allocator could not hand MuJoCo memory that outlives the call safely)."""
    __slots__ = ("name", "ctype", "trampoline", "fn", "obj", "installed", "wraps")

    def __init__(self, name, python=True, wraps=True):
        self.name = name
        self.ctype = ffi.typeof(getattr(lib, name))
        self.trampoline = getattr(lib, "mjcffi_py_" + name) if python else None
        self.fn = None            # the Python callable the trampoline calls
        self.obj = None           # what the user gave, kept alive while installed
        self.installed = None     # the pointer written into the global
        self.wraps = wraps        # its callable receives MjModel and MjData wrappers
        _SLOTS.append(self)


def _attach(slot, trampoline):
    """Make `trampoline` the Python side of the slot's C trampoline."""
    ffi.def_extern("mjcffi_py_" + slot.name, onerror=_stasher(slot.name))(trampoline)
    return slot


# The trampolines.  Each counts the callbacks running, so that a callback
# re-entering MuJoCo raises RecursionError with room left to stash it (_room),
# and stashes what the callable raised: MuJoCo gets the neutral value.  If even
# stashing fails (at the recursion limit), the exception is kept in this
# thread's `lost` by statements that call nothing.

def _generic(name):
    slot = _Slot(name)

    def call(m, d):
        global _active
        fn = slot.fn
        if fn is None:
            return
        _active += 1
        try:
            if _active > _DEEP:
                _room(name)
            fn(*_wrappers(m, d))
        except BaseException as error:
            try:
                _contract.stash(name, error, d)
            except BaseException:
                if _contract.local.lost is None:      # calls nothing: see contract.py
                    _contract.local.lost = error
                    _contract.lost_count += 1
                    _contract.pending = True
        finally:
            _active -= 1
    return _attach(slot, call)


def _sensor(name):
    slot = _Slot(name)

    def call(m, d, stage):
        global _active
        fn = slot.fn
        if fn is None:
            return
        _active += 1
        try:
            if _active > _DEEP:
                _room(name)
            fn(*_wrappers(m, d), stage)
        except BaseException as error:
            try:
                _contract.stash(name, error, d)
            except BaseException:
                if _contract.local.lost is None:      # calls nothing: see contract.py
                    _contract.local.lost = error
                    _contract.lost_count += 1
                    _contract.pending = True
        finally:
            _active -= 1
    return _attach(slot, call)


def _contactfilter(name):
    slot = _Slot(name)

    def call(m, d, geom1, geom2):
        global _active
        fn = slot.fn
        if fn is None:
            return 0
        _active += 1
        try:
            if _active > _DEEP:
                _room(name)
            result = fn(*_wrappers(m, d), geom1, geom2)
            try:
                return 1 if operator.index(result) else 0
            except TypeError:
                raise with_note(TypeError(f"{name} callback did not return an integer"),
                                f"it returned {type(result).__name__}; an int, nonzero to "
                                f"discard the pair, is needed") from None
        except BaseException as error:
            try:
                _contract.stash(name, error, d)
            except BaseException:
                if _contract.local.lost is None:      # calls nothing: see contract.py
                    _contract.local.lost = error
                    _contract.lost_count += 1
                    _contract.pending = True
            return 0                      # keep the pair
        finally:
            _active -= 1
    return _attach(slot, call)


def _number(name, result):
    """`result` as MuJoCo's mjtNum: a number (__float__ or __index__), not a string."""
    if type(result) is float:
        return result
    if not isinstance(result, (str, bytes, bytearray)):
        try:
            return float(result)
        except (TypeError, ValueError):
            pass
    raise with_note(TypeError(f"{name} callback did not return a number"),
                    f"it returned {type(result).__name__}")


def _time(name):
    slot = _Slot(name, wraps=False)

    def call():
        global _active
        fn = slot.fn
        if fn is None:
            return 0.0
        _active += 1
        try:
            if _active > _DEEP:
                _room(name)
            return _number(name, fn())
        except BaseException as error:
            try:
                _contract.stash(name, error, None)
            except BaseException:
                if _contract.local.lost is None:      # calls nothing: see contract.py
                    _contract.local.lost = error
                    _contract.lost_count += 1
                    _contract.pending = True
            return 0.0
        finally:
            _active -= 1
    return _attach(slot, call)


def _actuator(name):
    slot = _Slot(name)

    def call(m, d, actuator):
        global _active
        fn = slot.fn
        if fn is None:
            return 0.0
        _active += 1
        try:
            if _active > _DEEP:
                _room(name)
            return _number(name, fn(*_wrappers(m, d), actuator))
        except BaseException as error:
            try:
                _contract.stash(name, error, d)
            except BaseException:
                if _contract.local.lost is None:      # calls nothing: see contract.py
                    _contract.local.lost = error
                    _contract.lost_count += 1
                    _contract.pending = True
            return 0.0
        finally:
            _active -= 1
    return _attach(slot, call)


def _message(name):
    """A mju_user_warning-style slot: handler(msg: str)."""
    slot = _Slot(name, wraps=False)

    def call(msg):
        global _active
        fn = slot.fn
        if fn is None:
            return
        _active += 1
        try:
            if _active > _DEEP:
                _room(name)
            fn(ffi.string(msg).decode("utf-8", "replace"))
        except BaseException as error:
            try:
                _contract.stash(name, error, None)
            except BaseException:
                if _contract.local.lost is None:      # calls nothing: see contract.py
                    _contract.local.lost = error
                    _contract.lost_count += 1
                    _contract.pending = True
        finally:
            _active -= 1
    return _attach(slot, call)


_PASSIVE = _generic("mjcb_passive")
_CONTROL = _generic("mjcb_control")
_CONTACTFILTER = _contactfilter("mjcb_contactfilter")
_SENSOR = _sensor("mjcb_sensor")
_TIME = _time("mjcb_time")
_ACT_DYN = _actuator("mjcb_act_dyn")
_ACT_GAIN = _actuator("mjcb_act_gain")
_ACT_BIAS = _actuator("mjcb_act_bias")
# the mjcb_* globals MuJoCo calls while it computes (a Batch refuses Python ones)
PHYSICS_SLOTS = (_PASSIVE, _CONTROL, _CONTACTFILTER, _SENSOR, _TIME, _ACT_DYN, _ACT_GAIN,
                 _ACT_BIAS)
# the mju_user_* handlers (their setters are in mjcffi/user_handlers.py): a Python warning
# handler, and C allocators only
USER_HANDLERS = {"mju_user_warning": _message("mju_user_warning"),
                 "mju_user_malloc": _Slot("mju_user_malloc", python=False),
                 "mju_user_free": _Slot("mju_user_free", python=False)}


def set_user_handler(name, handler):
    """Install `handler` in the mju_user_* global `name` (None restores the default)."""
    _set(USER_HANDLERS[name], handler)


def get_user_handler(name):
    """The mju_user_* handler `name` that mjcffi installed, while still installed."""
    return _get(USER_HANDLERS[name])


# ------------------------------------------------------ setting and getting

def _signature(ctype):
    """A function type as comparable data, whatever cffi module declared it
    (`struct mjModel_ *` in one, `mjModel *` in another)."""
    if ctype.kind == "function":
        return ("function", _signature(ctype.result), tuple(map(_signature, ctype.args)),
                ctype.ellipsis)
    if ctype.kind == "pointer":
        return ("pointer", _signature(ctype.item))
    if ctype.kind in ("struct", "union"):
        name = ctype.cname.split(" ")[-1]
        return (ctype.kind, name[:-1] if name.endswith("_") else name)
    return (ctype.kind, ctype.cname)


def _from_cffi(slot, pointer):
    ctype = ffi.typeof(pointer)
    if ctype is slot.ctype:
        return pointer
    if ctype.kind == "function" and _signature(ctype) == _signature(slot.ctype):
        return ffi.cast(slot.ctype, pointer)
    raise TypeError(f"{slot.name} needs a C function pointer of type {slot.ctype.cname}, "
                    f"not <cdata {ctype.cname}>")


def _from_ctypes(slot, function, ctypes):
    declared = function.argtypes
    if declared is not None and len(declared) != len(slot.ctype.args):
        raise TypeError(f"{slot.name} needs a C function of {len(slot.ctype.args)} arguments "
                        f"({slot.ctype.cname}), not {len(declared)}")
    return ffi.cast(slot.ctype, ctypes.cast(function, ctypes.c_void_p).value or 0)


def _set(slot, callback):
    fn = None
    ctypes = sys.modules.get("ctypes")     # a ctypes function means ctypes is loaded
    if callback is None:
        pointer = ffi.NULL
    elif isinstance(callback, ffi.CData):
        pointer = _from_cffi(slot, callback)
    elif ctypes is not None and isinstance(callback, ctypes._CFuncPtr):
        pointer = _from_ctypes(slot, callback, ctypes)
    elif callable(callback) and slot.trampoline is not None:
        if slot.wraps:
            _load_classes()
        pointer, fn = slot.trampoline, callback
        slot.fn = fn                       # before MuJoCo can reach the trampoline
    else:
        raise _refused(slot, callback)
    _contract.python_callbacks = True      # rollout and Batch claim from now on
    setattr(lib, slot.name, pointer)
    # only now that MuJoCo no longer sees the old one, let it go
    slot.fn, slot.obj = fn, callback
    slot.installed = None if callback is None else pointer
    _contract.python_callbacks = any(s.fn is not None for s in _SLOTS)


def _refused(slot, callback):
    """The TypeError for what `_set` cannot install: the official message, ours in a note."""
    if slot.trampoline is None:
        return with_note(TypeError(f"{slot.name} must be a C function pointer"),
                         f"got {type(callback).__name__}; pass a cffi pointer of type "
                         f"{slot.ctype.cname}, a ctypes CFUNCTYPE object, or None")
    return with_note(TypeError("callback is not an Optional[Callable]"),
                     f"{slot.name} takes a Python callable, a C function pointer (cffi, of type "
                     f"{slot.ctype.cname}, or ctypes) or None, not {type(callback).__name__}")


def _get(slot):
    if slot.obj is not None and getattr(lib, slot.name) == slot.installed:
        return slot.obj
    return None


def set_mjcb_passive(callback):
    """Install `callback(model, data)` as mjcb_passive (mjfGeneric); None clears it."""
    _set(_PASSIVE, callback)


def get_mjcb_passive():
    """The mjcb_passive that mjcffi installed, while still installed; else None."""
    return _get(_PASSIVE)


def set_mjcb_control(callback):
    """Install `callback(model, data)` as mjcb_control (mjfGeneric); None clears it."""
    _set(_CONTROL, callback)


def get_mjcb_control():
    """The mjcb_control that mjcffi installed, while still installed; else None."""
    return _get(_CONTROL)


def set_mjcb_contactfilter(callback):
    """Install `callback(model, data, geom1, geom2) -> int` as mjcb_contactfilter
    (mjfConFilt; nonzero discards the pair); None clears it."""
    _set(_CONTACTFILTER, callback)


def get_mjcb_contactfilter():
    """The mjcb_contactfilter that mjcffi installed, while still installed; else None."""
    return _get(_CONTACTFILTER)


def set_mjcb_sensor(callback):
    """Install `callback(model, data, stage)` as mjcb_sensor (mjfSensor); None clears it."""
    _set(_SENSOR, callback)


def get_mjcb_sensor():
    """The mjcb_sensor that mjcffi installed, while still installed; else None."""
    return _get(_SENSOR)


def set_mjcb_time(callback):
    """Install `callback() -> float` as mjcb_time (mjfTime); None clears it."""
    _set(_TIME, callback)


def get_mjcb_time():
    """The mjcb_time that mjcffi installed, while still installed; else None."""
    return _get(_TIME)


def install_timer() -> None:
    """Install mjcffi's C timer as mjcb_time, so that `d.timer` measures durations.

    The timer reads CLOCK_MONOTONIC in seconds, in C: MuJoCo's profiler calls
    it dozens of times per step with no Python and no GIL in between.  It is
    not installed by default, because those calls cost about 20 ns each (1.8
    times the step time on a one-hinge pendulum).  `set_mjcb_time(None)`
    removes it; `get_mjcb_time()` returns the pointer while it is installed.
    """
    _set(_TIME, ffi.addressof(lib, "mjcffi_timer"))


def set_mjcb_act_dyn(callback):
    """Install `callback(model, data, id) -> float` as mjcb_act_dyn (mjfAct); None clears it."""
    _set(_ACT_DYN, callback)


def get_mjcb_act_dyn():
    """The mjcb_act_dyn that mjcffi installed, while still installed; else None."""
    return _get(_ACT_DYN)


def set_mjcb_act_gain(callback):
    """Install `callback(model, data, id) -> float` as mjcb_act_gain (mjfAct); None clears it."""
    _set(_ACT_GAIN, callback)


def get_mjcb_act_gain():
    """The mjcb_act_gain that mjcffi installed, while still installed; else None."""
    return _get(_ACT_GAIN)


def set_mjcb_act_bias(callback):
    """Install `callback(model, data, id) -> float` as mjcb_act_bias (mjfAct); None clears it."""
    _set(_ACT_BIAS, callback)


def get_mjcb_act_bias():
    """The mjcb_act_bias that mjcffi installed, while still installed; else None."""
    return _get(_ACT_BIAS)
