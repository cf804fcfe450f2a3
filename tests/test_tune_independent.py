"""mjcffi.tune checked from outside, on gymnasium's models: from fresh states (a seed and a
way of drawing them that tune never used), stepped here with plain mj_step, with joint
errors computed here from mju_subQuat:

- one control period: each joint kind's 90 % quantile of its largest error, against a fine
  reference built here (RK4 at timestep / 100, Newton at 1e-12), within the budget;
- 0.5 s: how far the tuned model strays from the original settings at timestep / 8, within
  what the budget states: the original's own distance plus the budget over the periods of
  those 0.5 s.  A kind whose original already strays further than that accumulated budget
  is chaotic over 0.5 s and states nothing (tune says so in its report, and checks the
  same); the test then checks that tune reported it so.
"""

import math
import os

import numpy as np
import pytest

import mjcffi

from .test_tune import _kind_errors

FULL = int(mjcffi.mjtState.mjSTATE_FULLPHYSICS)
MODELS = ("inverted_pendulum", "reacher", "swimmer", "hopper")
BUDGETS = (1e-2, 1e-3)
HORIZON = 0.5


def load(name):
    import gymnasium
    return mjcffi.MjModel.from_xml_path(os.path.join(
        os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets", f"{name}.xml"))


def controls(m, rng, n):
    if not m.nu:
        return np.zeros((n, 0))
    lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
    return rng.uniform(lo, hi, (n, m.nu))


def fresh_states(m, rng, n, period):
    """States along runs of the original from its keyframe (or qpos0), perturbed by ±0.02
    (tune perturbs by ±0.01), after a random number of periods of random controls."""
    d = mjcffi.MjData(m)
    k = round(period / m.opt.timestep)
    out = []
    for _ in range(n):
        if m.nkey:
            mjcffi.mj_resetDataKeyframe(m, d, 0)
        else:
            mjcffi.mj_resetData(m, d)
        d.qpos[:] += rng.uniform(-0.02, 0.02, m.nq)
        d.qvel[:] += rng.uniform(-0.02, 0.02, m.nv)
        mjcffi.mj_normalizeQuat(m, d.qpos)
        for u in controls(m, rng, int(rng.integers(0, 60))):
            d.ctrl[:] = u
            mjcffi.mj_step(m, d, nstep=k)
        s = np.empty(mjcffi.mj_stateSize(m, FULL))
        mjcffi.mj_getState(m, d, s, FULL)
        out.append((s, d.qacc_warmstart.copy()))
    return out


def run(m, start, us, period):
    s, warm = start
    d = mjcffi.MjData(m)
    mjcffi.mj_setState(m, d, s, FULL)
    d.qacc_warmstart[:] = warm
    k = round(period / m.opt.timestep)
    for u in us:
        d.ctrl[:] = u
        mjcffi.mj_step(m, d, nstep=k)
    return d.qpos.copy()


def q90(rows):
    kinds = rows[0].keys()
    return {k: float(np.quantile([r[k] for r in rows], 0.9)) for k in kinds}


def with_options(name, **options):
    m = load(name)
    for field, value in options.items():
        setattr(m.opt, field, value)
    return m


@pytest.fixture(scope="module")
def tuned():
    out = {}
    with mjcffi.ignore_warnings():
        for name in MODELS:
            m = load(name)
            for budget in BUDGETS:
                out[name, budget] = (m, mjcffi.tune(m, budget, progress=False))
    return out


@pytest.mark.parametrize("budget", BUDGETS)
@pytest.mark.parametrize("name", MODELS)
def test_one_period_from_fresh_states_is_within_the_budget(tuned, name, budget):
    m, r = tuned[name, budget]
    period = r.control_period
    ref = with_options(name, integrator=int(mjcffi.mjtIntegrator.mjINT_RK4),
                       timestep=m.opt.timestep / 100, solver=int(mjcffi.mjtSolver.mjSOL_NEWTON),
                       iterations=100, tolerance=1e-12, ls_iterations=50)
    ref.opt.disableflags = r.model.opt.disableflags
    rng = np.random.default_rng(4242)
    rows = []
    with mjcffi.ignore_warnings():
        for start in fresh_states(m, rng, 120, period):
            u = controls(m, rng, 1)
            rows.append(_kind_errors(m, run(r.model, start, u, period),
                                    run(ref, start, u, period)))
    for kind, e in q90(rows).items():
        assert e <= budget, (name, budget, kind, e, r.report())


@pytest.mark.parametrize("budget", BUDGETS)
@pytest.mark.parametrize("name", MODELS)
def test_half_a_second_from_fresh_states_is_within_the_stated_budget(tuned, name, budget):
    m, r = tuned[name, budget]
    period = r.control_period
    nperiod = max(1, round(HORIZON / period))
    fine = with_options(name, timestep=m.opt.timestep / 8)
    rng = np.random.default_rng(2424)
    tuned_rows, original_rows = [], []
    with mjcffi.ignore_warnings():
        for start in fresh_states(m, rng, 64, period):
            us = controls(m, rng, nperiod)
            truth = run(fine, start, us, period)
            tuned_rows.append(_kind_errors(m, run(r.model, start, us, period), truth))
            original_rows.append(_kind_errors(m, run(m, start, us, period), truth))
    tuned_q, original_q = q90(tuned_rows), q90(original_rows)
    stated = r.error.divergence
    for kind, e in tuned_q.items():
        accumulated = nperiod * r.error.budget[kind]
        if original_q[kind] > accumulated:
            # chaotic over 0.5 s: tune must have said so rather than state a figure
            # (its own draw of states may fall either side of the line when close to it)
            if original_q[kind] > 4 * accumulated:
                assert stated.allowed[kind] == math.inf, (name, kind, r.report())
            continue
        assert e <= original_q[kind] + accumulated, (name, budget, kind, e, original_q[kind],
                                                     r.report())
