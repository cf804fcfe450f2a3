"""The command-line tools' user errors: one `prog: error: ...` line on stderr, exit status 2,
no traceback, and every check made before the work starts (issue 27, finding 6).

Each command runs as a subprocess in a temporary folder, so that nothing it might leave
behind (MUJOCO_LOG.TXT, a report) lands in the source tree.
"""

import json
import os
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

import mjcffi

GOOD_XML = """<mujoco>
  <option timestep="0.002"/>
  <worldbody>
    <body>
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom type="capsule" size="0.05" fromto="0 0 0 0 0 -0.5"/>
    </body>
  </worldbody>
  <actuator><motor joint="hinge"/></actuator>
</mujoco>
"""
BAD_XML = "<mujoco><worldbody><bogus/></worldbody></mujoco>\n"


@pytest.fixture
def files(tmp_path):
    """A good model, a bad one, a bad .mjb and a regular file (to put paths under)."""
    (tmp_path / "good.xml").write_text(GOOD_XML)
    (tmp_path / "bad.xml").write_text(BAD_XML)
    (tmp_path / "bad.mjb").write_bytes(b"not a model\n")
    (tmp_path / "plain.txt").write_text("a regular file\n")
    return tmp_path


@pytest.fixture
def no_ray(tmp_path):
    """An environment in which `import ray` fails, as where Ray is not installed."""
    fake = tmp_path / "no_ray" / "ray"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError(\"No module named 'ray'\")\n")
    paths = [str(fake.parent), os.environ.get("PYTHONPATH", "")]
    return {"PYTHONPATH": os.pathsep.join(p for p in paths if p)}


def _run(module, args, cwd, env=None, timeout=120):
    """Run `python -m module args` in `cwd`; (result, seconds it took)."""
    environment = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1", **(env or {})}
    environment = {k: v for k, v in environment.items() if v is not None}
    start = time.monotonic()
    result = subprocess.run([sys.executable, "-m", module, *map(str, args)], cwd=cwd,
                            capture_output=True, text=True, timeout=timeout, env=environment)
    return result, time.monotonic() - start


def _error_line(result):
    """The one error line of a user error, after checking the conventions around it."""
    detail = f"rc={result.returncode}\nstdout:\n{result.stdout[-2000:]}\n" \
             f"stderr:\n{result.stderr[-3000:]}"
    assert result.returncode == 2, detail
    assert "Traceback" not in result.stderr, detail
    lines = result.stderr.splitlines()
    if lines and lines[0].startswith("usage:"):      # argparse's usage block, then the error
        lines = lines[1:]
        while lines and lines[0].startswith(" "):
            lines = lines[1:]
    assert len(lines) == 1, detail
    assert ": error: " in lines[0], detail
    return lines[0]


# ------------------------------------------------------------------ python -m mjcffi.tune

TUNE = "mjcffi.tune"


def test_tune_reports_a_model_that_does_not_load_in_one_line(files):
    result, _ = _run(TUNE, ["bad.xml", "--budget", "0.01", "--quiet"], files)
    line = _error_line(result)
    assert "bad.xml" in line and "bogus" in line and "unrecognized element" in line


def test_tune_reports_a_bad_binary_model_in_one_line(files):
    result, _ = _run(TUNE, ["bad.mjb", "--budget", "0.01", "--quiet"], files)
    line = _error_line(result)
    assert "bad.mjb" in line and "mjb" in line.split("bad.mjb", 1)[1]
    assert not (files / "MUJOCO_LOG.TXT").exists()       # MuJoCo's warning was taken in


