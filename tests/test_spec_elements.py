"""The generated spec element layer (issue 13, items 2 and 3): str, char, vector and
enum attributes, the one wrapper of each element, add_* with keywords (orientations,
padded sizes), name errors, deleted elements and the NumPy views of their memory;
checked against the official bindings (mujoco.MjSpec)."""

import typing

import mujoco
import numpy as np
import pytest

import mjcffi
from mjcffi._support import elements as _elements
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


def test_vectors_are_live_and_take_any_sequence():
    spec = mjcffi.mj_makeSpec()
    body = _world(spec).add_body(userdata=(1, 2, 3))
    live = body.userdata
    live[0] = 9                                            # writes the spec, as official
    assert body.userdata.tolist() == [9, 2, 3] and type(live).__name__ == "MjDoubleVec"
    copy = np.asarray(body.userdata)
    copy[1] = 7                                            # an array of it is a copy
    assert body.userdata.tolist() == [9, 2, 3]
    live += 1                                              # in place, as an array would
    live[1:] = [0, 0]
    assert body.userdata.tolist() == [10, 0, 0] and len(live) == 3
    assert (live + 1).tolist() == [11, 1, 1] and (live == [10, 0, 0]).all()
    body.userdata = np.arange(4, dtype=np.int64)
    assert body.userdata.dtype == np.float64 and body.userdata.tolist() == [0, 1, 2, 3]
    assert live.tolist() == [0, 1, 2, 3]                   # the same vector, resized
    mesh = spec.add_mesh(uservert=[0, 0, 0, 1, 0, 0, 0, 1, 0], userface=[0, 1, 2])
    assert mesh.uservert.dtype == np.float32 and mesh.uservert[3] == 1
    assert mesh.userface.dtype == np.int32 and mesh.userface.tolist() == [0, 1, 2]
    texture = spec.add_texture()
    assert texture.cubefiles == [""] * 6
    texture.cubefiles = ["a", "b" * 40, ""]                # a short and a long std::string
    assert texture.cubefiles == ["a", "b" * 40, ""]
    texture.cubefiles[2] = "c"
    assert list(texture.cubefiles) == ["a", "b" * 40, "c"]
    texture.data = b"\x01\x02\xff"
    assert texture.data == b"\x01\x02\xff"
    with pytest.raises(TypeError, match="MjsBody.userdata"):
        body.userdata = "abc"
    with pytest.raises(TypeError, match="MjsMesh.userface"):
        mesh.userface = [0.5, 1]
    with pytest.raises(TypeError, match="MjsMesh.userface"):
        mesh.userface[0] = 0.5
    with pytest.raises(IndexError):
        live[4] = 1
    with pytest.raises(TypeError, match="MjsTexture.cubefiles"):
        texture.cubefiles = 3


def test_vectors_are_written_in_place_as_the_official():
    ours = _world(mjcffi.mj_makeSpec()).add_site(userdata=[7, 2, 3])
    theirs = mujoco.MjSpec().worldbody.add_site(userdata=[7, 2, 3])
    for site in (ours, theirs):
        site.userdata[0] = 1
    assert list(ours.userdata) == list(theirs.userdata) == [1, 2, 3]
    assert ours.userdata[-1] == 3 and list(ours.userdata) == ours.userdata.tolist()


def test_string_vectors_take_a_str_and_keep_their_roles_as_the_official():
    ours, theirs = mjcffi.mj_makeSpec(), mujoco.MjSpec()
    pairs = [(ours.add_flex(), theirs.add_flex()),
             (ours.add_material(), theirs.add_material())]
    for flex in pairs[0]:
        flex.material = "mat1"                             # a str: a list of it
    assert list(pairs[0][0].material) == list(pairs[0][1].material) == ["mat1"]
    for flex in pairs[0]:
        flex.material = ""
    assert list(pairs[0][0].material) == list(pairs[0][1].material) == []
    for material in pairs[1]:
        material.textures[1] = "tex"
        with pytest.raises(ValueError, match="must have exactly 10 elements, got 1"):
            material.textures = ["tex"]
        with pytest.raises(IndexError):
            material.textures[-1] = "x"
        with pytest.raises(IndexError):
            material.textures[10] = "x"
    assert list(pairs[1][0].textures) == list(pairs[1][1].textures)


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
    with pytest.raises(TypeError, match=r"Invalid sise keyword argument\. Valid options are: "
                                        r".*euler.*size"):
        world.add_geom(sise=[1, 1, 1])
    with pytest.raises(ValueError, match="size should be a list/array of size 1 to 3"):
        world.add_geom(size=[1, 2, 3, 4])
    with pytest.raises((TypeError, ValueError), match="MjsGeom.rgba"):
        world.add_geom(rgba="red")
    with pytest.raises(TypeError, match="no default class"):
        spec.add_sensor(default=object())
    assert mjcffi.mj_compile(spec, None).ngeom == 0      # none of the refused geoms stayed


