"""Static detection of pipeline stages a model cannot need (mjcffi.tune._stages).

Every scene is checked both ways: a stage reported unneeded must leave the
trajectory bit-identical when switched off, and a stage a scene was built to
need must change the trajectory when switched off.
"""

import numpy as np
import pytest

import mjcffi
from mjcffi.tune._stages import Stage, unneeded_stages
from tests.conftest import gymnasium_assets

DSBL = mjcffi.mjtDisableBit
FLAGS = {
    "contact": int(DSBL.mjDSBL_CONTACT),
    "constraint": int(DSBL.mjDSBL_CONSTRAINT),
    "passive": int(DSBL.mjDSBL_SPRING) | int(DSBL.mjDSBL_DAMPER),
    "actuation": int(DSBL.mjDSBL_ACTUATION),
    "sensor": int(DSBL.mjDSBL_SENSOR),
}
STEPS = 200


def trajectory(m, extra_flags=0, steps=STEPS):
    """qpos, qvel, act and sensordata of every step under random controls."""
    saved = m.opt.disableflags
    m.opt.disableflags = saved | extra_flags
    try:
        d = mjcffi.MjData(m)
        rng = np.random.default_rng(7)
        rows = []
        for _ in range(steps):
            if m.nu:
                d.ctrl[:] = rng.uniform(-1.0, 1.0, m.nu)
            mjcffi.mj_step(m, d)
            rows.append(np.concatenate([d.qpos, d.qvel, d.act, d.sensordata]))
        return np.array(rows)
    finally:
        m.opt.disableflags = saved


def changes_trajectory(m, flag):
    return not np.array_equal(trajectory(m), trajectory(m, flag))


def names(m):
    return {stage.name for stage in unneeded_stages(m)}


def assert_unneeded_are_exact(m):
    """Switching off each reported stage changes no trajectory bit."""
    stages = unneeded_stages(m)
    base = trajectory(m)
    for stage in stages:
        assert np.array_equal(base, trajectory(m, stage.flag)), stage.name
    return stages


def assert_needed(m, name):
    """The scene needs the stage: it is not reported, and switching it off matters."""
    assert name not in names(m)
    assert changes_trajectory(m, FLAGS[name]), name


def scene(body, world="", option="", flags="", extra=""):
    return mjcffi.MjModel.from_xml_string(f"""
<mujoco>
  <option {option}><flag {flags}/></option>
  <worldbody>{world}{body}</worldbody>
  {extra}
</mujoco>""")


# A horizontal pendulum: it swings from rest, and its geom touches nothing.
ARM = """
<body name="arm" pos="0 0 2">
  <joint name="hinge" axis="0 1 0" {joint}/>
  <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.05" {geom}/>
</body>"""


def arm(joint="", geom="", **kw):
    return scene(ARM.format(joint=joint, geom=geom), **kw)


FLOOR = '<geom name="floor" type="plane" size="5 5 0.1" {attrs}/>'
BALL = """
<body pos="0 0 0.12">
  <freejoint/>
  <geom type="sphere" size="0.1" {attrs}/>
</body>"""


def ball_on_floor(floor="", ball="", **kw):
    return scene(BALL.format(attrs=ball), world=FLOOR.format(attrs=floor), **kw)


# ------------------------------------------------------------ plain scenes


def test_plain_arm_needs_only_what_it_uses():
    m = arm()
    stages = assert_unneeded_are_exact(m)
    assert [s.name for s in stages] == ["contact", "constraint", "passive", "actuation", "sensor"]
    assert all(isinstance(s, Stage) and s.reason for s in stages)
    assert stages[2].flag == FLAGS["passive"]


def test_stage_fields_are_the_disable_bits():
    for stage in unneeded_stages(arm()):
        assert stage.flag == FLAGS[stage.name]
        assert isinstance(stage.flag, int)


# ------------------------------------------------------------------ contact


def test_ball_on_floor_needs_contact_and_constraint():
    m = ball_on_floor()
    assert_needed(m, "contact")
    assert_needed(m, "constraint")
    assert_unneeded_are_exact(m)


def test_contype_conaffinity_that_never_match():
    m = ball_on_floor(floor='contype="1" conaffinity="2"', ball='contype="1" conaffinity="2"')
    assert {"contact", "constraint"} <= names(m)
    assert_unneeded_are_exact(m)


def test_one_sided_bitmask_match_is_enough():
    m = ball_on_floor(floor='contype="2" conaffinity="0"', ball='contype="0" conaffinity="2"')
    assert_needed(m, "contact")


def test_exclude_pair_removes_contact():
    bodies = """
<body name="a" pos="0 0 1"><joint axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.1"/></body>
<body name="b" pos="0.1 0 1"><joint axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0.5 0 0.1" size="0.1"/></body>"""
    assert_needed(scene(bodies), "contact")
    m = scene(bodies, extra='<contact><exclude body1="b" body2="a"/></contact>')
    assert "contact" in names(m)
    assert_unneeded_are_exact(m)


