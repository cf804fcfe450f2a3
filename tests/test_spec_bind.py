"""MjModel.bind / MjData.bind (mjcffi/_support/bind.py): a spec element's compiled
counterpart, against the official bindings and against named access."""

import os

import numpy as np
import pytest

import mjcffi
from mjcffi import MjSpec

gymnasium = pytest.importorskip("gymnasium")
HUMANOID = os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets",
                        "humanoid.xml")

# list name -> does the official MjData bind it (else only MjModel does)
KINDS = {"bodies": True, "joints": True, "geoms": True, "sites": True, "cameras": True,
         "lights": True, "actuators": True, "sensors": True, "tendons": True,
         "textures": False, "materials": False, "meshes": False, "hfields": False,
         "pairs": False, "excludes": False, "equalities": False, "numerics": False,
         "tuples": False, "keys": False}

SMALL = """
<mujoco>
  <asset>
    <texture name="t" type="2d" builtin="checker" width="8" height="8"/>
    <material name="mat" texture="t"/>
    <mesh name="tet" vertex="0 0 0  1 0 0  0 1 0  0 0 1"/>
    <hfield name="hf" nrow="2" ncol="3" size="1 1 1 1"/>
  </asset>
  <custom>
    <numeric name="n" data="1 2"/>
    <tuple name="tu"><element objtype="body" objname="b"/></tuple>
  </custom>
  <worldbody>
    <light name="l"/>
    <camera name="c" pos="0 0 1"/>
    <body name="b" pos="0 0 1">
      <freejoint/>
      <geom name="g" size=".1" material="mat"/>
      <site name="s"/>
      <geom type="mesh" mesh="tet"/>
    </body>
    <body name="b2" pos="1 0 1">
      <joint name="h" axis="0 1 0"/>
      <geom type="capsule" size=".1" fromto="0 0 0 .3 0 0"/>
      <body name="b3" pos=".3 0 0">
        <joint name="ball" type="ball"/>
        <geom size=".1"/>
      </body>
    </body>
  </worldbody>
  <contact><pair geom1="g" geom2="g"/><exclude body1="b" body2="b2"/></contact>
  <equality><weld body1="b" body2="b2" active="false"/></equality>
  <tendon><fixed name="ten"><joint joint="h" coef="1"/></fixed></tendon>
  <actuator><motor joint="h" gear="2"/><position joint="h" kp="3"/></actuator>
  <sensor><jointpos joint="h"/><framepos objtype="body" objname="b"/></sensor>
  <keyframe><key name="k"/></keyframe>
</mujoco>
"""


def compiled(make_spec, mujoco_module, source, forward=True):
    """(spec, model, data) from `source` (an XML path or text), stepped to a
    posture that moves every joint."""
    load = make_spec.from_file if source.endswith(".xml") else make_spec.from_string
    spec = load(source)
    model = spec.compile()
    data = mujoco_module.MjData(model)
    data.qpos[:] = np.linspace(0.1, 0.9, model.nq)
    data.ctrl[:] = np.linspace(-0.5, 0.5, model.nu)
    if forward:
        mujoco_module.mj_forward(model, data)
    return spec, model, data


@pytest.fixture(params=["humanoid", "small"])
def pair(request, mujoco):
    """The same scene in mjcffi and in the official bindings."""
    source = HUMANOID if request.param == "humanoid" else SMALL
    return (compiled(MjSpec, mjcffi, source), compiled(mujoco.MjSpec, mujoco, source))


def fields_of(accessor):
    return [a for a in dir(accessor) if not a.startswith("_") and a not in ("id", "name")]


def flat(official_list):
    """The official list binding's value (a flat list of numbers and rows), flat."""
    return np.concatenate([np.ravel(x) for x in official_list]) if official_list \
        else np.zeros(0)


# ------------------------------------------------------------ single elements

