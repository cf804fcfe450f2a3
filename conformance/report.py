"""python -m conformance [FILE ...] [--write]: the official test files against mjcffi.

Prints the report (CONFORMANCE.md's text); --write writes it.  FILE names
official test files ('bindings' or 'bindings_test.py'); the default is all of
them.  -k passes a pytest keyword expression through, for working on a few
tests; --failures lists every failing test with its message.
"""

import argparse
import pathlib
import re
import sys

from mjcffi._support.machine import environment

from . import _mujoco_py_report, mjx, notes
from .runner import official_files, run_file

CONFORMANCE = pathlib.Path(__file__).resolve().parent.parent / "CONFORMANCE.md"
# A section of CONFORMANCE.md written by hand (the enum audit of issue 28).
STRICTNESS = "# Strictness beyond the official bindings"

# Files that need an OpenGL context or a window; the rest run anywhere.
GL_FILES = ("egl_test.py", "render_test.py", "renderer_test.py", "viewer_test.py")


def non_gl_files():
    return [name for name in official_files() if name not in GL_FILES]


def _file_name(arg):
    """'bindings' -> 'bindings_test.py'; a subpackage's file is named in full
    ('sysid/tests/test_signal.py')."""
    return arg if arg.endswith(".py") else f"{arg}_test.py"


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m conformance",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="*", help="official test files (default: all)")
    parser.add_argument("--write", action="store_true", help=f"write {CONFORMANCE.name}")
    parser.add_argument("--no-official", action="store_true",
                        help="do not also run the files against the official bindings")
    parser.add_argument("-k", dest="keyword", help="pytest -k expression")
    parser.add_argument("--failures", action="store_true",
                        help="print each failing test and its message")
    args = parser.parse_args(argv)
    names = [_file_name(f) for f in args.files] or official_files()
    unknown = sorted(set(names) - set(official_files()))
    if unknown:
        parser.error(f"no such official test file: {', '.join(unknown)}")
    if args.write and (args.files or args.keyword or args.no_official):
        parser.error("--write needs the full run: no FILE, -k or --no-official")

    ours, theirs = {}, {}
    for name in names:
        ours[name] = run_file(name, "mjcffi", keyword=args.keyword)
        if not args.no_official:
            theirs[name] = run_file(name, "official", keyword=args.keyword)
        print(_summary_line(ours[name], theirs.get(name)), file=sys.stderr)
    if args.failures:
        for result in ours.values():
            for test, outcome in result.tests.items():
                if outcome.outcome not in ("passed", "xfailed", "skipped"):
                    print(f"{result.name}::{test}: {outcome.outcome}: {outcome.message}")
    text = render(ours, theirs)
    if args.write:
        # The mujoco-py section is written by `python -m conformance mujoco_py --write`,
        # the MJX one by `python -m conformance mjx --write`, the strictness audit by
        # hand: they are kept as they are.
        text = _mujoco_py_report.keep_section(CONFORMANCE, text)
        text = _mujoco_py_report.keep_section(CONFORMANCE, text, mjx.TITLE)
        text = _mujoco_py_report.keep_section(CONFORMANCE, text, STRICTNESS)
        CONFORMANCE.write_text(text)
        print(f"wrote {CONFORMANCE}", file=sys.stderr)
    elif not args.failures:
        print(text)


def _summary_line(ours, theirs):
    line = f"{ours.name}: mjcffi {ours.passed}/{len(ours.tests)} passed"
    if ours.collect_error:
        line += f" (collection error: {ours.collect_error})"
    if theirs is not None:
        line += f"; official {theirs.passed}/{len(theirs.tests)}"
    return line


# ------------------------------------------------------------------ report

def _total(ours, theirs):
    """The file's test count: the official run's when ours could not collect."""
    if theirs is not None and (ours.collect_error or len(theirs.tests) > len(ours.tests)):
        return len(theirs.tests)
    return len(ours.tests)


def _percent(passed, total, skipped):
    ran = total - skipped
    return f"{100 * passed / ran:.1f} %" if ran else "-"


