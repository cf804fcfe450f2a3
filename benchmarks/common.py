"""Shared pieces of the benchmarks: interleaved timing and the machine's description."""

import datetime
import platform
import statistics
import timeit
from importlib import metadata


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


def cpu_name():
    try:
        with open("/proc/cpuinfo") as info:
            for line in info:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def environment():
    """Lines naming date, versions and CPU, for RESULTS.md."""
    versions = ", ".join(f"{name} {metadata.version(name)}"
                         for name in ("mjcffi", "mujoco-core", "cffi", "numpy"))
    return [f"- date: {datetime.date.today().isoformat()}",
            f"- Python {platform.python_version()} ({platform.python_implementation()}), {versions}",
            f"- CPU: {cpu_name()}; {platform.system()} {platform.machine()}"]
