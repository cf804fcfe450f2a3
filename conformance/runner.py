"""Run one official test file, against mjcffi (import swapped) or the official bindings.

Each file runs in its own pytest process, from a fresh temporary folder that
holds an empty pytest.ini, the file rewritten for mjcffi, and a plugin that
logs every test's start and result as a JSON line as it happens.  So a
crash or a timeout still leaves the results before it, and names the test
that was running.
"""

import dataclasses
import importlib.util
import json
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import time

# The swap, applied to the whole text: import statements, `sys.modules`
# lookups and the code strings the tests run in subprocesses.
_REWRITES = (
    (re.compile(r"\bfrom mujoco(\.[\w.]+)? import\b"), r"from mjcffi\1 import"),
    (re.compile(r"\bimport mujoco\b(?![.\w])"), "import mjcffi as mujoco"),
    (re.compile(r"\bimport mujoco\.([\w.]+) as\b"), r"import mjcffi.\1 as"),
    (re.compile(r"""(sys\.modules\[['"])mujoco\."""), r"\1mjcffi."),
)
# The official package's own data (testdata/...): the tests find it beside the package
# they import, which under the swap is mjcffi's folder.
_RESOURCE = re.compile(r"""\bepath\.resource_path\(\s*(['"])mujoco\1\s*\)""")

# The test files of the official pure-Python subpackages (mjcffi.sysid, .usd,
# .introspect: mjcffi/_support/official_source.py), beside the top-level *_test.py.
SUBPACKAGE_TESTS = ("sysid/tests/test_*.py", "usd/exporter_test.py", "introspect/*_test.py")

# Logs each test's start and reports to $CONFORMANCE_LOG, one JSON object a line.
_LOGGER = '''
import gc, json, os

_LOG = open(os.environ["CONFORMANCE_LOG"], "a", buffering=1)


def _write(**record):
    _LOG.write(json.dumps(record) + "\\n")


def _message(report):
    longrepr = report.longrepr
    if isinstance(longrepr, tuple):           # a skip: (file, line, reason)
        return str(longrepr[2])
    crash = getattr(longrepr, "reprcrash", None)
    if crash is not None:
        return crash.message
    return str(longrepr).strip().splitlines()[-1] if longrepr else ""


def pytest_configure(config):
    # absltest's create_tempdir reads --test_tmpdir, which only absltest.main()
    # parses: under pytest, take the flags' defaults (a temporary folder)
    try:
        from absl import flags
    except ImportError:
        return
    if not flags.FLAGS.is_parsed():
        flags.FLAGS.mark_as_parsed()


def pytest_runtest_logstart(nodeid, location):
    _write(event="start", nodeid=nodeid)


def pytest_runtest_logreport(report):
    outcome = "xfailed" if hasattr(report, "wasxfail") else report.outcome
    if report.when == "call" or outcome != "passed":
        _write(event="report", nodeid=report.nodeid, when=report.when, outcome=outcome,
               subtest=type(report).__name__ == "SubtestReport",
               message="" if outcome == "passed" else _message(report))


def pytest_runtest_logfinish(nodeid, location):
    # Free what a test left in reference cycles (a failed test's traceback holds
    # its models and data) now, not inside a later test that counts MuJoCo's frees.
    gc.collect()


def pytest_collectreport(report):
    if report.failed:
        _write(event="collect_error", nodeid=report.nodeid, message=_message(report))
'''


@dataclasses.dataclass
class Outcome:
    """One test's result: passed, failed, skipped, xfailed, crashed or timeout."""
    outcome: str
    message: str = ""


@dataclasses.dataclass
class FileResult:
    """The results of one official test file."""
    name: str
    tests: dict                      # nodeid -> Outcome, in run order
    collect_error: str = ""
    returncode: int = 0
    seconds: float = 0.0

    def count(self, *outcomes):
        return sum(t.outcome in outcomes for t in self.tests.values())

    @property
    def passed(self):
        """Passes, counting an expected failure that failed as expected."""
        return self.count("passed", "xfailed")


def official_dir():
    """The folder of the installed official `mujoco` package (not imported here)."""
    spec = importlib.util.find_spec("mujoco")
    if spec is None or not spec.submodule_search_locations:
        raise RuntimeError("the official `mujoco` package is not installed: "
                           "pip install mujoco-core==4.0.0")
    return pathlib.Path(list(spec.submodule_search_locations)[0])


