"""mujoco-py's PID actuators (mjcffi.sim._pid.set_pid_control, C callbacks in mjcffi/_c/sim_pid.c).

The callbacks are process-global: the autouse fixture clears mjcb_act_gain and
mjcb_act_bias after each test.  Models are plain mjcffi MjModel / MjData, stepped
with mj_step, so these tests need nothing of MjSim.
"""

import os
import subprocess
import sys
import textwrap

import gymnasium
import numpy as np
import pytest

import mjcffi
from mjcffi._support import callbacks
from mjcffi.sim._pid import set_pid_control

# mujoco-py's inverted pendulum of its test_pid.py, in MuJoCo 4's stricter XML
POLE = """
<mujoco>
  <size nuserdata="{nuserdata}" nuser_actuator="{nuser_actuator}"/>
  <compiler inertiafromgeom="true"/>
  <default>
    <joint armature="0" damping="1" limited="true"/>
    <geom contype="0" friction="1 0.1 0.1"/>
  </default>
  <option gravity="0 0 -9.81" integrator="{integrator}" timestep="0.001"/>
  <worldbody>
    <body name="cart">
      <geom quat="0.707 0 0.707 0" size="0.1 0.1" type="capsule"/>
      <body name="pole">
        <joint axis="0 1 0" name="hinge" range="-90 90" type="hinge"/>
        <geom fromto="0 0 0 0.001 0 0.6" size="0.049 0.3" type="capsule"/>
      </body>
    </body>
  </worldbody>
  <actuator>{actuator}</actuator>
</mujoco>
"""

P_ONLY = '<general ctrlrange="-1 1" gaintype="user" biastype="user" gainprm="200" joint="hinge"/>'
POSITION = '<position ctrlrange="-1 1" kp="200" joint="hinge"/>'
PID = ('<general ctrlrange="-1 1" gaintype="user" biastype="user" forcerange="-100 100" '
       'gainprm="200 10 10.0 0.1 0.1 0" joint="hinge"/>')
CASCADED = ('<general ctrlrange="-1 1" gaintype="user" biastype="user" forcerange="-3 3" '
            'gainprm="{kp} 0 0 {td} {smooth} 10 .1 1.5 {ema} 3" joint="hinge" user="1"/>')
STATE = 5     # userdata numbers per actuator


def pole(actuator, nuserdata=100, nuser_actuator=1, integrator="RK4"):
    model = mjcffi.MjModel.from_xml_string(POLE.format(
        actuator=actuator, nuserdata=nuserdata, nuser_actuator=nuser_actuator,
        integrator=integrator))
    return model, mjcffi.MjData(model)


def cascaded(kp=5, td=0, smooth=0, ema=0.97):
    return CASCADED.format(kp=kp, td=td, smooth=smooth, ema=ema)


@pytest.fixture(autouse=True)
def clear_callbacks():
    yield
    callbacks.set_mjcb_act_gain(None)
    callbacks.set_mjcb_act_bias(None)


# ------------------------------------------------------------ the PID

@pytest.mark.parametrize("ctrl", [0.0, 0.3, -0.7, 1.5])
def test_p_only_follows_a_position_actuator(ctrl):
    """Kp alone is a <position> actuator.  With ctrl 0, Kp * (0 - L) and MuJoCo's
    0 * ctrl + (-Kp) * L are the same double: bit-identical.  Otherwise Kp * (c - L)
    and Kp * c - Kp * L round differently, by a few ulp of the force.  A ctrl out
    of ctrlrange (1.5) is clamped as MuJoCo clamps it for <position>."""
    m, d = pole(P_ONLY)
    set_pid_control(m, d)
    m2, d2 = pole(POSITION)
    d.qpos[0] = d2.qpos[0] = 0.03
    d.ctrl[0] = d2.ctrl[0] = ctrl
    moved = 0.0
    for _ in range(2000):
        mjcffi.mj_step(m, d)
        mjcffi.mj_step(m2, d2)
        if ctrl == 0.0:
            np.testing.assert_array_equal(d.qpos, d2.qpos)
            np.testing.assert_array_equal(d.qvel, d2.qvel)
        else:
            assert abs(d.qpos[0] - d2.qpos[0]) <= 1e-12
        moved = max(moved, abs(d.qpos[0] - 0.03))
    assert moved > 1e-3             # the controller did drive the pole


