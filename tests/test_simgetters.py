"""mujoco-py's named getters (mjcffi/sim/generated/getters.py), checked against independent computations."""

import numpy as np
import pytest

import mjcffi
from mjcffi.sim.generated.getters import SimDataGetters, SimModelGetters, UnknownIdError, UnknownNameError
from mjcffi.sim._model import SimData, load_model_from_mjb, load_model_from_path, \
    load_model_from_xml

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
    """The names of the named elements in id order (mujoco-py leaves the others out)."""
    names = [mjcffi.mj_id2name(m, getattr(mjcffi.mjtObj, "mjOBJ_" + category), i)
             for i in range(count)]
    return [name for name in names if name]


def _named(m, obj, size):
    """(id, name) of the named elements of `obj`."""
    ids = ((i, getattr(m, obj + "_id2name")(i)) for i in range(size))
    return [(i, name) for i, name in ids if name is not None]


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
        for i in range(count):
            name = getattr(m, public + "_id2name")(i)
            assert name == (mjcffi.mj_id2name(m, getattr(mjcffi.mjtObj, "mjOBJ_" + obj), i)
                            or None)
            if name is not None:
                assert getattr(m, public + "_name2id")(name) == i


def test_unnamed_elements_and_bad_names_and_ids():
    m = M.from_xml_string('<mujoco><worldbody><body><geom size="1"/></body>'
                          '<body name="b"><geom size="1"/></body></worldbody></mujoco>')
    assert m.body_names == ("world", "b")          # unnamed bodies left out, as mujoco-py
    assert m.body_id2name(1) is None and m.body_id2name(2) == "b"
    assert m.geom_id2name(0) is None
    with pytest.raises(ValueError, match="'bb'.*'b'") as info:
        m.body_name2id("bb")
    assert isinstance(info.value, KeyError) and isinstance(info.value, UnknownNameError)
    with pytest.raises(KeyError):
        m.geom_name2id("nothing")
    for bad in (3, -1):
        with pytest.raises(IndexError):
            m.body_id2name(bad)
        with pytest.raises(ValueError):           # as mujoco-py
            m.body_id2name(bad)
    assert issubclass(UnknownIdError, ValueError)
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
        for i, name in _named(m, obj, size):
            for quantity, array in fields.items():
                got = getattr(d, f"get_{obj}_{quantity}")(name)
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
        for i, name in _named(m, obj, size):
            velp, velr = getattr(d, f"get_{obj}_xvelp")(name), getattr(d, f"get_{obj}_xvelr")(name)
            jacp, jacr = getattr(d, f"get_{obj}_jacp")(name), getattr(d, f"get_{obj}_jacr")(name)
            assert jacp.shape == jacr.shape == (3 * m.nv,)      # flat, as mujoco-py
            np.testing.assert_allclose(jacp.reshape(3, m.nv) @ d.qvel, velp, atol=1e-9, rtol=1e-9)
            np.testing.assert_allclose(jacr.reshape(3, m.nv) @ d.qvel, velr, atol=1e-9, rtol=1e-9)
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


def _quat_mul(a, b):
    w1, v1, w2, v2 = a[0], a[1:], b[0], b[1:]
    return np.concatenate([[w1 * w2 - v1 @ v2], w1 * v2 + w2 * v1 + np.cross(v1, v2)])


def test_whole_array_attributes(moving):
    m, d = moving
    nv = m.nv
    for obj, size, pos in [("body", m.nbody, "xpos"), ("geom", m.ngeom, "geom_xpos"),
                           ("site", m.nsite, "site_xpos")]:
        jacp, jacr = getattr(d, obj + "_jacp"), getattr(d, obj + "_jacr")
        velp, velr = getattr(d, obj + "_xvelp"), getattr(d, obj + "_xvelr")
        assert jacp.shape == jacr.shape == (size, 3 * nv)
        assert velp.shape == velr.shape == (size, 3)
        for i in range(size):
            jp, jr = np.zeros((3, nv)), np.zeros((3, nv))
            getattr(mjcffi, {"body": "mj_jacBody", "geom": "mj_jacGeom",
                             "site": "mj_jacSite"}[obj])(m, d, jp, jr, i)
            np.testing.assert_array_equal(jacp[i], jp.ravel())
            np.testing.assert_array_equal(jacr[i], jr.ravel())
            np.testing.assert_allclose(velp[i], jp @ d.qvel, atol=1e-12)
            np.testing.assert_allclose(velr[i], jr @ d.qvel, atol=1e-12)
        for i, name in _named(m, obj, size):
            np.testing.assert_array_equal(jacp[i], getattr(d, f"get_{obj}_jacp")(name))
            np.testing.assert_array_equal(velr[i], getattr(d, f"get_{obj}_xvelr")(name))
    # body velocities against finite differences: xpos, and xquat's rotation
    dt = 1e-7
    e = _shifted(m, d, dt)
    for i in range(m.nbody):
        fd_p = (e.xpos[i] - d.xpos[i]) / dt
        np.testing.assert_allclose(d.body_xvelp[i], fd_p, atol=1e-4 * (1 + np.abs(fd_p).max()))
        q0, q1 = d.xquat[i], e.xquat[i]
        dq = _quat_mul(q1, q0 * [1, -1, -1, -1])          # world-frame rotation q1 q0^-1
        fd_r = 2 * np.sign(dq[0]) * dq[1:] / dt
        np.testing.assert_allclose(d.body_xvelr[i], fd_r, atol=1e-4 * (1 + np.abs(fd_r).max()))


