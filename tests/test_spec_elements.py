"""The generated spec element layer (issue 13, items 2 and 3): str, vector and enum
attributes, the one wrapper of each element, add_* with keywords, use after
invalidate; checked against the official bindings (mujoco.MjSpec)."""

import mujoco
import numpy as np
import pytest

import mjcffi
from mjcffi.structs import _elements
from mjcffi.structs.mjspec import MjsBody, MjsGeom


def _world(spec):
    return _elements.wrap(mjcffi.mjs_findBody(spec, "world")._ptr, spec)


def _build(world, spec):
    """The same model through either binding's add_* methods and keywords."""
    body = world.add_body(name="torso", pos=[0, 0, 1.5], userdata=[1.0, 2.0])
    body.add_freejoint(name="root")
    body.add_geom(name="box", type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.2, 0.1, 0.05],
                  rgba=[1, 0, 0, 1])
    arm = body.add_body(name="arm", pos=[0.3, 0, 0])
    arm.add_joint(name="elbow", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0],
                  range=[-1, 1])
    arm.add_geom(name="cap", type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.05, 0.2, 0],
                 material="red")
    arm.add_site(name="tip", pos=[0.2, 0, 0])
    spec.add_material(name="red", rgba=[1, 0, 0, 1])
    spec.add_actuator(name="motor", target="elbow", trntype=mujoco.mjtTrn.mjTRN_JOINT,
                      gear=[2, 0, 0, 0, 0, 0])
    spec.add_sensor(name="pos", type=mujoco.mjtSensor.mjSENS_JOINTPOS, objname="elbow",
                    objtype=mujoco.mjtObj.mjOBJ_JOINT)
    spec.add_numeric(name="n", data=[1, 2, 3])
    spec.add_text(name="t", data="hello")
    spec.add_key(name="k", time=1.0)
    return body


def _official_bytes(model):
    buffer = np.zeros(mujoco.mj_sizeModel(model), np.uint8)
    mujoco.mj_saveModel(model, None, buffer)
    return buffer.tobytes()


def test_add_methods_compile_to_the_official_model_byte_for_byte():
    ours = mjcffi.mj_makeSpec()
    _build(_world(ours), ours)
    theirs = mujoco.MjSpec()
    _build(theirs.worldbody, theirs)
    model = mjcffi.mj_compile(ours, None)
    official = theirs.compile()
    assert model.nbody == official.nbody == 3 and model.nu == official.nu == 1
    assert model.to_bytes() == _official_bytes(official)


def test_attribute_reads_have_the_official_types_and_values():
    ours = mjcffi.mj_makeSpec()
    mine = _build(_world(ours), ours)
    theirs = mujoco.MjSpec()
    official = _build(theirs.worldbody, theirs)
    geom, official_geom = mine.add_geom(), official.add_geom()
    assert type(geom.type) is mjcffi.mjtGeom and geom.type == official_geom.type
    assert geom.type is mjcffi.mjtGeom.mjGEOM_SPHERE
    assert type(geom.name) is str and geom.name == official_geom.name == ""
    assert geom.size.dtype == official_geom.size.dtype and geom.size.shape == (3,)
    assert mine.name == official.name == "torso"
    assert mine.userdata.tolist() == list(official.userdata) == [1.0, 2.0]
    assert mine.alt.type == official.alt.type
    assert type(ours.compiler.inertiafromgeom).__name__ == "mjtInertiaFromGeom"
    text_ours = mjcffi.mjs_findElement(ours, mjcffi.mjtObj.mjOBJ_TEXT, "t")._ptr
    assert _elements.wrap(text_ours, ours).data == theirs.text("t").data == "hello"


def test_fixed_arrays_are_writable_views():
    spec = mjcffi.mj_makeSpec()
    geom = _world(spec).add_geom()
    geom.size[1] = 0.25
    assert geom.size[1] == 0.25
    geom.pos = (1, 2, 3)
    assert geom.pos.tolist() == [1, 2, 3]