def test_pid_holds_the_pole_where_p_alone_still_swings():
    """mujoco-py's test_mj_pid, from a larger tilt: the PID settles within 1e-4 in
    3 s, while the same Kp alone (no derivative damping) still swings by more
    than 1e-3 (MuJoCo's joint damping alone takes some 8 s)."""
    m, d = pole(PID)
    set_pid_control(m, d)
    mp, dp = pole(P_ONLY)
    set_pid_control(mp, dp)
    d.qpos[0] = dp.qpos[0] = 0.02
    for _ in range(3000):
        mjcffi.mj_step(m, d)
        mjcffi.mj_step(mp, dp)
    assert abs(d.qpos[0]) < 1e-4
    assert abs(dp.qpos[0]) > 1e-3


def reference_pid(kp, ti, imax, td, smooth, deadband, setpoint, feedback, dt, previous):
    """mujoco-py's PID step, in Python doubles: (output, (error, integral, derivative))."""
    error, integral, derivative = previous
    new_error = setpoint - feedback
    if abs(new_error) < deadband:
        new_error = 0.0
    rate = (new_error - error) / dt
    derivative = (1.0 - smooth) * derivative + smooth * rate
    integral = max(-imax, min(imax, integral + new_error * dt))
    integral_term = integral / ti if ti != 0 else 0.0
    return kp * (new_error + integral_term + derivative * td), (new_error, integral, derivative)


def test_pid_matches_its_formula_bit_for_bit():
    """Under Euler MuJoCo evaluates the force once per step, from the state of the
    step's forward pass, which mj_step leaves in actuator_length: the force and the
    new state can be recomputed exactly.  Deadband, smoothing, integral clamp and
    force limit all act here."""
    m, d = pole('<general gaintype="user" biastype="user" forcerange="-4 4" '
                'gainprm="30 0.5 0.02 0.2 0.3 0.004" joint="hinge"/>', integrator="Euler")
    set_pid_control(m, d)
    d.qpos[0] = 0.2
    clamped = deadbanded = 0
    for step in range(600):
        d.ctrl[0] = 0.3 * np.sin(step / 50)
        before = d.userdata[:3].copy()       # integral, error, derivative
        mjcffi.mj_step(m, d)
        force, (error, integral, derivative) = reference_pid(
            30, 0.5, 0.02, 0.2, 0.3, 0.004, d.ctrl[0], d.actuator_length[0],
            m.opt.timestep, (before[1], before[0], before[2]))
        clamped += abs(force) > 4
        deadbanded += error == 0.0
        assert d.actuator_force[0] == max(-4.0, min(4.0, force))
        assert tuple(d.userdata[:3]) == (integral, error, derivative)
    assert clamped and deadbanded          # both limits were exercised


def test_forcerange_limits_even_when_not_forcelimited():
    """mujoco-py's rule: the controller clamps to a nonzero forcerange itself,
    whatever forcelimited says (MuJoCo would not clamp here)."""
    m, d = pole('<general gaintype="user" biastype="user" forcelimited="false" '
                'forcerange="-2 2" gainprm="200" joint="hinge"/>')
    set_pid_control(m, d)
    d.qpos[0] = 0.05                         # Kp * error = -10 at first
    mjcffi.mj_step(m, d)
    assert d.actuator_force[0] == -2.0


# ------------------------------------------------------- the cascaded controller

def reference_cascade(prm, ctrl, length, velocity, bias, time, dt, forcerange, state):
    """mujoco-py's cascaded step in Python doubles: (force, new state, the desired
    velocity before the velocity limit)."""
    error, integral, derivative, integral_vel, ema = state
    setpoint = prm[8] * ema + (1 - prm[8]) * ctrl if time > 0.0 else ctrl
    desired = ctrl
    if prm[0] != 0:
        desired, (error, integral, derivative) = reference_pid(
            *prm[0:5], 0.0, setpoint, length, dt, (error, integral, derivative))
    limited = max(-prm[9], min(prm[9], desired))
    force, (_, integral_vel, _) = reference_pid(
        prm[5], prm[6], prm[7], 0.0, 0.0, 0.0, limited, velocity, dt, (0.0, integral_vel, 0.0))
    force += bias
    return max(forcerange[0], min(forcerange[1], force)), (
        error, integral, derivative, integral_vel, setpoint), desired


