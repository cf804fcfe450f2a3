"""What a setting costs: steps per second, and speed ratios measured interleaved.

The machine may be shared and noisy, so an absolute time means little: a ratio
is measured by timing two settings in turn, pair after pair, and taking the
median of the pairs' ratios.  A control period is timed in CPU time of the
calling thread (`time.thread_time`), not wall-clock time: on a loaded machine
wall-clock ratios of two identical settings spread 0.3-1.9x, CPU-time ratios
0.98-1.02x (DESIGN.md, fourth round).  What a solver option saves is counted
instead (`solver_work`): its iterations and line-search evaluations, no timing at all.
"""

import dataclasses
import math
import statistics
import time

import numpy as np

from .. import functions as mjf
from .. import rollout as _rollout
from .._generated.constants import mjNSOLVER
from ..data import MjData
from .states import FULLPHYSICS


def steps_per_second(m, reset, nstep, repeats=3, min_time=0.05):
    """Median steps/s of `mj_step(m, d, nstep=nstep)` (the loop in C) from `reset(m, d)`;
    each of `repeats` samples repeats the run until it has taken `min_time` seconds."""
    d = MjData(m)
    rates = []
    for _ in range(repeats):
        steps = 0
        elapsed = 0.0
        while elapsed < min_time:
            reset(m, d)
            t = time.perf_counter()
            mjf.mj_step(m, d, nstep=nstep)
            elapsed += time.perf_counter() - t
            steps += nstep
        rates.append(steps / elapsed)
    return statistics.median(rates)


TIMED_SAMPLES = 64     # periods timed per run, spread over the samples


class PeriodTimer:
    """Times one control period from each sampled state under one model, on the calling
    thread (the C rollout loop, GIL released), repeating until `min_time` has passed."""

    def __init__(self, m, samples, nstep, min_time=0.02, nsample=TIMED_SAMPLES):
        self.m = m
        self.data = MjData(m)
        # a spread subset of the samples: the cost of a period is an average, and one
        # run of all of them would take far longer than min_time on a big model
        pick = np.unique(np.linspace(0, len(samples) - 1, min(nsample, len(samples)))
                         .round().astype(int))
        self.states = samples.states[pick]
        self.warmstarts = samples.warmstarts[pick]
        self.nstep = nstep
        self.min_time = min_time
        self.control = np.repeat(samples.next_controls[pick, None, :], nstep, axis=1)
        self.state = np.empty((len(pick), nstep, samples.states.shape[1]))
        self.sensordata = np.empty((len(pick), nstep, m.nsensordata))

    def seconds_per_period(self):
        """CPU seconds of this thread per control period simulated (one sample).  The
        rollout runs on the calling thread, so its CPU time is the thread's."""
        runs = 0
        elapsed = 0.0
        while elapsed < self.min_time:
            t = time.thread_time()
            _rollout.rollout(self.m, self.data, self.states, self.control,
                             nstep=self.nstep, initial_warmstart=self.warmstarts,
                             state=self.state, sensordata=self.sensordata)
            elapsed += time.thread_time() - t
            runs += 1
        return elapsed / (runs * len(self.states))


def solver_work(m, samples, nstep, nsample=256):
    """(iterations, line-search evaluations): the mean count of each that one control
    period of `nstep` steps takes in the constraint solver, over a spread subset of the
    samples.  A cost that no load moves: the same counts on every run.

    Each step adds its islands' counts (`solver_niter` and the per-iteration `neval` of
    `solver`, one block per island; the first block alone when the step made no island).
    Under RK4 a step keeps only its last stage's counts, which serve as that step's share.
    """
    d = MjData(m)
    pick = np.unique(np.linspace(0, len(samples) - 1, min(nsample, len(samples)))
                     .round().astype(int))
    niter = d.solver_niter
    neval = d.solver.neval
    iterations = evaluations = 0
    for i in pick:
        mjf.mj_setState(m, d, samples.states[i], FULLPHYSICS)
        d.qacc_warmstart[:] = samples.warmstarts[i]
        d.ctrl[:] = samples.next_controls[i]
        for _ in range(nstep):
            mjf.mj_step(m, d)
            for island in range(max(1, d.nisland)):
                n = int(niter[island])
                iterations += n
                evaluations += int(neval[island * mjNSOLVER:island * mjNSOLVER + n].sum())
    return iterations / len(pick), evaluations / len(pick)


@dataclasses.dataclass(frozen=True)
class Speed:
    """A measured speed ratio: the median of the pairs and a distribution-free confidence
    interval of that median (order statistics of the pairs' ratios)."""

    value: float
    low: float
    high: float
    ratios: tuple

    def __str__(self):
        return f"{self.value:.2f}× (95 % interval {self.low:.2f}–{self.high:.2f})"


def median_interval(ratios, confidence=0.95):
    """(low, high): order statistics X(j), X(n+1-j) of `ratios` that bracket their true
    median with probability at least `confidence` (the largest such j; X(1), X(n) when n is
    too small for any)."""
    x = sorted(ratios)
    n = len(x)
    best = 1
    for j in range(1, n // 2 + 1):
        # P(median outside [X(j), X(n+1-j)]) = 2 P(Binomial(n, 1/2) <= j - 1)
        tail = sum(math.comb(n, i) for i in range(j)) / 2 ** n
        if 1 - 2 * tail >= confidence:
            best = j
    return x[best - 1], x[n - best]


def speed(base, candidate, pairs=9):
    """A Speed: how many times faster `candidate` runs a control period than `base` (two
    PeriodTimers), timed in turn `pairs` times."""
    ratios = []
    for i in range(pairs):
        # alternate which goes first, so that a warm cache or a busy core favours neither
        first, second = (base, candidate) if i % 2 == 0 else (candidate, base)
        a = first.seconds_per_period()
        b = second.seconds_per_period()
        tb, tc = (a, b) if first is base else (b, a)
        ratios.append(tb / tc)
    low, high = median_interval(ratios)
    return Speed(statistics.median(ratios), low, high, tuple(ratios))


def speed_ratio(base, candidate, pairs=5):
    """(median, ratios): how many times faster `candidate` runs a control period than `base`
    (two PeriodTimers), timed in turn `pairs` times."""
    s = speed(base, candidate, pairs)
    return s.value, list(s.ratios)
