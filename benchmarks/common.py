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


def side_by_side(statement, ours, theirs, calls, rounds, official_statement=None):
    """Median seconds per run of `statement` in mjcffi's namespace `ours` and of
    `official_statement` (the same by default) in the official's `theirs`,
    interleaved: (mjcffi, official)."""
    medians = interleaved({"mjcffi": per_call(statement, ours, calls),
                           "official": per_call(official_statement or statement, theirs,
                                                calls)}, rounds)
    return medians["mjcffi"], medians["official"]


def write_section(heading, lines, path=None):
    """Replace the section of RESULTS.md (or `path`) that starts at the line `heading`
    with `lines`, up to the next `## ` heading, keeping the rest byte for byte; append
    it when there is none.  Returns the path written."""
    import pathlib
    path = pathlib.Path(path) if path else pathlib.Path(__file__).resolve().parent / "RESULTS.md"
    text = path.read_text()
    section = "\n".join(lines) + "\n"
    keep = text.splitlines(keepends=True)
    start = next((i for i, line in enumerate(keep) if line.rstrip("\n") == heading), None)
    if start is None:
        path.write_text(text + ("" if text.endswith("\n") or not text else "\n") +
                        ("\n" if text else "") + section)
        return path
    end = next((i for i in range(start + 1, len(keep)) if keep[i].startswith("## ")),
               len(keep))
    tail = "".join(keep[end:])
    path.write_text("".join(keep[:start]) + section + ("\n" + tail if tail else ""))
    return path
