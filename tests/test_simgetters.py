"""mujoco-py's named getters (mjcffi/_simgetters.py), checked against independent computations."""

import numpy as np
import pytest

import mjcffi
from mjcffi._simgetters import SimDataGetters, SimModelGetters, UnknownNameError

from .conftest import gymnasium_assets

SCENE = __import__("pathlib").Path(__file__).parent / "scenes" / "every_category.xml"


class M(SimModelGetters, mjcffi.MjModel):
    pass


class D(SimDataGetters, mjcffi.MjData):
    pass


def _moving(path, seed=0):
    """Model and data at a random state with random velocities, after mj_forward."""
    m = M.from_xml_path(str(path))
    d = D(m)
    rng = np.random.default_rng(seed)
    if m.nkey:
        mjcffi.mj_resetDataKeyframe(m, d, 0)
    mjcffi.mj_integratePos(m, d.qpos, rng.normal(size=m.nv) * 0.3, 1.0)
    d.qvel[:] = rng.normal(size=m.nv)
    mjcffi.mj_forward(m, d)
    return m, d


def _humanoid():
    return next(p for p in gymnasium_assets() if p.name == "humanoid.xml")


@pytest.fixture(params=["every_category", "humanoid"])
def moving(request):
    return _moving(SCENE if request.param == "every_category" else _humanoid())


def _shifted(m, d, dt):
    """A copy of d with qpos moved by qvel * dt, positions recomputed."""
    e = D(m)
    e.qpos[:] = d.qpos
    mjcffi.mj_integratePos(m, e.qpos, d.qvel, dt)
    mjcffi.mj_kinematics(m, e)
    return e


def _names(m, count, category):
    return [mjcffi.mj_id2name(m, getattr(mjcffi.mjtObj, "mjOBJ_" + category), i)
            for i in range(count)]


def test_model_getters_follow_the_categories():
    m = M.from_xml_path(str(SCENE))
    for public, size, obj in [("body", "nbody", "BODY"), ("joint", "njnt", "JOINT"),
                              ("geom", "ngeom", "GEOM"), ("site", "nsite", "SITE"),
                              ("camera", "ncam", "CAMERA"), ("light", "nlight", "LIGHT"),
                              ("actuator", "nactuator", "ACTUATOR"),
                              ("sensor", "nsensor", "SENSOR"), ("tendon", "ntendon", "TENDON"),
                              ("mesh", "nmesh", "MESH"), ("material", "nmat", "MATERIAL"),
                              ("texture", "ntex", "TEXTURE"), ("equality", "neq", "EQUALITY"),
                              ("keyframe", "nkey", "KEY"), ("numeric", "nnumeric", "NUMERIC"),
                              ("text", "ntext", "TEXT"), ("tuple", "ntuple", "TUPLE"),
                              ("hfield", "nhfield", "HFIELD"), ("pair", "npair", "PAIR"),
                              ("exclude", "nexclude", "EXCLUDE")]:
        count = getattr(m, size)
        assert count >= 1, public
        names = getattr(m, public + "_names")
        assert isinstance(names, tuple)
        assert list(names) == _names(m, count, obj), public
        for i, name in enumerate(names):
            assert getattr(m, public + "_id2name")(i) == name
            if name is not None:
                assert getattr(m, public + "_name2id")(name) == i
                assert mjcffi.mj_name2id(m, getattr(mjcffi.mjtObj, "mjOBJ_" + obj), name) == i


def test_unnamed_elements_and_bad_names_and_ids():
    m = M.from_xml_string('<mujoco><worldbody><body><geom size="1"/></body>'
                          '<body name="b"><geom size="1"/></body></worldbody></mujoco>')
    assert m.body_names == ("world", None, "b")
    assert m.geom_id2name(0) is None
    with pytest.raises(ValueError, match="'bb'.*'b'") as info:
        m.body_name2id("bb")
    assert isinstance(info.value, KeyError) and isinstance(info.value, UnknownNameError)
    with pytest.raises(KeyError):
        m.geom_name2id("nothing")
    with pytest.raises(IndexError):
        m.body_id2name(3)
    with pytest.raises(IndexError):
        m.body_id2name(-1)
    with pytest.raises(TypeError):
        m.body_name2id(1)
    d = D(m)
    mjcffi.mj_forward(m, d)
    for getter in (d.get_body_xpos, d.get_body_xvelp, d.get_body_jacr, d.get_geom_xmat,
                   d.get_site_xpos, d.get_joint_qpos, d.get_sensor, d.get_mocap_pos):
        with pytest.raises(ValueError, match="nope"):
            getter("nope")
    with pytest.raises(ValueError, match="not a mocap body"):
        d.get_mocap_pos("b")