def test_one_wrapper_per_element_of_its_class():
    spec = mjcffi.mj_makeSpec()
    body = _world(spec).add_body(name="b")
    # the class registered last for the kind (mjcffi.spec's subclass, once imported)
    assert isinstance(body, MjsBody) and type(body) is _elements._BY_KIND["Body"]
    assert _elements.wrap(body._ptr, spec) is body
    assert _elements.wrap(body._ptr.element, spec) is body
    geom = body.add_geom()
    assert type(_elements.wrap(geom._ptr.element, spec)) is _elements._BY_KIND["Geom"]
    assert isinstance(geom, MjsGeom)
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


def test_an_invalidated_element_keeps_its_values_and_refuses_the_rest():
    spec = mjcffi.mj_makeSpec()
    geom = _world(spec).add_geom(name="doomed", size=[1, 2, 3], userdata=[4])
    vector = geom.userdata
    _elements.invalidate([geom])
    assert geom.name == "doomed" and geom.size.tolist() == [1, 2, 3]   # as the official
    assert geom.userdata.tolist() == [4]
    assert isinstance(geom, MjsGeom) and "deleted" in repr(geom)
    with pytest.raises(ValueError, match="read-only"):
        geom.size[0] = 5                                   # a copy: it would be lost
    with pytest.raises(_elements.DeletedElementError, match="MjsGeom 'doomed' was deleted"):
        geom.rgba = [1, 1, 1, 1]
    with pytest.raises(RuntimeError, match="deleted"):   # also the RuntimeError it was
        vector[0]                                          # read before: through the wrapper
    body = _world(spec).add_body()
    _elements.invalidate_missing(spec, alive=set())        # freed, nothing taken before
    with pytest.raises(_elements.DeletedElementError, match="MjsBody"):
        body.add_geom()
    with pytest.raises(ValueError, match="MjsBody"):
        body.pos


def test_names_are_set_through_mujoco_which_refuses_a_repeated_one():
    spec = mjcffi.mj_makeSpec()
    world = _world(spec)
    body = world.add_body(name="b")
    body.name = "renamed"
    assert body.name == "renamed"
    assert mjcffi.mjs_findBody(spec, "renamed")._ptr == body._ptr
    with pytest.raises(ValueError, match="^Error: repeated name 'renamed' in body$"):
        world.add_body(name="renamed")
    assert mjcffi.mj_compile(spec, None).nbody == 2      # the refused body was removed
    long_name = "x" * 40                                   # past the short-string buffer
    body.name = long_name
    assert body.name == long_name and _world(spec).name == "world"


def test_a_refused_name_raises_the_official_message():
    ours, theirs = mjcffi.mj_makeSpec(), mujoco.MjSpec()
    messages = []
    for spec in (ours, theirs):
        spec.add_material().name = "yellow"
        with pytest.raises(ValueError) as refused:
            spec.add_material().name = "yellow"
        messages.append(str(refused.value))
    assert messages[0] == messages[1] == "Error: repeated name 'yellow' in material"


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
    if kind in ("MjDoubleVec", "MjFloatVec", "MjIntVec", "MjStringVec", "MjCharVec"):
        return type(ours).__name__ == kind and list(ours) == list(official)
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
    differ: set = set()
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


# ------------------------------------------------------------- char arrays

def test_char_arrays_read_and_write_as_the_official():
    ours, theirs = mjcffi.mj_makeSpec(), mujoco.MjSpec()
    for spec in (ours, theirs):
        compiler = spec.compiler
        assert compiler.eulerseq[0] == "x" and len(compiler.eulerseq) == 3
        compiler.eulerseq = ["z", "y", "x"]
        compiler.eulerseq[0] = "y"
        with pytest.raises(IndexError):
            compiler.eulerseq[3] = "x"
        with pytest.raises(IndexError):
            compiler.eulerseq[-1] = "x"
        with pytest.raises(ValueError, match="eulerseq may have at most 3 characters"):
            compiler.eulerseq = "xyzw"
        with pytest.raises(ValueError, match="multi-character"):
            compiler.eulerseq[0] = "xy"
    assert list(ours.compiler.eulerseq) == list(theirs.compiler.eulerseq) == list("yyx")
    assert type(ours.compiler.eulerseq).__name__ == "MjCharVec"
    for spec in (ours, theirs):
        spec.compiler.eulerseq = "zy"                      # the rest is NUL
    assert list(ours.compiler.eulerseq) == list(theirs.compiler.eulerseq) == ["z", "y", "\0"]
    with pytest.raises(TypeError, match="MjsCompiler.eulerseq"):
        ours.compiler.eulerseq = 5
    with pytest.raises(TypeError, match="MjsCompiler.eulerseq"):
        ours.compiler.eulerseq[0] = 5


