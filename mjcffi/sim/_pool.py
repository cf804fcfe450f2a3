"""MjSimPool: many MjSim stepped together on mjcffi's C thread pool (that of mjcffi.rollout)."""

import copy
import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .._support import errors as _errors, marshal as _marshal
from .._support import contract as _contract, interrupt as _interrupt, stack as _stack
from .. import warning_errors as _warnings
from .._support.library import ffi, lib
from ..functions._overrides import mj_forward, mj_step
from ..rollout import Rollout
from ._sim import MjSim, _count

_MESSAGE_SIZE = 2048        # as the C helper's record of a caught error
_STOPPED = lib.MJCFFI_STEP_STOPPED     # what a step loop that a SIGINT stopped returns


class MjSimPool:
    """Many MjSim stepped together on a persistent pool of threads.

    `step()` first calls each sim's udd_callback (if any), as mujoco-py's pool
    did, then runs `nsubsteps` MuJoCo steps of each sim, each step after the
    sim's substep callback (if any), as `MjSim.step()` does; `nsubsteps` is the
    pool's own count (the sims' own counts are not used here).  The sims run on
    a C thread pool (mjcffi/_c/rollout.c, the one of mjcffi.rollout) with the GIL
    released, one sim at a time per thread, so they advance in parallel; the
    results are those of stepping each sim alone.  Where Python must run
    during the steps (a sim with a Python substep callback, a Python mjcb_*
    callback installed, or mjcffi.set_warnings_as_errors(True)) the sims run
    on Python threads instead, which take turns on the GIL.

    The sims must have an MjData each: a sim given twice, or two sims on one
    MjData, would be stepped by two threads at once.  An error in one sim
    (a FatalError, a callback's exception, ...) is raised once every other sim
    has stepped; the first one, in the order of `sims`.  A FatalError raised
    by the C pool has `failed`, the indices of every sim that failed.
    """

    def __init__(self, sims, nsubsteps=1, nthreads=None):
        try:
            self.sims = list(sims)
        except TypeError:
            raise TypeError(f"sims must be a sequence of MjSim, not {type(sims).__name__}") \
                from None
        _distinct(self.sims)
        self.nsubsteps = _count(nsubsteps, "nsubsteps", 1)
        if nthreads is None:
            nthreads = os.cpu_count() or 1
        nthreads = _count(nthreads, "nthreads", 1)
        self.nthreads = min(nthreads, len(self.sims))
        # the calling thread takes part in both pools: the C pool holds the others
        self._threads = Rollout(nthread=self.nthreads) if self.nthreads > 1 else None
        self._executor = None      # Python threads, started on first need
        self._closed = False
        self._running = False      # a step or forward is under way

    @classmethod
    def create_from_sim(cls, sim, nsims):
        """A pool of `nsims` sims on copies of `sim`'s model, each with its own fresh data."""
        if not isinstance(sim, MjSim):
            raise TypeError(f"sim must be an MjSim, not {type(sim).__name__}")
        nsims = _count(nsims, "nsims", 1)
        sims = [MjSim(copy.copy(sim.model), nsubsteps=sim.nsubsteps,
                      udd_callback=sim.udd_callback) for _ in range(nsims)]
        return cls(sims, nsubsteps=sim.nsubsteps)

    @property
    def nsims(self):
        return len(self.sims)

    def _selected(self, nsims):
        """The first `nsims` sims (all for None), checked: the pool open, each data once."""
        if self._closed:
            raise ValueError("MjSimPool is closed")
        if nsims is None:
            sims = self.sims
        else:
            nsims = _count(nsims, "nsims", 0)
            if nsims > len(self.sims):
                raise ValueError(f"nsims must be at most the pool's {len(self.sims)} sims, "
                                 f"got {nsims}")
            sims = self.sims[:nsims]
        # `sims` is a public list: checked again at each call, in one set on the way
        try:
            distinct = len({sim.data._ptr for sim in sims}) == len(sims)
        except AttributeError:
            distinct = False
        if not distinct and sims:
            _distinct(sims)     # raises, naming the culprit
        return sims

    def step(self, nsims=None):
        """Run `nsubsteps` steps of the first `nsims` sims (all by default), in parallel,
        each after its udd_callback."""
        sims = self._selected(nsims)
        for sim in sims:
            if sim.udd_callback is not None:
                sim.step_udd()
        self._run(mj_step, sims)

    def forward(self, nsims=None):
        """mj_forward on the first `nsims` sims (all by default), in parallel."""
        self._run(mj_forward, self._selected(nsims))

    def reset(self, nsims=None):
        """Reset the first `nsims` sims (all by default).

        In turn, on this thread: mj_resetData is a copy of the model's defaults,
        cheaper than handing it to other threads, and each sim's udd_callback
        (Python) runs again."""
        for sim in self._selected(nsims):
            sim.reset()

    def _run(self, job, sims):
        if not sims:
            return
        if self._running:
            raise _errors.with_note(
                RecursionError(f"MjSimPool.{'forward' if job is mj_forward else 'step'}: this "
                               f"pool is in a call already (a callback of its sims called "
                               f"it, or another thread is using it)"),
                "a pool waits for the callbacks its threads run, so they may not call it; "
                "an MjSimPool takes one call at a time")
        try:
            self._running = True     # inside the `try`: an interrupt cannot leave it set
            if _contract.python_callbacks or _contract.warnings_as_errors or \
                    any(s._substep_python is not None for s in sims):
                self._run_python(job, sims)
            else:
                self._run_c(job is mj_forward, sims)
        finally:
            self._running = False

    def _run_c(self, forward, sims):
        """The sims on the C pool: one guarded call per sim, the GIL released."""
        n = len(sims)
        threads = self._threads          # None without a pool (or once closed)
        pairs = [_marshal.model_data(sim.model, sim.data) for sim in sims]
        substeps = [sim._substep_fn for sim in sims]     # NULL where there is none
        status = ffi.new("unsigned char[]", n)
        message = ffi.new("char[]", _MESSAGE_SIZE)
        nfailed = lib.mjcffi_sim_pool_run(
            threads._pool if threads is not None else ffi.NULL,
            ffi.new("mjModel*[]", [m for m, _ in pairs]),
            ffi.new("mjData*[]", [d for _, d in pairs]),
            ffi.new("mjfGeneric[]", substeps) if any(substeps) else ffi.NULL,
            n, self.nsubsteps, forward, status, message, _MESSAGE_SIZE)
        if _stack.live:                  # a bad state's reset empties the stack
            for _, d in pairs:
                _stack.sweep(d)
        if nfailed == -1:                # refused: a callback of this pool's call
            _errors.raise_pending()
        if nfailed == -2:                # a SIGINT stopped the steps (interrupt.py)
            _interrupt.stopped("MjSimPool.step")
        if _contract.pending:
            _contract.raise_stashed()
        if nfailed:
            failed = np.flatnonzero(np.frombuffer(ffi.buffer(status), np.uint8))
            text = ffi.string(message).decode("utf-8", "replace")
            kind = status[failed[0]] - 1
            error = (_errors.FatalError(text) if kind == lib.MJCFFI_ERROR_FATAL
                     else _contract.refusal(kind, text))
            error.failed = failed
            raise error

    def _run_python(self, job, sims):
        """The sims on Python threads, for the calls that run Python during the steps.

        Ctrl-C: the C step loops of every thread take the calling thread's interrupt
        token, so a SIGINT stops each at its next step (mjcffi/_c/interrupt.c), and a
        KeyboardInterrupt the calling thread sees stops the Python loops (`stop`) at
        theirs; the call waits for the threads to end, then raises it."""
        n = min(self.nthreads, len(sims))
        if n > 1 and self._executor is None:
            self._executor = ThreadPoolExecutor(self.nthreads - 1,
                                                thread_name_prefix="MjSimPool")
        shares = [sims[i::n] for i in range(n)]
        token = lib.mjcffi_interrupt_token()   # -1 where a SIGINT stops nothing
        stop = []                              # non-empty: the caller saw Ctrl-C
        futures = [self._executor.submit(_run_share, job, share, self.nsubsteps, token, stop)
                   for share in shares[1:]]
        try:
            errors = [_run_share(job, shares[0], self.nsubsteps, token, stop)]
            for future in futures:     # wait for every share, whatever failed
                try:
                    errors.append(future.result())
                except KeyboardInterrupt:
                    raise
                except BaseException as exc:
                    errors.append([(-1, exc)])
        except KeyboardInterrupt:
            stop.append(True)          # the other threads end at their next step
            _wait(futures)
            raise
        if lib.mjcffi_interrupted(token):      # a SIGINT whose handler raised nothing
            _interrupt.stopped("MjSimPool.step")
        if any(errors):            # the first in the order of `sims`
            raise min(((i * n + k, exc) for k, share_errors in enumerate(errors)
                       for i, exc in share_errors), key=lambda entry: entry[0])[1]

    def close(self):
        """Stop the pool's threads (also done when the pool is collected); later calls
        raise ValueError."""
        self._closed = True
        if self._threads is not None:
            self._threads.close()
            self._threads = None
        if self._executor is not None:
            self._executor.shutdown(wait=True)
            self._executor = None

    def __del__(self):
        executor = getattr(self, "_executor", None)
        if executor is not None:
            executor.shutdown(wait=False)


