"""mjcffi.MjSpec (issue 13): parse, compile, save, copy, lookups, lists, delete, attach,
against the official bindings and MuJoCo's own loader."""

import copy
import glob
import os
import subprocess
import sys

import numpy as np
import pytest

import mjcffi
from mjcffi import MjSpec, mjtObj

gymnasium = pytest.importorskip("gymnasium")
ASSETS = sorted(glob.glob(os.path.join(os.path.dirname(gymnasium.__file__),
                                       "envs", "mujoco", "assets", "*.xml")))

TREE = """
<mujoco model="tree">
  <worldbody>
    <body name="torso" pos="0 0 1">
      <freejoint name="root"/>
      <geom name="torso_geom" type="box" size=".2 .1 .05"/>
      <site name="imu"/>
      <body name="arm" pos=".2 0 0">
        <joint name="shoulder" axis="0 1 0"/>
        <geom name="arm_geom" type="capsule" fromto="0 0 0 .3 0 0" size=".03"/>
        <site name="tip" pos=".3 0 0"/>
        <body name="hand" pos=".3 0 0">
          <joint name="wrist"/>
          <geom name="hand_geom" size=".04"/>
        </body>
      </body>
    </body>
    <light name="top" pos="0 0 3"/>
    <camera name="side" pos="0 -3 1"/>
  </worldbody>
  <actuator>
    <motor name="m_shoulder" joint="shoulder"/>
    <motor name="m_wrist" joint="wrist"/>
  </actuator>
  <sensor>
    <jointpos name="s_wrist" joint="wrist"/>
  </sensor>
</mujoco>
"""


def trajectory(model, steps=200):
    data = mjcffi.MjData(model)
    data.ctrl[:] = 0.1              # a fixed control, so the actuators take part
    states = []
    for _ in range(steps):
        mjcffi.mj_step(model, data)
        states.append(np.concatenate([data.qpos, data.qvel, data.act]))
    return np.array(states)


# ----------------------------------------------------------- round trips

@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.parametrize("path", ASSETS, ids=os.path.basename)
def test_gymnasium_round_trip(path, mujoco):
    model = MjSpec.from_file(path).compile()
    reference = mjcffi.MjModel.from_xml_path(path)
    assert model.nq == reference.nq and model.nu == reference.nu
    assert trajectory(model).tobytes() == trajectory(reference).tobytes()
    assert MjSpec.from_file(path).to_xml() == mujoco.MjSpec.from_file(path).to_xml()


def test_there_are_gymnasium_assets():
    assert len(ASSETS) >= 10


def test_from_string_to_xml_matches_official(mujoco):
    assert MjSpec.from_string(TREE).to_xml() == mujoco.MjSpec.from_string(TREE).to_xml()


def test_empty_spec_compiles():
    model = MjSpec().compile()
    assert model.nbody == 1 and model.nq == 0


def test_assets_are_read_at_parse_and_compile():
    xml = '<mujoco><include file="part.xml"/></mujoco>'
    part = b'<mujoco><worldbody><body name="b"><geom size=".1"/></body></worldbody></mujoco>'
    spec = MjSpec.from_string(xml, include={"part.xml": part})
    assert spec.compile().nbody == 2
    with pytest.raises(ValueError, match="part.xml"):
        MjSpec.from_string(xml)


def test_to_file_writes_to_xml(tmp_path):
    spec = MjSpec.from_string(TREE)
    path = tmp_path / "tree.xml"
    spec.to_file(str(path))
    assert path.read_text() == spec.to_xml()
    assert MjSpec.from_file(str(path)).compile().nbody == 4


def test_from_zip(tmp_path):
    import zipfile
    path = tmp_path / "model.zip"
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("folder/model.xml", '<mujoco><include file="parts/arm.xml"/></mujoco>')
        archive.writestr("folder/parts/arm.xml", TREE)
    spec = MjSpec.from_zip(str(path))
    assert sorted(spec.assets) == ["parts/arm.xml"]
    assert spec.compile().nbody == 4


# ------------------------------------------------------------- errors

def test_parse_error_is_value_error_with_mujocos_message():
    with pytest.raises(ValueError, match="XML parse error"):
        MjSpec.from_string("<mujoco><worldbody>")


def test_compile_error_duplicate_names(mujoco):
    xml = TREE.replace('name="hand_geom"', 'name="arm_geom"')
    with pytest.raises(ValueError) as ours:
        MjSpec.from_string(xml).compile()
    with pytest.raises(ValueError) as official:
        mujoco.MjSpec.from_string(xml).compile()
    assert "repeated name 'arm_geom'" in str(ours.value)
    assert str(ours.value).strip() == str(official.value).strip()


def test_duplicate_name_made_in_code_is_refused():
    spec = MjSpec.from_string(TREE)
    with pytest.raises(ValueError, match="arm_geom"):
        spec.body("hand").add_geom(name="arm_geom", size=[0.1, 0, 0])


def test_compile_error_unknown_joint_reference():
    spec = MjSpec.from_string(TREE.replace('joint="wrist"/>\n  </sensor>',
                                           'joint="elbow"/>\n  </sensor>'))
    with pytest.raises(ValueError, match="elbow"):
        spec.compile()


# ------------------------------------------------------- lookups, lists

