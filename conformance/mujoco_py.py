"""python -m conformance mujoco_py [FILE ...] [--write]: mujoco-py's own tests against mjcffi.sim.

The test files of mujoco-py's wheel (PyPI, cached in ~/.cache/mjcffi/) run
from a temporary folder in which `mujoco_py` is mjcffi.sim
(conformance/_mujoco_py_alias.py), each file in its own pytest process with
the official runner's JSON-line log, so a crash still names its test.

mujoco-py's `compare_imgs` compares renders with reference images that the
wheel does not ship (and MuJoCo 2.1's images would not apply: MuJoCo 4
renders differently).  So each file runs twice against one temporary image
folder: first with REGENERATE_TEST_IMAGES=1, which writes mjcffi's own
renders, then the counted run, in which compare_imgs checks that mjcffi
renders the same images again.  Rendering is MUJOCO_GL=egl, except in the
files that open GLFW windows (X_FILES), which run under MUJOCO_GL=glfw and
an X server: the display there is, or Xvfb through xvfb-run.
"""

import argparse
import json
import os
import pathlib
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

from . import _mujoco_py_notes as notes
from . import _mujoco_py_report as report
from . import _mujoco_py_wheel as wheel
from .runner import _LOGGER, Outcome, _result

# Files whose tests open GLFW windows or contexts: they need an X server.
X_FILES = ("test_opengl_context.py", "test_viewer.py")
NO_X_SERVER = "no DISPLAY and no xvfb-run: install the xvfb package (apt-get install xvfb)"

# Marks every test that CONFORMANCE_SKIPS names ([[pattern, reason], ...]) as skipped.
_SKIPPER = '''
import fnmatch, json, os
import pytest

_SKIPS = json.loads(os.environ.get("CONFORMANCE_SKIPS", "[]"))


def pytest_collection_modifyitems(items):
    for item in items:
        test = item.nodeid.split(".py::", 1)[-1]
        for pattern, reason in _SKIPS:
            if fnmatch.fnmatchcase(test, pattern):
                item.add_marker(pytest.mark.skip(reason=reason))
                break
'''

_PYTEST_INI = "[pytest]\nmarkers =\n    requires_rendering\n    requires_glfw\n"


def x_server_prefix():
    """The command prefix that gives an X server: [] under a DISPLAY, xvfb-run's, or None."""
    if os.environ.get("DISPLAY"):
        return []
    if shutil.which("xvfb-run"):
        return ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24"]
    return None


class Workspace:
    """A temporary folder that holds `mujoco_py` (alias + extracted tests) and the plugins."""

    def __init__(self, wheel_path):
        self._tmp = tempfile.TemporaryDirectory(prefix="conformance-mujoco_py-")
        self.folder = pathlib.Path(self._tmp.name)
        self.tests = wheel.extract(wheel_path, self.folder)
        self.images = self.folder / "images"
        self.images.mkdir()
        (self.folder / "pytest.ini").write_text(_PYTEST_INI)
        (self.folder / "_conformance_log.py").write_text(_LOGGER)
        (self.folder / "_conformance_skips.py").write_text(_SKIPPER)

    def files(self):
        return sorted(p.name for p in self.tests.glob("test_*.py"))

    def close(self):
        self._tmp.cleanup()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _environment(workspace, log, skips, backend, regenerate):
    env = dict(os.environ, CONFORMANCE_LOG=str(log), CONFORMANCE_SKIPS=json.dumps(skips),
               PYTHONDONTWRITEBYTECODE="1", MUJOCO_GL=backend,
               MUJOCO_PY_TEST_ASSET_DIR_PATH=str(workspace.images),
               PYTHONPATH=os.pathsep.join(filter(None, [str(workspace.folder),
                                                        os.environ.get("PYTHONPATH")])))
    env.pop("REGENERATE_TEST_IMAGES", None)
    if regenerate:
        env["REGENERATE_TEST_IMAGES"] = "1"
    return env


def _pytest(command, cwd, env, timeout):
    """Run `command` in its own session; (returncode or None on timeout, output)."""
    with subprocess.Popen(command, cwd=cwd, env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, start_new_session=True) as proc:
        try:
            output, _ = proc.communicate(timeout=timeout)
            return proc.returncode, output
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)     # xvfb-run, pytest and their children
            proc.communicate()
            return None, ""