@pytest.mark.parametrize("path", [SCENE, _humanoid()], ids=["every_category", "humanoid"])
def test_joint_addresses(path):
    m = M.from_xml_path(str(path))
    widths = {0: (7, 6), 1: (4, 3), 2: (1, 1), 3: (1, 1)}
    for j, name in enumerate(m.joint_names):
        qw, vw = widths[int(m.jnt_type[j])]
        qa, va = int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j])
        assert m.get_joint_qpos_addr(name) == (qa if qw == 1 else (qa, qa + qw))
        assert m.get_joint_qvel_addr(name) == (va if vw == 1 else (va, va + vw))
        a = m.get_joint_qpos_addr(name)
        assert isinstance(a, int) or all(isinstance(x, int) for x in a)


def test_joint_qpos_qvel_get_and_set(moving):
    m, d = moving
    for j, name in enumerate(m.joint_names):
        qa, va = int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j])
        for what, adr in (("qpos", qa), ("qvel", va)):
            got = getattr(d, "get_joint_" + what)(name)
            array = getattr(d, what)
            if np.ndim(got) == 0:
                assert got == array[adr]
                getattr(d, "set_joint_" + what)(name, 0.25)
                assert array[adr] == 0.25
                with pytest.raises(ValueError):
                    getattr(d, "set_joint_" + what)(name, [1.0, 2.0])
            else:
                n = len(got)
                np.testing.assert_array_equal(got, array[adr:adr + n])
                got[:] = 99                                     # a copy
                assert not np.any(array[adr:adr + n] == 99)
                value = np.arange(n) / 10
                getattr(d, "set_joint_" + what)(name, value)
                np.testing.assert_array_equal(array[adr:adr + n], value)
                with pytest.raises(ValueError):
                    getattr(d, "set_joint_" + what)(name, np.zeros(n + 1))


def test_positions_are_copies_of_the_rows(moving):
    m, d = moving
    for obj, size, fields in [("body", m.nbody, {"xpos": d.xpos, "xquat": d.xquat,
                                                 "xmat": d.xmat, "xipos": d.xipos,
                                                 "ximat": d.ximat}),
                              ("geom", m.ngeom, {"xpos": d.geom_xpos, "xmat": d.geom_xmat}),
                              ("site", m.nsite, {"xpos": d.site_xpos, "xmat": d.site_xmat}),
                              ("camera", m.ncam, {"xpos": d.cam_xpos, "xmat": d.cam_xmat}),
                              ("light", m.nlight, {"xpos": d.light_xpos, "xdir": d.light_xdir}),
                              ("joint", m.njnt, {"xanchor": d.xanchor, "xaxis": d.xaxis})]:
        names = getattr(m, obj + "_names")
        for i in range(size):
            if names[i] is None:
                continue
            for quantity, array in fields.items():
                got = getattr(d, f"get_{obj}_{quantity}")(names[i])
                want = array[i].reshape(3, 3) if quantity.endswith("mat") else array[i]
                np.testing.assert_array_equal(got, want)
                got[...] = 7.5
                assert not np.all(array[i] == 7.5), (obj, quantity)
    if m.ncam:
        np.testing.assert_array_equal(d.get_cam_xpos(m.camera_names[0]), d.cam_xpos[0])


