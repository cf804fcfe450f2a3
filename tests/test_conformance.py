"""The official bindings' own test files keep passing against mjcffi (python -m conformance).

Every official test file that needs no OpenGL runs here with the import
swapped, and must pass at least as many tests as CONFORMANCE.md records.
"""

import pytest

from conformance import report, runner


def test_the_import_swap_reaches_every_form():
    text = ("import mujoco\nimport mujoco  # pytype\nfrom mujoco import rollout\n"
            "from mujoco.rollout import Rollout\nx = sys.modules['mujoco.egl']\n"
            "code = 'import mujoco; gl = mujoco.GLContext(64, 64)'\nimport mujoco_menagerie\n")
    assert runner.swap_imports(text) == (
        "import mjcffi as mujoco\nimport mjcffi as mujoco  # pytype\nfrom mjcffi import rollout\n"
        "from mjcffi.rollout import Rollout\nx = sys.modules['mjcffi.egl']\n"
        "code = 'import mjcffi as mujoco; gl = mujoco.GLContext(64, 64)'\n"
        "import mujoco_menagerie\n")


def test_a_subpackage_file_is_swapped_with_its_package_and_the_official_data():
    text = ("from . import enums\nfrom .ast_nodes import ValueType\n"
            "import mujoco.rollout as rollout\n"
            "path = epath.resource_path('mujoco') / 'testdata'\n")
    official = str(runner.official_dir())
    assert runner.swap_imports(text, "introspect") == (
        "from mjcffi.introspect import enums\nfrom mjcffi.introspect.ast_nodes import ValueType\n"
        "import mjcffi.rollout as rollout\n"
        f"path = epath.Path({official!r}) / 'testdata'\n")
    names = runner.official_files()
    assert "usd/exporter_test.py" in names and "sysid/tests/test_signal.py" in names
    assert not any(name.endswith("conftest.py") for name in names)


def test_a_crash_is_reported_against_the_test_that_was_running():
    records = [{"event": "start", "nodeid": "f.py::T::test_a"},
               {"event": "report", "nodeid": "f.py::T::test_a", "when": "call",
                "outcome": "passed", "subtest": False, "message": ""},
               {"event": "start", "nodeid": "f.py::T::test_b"}]
    result = runner._result("f.py", records, -11, "", 0.0)
    assert {t: o.outcome for t, o in result.tests.items()} == {"T::test_a": "passed",
                                                                "T::test_b": "crashed"}
    assert result.passed == 1


def test_a_failed_subtest_fails_its_test():
    records = [{"event": "start", "nodeid": "f.py::T::test_a"},
               {"event": "report", "nodeid": "f.py::T::test_a", "when": "call",
                "outcome": "failed", "subtest": True, "message": "boom"},
               {"event": "report", "nodeid": "f.py::T::test_a", "when": "call",
                "outcome": "passed", "subtest": False, "message": ""}]
    outcome = runner._result("f.py", records, 1, "", 0.0).tests["T::test_a"]
    assert (outcome.outcome, outcome.message) == ("failed", "boom")


def test_the_committed_report_covers_every_official_file():
    assert set(report.committed_passes()) == set(runner.official_files())


@pytest.mark.parametrize("name", report.non_gl_files())
def test_no_official_file_passes_fewer_tests_than_committed(name):
    committed = report.committed_passes()[name]
    result = runner.run_file(name, "mjcffi")
    failing = {t: o.message for t, o in result.tests.items()
               if o.outcome not in ("passed", "xfailed", "skipped")}
    assert result.passed >= committed, (
        f"{name}: {result.passed} passed, CONFORMANCE.md records {committed}; "
        f"collection error: {result.collect_error!r}; failing: {failing}")
