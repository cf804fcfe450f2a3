"""The speed-against-error report (python -m mjcffi.accuracy), on one small scene."""

import math
import re

import numpy as np
import pytest

import mjcffi
from mjcffi import accuracy, evaluation
from mjcffi.evaluation import quat_angle, settings, states


@pytest.fixture(scope="module")
def pendulum():
    return accuracy.all_scenes()["double_pendulum"]


@pytest.fixture(scope="module")
def quick_rows(pendulum):
    m, ref_setting, ref, rows = accuracy.run_scene(pendulum, quick=True, log=lambda *a: None)
    return m, rows


def test_report_on_one_scene(tmp_path, capsys):
    assert accuracy.main(["double_pendulum", "--quick", "--budget", "1e-3",
                          "--out", str(tmp_path)]) == 0
    text = (tmp_path / "ACCURACY.md").read_text()
    assert "## double_pendulum" in text
    assert "- CPU:" in text and "mujoco-core" in text
    # one table row per swept setting, each with a finite positive steps/s
    rows = [line for line in text.splitlines() if re.match(r"\| (Euler|RK4) dt=", line)]
    assert len(rows) >= 6
    for line in rows:
        assert float(line.split("|")[2].replace(",", "")) > 0
    pick = re.search(r"Cheapest within the budget 0\.001: (.+?)\*\*"
                     r".*position error ([0-9.]+e[+-][0-9]+)", text)
    assert pick, text
    assert float(pick.group(2)) <= 1e-3
    # Euler is far off on a chaotic pendulum; only RK4 fits 1e-3
    assert pick.group(1).startswith("RK4")
    if (tmp_path / "accuracy.png").exists():
        assert (tmp_path / "accuracy.png").stat().st_size < 200_000
    else:
        assert "matplotlib" in capsys.readouterr().err


def test_rk4_error_shrinks_with_the_timestep(quick_rows):
    m, rows = quick_rows
    rk4 = sorted((r for r in rows if r.label.startswith("RK4") and not r.setting.enable_stages),
                 key=lambda r: -r.setting.timestep)
    assert len(rk4) >= 3
    errs = [r.pos_err for r in rk4]
    assert all(a > b for a, b in zip(errs, errs[1:])), errs
    # fourth order: halving dt divides the error by about 16
    assert errs[0] / errs[1] > 8
    assert all(r.energy_drift < 1e-3 for r in rk4)


def test_reference_against_itself_is_exact(pendulum):
    m = pendulum.model()
    ref_setting = accuracy.scene_reference(pendulum, m)
    a = accuracy.simulate(pendulum, m, ref_setting)
    b = accuracy.simulate(pendulum, m, ref_setting)
    assert accuracy.errors_against(m, a, b) == 0.0
    assert not a.unstable


def test_the_report_uses_the_shared_evaluation_core():
    # one copy of the setting, error measure, reference and timing: tune's
    assert accuracy.Setting is evaluation.Setting
    assert accuracy.position_error is evaluation.position_error
    assert accuracy.reference_setting is evaluation.reference_setting
    assert accuracy.REF_FACTOR is evaluation.REF_FACTOR
    assert accuracy._steps_per_second is evaluation.steps_per_second
    assert accuracy.INTEGRATOR_NAMES is settings.INTEGRATOR_NAMES
    assert accuracy.flag_names is settings.flag_names
    assert accuracy.DIVERGED is states.DIVERGED
    # and no second copy left behind under the old names
    assert not hasattr(accuracy, "quat_angle") and not hasattr(accuracy, "BAD")


def test_reference_for_a_contact_scene_is_newton_converged():
    scene = accuracy.all_scenes()["box_stack"]
    assert scene.contact
    m = scene.model()
    ref = accuracy.scene_reference(scene, m)
    assert ref == evaluation.reference_setting(m, tight_solver=True)
    assert ref.integrator == mjcffi.mjtIntegrator.mjINT_RK4
    assert ref.timestep == pytest.approx(m.opt.timestep / 100)
    assert ref.solver == mjcffi.mjtSolver.mjSOL_NEWTON
    assert ref.tolerance == 1e-12
    assert ref.iterations >= 100 and ref.ls_iterations >= 50
    # a scene without contacts has no constraint to solve: the model's own solver stays
    pendulum = accuracy.all_scenes()["double_pendulum"]
    free = accuracy.scene_reference(pendulum, pendulum.model())
    assert free.solver is None and free.tolerance is None