def test_exclude_of_another_pair_keeps_contact():
    bodies = """
<body name="a" pos="0 0 1"><joint axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.1"/></body>
<body name="b" pos="0.1 0 1"><joint axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0.5 0 0.1" size="0.1"/></body>
<body name="c" pos="3 0 1"><joint axis="0 1 0"/><geom size="0.1"/></body>"""
    m = scene(bodies, extra='<contact><exclude body1="a" body2="c"/></contact>')
    assert_needed(m, "contact")


PARENT_CHILD = """
<body name="parent" pos="0 0 1"><joint axis="0 1 0"/>
  <geom pos="0.5 0 0" size="0.15"/>
  <body name="child" pos="0.3 0 0"><joint axis="0 1 0"/>
    <geom pos="0.3 0 0.1" size="0.15"/></body>
</body>"""


def test_parent_child_pair_is_filtered():
    m = scene(PARENT_CHILD)
    assert "contact" in names(m)
    assert_unneeded_are_exact(m)


def test_parent_child_pair_collides_without_filterparent():
    m = scene(PARENT_CHILD, flags='filterparent="disable"')
    assert_needed(m, "contact")


def test_static_geoms_never_collide_with_each_other():
    world = """
<geom type="plane" size="5 5 0.1"/>
<body pos="0 0 0.05"><geom type="box" size="0.2 0.2 0.2"/></body>"""
    m = scene(ARM.format(joint="", geom='contype="0" conaffinity="0"'), world=world)
    assert "contact" in names(m)
    assert_unneeded_are_exact(m)


def test_mocap_body_and_world_never_collide():
    # A mocap body is its own weld body, so only the dof-free filter drops it.
    world = """
<geom type="plane" size="5 5 0.1"/>
<body mocap="true" pos="0 0 0.05"><geom type="box" size="0.2 0.2 0.2"/></body>"""
    m = scene(ARM.format(joint="", geom='contype="0" conaffinity="0"'), world=world)
    assert m.body_mocapid[1] == 0 and m.body_weldid[1] == 1
    assert "contact" in names(m)
    assert_unneeded_are_exact(m)


def test_explicit_pair_needs_contact():
    m = ball_on_floor(floor='contype="0" conaffinity="0"',
                      ball='name="ball" contype="0" conaffinity="0"',
                      extra='<contact><pair geom1="floor" geom2="ball"/></contact>')
    assert_needed(m, "contact")


def test_already_disabled_contact_is_not_listed():
    m = ball_on_floor(flags='contact="disable"')
    assert "contact" not in names(m)
    assert "constraint" in names(m)
    assert_unneeded_are_exact(m)


def _many_spheres(n, last_collides):
    """n free spheres whose bitmasks never match; optionally the last one does."""
    spheres = []
    for i in range(n):
        attrs = 'contype="1" conaffinity="1"' if last_collides and i == n - 1 else \
            'contype="1" conaffinity="2"'
        spheres.append(f'<body pos="{i % 40} {i // 40} 0.09"><freejoint/>'
                       f'<geom size="0.1" {attrs}/></body>')
    floor = FLOOR.format(attrs='contype="1" conaffinity="2"')
    return scene("".join(spheres), world=floor)


def test_thousand_geoms_without_a_match():
    m = _many_spheres(1000, last_collides=False)
    assert m.ngeom == 1001
    assert {"contact", "constraint"} <= names(m)


def test_thousand_geoms_with_one_match_past_the_first_block():
    assert "contact" not in names(_many_spheres(1000, last_collides=True))


# --------------------------------------------------------------- constraint


def test_limited_joint_needs_constraint():
    m = arm(joint='range="-10 10" limited="true"')
    assert "contact" in names(m)
    assert_needed(m, "constraint")
    assert_unneeded_are_exact(m)


# Two pendulums whose geoms never collide: only an equality could couple them.
TWO_ARMS = ARM.format(joint="", geom='contype="0" conaffinity="0"') + """
<body name="other" pos="0 2 2"><joint name="hinge2" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05" contype="0" conaffinity="0"/></body>"""


def test_equality_needs_constraint():
    bodies = TWO_ARMS
    m = scene(bodies, extra='<equality><joint joint1="hinge" joint2="hinge2"/></equality>')
    assert "contact" in names(m)
    assert_needed(m, "constraint")
    assert_unneeded_are_exact(m)


def test_disabled_equality_leaves_constraint_unneeded():
    bodies = TWO_ARMS
    m = scene(bodies, flags='equality="disable"',
              extra='<equality><joint joint1="hinge" joint2="hinge2"/></equality>')
    assert "constraint" in names(m)
    assert_unneeded_are_exact(m)


def test_frictionloss_is_a_constraint():
    m = arm(joint='frictionloss="0.5"')
    assert_needed(m, "constraint")
    assert_unneeded_are_exact(m)
    reason = next(s.reason for s in unneeded_stages(arm()) if s.name == "constraint")
    assert "frictionloss" in reason


