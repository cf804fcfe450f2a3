"""python -m tests.fuzz: run the fuzzer.

    python -m tests.fuzz --calls 20000 --seed 1 --out fuzz-report.md   # a full run
    python -m tests.fuzz --calls 3000 --seed 0                         # what CI runs
    python -m tests.fuzz --replay 'fn:mj_jac|body|2**31-1'             # one call, alone
    python -m tests.fuzz --probes                                      # the scenario probes
    python -m tests.fuzz --list | grep mj_jac                          # the call keys

--calls N takes N keys of the whole key space (every target's valid call and
every variation of each argument), a fixed sample for a given --seed, or all
of them (and, past that, further random variants: pickle byte flips, XML cuts)
when N is larger.  Exit status: 0 when there is no finding outside
known.KNOWN_OPEN, 1 otherwise.
"""

import argparse
import sys
import time

from . import plan, probes, report, runner
from .known import match as known_match


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tests.fuzz", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--calls", type=int, default=3000, help="calls to make (default 3000)")
    parser.add_argument("--seed", type=int, default=0, help="sample seed (default 0)")
    parser.add_argument("--jobs", type=int, default=0, help="workers at once (default: CPUs)")
    parser.add_argument("--batch", type=int, default=200, help="calls per worker process")
    parser.add_argument("--timeout", type=float, default=20.0,
                        help="seconds a call may take before it counts as a hang")
    parser.add_argument("--only", default="", help="only keys containing this text")
    parser.add_argument("--out", help="write the markdown report here")
    parser.add_argument("--replay", nargs="+", metavar="KEY",
                        help="run these keys, in order, in one fresh worker (a known.py "
                             "witness 'a ; b' is split)")
    parser.add_argument("--probes", action="store_true", help="run the scenario probes")
    parser.add_argument("--no-probes", action="store_true", help="skip the scenario probes")
    parser.add_argument("--list", action="store_true", help="print the call keys and exit")
    args = parser.parse_args(argv)

    if args.list:
        for key in plan.keys(args.calls, args.seed, args.only):
            print(key)
        return 0
    if args.replay:
        keys = [k for arg in args.replay for k in arg.split(" ; ")]
        return _replay(keys, args.timeout)
    if args.probes:
        return _probes()

    keys = plan.keys(args.calls, args.seed, args.only)
    jobs = args.jobs or None
    start = time.monotonic()
    done = [0]

    def progress(r):
        done[0] += 1
        if r.finding:
            print(f"FINDING {report.finding_class(r)}: {r.key}  {r.message[:120]}",
                  file=sys.stderr, flush=True)
        elif done[0] % 1000 == 0:
            print(f"... {done[0]} / {len(keys)}", file=sys.stderr, flush=True)

    results = runner.run_parallel(keys, jobs=jobs, timeout=args.timeout, batch=args.batch,
                                  on_result=progress)
    probe_results = [] if args.no_probes else probes.run_all()
    elapsed = time.monotonic() - start
    command = "python -m tests.fuzz " + " ".join(argv if argv is not None else sys.argv[1:])
    text = report.markdown(results, command=command, seed=args.seed, elapsed=elapsed,
                           jobs=jobs or runner.os.cpu_count())
    text += probes.markdown(probe_results)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)
    print(text)
    new = [r for r in results if r.finding and not known_match(r.key, r.outcome)]
    new_probes = [p for p in probe_results if not p.passed and not p.known]
    return 1 if new or new_probes else 0


def _replay(keys, timeout):
    results, crash = runner.run_batch(keys, timeout)
    for i, key in enumerate(keys):
        if i in results:
            outcome, etype, message, description = results[i]
            print(f"{key}\n  {outcome} {etype} {message}\n  call: {description}")
    if crash is not None:
        index, status, tail = crash
        which = keys[index] if isinstance(index, int) else "the final collection"
        print(f"CRASH ({status}) in {which}\n{tail}")
        return 1
    return 1 if any(results[i][0] == "undocumented" for i in results) else 0


def _probes():
    results = probes.run_all()
    print(probes.markdown(results))
    return 1 if any(not p.passed and not p.known for p in results) else 0


if __name__ == "__main__":
    sys.exit(main())