def test_unneeded_stages_change_nothing_but_speed(quick_rows):
    m, rows = quick_rows
    by = {r.setting: r for r in rows}
    on = [r for r in rows if r.setting.enable_stages]
    assert on
    for r in on:
        off = by[accuracy.Setting(r.setting.integrator, r.setting.timestep)]
        assert np.array_equal(off.qpos, r.qpos)


def test_pareto_and_budget_pick():
    s = accuracy.Setting(accuracy.INT.mjINT_EULER, 0.01)
    rows = [accuracy.Row(s, "fast", 100.0, 1.0, math.nan, math.nan, math.nan, False),
            accuracy.Row(accuracy.Setting(accuracy.INT.mjINT_RK4, 0.01), "accurate",
                         50.0, 0.01, math.nan, math.nan, math.nan, False),
            accuracy.Row(accuracy.Setting(accuracy.INT.mjINT_RK4, 0.005), "worse", 40.0, 0.1,
                         math.nan, math.nan, math.nan, False),
            accuracy.Row(accuracy.Setting(accuracy.INT.mjINT_EULER, 0.02), "blew up", 100.0,
                         math.inf, math.nan, math.nan, math.nan, True)]
    accuracy.pareto(rows)
    assert [r.pareto for r in rows] == [True, True, False, False]
    assert accuracy.cheapest_within(rows, 0.05).label == "accurate"
    assert accuracy.cheapest_within(rows, 2.0).label == "fast"
    assert accuracy.cheapest_within(rows, 1e-3) is None


def _quat(axis, angle):
    axis = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis])


def _mul(a, b):
    w = a[0] * b[0] - a[1:] @ b[1:]
    return np.concatenate([[w], a[0] * b[1:] + b[0] * a[1:] + np.cross(a[1:], b[1:])])


@pytest.mark.parametrize("angle", [1e-13, 1e-11, 1e-10, 1e-8, 1e-6, 1e-3, 0.5, 3.0])
def test_item_dzhanibekov_quat_angle_resolves_tiny_rotations(angle):
    # The Dzhanibekov rows of ACCURACY.md read an exact 0 for RK4 at small timesteps:
    # 2*acos(min(1, c)) cannot tell an angle below ~1e-8 rad from none, as
    # cos(1e-8) rounds to 1.  atan2 of the vector part keeps it to full precision.
    base = _quat([0.3, -0.4, 0.5], 1.1)
    turned = _mul(base, _quat([1.0, 2.0, -0.5], angle))
    got = quat_angle(base, turned)
    assert got > 0
    assert got == pytest.approx(angle, rel=1e-3, abs=1e-17)
    # the same rotation whatever the sign of either quaternion, and either way round
    assert quat_angle(-base, turned) == pytest.approx(got, rel=1e-12, abs=1e-18)
    assert quat_angle(turned, base) == pytest.approx(got, rel=1e-12, abs=1e-18)


def test_item_dzhanibekov_quat_angle_agrees_with_mujoco():
    rng = np.random.default_rng(7)
    for _ in range(200):
        a, b = rng.normal(size=4), rng.normal(size=4)
        a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
        difference = np.zeros(3)
        mjcffi.mju_subQuat(difference, b, a)      # axis * angle, angle <= pi
        assert quat_angle(a, b) == pytest.approx(np.linalg.norm(difference), abs=1e-12)
    assert quat_angle([1, 0, 0, 0], [1, 0, 0, 0]) == 0.0
    assert quat_angle([1, 0, 0, 0], [0, 1, 0, 0]) == pytest.approx(math.pi)
    # unnormalized quaternions are normalized first
    assert quat_angle([2, 0, 0, 0], _quat([0, 0, 1], 0.25) * 3) == pytest.approx(0.25)