def test_tendon_frictionloss_and_limit_need_constraint():
    for attrs in ('frictionloss="0.5"', 'limited="true" range="-0.1 0.1"'):
        m = arm(extra=f'<tendon><fixed {attrs}><joint joint="hinge" coef="1"/></fixed></tendon>')
        assert_needed(m, "constraint")


# ------------------------------------------------------------------ passive


@pytest.mark.parametrize("joint, option", [
    ('stiffness="5"', ""),
    ('damping="0.5"', ""),
    ("", 'density="1000"'),
    ("", 'viscosity="1"'),
])
def test_passive_sources(joint, option):
    m = arm(joint=joint, option=option)
    assert_needed(m, "passive")
    assert_unneeded_are_exact(m)


def test_gravcomp_needs_passive():
    m = scene(ARM.replace('name="arm"', 'name="arm" gravcomp="1"').format(joint="", geom=""))
    assert_needed(m, "passive")
    assert_unneeded_are_exact(m)


def test_gravcomp_without_gravity_is_not_a_passive_force():
    m = scene(ARM.replace('name="arm"', 'name="arm" gravcomp="1"').format(joint="", geom=""),
              option='gravity="0 0 0"', extra='<actuator><motor joint="hinge"/></actuator>')
    assert "passive" in names(m)
    assert_unneeded_are_exact(m)


def test_tendon_spring_needs_passive():
    m = arm(extra='<tendon><fixed stiffness="5" springlength="1">'
                  '<joint joint="hinge" coef="1"/></fixed></tendon>')
    assert_needed(m, "passive")
    assert_unneeded_are_exact(m)


def test_tendon_damper_needs_passive():
    m = arm(extra='<tendon><fixed damping="2"><joint joint="hinge" coef="1"/></fixed></tendon>')
    assert_needed(m, "passive")


def test_actuator_damping_needs_passive():
    m = arm(option='integrator="Euler"',
            extra='<actuator><motor joint="hinge" damping="1"/></actuator>')
    assert_needed(m, "passive")
    assert_unneeded_are_exact(m)


def test_wind_alone_is_not_a_passive_force():
    m = arm(option='wind="5 0 0"')
    assert "passive" in names(m)
    assert_unneeded_are_exact(m)


@pytest.mark.parametrize("integrator", ["Euler", "RK4", "implicit", "implicitfast"])
def test_unneeded_passive_is_exact_under_every_integrator(integrator):
    m = arm(option=f'integrator="{integrator}"',
            extra='<actuator><motor joint="hinge"/></actuator>')
    assert "passive" in names(m)
    assert_unneeded_are_exact(m)


# ------------------------------------------------------- actuation, sensor


def test_motor_needs_actuation():
    m = arm(extra='<actuator><motor joint="hinge"/></actuator>')
    assert_needed(m, "actuation")
    assert "actuation" not in names(m)
    assert_unneeded_are_exact(m)


def test_sensor_needs_sensor_stage():
    m = arm(extra='<sensor><jointpos joint="hinge"/></sensor>')
    assert_needed(m, "sensor")
    assert_unneeded_are_exact(m)


def test_already_disabled_stages_are_not_listed():
    m = arm(flags='sensor="disable" actuation="disable" spring="disable" damper="disable"')
    assert names(m) == {"contact", "constraint"}


def test_half_disabled_passive_is_still_listed():
    m = arm(flags='spring="disable"')
    assert "passive" in names(m)
    assert_unneeded_are_exact(m)


# ---------------------------------------------------------------- gymnasium


def _gym(name):
    path = next(p for p in gymnasium_assets() if p.name == name)
    return mjcffi.MjModel.from_xml_path(str(path))


def test_hopper_needs_all_but_sensor():
    m = _gym("hopper.xml")
    assert names(m) == {"sensor"}
    for name in ("contact", "constraint", "passive", "actuation"):
        assert changes_trajectory(m, FLAGS[name]), name


def test_inverted_pendulum_cannot_touch_anything():
    m = _gym("inverted_pendulum.xml")
    assert "contact" in names(m)
    assert_needed(m, "constraint")


def test_point_has_no_passive_force():
    assert "passive" in names(_gym("point.xml"))


def test_official_bindings_model_gives_the_same_answer(mujoco):
    path = next(p for p in gymnasium_assets() if p.name == "reacher.xml")
    ours = unneeded_stages(mjcffi.MjModel.from_xml_path(str(path)))
    theirs = unneeded_stages(mujoco.MjModel.from_xml_path(str(path)))
    assert ours == theirs
    assert {s.name for s in ours} == {"contact", "sensor"}


@pytest.mark.parametrize("path", gymnasium_assets(), ids=lambda p: p.name)
def test_gymnasium_unneeded_stages_are_exact(path):
    m = mjcffi.MjModel.from_xml_path(str(path))
    stages = assert_unneeded_are_exact(m)
    assert "sensor" in {s.name for s in stages}  # none of them has a sensor
