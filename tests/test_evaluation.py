"""mjcffi.evaluation: the core shared by the accuracy report and tune."""

import math

import numpy as np
import pytest

import mjcffi
from mjcffi import scenes
from mjcffi.evaluation import measures, periods, reference, states
from mjcffi.evaluation.settings import Setting


def test_a_period_under_the_models_own_setting_replays_its_trajectory_bit_for_bit():
    # every boundary, with its warm start and control, leads to the next boundary exactly
    m = mjcffi.MjModel.from_xml_string(scenes.DEFAULT)
    rng = np.random.default_rng(3)
    init = states.initial_states(m, 3, rng)
    controls = states.random_controls(m, rng, (3, 12))
    samples, diverged = states.sample(m, init, controls, 4, nsample=10**6)
    assert not diverged and len(samples) == 36
    with periods.new_pool(2) as pool:
        end, ok = periods.end_states(pool, periods.setting_model(m, Setting.of(m)), samples, 4, 2)
    assert ok.all()
    follows = [i for i in range(len(samples) - 1) if (i + 1) % 12]   # not a trajectory's last
    assert np.array_equal(end[follows], samples.states[[i + 1 for i in follows]])


def test_a_diverging_setting_is_marked_not_ok():
    m = mjcffi.MjModel.from_xml_string(scenes.HARD_CASES["mass_ratio_chain"])
    rng = np.random.default_rng(0)
    samples, _ = states.sample(m, states.initial_states(m, 2, rng),
                               np.zeros((2, 10, 0)), 5, nsample=20)
    # explicit in the damping of the light links: RK4 diverges where Euler (implicit
    # damping) does not
    fast = Setting.of(m).replace(integrator=int(mjcffi.mjtIntegrator.mjINT_RK4), timestep=0.01)
    with mjcffi.ignore_warnings(), periods.new_pool(0) as pool:
        _, ok = periods.end_states(pool, periods.setting_model(m, fast), samples, 20, 1)
    assert not ok.all()


def test_random_controls_stay_in_ctrlrange():
    m = mjcffi.MjModel.from_xml_string(scenes.DEFAULT)
    u = states.random_controls(m, np.random.default_rng(1), (50, 7))
    assert u.shape == (50, 7, m.nu)
    assert np.all(u >= -1) and np.all(u <= 1) and u.std() > 0.3


def test_the_reference_is_rk4_at_a_hundredth_of_the_timestep_with_a_tight_solver():
    m = mjcffi.MjModel.from_xml_string(scenes.HARD_CASES["box_stack"])
    ref = reference.reference_setting(m)
    assert ref.integrator == mjcffi.mjtIntegrator.mjINT_RK4
    assert ref.timestep == m.opt.timestep / 100
    assert (ref.solver, ref.tolerance) == (mjcffi.mjtSolver.mjSOL_NEWTON, 1e-12)
    assert ref.iterations >= 100 and ref.ls_iterations >= 50
    loose = reference.reference_setting(m, tight_solver=False, timestep=0.01)
    assert loose.timestep == 1e-4 and loose.solver is None


def test_steps_per_period_needs_a_whole_number():
    assert periods.steps_per_period(0.01, 0.002) == 5
    with pytest.raises(ValueError, match="whole number"):
        periods.steps_per_period(0.01, 0.003)


def test_joint_errors_per_kind():
    m = mjcffi.MjModel.from_xml_string("""<mujoco><worldbody>
      <body><freejoint/><geom size=".1"/></body>
      <body pos="1 0 0"><joint type="ball"/><geom size=".1"/>
        <body><joint type="slide"/><joint type="hinge"/><geom size=".1"/></body></body>
      </worldbody></mujoco>""")
    ref = np.tile(m.qpos0, (2, 1))
    q = ref.copy()
    q[1, 0] += 0.003                       # free position, m
    half = 0.01 / 2                        # a 0.01 rad turn about z of the ball joint
    q[1, 7:11] = [math.cos(half), 0, 0, math.sin(half)]
    q[1, 11] += 0.2                        # slide, m
    q[1, 12] -= 0.5                        # hinge, rad
    errs = measures.joint_errors(m, q, ref)
    assert list(errs) == ["free_pos", "free_rot", "ball", "slide", "hinge"]
    assert errs["free_pos"].tolist() == [0, pytest.approx(0.003)]
    assert errs["free_rot"].tolist() == [0, 0]
    assert errs["ball"][1] == pytest.approx(0.01, rel=1e-9)
    assert errs["slide"][1] == pytest.approx(0.2) and errs["hinge"][1] == pytest.approx(0.5)
    local = measures.local_error(m, q, ref)
    assert local["hinge"] == pytest.approx(0.5 / math.sqrt(2))
    assert measures.within(local, {"hinge": 0.4}) and not measures.within(local, {"hinge": 0.3})
    assert measures.worst_ratio(local, {"hinge": 0.5 / math.sqrt(2), "slide": 1.0}) \
        == pytest.approx(1.0)
    q[0, 12] = np.nan
    assert measures.local_error(m, q, ref)["hinge"] == math.inf


def test_setting_apply_changes_and_label():
    m = mjcffi.MjModel.from_xml_string(scenes.HARD_CASES["box_stack"])
    own = Setting.of(m)
    s = own.replace(integrator=int(mjcffi.mjtIntegrator.mjINT_RK4), timestep=0.004,
                    iterations=3, cone=int(mjcffi.mjtCone.mjCONE_ELLIPTIC))
    assert s.changes(own) == {"integrator": (0, 1), "timestep": (0.002, 0.004),
                              "iterations": (100, 3), "cone": (0, 1)}
    assert s.label(own) == "RK4 dt=0.004 iter=3 cone=elliptic"
    copy = periods.setting_model(m, s, base_disable=int(mjcffi.mjtDisableBit.mjDSBL_SENSOR))
    assert (copy.opt.integrator, copy.opt.timestep, copy.opt.iterations, copy.opt.cone) == \
        (1, 0.004, 3, 1)
    assert copy.opt.disableflags == mjcffi.mjtDisableBit.mjDSBL_SENSOR
    assert m.opt.timestep == 0.002          # the model itself is untouched