def test_cascade_matches_its_formula_bit_for_bit():
    """As the PID's formula test, for the cascaded controller: the EMA, the
    velocity limit (0.4), the force limit and the gravity term (qfrc_bias of
    the hinge's dof) all act."""
    prm = (8.0, 0.5, 0.3, 0.05, 0.5, 6.0, 0.2, 0.5, 0.9, 0.4)
    m, d = pole('<general gaintype="user" biastype="user" forcerange="-3 3" gainprm="'
                + " ".join(map(str, prm)) + '" joint="hinge" user="1"/>', integrator="Euler")
    set_pid_control(m, d)
    d.qpos[0] = 0.3
    limited = saturated = 0
    for step in range(800):
        d.ctrl[0] = 0.5 * np.sign(np.sin(step / 80))
        before, time = tuple(d.userdata[:5]), d.time
        mjcffi.mj_step(m, d)
        assert d.qfrc_bias[0] != 0.0
        force, state, desired = reference_cascade(prm, d.ctrl[0], d.actuator_length[0],
                                         d.actuator_velocity[0], d.qfrc_bias[0], time,
                                         m.opt.timestep, (-3.0, 3.0), before)
        assert d.actuator_force[0] == force
        assert tuple(d.userdata[:5]) == state
        limited += abs(desired) > prm[9]
        saturated += abs(force) == 3.0
    assert limited and saturated



def test_cascaded_respects_the_force_limit_and_holds():
    m, d = pole(cascaded())
    set_pid_control(m, d)
    d.qpos[0] = -0.05
    forces = []
    for _ in range(1000):
        mjcffi.mj_step(m, d)
        forces.append(abs(d.actuator_force[0]))
    assert max(forces) == 3.0               # reached, and never passed
    assert abs(d.qpos[0]) < 1e-3


def test_cascaded_pd_needs_its_derivative():
    """mujoco-py's PD-PI case: Kp 10 on position holds with Td 0.1, not without."""
    m, d = pole(cascaded(kp=10, td=0.1, smooth=1))
    m2, d2 = pole(cascaded(kp=10))
    set_pid_control(m, d)
    set_pid_control(m2, d2)
    d.qpos[0] = d2.qpos[0] = -0.05
    for _ in range(2000):
        mjcffi.mj_step(m, d)
        mjcffi.mj_step(m2, d2)
    assert abs(d.qpos[0]) < 1e-3
    assert abs(d2.qpos[0]) > 1e-3


def test_cascaded_ema_starts_at_the_setpoint():
    m, d = pole(cascaded(kp=10, td=0.1, smooth=1, ema=0.97))
    m2, d2 = pole(cascaded(kp=10, td=0.1, smooth=1, ema=0.0))
    set_pid_control(m, d)
    set_pid_control(m2, d2)
    d.ctrl[0] = d2.ctrl[0] = 0.2
    mjcffi.mj_step(m, d)
    mjcffi.mj_step(m2, d2)
    # RK4's later stages run at time > 0, where the EMA of 0.2 with itself is 0.2
    assert abs(d.userdata[4] - 0.2) < 1e-15
    assert d2.userdata[4] == 0.2
    d.ctrl[0] = 0.0
    mjcffi.mj_step(m, d)
    assert abs(d.userdata[4] - 0.2 * 0.97 ** 4) < 1e-12    # four stages, four updates


SLIDER = """
<mujoco>
  <size nuserdata="5" nuser_actuator="1"/>
  <option gravity="0 0 0" timestep="0.001"/>
  <worldbody>
    <body><joint name="slide" type="slide" axis="1 0 0"/><geom size=".1" mass="1"/></body>
  </worldbody>
  <actuator>
    <general gaintype="user" biastype="user" gainprm="0 0 0 0 0 50 0.1 10 0 3" joint="slide"
             user="1"/>
  </actuator>
</mujoco>
"""


@pytest.mark.parametrize("ctrl, speed", [(2.0, 2.0), (10.0, 3.0), (-10.0, -3.0)])
def test_cascaded_with_no_position_gain_tracks_a_limited_velocity(ctrl, speed):
    """Position Kp 0: ctrl is the velocity setpoint, clamped to the limit (3)."""
    m = mjcffi.MjModel.from_xml_string(SLIDER)
    d = mjcffi.MjData(m)
    set_pid_control(m, d)
    d.ctrl[0] = ctrl
    for _ in range(3000):
        mjcffi.mj_step(m, d)
    assert abs(d.qvel[0] - speed) < 1e-3


# -------------------------------------------------------- other actuators, other models

def test_actuators_of_other_types_are_unaffected():
    """A real model with a motor: the same trajectory with the callbacks in place."""
    path = os.path.join(os.path.dirname(gymnasium.__file__), "envs/mujoco/assets",
                        "inverted_pendulum.xml")
    m = mjcffi.MjModel.from_xml_path(path)
    runs = []
    for install in (False, True):
        if install:
            set_pid_control(*pole(PID))      # callbacks now global
        d = mjcffi.MjData(m)
        d.qpos[1] = 0.1
        d.ctrl[0] = 0.5
        for _ in range(500):
            mjcffi.mj_step(m, d)
        runs.append((d.qpos.copy(), d.qvel.copy(), d.actuator_force.copy()))
    assert callbacks.get_mjcb_act_bias() is not None
    for before, after in zip(*runs):
        np.testing.assert_array_equal(before, after)