def _error(call):
    try:
        call()
    except Exception as exc:             # noqa: BLE001 -- the official's type is compared
        return type(exc), str(exc)
    return None


def test_a_char_array_keyword_has_the_official_length_rule():
    ours, theirs = mjcffi.mj_makeSpec(), mujoco.MjSpec()
    layout = ".U..LFRB.D.."
    for value in (layout, list(layout)):
        assert list(ours.add_texture(gridlayout=value).gridlayout) == \
            list(theirs.add_texture(gridlayout=value).gridlayout) == list(layout)
    for value in (".U..", [".", "U"], ["..", "U"] + ["."] * 10, tuple(layout), 5):
        mine, official = (_error(lambda: s.add_texture(gridlayout=value))
                          for s in (ours, theirs))
        assert mine == official and mine is not None, value
    texture = ours.add_texture(gridsize=[2, 4])
    texture.gridlayout = "LFRB.D.."                        # an attribute may be shorter
    assert list(texture.gridlayout) == list("LFRB.D..") + ["\0"] * 4
    with pytest.raises(ValueError, match="gridlayout may have at most 12 characters"):
        texture.gridlayout = "." * 13


# ----------------------------------------------------------------- keywords

def test_orientation_keywords_set_alt_as_the_official():
    ours, theirs = mjcffi.mj_makeSpec(), mujoco.MjSpec()
    keywords = [dict(euler=[0, 0, 90]), dict(axisangle=[0, 0, 1, 30]),
                dict(xyaxes=[0, 1, 0, -1, 0, 0]), dict(zaxis=[0, 0, -1])]
    for world in (_world(ours), theirs.worldbody):
        for i, orientation in enumerate(keywords):
            body = world.add_body(pos=[i, 0, 0], **orientation)
            body.add_site(**orientation)
            body.add_geom(size=[0.1], **orientation)
        world.add_body(ieuler=[1, 2, 3], euler=[4, 5, 6], mass=1, inertia=[1, 1, 1])
    model, official = mjcffi.mj_compile(ours, None), theirs.compile()
    assert model.to_bytes() == _official_bytes(official)
    alt = _world(ours).add_frame(zaxis=[0, 0, -1]).alt
    assert alt.type == mjcffi.mjtOrientation.mjORIENTATION_ZAXIS
    assert alt.zaxis.tolist() == [0, 0, -1]


def test_orientation_keyword_errors_are_the_officials():
    ours, theirs = mjcffi.mj_makeSpec(), mujoco.MjSpec()
    calls = [dict(axisangle=[1, 2, 3]), dict(xyaxes=[1, 2, 3, 4, 5]), dict(zaxis=[1, 2, 3, 4]),
             dict(euler=[1]), dict(axisangle=[1, 2, 3, 4], euler=[1, 2, 3]),
             dict(pos=[0, 1]), dict(rgba=[1, 2]), dict(size=[1, 2, 3, 4]), dict(size=[])]
    for keywords in calls:
        mine = _error(lambda: _world(ours).add_geom(**keywords))
        official = _error(lambda: theirs.worldbody.add_geom(**keywords))
        assert mine == official and mine is not None, keywords
    mine = _error(lambda: _world(ours).add_body(iaxisangle=[1, 2, 3, 4], ieuler=[1, 2, 3]))
    assert mine == _error(lambda: theirs.worldbody.add_body(iaxisangle=[1, 2, 3, 4],
                                                            ieuler=[1, 2, 3]))
    assert mjcffi.mj_compile(ours, None).ngeom == 0       # no refused geom left behind
    with pytest.raises(TypeError, match="Invalid axis keyword argument. Valid options are: "
                                        "align, group, name."):
        _world(ours).add_freejoint(axis=[1, 2, 3])


