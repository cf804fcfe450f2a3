"""mujoco-py's own tests keep passing against mjcffi.sim (python -m conformance mujoco_py).

Each test file of mujoco-py's wheel runs here through the conformance runner
and must pass at least as many tests as CONFORMANCE.md's "mujoco-py's own
tests" section records.  The wheel comes from PyPI once, then from
~/.cache/mjcffi/; these tests skip only when neither is available.  The
rest checks the runner's pieces: the `mujoco_py` -> mjcffi.sim mapping, the
not-applicable list (its claims about MuJoCo 4 are checked against the
official bindings), and the section's writing and reading.
"""

import ast
import fnmatch
import json
import os
import subprocess
import sys
import textwrap
import zipfile

import pytest

from conformance import _mujoco_py_notes as notes
from conformance import _mujoco_py_report as report
from conformance import _mujoco_py_wheel as wheel
from conformance import mujoco_py as runner
from conformance import report as official_report
from conformance.runner import _result


@pytest.fixture(scope="module")
def wheel_path():
    try:
        return wheel.wheel()
    except wheel.WheelUnavailable as error:
        pytest.skip(f"PyPI cannot be reached and no cached wheel exists: {error}")


@pytest.fixture(scope="module")
def workspace(wheel_path):
    with runner.Workspace(wheel_path) as space:
        yield space


# ------------------------------------------------------------------ mapping

def test_the_runner_maps_no_module_itself():
    # the runner's mujoco_py package calls the public install_as_mujoco_py(), nothing more:
    # the face's module paths are tested in tests/test_mujoco_py_face.py
    text = wheel.ALIAS.read_text()
    assert "install_as_mujoco_py()" in text
    for mapping in ("meta_path", "import_module", "MetaPathFinder", "mjviewer"):
        assert mapping not in text


def test_mujoco_py_imports_give_the_mjcffi_modules_themselves(tmp_path):
    (tmp_path / "mujoco_py" / "tests").mkdir(parents=True)
    (tmp_path / "mujoco_py" / "__init__.py").write_text(wheel.ALIAS.read_text())
    (tmp_path / "mujoco_py" / "tests" / "__init__.py").write_text("")
    (tmp_path / "mujoco_py" / "tests" / "utils.py").write_text("HERE = True\n")
    script = textwrap.dedent("""
        import json
        import mujoco_py, mujoco_py.tests
        from mujoco_py.tests.utils import HERE
        from mujoco_py import MjSim
        from mujoco_py.mjviewer import MjViewer
        import mjcffi.sim
        print(json.dumps({"tests": mujoco_py.tests.__file__, "face": mujoco_py is mjcffi.sim,
                          "MjSim": MjSim is mjcffi.sim.MjSim, "utils": HERE,
                          "MjViewer": MjViewer is mjcffi.sim.MjViewer}))
    """)
    run = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True,
                         text=True, timeout=120,
                         env=dict(os.environ, PYTHONPATH=str(tmp_path), MUJOCO_GL="egl"))
    assert run.returncode == 0, run.stderr
    found = json.loads(run.stdout.splitlines()[-1])
    assert found.pop("tests") == str(tmp_path / "mujoco_py" / "tests" / "__init__.py")
    assert found == {"face": True, "MjSim": True, "utils": True, "MjViewer": True}


# ------------------------------------------------------------ not applicable

def _source_of(wheel_path, file):
    with zipfile.ZipFile(wheel_path) as archive:
        return archive.read(wheel.TESTS + file).decode()


def test_each_not_applicable_pattern_names_tests_of_the_wheel(workspace):
    ids = {f"{name}::{t}" for name in workspace.files()
           for t in wheel.source_test_ids(workspace.tests / name)}
    for note in notes.NOT_APPLICABLE:
        for pattern in note.patterns:
            assert fnmatch.filter(ids, pattern), pattern
    assert notes.classify("test_cymj.py", "test_mj_sim_basics") is None
    assert notes.classify("test_cymj.py", "test_multiprocess") is not None
    assert notes.classify("test_cymj.py", "test_multiprocess_other") is None


def test_the_skips_of_a_file_are_its_patterns_without_the_file():
    skipped = dict(notes.skips("test_cymj.py"))
    assert set(skipped) == {"test_multiprocess", "test_multiprocess_with_killing",
                            "test_mj_warning_raises", "test_ignore_mujoco_warnings"}
    assert all(reason.startswith("not applicable: ") for reason in skipped.values())
    assert notes.skips("test_vfs.py") == []