def test_body_poses_are_views_of_mjdata(moving):
    m, d = moving
    for attr, field, width in (("body_xpos", "xpos", 3), ("body_xquat", "xquat", 4),
                               ("body_xmat", "xmat", 9)):
        view = getattr(d, attr)
        assert view.shape == (m.nbody, width)
        assert np.shares_memory(view, getattr(d, field))
        getattr(d, field)[1] = 0.125                        # a write through d.<field> ...
        assert np.all(getattr(d, attr)[1] == 0.125)        # ... shows in the attribute
        view[1, 0] = 2.5                                    # and the other way round
        assert getattr(d, field)[1, 0] == 2.5


def test_velocities_follow_qvel_before_the_next_forward():
    """As in mujoco-py: Jacobian (of the last positions) @ the current qvel."""
    m, d = _moving(_humanoid())
    d.qvel[:] = np.random.default_rng(3).normal(size=m.nv)    # no mj_forward since
    torso = m.body_name2id("torso")
    jac = d.get_body_jacp("torso").reshape(3, m.nv)
    np.testing.assert_allclose(d.get_body_xvelp("torso"), jac @ d.qvel, atol=1e-12)
    np.testing.assert_allclose(d.body_xvelp[torso], jac @ d.qvel, atol=1e-12)
    mjcffi.mj_forward(m, d)                 # now mj_objectVelocity (cvel) agrees too
    res = np.zeros(6)
    mjcffi.mj_objectVelocity(m, d, mjcffi.mjtObj.mjOBJ_XBODY, torso, res, 0)
    np.testing.assert_allclose(d.get_body_xvelp("torso"), res[3:], atol=1e-9)
    np.testing.assert_allclose(d.get_body_xvelr("torso"), res[:3], atol=1e-9)


def test_jacobian_into_an_array():
    m, d = _moving(SCENE)
    name = m.site_names[0]
    for which in ("p", "r"):
        getter = getattr(d, f"get_site_jac{which}")
        out = np.full(3 * m.nv, 7.0)
        assert getter(name, **{f"jac{which}": out}) is out
        np.testing.assert_array_equal(out, getter(name))     # every entry written
        bad = [np.zeros(3 * m.nv, dtype=np.int64), np.zeros(3 * m.nv, dtype=np.float32),
               np.zeros(3 * m.nv + 1), np.zeros(3 * m.nv - 1), np.zeros((3, m.nv)),
               np.zeros(6 * m.nv)[::2]]
        readonly = np.zeros(3 * m.nv)
        readonly.flags.writeable = False
        for array in bad + [readonly]:
            before = array.copy()
            with pytest.raises(ValueError, match=f"jac{which}.*{3 * m.nv}"):
                getter(name, **{f"jac{which}": array})
            np.testing.assert_array_equal(array, before)
        with pytest.raises(TypeError):
            getter(name, **{f"jac{which}": [0.0] * (3 * m.nv)})
    for obj in ("body", "geom"):
        out = np.zeros(3 * m.nv)
        last = _named(m, obj, getattr(m, "n" + obj))[-1][1]
        assert getattr(d, f"get_{obj}_jacr")(last, jacr=out) is out
        assert np.any(out != 0)
        np.testing.assert_array_equal(out, getattr(d, f"get_{obj}_jacr")(last))


@pytest.mark.parametrize("name, instead", [("get_xpos", "get_body_xpos"),
                                           ("get_xquat", "get_body_xquat"),
                                           ("get_xmat", "get_body_xmat"),
                                           ("get_xipos", "get_body_xipos"),
                                           ("get_ximat", "get_body_ximat"),
                                           ("get_xanchor", "get_joint_xanchor"),
                                           ("get_xaxis", "get_joint_xaxis"),
                                           ("get_sensordata", "get_sensor")])
def test_getters_mujoco_py_refused(name, instead):
    m, d = _moving(SCENE)
    with pytest.raises(RuntimeError, match=instead):
        getattr(d, name)("anything")


