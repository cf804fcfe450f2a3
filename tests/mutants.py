"""Mutation check: deliberate small bugs that the test suite must catch.

    python -m tests.mutants                    # every mutant, with the tests named to catch it
    python -m tests.mutants id_bound plastic_span_end    # some of them (names or prefixes)
    python -m tests.mutants --list             # the mutants and their tests, nothing run
    python -m tests.mutants --full             # the whole suite for each mutant (slow)
    python -m tests.mutants --markdown         # the result table as markdown

Each mutant is a few exact source edits: (file, old text, new text).  The tree
is copied once to a temporary folder (the files git tracks or would track, and
the compiled mjcffi/_mjcffi*.so and _descriptors*.so as they are), and that snapshot again for each
mutant; the edits are applied in the mutant's copy, and its tests run there
with `python -m pytest -x`, so that `import mjcffi` imports the copy (checked
once).  The working tree is never touched, and other work going on in it
meanwhile plays no part.

A mutant of the C in mjcffi/_c/ is rebuilt: `python setup.py build_ext --inplace`
compiles the mutated module in its copy (about half a minute) before its tests run.

A mutant of codegen/ is regenerated: `python -m codegen --out` runs with the
mutated and with the unmutated generator, and the generated files that differ
are written into the copy (so that other drift in the tree plays no part).

Verdicts: `caught` (a test failed; the first one is named), `crashed` (the
test process died, which fails the suite too), `timeout`, `missed` (every
test passed), `stale` (an edit's old text is no longer in the file exactly
once: update the list), `broken` (pytest could not run the tests, or the C
did not compile: an error of the mutant itself or of the selection).  Before the mutants, the tests of
every selected mutant run once on the unmutated copy and must pass; else no
verdict would mean anything: a test that fails there (work in progress in the
tree, say) is listed and deselected from every mutant's run.  The exit status
is 1 if any mutant is neither caught nor crashed.
"""

import argparse
import dataclasses
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time

REPO = pathlib.Path(__file__).resolve().parent.parent


@dataclasses.dataclass(frozen=True)
class Mutant:
    name: str
    what: str                     # the bug, in words
    edits: tuple                  # ((path, old, new), ...)
    tests: tuple                  # pytest selections (files, node ids) expected to catch it
    regenerate: bool = False      # a codegen/ edit: regenerate the generated files
    rebuild: bool = False         # an mjcffi/_c/ edit: compile the module again


def _mutant(name, what, edits, tests, regenerate=False):
    if isinstance(edits[0], str):
        edits = (edits,)
    rebuild = any(path.startswith("mjcffi/_c/") for path, _, _ in edits)
    return Mutant(name, what, tuple(edits), tuple(tests), regenerate, rebuild)


# --------------------------------------------------------------- the mutants
#
# The first four are those the suite missed when issue 11 was written; the
# next seven, the kinds it caught then; the rest guard other subtle code.

