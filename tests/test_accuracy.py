"""The speed-against-error report (python -m mjcffi.accuracy), on one small scene."""

import math
import re

import numpy as np
import pytest

from mjcffi import accuracy


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
    ref_setting = accuracy.reference_setting(pendulum, m)
    a = accuracy.simulate(pendulum, m, ref_setting)
    b = accuracy.simulate(pendulum, m, ref_setting)
    assert accuracy.errors_against(m, a, b) == 0.0
    assert not a.unstable


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