def test_single_element_matches_official(pair):
    (spec, m, d), (spec0, m0, d0) = pair
    checked = 0
    for kind, data_side in KINDS.items():
        elements, elements0 = getattr(spec, kind), getattr(spec0, kind)
        assert len(elements) == len(elements0), kind
        assert elements or m.nmesh == 0, f"the small scene has every kind, {kind} too"
        sides = [(m, m0)] + ([(d, d0)] if data_side else [])
        for element, element0 in zip(elements, elements0):
            for owner, owner0 in sides:
                ours, theirs = owner.bind(element), owner0.bind(element0)
                assert type(ours).__name__ == type(theirs).__name__
                assert (ours.id, ours.name) == (theirs.id, theirs.name)
                assert set(fields_of(theirs)) <= set(fields_of(ours))
                for attr in fields_of(theirs):
                    np.testing.assert_array_equal(getattr(ours, attr), getattr(theirs, attr),
                                                  err_msg=f"{kind} {attr}")
                    checked += 1
    assert checked > 100


def test_single_element_is_the_named_accessor(pair):
    (spec, m, d), _ = pair
    for geom in spec.geoms:
        bound = d.bind(geom)
        assert bound is d.geom(bound.id)
        if geom.name:
            assert bound is d.geom(geom.name)
        assert m.bind(geom) is m.geom(bound.id)
    joint = spec.joints[-1]
    assert np.shares_memory(d.bind(joint).qpos, d.qpos)
    d.bind(joint).qpos[...] = 0.25
    np.testing.assert_array_equal(d.joint(joint.name).qpos, 0.25)


def test_single_element_writes_through():
    spec, m, d = compiled(MjSpec, mjcffi, SMALL)
    geom = spec.geom("g")
    m.bind(geom).rgba = [1, 0, 0, 1]
    np.testing.assert_array_equal(m.geom_rgba[m.bind(geom).id], [1, 0, 0, 1])
    free = spec.joints[0]
    d.bind(free).qpos = [1, 2, 3, 1, 0, 0, 0]
    np.testing.assert_array_equal(d.qpos[:7], [1, 2, 3, 1, 0, 0, 0])


def test_unnamed_elements_bind_by_their_compiled_id(mujoco):
    def build(module):
        spec = module.MjSpec()
        for x in range(3):
            body = spec.worldbody.add_body(pos=[x, 0, 0])
            body.add_geom(size=[0.1, 0, 0])
            body.add_joint(type=module.mjtJoint.mjJNT_SLIDE)
        return spec, spec.compile()
    spec, m = build(mjcffi)
    spec0, m0 = build(mujoco)
    assert [m.bind(g).id for g in spec.geoms] == [m0.bind(g).id for g in spec0.geoms] == [0, 1, 2]
    assert [m.bind(j).name for j in spec.joints] == ["", "", ""]
    np.testing.assert_array_equal(m.bind(spec.bodies[2]).pos, [1, 0, 0])


# --------------------------------------------------------------------- lists

def test_list_values_match_official(pair):
    (spec, m, d), (spec0, m0, d0) = pair
    for kind, data_side in KINDS.items():
        elements, elements0 = getattr(spec, kind), getattr(spec0, kind)
        if not elements:
            continue
        sides = [(m, m0)] + ([(d, d0)] if data_side else [])
        for owner, owner0 in sides:
            ours, theirs = owner.bind(elements), owner0.bind(elements0)
            assert ours.id == theirs.id and ours.name == theirs.name
            for attr in fields_of(owner0.bind(elements0[0])):
                np.testing.assert_array_equal(np.ravel(getattr(ours, attr)),
                                              flat(getattr(theirs, attr)),
                                              err_msg=f"{kind} {attr}")