def test_the_not_applicable_files_are_missing_from_the_wheel(wheel_path):
    names = zipfile.ZipFile(wheel_path).namelist()
    assert not [n for n in names if "/examples/" in n or n.startswith("examples/")]
    assert not [n for n in names if n.endswith("scripts/gen_wrappers.py")]


def _string_assigned(tree, variable, function=None):
    scope = tree
    if function:
        scope = next(n for n in ast.walk(tree)
                     if isinstance(n, ast.FunctionDef) and n.name == function)
    for node in ast.walk(scope):
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == variable
                                                for t in node.targets):
            return node.value.value
    raise AssertionError(f"no {variable} in {function}")


def test_mujoco_4_rejects_the_composite_of_test_composite(wheel_path):
    mujoco = pytest.importorskip("mujoco")
    xml = _string_assigned(ast.parse(_source_of(wheel_path, "test_composite.py")), "PARTICLE_XML")
    with pytest.raises(ValueError, match="unrecognized element"):
        mujoco.MjModel.from_xml_string(xml)


@pytest.mark.parametrize("test", ["test_mj_warning_raises", "test_ignore_mujoco_warnings"])
def test_mujoco_4_steps_the_nconmax_model_without_a_warning(wheel_path, test):
    mujoco = pytest.importorskip("mujoco")
    xml = _string_assigned(ast.parse(_source_of(wheel_path, "test_cymj.py")), "xml", test)
    assert 'nconmax="1"' in xml
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data)
    assert data.ncon > 1
    assert [w.number for w in data.warning] == [0] * len(data.warning)


def _pid_model(wheel_path, actuator, nuser_actuator):
    tree = ast.parse(_source_of(wheel_path, "test_pid.py"))
    return _string_assigned(tree, "MODEL_XML").format(
        actuator=_string_assigned(tree, actuator), nuser_actuator=nuser_actuator)


def test_mujoco_4_refuses_the_models_of_the_not_applicable_pid_tests(wheel_path):
    mujoco = pytest.importorskip("mujoco")
    # test_mj_proportional_only: its reference actuator; its PID actuator loads.
    mujoco.MjModel.from_xml_string(_pid_model(wheel_path, "P_ONLY_ACTUATOR", 1))
    with pytest.raises(ValueError, match="XML_ERROR_PARSING_ATTRIBUTE"):
        mujoco.MjModel.from_xml_string(_pid_model(wheel_path, "POSITION_ACTUATOR", 1))
    # test_mjsize_exception: the model itself, with nuser_actuator=0.
    with pytest.raises(ValueError, match="more values than nuser_actuator"):
        mujoco.MjModel.from_xml_string(_pid_model(wheel_path, "CASCADED_PIPI_ACTUATOR", 0))


# ------------------------------------------------------------------ results

def test_a_skip_of_a_not_applicable_test_is_counted_apart():
    records = [{"event": "start", "nodeid": "mujoco_py/tests/test_cymj.py::test_multiprocess"},
               {"event": "report", "nodeid": "mujoco_py/tests/test_cymj.py::test_multiprocess",
                "when": "setup", "outcome": "skipped", "subtest": False, "message": "n/a"},
               {"event": "start", "nodeid": "mujoco_py/tests/test_cymj.py::test_nested"}]
    result = _result("test_cymj.py", records, -11, "", 0.0)
    runner._mark_not_applicable(result)
    assert {t: o.outcome for t, o in result.tests.items()} == {
        "test_multiprocess": "not applicable", "test_nested": "crashed"}
    assert report.counts(result) == (2, 0, 1, 0, 1)


def test_source_test_ids_name_functions_and_unittest_methods(tmp_path):
    path = tmp_path / "test_x.py"
    path.write_text("def test_a():\n    pass\ndef helper():\n    pass\n"
                    "class TestB:\n    def test_c(self):\n        pass\n    def setUp(self):\n"
                    "        pass\n")
    assert wheel.source_test_ids(path) == ["test_a", "TestB::test_c"]


def test_a_run_names_each_test_and_sets_the_not_applicable_apart(workspace):
    result = runner.run_file(workspace, "test_composite.py")
    assert {t: o.outcome for t, o in result.tests.items()} == {
        "test_load_particle": "not applicable"}
    result = runner.run_file(workspace, "test_vfs.py")
    assert set(result.tests) == {"test_vfs", "test_files"}