def official_files():
    """Names of the official test files, relative to the package: 'bindings_test.py',
    'sysid/tests/test_signal.py', ..."""
    root = official_dir()
    top = sorted(p.name for p in root.glob("*_test.py"))
    return top + sorted(p.relative_to(root).as_posix() for pattern in SUBPACKAGE_TESTS
                        for p in root.glob(pattern))


def swap_imports(text, package=""):
    """The test file's text with every use of `mujoco` turned into `mjcffi as mujoco`.

    `package` is the file's folder in the official package ('sysid/tests'): its
    relative imports (`from . import enums`) become absolute ones of that package,
    swapped too, since the copy runs outside it."""
    if package:
        dotted = "mujoco." + package.replace("/", ".")
        text = re.sub(r"^(\s*)from \.(\w*) import\b",
                      lambda m: f"{m[1]}from {dotted}{'.' + m[2] if m[2] else ''} import",
                      text, flags=re.M)
    for pattern, replacement in _REWRITES:
        text = pattern.sub(replacement, text)
    return _RESOURCE.sub(lambda m: f"epath.Path({str(official_dir())!r})", text)


def run_file(name, target="mjcffi", timeout=900, keyword=None):
    """Run official test file `name` against `target` ('mjcffi' or 'official').

    For mjcffi the file runs as a rewritten copy in a temporary folder; for the
    official bindings it runs where it was installed, as upstream runs it.
    """
    original = official_dir() / name
    package = pathlib.PurePosixPath(name).parent.as_posix().strip(".")
    with tempfile.TemporaryDirectory(prefix="conformance-") as folder:
        folder = pathlib.Path(folder)
        if target == "mjcffi":
            # a subpackage's file runs flat in the folder, with its conftest.py
            test_file = folder / original.name
            test_file.write_text(swap_imports(original.read_text(), package))
            conftest = original.with_name("conftest.py")
            if package and conftest.exists():
                (folder / "conftest.py").write_text(swap_imports(conftest.read_text(), package))
        else:
            test_file = original
        (folder / "pytest.ini").write_text("[pytest]\n")
        (folder / "_conformance_log.py").write_text(_LOGGER)
        log = folder / "results.jsonl"
        log.touch()
        command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                   "-p", "_conformance_log", "-c", str(folder / "pytest.ini"),
                   "--rootdir", str(folder), str(test_file)]
        if keyword:
            command += ["-k", keyword]
        path = os.pathsep.join(filter(None, [str(folder), os.environ.get("PYTHONPATH")]))
        env = dict(os.environ, CONFORMANCE_LOG=str(log), PYTHONDONTWRITEBYTECODE="1",
                   PYTHONPATH=path)
        start = time.perf_counter()
        try:
            done = subprocess.run(command, cwd=folder, env=env, capture_output=True,
                                  text=True, timeout=timeout)
            returncode, tail = done.returncode, done.stdout + done.stderr
        except subprocess.TimeoutExpired:
            returncode, tail = None, ""
        seconds = time.perf_counter() - start
        records = [json.loads(line) for line in log.read_text().splitlines() if line]
    return _result(name, records, returncode, tail, seconds)


def _result(name, records, returncode, tail, seconds):
    tests, collect_error = {}, ""
    for record in records:
        nodeid = record["nodeid"].split(".py::", 1)[-1]
        if record["event"] == "start":
            tests.setdefault(nodeid, Outcome("crashed" if returncode is not None else "timeout"))
        elif record["event"] == "collect_error":
            collect_error = record["message"]
        else:
            _merge(tests.setdefault(nodeid, Outcome("passed")), record)
    if returncode not in (0, 1, 5) and not tests and not collect_error:
        collect_error = f"pytest exited with {returncode}: " + tail.strip()[-300:]
    return FileResult(name, tests, collect_error, returncode if returncode is not None else -1,
                      seconds)


_RANK = {"crashed": 0, "timeout": 0, "passed": 1, "xfailed": 2, "skipped": 3, "failed": 4}


def _merge(outcome, record):
    """Fold one report into a test's outcome: a failure anywhere fails the test."""
    new = record["outcome"]
    if outcome.outcome in ("crashed", "timeout") or _RANK[new] > _RANK[outcome.outcome]:
        outcome.outcome = new
        if record["message"]:
            outcome.message = record["message"]
