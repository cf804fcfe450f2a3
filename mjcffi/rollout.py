"""Open-loop rollouts from initial states: the states and sensor values that follow.

The same interface as the official `mujoco.rollout`:

    from mjcffi import rollout
    state, sensordata = rollout.rollout(model, data, initial_state, control)
    with rollout.Rollout(nthread=2) as pool:
        state, sensordata = pool.rollout(model, [d0, d1], initial_state, control)

The loop runs in C (mjcffi/_c/rollout.c) with the GIL released.  Each rollout
sets its initial state (mjSTATE_FULLPHYSICS) and qacc_warmstart, resets the
inputs that `control_spec` leaves out, then before each step sets its controls
with mj_setState(control_spec), calls mj_step and records mj_getState and
sensordata.  Given several MjData (one per thread), chunks of rollouts go to
a pool of threads that persists for the life of a `Rollout`; the calling
thread works as one of them.

A rollout diverges when a MuJoCo warning is raised in it (a bad control, a
bad qacc, ...): the rest of its trajectory repeats its last state and sensor
values, so a time that stops increasing marks it.  A rollout in which MuJoCo
raises a fatal error (mju_error) fails alone: its data is reset, the rest of
its trajectory from the failed step on is NaN, the other rollouts complete,
and the call then raises `mjcffi.FatalError` with MuJoCo's message (of the
first failed rollout) and the failed indices in its `failed` attribute.
"""

import atexit
import operator
import os
import threading
import weakref

import numpy as np

from ._support import contract as _contract, interrupt as _interrupt, marshal as _marshal
from ._support import official as _official, stack as _stack
from ._generated.enums import mjtState
from ._support.errors import FatalError, raise_pending, with_note
from ._support.library import ffi, lib

__all__ = ["Rollout", "rollout", "shutdown_persistent_pool"]

_DTYPE = np.dtype(np.float64)
_FULLPHYSICS = int(mjtState.mjSTATE_FULLPHYSICS)
_USER = int(mjtState.mjSTATE_USER)
_CTRL = int(mjtState.mjSTATE_CTRL)
_MESSAGE_SIZE = 2048
_INT_MAX = 2**31 - 1
_MAX_THREADS = 4096      # the most threads a Rollout starts (its nthread)
_REFUSED, _INTERRUPTED = -1, -2   # what mjcffi_rollout returns besides a count (rollout.h)