def test_short_keyword_arrays_are_padded_where_the_official_pads():
    ours, theirs = mjcffi.mj_makeSpec(), mujoco.MjSpec()
    made = []
    for world, spec in ((_world(ours), ours), (theirs.worldbody, theirs)):
        made.append([world.add_geom(size=[0.5]).size, world.add_site(size=[0.2, 0.1]).size,
                     world.add_joint(damping=2).damping,
                     spec.add_tendon(stiffness=2, springlength=[0.1, 0.2]).stiffness,
                     world.add_frame(scale=2).scale])
    assert [a.tolist() for a in made[0]] == [list(a) for a in made[1]]
    assert made[0][0].tolist() == [0.5, 0, 0] and made[0][4].tolist() == [2, 2, 2]


def test_a_fixed_array_attribute_takes_exactly_its_length_as_the_official():
    ours = _world(mjcffi.mj_makeSpec()).add_geom()
    theirs = mujoco.MjSpec().worldbody.add_geom()
    for value in (2, [2], [1, 2, 3, 4], "abc"):
        for geom in (ours, theirs):
            with pytest.raises(TypeError):                 # ours: ArgumentError, both kinds
                geom.size = value
    for value in ([1, 2, 3], (1, 2, 3), np.array([1.0, 2, 3]), np.arange(1, 4)):
        ours.size = value
        assert ours.size.tolist() == [1, 2, 3]
    with pytest.raises(ValueError, match="MjsGeom.size"):
        ours.size = [1, 2]
    ours.contype = 3
    with pytest.raises(TypeError, match="takes ints"):
        _world(mjcffi.mj_makeSpec()).add_camera().resolution = [1.5, 2]


def test_positional_default_and_frame_as_the_official():
    spec = mjcffi.mj_makeSpec()
    main = spec.add_default("big", None)
    main.geom.size = [1, 1, 1]
    world = _world(spec)
    assert world.add_geom(main).size.tolist() == [1, 1, 1]
    frame = world.add_frame(name="outer")
    inner = world.add_frame(default=frame, name="inner")    # the official's keyword
    assert mjcffi.mjs_getFrame(inner.element)._ptr == frame._ptr
    with pytest.raises(TypeError, match="two default classes"):
        world.add_geom(main, default=main)


def test_plugin_assignment_copies_values_never_pointers():
    spec = mjcffi.mj_makeSpec()
    plugin = spec.add_plugin(name="inst", plugin_name="mujoco.pid", active=True, info="i")
    body = _world(spec).add_body(plugin=plugin)
    assert (body.plugin.name, body.plugin.plugin_name, body.plugin.active) == \
        ("inst", "mujoco.pid", True)
    plugin.name = "renamed"
    assert body.plugin.name == "inst"                      # a copy: no shared memory
    assert body.plugin.info == ""                          # MuJoCo made no string for it
    with pytest.raises(ValueError, match="MjsPlugin.info cannot be set"):
        body.plugin.info = "x"
    with pytest.raises(TypeError, match="MjsBody.plugin takes MjsPlugin"):
        body.plugin = body


def test_mjstruct_is_the_union_of_the_officials_element_classes():
    from mjcffi.structs.mjspec import MjStruct
    ours = [cls.__name__ for cls in typing.get_args(MjStruct)]
    assert sorted(ours) == sorted(cls.__name__ for cls in typing.get_args(mujoco.MjStruct))
    assert isinstance(_world(mjcffi.mj_makeSpec()), typing.get_args(MjStruct))


# -------------------------------------------- deleted elements and their views

def _live_addresses(spec):
    from mjcffi._support.library import ffi, lib
    found = set()
    for kind in [*range(1, lib.mjNOBJECT), lib.mjOBJ_FRAME]:   # all but mjOBJ_UNKNOWN
        element = lib.mjs_firstElement(spec._ptr, kind)
        while element != ffi.NULL:
            found.add(int(ffi.cast("uintptr_t", element)))
            element = lib.mjs_nextElement(spec._ptr, element)
    return found


def _delete(spec, element):
    """What MjSpec.delete does with the element layer: refuse while views are held,
    take the values, delete, end the wrappers of what was freed."""
    from mjcffi._support.library import lib
    taken = _elements.prepare_delete(spec, element)
    assert lib.mjcffi_guard_mjs_delete(spec._ptr, element._ptr.element) == 0
    _elements.invalidate_missing(spec, _live_addresses(spec), taken)