LISTS = ("bodies", "geoms", "joints", "sites", "cameras", "lights", "actuators", "sensors",
         "meshes", "materials", "textures", "tendons", "equalities", "keys", "frames")


@pytest.mark.filterwarnings("ignore::UserWarning")
@pytest.mark.parametrize("path", [TREE] + ASSETS[:4], ids=lambda p: os.path.basename(p)[:12])
def test_lists_match_official(path, mujoco):
    load = "from_string" if path is TREE else "from_file"
    ours, theirs = getattr(MjSpec, load)(path), getattr(mujoco.MjSpec, load)(path)
    for name in LISTS:
        assert [e.name for e in getattr(ours, name)] == \
               [e.name for e in getattr(theirs, name)], name


def test_lookups():
    spec = MjSpec.from_string(TREE)
    assert spec.body("arm").name == "arm"
    assert spec.geom("hand_geom").size[0] == pytest.approx(0.04)
    assert spec.joint("wrist").name == "wrist"
    assert spec.site("tip").pos[0] == pytest.approx(0.3)
    assert spec.actuator("m_wrist").name == "m_wrist"
    assert spec.sensor("s_wrist").name == "s_wrist"
    assert spec.camera("side").name == "side" and spec.light("top").name == "top"
    assert spec.body("nowhere") is None and spec.geom("arm") is None


def test_one_wrapper_per_element():
    spec = MjSpec.from_string(TREE)
    assert spec.body("arm") is spec.bodies[2]
    assert spec.worldbody is spec.bodies[0]


def test_find_all_by_enum_or_name():
    spec = MjSpec.from_string(TREE)
    assert [s.name for s in spec.find_all(mjtObj.mjOBJ_SITE)] == ["imu", "tip"]
    assert [s.name for s in spec.find_all("joint")] == ["root", "shoulder", "wrist"]
    with pytest.raises(ValueError, match="unknown element type"):
        spec.find_all("gizmo")


def test_edit_then_compile():
    spec = MjSpec.from_string(TREE)
    spec.geom("hand_geom").size = [0.08, 0, 0]
    spec.modelname = "edited"
    model = spec.compile()
    assert model.geom_size[model.geom("hand_geom").id][0] == pytest.approx(0.08)
    assert '<mujoco model="edited">' in spec.to_xml()


# ------------------------------------------------------------ delete

def assert_ended(wrapper, name):
    """`wrapper`'s element was freed: it reads its name as it was (as official), is in
    no body, and refuses writes and MuJoCo calls."""
    from mjcffi.spec import lifetime
    assert lifetime.is_deleted(wrapper)
    assert wrapper.name == name
    if hasattr(type(wrapper), "parent"):
        assert wrapper.parent is None
    with pytest.raises(RuntimeError, match="deleted"):
        wrapper.name = "again"
    with pytest.raises(RuntimeError, match="deleted"):
        mjcffi.mjs_getName(wrapper.element)


def test_delete_a_subtree_ends_its_wrappers():
    spec = MjSpec.from_string(TREE)
    arm, hand, tip = spec.body("arm"), spec.geom("hand_geom"), spec.site("tip")
    torso, motor = spec.body("torso"), spec.actuator("m_wrist")
    spec.delete(arm)
    for dead, name in ((arm, "arm"), (hand, "hand_geom"), (tip, "tip"), (motor, "m_wrist")):
        assert_ended(dead, name)
        with pytest.raises(RuntimeError, match="deleted"):
            dead.info = "x"
    assert hand.size[0] == pytest.approx(0.04)            # a read-only copy
    with pytest.raises(ValueError, match="read-only"):
        hand.size[0] = 1
    assert torso.name == "torso"                         # the rest lives on
    assert [b.name for b in spec.bodies] == ["world", "torso"]


def test_deleted_wrappers_read_as_official(mujoco):
    def deleted_names(module):
        spec = module.MjSpec()
        for i in range(3):
            body = spec.worldbody.add_body(name=f"body_{i}")
            joint = body.add_joint(name=f"joint_{i}")
            body.add_geom(size=[0.1, 0.1, 0.1])
            act = spec.add_actuator(name=f"act_{i}", target=f"joint_{i}",
                                    trntype=module.mjtTrn.mjTRN_JOINT)
            spec.delete(body)
        model = spec.compile()
        return (model.nbody, model.nu, body.name, joint.name, act.name, body.parent)
    assert deleted_names(mjcffi) == deleted_names(mujoco) == (1, 0, "body_2", "joint_2",
                                                              "act_2", None)


def test_delete_then_compile_matches_xml_without_it():
    spec = MjSpec.from_string(TREE.replace(
        '<actuator>\n    <motor name="m_shoulder" joint="shoulder"/>\n'
        '    <motor name="m_wrist" joint="wrist"/>\n  </actuator>\n  <sensor>\n'
        '    <jointpos name="s_wrist" joint="wrist"/>\n  </sensor>\n', ""))
    spec.delete(spec.body("hand"))
    model = spec.compile()
    assert model.nbody == 3 and model.njnt == 2 and model.ngeom == 2


