"""mjcffi.tune: the cheapest settings within a local-error budget, verified on held-out states.

The budget claims are checked by an independent rerun written here: fresh states from
trajectories tune never saw (another seed), stepped in Python with plain mj_step, against
a reference built here (RK4 at timestep / 100, Newton at 1e-12), with the joint errors
computed here from mju_subQuat rather than by mjcffi.evaluation, and the same statistic
tune states its budget in: the 90 % quantile over states of each kind's largest error.
"""

import math
import os
import subprocess
import sys

import numpy as np
import pytest

import mjcffi
from mjcffi import scenes
from mjcffi.tune import BudgetError, TuneResult

FULL = int(mjcffi.mjtState.mjSTATE_FULLPHYSICS)
# (scene, control period in s, budget): each hard case with a budget it can meet
HARD = [("double_pendulum", 0.01, 1e-4), ("dzhanibekov", 0.01, 1e-3),
        ("mass_ratio_chain", 0.01, 1e-3), ("box_stack", 0.016, 1e-3)]


def scene(name):
    return mjcffi.MjModel.from_xml_string(scenes.HARD_CASES[name])


@pytest.fixture(scope="module")
def tuned():
    """One tune per hard case, shared by the tests below."""
    out = {}
    for name, period, budget in HARD:
        m = scene(name)
        out[name] = (m, period, budget, mjcffi.tune(m, budget, control_period=period,
                                                    progress=False))
    return out


# ------------------------------------------------------- independent rerun

def _fresh_states(m, period, seed, ntraj=8, every=2):
    """(state, warm start, control) at period boundaries of trajectories of the original,
    drawn as tune documents its default: the first keyframe (or qpos0) perturbed by ±0.01,
    controls uniform in [-1, 1] (these scenes have none), 1 s of trajectory."""
    rng = np.random.default_rng(seed)
    d = mjcffi.MjData(m)
    k = round(period / m.opt.timestep)
    out = []
    for _ in range(ntraj):
        if m.nkey:
            mjcffi.mj_resetDataKeyframe(m, d, 0)
        else:
            mjcffi.mj_resetData(m, d)
        d.qpos[:] += rng.uniform(-0.01, 0.01, m.nq)
        d.qvel[:] += rng.uniform(-0.01, 0.01, m.nv)
        mjcffi.mj_normalizeQuat(m, d.qpos)
        for i in range(round(max(1.0, 20 * period) / period)):
            u = rng.uniform(-1, 1, m.nu)
            if i % every == 0:
                s = np.empty(mjcffi.mj_stateSize(m, FULL))
                mjcffi.mj_getState(m, d, s, FULL)
                out.append((s, d.qacc_warmstart.copy(), u))
            d.ctrl[:] = u
            mjcffi.mj_step(m, d, nstep=k)
    return out


def _one_period(m, period, start):
    s, warm, u = start
    d = mjcffi.MjData(m)
    mjcffi.mj_setState(m, d, s, FULL)
    d.qacc_warmstart[:] = warm
    d.ctrl[:] = u
    mjcffi.mj_step(m, d, nstep=round(period / m.opt.timestep))
    return d.qpos.copy()


def _reference(name, m):
    ref = scene(name)
    ref.opt.disableflags = m.opt.disableflags
    ref.opt.integrator = mjcffi.mjtIntegrator.mjINT_RK4
    ref.opt.timestep = m.opt.timestep / 100
    ref.opt.solver = mjcffi.mjtSolver.mjSOL_NEWTON
    ref.opt.iterations = 100
    ref.opt.tolerance = 1e-12
    ref.opt.ls_iterations = 50
    return ref


def _kind_errors(m, q, r):
    """{kind: error} of one state: the largest per joint of each kind."""
    out = {}
    for j in range(m.njnt):
        a = m.jnt_qposadr[j]
        t = m.jnt_type[j]
        if t == mjcffi.mjtJoint.mjJNT_FREE:
            rot = np.zeros(3)
            mjcffi.mju_subQuat(rot, q[a + 3:a + 7], r[a + 3:a + 7])
            pairs = [("free_pos", np.linalg.norm(q[a:a + 3] - r[a:a + 3])),
                     ("free_rot", np.linalg.norm(rot))]
        elif t == mjcffi.mjtJoint.mjJNT_BALL:
            rot = np.zeros(3)
            mjcffi.mju_subQuat(rot, q[a:a + 4], r[a:a + 4])
            pairs = [("ball", np.linalg.norm(rot))]
        else:
            kind = "slide" if t == mjcffi.mjtJoint.mjJNT_SLIDE else "hinge"
            pairs = [(kind, abs(q[a] - r[a]))]
        for kind, e in pairs:
            # a diverged state is an infinite error: max() would drop a NaN
            out[kind] = max(out.get(kind, 0.0), float(e) if np.isfinite(e) else math.inf)
    return out


def independent_error(name, original, tuned_model, period, seed=12345):
    """{kind: 90 % quantile} over fresh states of each kind's largest one-period error."""
    ref = _reference(name, original)
    per_kind = {}
    starts = _fresh_states(original, period, seed)
    for start in starts:
        errs = _kind_errors(original, _one_period(tuned_model, period, start),
                            _one_period(ref, period, start))
        for kind, e in errs.items():
            per_kind.setdefault(kind, []).append(e)
    return {k: float(np.quantile(v, 0.9)) for k, v in per_kind.items()}