def test_list_shapes_and_zero_copy(pair):
    (spec, m, d), _ = pair
    xpos = d.bind(spec.geoms).xpos
    assert xpos.shape == (m.ngeom, 3)
    assert np.shares_memory(xpos, d.geom_xpos)
    np.testing.assert_array_equal(xpos, d.geom_xpos)
    size = m.bind(spec.geoms).size
    np.testing.assert_array_equal(size, m.geom_size)
    assert m.bind(spec.bodies).mass.shape == (m.nbody,)       # one number each: (n,)
    qpos = d.bind(spec.joints).qpos                       # ragged: the whole qpos
    assert qpos.shape == (m.nq,) and np.shares_memory(qpos, d.qpos)
    cdof = d.bind(spec.joints).cdof                       # ragged rows: (nv, 6)
    assert cdof.shape == (m.nv, 6) and np.shares_memory(cdof, d.cdof)
    xpos[0, 2] = 7.0                                      # a view writes through
    assert d.geom_xpos[0, 2] == 7.0


def test_list_not_in_id_order_is_a_copy_and_setattr_writes_back():
    spec, m, d = compiled(MjSpec, mjcffi, HUMANOID)
    geoms = spec.geoms[::-1]
    bound = d.bind(geoms)
    xpos = bound.xpos
    np.testing.assert_array_equal(xpos, d.geom_xpos[::-1])
    assert not np.shares_memory(xpos, d.geom_xpos)
    new = np.arange(3 * m.ngeom, dtype=float).reshape(-1, 3)
    bound.xpos = new
    np.testing.assert_array_equal(d.geom_xpos, new[::-1])
    bound.xpos += 1                          # read a copy, add, write it back
    np.testing.assert_array_equal(d.geom_xpos, new[::-1] + 1)
    xpos = bound.xpos
    xpos[0] = -1                             # a copy's entries are not the model's
    assert not np.any(d.geom_xpos == -1)
    d.geom_xpos[-1] = 5.0                    # a copy is read anew each time
    np.testing.assert_array_equal(bound.xpos[0], [5, 5, 5])


def test_list_setattr_writes_through_a_view():
    spec, m, d = compiled(MjSpec, mjcffi, HUMANOID)
    hinges = spec.joints[1:]
    bound = d.bind(hinges)
    bound.qpos = np.arange(len(hinges))
    np.testing.assert_array_equal(d.qpos[7:], np.arange(len(hinges)))
    bound.qpos += 0.5
    np.testing.assert_array_equal(d.qpos[7:], np.arange(len(hinges)) + 0.5)
    with pytest.raises(ValueError):          # no broadcasting of a scalar, as official
        bound.qpos = 0
    np.testing.assert_array_equal(d.qpos[7:], np.arange(len(hinges)) + 0.5)
    bound.qpos = np.zeros(len(hinges))
    assert not d.qpos[7:].any()
    np.testing.assert_array_equal(d.qpos[:7], np.linspace(0.1, 0.9, m.nq)[:7])


def test_list_setattr_takes_one_value_per_element_as_the_official(mujoco):
    def scene(module):
        spec, m, d = compiled(module.MjSpec, module, SMALL, forward=False)
        joints = [spec.joints[0], spec.joint("h")]             # free (7) and hinge (1)
        d.bind(joints).qpos = [np.arange(7), 9]
        return d.qpos.copy()
    np.testing.assert_array_equal(scene(mjcffi), scene(mujoco))
    spec, m, d = compiled(MjSpec, mjcffi, SMALL)
    with pytest.raises(ValueError):
        d.bind([spec.joints[0], spec.joint("h")]).qpos = [np.arange(6), 9]


