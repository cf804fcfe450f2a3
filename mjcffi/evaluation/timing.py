"""What a setting costs: steps per second, and speed ratios measured interleaved.

The machine may be shared and noisy, so an absolute time means little: a ratio
is measured by timing two settings in turn, pair after pair, and taking the
median of the pairs' ratios.
"""

import statistics
import time

import numpy as np

from .. import functions as mjf
from .. import rollout as _rollout
from ..data import MjData


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


class PeriodTimer:
    """Times one control period from each sampled state under one model, on the calling
    thread (the C rollout loop, GIL released), repeating until `min_time` has passed."""

    def __init__(self, m, samples, nstep, min_time=0.02):
        self.m = m
        self.data = MjData(m)
        self.samples = samples
        self.nstep = nstep
        self.min_time = min_time
        self.control = np.repeat(samples.next_controls[:, None, :], nstep, axis=1)
        self.state = np.empty((len(samples), nstep, samples.states.shape[1]))
        self.sensordata = np.empty((len(samples), nstep, m.nsensordata))

    def seconds_per_period(self):
        """Wall-clock seconds per control period simulated (one sample)."""
        runs = 0
        elapsed = 0.0
        while elapsed < self.min_time:
            t = time.perf_counter()
            _rollout.rollout(self.m, self.data, self.samples.states, self.control,
                             nstep=self.nstep, initial_warmstart=self.samples.warmstarts,
                             state=self.state, sensordata=self.sensordata)
            elapsed += time.perf_counter() - t
            runs += 1
        return elapsed / (runs * len(self.samples))


def speed_ratio(base, candidate, pairs=5):
    """(median, ratios): how many times faster `candidate` runs a control period than `base`
    (two PeriodTimers), timed in turn `pairs` times."""
    ratios = []
    for i in range(pairs):
        # alternate which goes first, so that a warm cache or a busy core favours neither
        first, second = (base, candidate) if i % 2 == 0 else (candidate, base)
        a = first.seconds_per_period()
        b = second.seconds_per_period()
        tb, tc = (a, b) if first is base else (b, a)
        ratios.append(tb / tc)
    return statistics.median(ratios), ratios