def test_velocities_match_the_jacobians_and_finite_differences(moving):
    m, d = moving
    dt = 1e-7
    e = _shifted(m, d, dt)
    for obj, size, pos, mat in [("body", m.nbody, "xpos", "xmat"),
                                ("geom", m.ngeom, "geom_xpos", "geom_xmat"),
                                ("site", m.nsite, "site_xpos", "site_xmat")]:
        names = getattr(m, obj + "_names")
        for i in range(size):
            if names[i] is None:
                continue
            name = names[i]
            velp, velr = getattr(d, f"get_{obj}_xvelp")(name), getattr(d, f"get_{obj}_xvelr")(name)
            jacp, jacr = getattr(d, f"get_{obj}_jacp")(name), getattr(d, f"get_{obj}_jacr")(name)
            assert jacp.shape == jacr.shape == (3, m.nv)
            np.testing.assert_allclose(jacp @ d.qvel, velp, atol=1e-9, rtol=1e-9)
            np.testing.assert_allclose(jacr @ d.qvel, velr, atol=1e-9, rtol=1e-9)
            # finite differences of the frame's position and orientation
            fd_p = (getattr(e, pos)[i] - getattr(d, pos)[i]) / dt
            np.testing.assert_allclose(velp, fd_p, atol=1e-4 * (1 + np.abs(velp).max()))
            r0, r1 = getattr(d, mat)[i].reshape(3, 3), getattr(e, mat)[i].reshape(3, 3)
            w = (r1 @ r0.T - r0 @ r1.T) / (2 * dt)        # skew part: [omega]x
            fd_r = np.array([w[2, 1], w[0, 2], w[1, 0]])
            np.testing.assert_allclose(velr, fd_r, atol=1e-4 * (1 + np.abs(velr).max()))


def test_camera_velocity_by_finite_differences():
    m = M.from_xml_string('<mujoco><worldbody><body name="rig"><freejoint/><geom size=".1"/>'
                          '<camera name="eye" pos=".3 .1 .2" xyaxes="0 1 0 -1 0 1"/>'
                          '</body></worldbody></mujoco>')
    d = D(m)
    d.qvel[:] = [0.4, -0.2, 0.3, 1.1, -0.7, 0.5]
    mjcffi.mj_forward(m, d)
    dt = 1e-7
    e = _shifted(m, d, dt)
    mjcffi.mj_camlight(m, e)                     # cameras are placed after mj_kinematics
    velp, velr = d.get_camera_xvelp("eye"), d.get_camera_xvelr("eye")
    assert np.abs(velp).max() > 0.1 and np.abs(velr).max() > 0.1
    np.testing.assert_allclose(velp, (e.cam_xpos[0] - d.cam_xpos[0]) / dt, atol=1e-5)
    r0, r1 = d.cam_xmat[0].reshape(3, 3), e.cam_xmat[0].reshape(3, 3)
    w = (r1 @ r0.T - r0 @ r1.T) / (2 * dt)
    np.testing.assert_allclose(velr, [w[2, 1], w[0, 2], w[1, 0]], atol=1e-5)
    np.testing.assert_array_equal(d.get_cam_xvelp("eye"), velp)


def test_sensor_scalar_or_array():
    m, d = _moving(SCENE, seed=1)
    for s, name in enumerate(m.sensor_names):
        adr, dim = int(m.sensor_adr[s]), int(m.sensor_dim[s])
        got = d.get_sensor(name)
        if dim == 1:
            assert np.ndim(got) == 0 and got == d.sensordata[adr]
        else:
            np.testing.assert_array_equal(got, d.sensordata[adr:adr + dim])
    assert np.ndim(d.get_sensor("fp")) == 1 and np.ndim(d.get_sensor("jp")) == 0
    assert d.get_sensor("jp") == d.get_joint_qpos("hinge")


def test_mocap_get_and_set():
    m = M.from_xml_string('<mujoco><worldbody><body name="target" mocap="true" pos="1 2 3">'
                          '<geom size=".1" contype="0" conaffinity="0"/></body>'
                          '<body name="ball"><freejoint/><geom size=".1"/></body>'
                          '</worldbody></mujoco>')
    d = D(m)
    mjcffi.mj_forward(m, d)
    np.testing.assert_array_equal(d.get_mocap_pos("target"), [1, 2, 3])
    np.testing.assert_array_equal(d.get_mocap_quat("target"), [1, 0, 0, 0])
    d.set_mocap_pos("target", [4, 5, 6])
    d.set_mocap_quat("target", [0, 1, 0, 0])
    mjcffi.mj_forward(m, d)
    np.testing.assert_array_equal(d.get_body_xpos("target"), [4, 5, 6])
    np.testing.assert_array_equal(d.get_body_xquat("target"), [0, 1, 0, 0])
    with pytest.raises(ValueError):
        d.set_mocap_pos("target", [1, 2])
    with pytest.raises(ValueError, match="not a mocap body"):
        d.set_mocap_quat("ball", [1, 0, 0, 0])