def test_sequence_setattr_and_str_fields_as_the_official(mujoco):
    xml = """<mujoco><worldbody>
      <body><joint name="box" damping=".1"/><geom size=".1"/></body>
      <body><joint name="sphere" damping=".2"/><geom size=".1"/></body>
    </worldbody></mujoco>"""
    for module in (mjcffi, mujoco):
        spec = module.MjSpec.from_string(xml)
        joints = [spec.joint("box"), spec.joint("sphere")]
        m = spec.compile()
        d = module.MjData(m)
        assert m.bind(joints).id == d.bind(joints).id == [0, 1]
        assert m.bind(joints).name == d.bind(joints).name == ["box", "sphere"]
        m.bind(joints).damping = [0.5, 1.5]
        np.testing.assert_allclose(m.dof_damping, [0.5, 1.5])
        np.testing.assert_array_equal(m.bind(tuple(joints)).qposadr, [0, 1])


def test_empty_list():
    spec, m, d = compiled(MjSpec, mjcffi, SMALL)
    for owner in (m, d):
        bound = owner.bind([])
        assert bound.id == [] and bound.name == []
        assert np.size(bound.qpos) == 0
    with pytest.raises(ValueError, match="Expected 0 values"):
        d.bind([]).qpos = [1]


def test_list_of_mixed_kinds_reads_copies():
    spec, m, d = compiled(MjSpec, mjcffi, SMALL)
    bound = d.bind([spec.geom("g"), spec.site("s")])
    np.testing.assert_array_equal(bound.xpos, [d.geom("g").xpos, d.site("s").xpos])
    with pytest.raises(AttributeError, match="no attribute 'size'"):
        d.bind([spec.geom("g"), spec.joint("h")]).size


def test_sparse_rows_are_read_only_copies():
    spec, m, d = compiled(MjSpec, mjcffi, SMALL)
    moment = d.bind(spec.actuators).moment
    assert moment.shape == (2, m.nv) and not moment.flags.writeable
    np.testing.assert_array_equal(moment[0], d.actuator(0).moment)
    with pytest.raises(AttributeError, match="read-only"):
        d.bind(spec.actuators).moment = 0


def test_joined_shapes():
    from mjcffi._support.bind import _joined_shape
    assert _joined_shape([(3,), (3,)]) == (2, 3)
    assert _joined_shape([(1,), (1,), (1,)]) == (3,)
    assert _joined_shape([(7,), (1,)]) == (8,)               # qpos: free and hinge
    assert _joined_shape([(6, 6), (1, 6)]) == (7, 6)         # cdof: free and hinge
    assert _joined_shape([(6,), (2, 6)]) == (3, 6)           # gear: one row and two
    assert _joined_shape([(2, 3), (3, 4)]) == (18,)          # images of two sizes


def test_repr_and_dir():
    spec, m, d = compiled(MjSpec, mjcffi, SMALL)
    text = repr(d.bind(spec.joints))
    assert text.startswith("<_MjBindData of 3 joint(s)") and "'h'" in text
    assert repr(m.bind(spec.geoms)).startswith("<_MjBindModel of 4 geom(s)")
    assert {"qpos", "qvel", "id", "name", "elements"} <= set(dir(d.bind(spec.joints)))
    assert "xpos" in repr(d.bind(spec.geom("g")))


# -------------------------------------------------------------------- errors

def test_unknown_field():
    spec, m, d = compiled(MjSpec, mjcffi, SMALL)
    with pytest.raises(AttributeError, match="object has no attribute 'invalid'") as info:
        m.bind(spec.joints).invalid
    assert "qposadr" in "".join(info.value.__notes__)
    with pytest.raises(AttributeError, match="object has no attribute 'invalid'"):
        m.bind(spec.joint("h")).invalid
    with pytest.raises(AttributeError):
        m.bind(spec.joints).id = [1, 2, 3]


def test_not_an_element_is_a_type_error():
    spec, m, d = compiled(MjSpec, mjcffi, SMALL)
    for bad in (1, None, "g", b"g", spec, m, 2.5):
        with pytest.raises(TypeError):
            m.bind(bad)
        with pytest.raises(TypeError):
            d.bind([bad])
    spec, m, d = compiled(MjSpec, mjcffi, SMALL)
    frame = spec.worldbody.add_frame()
    spec.worldbody.add_geom(size=[0.1, 0, 0])
    m = spec.compile()
    with pytest.raises(TypeError, match="frame"):
        m.bind(frame)


