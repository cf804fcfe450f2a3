"""Shared pieces of the benchmarks: interleaved timing of statements."""

import statistics
import timeit


def interleaved(candidates, rounds):
    """Time each zero-argument callable once per round, alternating; return medians.

    `candidates` maps a label to a callable that returns its own elapsed
    seconds (so it can exclude set-up).  Alternating the candidates inside
    every round spreads the noise of a shared machine over both.
    """
    samples = {label: [] for label in candidates}
    for _ in range(rounds):
        for label, run in candidates.items():
            samples[label].append(run())
    return {label: statistics.median(values) for label, values in samples.items()}


def per_call(statement, namespace, calls):
    """A callable timing `calls` runs of `statement` (timeit, in `namespace`).

    It returns seconds per run; timeit's loop costs the same on both sides.
    """
    timer = timeit.Timer(statement, globals=namespace)

    def run():
        return timer.timeit(calls) / calls
    return run