# ------------------------------------------------------------------- tests

@pytest.mark.parametrize("name,period,budget", HARD, ids=[h[0] for h in HARD])
def test_tuned_hard_case_is_within_budget_on_states_it_never_saw(tuned, name, period, budget):
    m, _, _, result = tuned[name]
    assert isinstance(result, TuneResult)
    errors = independent_error(name, m, result.model, period)
    assert errors, "the scene has joints to compare"
    for kind, e in errors.items():
        assert e <= budget, (name, kind, e, result.report())
    # what tune reports agrees: held-out bound within the budget, one setting chosen
    assert all(e <= budget for e in result.error.local_bound.values())
    chosen = [c for c in result.candidates if c.status == "chosen"]
    assert len(chosen) == 1 and chosen[0].setting == result.setting


@pytest.mark.parametrize("name", ["double_pendulum", "dzhanibekov", "box_stack"])
def test_tuning_changes_something_and_leaves_the_model_alone(tuned, name):
    m, period, _, result = tuned[name]
    assert result.settings, "a cheaper setting exists within these budgets"
    fresh = scene(name)
    assert m.opt.timestep == fresh.opt.timestep and m.opt.integrator == fresh.opt.integrator
    assert m.opt.disableflags == fresh.opt.disableflags
    assert result.model is not m
    for change in result.settings.values():
        assert change.reason and change.before != change.after
    # the control rate is kept: the timestep divides the control period
    k = period / result.model.opt.timestep
    assert abs(k - round(k)) < 1e-9


def test_static_stages_are_switched_off_with_reasons(tuned):
    m, _, _, result = tuned["double_pendulum"]
    for name, bits in (("passive", mjcffi.mjtDisableBit.mjDSBL_SPRING
                        | mjcffi.mjtDisableBit.mjDSBL_DAMPER),
                       ("actuation", mjcffi.mjtDisableBit.mjDSBL_ACTUATION),
                       ("sensor", mjcffi.mjtDisableBit.mjDSBL_SENSOR)):
        change = result.settings[name]
        assert (change.before, change.after) == ("on", "off")
        assert len(change.reason) > 20
        assert result.model.opt.disableflags & bits == bits
    # the box stack needs contact and constraints: neither is touched
    _, _, _, boxes = tuned["box_stack"]
    assert "contact" not in boxes.settings and "constraint" not in boxes.settings
    assert not boxes.model.opt.disableflags & mjcffi.mjtDisableBit.mjDSBL_CONTACT


def test_original_budget_is_as_accurate_as_the_model_itself():
    m = scene("mass_ratio_chain")
    result = mjcffi.tune(m, "original", control_period=0.01, progress=False)
    # equal within 1 % (the two digits the report prints), or better
    assert result.error.budget == pytest.approx(
        {k: 1.01 * v for k, v in result.error.original_local.items()}, rel=1e-12)
    for kind, e in result.error.local.items():
        assert e <= 1.01 * result.error.original_local[kind]
    assert result.error.stability.diverged == 0


def test_accurate_objective_is_no_less_accurate():
    m = scene("mass_ratio_chain")
    result = mjcffi.tune(m, 1e-2, control_period=0.01, objective="accurate", progress=False)
    assert result.objective == "accurate"
    for kind, e in result.error.local.items():
        assert e <= result.error.original_local[kind]


def test_an_impossible_budget_says_so_and_names_the_best():
    m = scene("double_pendulum")
    with pytest.raises(BudgetError, match="no setting met the budget.*closest") as info:
        mjcffi.tune(m, 1e-15, control_period=0.01, progress=False)
    best = info.value.best
    assert best.setting.integrator in (0, 1, 2, 3)
    errors = best.held_out if best.held_out is not None else best.estimates
    assert max(e.upper for e in errors.values()) > 1e-15
    assert isinstance(info.value, ValueError) and info.value.candidates


def test_tuned_xml_reloads_bit_identical(tuned, tmp_path):
    m, period, _, result = tuned["box_stack"]
    source = tmp_path / "boxes.xml"
    source.write_text(scenes.HARD_CASES["box_stack"])
    path, route = result.write_xml(str(source), str(tmp_path / "tuned.xml"))
    assert route in ("spec", "text", "etree")
    reloaded = mjcffi.MjModel.from_xml_path(path)
    for field in ("timestep", "integrator", "iterations", "tolerance", "ls_iterations",
                  "disableflags", "solver", "cone", "jacobian"):
        assert getattr(reloaded.opt, field) == getattr(result.model.opt, field), field
    runs = []
    for model in (result.model, reloaded):
        d = mjcffi.MjData(model)
        rows = []
        for _ in range(200):
            mjcffi.mj_step(model, d)
            rows.append(np.concatenate([d.qpos, d.qvel]))
        runs.append(np.array(rows))
    assert np.array_equal(runs[0], runs[1])
    assert not np.array_equal(runs[0][0], runs[0][-1])


