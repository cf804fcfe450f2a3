"""The "mujoco-py's own tests" section of CONFORMANCE.md: written, parsed and kept.

The section starts at its title line and runs to the next top-level heading
or the end of the file.  `python -m conformance mujoco_py --write` replaces
it (or appends it); `python -m conformance --write`, which rewrites the rest
of the file, keeps it (`keep_section`).  tests/test_conformance_mujoco_py.py
reads the pass counts back (`committed_passes`).
"""

import pathlib
import re

from mjcffi._support.machine import environment

from . import _mujoco_py_wheel as wheel

CONFORMANCE = pathlib.Path(__file__).resolve().parent.parent / "CONFORMANCE.md"
TITLE = "# mujoco-py's own tests"

_ROW = re.compile(r"^\| `(?P<name>test_\w+\.py)` \| (?P<total>\d+) \| (?P<passed>\d+) \|")
_PASSING = ("passed", "xfailed")


# ------------------------------------------------------------------ figures

def counts(result):
    """(tests, passed, failed, skipped, not applicable) of one FileResult."""
    total = len(result.tests)
    passed = result.count(*_PASSING)
    skipped = result.count("skipped")
    excluded = result.count("not applicable")
    return total, passed, total - passed - skipped - excluded, skipped, excluded


def _rate(passed, failed):
    return f"{100 * passed / (passed + failed):.1f} %" if passed + failed else "-"


def summary_line(result):
    total, passed, failed, skipped, excluded = counts(result)
    line = (f"{result.name}: {passed} passed, {failed} failed, {skipped} skipped, "
            f"{excluded} not applicable (of {total})")
    if result.collect_error:
        line += f"; cannot be imported: {first_line(result.collect_error)}"
    return line


def first_line(message):
    lines = (message or "").strip().splitlines()
    text = lines[0] if lines else ""
    return (text[:200] + "…") if len(text) > 200 else text


def failure_lines(results):
    """'file::test: outcome: message' for every applicable test that did not pass or skip."""
    return [f"{name}::{test}: {outcome.outcome}: {outcome.message}"
            for name, result in results.items() for test, outcome in result.tests.items()
            if outcome.outcome not in _PASSING + ("skipped", "not applicable")]


# ------------------------------------------------------------------ section

_INTRO = (
    "Written by `python -m conformance mujoco_py --write`. The test files of mujoco-py "
    f"{wheel.VERSION}'s wheel (downloaded from PyPI with pip into `~/.cache/mjcffi/`) are "
    "extracted into a temporary folder, never into this repository, beside a `mujoco_py` "
    "package that calls `mjcffi.sim.install_as_mujoco_py()`, as a user would "
    "(`conformance/_mujoco_py_alias.py`): `mujoco_py` is then mjcffi.sim and every mujoco-py "
    "module path gives mjcffi's module; each file runs in its own pytest process. "
    "`tests/test_conformance_mujoco_py.py` fails if a file passes fewer tests than this table "
    "says.")

_IMAGES = (
    "Images: mujoco-py's `compare_imgs` compares renders with reference images that its wheel "
    "does not ship, made with MuJoCo 2.1, which renders differently from MuJoCo 4; they are "
    "not applicable. Instead each file runs twice against one temporary image folder: once "
    "with `REGENERATE_TEST_IMAGES=1`, which saves mjcffi's own renders, then the counted run, "
    "in which `compare_imgs` checks that mjcffi renders the same images again. Rendering uses "
    "`MUJOCO_GL=egl`; `test_viewer.py` and `test_opengl_context.py` open GLFW windows and run "
    "under `MUJOCO_GL=glfw` with an X server (Xvfb through `xvfb-run` when there is no "
    "display).")


_RENDER_POOL = (
    "`test_render_pool.py::test_multiprocessing` passes without testing the pool: it means to "
    "run the file's `mp_test_*` functions in a subprocess, but passes a list to "
    "`subprocess.check_call` with `shell=True`, so only a bare `python` runs. Those functions "
    "pass when the file is run as a script (`python test_render_pool.py` beside the mapped "
    "`mujoco_py`), and `tests/test_render_pool.py` checks the pool's images against single "
    "renders bit for bit.")