def test_data_bind_of_a_model_only_kind(mujoco):
    spec, m, d = compiled(MjSpec, mjcffi, SMALL)
    spec0, m0, d0 = compiled(mujoco.MjSpec, mujoco, SMALL)
    with pytest.raises(TypeError):
        d0.bind(spec0.meshes[0])
    with pytest.raises(TypeError, match="MjData has no fields of a mesh") as info:
        d.bind(spec.meshes[0])
    assert "'tet'" in str(info.value)
    assert m.bind(spec.meshes[0]).vertnum[0] == 4


def test_changed_spec_is_refused_until_recompiled():
    spec, m, d = compiled(MjSpec, mjcffi, SMALL)
    geom = spec.body("b2").add_geom(name="late", size=[0.1, 0, 0])
    for owner in (m, d):
        with pytest.raises(ValueError, match="The mjSpec does not match mjModel. "
                                             "Please recompile the mjSpec.") as info:
            owner.bind(geom)
        assert "'late'" in "".join(info.value.__notes__)
        with pytest.raises(ValueError, match="does not match"):
            owner.bind(spec.geom("g"))          # the spec changed: every element is refused
    m = spec.compile()
    assert m.bind(geom).name == "late"
    assert m.bind(geom).id == m.geom("late").id


def test_first_equality_invalidates_as_the_official(mujoco):
    for module in (mjcffi, mujoco):
        spec = module.MjSpec()
        for name in ("a", "b"):
            body = spec.worldbody.add_body(name=name)
            body.add_geom(size=[1, 0, 0])
            body.add_freejoint()
        model = spec.compile()
        equality = spec.add_equality(type=module.mjtEq.mjEQ_WELD,
                                     objtype=module.mjtObj.mjOBJ_BODY, name1="a", name2="b")
        with pytest.raises(ValueError, match="does not match"):
            model.bind(equality)
        assert spec.compile().bind(equality).id == 0


def test_element_of_another_spec_is_refused():
    spec, m, d = compiled(MjSpec, mjcffi, SMALL)
    other = MjSpec()
    body = other.worldbody.add_body(name="main")
    with pytest.raises(ValueError, match="does not match"):
        m.bind(body)
    with pytest.raises(ValueError, match="does not match"):
        d.bind([spec.geom("g"), body])


def test_deleted_element_is_an_index_error():
    spec = MjSpec()
    body = spec.worldbody.add_body(name="gone")
    joint = body.add_joint(name="j")
    body.add_geom(size=[0.1, 0, 0])
    spec.worldbody.add_body(name="kept").add_geom(size=[0.1, 0, 0])
    spec.delete(body)
    m = spec.compile()
    d = mjcffi.MjData(m)
    for owner in (m, d):
        for element in (body, joint):
            with pytest.raises(IndexError, match="Invalid index -1"):
                owner.bind(element)
            with pytest.raises(IndexError, match="Invalid index -1"):
                owner.bind([element])
    assert m.bind(spec.body("kept")).id == 1


def test_elements_of_an_attached_spec(mujoco):
    def scene(module):
        parent, child = module.MjSpec(), module.MjSpec()
        geom = child.worldbody.add_body(name="arm").add_geom(name="g", size=[0.1, 0, 0])
        parent.attach(child, frame=parent.worldbody.add_frame(pos=[0, 0, 1]), prefix="l_")
        m = parent.compile()
        d = module.MjData(m)
        module.mj_forward(m, d)
        return m.bind(geom).name, d.bind(geom).xpos.copy()
    ours, theirs = scene(mjcffi), scene(mujoco)
    assert ours[0] == theirs[0] == "l_g"
    np.testing.assert_array_equal(ours[1], theirs[1])