MUTANTS = [
    # -- missed in issue 11
    _mutant(
        "struct_assign_half", "m.opt = other copies half of the struct",
        ("mjcffi/_support/views.py",
         "ffi.memmove(self._ptr, other._ptr, ffi.sizeof(self._ctype))",
         "ffi.memmove(self._ptr, other._ptr, ffi.sizeof(self._ctype) // 2)"),
        ["tests/test_structs.py", "tests/test_struct_conformance.py"]),
    _mutant(
        "plastic_span_end", "a named plastic span ends one start too late",
        ("mjcffi/_support/named.py", "count)) if a > adr]", "count)) if a > adr + 1]"),
        ["tests/test_named_plastic.py",
         "tests/test_named_conformance.py::test_accessors_look_like_the_official_ones"]),
    _mutant(
        "id_bound", "an id check lets id == count through (<= for <)",
        ("mjcffi/_support/marshal.py", "if not low <= value < count:",
         "if not low <= value <= count:"),
        ["tests/test_mutation_gaps.py"]),
    _mutant(
        "simstate_swap", "MjSimState.flatten/from_flattened swap qpos and qvel consistently",
        [("mjcffi/sim/_state.py", "np.ravel(self.qpos),\n                 np.ravel(self.qvel)]",
          "np.ravel(self.qvel),\n                 np.ravel(self.qpos)]"),
         ("mjcffi/sim/_state.py", "qpos = array[1:1 + nq]\n    qvel = array[1 + nq:1 + nq + nv]",
          "qvel = array[1:1 + nv]\n    qpos = array[1 + nv:1 + nv + nq]")],
        ["tests/test_sim.py"]),

    # -- the kinds caught in issue 11
    _mutant(
        "model_data_check", "an MjData of a model of other sizes is accepted",
        ("mjcffi/_support/marshal.py",
         "if ffi.buffer(model._ptr, _SIZES)[:] != ffi.buffer(m._ptr, _SIZES)[:]:",
         "if False:"),
        ["tests/test_function_layer.py", "tests/test_rollout.py"]),
    _mutant(
        "output_dtype", "an output array of another dtype is written into",
        ("mjcffi/_support/marshal.py",
         "if type(value) is not _ndarray or value.dtype is not dtype or not value.flags.carray:",
         "if type(value) is not _ndarray or not value.flags.carray:"),
        ["tests/test_function_layer.py::test_inputs_are_converted_outputs_never_copied",
         "tests/test_function_conformance.py"]),
    _mutant(
        "slice_stride", "a slice of a struct array forgets its stride",
        ("mjcffi/_support/views.py", "len(range(start, stop, stride)), self._root, step * stride)",
         "len(range(start, stop, stride)), self._root, step)"),
        ["tests/test_structs.py", "tests/test_struct_conformance.py"]),
    _mutant(
        "setter_bound", "a bounded scalar takes one more than its bound (scene.ngeom)",
        ("mjcffi/_support/views.py", "    if not low <= number <= high:\n        raise ValueError(",
         "    if not low <= number <= high + 1:\n        raise ValueError("),
        ["tests/test_struct_conformance.py", "tests/test_hardening_structs.py"]),
    _mutant(
        "callback_stash", "an exception raised in a Python callback is lost",
        ("mjcffi/_support/contract.py", "(next(_order), error))\n        pending = True",
         "(next(_order), error))\n        pending = False"),
        ["tests/test_callbacks.py"]),
    _mutant(
        "ball_qpos_width", "a ball joint's named qpos has 3 entries, not 4",
        ("mjcffi/_support/named.py", "_QPOS_WIDTH = {0: 7, 1: 4}", "_QPOS_WIDTH = {0: 7, 1: 3}"),
        ["tests/test_named.py"]),
    _mutant(
        "pickle_header", "a pickled MjData carries a blank header (sizes, offsets, time)",
        ("mjcffi/data.py", "header = ffi.buffer(p, _HEADER_SIZE)[:]", "header = bytes(_HEADER_SIZE)"),
        ["tests/test_structs.py"]),

    # -- more, on hot or subtle code
    _mutant(
        "plastic_span_start", "a named plastic span starts one entry late",
        ("mjcffi/_support/named.py", "view(pointer + max(adr, 0), dtype",
         "view(pointer + max(adr, 0) + 1, dtype"),
        ["tests/test_named_plastic.py"]),
    _mutant(
        "named_row_stride", "a named row is found at id, not id * columns",
        ("mjcffi/_support/named.py", "return view(pointer + i * columns, dtype, (columns,), acc._root)",
         "return view(pointer + i, dtype, (columns,), acc._root)"),
        ["tests/test_named.py"]),
    _mutant(
        "pickle_arena", "a pickled MjData leaves out its arena (contacts, constraints)",
        ("mjcffi/data.py", "ffi.buffer(p.arena, p.parena)[:]", "ffi.buffer(p.arena, 0)[:]"),
        ["tests/test_structs.py"]),
    _mutant(
        "named_id_bound", "named access by id takes id == count",
        ("mjcffi/_support/named.py", "if not 0 <= element_id < count:",
         "if not 0 <= element_id <= count:"),
        ["tests/test_named_conformance.py", "tests/test_named.py"]),
    _mutant(
        "object_id_count", "mj_objectVelocity takes objid == nbody",
        ("mjcffi/_support/marshal.py", "index(objid, getattr(model, field), name)",
         "index(objid, getattr(model, field) + 1, name)"),
        ["tests/test_mutation_gaps.py"]),
    _mutant(
        "vector_any_shape", "a vector argument takes any shape of its size",
        ("mjcffi/_support/marshal.py", "if array.shape == (n,) or array.shape == (n, 1):",
         "if array.size == n:"),
        ["tests/test_function_layer.py", "tests/test_function_conformance.py"]),
    _mutant(
        "view_keepalive", "a view no longer keeps its model's memory alive",
        ("mjcffi/_support/views.py", "ffi.buffer(ffi.gc(pointer, _KeepAlive(root)), count * dtype.itemsize)",
         "ffi.buffer(pointer, count * dtype.itemsize)"),
        ["tests/test_structs.py::test_views_outlive_their_owners", "tests/test_named.py"]),
    _mutant(
        "gravcomp_mirror", "m.flg_gravcomp = True leaves ngravcomp at 0",
        ("mjcffi/_support/views.py", "            setattr(self._ptr, mirror, 1 if value else 0)",
         "            pass"),
        ["tests/test_struct_conformance.py"]),
    _mutant(
        "csr_bound", "a sparse structure may address one element past the matrix",
        ("mjcffi/_support/marshal.py", "int((rowadr.astype(np.int64) + rownnz).max()) > nnz):",
         "int((rowadr.astype(np.int64) + rownnz).max()) > nnz + 1):"),
        ["tests/test_mutation_gaps.py"]),
    _mutant(
        "quat_angle_acos", "the shared rotation angle back to 2*acos(min(1, c))",
        ("mjcffi/evaluation/measures.py",
         "return 2.0 * np.arctan2(np.linalg.norm(v, axis=1), np.abs(w))",
         "return 2.0 * np.arccos(np.minimum(1.0, np.abs(w)))"),
        ["tests/test_accuracy.py"]),

    _mutant(
        "replay_without_extra", "set_state ignores the warm start the state carries",
        ("mjcffi/sim/_sim.py", "            mj_setState(self.model, d, extra, EXTRA_SIG)",
         "            pass"),
        ["tests/test_sim_replay.py"]),

    # -- in the generator: regenerated in the copy
    _mutant(
        "codegen_id_bound", "the generated id checks allow one past the count",
        ("codegen/functions.py", "not {low} <= {py} < {limit}:",
         "not {low} <= {py} <= {limit}:"),
        ["tests/test_mutation_gaps.py"], regenerate=True),
    _mutant(
        "codegen_tendon_plastic", "tendons lose their named plastic state",
        ("codegen/named.py", 'PLASTIC = {"jnt": "jnt_plasticadr", "tendon": "tendon_plasticadr"}',
         'PLASTIC = {"jnt": "jnt_plasticadr"}'),
        ["tests/test_named_plastic.py", "tests/test_named.py"], regenerate=True),
    # -- the fast paths and prepared calls (issue 25)
    _mutant(
        "fastpath_output_layout", "a fast path takes a read-only or misaligned output",
        ("codegen/fastpath.py", 'test.append(f"{a.py}.flags.carray")', "pass"),
        ["tests/test_fast_path.py"], regenerate=True),
    _mutant(
        "fastpath_id_bound", "a fast path lets an id equal to its count through",
        ("codegen/fastpath.py", 'f"{low} <= {py} < {limit}"', 'f"{low} <= {py} <= {limit}"'),
        ["tests/test_fast_path.py"], regenerate=True),
    _mutant(
        "fastpath_shape", "a fast path checks a vector's size, not its shape",
        ("codegen/fastpath.py", 'test.append(f"{a.py}.shape == {shape}")',
         'test.append(f"{a.py}.size == ({shape}[0] if len({shape}) == 1 else '
         '{shape}[0] * {shape}[1])")'),
        ["tests/test_fast_path.py"], regenerate=True),
    _mutant(
        "prepare_copies_inputs", "prepare binds a converted copy of an input",
        ("mjcffi/_support/marshal.py", "    if live and value is not given", "    if False and live"),
        ["tests/test_prepared.py"]),
    _mutant(
        "prepare_never_rechecks", "a prepared call skips the checks of what can change",
        ("mjcffi/_support/prepared.py", "if self._marshal is None or self._recheck:",
         "if self._marshal is None:"),
        ["tests/test_prepared.py"]),
    _mutant(
        "name2id_memo_keys_floats", "mj_name2id's memo answers a float type",
        ("mjcffi/functions/_overrides.py", "_OBJECT_TYPES = (int, mjtObj)", "_OBJECT_TYPES = (int, mjtObj, float)"),
        ["tests/test_prepared.py"]),
    # -- Ctrl-C, claims and fork (issue 34)
    _mutant(
        "step_stopped_ignored", "an mj_step loop that a SIGINT stopped early returns quietly",
        ("mjcffi/_support/marshal.py", "    if status != _STOPPED:\n        return check(status)",
         "    if True:\n        return check(0 if status == _STOPPED else status)"),
        ["tests/test_interrupt.py::"
         "test_a_sigint_handler_that_does_not_raise_still_stops_the_loop_loudly"]),
    _mutant(
        "rollout_data_unclaimed", "a rollout does not hold its MjData",
        ("mjcffi/_c/rollout.c", "rollout_work, &job, d, pool ? pool->nthread : 1,",
         "rollout_work, &job, d, 0,"),
        ["tests/test_rollout_claims.py"]),
    _mutant(
        "rollout_claim_not_adopted", "a rollout's pool thread leaves its data's claim the caller's",
        ("mjcffi/_c/rollout.c", "    mjcffi_data_adopt(d);", "    (void)d;"),
        ["tests/test_rollout_claims.py"]),
    _mutant(
        "claim_outside_try", "Rollout._call registers its caller before the try that "
        "releases it",
        ("mjcffi/rollout.py", "        try:\n            if claim is not None:\n"
         "                scopes.append(claim)\n            self._callers.add(me)\n",
         "        self._callers.add(me)\n        try:\n            if claim is not None:\n"
         "                scopes.append(claim)\n"),
        ["tests/test_claims_interrupt_safe.py"]),
    _mutant(
        "fork_handler_off", "the claim table has no fork handler",
        ("mjcffi/_c/claims.c", "  pthread_atfork(claims_before_fork,",
         "  if (0) pthread_atfork(claims_before_fork,"),
        ["tests/test_fork.py"]),
    _mutant(
        "batch_fork_unrefused", "a Batch with threads made before fork is called in the child",
        ("mjcffi/batch/_batch.py", "            _threaded.add(self)", "            pass"),
        ["tests/test_fork.py"]),
]


