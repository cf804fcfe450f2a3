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

def test_delete_a_subtree_ends_its_wrappers():
    spec = MjSpec.from_string(TREE)
    arm, hand, tip = spec.body("arm"), spec.geom("hand_geom"), spec.site("tip")
    torso = spec.body("torso")
    spec.delete(arm)
    for dead in (arm, hand, tip):
        with pytest.raises(RuntimeError, match="deleted"):
            dead.name
        with pytest.raises(RuntimeError, match="deleted"):
            dead.pos = [1, 2, 3]
    assert torso.name == "torso"                         # the rest lives on
    assert [b.name for b in spec.bodies] == ["world", "torso"]


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
            "try:\n    g.size[0] = 1\nexcept RuntimeError:\n    print('raised')\n")
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