def test_the_x_server_is_the_display_then_xvfb_run(monkeypatch):
    monkeypatch.setenv("DISPLAY", ":7")
    assert runner.x_server_prefix() == []
    monkeypatch.delenv("DISPLAY")
    monkeypatch.setattr(runner.shutil, "which", lambda name: None)
    assert runner.x_server_prefix() is None
    monkeypatch.setattr(runner.shutil, "which", lambda name: "/usr/bin/" + name)
    assert runner.x_server_prefix()[0] == "xvfb-run"


# ------------------------------------------------------------------ section

def _fake_results():
    from conformance.runner import FileResult, Outcome
    return {"test_a.py": FileResult("test_a.py", {"t1": Outcome("passed"),
                                                  "t2": Outcome("failed", "boom\nmore")}),
            "test_b.py": FileResult("test_b.py", {"t3": Outcome("not applicable", "why"),
                                                  "t4": Outcome("skipped", "no X")})}


def test_the_section_reads_back_and_keeps_the_rest_of_the_file(tmp_path):
    path = tmp_path / "CONFORMANCE.md"
    official = "# Conformance with the official bindings' tests\n\n| `x_test.py` | 3 | 2 |\n"
    path.write_text(official)
    report.write(report.render(_fake_results()), path)
    text = path.read_text()
    assert text.startswith(official)
    assert "| `test_a.py` | 2 | 1 | 1 | 0 | 0 | 50.0 % |" in text
    assert "- `test_a.py::t2` (failed): boom" in text
    assert report.committed_passes(path) == {"test_a.py": 1, "test_b.py": 0}
    assert official_report.committed_passes(path) == {"x_test.py": 2}
    # The official report's --write rewrites the rest and keeps the section.
    rewritten = report.keep_section(path, "# Conformance with the official bindings' tests\n")
    assert report.split(rewritten)[1] == report.split(text)[1]
    # A second write replaces the section instead of adding one.
    report.write(report.render(_fake_results()), path)
    assert path.read_text().count(report.TITLE) == 1


def test_a_section_before_another_heading_keeps_that_heading(tmp_path):
    text = f"# A\n\n{report.TITLE}\n\nold\n\n# B\n\ntail\n"
    assert report.replace_section(text, f"{report.TITLE}\n\nnew\n") == \
        f"# A\n\n{report.TITLE}\n\nnew\n\n# B\n\ntail\n"


def test_both_writers_keep_the_hand_written_strictness_section(tmp_path):
    path = tmp_path / "CONFORMANCE.md"
    strictness = f"{official_report.STRICTNESS}\n\n| audit |\n\n## Differences the other way\n\nx\n"
    path.write_text(f"# Conformance with the official bindings' tests\n\nold\n\n"
                    f"{report.TITLE}\n\nold\n\n{strictness}")
    report.write(report.render(_fake_results()), path)               # the mujoco-py writer
    assert path.read_text().endswith(strictness)
    fresh = "# Conformance with the official bindings' tests\n\nnew\n"
    text = report.keep_section(path, fresh)                          # the official writer
    text = report.keep_section(path, text, official_report.STRICTNESS)
    assert text.startswith(fresh) and text.endswith(strictness)
    assert report.split(text)[1] == report.split(path.read_text())[1]


# ------------------------------------------------------------- regression

def _committed():
    try:
        return report.committed_passes()
    except FileNotFoundError:
        return {}


def test_the_committed_section_covers_every_file_of_the_wheel(workspace):
    assert set(_committed()) == set(workspace.files())


@pytest.mark.parametrize("name", sorted(_committed()))
def test_no_mujoco_py_file_passes_fewer_tests_than_committed(workspace, name):
    if name in runner.X_FILES and runner.x_server_prefix() is None:
        pytest.skip(runner.NO_X_SERVER)
    committed = _committed()[name]
    result = runner.run_file(workspace, name)
    failing = {t: o.message for t, o in result.tests.items()
               if o.outcome not in ("passed", "xfailed", "skipped", "not applicable")}
    assert result.passed >= committed, (
        f"{name}: {result.passed} passed, CONFORMANCE.md records {committed}; "
        f"collection error: {result.collect_error!r}; failing: {failing}")