def test_vectors_read_copies_and_take_any_sequence():
    spec = mjcffi.mj_makeSpec()
    body = _world(spec).add_body(userdata=(1, 2, 3))
    copy = body.userdata
    copy[0] = 9
    assert body.userdata.tolist() == [1, 2, 3]           # a copy: the spec is unchanged
    body.userdata = np.arange(4, dtype=np.int64)
    assert body.userdata.dtype == np.float64 and body.userdata.tolist() == [0, 1, 2, 3]
    mesh = spec.add_mesh(uservert=[0, 0, 0, 1, 0, 0, 0, 1, 0], userface=[0, 1, 2])
    assert mesh.uservert.dtype == np.float32 and mesh.uservert.tolist()[3] == 1
    assert mesh.userface.dtype == np.int32 and mesh.userface.tolist() == [0, 1, 2]
    texture = spec.add_texture()
    assert texture.cubefiles == [""] * 6
    texture.cubefiles = ["a", "b" * 40, ""]                # a short and a long std::string
    assert texture.cubefiles == ["a", "b" * 40, ""]
    texture.data = b"\x01\x02\xff"
    assert texture.data == b"\x01\x02\xff"
    with pytest.raises(TypeError, match="MjsBody.userdata"):
        body.userdata = "abc"
    with pytest.raises(TypeError, match="MjsMesh.userface"):
        mesh.userface = [0.5, 1]
    with pytest.raises(TypeError, match="MjsTexture.cubefiles"):
        texture.cubefiles = "abc"


def test_strings_and_enums_convert_and_refuse_wrong_types():
    spec = mjcffi.mj_makeSpec()
    geom = _world(spec).add_geom(name="g", material="steel")
    assert geom.material == "steel" and geom.name == "g"
    geom.type = 6                                          # an int is taken
    assert geom.type is mjcffi.mjtGeom.mjGEOM_BOX
    with pytest.raises(TypeError, match="MjsGeom.material"):
        geom.material = 3
    with pytest.raises(ValueError, match="NUL"):
        geom.material = "a\0b"
    with pytest.raises(TypeError, match="MjsGeom.type"):
        geom.type = "box"
    with pytest.raises(ValueError, match="MjsGeom.type"):
        geom.type = 2**40


def test_keywords_are_checked_and_a_refused_element_is_not_left_behind():
    spec = mjcffi.mj_makeSpec()
    world = _world(spec)
    with pytest.raises(TypeError, match=r"no attribute 'sise'.*valid keywords: .*size"):
        world.add_geom(sise=[1, 1, 1])
    with pytest.raises(ValueError, match="MjsGeom.size"):
        world.add_geom(size=[1, 2, 3, 4])
    with pytest.raises((TypeError, ValueError), match="MjsGeom.rgba"):
        world.add_geom(rgba="red")
    with pytest.raises(TypeError, match="no default class"):
        spec.add_sensor(default=object())
    assert mjcffi.mj_compile(spec, None).ngeom == 0      # none of the refused geoms stayed


def test_one_wrapper_per_element_of_its_class():
    spec = mjcffi.mj_makeSpec()
    body = _world(spec).add_body(name="b")
    assert type(body) is MjsBody
    assert _elements.wrap(body._ptr, spec) is body
    assert _elements.wrap(body._ptr.element, spec) is body
    geom = body.add_geom()
    assert type(_elements.wrap(geom._ptr.element, spec)) is MjsGeom
    assert body in _elements.registered(spec) and geom in _elements.registered(spec)


def test_default_frame_and_tendon_wraps():
    spec = mjcffi.mj_makeSpec()
    main = spec.add_default("big")
    main.geom.size = [1, 1, 1]
    body = _world(spec).add_body(name="b", pos=[0, 0, 1])
    geom = body.add_geom(default=main, name="g")
    assert geom.size.tolist() == [1, 1, 1]
    frame = body.add_frame(pos=[0, 0, 1])
    assert frame.pos.tolist() == [0, 0, 1]
    body.add_site(name="s1")
    body.add_site(name="s2", pos=[0, 0, 0.5])
    tendon = spec.add_tendon(name="t")
    tendon.wrap_site("s1")
    tendon.wrap_site("s2")
    model = mjcffi.mj_compile(spec, None)
    assert model.ntendon == 1 and model.tendon_num[0] == 2


def test_use_after_invalidate_raises_naming_the_element():
    spec = mjcffi.mj_makeSpec()
    geom = _world(spec).add_geom(name="doomed")
    _elements.invalidate([geom])
    with pytest.raises(RuntimeError, match="MjsGeom 'doomed' was deleted"):
        geom.size
    with pytest.raises(RuntimeError, match="deleted"):
        geom.rgba = [1, 1, 1, 1]
    assert "deleted" in repr(geom)
    body = _world(spec).add_body()
    _elements.invalidate_missing(spec, alive=set())
    with pytest.raises(RuntimeError, match="MjsBody"):
        body.add_geom()