# ----------------------------------------------------------------- the copy

def _tree_files():
    """The files of the tree as git sees them (tracked, or new and not ignored)."""
    listed = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                            cwd=REPO, check=True, capture_output=True).stdout
    files = [name for name in listed.decode().split("\0") if name]
    files += [str(p.relative_to(REPO)) for pattern in ("_mjcffi*.so", "_descriptors*.so")
              for p in (REPO / "mjcffi").glob(pattern)]
    return sorted({f for f in files if (REPO / f).is_file()})


def _env():
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")     # no .pyc to go stale between edits
    env.pop("PYTHONPATH", None)
    return env


def _copy(files, source, dest):
    for name in files:
        target = dest / name
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source / name, target)


def _check_import(tree):
    """`import mjcffi` in the copy must import the copy."""
    found = subprocess.run([sys.executable, "-c", "import mjcffi; print(mjcffi.__file__)"],
                           cwd=tree, env=_env(), capture_output=True, text=True)
    path = found.stdout.strip()
    if found.returncode or not pathlib.Path(path).resolve().is_relative_to(tree.resolve()):
        sys.exit(f"the copy does not import its own mjcffi: {path or found.stderr[-2000:]}")


def _apply(mutant, tree):
    """Apply the edits in `tree`; return None, or why the mutant is stale."""
    for path, old, new in mutant.edits:
        file = tree / path
        text = file.read_text()
        found = text.count(old)
        if found != 1:
            return f"{path}: the old text occurs {found} times"
        file.write_text(text.replace(old, new))
    return None