class Rollout:
    """A pool of threads for parallel rollouts, kept between calls.

    `Rollout(nthread=n)` takes n MjData per call, one per thread; the calling
    thread is one of the n, so n - 1 threads are started.  With nthread 0
    (the default) the rollouts run on the calling thread with one MjData.
    Use it as a context manager, or call `close()`.  Calls on one pool from
    several Python threads run one after the other.
    """

    def __init__(self, *, nthread=None):
        """Start a pool of `nthread` threads (0 or None: none, roll out on the calling thread)."""
        nthread = 0 if nthread is None else _integer(nthread, "nthread", TypeError)
        if nthread < 0:
            raise ValueError(f"nthread must be non-negative, got {nthread}")
        if nthread > _MAX_THREADS:
            raise ValueError(f"nthread must be at most {_MAX_THREADS}, got {nthread}")
        self.nthread = nthread
        self._pool = self._start()
        self._open = True
        self._callers = set()      # the threads in a call on this pool now
        _live.add(self)

    def _start(self):
        """A new C pool (NULL below 2 threads: the caller works alone)."""
        if self.nthread < 2:
            return ffi.NULL
        pool = lib.mjcffi_rollout_pool_new(self.nthread)
        if pool == ffi.NULL:
            raise with_note(ValueError(f"nthread={self.nthread}: the system could not start "
                                       f"the {self.nthread - 1} threads of a rollout pool"),
                            f"mjcffi allows up to {_MAX_THREADS}; the system's limit (ulimit "
                            "-u, memory) was lower here")
        return ffi.gc(pool, lib.mjcffi_rollout_pool_free)

    def _forked(self):
        """In a child process: fork copied the pool but not its threads, so start anew."""
        if self._pool != ffi.NULL:
            ffi.gc(self._pool, None)     # never join threads that live in the parent
            self._pool = self._start() if self._open else ffi.NULL

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc_val, exc_tb):
        self.close()

    def close(self):
        """Shut the pool down; its threads end once no call is using them."""
        self._open = False
        self._pool = ffi.NULL      # the last reference frees the pool and joins its threads

    def rollout(self, model, data, initial_state, control=None, *,
                control_spec=_CTRL, skip_checks=False, nstep=None, initial_warmstart=None,
                state=None, sensordata=None, chunk_size=None):
        """Roll out open-loop trajectories; get the states and sensor values that follow.

        Infers nbatch and nstep, repeats inputs whose leading dimensions are 1,
        and allocates the outputs that are not given.

        Args:
          model: an MjModel, or a sequence of nbatch MjModels of the same sizes.
          data: an MjData, or a sequence of them, one per thread (nthread of them).
          initial_state: initial states, ([nbatch or 1] x nstate), where
            nstate = mj_stateSize(model, mjSTATE_FULLPHYSICS).
          control: open-loop controls, ([nbatch or 1] x [nstep or 1] x ncontrol),
            where ncontrol = mj_stateSize(model, control_spec); optional.
          control_spec: the mjtState bits (within mjSTATE_USER) that `control` sets.
          skip_checks: take the arrays as given: no inference, repetition or
            allocation (`model` and `data` are lists, `nstep` is given, arrays
            have their full sizes); sizes and types are still checked.
          nstep: number of steps of each rollout (inferred if None).
          initial_warmstart: initial qacc_warmstart, ([nbatch or 1] x nv); zero if None.
          state: output, (nbatch x nstep x nstate), written in place.
          sensordata: output, (nbatch x nstep x nsensordata), written in place.
          chunk_size: rollouts handed to a thread at a time; default
            max(1, nbatch // (10 * nthread)).

        Returns:
          (state, sensordata): (nbatch x nstep x nstate) and (nbatch x nstep x nsensordata).

        Raises:
          RuntimeError: rollout requested after thread pool shutdown.
          ValueError: bad shapes, sizes or values.
          TypeError: an argument of the wrong type, or an output that is not a
            writable float64 array.
          mjcffi.FatalError: MuJoCo raised a fatal error in a rollout (the
            others completed); its `failed` attribute lists the failed rollouts.
        """
        if not self._open:
            raise RuntimeError("rollout requested after thread pool shutdown")
        pool = self._pool          # held for the call: close() cannot free it under us
        if skip_checks:
            return self._run_unchecked(pool, model, data, initial_state, control, control_spec,
                                       nstep, initial_warmstart, state, sensordata, chunk_size)

        models = _models(model)
        control_spec = _integer(control_spec, "control_spec", TypeError)
        if control_spec & ~_USER:
            raise ValueError("control_spec can only contain bits in mjSTATE_USER")
        if nstep is not None:
            nstep = _integer(nstep, "nstep", ValueError)
            if nstep < 0:
                raise ValueError("nstep must be non-negative")
        chunk_size = _chunk_size(chunk_size)
        for name, value in (("initial_state", initial_state),
                            ("initial_warmstart", initial_warmstart), ("control", control),
                            ("state", state), ("sensordata", sensordata)):
            if value is not None and not isinstance(value, (np.ndarray, float)):
                raise ValueError(f"{name} must be a numpy array or float")
        for name, value, ndim in (("initial_state", initial_state, 2),
                                  ("initial_warmstart", initial_warmstart, 2),
                                  ("control", control, 3), ("state", state, 3),
                                  ("sensordata", sensordata, 3)):
            if value is not None and np.ndim(value) > ndim:
                raise ValueError(f"{name} can have at most {ndim} dimensions")

        if initial_state is None:
            raise TypeError("initial_state must be a numpy array or float, not None")
        initial_state = _input(initial_state, 2)
        initial_warmstart = None if initial_warmstart is None else _input(initial_warmstart, 2)
        control = None if control is None else _input(control, 3)
        state = None if state is None else _output(state, "state")
        sensordata = None if sensordata is None else _output(sensordata, "sensordata")

        arrays = (("initial_state", initial_state), ("initial_warmstart", initial_warmstart),
                  ("control", control), ("state", state), ("sensordata", sensordata))
        nbatch = _infer(0, 1, arrays)
        if models.__class__ is list:
            if nbatch == 1:
                nbatch = len(models)
            if len(models) > 1 and len(models) != nbatch:
                raise ValueError(f"nbatch inferred as {nbatch} but model is length {len(models)}")
        nstep = _infer(1, 1 if nstep is None else nstep, arrays[2:])

        first = models if models.__class__ is not list else models[0]
        m0 = first._ptr
        nstate = lib.mj_stateSize(m0, _FULLPHYSICS)
        ncontrol = lib.mj_stateSize(m0, control_spec)
        nv, nsensordata = m0.nv, m0.nsensordata
        if models.__class__ is list:
            _check_compatible(models)
        for name, value, dim in (("initial_state", initial_state, nstate),
                                 ("state", state, nstate), ("control", control, ncontrol),
                                 ("initial_warmstart", initial_warmstart, nv),
                                 ("sensordata", sensordata, nsensordata)):
            if value is not None and value.shape[-1] != dim:
                raise with_note(ValueError(f"trailing dimension of {name} must be {dim}, "
                                           f"got {value.shape[-1]}"),
                                f"{name} must have shape {_expected(name, nbatch, nstep, dim)}")
        for name, value, dim in (("state", state, nstate),
                                 ("sensordata", sensordata, nsensordata)):
            if value is not None and value.shape != (nbatch, nstep, dim):
                raise ValueError(f"{name} has shape {value.shape}; an output must have the "
                                 f"full shape (nbatch, nstep, {dim}) = {(nbatch, nstep, dim)}")
        if nbatch > _INT_MAX or nstep > _INT_MAX:
            raise ValueError(f"nbatch ({nbatch}) and nstep ({nstep}) must fit in a C int")
        if state is None:
            state = _allocate((nbatch, nstep, nstate), "state")
        if sensordata is None:
            sensordata = _allocate((nbatch, nstep, nsensordata), "sensordata")

        datas = self._datas(data, first)
        if models.__class__ is list and len(models) == 1:
            models = first
        if nbatch == 0 or nstep == 0:
            return state, sensordata

        # a leading dimension of 1 repeats that row: stride 0 instead of a tiled copy
        control_rstride = control_tstride = 0
        if control is not None:
            control_tstride = 0 if control.shape[1] == 1 else ncontrol
            control_rstride = 0 if control.shape[0] == 1 else control.shape[1] * ncontrol
        self._call(pool, models, datas, nbatch, nstep, control_spec, chunk_size,
                   initial_state, 0 if initial_state.shape[0] == 1 else nstate,
                   initial_warmstart,
                   0 if initial_warmstart is None or initial_warmstart.shape[0] == 1 else nv,
                   control, control_rstride, control_tstride, state, sensordata)
        return state, sensordata

    def _run_unchecked(self, pool, model, data, initial_state, control, control_spec, nstep,
                       initial_warmstart, state, sensordata, chunk_size):
        """skip_checks=True: the arrays at their full sizes; only what keeps C safe is checked."""
        models = _models(model)
        control_spec = _integer(control_spec, "control_spec", TypeError)
        if control_spec & ~_USER:
            raise ValueError("control_spec can only contain bits in mjSTATE_USER")
        nstep = _integer(nstep, "nstep", ValueError)
        if nstep < 0:
            raise ValueError("nstep must be non-negative")
        chunk_size = _chunk_size(chunk_size)
        if initial_state is None:
            raise TypeError("initial_state must be a numpy array, not None")
        initial_state = _input(initial_state, 2)
        nbatch = initial_state.shape[0]
        if models.__class__ is list:
            if len(models) < nbatch:
                raise ValueError(f"model has {len(models)} models, fewer than nbatch {nbatch}")
            _check_compatible(models)
            first = models[0]
            models = models[:nbatch]
        else:
            first = models
        datas = self._datas(data, first)
        if nbatch == 0 or nstep == 0:
            return state, sensordata
        m0 = first._ptr
        nstate = lib.mj_stateSize(m0, _FULLPHYSICS)
        ncontrol = lib.mj_stateSize(m0, control_spec)
        arrays = {"initial_state": initial_state}
        if initial_warmstart is not None:
            arrays["initial_warmstart"] = _input(initial_warmstart, 2)
        if control is not None:
            arrays["control"] = _input(control, 3)
        if state is not None:
            arrays["state"] = _output(state, "state")
        if sensordata is not None:
            arrays["sensordata"] = _output(sensordata, "sensordata")
        sizes = {"initial_state": nstate, "initial_warmstart": m0.nv,
                 "control": nstep * ncontrol, "state": nstep * nstate,
                 "sensordata": nstep * m0.nsensordata}
        for name, array in arrays.items():
            if array.size != nbatch * sizes[name]:
                raise ValueError(f"{name}.size should be {nbatch * sizes[name]}, got {array.size}")
        if nbatch > _INT_MAX or nstep > _INT_MAX:
            raise ValueError(f"nbatch ({nbatch}) and nstep ({nstep}) must fit in a C int")
        self._call(pool, models, datas, nbatch, nstep, control_spec, chunk_size,
                   initial_state, nstate, arrays.get("initial_warmstart"), m0.nv,
                   arrays.get("control"), nstep * ncontrol, ncontrol,
                   arrays.get("state"), arrays.get("sensordata"))
        return state, sensordata

    def _datas(self, data, model):
        """The C pointers of `data`, one MjData per thread, each made for `model`'s sizes."""
        if isinstance(data, (list, tuple)):
            data = list(data)
        else:
            data = [data]
        if not data:
            raise ValueError("The list of data instances is empty")
        if self.nthread == 0 and len(data) > 1:
            raise ValueError("More than one data instance passed but rollout is configured to "
                             "run on main thread")
        if self.nthread > 0 and len(data) != self.nthread:
            raise ValueError(f"Length of data: {len(data)} not equal to nthread: {self.nthread}")
        pointers = []
        for i, d in enumerate(data):
            name = f"data[{i}]"
            pointer = _marshal.data_of(model, d, "model", name)
            if pointer.threadpool:
                raise ValueError(f"{name} has a thread pool installed (mju_threadpool); rollout "
                                 "parallelizes across simulations and cannot use it")
            if pointer in pointers:
                raise ValueError(f"{name} is data[{pointers.index(pointer)}]: each thread needs "
                                 "its own MjData")
            pointers.append(pointer)
        return pointers

    def _call(self, pool, models, datas, nbatch, nstep, control_spec, chunk_size,
              state0, state0_stride, warmstart0, warmstart0_stride,
              control, control_rstride, control_tstride, state, sensordata):
        """Run the C loop on checked arguments; raise FatalError if a rollout failed."""
        if models.__class__ is list:
            m = ffi.new("mjModel*[]", [model._ptr for model in models])
        else:
            m = ffi.new("mjModel*[1]", [models._ptr])
        if chunk_size is None:
            chunk_size = max(1, nbatch // (10 * self.nthread)) if self.nthread else nbatch
        failed = np.zeros(nbatch, np.uint8)
        message = ffi.new("char[]", _MESSAGE_SIZE)
        me = threading.get_ident()
        if me in self._callers:      # a callback on this thread (the pool's C refuses its own)
            raise with_note(RecursionError("rollout: this Rollout is running the call whose "
                                           "callback made this one"),
                            "a Rollout waits for the callbacks of its call, so they may not "
                            "call it; give the callback a Rollout of its own")
        # a Python callback's exception on the pool's threads is this call's
        claim = _contract.claim(datas) if _contract.python_callbacks and len(datas) > 1 else None
        scopes = _contract.scopes
        # Each claim is taken inside the `try` whose `finally` releases it, each release
        # the first call of a `finally` of its own: a KeyboardInterrupt at any bytecode
        # leaves neither this thread in _callers nor the claim in force.
        try:
            if claim is not None:
                scopes.append(claim)
            self._callers.add(me)
            nfailed = lib.mjcffi_rollout(
                pool, m, len(m), ffi.new("mjData*[]", datas), nbatch, nstep, control_spec,
                min(chunk_size, _INT_MAX), _pointer(state0), state0_stride,
                _pointer(warmstart0), warmstart0_stride,
                _pointer(control), control_rstride, control_tstride,
                _pointer(state), _pointer(sensordata),
                ffi.from_buffer("unsigned char[]", failed), message, _MESSAGE_SIZE)
        finally:
            try:
                self._callers.discard(me)
            finally:
                if claim is not None and claim in scopes:
                    scopes.remove(claim)
        if _stack.live:          # a bad state's reset, or a failed rollout's, empties the stack
            for d in datas:
                _stack.sweep(d)
        if nfailed == _REFUSED:        # a callback of this pool's call called it
            raise_pending()
        if nfailed == _INTERRUPTED:
            _interrupt.stopped("rollout")
        if _contract.pending:
            _contract.raise_stashed()
        if nfailed:
            error = FatalError(ffi.string(message).decode("utf-8", "replace"))
            error.failed = np.flatnonzero(failed)
            raise error


_live: weakref.WeakSet = weakref.WeakSet()    # every Rollout: restart its threads after a fork


def _after_fork():
    for pool in list(_live):
        pool._forked()


os.register_at_fork(after_in_child=_after_fork)


# ----------------------------------------------------------------- checks

def _integer(value, name, error):
    """`value` as an int (a bool is not one); `error` is the exception type otherwise."""
    if isinstance(value, bool):
        raise error(f"{name} must be an integer")
    try:
        return operator.index(value)
    except TypeError:
        raise error(f"{name} must be an integer") from None


def _chunk_size(chunk_size):
    if chunk_size is None:
        return None
    chunk_size = _integer(chunk_size, "chunk_size", ValueError)
    if chunk_size <= 0:
        raise ValueError("chunk_size must be a positive integer")
    return chunk_size


def _allocate(shape, name):
    """An output array, or ValueError when nbatch x nstep x its width is too much memory."""
    try:
        return np.empty(shape, _DTYPE)
    except MemoryError:
        raise with_note(ValueError(f"the {name} output of shape {shape} does not fit in "
                                   "memory"), "pass fewer rollouts or steps (nbatch, nstep), "
                        "or an output array of your own") from None


def _is_model(value):
    """An MjModel instance (the class itself has the same `_cname`)."""
    return getattr(value, "_cname", None) == "mjModel" and not isinstance(value, type)


def _kind(value):
    return f"the class {value.__name__} itself" if isinstance(value, type) else \
        type(value).__name__


def _models(model):
    """An MjModel as itself, any other iterable as a list of MjModels."""
    if _is_model(model):
        return model
    if _official.is_official(model):     # both bindings have an MjModel: say which
        raise _official.not_accepted("model", "MjModel", model)
    try:
        models = list(model)
    except TypeError:
        raise TypeError(f"model must be an MjModel or a sequence of them, not "
                        f"{_kind(model)}") from None
    for i, m in enumerate(models):
        if not _is_model(m):
            if _official.is_official(m):
                raise _official.not_accepted(f"model[{i}]", "MjModel", m)
            raise TypeError(f"model[{i}] must be an MjModel, not {_kind(m)}")
    if not models:
        raise ValueError("model is an empty sequence")
    return models


def _check_compatible(models):
    """Every model must have model[0]'s sizes: one MjData steps them all."""
    first = models[0]
    seen = {id(first)}
    head = ffi.buffer(first._ptr, _marshal._SIZES)[:]
    for i, m in enumerate(models):
        if id(m) in seen:
            continue
        seen.add(id(m))
        if ffi.buffer(m._ptr, _marshal._SIZES)[:] != head:
            raise ValueError(f"models are not compatible: model[{i}] has other sizes than "
                             f"model[0] (nq {m._ptr.nq} vs {first._ptr.nq}, nv {m._ptr.nv} vs "
                             f"{first._ptr.nv}, nbody {m._ptr.nbody} vs {first._ptr.nbody}, ...)")


def _input(value, ndim):
    """An input as a C-contiguous float64 array with `ndim` dimensions (leading ones added)."""
    array = np.asarray(value)
    if array.ndim < ndim:
        array = array.reshape((1,) * (ndim - array.ndim) + array.shape)
    if array.dtype is not _DTYPE or not array.flags.c_contiguous:
        array = np.ascontiguousarray(array, dtype=_DTYPE)
    return array


def _output(value, name):
    """An output buffer, as a 3-d view of the caller's memory: MuJoCo writes into it."""
    if not isinstance(value, np.ndarray) or value.dtype != _DTYPE or not value.flags.carray:
        _marshal._check_output(value, _DTYPE, name)
    if value.ndim < 3:
        value = value.reshape((1,) * (3 - value.ndim) + value.shape)
    return value


def _infer(axis, value, arrays):
    """The common length of `axis` of the given arrays, where a length of 1 repeats."""
    for name, array in arrays:
        if array is None:
            continue
        n = array.shape[axis]
        if n != value:
            if value == 1:
                value = n
            elif n != 1:
                raise ValueError(f"dimension {axis} inferred as {value} but {name} has {n}")
    return value


def _expected(name, nbatch, nstep, dim):
    """The shape `name` must have, in words: a leading size n may also be 1."""
    def lead(n):
        return f"[{n} or 1]" if n != 1 else "1"
    if name in ("state", "sensordata"):
        return f"({nbatch}, {nstep}, {dim})"
    if name == "control":
        return f"({lead(nbatch)}, {lead(nstep)}, {dim})"
    return f"({lead(nbatch)}, {dim})"


def _pointer(array):
    return ffi.NULL if array is None else ffi.from_buffer("mjtNum[]", array)


# ---------------------------------------------------------- the function

persistent_rollout = None
_persistent_lock = threading.Lock()


def shutdown_persistent_pool():
    """Shut down the persistent thread pool that `rollout(..., persistent_pool=True)` keeps.

    Called at interpreter shutdown; it can also be called by hand.
    """
    global persistent_rollout
    with _persistent_lock:
        if persistent_rollout is not None:
            persistent_rollout.close()
        persistent_rollout = None


atexit.register(shutdown_persistent_pool)


def rollout(model, data, initial_state, control=None, *, control_spec=_CTRL, skip_checks=False,
            nstep=None, initial_warmstart=None, state=None, sensordata=None, chunk_size=None,
            persistent_pool=False):
    """Roll out open-loop trajectories; get the states and sensor values that follow.

    Infers nbatch and nstep, repeats inputs whose leading dimensions are 1,
    and allocates the outputs that are not given.  With several MjData, one
    per thread, the rollouts run on that many threads: a pool started for
    this call, or with `persistent_pool=True` one kept between calls (and
    restarted when the number of threads changes).

    Args:
      model: an MjModel, or a sequence of nbatch MjModels of the same sizes.
      data: an MjData, or a sequence of them, one per thread.
      initial_state: initial states, ([nbatch or 1] x nstate), where
        nstate = mj_stateSize(model, mjSTATE_FULLPHYSICS).
      control: open-loop controls, ([nbatch or 1] x [nstep or 1] x ncontrol),
        where ncontrol = mj_stateSize(model, control_spec); optional.
      control_spec: the mjtState bits (within mjSTATE_USER) that `control` sets.
      skip_checks: take the arrays as given (see `Rollout.rollout`).
      nstep: number of steps of each rollout (inferred if None).
      initial_warmstart: initial qacc_warmstart, ([nbatch or 1] x nv); zero if None.
      state: output, (nbatch x nstep x nstate), written in place.
      sensordata: output, (nbatch x nstep x nsensordata), written in place.
      chunk_size: rollouts handed to a thread at a time; default
        max(1, nbatch // (10 * nthread)).
      persistent_pool: keep the thread pool for later calls.

    Returns:
      (state, sensordata): (nbatch x nstep x nstate) and (nbatch x nstep x nsensordata).

    Raises:
      ValueError: bad shapes, sizes or values.
      TypeError: an argument of the wrong type.
      mjcffi.FatalError: MuJoCo raised a fatal error in a rollout (see `Rollout.rollout`).
    """
    if isinstance(data, (list, tuple)):
        data = list(data)
    else:
        data = [data]
    nthread = len(data) if len(data) > 1 else 0

    if persistent_pool:
        global persistent_rollout
        with _persistent_lock:
            if persistent_rollout is None or persistent_rollout.nthread != nthread:
                # the old pool ends with its last call: another thread may be in one
                persistent_rollout = Rollout(nthread=nthread)
            pool = persistent_rollout
    else:
        pool = Rollout(nthread=nthread)
    try:
        return pool.rollout(model, data, initial_state, control, control_spec=control_spec,
                            skip_checks=skip_checks, nstep=nstep,
                            initial_warmstart=initial_warmstart, state=state,
                            sensordata=sensordata, chunk_size=chunk_size)
    finally:
        if not persistent_pool:
            pool.close()