def test_mixed_model_keeps_the_state_of_its_user_actuators_only():
    two = """
    <mujoco>
      <size nuserdata="12" nuser_actuator="1"/>
      <worldbody>
        <body><joint name="a" axis="0 1 0"/><geom size=".1" pos="0 0 .3"/></body>
        <body pos="1 0 0"><joint name="b" axis="0 1 0"/><geom size=".1" pos="0 0 .3"/></body>
      </worldbody>
      <actuator>
        <position joint="a" kp="50"/>
        <general gaintype="user" biastype="user" gainprm="50" joint="b"/>
      </actuator>
    </mujoco>"""
    m = mjcffi.MjModel.from_xml_string(two)
    d = mjcffi.MjData(m)
    d.userdata[:] = 7.0
    set_pid_control(m, d)
    np.testing.assert_array_equal(d.userdata, [0.0] * 10 + [7.0] * 2)
    d.qpos[:] = 0.05
    d.ctrl[:] = 0.1
    mjcffi.mj_step(m, d)
    assert np.all(d.userdata[:5] == 0.0)         # the position actuator has no state
    assert d.userdata[6] != 0.0                   # actuator 1's error, in its own slots
    np.testing.assert_array_equal(d.userdata[10:], [7.0, 7.0])
    # both are Kp (ctrl - length) at the first forward pass, up to rounding
    assert d.actuator_force[0] == pytest.approx(d.actuator_force[1], rel=1e-12)


def test_an_unchecked_model_gets_no_force_and_no_crash():
    """The callbacks are global: a model set_pid_control never saw, with no room for
    state, must not be written past its userdata (run apart: a bug would crash)."""
    code = textwrap.dedent(f"""
        import mjcffi
        from mjcffi.sim._pid import set_pid_control
        POLE = {POLE!r}
        def build(nuserdata, nuser_actuator):
            return mjcffi.MjModel.from_xml_string(POLE.format(actuator={PID!r},
                nuserdata=nuserdata, nuser_actuator=nuser_actuator, integrator="RK4"))
        checked = build(100, 1)
        set_pid_control(checked, mjcffi.MjData(checked))
        for nuserdata in (0, 4):
            m = build(nuserdata, 0)
            d = mjcffi.MjData(m)
            d.qpos[0] = 0.1
            for _ in range(100):
                mjcffi.mj_step(m, d)
            assert d.actuator_force[0] == 0.0, d.actuator_force
        print("ok")
    """)
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"


# ------------------------------------------------------------------ bad models

def test_too_little_userdata_raises():
    m, d = pole(PID, nuserdata=4)
    with pytest.raises(ValueError, match="nuserdata is 4.*nuserdata=\"5\""):
        set_pid_control(m, d)
    assert callbacks.get_mjcb_act_bias() is None      # nothing installed


def test_no_user_field_raises():
    """mujoco-py's test_mjsize_exception: the controller type needs user[0]."""
    m, d = pole(PID, nuser_actuator=0)
    with pytest.raises(ValueError, match="nuser_actuator is 0"):
        set_pid_control(m, d)


def test_cascaded_on_a_ball_joint_raises():
    ball = """
    <mujoco>
      <size nuserdata="5" nuser_actuator="1"/>
      <worldbody><body><joint name="j" type="ball"/><geom size=".1"/></body></worldbody>
      <actuator><general gaintype="user" biastype="user" joint="j" user="1"/></actuator>
    </mujoco>"""
    m = mjcffi.MjModel.from_xml_string(ball)
    with pytest.raises(ValueError, match="actuator 0 is cascaded.*hinge or slide"):
        set_pid_control(m, mjcffi.MjData(m))


def test_data_of_another_model_raises():
    m, _ = pole(PID)
    other = mjcffi.MjModel.from_xml_string("<mujoco><worldbody/></mujoco>")
    with pytest.raises(ValueError):
        set_pid_control(m, mjcffi.MjData(other))
    with pytest.raises(TypeError):
        set_pid_control(m, "data")


def test_a_model_with_no_user_actuators_is_accepted():
    m, d = pole(POSITION, nuserdata=0, nuser_actuator=0)
    set_pid_control(m, d)
    assert callbacks.get_mjcb_act_bias() is not None
