"""`python -m mjcffi`, the README's main job."""

import pathlib
import subprocess
import sys

REPO = pathlib.Path(__file__).resolve().parent.parent


def _run(*args):
    return subprocess.run([sys.executable, "-m", "mjcffi", *args], cwd=REPO,
                          capture_output=True, text=True, timeout=300)


def test_default_scene_runs_and_is_bit_identical():
    result = _run("--steps", "300", "--rounds", "1")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "bit-identical over 300 steps" in result.stdout
    assert "mjcffi" in result.stdout and "official" in result.stdout


def test_a_gymnasium_model_by_path():
    from .conftest import gymnasium_assets
    hopper = next(p for p in gymnasium_assets() if p.name == "hopper.xml")
    result = _run("--xml", str(hopper), "--steps", "100", "--rounds", "1")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "bit-identical" in result.stdout


def test_bad_arguments_are_reported_not_crashed(tmp_path):
    result = _run("--xml", str(tmp_path / "missing.xml"))
    assert result.returncode == 2
    assert "missing.xml" in result.stderr and "Traceback" not in result.stderr
    result = _run("--steps", "0")
    assert result.returncode == 2 and "positive" in result.stderr


def test_the_readme_example_runs():
    text = (REPO / "README.md").read_text()
    example = text.split("```python\n", 1)[1].split("```", 1)[0]
    assert "mj_step" in example and "mj_jac" in example
    result = subprocess.run([sys.executable, "-c", example], cwd=REPO, capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0, result.stderr