def test_names_are_set_through_mujoco_which_refuses_a_repeated_one():
    spec = mjcffi.mj_makeSpec()
    world = _world(spec)
    body = world.add_body(name="b")
    body.name = "renamed"
    assert body.name == "renamed"
    assert mjcffi.mjs_findBody(spec, "renamed")._ptr == body._ptr
    with pytest.raises(ValueError, match="MjsBody.name"):
        world.add_body(name="renamed")
    assert mjcffi.mj_compile(spec, None).nbody == 2      # the refused body was removed


_BODY_ADDS = ("add_body", "add_geom", "add_site", "add_joint", "add_camera", "add_light",
              "add_frame")
_SPEC_ADDS = ("add_mesh", "add_material", "add_texture", "add_hfield", "add_skin",
              "add_actuator", "add_sensor", "add_tendon", "add_equality", "add_pair",
              "add_exclude", "add_key", "add_numeric", "add_text", "add_tuple", "add_plugin",
              "add_flex")


def _same_read(ours, official):
    """Whether an attribute read of ours matches the official one in type and value."""
    kind = type(official).__name__
    if type(official).__module__ == "mujoco._enums":
        return type(ours).__name__ == kind and int(ours) == int(official)
    if isinstance(official, np.ndarray):
        return (type(ours) is np.ndarray and ours.dtype == official.dtype
                and np.array_equal(ours, official, equal_nan=True))
    if isinstance(official, float):
        return type(ours) is float and (ours == official or np.isnan(ours) and np.isnan(official))
    if isinstance(official, (str, bytes, bool, int)):
        return type(ours) is type(official) and ours == official
    if kind in ("MjDoubleVec", "MjFloatVec", "MjIntVec"):
        return type(ours) is np.ndarray and ours.tolist() == list(official)
    if kind == "MjStringVec":
        return ours == list(official)
    if kind == "MjByteVec":
        return ours == bytes(official)
    if isinstance(official, list):
        return [row.tolist() for row in ours] == [list(row) for row in official]
    return type(ours).__name__ == kind        # nested structs (alt): their fields apart


def test_every_attribute_of_every_new_element_reads_as_the_official():
    ours = mjcffi.mj_makeSpec()
    world = _world(ours)
    theirs = mujoco.MjSpec()
    pairs = [(getattr(world, m)(), getattr(theirs.worldbody, m)()) for m in _BODY_ADDS]
    pairs += [(getattr(ours, m)(), getattr(theirs, m)()) for m in _SPEC_ADDS]
    # deliberate: a fixed char array (texture.gridlayout) is a str here
    differ = {("MjsTexture", "gridlayout")}
    compared = 0
    for mine, official in pairs:
        for field in type(mine)._fields + ("name",):
            if field == "element" or (type(mine).__name__, field) in differ:
                continue
            value = getattr(official, field)
            assert _same_read(getattr(mine, field), value), (type(mine).__name__, field)
            compared += 1
    assert compared > 350


def test_vectors_of_vectors_are_lists_of_arrays_written_once():
    spec = mjcffi.mj_makeSpec()
    skin = spec.add_skin(vertid=[[0, 1], [2]], vertweight=[[0.5, 0.5], [1]])
    assert [v.tolist() for v in skin.vertid] == [[0, 1], [2]]
    assert [v.dtype for v in skin.vertweight] == [np.float32, np.float32]
    with pytest.raises(ValueError, match="MjsSkin.vertid is set already"):
        skin.vertid = [[1]]
    assert [v.tolist() for v in skin.vertid] == [[0, 1], [2]]


def _frames(world):
    body = world.add_body(name="b", pos=[0, 0, 1])
    frame = body.add_frame(pos=[0, 0, 0.5], quat=[0, 1, 0, 0])
    frame.add_geom(name="g", size=[0.1, 0, 0], pos=[0.2, 0, 0])
    inner = frame.add_frame(pos=[1, 0, 0])
    inner.add_site(name="s")
    child = inner.add_body(name="c")
    child.add_joint(name="j")
    child.add_geom(size=[0.1, 0, 0])


def test_frames_place_their_elements_as_the_official():
    ours = mjcffi.mj_makeSpec()
    _frames(_world(ours))
    theirs = mujoco.MjSpec()
    _frames(theirs.worldbody)
    model = mjcffi.mj_compile(ours, None)
    assert model.site_pos.tolist() == [[1, 0, 0.5]]          # in the frame's frame
    assert model.to_bytes() == _official_bytes(theirs.compile())
