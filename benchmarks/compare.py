"""python -m benchmarks.compare [--write]: mjcffi against the official bindings.

Runs every benchmark in one process (import times in fresh interpreters),
interleaved, and prints RESULTS.md, or writes it with --write, together with
the README's figures (benchmarks/readme.py).  Models: a
tiny pendulum and gymnasium's humanoid and ant.  Rendering runs in a child
interpreter with MUJOCO_GL=egl (bench_render).
"""

import argparse
import pathlib

from . import (bench_batch, bench_calls, bench_distributed, bench_fields, bench_import,
               bench_named, bench_nstep, bench_render, bench_rollout, bench_sim, bench_spec,
               bench_step, bench_structs, bench_tune, readme)
from mjcffi._support.machine import environment

RESULTS = pathlib.Path(__file__).resolve().parent / "RESULTS.md"


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m benchmarks.compare",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help=f"write {RESULTS.name}")
    args = parser.parse_args(argv)
    lines = ["# Benchmark results", "",
             "Written by `python -m benchmarks.compare --write`; every figure is a measurement of "
             "that run. Call benchmarks run both bindings in one process on the same libmujoco; "
             "import times come from fresh interpreters. Candidates alternate within every "
             "round, figures are medians, and ratios are mjcffi / official (below 1: mjcffi "
             "is faster). The machine is "
             "shared and noisy: read the ratios, not the absolute times.", ""]
    lines += environment() + [""]
    for bench in (bench_import, bench_step, bench_calls, bench_nstep, bench_structs, bench_fields,
                  bench_named, bench_rollout, bench_distributed, bench_batch, bench_sim,
                  bench_spec, bench_render, bench_tune):
        lines += bench.run() + [""]
    text = "\n".join(lines)
    print(text)
    if args.write:
        RESULTS.write_text(text)
        readme.write(RESULTS)
        print(f"wrote {RESULTS} and the figures in {readme.README.name}")


if __name__ == "__main__":
    main()