def render(ours, theirs):
    lines = ["# Conformance with the official bindings' tests", "",
             "Written by `python -m conformance --write`. Each `*_test.py` file that ships in the "
             "installed `mujoco` package (the mujoco-core wheel), and the test files of its "
             "pure-Python subpackages (`sysid/tests/`, `usd/`, `introspect/`, which mjcffi runs "
             "from the official source: mjcffi.sysid, ...), runs against mjcffi with "
             "`import mujoco` rewritten to `import mjcffi as mujoco`, in a temporary folder; the "
             "files are not copied into this repository. The same files also run unmodified "
             "against the official bindings on the same machine. `tests/test_conformance.py` "
             "fails if a file that needs no OpenGL passes fewer tests than this table says. The "
             "rendering files need an OpenGL driver (Debian's Mesa); where it is missing, most "
             "of their tests skip or fail under both bindings. The sysid files need mjcffi's "
             "`sysid` extra, `usd/exporter_test.py` its `usd` extra (usd-core); without them "
             "their tests skip, under both bindings. MJX, which needs jax, is checked by "
             "`python -m conformance mjx` (its section below).", ""]
    lines += environment(("mjcffi", "mujoco-core", "numpy", "cffi", "pytest", "absl-py")) + [""]
    lines += ["| file | tests | mjcffi passed | failed | skipped | mjcffi pass rate "
              "| official passed |",
              "|---|---:|---:|---:|---:|---:|---:|"]
    for name, result in ours.items():
        other = theirs.get(name)
        total = _total(result, other)
        failed = total - result.passed - result.count("skipped")
        lines.append(f"| `{name}` | {total} | {result.passed} | {failed} | "
                     f"{result.count('skipped')} | "
                     f"{_percent(result.passed, total, result.count('skipped'))} | "
                     f"{_official_cell(other)} |")
    lines += [""] + _failures(ours)
    return "\n".join(lines).rstrip("\n") + "\n"


def _official_cell(result):
    if result is None:
        return "not run"
    if result.collect_error:
        return "cannot be imported: " + result.collect_error.removeprefix("E   ")
    skipped = result.count("skipped")
    return f"{result.passed} of {len(result.tests) - skipped}" + \
        (f" ({skipped} skipped)" if skipped else "")


def _failures(ours):
    """The remaining failures, grouped by kind, then by reason."""
    groups = {}            # (kind, reason) -> [test ids]
    for name, result in ours.items():
        if result.collect_error:
            note = notes.classify(name, "")
            key = (note.kind, note.reason) if note else \
                (notes.GAP, f"unclassified: the file cannot be imported: {result.collect_error}")
            groups.setdefault(key, []).append(f"`{name}` (all tests: it cannot be imported)")
            continue
        for test, outcome in result.tests.items():
            if outcome.outcome in ("passed", "xfailed", "skipped"):
                continue
            note = notes.classify(name, test)
            if note is not None:
                key = (note.kind, note.reason)
            else:
                key = (notes.GAP, "unclassified: " + _first_line(outcome))
            groups.setdefault(key, []).append(f"`{name}::{test}`")
    if not groups:
        return ["No failures."]
    lines = ["## Remaining failures", ""]
    for kind, title in ((notes.DELIBERATE, "Deliberate differences"),
                        (notes.NOT_APPLICABLE, "Not applicable"),
                        (notes.GAP, "Gaps")):
        entries = [(reason, tests) for (k, reason), tests in groups.items() if k == kind]
        if not entries:
            continue
        lines += [f"### {title} ({sum(len(t) for _, t in entries)} tests)", ""]
        for reason, tests in entries:
            lines += [f"- {reason}", ""] + [f"  - {t}" for t in tests] + [""]
    return lines


def _first_line(outcome):
    message = (outcome.message or outcome.outcome).strip().splitlines()
    text = message[0] if message else outcome.outcome
    return (text[:200] + "…") if len(text) > 200 else text


# ------------------------------------------------------- committed figures

_ROW = re.compile(r"^\| `(?P<name>[\w/]+\.py)` \| (?P<total>\d+) \| (?P<passed>\d+) \|")


def committed_passes(path=CONFORMANCE):
    """file -> the mjcffi pass count that the committed CONFORMANCE.md records (its
    first section: the official files)."""
    figures = {}
    for number, line in enumerate(pathlib.Path(path).read_text().splitlines()):
        if number and line.startswith("# "):
            break                       # the next section (mujoco-py's, MJX's, ...)
        match = _ROW.match(line)
        if match:
            figures[match["name"]] = int(match["passed"])
    return figures