def test_deleted_wrapper_passed_to_mujoco_raises():
    spec = MjSpec.from_string(TREE)
    geom = spec.geom("hand_geom")
    spec.delete(geom)
    with pytest.raises(ValueError, match="geom is not in this model"):
        spec.delete(geom)                           # the official's message
    with pytest.raises(RuntimeError, match="deleted"):
        mjcffi.mjs_getName(geom.element)


def test_delete_refuses_elements_of_another_spec():
    spec, other = MjSpec.from_string(TREE), MjSpec.from_string(TREE)
    with pytest.raises(ValueError, match="another spec"):
        spec.delete(other.body("arm"))
    assert other.body("arm").name == "arm"
    with pytest.raises(TypeError, match="spec element"):
        spec.delete("arm")


def test_use_after_delete_does_not_crash_the_process():
    code = ("import mjcffi, gc\n"
            f"s = mjcffi.MjSpec.from_string({TREE!r})\n"
            "g = s.geom('hand_geom'); s.delete(s.body('torso')); gc.collect()\n"
            "try:\n    g.size[0] = 1\nexcept ValueError:\n    print('raised')\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "raised"


# ------------------------------------------------------------ lifetimes

def test_wrappers_keep_the_spec_alive():
    import gc
    geom = MjSpec.from_string(TREE).geom("hand_geom")
    gc.collect()
    assert geom.name == "hand_geom" and geom.size[0] == pytest.approx(0.04)


def test_copy_is_independent():
    spec = MjSpec.from_string(TREE)
    for other in (spec.copy(), copy.copy(spec), copy.deepcopy(spec)):
        assert isinstance(other, MjSpec)
        other.delete(other.body("arm"))
        other.geom("torso_geom").size = [1, 1, 1]
        assert len(spec.bodies) == 4 and len(other.bodies) == 2
        assert spec.geom("torso_geom").size[0] == pytest.approx(0.2)
        assert spec.compile().nbody == 4 and other.compile().nbody == 2


# ------------------------------------------------------------ recompile

def test_recompile_keeps_the_state():
    spec = MjSpec.from_string(TREE)
    model = spec.compile()
    data = mjcffi.MjData(model)
    for _ in range(20):
        mjcffi.mj_step(model, data)
    spec.geom("hand_geom").size = [0.06, 0, 0]
    new_model, new_data = spec.recompile(model, data)
    assert isinstance(new_model, mjcffi.MjModel) and isinstance(new_data, mjcffi.MjData)
    assert new_data.model is new_model
    np.testing.assert_array_equal(new_data.qpos, data.qpos)
    np.testing.assert_array_equal(new_data.qvel, data.qvel)
    assert new_data.time == data.time
    assert new_model.geom_size[new_model.geom("hand_geom").id][0] == pytest.approx(0.06)
    assert model.geom_size[model.geom("hand_geom").id][0] == pytest.approx(0.04)


def test_recompile_error_leaves_model_and_data_usable():
    spec = MjSpec.from_string(TREE)
    model = spec.compile()
    data = mjcffi.MjData(model)
    spec.actuator("m_wrist").target = "elbow"
    with pytest.raises(ValueError, match="elbow"):
        spec.recompile(model, data)
    mjcffi.mj_step(model, data)
    assert data.time > 0


# ------------------------------------------------------------ attach

ARM = ('<mujoco><worldbody><body name="link"><joint/><geom size=".05"/></body>'
       '</worldbody></mujoco>')


def test_attach_at_a_site_and_a_frame():
    # Both attaches before compiling: attaching again after a compile hangs inside
    # MuJoCo (the official bindings too), so this test does not do it.
    arm = MjSpec.from_string(ARM)
    spec = MjSpec.from_string(TREE)
    spec.attach(arm, prefix="left_", site="tip")
    frame = spec.attach(MjSpec.from_string(ARM), prefix="free_",
                        frame=spec.worldbody.add_frame())
    assert isinstance(frame, mjcffi.structs.mjspec.MjsFrame)
    model = spec.compile()
    assert model.body("left_link").parentid == model.body("arm").id
    assert model.body("free_link").parentid == 0
    with pytest.raises(ValueError, match="already attached"):
        spec.attach(arm, prefix="again_", site="imu")
    with pytest.raises(ValueError, match="frame or site"):
        spec.attach(MjSpec.from_string(ARM), prefix="nowhere_")
    with pytest.raises(TypeError, match="MjSpec"):
        spec.attach("arm", site="imu")


def test_attach_matches_the_same_model_written_as_xml():
    arm = MjSpec.from_string(ARM)
    spec = MjSpec.from_string(TREE)
    spec.attach(arm, prefix="left_", site="tip")
    # the attached body comes after the site's body's own children
    hand_end = '<geom name="hand_geom" size=".04"/>\n        </body>'
    written = TREE.replace(hand_end, hand_end + '<frame pos=".3 0 0"><body name="left_link">'
                           '<joint/><geom size=".05"/></body></frame>')
    ours, reference = spec.compile(), MjSpec.from_string(written).compile()
    assert ours.nbody == reference.nbody
    assert trajectory(ours).tobytes() == trajectory(reference).tobytes()


# ------------------------------------------------- assets, vfs and parsing

CUBE_OBJ = (b"v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\n"
            b"v -1 1 1\nf 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n")
MESHED = ('<mujoco><asset><mesh name="box" file="box.obj"/></asset><worldbody>'
          '<body name="b"><joint/><geom type="mesh" mesh="box"/></body></worldbody></mujoco>')


def test_assets_setter_adds_files_as_official(mujoco):
    for module in (mjcffi, mujoco):
        spec = module.MjSpec()
        spec.assets = {"a.obj": b"1"}
        spec.assets = {"b.obj": b"2"}
        assert spec.assets == {"a.obj": b"1", "b.obj": b"2"}, module.__name__
    with pytest.raises(TypeError, match="dict"):
        MjSpec().assets = [("a", b"1")]
    with pytest.raises(TypeError, match="must be bytes"):
        MjSpec().assets = {"a.obj": 5}


def test_from_string_keeps_assets_not_includes():
    xml = '<mujoco><include file="part.xml"/></mujoco>'
    part = MESHED.encode()
    spec = MjSpec.from_string(xml, include={"part.xml": part}, assets={"box.obj": CUBE_OBJ})
    assert list(spec.assets) == ["box.obj"]
    assert spec.compile().nmesh == 1


def test_vfs_with_assets_or_include_is_refused():
    with mjcffi.MjVfs() as vfs:
        with pytest.raises(ValueError, match="Cannot specify both 'vfs' and 'include'/'assets'"):
            MjSpec.from_string(MESHED, assets={"box.obj": CUBE_OBJ}, vfs=vfs)
        with pytest.raises(ValueError, match="Cannot specify both"):
            MjSpec.from_file("x.xml", include={}, vfs=vfs)
        spec = MjSpec.from_string(MESHED, assets={"box.obj": CUBE_OBJ})
        for call in (spec.compile, spec.fuse_static, spec.discard_visual):
            with pytest.raises(ValueError, match="Cannot specify both 'vfs' and 'assets'"):
                call(vfs=vfs)


def test_compile_reads_a_vfs_and_a_closed_one_raises():
    spec = MjSpec.from_string(MESHED)
    with mjcffi.MjVfs() as vfs:
        vfs["box.obj"] = CUBE_OBJ
        assert spec.compile(vfs=vfs).nmesh == 1
    for call in (spec.compile, spec.fuse_static, spec.discard_visual,
                 lambda vfs: MjSpec.from_string("<mujoco/>", vfs=vfs)):
        with pytest.raises(RuntimeError, match="VFS is closed"):
            call(vfs=vfs)
    with pytest.raises(TypeError, match="vfs"):
        spec.compile(vfs="box.obj")


def test_recompile_with_a_vfs_keeps_the_state():
    spec = MjSpec.from_string(MESHED)
    with mjcffi.MjVfs() as vfs:
        vfs["box.obj"] = CUBE_OBJ
        model = spec.compile(vfs=vfs)
        data = mjcffi.MjData(model)
        data.qpos[0] = 0.75
        spec.worldbody.add_body(name="extra").add_geom(size=[0.1, 0, 0])
        new_model, new_data = spec.recompile(model, data, vfs=vfs)
    assert new_model.ngeom == 2 and new_data.qpos[0] == 0.75
    with_assets = MjSpec.from_string(MESHED, assets={"box.obj": CUBE_OBJ})
    model = with_assets.compile()
    with mjcffi.MjVfs() as vfs, pytest.raises(ValueError, match="Cannot specify both"):
        with_assets.recompile(model, mjcffi.MjData(model), vfs=vfs)


def test_from_file_decodes_by_extension(mujoco):
    bad_stl = b"too short for an stl header"
    for module in (mjcffi, mujoco):
        with pytest.raises(ValueError, match="stl_decoder: invalid header"):
            module.MjSpec.from_file("bad.stl", include={"bad.stl": bad_stl})


def test_to_zip_then_from_zip(tmp_path, mujoco):
    spec = MjSpec.from_string(MESHED.replace("<mujoco>", '<mujoco model="boxy">'),
                              assets={"box.obj": CUBE_OBJ})
    path = tmp_path / "out" / "boxy.zip"
    spec.to_zip(str(path))
    import zipfile
    with zipfile.ZipFile(path) as archive:
        assert sorted(archive.namelist()) == ["box.obj", "boxy.xml"]
    again = MjSpec.from_zip(str(path))
    assert again.assets == {"box.obj": CUBE_OBJ}
    assert again.compile().nmesh == 1
    assert mujoco.MjSpec.from_zip(str(path)).compile().nmesh == 1   # the official reads it
    with pytest.raises(ValueError, match="not a zip file"):
        MjSpec.from_zip(__file__)


# --------------------------------------------------- compiling, warnings

def test_compile_warnings_are_user_warnings():
    xml = ('<mujoco><worldbody><flexcomp name="my_flex" type="grid" count="3 3 1" '
           'spacing=".05 .05 .05" radius=".01" dim="2"/></worldbody></mujoco>')
    with pytest.warns(UserWarning, match="is not rigid"):
        MjSpec.from_string(xml).compile()


def test_timer_is_filled_by_compile():
    spec = MjSpec.from_string(
        '<mujoco><asset><texture name="grid" type="2d" builtin="checker" width="64" '
        'height="64"/><material name="grid" texture="grid"/></asset><worldbody>'
        '<geom type="plane" size="1 1 1" material="grid"/></worldbody></mujoco>')
    assert spec.timer.shape == (mjcffi.mjtCTimer.mjNCTIMER,)
    assert not spec.timer.any()
    spec.compile()
    timer = spec.timer
    del spec
    import gc
    gc.collect()
    assert timer[mjcffi.mjtCTimer.mjCTIMER_TOTAL] > 0       # the view kept the spec
    assert timer[mjcffi.mjtCTimer.mjCTIMER_TEXTURE] > 0


def test_spec_settings():
    spec = MjSpec()
    spec.meshdir, spec.texturedir = "/meshes", "/textures"
    assert (spec.compiler.meshdir, spec.compiler.texturedir) == ("/meshes", "/textures")
    assert spec.meshdir == "/meshes" and spec.texturedir == "/textures"
    assert spec.override_assets is True and spec.parent is None
    spec.override_assets = False
    assert spec.copy().override_assets is False
    with pytest.raises(ValueError, match="can only be set"):
        spec.copy_during_attach
    spec.copy_during_attach = True


def test_activate_plugin():
    inactive = MjSpec()
    inactive.add_plugin(name="torus", plugin_name="mujoco.sdf.torus")
    with pytest.raises(ValueError, match="unrecognized plugin"):
        inactive.compile()
    spec = MjSpec()
    spec.activate_plugin("mujoco.sdf.torus")
    spec.add_plugin(name="torus", plugin_name="mujoco.sdf.torus")
    assert spec.compile().nplugin == 1
    with pytest.raises(ValueError, match="no plugin named 'no.such'"):
        spec.activate_plugin("no.such")
    with pytest.raises(TypeError, match="name"):
        spec.activate_plugin(3)


def test_resolve_orientation(mujoco):
    spec = MjSpec()
    body = spec.worldbody.add_body()
    body.alt.type = mjcffi.mjtOrientation.mjORIENTATION_EULER
    body.alt.euler = [0, 0, 90]
    quat = MjSpec.resolve_orientation(degree=True, sequence=spec.compiler.eulerseq,
                                      orientation=body.alt)
    np.testing.assert_allclose(quat, [np.sqrt(0.5), 0, 0, np.sqrt(0.5)], atol=1e-12)
    assert MjSpec.resolve_orientation(True, None, body.alt) == quat
    with pytest.raises(ValueError, match="3 axes"):
        MjSpec.resolve_orientation(True, "xy", body.alt)
    with pytest.raises(TypeError, match="MjsOrientation"):
        MjSpec.resolve_orientation(True, "xyz", body)


# --------------------------------------------------------------- defaults

def test_defaults():
    spec = MjSpec()
    main = spec.default
    assert main.name == "main" and spec.find_default("main") is main
    flat = spec.add_default("flat", main)
    assert spec.find_default("flat") is flat and spec.find_default("none") is None
    child = spec.add_default("child")            # under main
    assert child.name == "child"
    with pytest.raises(ValueError, match="exists already"):
        spec.add_default("flat", main)
    with pytest.raises(ValueError, match="another spec"):
        spec.add_default("other", MjSpec().default)
    with pytest.raises(TypeError, match="MjsDefault"):
        spec.add_default("geomy", spec.worldbody)


def test_delete_a_default_ends_it_and_its_children():
    spec = MjSpec.from_string(
        '<mujoco><default><default class="a"><geom size="3"/><default class="b">'
        '<geom size="4"/></default></default></default><worldbody><body name="x">'
        '<geom name="g" class="b"/></body></worldbody></mujoco>')
    a, b, main = spec.find_default("a"), spec.find_default("b"), spec.default
    spec.delete(a)
    assert spec.find_default("a") is None and spec.find_default("b") is None
    for dead, name in ((a, "a"), (b, "b")):
        assert_ended(dead, name)
    assert main.name == "main" and spec.geom("g").name == "g"
    with pytest.raises(ValueError, match="global default"):
        spec.delete(main)
    with pytest.raises(ValueError, match="default is not in this model"):
        spec.delete(a)


# ------------------------------------------------- edits that free elements

STATIC = """
<mujoco>
  <worldbody>
    <body name="moving">
      <joint/>
      <geom name="moving" size=".1"/>
      <body name="static" pos="1 0 0">
        <geom name="static" size=".1"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_fuse_static_ends_the_fused_bodies(mujoco):
    spec = MjSpec.from_string(STATIC)
    static, geom = spec.body("static"), spec.geom("static")
    assert spec.fuse_static() == 1
    assert spec.body("static") is None
    assert_ended(static, "static")
    assert geom.name == "static"                        # moved into the parent, alive
    model = spec.compile()
    assert model.nbody == 2
    np.testing.assert_allclose(model.geom("static").pos, [1, 0, 0])
    assert spec.fuse_static() == 0
    official = mujoco.MjSpec.from_string(STATIC)
    official.fuse_static()
    assert spec.to_xml() == official.to_xml()


def test_compile_with_fusestatic_changes_the_spec_as_official(mujoco):
    xml = STATIC.replace("<mujoco>", '<mujoco><compiler fusestatic="true"/>')
    spec, official = MjSpec.from_string(xml), mujoco.MjSpec.from_string(xml)
    static = spec.body("static")
    assert spec.compile().nbody == official.compile().nbody == 2
    assert len(spec.bodies) == len(official.bodies) == 2
    assert_ended(static, "static")
    assert spec.to_xml() == official.to_xml()


def test_discard_visual(mujoco):
    xml = ('<mujoco><asset><material name="mat"/></asset><worldbody><body name="body">'
           '<joint/><geom name="collision" size=".1" material="mat"/>'
           '<geom name="visual" size=".2" contype="0" conaffinity="0"/></body>'
           '</worldbody></mujoco>')
    spec = MjSpec.from_string(xml)
    visual, material = spec.geom("visual"), spec.material("mat")
    assert spec.discard_visual() == 2
    assert_ended(visual, "visual")
    assert_ended(material, "mat")
    assert spec.geom("collision").material == ""
    assert spec.compile().ngeom == 1 and spec.discard_visual() == 0
    official = mujoco.MjSpec.from_string(xml)
    official.discard_visual()
    assert spec.to_xml() == official.to_xml()
    refused = MjSpec.from_string(xml.replace("<mujoco>",
                                             '<mujoco><compiler inertiafromgeom="true"/>'))
    with pytest.raises(ValueError, match="inertiafromgeom"):
        refused.discard_visual()
    assert refused.geom("visual").name == "visual"


def test_dedup_assets_ends_the_merged_ones():
    spec = MjSpec.from_string(
        '<mujoco><asset><mesh name="mesh1" vertex="0 0 0  1 0 0  0 1 0  0 0 1"/>'
        '<mesh name="mesh2" vertex="0 0 0  1 0 0  0 1 0  0 0 1"/></asset><worldbody>'
        '<geom type="mesh" mesh="mesh1"/><geom name="g2" type="mesh" mesh="mesh2"/>'
        '</worldbody></mujoco>')
    mesh1, mesh2 = spec.mesh("mesh1"), spec.mesh("mesh2")
    assert spec.dedup_assets() == 1
    assert_ended(mesh2, "mesh2")
    assert mesh1.name == "mesh1" and spec.geom("g2").meshname == "mesh1"
    assert spec.compile().nmesh == 1 and spec.dedup_assets() == 0


def test_adopt_inertial():
    spec = MjSpec.from_string(TREE)
    arm = spec.body("arm")
    mass = spec.compile().body("arm").mass[0]
    spec.adopt_inertial(arm)
    assert arm.explicitinertial and arm.mass == pytest.approx(mass)
    spec.geom("arm_geom").size = [0.3, 0, 0]        # the geom no longer decides the mass
    assert spec.compile().body("arm").mass[0] == pytest.approx(mass)
    with pytest.raises(TypeError, match="MjsBody"):
        spec.adopt_inertial(spec.geom("arm_geom"))
    with pytest.raises(ValueError, match="another spec"):
        spec.adopt_inertial(MjSpec.from_string(TREE).body("arm"))


def test_copy_back():
    spec = MjSpec.from_string(TREE)
    model = spec.compile()
    model.geom("hand_geom").size[0] = 0.07
    spec.copy_back(model)
    assert spec.geom("hand_geom").size[0] == pytest.approx(0.07)
    assert spec.compile().geom("hand_geom").size[0] == pytest.approx(0.07)
    spec.delete(spec.body("hand"))
    with pytest.raises(ValueError, match="incompatible"):
        spec.copy_back(model)
    with pytest.raises(ValueError, match="not been compiled"):
        MjSpec.from_string(TREE).copy_back(model)
    with pytest.raises(TypeError, match="MjModel"):
        spec.copy_back("model")


# ----------------------------------------------------------------- encode

def test_encode(tmp_path):
    spec = MjSpec.from_string(TREE)
    with pytest.raises(mjcffi.FatalError, match="compiled"):
        spec.encode(str(tmp_path / "early.xml"))
    model = spec.compile()
    assert spec.encode(str(tmp_path / "tree.xml")) > 0
    assert MjSpec.from_file(str(tmp_path / "tree.xml")).compile().nbody == model.nbody
    assert spec.encode(str(tmp_path / "tree.mjb"), model) == \
        os.path.getsize(tmp_path / "tree.mjb")
    assert mjcffi.MjModel.from_binary_path(str(tmp_path / "tree.mjb")).nbody == model.nbody
    with pytest.raises(mjcffi.FatalError, match="model is required"):
        spec.encode(str(tmp_path / "tree2.mjb"))
    with pytest.raises(mjcffi.FatalError, match="no encoder"):
        spec.encode(str(tmp_path / "tree.unknown"), model)
    with pytest.raises(TypeError, match="MjModel"):
        spec.encode(str(tmp_path / "x.xml"), "model")


# ----------------------------------------------------------------- attach

def test_attach_carries_and_renames_assets(mujoco):
    for module in (mjcffi, mujoco):
        parent = module.MjSpec()
        frame = parent.worldbody.add_frame(name="mount")
        child = module.MjSpec.from_string(MESHED.replace('file="box.obj"',
                                                         'file="meshes/box.obj"'),
                                          assets={"meshes/box.obj": CUBE_OBJ})
        attached = parent.attach(child, prefix="left_", suffix="_1", frame="mount")
        assert isinstance(attached, module.MjsFrame)
        assert parent.assets == {"meshes/left_box_1.obj": CUBE_OBJ}, module.__name__
        assert [m.file for m in parent.meshes] == ["meshes/left_box_1.obj"]
        assert child.parent is parent and frame.name == "mount"
        assert parent.compile().nmesh == 1


def test_attach_refused_asset_leaves_both_specs_as_they_were():
    parent = MjSpec()
    frame = parent.worldbody.add_frame()
    parent.assets = {"c_shared.obj": b"parent"}
    parent.override_assets = False
    child = MjSpec()
    child.assets = {"shared.obj": b"child"}
    child.worldbody.add_body(name="part").add_geom(size=[0.1, 0, 0])
    before = parent.to_xml()
    with pytest.raises(ValueError, match=r"Asset shared\.obj already exists in parent spec"):
        parent.attach(child, prefix="c_", frame=frame)
    assert parent.assets == {"c_shared.obj": b"parent"} and child.parent is None
    assert parent.to_xml() == before
    parent.override_assets = True
    parent.attach(child, prefix="c_", frame=frame)
    assert parent.assets == {"c_shared.obj": b"child"}


def test_attach_errors_are_the_officials():
    spec = MjSpec()
    spec.worldbody.add_frame(name="f")
    spec.worldbody.add_site(name="s")
    cases = [({}, "One of frame or site must be specified."),
             ({"frame": "f", "site": "s"}, "Only one of frame or site can be specified."),
             ({"frame": "nope"}, "Frame not found."), ({"site": "nope"}, "Site not found."),
             ({"frame": MjSpec().worldbody.add_frame()},
              "Frame spec does not match parent spec.")]
    for where, message in cases:
        with pytest.raises(ValueError) as error:
            spec.attach(MjSpec(), **where)
        assert str(error.value) == message
    with pytest.raises(TypeError, match="MjsFrame"):
        spec.attach(MjSpec(), frame=spec.worldbody)


def test_attach_default_prefix_and_empty_prefix_warning(mujoco):
    for module in (mjcffi, mujoco):
        parent, child = module.MjSpec(), module.MjSpec()
        child.worldbody.add_body(name="b").add_geom(size=[1, 0, 0])
        parent.attach(child, frame=parent.worldbody.add_frame())
        assert [b.name for b in parent.bodies] == ["world", "/b"], module.__name__
    parent, child = MjSpec(), MjSpec()
    child.worldbody.add_body(name="b").add_geom(size=[1, 0, 0])
    parent.attach(child, frame=parent.worldbody.add_frame(), prefix="")
    with pytest.warns(UserWarning, match="may prevent the model from being saved"):
        parent.compile()


def test_delete_in_a_spec_attached_as_a_copy_is_allowed(mujoco):
    for module in (mjcffi, mujoco):
        parent, child = module.MjSpec(), module.MjSpec()
        parent.copy_during_attach = True
        geom = child.worldbody.add_body(name="b").add_geom(name="g", size=[1, 0, 0])
        parent.attach(child, frame=parent.worldbody.add_frame(), prefix="x")
        child.delete(geom)
        assert [g.name for g in child.geoms] == [], module.__name__
        assert [g.name for g in parent.geoms] == ["xg"]


def test_delete_in_an_attached_spec_is_refused():
    parent, child = MjSpec(), MjSpec()
    geom = child.worldbody.add_body(name="b").add_geom(name="g")
    parent.attach(child, frame=parent.worldbody.add_frame(), prefix="c_")
    with pytest.raises(ValueError, match="Cannot delete element from an attached mjSpec"):
        child.delete(geom)
    with pytest.raises(ValueError, match="world body cannot be deleted"):
        child.delete(child.worldbody)
    with pytest.raises(ValueError, match="Cannot merge the assets of an attached mjSpec"):
        child.dedup_assets()
    # the parent may delete it; the child, which still lists it, keeps it alive
    parent.delete(parent.body("c_b"))
    assert parent.geom("c_g") is None and [g.name for g in parent.geoms] == []
    assert geom.name == "c_g" and [g.name for g in child.geoms] == ["c_g"]


# ---------------------------------------------------------- predicting frees

def test_the_dry_run_predicts_what_delete_frees():
    from mjcffi.spec import lifetime
    spec = MjSpec.from_string(TREE)
    held = [e for kind in ("bodies", "geoms", "joints", "sites", "actuators", "sensors",
                           "lights", "cameras") for e in getattr(spec, kind)] + [spec.default]
    arm = spec.body("arm")._ptr.element

    def delete(c_spec, counterpart):
        assert mjcffi.lib.mjs_delete(c_spec, counterpart(arm)) == 0

    predicted = lifetime._freed_by(spec, delete, held)
    assert sorted(w.name for w in predicted) == [
        "arm", "arm_geom", "hand", "hand_geom", "m_shoulder", "m_wrist", "s_wrist",
        "shoulder", "tip", "wrist"]
    assert len(spec.bodies) == 4                        # the spec itself is untouched
    spec.delete(spec.body("arm"))
    assert {id(w) for w in predicted} == {id(w) for w in held if lifetime.is_deleted(w)}


def test_freeing_an_element_whose_views_are_held_is_refused():
    spec = MjSpec.from_string(TREE)
    hand_geom, motor = spec.geom("hand_geom"), spec.actuator("m_wrist")
    size, gear = hand_geom.size, motor.gear
    kept = spec.geom("torso_geom").size                  # held, but not freed
    with pytest.raises(ValueError, match=r"cannot delete MjsBody 'arm'.*hand_geom'\.size"):
        spec.delete(spec.body("arm"))
    assert len(spec.bodies) == 4 and size[0] == pytest.approx(0.04)
    del size
    # the motor is freed with the wrist joint that it drives: the dry run knows it
    with pytest.raises(ValueError, match=r"m_wrist'\.gear"):
        spec.delete(spec.body("hand"))
    del gear
    spec.delete(spec.body("arm"))
    assert [b.name for b in spec.bodies] == ["world", "torso"]
    assert kept[0] == pytest.approx(0.2)
    assert_ended(hand_geom, "hand_geom")
    assert_ended(motor, "m_wrist")


def test_fusing_a_body_whose_views_are_held_is_refused():
    spec = MjSpec.from_string(STATIC)
    static = spec.body("static")
    pos = static.pos
    with pytest.raises(ValueError, match="cannot fuse_static"):
        spec.fuse_static()
    model = spec.compile()
    data = mjcffi.MjData(model)
    spec.compiler.fusestatic = True
    with pytest.raises(ValueError, match="cannot recompile"):
        spec.recompile(model, data)
    with pytest.raises(ValueError, match="cannot compile"):
        spec.compile()
    assert spec.body("static") is static and pos[0] == 1
    del pos
    assert spec.compile().nbody == 2 and spec.body("static") is None


def test_find_all_refuses_bad_types():
    spec = MjSpec.from_string(TREE)
    with pytest.raises(TypeError, match="mjtObj or a name"):
        spec.find_all(2.5)
    with pytest.raises(ValueError, match="no list"):
        spec.find_all(mjtObj.mjOBJ_UNKNOWN)


def test_recompile_of_a_spec_never_compiled_compiles_it_first():
    # MuJoCo's mj_recompile reads what compiling left: without it, it crashes
    code = ("import mjcffi\n"
            f"TREE = {TREE!r}\n"
            "spec = mjcffi.MjSpec.from_string(TREE)\n"
            "model = mjcffi.MjSpec.from_string(TREE).compile()\n"
            "data = mjcffi.MjData(model)\n"
            "data.qpos[7] = 0.25\n"
            "new_model, new_data = spec.recompile(model, data)\n"
            "print(new_model.nbody, new_data.qpos[7])\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["4", "0.25"]


def test_recompile_refuses_data_of_another_model():
    spec = MjSpec.from_string(TREE)
    model = spec.compile()
    with pytest.raises(ValueError, match="other sizes"):
        spec.recompile(model, mjcffi.MjData(MjSpec().compile()))
    with pytest.raises(TypeError, match="MjModel"):
        spec.recompile(None, mjcffi.MjData(model))


def test_delete_refuses_the_world_and_non_elements():
    spec = MjSpec.from_string(TREE)
    with pytest.raises(ValueError, match="world body cannot be deleted"):
        spec.delete(spec.worldbody)
    for thing in (spec, spec.compiler, spec.body("arm").alt, None):
        with pytest.raises(TypeError, match="spec element"):
            spec.delete(thing)
    assert len(spec.bodies) == 4


def test_delete_a_plugin_which_spec_copies_leave_out():
    # mj_copySpec drops the plugins: the dry run cannot map them and counts them freed
    spec = MjSpec.from_string(
        '<mujoco><extension><plugin plugin="mujoco.pid"><instance name="pid1">'
        '<config key="kp" value="4.0"/></instance></plugin></extension><worldbody>'
        '<body><geom size="1"/></body></worldbody></mujoco>')
    plugin, geom = spec.plugins[0], spec.geoms[0]
    spec.delete(plugin)
    assert_ended(plugin, "pid1")
    assert geom.size[0] == 1 and not mjcffi.spec.lifetime.is_deleted(geom)
    assert spec.compile().nplugin == 0


def test_freeing_edits_of_an_attached_spec_are_refused_without_a_crash():
    # a copy of a spec attached by reference crashes when edited, and one whose body
    # was attached cannot be copied: the dry run must not use either
    code = """if True:
        import mjcffi
        xml = ('<mujoco><asset><material name="m"/></asset><worldbody><body name="b">'
               '<geom name="g" size="1" material="m"/><body name="s"><geom size="1"/>'
               '</body></body><body name="o"><geom name="og" size="1"/></body>'
               '</worldbody></mujoco>')
        for how in ("whole", "body"):
            parent, child = mjcffi.MjSpec(), mjcffi.MjSpec.from_string(xml)
            geom, other = child.geom("g"), child.geom("og")
            if how == "whole":
                parent.attach(child, frame=parent.worldbody.add_frame(), prefix="x")
            else:
                parent.worldbody.add_frame().attach_body(child.body("b"), "x", "")
            for edit in ("fuse_static", "discard_visual", "dedup_assets", "delete"):
                try:
                    child.delete(other) if edit == "delete" else getattr(child, edit)()
                except ValueError as error:
                    assert "attached" in str(error), error
                else:
                    raise AssertionError(edit + " was not refused")
            print(how, geom.name, parent.compile().nbody)
    """
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split("\n")[:2] == ["whole xg 4", "body xg 3"]