def render(results):
    """The section's Markdown text for {file: FileResult}."""
    lines = [TITLE, "", _INTRO, "", _IMAGES, "", _RENDER_POOL, ""]
    lines += environment(("mjcffi", "mujoco-core", "numpy", "pytest", "pillow", "imagehash"))
    lines += ["", "| file | tests | passed | failed | skipped | not applicable | pass rate |",
              "|---|---:|---:|---:|---:|---:|---:|"]
    sums = [0] * 5
    for name, result in results.items():
        figures = counts(result)
        sums = [a + b for a, b in zip(sums, figures)]
        lines.append(f"| `{name}` | " + " | ".join(map(str, figures)) +
                     f" | {_rate(figures[1], figures[2])} |")
    lines.append("| all | " + " | ".join(map(str, sums)) + f" | {_rate(sums[1], sums[2])} |")
    lines += ["", f"Pass rate of the applicable tests that ran: {sums[1]} of {sums[1] + sums[2]}"
              f" ({_rate(sums[1], sums[2])}); skipped and not applicable tests are left out.",
              ""]
    lines += _listing(results)
    return "\n".join(lines).rstrip("\n") + "\n"


def _listing(results):
    failures, skipped, excluded = [], [], {}
    for name, result in results.items():
        for test, outcome in result.tests.items():
            test_id = f"`{name}::{test}`"
            if outcome.outcome == "not applicable":
                excluded.setdefault(outcome.message, []).append(test_id)
            elif outcome.outcome == "skipped":
                skipped.append(f"- {test_id}: {first_line(outcome.message)}")
            elif outcome.outcome not in _PASSING:
                failures.append(f"- {test_id} ({outcome.outcome}): "
                                f"{first_line(outcome.message) or 'no message'}")
    lines = []
    if excluded:
        lines += [f"## Not applicable ({sum(map(len, excluded.values()))} tests)", ""]
        for reason, tests in excluded.items():
            lines += [f"- {reason}", ""] + [f"  - {t}" for t in tests] + [""]
    lines += [f"## Failures ({len(failures)} tests)", ""] + (failures or ["None."]) + [""]
    if skipped:
        lines += [f"## Skipped ({len(skipped)} tests)", ""] + skipped + [""]
    return lines


# ------------------------------------------------------------ CONFORMANCE.md

def split(text, title=TITLE):
    """(text before the section, the section, text after it); section '' when absent.
    A section runs from its `# title` line to the next top-level heading."""
    lines = text.splitlines(keepends=True)
    try:
        start = next(i for i, line in enumerate(lines) if line.rstrip("\n") == title)
    except StopIteration:
        return text, "", ""
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("# ")),
               len(lines))
    return "".join(lines[:start]), "".join(lines[start:end]), "".join(lines[end:])


def replace_section(text, section, title=TITLE):
    """`text` with its section replaced by `section`, or `section` appended."""
    before, old, after = split(text, title)
    if not old:
        before = before.rstrip("\n") + "\n\n" if before.strip() else ""
    return before + section.rstrip("\n") + "\n" + (("\n" + after) if after else "")


def write(section, path=CONFORMANCE):
    path = pathlib.Path(path)
    path.write_text(replace_section(path.read_text() if path.exists() else "", section))


def keep_section(path, text, title=TITLE):
    """`text` (a new CONFORMANCE.md) with the section `title` (by default the mujoco-py
    one) that `path` holds now."""
    path = pathlib.Path(path)
    _, section, _ = split(path.read_text(), title) if path.exists() else ("", "", "")
    return replace_section(text, section, title) if section else text


def committed_passes(path=CONFORMANCE):
    """file -> the pass count that the committed section records."""
    _, section, _ = split(pathlib.Path(path).read_text())
    return {m["name"]: int(m["passed"]) for m in map(_ROW.match, section.splitlines()) if m}
