"""The fuzzer of issue 11: bad calls for every public entry point, crashes seen as signals.

It lives under tests/ because it is a test: tests/test_fuzz.py runs a
derandomized sample of it in CI, and its scenario probes are checks that the
other test files can call.  (benchmarks/ holds speed measurements only.)

What it calls (the key space; `python -m tests.fuzz --list` prints it):
- every function of mjcffi.functions.NAMES (functions.py): the metadata of
  mjcffi/_generated/funcinfo.py (C types, const, extents, Nullable), the public
  wrappers' signatures, and codegen/functions.py's tables (SHAPES, SIZED,
  UNSUPPORTED) build one valid call; each variation then changes one argument
  to a bad value of its kind (values.py): None, wrong types, ints at the C
  limits (±2**31, ±2**63, 2**64), NaN and inf, out-of-range ids (-1, count,
  count+1), strings with NUL, format directives, surrogates; arrays short,
  long, empty, 3-D, transposed, of the wrong dtype, big-endian, Fortran-ordered,
  strided, misaligned, read-only, NaN-filled; structs of the wrong type, of
  another model, closed or freed, deleted spec elements, raw cffi pointers;
- the other entry points (entries.py): struct constructors and every field
  setter (each followed by reading the whole struct back), named access, the
  MjModel loaders with garbage, truncated and byte-flipped XML and MJB,
  corrupted MjData and MjModel pickles, MjVfs, rollout and Rollout, Batch and
  its methods, minimize.least_squares, MjSim / MjSimPool / MjSimState,
  set_mjcb_* and set_mju_user_* (then a step), spec and object lifetimes;
- the scenario probes (probes.py): issue 11's triggers, one function each.

How (runner.py, worker.py): arrays, inputs and outputs alike, sit against a
guard page (guard.py: mmap, then mprotect PROT_NONE on the page after the
array's last byte, or before its first), so that an over-read by one element
faults; const inputs are mapped read-only, so that a write into them faults
too.  Calls run in batched worker subprocesses that report each call before
and after it; a worker that dies of a signal, exits, or stops answering names
the call under way, which is then replayed alone and, if needed, bisected
against the calls before it.  Outcomes: ok; raised (TypeError, ValueError,
IndexError, KeyError, FatalError and their subclasses, or an exception
documented for that entry point); undocumented (any other type: a finding);
crash and timeout (findings).

    python -m tests.fuzz --calls 3000 --seed 0            # what CI runs (20-40 s, 2 cores)
    python -m tests.fuzz --calls 70000 --seed 1 --out fuzz-report.md   # a full run
    python -m tests.fuzz --replay 'fn:mj_jac|body|2**31-1'
    python -m tests.fuzz --probes

A full run takes every key of the key space (about 67,000; some 55,500 of them
are calls that apply, the rest variations that do not apply to their argument)
plus, past that, random variants (byte flips of XML, MJB and pickles) drawn
from the seed: about 5.5 minutes on 2 cores.  Workers run under a 4 GB
address-space cap (MJCFFI_FUZZ_MEMORY_GB), so that a call asking for
terabytes fails the same way on every machine.  Its report (--out) lists the calls by
outcome, every finding by class with its call, message and minimal trigger,
and the probes' results.  Known open findings are listed, each with the
issue item it belongs to, in known.py (KNOWN_OPEN).
"""