def _distinct(sims):
    """TypeError unless all are MjSim; ValueError if two are one, or share an MjData."""
    if not sims:
        raise TypeError("sims must be a non-empty sequence of MjSim")
    seen = {}
    for i, sim in enumerate(sims):
        if not isinstance(sim, MjSim):
            raise TypeError(f"sims[{i}] must be an MjSim, not {type(sim).__name__}")
        pointer = getattr(sim.data, "_ptr", None)
        first = seen.setdefault(pointer, i)
        if first != i:
            what = "is" if sims[first] is sim else "shares its MjData with"
            raise ValueError(f"sims[{i}] {what} sims[{first}]: each sim of a pool needs an "
                             "MjData of its own, which one thread steps")


def _wait(futures):
    """Wait for `futures` to end; a second Ctrl-C meanwhile is the caller's too."""
    for future in futures:
        while True:
            try:
                future.exception()
                break
            except KeyboardInterrupt:
                continue          # the threads are stopping already: keep waiting
            except BaseException:
                break             # cancelled


def _run_share(job, sims, nsubsteps, token=-1, stop=()):
    """Step (or forward) each sim; [(index in `sims`, exception)] for those that raised.
    A SIGINT after `token`, or a non-empty `stop`, ends the share at the next step."""
    errors = []
    for i, sim in enumerate(sims):
        if stop or lib.mjcffi_interrupted(token):
            break
        try:
            if job is not mj_step:
                job(sim.model, sim.data)
            elif sim._substep_python is not None:
                fn = sim._substep_python
                for _ in range(nsubsteps):
                    if stop or lib.mjcffi_interrupted(token):
                        break
                    fn(sim.model, sim.data)
                    mj_step(sim.model, sim.data)
            elif sim.substep_callback_ptr:
                _steps(sim, nsubsteps, sim._substep_fn, token, warned=False)
            else:
                _steps(sim, nsubsteps, ffi.NULL, token, warned=True)
        except Exception as exc:
            errors.append((i, exc))
        if _stack.live:              # as mj_step does
            _stack.sweep(sim.data)
    return errors


def _steps(sim, nsubsteps, fn, token, warned):
    """`nsubsteps` steps of `sim`, each after C function `fn` (or NULL), in one C loop
    that a SIGINT after `token` stops at a step boundary: mj_step(m, d, nsubsteps) and
    MjSim's C substep loop, with the calling thread's token on any thread.  `warned`:
    with mjcffi.set_warnings_as_errors(True), check the counts over the loop, as
    mj_step does."""
    m, d = sim._pointers
    before = _warnings.before_call(sim.data) if warned and _contract.warnings_as_errors \
        else None
    try:
        status = lib.mjcffi_step_loop(m, d, nsubsteps, fn, token)
        if status == _STOPPED:       # a SIGINT: _run_python raises once every thread stopped
            status = 0
        if status or _contract.pending:
            _marshal.check(status)
    except BaseException:
        if before is not None:
            _warnings.restore(sim.data, before)     # keep the counts under the exception
        raise
    if before is not None:
        _warnings.after_call(sim.data, before)