def test_a_held_view_of_an_element_refuses_its_delete():
    spec = mjcffi.mj_makeSpec()
    body = _world(spec).add_body(name="b", euler=[0, 0, 1])
    frame = body.add_frame()
    geom = frame.add_body(name="c").add_geom(name="g", size=[1, 2, 3])
    size, row, euler = geom.size, geom.rgba[1:3], body.alt.euler
    with pytest.raises(ValueError, match=r"cannot delete MjsBody 'b': .*MjsBody 'b'\.alt\."
                                         r"euler.*MjsGeom 'g'\.size.*MjsGeom 'g'\.rgba"):
        _delete(spec, body)
    assert _elements.held_views([geom]) == ["MjsGeom 'g'.size", "MjsGeom 'g'.rgba"]
    assert size.tolist() == [1, 2, 3] and body.name == "b"  # nothing was freed
    del size, row
    assert _elements.held_views([geom, body]) == ["MjsBody 'b'.alt.euler"]
    kept = euler.copy()
    del euler
    assert _elements.held_views(_elements.doomed(spec, body)) == []
    _delete(spec, body)
    assert geom.size.tolist() == [1, 2, 3] and kept.tolist() == [0, 0, 1]
    assert geom.name == "g" and body.alt.euler.tolist() == [0, 0, 1]
    assert mjcffi.mj_compile(spec, None).nbody == 1


def test_doomed_holds_the_subtree_and_what_may_go_with_it():
    from mjcffi._support.library import lib
    spec = mjcffi.mj_makeSpec()
    world = _world(spec)
    body = world.add_body(name="b")
    frame = body.add_frame(name="f")
    inner = frame.add_geom(name="in_frame")
    child = frame.add_body(name="c")
    joint = child.add_joint(name="j")
    other = world.add_body(name="other")
    actuator = spec.add_actuator(name="a", target="j", trntype=mjcffi.mjtTrn.mjTRN_JOINT)
    mesh = spec.add_mesh(name="m")
    mesh_taken = _elements.doomed(spec, mesh)
    taken = _elements.prepare_delete(spec, mesh)
    assert lib.mjcffi_guard_mjs_delete(spec._ptr, mesh._ptr.element) == 0   # no mesh: no
    _elements.invalidate_missing(spec, _live_addresses(spec), taken)       # vertices
    assert mesh_taken == [mesh] and mesh.name == "m"
    names = {w.name for w in _elements.doomed(spec, body)}
    assert names == {"b", "f", "in_frame", "c", "j", "a"}
    assert {w.name for w in _elements.doomed(spec, frame)} == {"f", "in_frame", "c", "j", "a"}
    _delete(spec, body)
    assert actuator.name == "a" and joint.name == "j"      # freed, as the official reads
    assert other.name == "other" and mjcffi.mj_compile(spec, None).nu == 0
    with pytest.raises(_elements.DeletedElementError):
        actuator.gear = [1, 0, 0, 0, 0, 0]
    del inner


def test_deleted_elements_match_the_officials_reads():
    spec, official = mjcffi.mj_makeSpec(), mujoco.MjSpec()
    made = []
    for world, owner in ((_world(spec), spec), (official.worldbody, official)):
        body = world.add_body(name="body", pos=[1, 2, 3], userdata=[5])
        joint = body.add_joint(name="joint", type=mujoco.mjtJoint.mjJNT_HINGE)
        act = owner.add_actuator(name="act", target="joint", trntype=mujoco.mjtTrn.mjTRN_JOINT)
        made.append((body, joint, act))
    _delete(spec, made[0][0])
    official.delete(made[1][0])
    for mine, theirs in zip(made[0], made[1]):
        assert mine.name == theirs.name
    assert made[0][0].pos.tolist() == list(made[1][0].pos) == [1, 2, 3]
    assert list(made[0][0].userdata) == list(made[1][0].userdata) == [5]


def test_strings_never_made_read_empty():
    body = _world(mjcffi.mj_makeSpec()).add_body()
    assert body.plugin.info == ""                          # the official crashes here
    assert body.plugin.name == "" and body.plugin.element is None


def test_view_outliving_its_wrapper_still_blocks_the_free():
    """A slice of an element's view, kept after its wrapper is dropped, still keeps
    MuJoCo from freeing the element under it."""
    import gc
    spec = mjcffi.MjSpec()
    spec.worldbody.add_body(name="b").add_geom(name="g", size=[1, 2, 3])
    tail = spec.geom("g").size[1:]
    gc.collect()
    with pytest.raises(ValueError, match=r"MjsGeom 'g'\.size"):
        spec.delete(spec.body("b"))
    np.testing.assert_array_equal(tail, [2, 3])
    assert [b.name for b in spec.bodies] == ["world", "b"]
    del tail
    gc.collect()
    spec.delete(spec.body("b"))
    assert spec.geoms == []
