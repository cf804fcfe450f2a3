"""MjSimPool: many MjSim stepped together on a persistent pool of threads."""

import copy
import os
from concurrent.futures import ThreadPoolExecutor

from .._overrides import mj_forward, mj_step
from ._sim import MjSim, _count


class MjSimPool:
    """Many MjSim stepped together on a persistent pool of threads.

    Each thread steps its share of the sims with mjcffi's C loop, which runs
    with the GIL released, so the sims advance in parallel; the results are
    those of stepping each sim alone.  `nsubsteps` is the pool's own count of
    MuJoCo steps per `step()` (the sims' own counts are not used here).  The
    sims must have an MjData each: a sim given twice, or two sims on one
    MjData, would be stepped by two threads at once.  An error in one sim
    (a FatalError, a callback's exception, ...) is raised
    once every other sim has stepped; the first one, in the order of `sims`.
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
        # the calling thread takes one share, the pool the others
        self._executor = (ThreadPoolExecutor(self.nthreads - 1, thread_name_prefix="MjSimPool")
                          if self.nthreads > 1 else None)
        self._closed = False

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

    def _run(self, job, nsims):
        sims = self._selected(nsims)
        if not sims:
            return
        n = min(self.nthreads, len(sims))
        shares = [sims[i::n] for i in range(n)]
        futures = [self._executor.submit(_run_share, job, share, self.nsubsteps)
                   for share in shares[1:]]
        errors = [_run_share(job, shares[0], self.nsubsteps)]
        for future in futures:     # wait for every share, whatever failed
            try:
                errors.append(future.result())
            except BaseException as exc:
                errors.append([(-1, exc)])
        if any(errors):            # the first in the order of `sims`
            raise min(((i * n + k, exc) for k, share_errors in enumerate(errors)
                       for i, exc in share_errors), key=lambda entry: entry[0])[1]

    def step(self, nsims=None):
        """Run `nsubsteps` steps of the first `nsims` sims (all by default), in parallel."""
        self._run(mj_step, nsims)

    def forward(self, nsims=None):
        """mj_forward on the first `nsims` sims (all by default), in parallel."""
        self._run(mj_forward, nsims)

    def reset(self, nsims=None):
        """Reset the first `nsims` sims (all by default)."""
        for sim in self._selected(nsims):
            sim.reset()

    def close(self):
        """Stop the pool's threads (also done when the pool is collected); later calls
        raise ValueError."""
        self._closed = True
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


def _run_share(job, sims, nsubsteps):
    """Step (or forward) each sim; [(index in `sims`, exception)] for those that raised."""
    errors = []
    for i, sim in enumerate(sims):
        try:
            if job is mj_step:
                mj_step(sim.model, sim.data, nsubsteps)
            else:
                job(sim.model, sim.data)
        except Exception as exc:
            errors.append((i, exc))
    return errors