def _codegen(tree, out):
    run = subprocess.run([sys.executable, "-m", "codegen", "--out", str(out)], cwd=tree,
                         env=_env(), capture_output=True, text=True)
    if run.returncode:
        raise RuntimeError(f"codegen failed:\n{run.stderr[-3000:]}")
    return {str(p.relative_to(out)): p.read_text() for p in out.rglob("*") if p.is_file()}


def _rebuild(tree):
    """Compile the (mutated) C module in `tree`; None, or the compiler's complaint."""
    run = subprocess.run([sys.executable, "setup.py", "build_ext", "--inplace"], cwd=tree,
                         env=_env(), capture_output=True, text=True)
    if run.returncode:
        errors = [line for line in run.stderr.splitlines() if "error" in line]
        return (errors or run.stderr.splitlines() or ["no output"])[-1]
    return None


def _regenerate(tree, baseline, scratch):
    """Write into `tree` the generated files that the mutated codegen writes otherwise."""
    mutated = _codegen(tree, scratch)
    changed = [name for name, text in mutated.items() if baseline.get(name) != text]
    for name in changed:
        (tree / name).write_text(mutated[name])
    return changed


# ------------------------------------------------------------------ running

@dataclasses.dataclass
class Result:
    mutant: Mutant
    verdict: str
    detail: str = ""
    seconds: float = 0.0