def test_result_report_repr_and_plot(tuned, tmp_path):
    _, _, budget, result = tuned["dzhanibekov"]
    text = result.report(plot=str(tmp_path / "front.png"))
    assert text.startswith("# Tuned settings")
    assert "| setting | original | tuned | why |" in text
    assert "| free_rot | rad |" in text
    assert f"{result.speedup:.2f}×" in text and "95 % interval" in text
    if "No plot" not in text:
        assert (tmp_path / "front.png").stat().st_size > 1000
    assert repr(result).startswith("<TuneResult ") and "×" in repr(result)
    assert result.options() == {n: c.after for n, c in result.settings.items()
                                if c.before not in ("on", "off")}


@pytest.mark.parametrize("kwargs,error,match", [
    (dict(budget=-1e-3), ValueError, "positive"),
    (dict(budget=0.0), ValueError, "positive"),
    (dict(budget=float("nan")), ValueError, "positive"),
    (dict(budget=True), TypeError, "number"),
    (dict(budget="cheap"), ValueError, "'original'"),
    (dict(budget={"hinges": 1e-3}), ValueError, "unknown joint kinds"),
    (dict(budget=1e-3, horizon=1e-4), ValueError, "shorter than one step"),
    (dict(budget=1e-3, horizon=0.005, control_period=0.01), ValueError,
     "shorter than one control period"),
    (dict(budget=1e-3, horizon=-1.0), ValueError, "positive"),
    (dict(budget=1e-3, control_period=0.0015), ValueError, "whole number of timesteps"),
    (dict(budget=1e-3, objective="fastest"), ValueError, "objective"),
    (dict(budget=1e-3, states=np.zeros((1, 3))), ValueError, "states must have shape"),
    (dict(budget=1e-3, control=np.zeros((5, 2))), ValueError, "control must have shape"),
    (dict(budget=1e-3, nthread=0), ValueError, "nthread"),
])
def test_bad_input_is_a_clear_error(kwargs, error, match):
    m = scene("double_pendulum")
    budget = kwargs.pop("budget")
    with pytest.raises(error, match=match):
        mjcffi.tune(m, budget, progress=False, **kwargs)


def test_not_a_model_is_a_type_error():
    with pytest.raises(TypeError, match="MjModel"):
        mjcffi.tune(scenes.PENDULUM, 1e-3)


def test_a_model_that_diverges_at_its_own_settings_is_refused():
    stiff = """<mujoco><option timestep="0.05" integrator="Euler"/><worldbody><body>
      <joint type="hinge" stiffness="1e7"/><geom type="sphere" size=".1" pos=".5 0 0" mass="0.01"/>
      </body></worldbody></mujoco>"""
    m = mjcffi.MjModel.from_xml_string(stiff)
    with pytest.raises(ValueError, match="diverges at its own settings"):
        mjcffi.tune(m, 1e-3, progress=False)


def test_warnings_as_errors_do_not_break_a_search_over_diverging_candidates():
    m = scene("mass_ratio_chain")      # RK4, explicit in damping, diverges here at large steps
    mjcffi.set_warnings_as_errors(True)
    try:
        result = mjcffi.tune(m, 1e-3, control_period=0.01, progress=False)
    finally:
        mjcffi.set_warnings_as_errors(False)
    assert any(math.isinf(max(c.error.values())) for c in result.candidates)
    assert all(math.isfinite(e) for e in result.error.local.values())


def test_tune_is_a_callable_module():
    import mjcffi.tune as module
    assert mjcffi.tune is module is sys.modules["mjcffi.tune"]
    assert callable(module) and module.tune.__doc__.startswith("The cheapest settings")


def test_command_line_writes_the_report_and_the_tuned_mjcf(tmp_path):
    source = tmp_path / "pendulum.xml"
    source.write_text(scenes.HARD_CASES["double_pendulum"])
    out = tmp_path / "tuned.xml"
    run = subprocess.run([sys.executable, "-m", "mjcffi.tune", str(source), "--budget", "1e-4",
                          "--control-period", "0.01", "--out", str(out), "--quiet",
                          "--report", str(tmp_path / "report.md")],
                         capture_output=True, text=True, timeout=300,
                         env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"})
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith("# Tuned settings")
    assert "wrote" in run.stderr and (tmp_path / "report.md").read_text().rstrip("\n") == run.stdout.rstrip("\n")
    tuned_model = mjcffi.MjModel.from_xml_path(str(out))
    assert tuned_model.opt.timestep == pytest.approx(0.01)
    # an impossible budget exits 1 with the reason; a bad one is a usage error
    bad = subprocess.run([sys.executable, "-m", "mjcffi.tune", str(source), "--budget", "1e-15",
                          "--control-period", "0.01", "--quiet"],
                         capture_output=True, text=True, timeout=300)
    assert bad.returncode == 1 and "no setting met the budget" in bad.stderr
    usage = subprocess.run([sys.executable, "-m", "mjcffi.tune", str(source), "--budget", "x"],
                           capture_output=True, text=True, timeout=60)
    assert usage.returncode == 2 and "not a number or 'original'" in usage.stderr