@pytest.mark.parametrize("args, option", [
    (["--budget", "-1"], "--budget"),
    (["--budget", "0"], "--budget"),
    (["--budget", "nan"], "--budget"),
    (["--budget", "inf"], "--budget"),
    (["--budget", "0.01", "--horizon", "0"], "--horizon"),
    (["--budget", "0.01", "--horizon", "-1"], "--horizon"),
    (["--budget", "0.01", "--horizon", "inf"], "--horizon"),
    (["--budget", "0.01", "--horizon", "nan"], "--horizon"),
    (["--budget", "0.01", "--control-period", "-1"], "--control-period"),
    (["--budget", "0.01", "--control-period", "0"], "--control-period"),
    (["--budget", "0.01", "--control-period", "inf"], "--control-period"),
    (["--budget", "0.01", "--seed", "-1"], "--seed"),
    # valid numbers that do not fit the model (timestep 0.002 s)
    (["--budget", "0.01", "--control-period", "0.003"], "--control-period"),
    (["--budget", "0.01", "--horizon", "0.001"], "--horizon"),
    (["--budget", "0.01", "--control-period", "0.01", "--horizon", "0.004"], "--horizon"),
])
def test_tune_rejects_bad_numbers(files, args, option):
    result, _ = _run(TUNE, ["good.xml", "--quiet", *args], files)
    line = _error_line(result)
    assert option in line
    assert result.stdout == ""


@pytest.mark.parametrize("option, where, why", [
    ("--report", "/nonexistent/r.md", "no such folder"),
    ("--report", "plain.txt/r.md", "not a folder"),     # its folder is a regular file
    ("--report", ".", "is a folder"),                   # a folder, not a file
    ("--out", "plain.txt/tuned.xml", "not a folder"),
])
def test_tune_checks_output_paths_before_tuning(files, option, where, why):
    # a long horizon makes the tuning itself take many seconds: the check must come first
    result, seconds = _run(TUNE, ["good.xml", "--budget", "0.01", "--quiet",
                                  "--horizon", "200", option, where], files)
    line = _error_line(result)
    assert option in line and where in line and why in line
    assert result.stdout == ""                    # no report: the tuning never ran
    assert seconds < 10


def test_tune_reports_a_model_that_diverges_at_its_own_settings_without_a_traceback(files):
    # found only once the work has started: MuJoCo's own warnings may come before the error
    stiff = GOOD_XML.replace('timestep="0.002"', 'timestep="0.5"').replace(
        'axis="0 1 0"', 'axis="0 1 0" stiffness="1e6"')
    (files / "stiff.xml").write_text(stiff)
    result, _ = _run(TUNE, ["stiff.xml", "--budget", "0.01", "--quiet"], files)
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    assert result.stderr.splitlines()[-1].startswith(f"python -m {TUNE}: error: the model "
                                                     "diverges")


def test_tune_ray_without_ray_is_a_usage_error(files, no_ray):
    result, _ = _run(TUNE, ["good.xml", "--budget", "0.01", "--quiet", "--ray"], files,
                     env=no_ray)
    assert "ray" in _error_line(result).lower()
    assert result.stdout == ""


# ------------------------------------------------------------------ python -m mjcffi.accuracy

ACCURACY = "mjcffi.accuracy"
CHEAP = ["double_pendulum", "--quick"]


@pytest.mark.parametrize("where", ["/dev/null/x", "plain.txt/x", "plain.txt"])
def test_accuracy_checks_the_out_folder_first(files, where):
    result, _ = _run(ACCURACY, [*CHEAP, "--out", where], files)
    line = _error_line(result)
    assert "--out" in line and where in line
    assert result.stdout == ""                    # no scene was started


@pytest.mark.parametrize("budget", ["-1", "0", "nan", "inf"])
def test_accuracy_rejects_bad_budgets(files, budget):
    result, _ = _run(ACCURACY, [*CHEAP, "--out", files, "--budget", budget], files)
    assert "--budget" in _error_line(result)
    assert not (files / "ACCURACY.md").exists()


def test_accuracy_ray_without_ray_is_a_usage_error(files, no_ray):
    result, _ = _run(ACCURACY, [*CHEAP, "--out", files, "--ray"], files, env=no_ray)
    assert "ray" in _error_line(result).lower()
    assert result.stdout == ""


def test_accuracy_writes_into_the_current_folder_by_default(tmp_path):
    # the cheapest run (one scene, quick sweep) takes about a second
    tree = Path(mjcffi.__file__).resolve().parent.parent / "benchmarks" / "ACCURACY.md"
    before = tree.stat().st_mtime_ns if tree.exists() else None
    result, _ = _run(ACCURACY, CHEAP, tmp_path)
    assert result.returncode == 0, result.stderr[-3000:]
    assert "## double_pendulum" in (tmp_path / "ACCURACY.md").read_text(encoding="utf-8")
    assert (tree.stat().st_mtime_ns if tree.exists() else None) == before