def _pytest(tree, tests, timeout, stop_first=True):
    command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--no-header",
               "-rf", *(["-x"] if stop_first else []), *tests]
    try:
        run = subprocess.run(command, cwd=tree, env=_env(), capture_output=True, text=True,
                             timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, ""
    return run.returncode, run.stdout + run.stderr


def _failures(output):
    """The node ids of the failed tests in pytest's short summary."""
    return [line.split(" - ")[0].split(" ", 1)[1] for line in output.splitlines()
            if line.startswith(("FAILED ", "ERROR "))]


def _first_failure(output):
    failed = _failures(output)
    return failed[0] if failed else ""


def _verdict(code, output):
    if code is None:
        return "timeout", ""
    if code == 0:
        return "missed", ""
    if code == 1:
        return "caught", _first_failure(output)
    if code < 0 or code >= 128 or "Fatal Python error" in output:
        return "crashed", f"exit status {code}"
    tail = [line for line in output.splitlines() if line.strip()][-3:]
    return "broken", f"pytest exit status {code}: {' | '.join(tail)}"


def run_mutant(mutant, files, pristine, baseline, tests, timeout):
    """Copy the pristine tree, apply `mutant`, run `tests` there: its Result."""
    start = time.monotonic()
    with tempfile.TemporaryDirectory(prefix=f"mutant-{mutant.name}-") as folder:
        tree = pathlib.Path(folder) / "tree"
        _copy(files, pristine, tree)
        stale = _apply(mutant, tree)
        if stale:
            return Result(mutant, "stale", stale)
        if mutant.regenerate:
            try:
                changed = _regenerate(tree, baseline(), pathlib.Path(folder) / "generated")
            except RuntimeError as exc:
                return Result(mutant, "broken", str(exc).splitlines()[-1],
                              time.monotonic() - start)
            if not changed:
                return Result(mutant, "missed", "the generated files do not change",
                              time.monotonic() - start)
        if mutant.rebuild:
            failed = _rebuild(tree)
            if failed:
                return Result(mutant, "broken", f"the C does not compile: {failed}",
                              time.monotonic() - start)
        code, output = _pytest(tree, tests, timeout)
        verdict, detail = _verdict(code, output)
        return Result(mutant, verdict, detail, time.monotonic() - start)


# ------------------------------------------------------------------ report

def _table(results, markdown):
    rows = [("mutant", "the bug", "expected to be caught by", "verdict", "first failing test")]
    for r in results:
        rows.append((r.mutant.name, r.mutant.what, ", ".join(r.mutant.tests), r.verdict,
                     r.detail))
    if markdown:
        lines = ["| " + " | ".join(rows[0]) + " |", "|" + "---|" * len(rows[0])]
        lines += ["| " + " | ".join(cell.replace("|", "\\|") for cell in row) + " |"
                  for row in rows[1:]]
        return "\n".join(lines)
    lines = []
    for r in results:
        lines.append(f"{r.verdict:8} {r.mutant.name:24} {r.seconds:6.1f} s  {r.mutant.what}")
        lines.append(f"{'':42}expected: {', '.join(r.mutant.tests)}")
        if r.detail:
            lines.append(f"{'':42}{r.detail}")
    return "\n".join(lines)


def _select(names):
    if not names:
        return MUTANTS
    chosen = [m for m in MUTANTS if any(m.name == n or m.name.startswith(n) for n in names)]
    if not chosen:
        sys.exit(f"no mutant named {', '.join(names)}; see --list")
    return chosen


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m tests.mutants",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help="mutants to run (names or prefixes); all if none")
    parser.add_argument("--list", action="store_true", help="list the mutants and exit")
    parser.add_argument("--full", action="store_true",
                        help="run the whole test suite for each mutant, not its selection")
    parser.add_argument("--no-baseline", action="store_true",
                        help="skip the run of the selections on the unmutated copy")
    parser.add_argument("--markdown", action="store_true", help="print the table as markdown")
    parser.add_argument("--timeout", type=float, default=900,
                        help="seconds per mutant's test run (default 900)")
    args = parser.parse_args(argv)
    mutants = _select(args.names)
    if args.list:
        for m in mutants:
            print(f"{m.name:24} {m.what}\n{'':24} {', '.join(m.tests)}")
        return 0

    files = _tree_files()
    with tempfile.TemporaryDirectory(prefix="mutants-base-") as folder:
        pristine = pathlib.Path(folder) / "tree"
        _copy(files, REPO, pristine)     # one snapshot: the tree may change meanwhile
        _check_import(pristine)
        generated = {}

        def baseline():
            if not generated:
                generated.update(_codegen(pristine, pathlib.Path(folder) / "generated"))
            return generated

        selections = sorted({t for m in mutants for t in m.tests})
        if args.full:
            selections = ["tests"]
        if not args.no_baseline:
            print(f"baseline: {len(selections)} test selections on the unmutated copy ...",
                  flush=True)
            code, output = _pytest(pristine, selections, args.timeout * 2, stop_first=False)
            known = _failures(output)
            if code not in (0, 1) or (code == 1 and not known):
                print(output[-5000:])
                sys.exit("the unmutated tree cannot run these tests: no verdict would mean "
                         "anything")
            for node in known:
                print(f"  fails unmutated, deselected: {node}")
            deselect = [arg for node in known for arg in ("--deselect", node)]
        else:
            deselect = []

        results = []
        for mutant in mutants:
            tests = ["tests"] if args.full else list(mutant.tests)
            result = run_mutant(mutant, files, pristine, baseline, tests + deselect,
                                args.timeout)
            results.append(result)
            print(f"{result.verdict:8} {mutant.name} ({result.seconds:.1f} s) {result.detail}",
                  flush=True)
    print()
    print(_table(results, args.markdown))
    killed = sum(r.verdict in ("caught", "crashed") for r in results)
    print(f"\n{killed} of {len(results)} mutants caught")
    return 0 if killed == len(results) else 1


if __name__ == "__main__":
    sys.exit(main())
