"""Issue 11: the fuzzer (tests/fuzz/) in CI.

- a derandomized sample of the fuzzer's calls (seed 0, FUZZ_CALLS calls: bad
  arguments for every public function and entry point, arrays against guard
  pages, in batched subprocesses) must give no finding outside
  tests/fuzz/known.py's KNOWN_OPEN;
- every scenario probe must pass, or be in KNOWN_OPEN;
- every KNOWN_OPEN entry must still fail, so that the table cannot go stale;
- the fuzzer itself must see what it is there to see: a segfault, an over-read
  past a guard page, an under-read, a write into a read-only input, an
  undocumented exception, a hang; and it must narrow a crash in a batch down to
  the call that made it.

A full run (>= 20,000 calls) is `python -m tests.fuzz --calls 20000 --seed 1
--out fuzz-report.md` (see tests/fuzz/__init__.py).
"""

import os

from tests.fuzz import known, plan, probes, runner
from tests.fuzz.report import finding_class

FUZZ_CALLS = int(os.environ.get("MJCFFI_FUZZ_CALLS", "3000"))
FUZZ_SEED = 0


def _line(r):
    text = f"{finding_class(r)}: {r.key}"
    if r.message:
        text += f"  ({r.message[:160]})"
    if r.trigger and len(r.trigger) > 1:
        text += f"  [trigger: {' ; '.join(r.trigger)}]"
    return text


def test_item_fuzz_sample_has_no_new_finding():
    keys = plan.keys(FUZZ_CALLS, FUZZ_SEED)
    results = runner.run_parallel(keys)
    assert len(results) >= len(keys)
    made = sum(r.outcome not in ("na", "setup") for r in results)
    assert made >= FUZZ_CALLS // 2, f"only {made} of {len(keys)} calls were made"
    new = [r for r in results if r.finding and not known.match(r.key, r.outcome)]
    assert not new, ("findings outside KNOWN_OPEN (replay one with python -m tests.fuzz "
                     "--replay KEY):\n" + "\n".join(map(_line, new)))


def test_item_scenario_probes_pass():
    results = probes.run_all()
    failing = [r for r in results if not r.passed and not r.known]
    assert not failing, "\n" + probes.markdown(failing)


def _still_fails(entry):
    """'' if `entry`'s witness still fails as recorded, else why the entry is stale."""
    keys = entry.replay
    witness = keys[-1]
    if witness.startswith("probe:"):
        result = probes.run(witness.split("|")[0][len("probe:"):])
        return "" if not result.passed else f"fixed: probe {witness} passes"
    if not known.matches(entry.pattern, witness):
        return f"the witness {witness!r} is not matched by its pattern"
    timeout = 5.0 if "timeout" in entry.outcomes else 20.0
    results, crash = runner.run_batch(keys, timeout)
    last = len(keys) - 1
    if crash is not None:
        status = "timeout" if crash[1] == "timeout" else "crash"
        if crash[0] != last:
            return f"{' ; '.join(keys)} now fails at call {crash[0]}, not at its witness"
        return "" if status in entry.outcomes else f"{witness} now gives {crash[1]}"
    outcome = results[last][0] if last in results else "no result"
    if outcome in entry.outcomes:
        return ""
    return f"fixed: {witness} now gives {outcome} {results.get(last, ('', ''))[1]}"


def test_item_known_open_entries_still_fail():
    """Each KNOWN_OPEN entry's witness is replayed alone: an entry whose trigger no longer
    fails must leave the table (so that it cannot hide a regression later)."""
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max(1, os.cpu_count() or 1)) as pool:
        verdicts = list(pool.map(_still_fails, known.KNOWN_OPEN))
    stale = [f"{e.pattern} ({e.outcome}): {why}" for e, why in zip(known.KNOWN_OPEN, verdicts)
             if why]
    assert not stale, "remove from tests/fuzz/known.py KNOWN_OPEN:\n" + "\n".join(stale)


def test_item_fuzzer_classifies_exceptions():
    labels = {"ok": "ok", "documented": "raised", "undocumented": "undocumented"}
    results, crash = runner.run_batch([f"case:selftest|-|{label}" for label in labels])
    assert crash is None
    assert [results[i][0] for i in range(len(labels))] == list(labels.values())


def test_item_fuzzer_sees_faults_at_guard_pages():
    """A segfault, an over-read by one element past a guard page, an under-read before
    a front guard, a write into a read-only input: each kills its worker with SIGSEGV."""
    from concurrent.futures import ThreadPoolExecutor
    labels = ["segfault", "guard overread", "guard underread", "guard read-only write"]
    with ThreadPoolExecutor(len(labels)) as pool:
        crashes = list(pool.map(lambda label: runner.run_batch(
            [f"case:selftest|-|{label}"])[1], labels))
    for label, crash in zip(labels, crashes):
        assert crash is not None and crash[1] == "SIGSEGV", (label, crash)


def test_item_fuzzer_sees_a_hang():
    results, crash = runner.run_batch(["case:selftest|-|ok", "case:selftest|-|hang"],
                                      timeout=1.0)
    assert results[0][0] == "ok"
    assert crash is not None and crash[:2] == (1, "timeout")


def test_item_fuzzer_bisects_a_crash_to_its_call():
    """A crash in the middle of a batch: the calls before it are reported, the crash is
    narrowed down to its own call, and the calls after it still run."""
    keys = (["case:selftest|-|ok"] * 5 + ["case:selftest|-|segfault"]
            + ["case:selftest|-|documented"] * 3)
    results = runner.run_keys(keys, batch=len(keys))
    outcomes = [r.outcome for r in results]
    assert outcomes == ["ok"] * 5 + ["crash"] + ["raised"] * 3
    crash = results[5]
    assert crash.trigger == ("case:selftest|-|segfault",)
    assert "Segmentation fault" in crash.stderr


def test_item_known_table_patterns():
    assert known.matches("fn:*|*|class", "fn:mj_step|m|class")
    assert known.matches("fn:mj_jac|body|2**31-1", "fn:mj_jac|body|2**31-1")
    assert not known.matches("fn:mj_jac|body|2**31-1", "fn:mj_jac|body|2**31")
    assert known.matches("fn:mjs_*|dest|raw: *", "fn:mjs_setBuffer|dest|raw: wrong handle type")