# ------------------------------------------------------------------ python -m mjcffi

MAIN = "mjcffi"


@pytest.mark.parametrize("model", ["bad.xml", "."])
def test_main_reports_a_model_that_does_not_load_in_one_line(files, model):
    result, _ = _run(MAIN, ["--xml", model, "--steps", "10", "--rounds", "1"], files)
    line = _error_line(result)
    assert "--xml" in line or "cannot load" in line
    if model == "bad.xml":
        assert "bogus" in line and "unrecognized element" in line
    assert result.stdout == ""


# ------------------------------------------------------------------ python -m mjcffi.viewer

VIEWER = "mjcffi.viewer"
NO_DISPLAY = {"DISPLAY": None, "WAYLAND_DISPLAY": None, "MJCFFI_VIEWER_CLOSE_AFTER": "3"}


def _needs_glfw():
    pytest.importorskip("glfw", reason="the viewer needs the glfw package (pip install glfw)")


@pytest.mark.parametrize("model", ["bad.xml", "bad.mjb", "missing.xml", "plain.txt/x.xml"])
def test_viewer_reports_a_bad_start_up_model_before_any_window(files, model):
    # no display: had the app got as far as opening a window, GLFW would fail instead
    _needs_glfw()
    result, _ = _run(VIEWER, ["--mjcf", model], files, env=NO_DISPLAY, timeout=60)
    line = _error_line(result)
    assert model in line and "GLFW" not in line
    if model == "bad.xml":
        assert "bogus" in line and "unrecognized element" in line


def test_viewer_rejects_a_bad_close_after(files):
    _needs_glfw()
    env = {**NO_DISPLAY, "MJCFFI_VIEWER_CLOSE_AFTER": "soon"}
    result, _ = _run(VIEWER, ["--mjcf", "good.xml"], files, env=env, timeout=60)
    assert "MJCFFI_VIEWER_CLOSE_AFTER" in _error_line(result)


def _display_prefix():
    """The command prefix that gives a subprocess an X display (as tests/test_viewer.py)."""
    if os.environ.get("DISPLAY"):
        return []
    if shutil.which("xvfb-run") is None:
        pytest.skip("no DISPLAY and no xvfb-run: install the xvfb package (apt-get install xvfb)")
    return ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24"]


DROP = """
import json
from mjcffi.viewer import _viewer
_viewer.DEFAULT_SIZE = (640, 480)
from mjcffi.viewer._managed import Simulation, file_loader
sim = Simulation(loader=file_loader("good.xml"))
sim.open()
out = {}
for _ in range(3):
    sim.frame()
out["nbody"] = sim.model.nbody
sim.viewer.on_drop(["bad.xml"])
sim.frame()
out["message"] = sim.viewer.message
out["nbody_after_bad"] = sim.model.nbody
sim.viewer.on_drop(["other.xml"])
for _ in range(2):
    sim.frame()
out["nbody_after_good"] = sim.model.nbody
out["message_after_good"] = sim.viewer.message
sim.viewer.destroy()
print(json.dumps(out))
"""


def test_viewer_reports_a_bad_dropped_file_in_one_line_and_stays_usable(files):
    _needs_glfw()
    (files / "other.xml").write_text(GOOD_XML.replace("<body>", "<body><body/>", 1))
    (files / "drop.py").write_text(textwrap.dedent(DROP))
    result = subprocess.run(_display_prefix() + [sys.executable, "drop.py"], cwd=files,
                            capture_output=True, text=True, timeout=120,
                            env={**os.environ, "MUJOCO_GL": "egl",
                                 "PYTHONDONTWRITEBYTECODE": "1"})
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    out = json.loads(result.stdout.strip().splitlines()[-1])
    assert "Traceback" not in result.stderr, result.stderr
    named = [line for line in result.stderr.splitlines() if "bad.xml" in line]
    assert len(named) == 1, result.stderr
    assert "bogus" in named[0] and "unrecognized element" in named[0]
    assert "bogus" in out["message"] and "unrecognized element" in out["message"]
    assert out["nbody_after_bad"] == out["nbody"]            # the old model stays up
    assert out["nbody_after_good"] == out["nbody"] + 1       # and a good drop still loads
    assert out["message_after_good"] == ""