def run_file(workspace, name, timeout=900, keyword=None):
    """Run mujoco-py's test file `name` twice (images, then counted); its FileResult."""
    skips = notes.skips(name)
    prefix, backend = [], "egl"
    if name in X_FILES:
        backend, prefix = "glfw", x_server_prefix()
        if prefix is None:
            skips, prefix = skips + [("*", NO_X_SERVER)], []
    command = prefix + [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                        "-p", "_conformance_log", "-p", "_conformance_skips",
                        "-c", str(workspace.folder / "pytest.ini"),
                        "--rootdir", str(workspace.folder), wheel.TESTS + name]
    if keyword:
        command += ["-k", keyword]
    images = _run_once(workspace, name, command, skips, backend, True, timeout)
    result = _run_once(workspace, name, command, skips, backend, False, timeout)
    _blame_the_images_run(result, images)
    _mark_not_applicable(result)
    return result


def _run_once(workspace, name, command, skips, backend, regenerate, timeout):
    log = workspace.folder / f"{name}.{'images' if regenerate else 'counted'}.jsonl"
    log.touch()
    env = _environment(workspace, log, skips, backend, regenerate)
    start = time.perf_counter()
    returncode, output = _pytest(command, workspace.folder, env, timeout)
    seconds = time.perf_counter() - start
    records = [json.loads(line) for line in log.read_text().splitlines() if line]
    result = _result(name, records, returncode, output, seconds)
    # The same text whatever the temporary folder, so that CONFORMANCE.md is stable.
    result.collect_error = re.sub(r"^E\s+", "", result.collect_error.strip()).replace(
        str(workspace.folder), "$TMP")
    for outcome in result.tests.values():
        outcome.message = outcome.message.replace(str(workspace.folder), "$TMP")
    if result.collect_error and not result.tests:
        ids = wheel.source_test_ids(workspace.tests / name)
        result.tests = {t: Outcome("failed", "cannot be imported: " + result.collect_error)
                        for t in ids}
    return result


def _blame_the_images_run(result, images):
    """Name the first cause of a failure whose image the first run never saved.

    A test that failed before its compare_imgs in the run that saves the images
    fails on the missing file in the counted run; its first run's message says why.
    """
    for test, outcome in result.tests.items():
        first = images.tests.get(test)
        if (outcome.outcome == "failed" and "$TMP/images/" in outcome.message
                and first is not None and first.outcome not in ("passed", "xfailed", "skipped")):
            outcome.message = (f"{first.message or first.outcome} "
                               "(in the run that saves the images)")


def _mark_not_applicable(result):
    """Turn the skips of not-applicable tests into outcome 'not applicable'."""
    for test, outcome in result.tests.items():
        note = notes.classify(result.name, test)
        if note is not None:
            outcome.outcome, outcome.message = "not applicable", note.reason


def run_all(names=None, keyword=None, progress=None):
    """{file: FileResult} for `names` (default: every test file of the wheel)."""
    with Workspace(wheel.wheel()) as workspace:
        unknown = sorted(set(names or ()) - set(workspace.files()))
        if unknown:
            raise ValueError(f"no such mujoco-py test file: {', '.join(unknown)}")
        results = {}
        for name in names or workspace.files():
            results[name] = run_file(workspace, name, keyword=keyword)
            if progress:
                progress(report.summary_line(results[name]))
        return results


def _file_name(arg):
    return arg if arg.endswith(".py") else f"test_{arg.removeprefix('test_')}.py"


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m conformance mujoco_py",
                                     description=__doc__.splitlines()[0].split(": ", 1)[1])
    parser.add_argument("files", nargs="*", help="mujoco-py test files, e.g. cymj or "
                        "test_cymj.py (default: all)")
    parser.add_argument("--write", action="store_true",
                        help=f"write the section into {report.CONFORMANCE.name}")
    parser.add_argument("-k", dest="keyword", help="pytest -k expression")
    parser.add_argument("--failures", action="store_true",
                        help="print each failing test and its message")
    args = parser.parse_args(argv)
    if args.write and (args.files or args.keyword):
        parser.error("--write needs the full run: no FILE or -k")
    names = [_file_name(f) for f in args.files]
    try:
        results = run_all(names, args.keyword, lambda line: print(line, file=sys.stderr))
    except wheel.WheelUnavailable as error:
        sys.exit(f"python -m conformance mujoco_py: {error}")
    except ValueError as error:
        parser.error(str(error))
    if args.failures:
        for line in report.failure_lines(results):
            print(line)
    section = report.render(results)
    if args.write:
        report.write(section)
        print(f"wrote {report.CONFORMANCE}", file=sys.stderr)
    elif not args.failures:
        print(section)