def test_userdata_names():
    xml = '<mujoco><size nuserdata="{}"/><worldbody/></mujoco>'
    m = load_model_from_xml(xml.format(2))
    assert m.userdata_names == []
    with pytest.raises(AssertionError, match="nuserdata=2"):
        m.set_userdata_names(["a", "b", "c"])
    with pytest.raises(AssertionError):
        m.set_userdata_names("ab")                   # a str is no list of names
    with pytest.raises(AssertionError):
        m.set_userdata_names(["a", 1])
    assert m.userdata_names == []
    m.set_userdata_names(("gain", "bias"))
    assert m.userdata_names == ["gain", "bias"]
    assert m.userdata_name2id("bias") == 1 and m.userdata_id2name(0) == "gain"
    d = SimData(m)
    d.userdata[:] = [3.0, 4.0]
    assert d.get_userdata("bias") == 4.0
    with pytest.raises(ValueError, match="'nope'.*gain"):
        d.get_userdata("nope")
    with pytest.raises(ValueError):
        m.userdata_id2name(2)
    with pytest.raises(AssertionError):
        load_model_from_xml(xml.format(0)).set_userdata_names(["foo"])


def test_active_contacts_efc_pos():
    m = load_model_from_xml('<mujoco><worldbody><geom type="plane" size="1 1 1"/>'
                            '<body pos="0 0 .09"><freejoint/><geom size=".1"/></body>'
                            '<body><joint name="j" limited="true" range="0 1"/><geom size=".1" '
                            'pos="2 0 1"/></body></worldbody>'
                            '<equality><joint joint1="j"/></equality></mujoco>')
    d = SimData(m)
    mjcffi.mj_forward(m, d)
    assert d.ne >= 1 and d.nefc > d.ne
    got = d.active_contacts_efc_pos
    np.testing.assert_array_equal(got, d.efc_pos[d.ne:d.nefc])
    assert np.shares_memory(got, d.efc_pos)


@pytest.mark.parametrize("path", gymnasium_assets(), ids=lambda p: p.name)
def test_get_xml_and_get_mjb_round_trip(path):
    m = load_model_from_path(path)
    xml = m.get_xml()
    assert "<mujoco" in xml
    again = load_model_from_xml(xml)
    for size in ("nq", "nv", "nbody", "njnt", "ngeom", "nsite", "nu", "nsensor"):
        assert getattr(again, size) == getattr(m, size), size
    for field in ("body_pos", "body_quat", "body_mass", "geom_rbound", "geom_pos", "jnt_range",
                  "actuator_gear"):
        np.testing.assert_allclose(getattr(again, field), getattr(m, field), rtol=1e-5,
                                   atol=1e-5)   # 6 significant digits
    # MuJoCo writes 6 significant digits: from the second save on the text is a fixed point
    xml2 = again.get_xml()
    assert load_model_from_xml(xml2).get_xml() == xml2
    mjb = m.get_mjb()
    assert isinstance(mjb, bytes) and mjb == m.to_bytes()
    assert load_model_from_mjb(mjb).get_mjb() == mjb


def test_get_xml_expands_includes_and_writes_back_changes(tmp_path):
    (tmp_path / "part.xml").write_text('<mujoco><body name="expanded" pos="0 0 1">'
                                       '<geom size=".1"/></body></mujoco>')
    (tmp_path / "main.xml").write_text('<mujoco><worldbody><include file="part.xml"/>'
                                       '</worldbody></mujoco>')
    m = load_model_from_path(tmp_path / "main.xml")
    xml = m.get_xml()
    assert 'name="expanded"' in xml and "<include" not in xml
    assert load_model_from_xml(xml).get_xml() == xml
    m.body_pos[1] = [0.25, 0.5, 0.75]                 # a change since loading is saved
    np.testing.assert_array_equal(load_model_from_xml(m.get_xml()).body_pos[1],
                                  [0.25, 0.5, 0.75])


def test_get_xml_of_a_model_without_xml():
    m = load_model_from_xml('<mujoco><worldbody><geom size="1"/></worldbody></mujoco>')
    from_mjb = load_model_from_mjb(m.get_mjb())
    with pytest.raises(ValueError, match="MJB"):
        from_mjb.get_xml()
    assert from_mjb.get_mjb() == m.get_mjb()


def test_copies_and_pickles_keep_the_xml_and_userdata_names():
    import copy
    import pickle
    m = load_model_from_xml('<mujoco><size nuserdata="1"/><worldbody><geom size="1"/>'
                            '</worldbody></mujoco>')
    m.set_userdata_names(["k"])
    for other in (copy.copy(m), copy.deepcopy(m), pickle.loads(pickle.dumps(m))):
        assert type(other) is type(m) and other is not m
        assert other.get_xml() == m.get_xml()
        assert other.userdata_names == ["k"]
        assert other.get_mjb() == m.get_mjb()
