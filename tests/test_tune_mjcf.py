"""mjcffi.tune._mjcf: the tuned MJCF reloads to the source model with only the
option changes, from its own folder or another, by either route; the text route
leaves every line but the <option>'s (and an anchoring <compiler>) as it was."""

import difflib
import os
import re
import struct
import xml.etree.ElementTree as ET
import zlib

import numpy as np
import pytest

import mjcffi
import mjcffi.scenes as scenes
from mjcffi.tune import _mjcf
from mjcffi.tune._mjcf import tuned_mjcf, tuned_xml, write_tuned_xml

from .conftest import gymnasium_assets

GYM = {path.stem: path for path in gymnasium_assets()}

CHANGES = dict(options={"integrator": 3, "timestep": 0.0015, "solver": 1, "iterations": 17,
                        "tolerance": 1e-7, "ls_iterations": 9, "ls_tolerance": 0.02,
                        "noslip_iterations": 2, "noslip_tolerance": 1e-5, "cone": 1,
                        "jacobian": 1},
               disable_set=int(mjcffi.mjtDisableBit.mjDSBL_WARMSTART),
               enable_set=int(mjcffi.mjtEnableBit.mjENBL_ENERGY))

# A model MuJoCo's writer cannot give back bit for bit (fromto, degrees).
FROMTO = """<mujoco>
  <!-- kept comment -->
  <compiler angle="degree"/>
  <option timestep="0.004"><flag gravity="disable"/></option>
  <worldbody>
    <body pos="0 0 1">
      <joint name="hinge" axis="0 1 0" range="-30 70"/>
      <geom type="capsule" fromto="0 0 0 0.3 0.1 -0.7" size="0.05"/>
    </body>
  </worldbody>
  <actuator><motor joint="hinge" gear="3"/></actuator>
</mujoco>
"""


def _opt_fields(opt):
    return {name: np.array(getattr(opt, name)) for name in dir(opt)
            if not name.startswith("_") and not callable(getattr(opt, name))}


def _applied(source, changes):
    """The source model with the changes made in memory."""
    model = mjcffi.MjModel.from_xml_path(str(source))
    for name, value in changes.get("options", {}).items():
        setattr(model.opt, name, value)
    model.opt.disableflags = ((model.opt.disableflags | changes.get("disable_set", 0))
                              & ~changes.get("disable_clear", 0))
    model.opt.enableflags = ((model.opt.enableflags | changes.get("enable_set", 0))
                             & ~changes.get("enable_clear", 0))
    return model


def _trajectory(model, steps=300):
    data = mjcffi.MjData(model)
    controls = np.random.default_rng(7).uniform(-1, 1, (steps, model.nu))
    states = []
    for control in controls:
        data.ctrl[:] = control
        mjcffi.mj_step(model, data)
        states.append(np.concatenate([data.qpos, data.qvel, data.act]))
    return np.array(states)


def _assert_same_model(source, out, changes):
    expected, got = _applied(source, changes), mjcffi.MjModel.from_xml_path(str(out))
    for size in ("nq", "nv", "nu", "na", "nbody", "ngeom", "njnt", "nmesh", "ntex", "nhfield",
                 "nsensor", "nkey", "neq"):
        assert getattr(got, size) == getattr(expected, size), size
    before = _opt_fields(mjcffi.MjModel.from_xml_path(str(source)).opt)
    after = _opt_fields(got.opt)
    changed = set(changes.get("options", {})) | {"disableflags", "enableflags"}
    for name in before:
        if name not in changed:
            assert np.array_equal(after[name], before[name]), f"opt.{name} changed"
    for name, value in changes.get("options", {}).items():
        assert getattr(got.opt, name) == value, name
    assert got.opt.disableflags == expected.opt.disableflags
    assert got.opt.enableflags == expected.opt.enableflags
    assert np.array_equal(_trajectory(got), _trajectory(expected))


def _write(folder, name, text):
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(text)
    return path


def _changed_lines(before, after):
    """The lines removed from or added to `before` to make `after`."""
    return [line for line in difflib.unified_diff(before.splitlines(), after.splitlines(),
                                                  lineterm="", n=0)
            if line[:1] in "+-" and not line.startswith(("+++", "---"))]


def _assert_only_option_lines_changed(before, after):
    changed = _changed_lines(before, after)
    assert changed, "the changes are in the text"
    for line in changed:
        assert re.search(r"<(/?option|flag)\b", line), line


# ------------------------------------------------------------ real models

GYM_NAMES = ["hopper", "ant", "humanoid", "half_cheetah", "walker2d"]


@pytest.mark.parametrize("name", GYM_NAMES)
def test_gymnasium_model_reloads_bit_identical_from_another_folder(name, tmp_path):
    out = write_tuned_xml(GYM[name], tmp_path / f"{name}_tuned.xml", **CHANGES)
    _assert_same_model(GYM[name], out, CHANGES)
    with open(out, encoding="utf-8") as file:
        # No file names a mesh or texture: no <compiler> anchoring either.
        _assert_only_option_lines_changed(GYM[name].read_text(), file.read())


@pytest.mark.parametrize("name", GYM_NAMES)
def test_gymnasium_model_takes_the_text_route_changing_only_its_option(name, tmp_path):
    # The source's own folder: no anchoring, so only <option>/<flag> lines differ.
    result = tuned_mjcf(GYM[name], **CHANGES)
    assert (result.route, result.refusal) == ("text", "")
    source = GYM[name].read_text()
    _assert_only_option_lines_changed(source, result.text)
    option = ET.fromstring(result.text).find("option")
    assert option.get("integrator") == "implicitfast" and option.get("iterations") == "17"
    assert option.find("flag").attrib == {"warmstart": "disable", "energy": "enable"}
    _assert_same_model(GYM[name], _write(tmp_path, "t.xml", result.text), CHANGES)


def test_spec_route_alone_would_not_give_gymnasium_models_back(tmp_path):
    # Why the text route goes first: MuJoCo's writer turns fromto/degrees into
    # six-digit pos/quat/size.
    changes = _mjcf._Changes({"timestep": 0.001}, 0, 0, 0, 0)
    source = str(GYM["hopper"])
    text, refusal = _mjcf._attempt(
        lambda: _mjcf._via_spec(source, changes, os.path.dirname(source), True),
        str(tmp_path), _mjcf._expected_model(source, changes))
    assert "differs in" in refusal and "body_mass" in refusal


def test_half_cheetah_keeps_its_header_comment_and_settotalmass(tmp_path):
    source = GYM["half_cheetah"].read_text()
    header = source[:source.index("<mujoco")]
    assert header.count("\n") > 30                 # the 34-line "Cheetah Model" comment
    for out in (None, tmp_path / "t.xml"):
        text = tuned_xml(GYM["half_cheetah"], {"timestep": 0.005}, out_path=out)
        assert text.startswith(header)
        assert 'settotalmass="14"' in text and 'timestep="0.005"' in text


@pytest.mark.parametrize("name", ["DEFAULT", "PENDULUM", *scenes.HARD_CASES])
@pytest.mark.parametrize("elsewhere", [False, True])
def test_scenes_reload_bit_identical(name, elsewhere, tmp_path):
    text = scenes.HARD_CASES.get(name) or getattr(scenes, name)
    source = _write(tmp_path / "src", "scene.xml", text)
    out = (tmp_path / "other" if elsewhere else tmp_path / "src") / "tuned.xml"
    out.parent.mkdir(exist_ok=True)
    write_tuned_xml(source, out, **CHANGES)
    _assert_same_model(source, out, CHANGES)
    assert tuned_mjcf(source, out_path=out, **CHANGES).route == "text"
    _assert_only_option_lines_changed(text, out.read_text())


def test_a_scene_without_option_gets_one_before_the_end(tmp_path):
    source = _write(tmp_path, "pendulum.xml", scenes.PENDULUM)
    result = tuned_mjcf(source, **CHANGES)
    assert result.route == "text"
    lines, before = result.text.splitlines(), scenes.PENDULUM.splitlines()
    end = before.index("</mujoco>")
    # The new <option> block sits, indented like its siblings, just before </mujoco>.
    assert lines[:end] == before[:end] and lines[-len(before) + end:] == before[end:]
    block = lines[end:len(lines) - len(before) + end]
    assert block[0].startswith('  <option integrator="implicitfast" timestep="0.0015"')
    assert block[1:] == ['    <flag warmstart="disable" energy="enable"/>', "  </option>"]


def test_a_value_mujoco_prints_short_is_kept_exactly(tmp_path):
    # MuJoCo's writer prints six significant digits: 0.00123456789 would come back
    # 0.00123457 by the spec route; the text route writes repr(value).
    source = _write(tmp_path, "pendulum.xml", scenes.PENDULUM)
    changes = {"options": {"timestep": 0.00123456789}}
    result = tuned_mjcf(source, **changes)
    assert result.route == "text" and 'timestep="0.00123456789"' in result.text
    out = _write(tmp_path / "o", "t.xml", result.text)
    _assert_same_model(source, out, changes)


def test_a_source_the_text_route_cannot_read_takes_the_spec_route(tmp_path):
    source = _write(tmp_path, "empty.xml", "<mujoco/>")
    changes = {"options": {"timestep": 0.004, "integrator": 1}}
    result = tuned_mjcf(source, **changes)
    assert result.route == "spec" and "text route: ValueError" in result.refusal
    assert "<mujoco/>" in result.refusal
    _assert_same_model(source, _write(tmp_path, "t.xml", result.text), changes)


# ------------------------------------------------------------ text route

def _without_options(root):
    for element in list(root):
        if element.tag == "option":
            root.remove(element)
    return [(e.tag, sorted(e.attrib.items())) for e in root.iter()]


def test_text_route_changes_nothing_but_the_option(tmp_path):
    source = _write(tmp_path, "arm.xml", FROMTO)
    result = tuned_mjcf(source, **CHANGES)
    assert result.route == "text"
    # The inline <option> and its <flag> are edited where they are; every other line stays.
    before, after = FROMTO.splitlines(), result.text.splitlines()
    assert [a for a in after if "<option" not in a] == [b for b in before if "<option" not in b]
    assert re.fullmatch(r'  <option timestep="0\.0015" integrator="implicitfast" .*>'
                        r'<flag gravity="disable" warmstart="disable" energy="enable"/></option>',
                        [a for a in after if "<option" in a][0])
    new, old = ET.fromstring(result.text), ET.fromstring(FROMTO)
    option = new.find("option")
    assert _without_options(new) == _without_options(old)
    assert option.get("integrator") == "implicitfast" and option.get("cone") == "elliptic"
    assert option.get("jacobian") == "sparse" and option.get("solver") == "CG"
    assert option.find("flag").attrib == {"gravity": "disable", "warmstart": "disable",
                                          "energy": "enable"}
    _assert_same_model(source, _write(tmp_path, "t.xml", result.text), CHANGES)


@pytest.mark.parametrize("kind, names", [("disable", _mjcf.DISABLE_NAMES),
                                         ("enable", _mjcf.ENABLE_NAMES)])
def test_every_flag_name_sets_its_bit(kind, names, tmp_path):
    source = _write(tmp_path, "arm.xml", FROMTO)
    for bit, name in enumerate(names):
        if name == "ipc":                   # MuJoCo allows it with the discrete integrator only
            continue
        for direction in ("set", "clear"):
            changes = {f"{kind}_{direction}": 1 << bit, "options": {}}
            result = tuned_mjcf(source, **changes)
            assert result.route == "text", name
            _assert_same_model(source, _write(tmp_path, "t.xml", result.text), changes)


@pytest.mark.parametrize("option", sorted(_mjcf.ENUM_WORDS))
def test_every_enum_word_compiles_to_its_value(option, tmp_path):
    source = _write(tmp_path, "arm.xml", FROMTO)
    for value in range(len(_mjcf.ENUM_WORDS[option])):
        result = tuned_mjcf(source, {option: value})
        model = mjcffi.MjModel.from_xml_path(str(_write(tmp_path, "t.xml", result.text)))
        assert getattr(model.opt, option) == value


def test_option_in_an_include_is_overridden_by_a_trailing_option(tmp_path):
    _write(tmp_path / "src", "opts.xml",
           '<mujoco><option timestep="0.003" iterations="4"/></mujoco>')
    source = _write(tmp_path / "src", "main.xml",
                    FROMTO.replace("<worldbody>", '<include file="opts.xml"/>\n  <worldbody>'))
    changes = {"options": {"timestep": 0.001}}
    for out in (tmp_path / "src" / "t.xml", tmp_path / "elsewhere" / "t.xml"):
        out.parent.mkdir(exist_ok=True)
        write_tuned_xml(source, out, **changes)
        root = ET.parse(out).getroot()
        assert root[-1].tag == "option" and root[-1].attrib == {"timestep": "0.001"}
        assert [element.get("timestep") for element in root.iter("option")] == ["0.004", "0.001"]
        model = mjcffi.MjModel.from_xml_path(str(out))
        assert (model.opt.timestep, model.opt.iterations) == (0.001, 4)
        _assert_same_model(source, out, changes)


# ------------------------------------------------------------ asset paths

def _png(width, height, value):
    """A small grey RGB PNG, written here so the test needs no image library."""
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff))
    rows = b"".join(b"\0" + bytes([value, value // 2, 255 - value]) * width
                    for _ in range(height))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


_TETRA = "v 0 0 0\nv 0.2 0 0\nv 0 0.2 0\nv 0 0 0.2\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"

ASSETS_MODEL = """<mujoco>
  <compiler meshdir="{meshdir}" {texturedir}/>
  <asset>
    <mesh name="tetra" file="tetra.obj"/>
    <texture name="grid" type="2d" file="{texfile}"/>
    <material name="mat" texture="grid"/>
    <hfield name="ground" file="ground.png" size="1 1 0.1 0.05"/>
  </asset>
  <include file="parts/body.xml"/>
</mujoco>
"""

BODY_PART = """<mujoco><worldbody>
  <geom type="hfield" hfield="ground"/>
  <body pos="0 0 0.5"><freejoint/>
    <geom type="mesh" mesh="tetra" material="mat"/>
    <geom type="capsule" fromto="0 0 0 0.1 0.1 0.1" size="0.02"/>
  </body>
</worldbody></mujoco>
"""


@pytest.mark.parametrize("texturedir", [None, "textures"])
def test_asset_paths_resolve_from_another_folder(texturedir, tmp_path):
    src = tmp_path / "model"
    (src / "meshes").mkdir(parents=True)
    (src / "meshes" / "tetra.obj").write_text(_TETRA)
    (src / "meshes" / "ground.png").write_bytes(_png(8, 8, 90))
    tex_folder = src / texturedir if texturedir else src
    tex_folder.mkdir(exist_ok=True)
    (tex_folder / "grid.png").write_bytes(_png(4, 4, 200))
    _write(src / "parts", "body.xml", BODY_PART)
    source = _write(src, "scene.xml", ASSETS_MODEL.format(
        meshdir="meshes", texfile="grid.png",
        texturedir=f'texturedir="{texturedir}"' if texturedir else ""))
    changes = {"options": {"integrator": 2, "timestep": 0.001}}
    for out in (tmp_path / "t.xml", tmp_path / "deep" / "er" / "t.xml", src / "t.xml"):
        out.parent.mkdir(parents=True, exist_ok=True)
        write_tuned_xml(source, out, **changes)
        _assert_same_model(source, out, changes)
        # Loaded with the source folder gone from view: the current folder is elsewhere.
        model = mjcffi.MjModel.from_xml_path(str(out))
        assert model.nmesh == 1 and model.ntex == 1 and model.nhfield == 1
    assert "meshes" in (src / "t.xml").read_text() and str(src) not in (src / "t.xml").read_text()
    # Moved: the <compiler> (and, with no texturedir, a new one naming the source
    # folder) and the <include> are anchored; no other line changes.
    source_text = source.read_text()
    changed = _changed_lines(source_text, (tmp_path / "t.xml").read_text())
    assert sorted(line[:9] for line in changed) == sorted(
        ["+  <compi"] * (1 if texturedir else 2) + ["-  <compi", "+  <inclu", "-  <inclu",
                                                    "+  <optio"])
    assert f'<include file="{src}{os.sep}parts{os.sep}body.xml"/>' in (tmp_path / "t.xml").read_text()


SPEC_ASSETS_MODEL = """<mujoco>
  <compiler meshdir="meshes" texturedir="textures"/>
  <asset>
    <texture name="grid" type="2d" file="grid.png"/>
    <material name="mat" texture="grid"/>
    <hfield name="ground" file="ground.png" size="1 1 0.1 0.05"/>
  </asset>
  <worldbody>
    <geom type="hfield" hfield="ground"/>
    <body pos="0 0 0.5"><freejoint/><geom type="box" size=".1 .2 .3" material="mat"/></body>
  </worldbody>
</mujoco>
"""


@pytest.mark.parametrize("route", ["text", "spec"])
def test_asset_folders_are_anchored_only_when_moved(route, tmp_path, monkeypatch):
    if route == "spec":         # the fallback, taken here by refusing the text route
        def refuse(*args):
            raise ValueError("refused for the test")
        monkeypatch.setattr(_mjcf, "_via_text", refuse)
    src = tmp_path / "model"
    for folder, name, value in (("meshes", "ground.png", 90), ("textures", "grid.png", 200)):
        (src / folder).mkdir(parents=True)
        (src / folder / name).write_bytes(_png(8, 8, value))
    source = _write(src, "scene.xml", SPEC_ASSETS_MODEL)
    changes = {"options": {"integrator": 2}}
    for out, anchored in ((tmp_path / "t.xml", True), (src / "t.xml", False)):
        result = tuned_mjcf(source, out_path=out, **changes)
        assert result.route == route, result.refusal
        assert ("refused for the test" in result.refusal) == (route == "spec")
        assert (f'meshdir="{src}{os.sep}meshes{os.sep}"' in result.text) == anchored
        assert (f'texturedir="{src}{os.sep}textures{os.sep}"' in result.text) == anchored
        out.write_text(result.text)
        _assert_same_model(source, out, changes)


def test_relative_folder_inside_an_include_cannot_move_and_says_so(tmp_path):
    # The included <compiler meshdir> is relative and the text route edits only the
    # main file; the spec route's writer is not faithful for meshes: neither passes.
    src = tmp_path / "model"
    (src / "meshes").mkdir(parents=True)
    (src / "meshes" / "tetra.obj").write_text(_TETRA)
    _write(src, "dirs.xml", '<mujoco><compiler meshdir="meshes"/></mujoco>')
    source = _write(src, "scene.xml", """<mujoco><include file="dirs.xml"/>
      <asset><mesh name="tetra" file="tetra.obj"/></asset>
      <worldbody><body><freejoint/><geom type="mesh" mesh="tetra"/></body></worldbody>
    </mujoco>""")
    assert tuned_mjcf(source, {"timestep": 0.001}).route == "text"   # same folder: fine
    with pytest.raises(ValueError, match="text route: .*does not load.*; spec route: "):
        tuned_xml(source, {"timestep": 0.001}, out_path=tmp_path / "t.xml")


# ------------------------------------------------------------ bad input

def test_missing_source_names_it(tmp_path):
    missing = tmp_path / "nope.xml"
    with pytest.raises(FileNotFoundError, match="nope.xml"):
        tuned_xml(missing, {"timestep": 0.01})


def test_missing_output_folder_names_it(tmp_path):
    source = _write(tmp_path, "p.xml", scenes.PENDULUM)
    with pytest.raises(FileNotFoundError, match="absent"):
        tuned_xml(source, {}, out_path=tmp_path / "absent" / "t.xml")


def test_unknown_option_lists_the_allowed(tmp_path):
    source = _write(tmp_path, "p.xml", scenes.PENDULUM)
    with pytest.raises(ValueError, match="'gravity'.*integrator.*noslip_tolerance"):
        tuned_xml(source, {"gravity": 0.0})


@pytest.mark.parametrize("options, error", [
    ({"timestep": "0.01"}, TypeError), ({"iterations": 2.5}, TypeError),
    ({"integrator": True}, TypeError), ({"integrator": "RK4"}, TypeError),
    ({"integrator": 9}, ValueError), ({"cone": -1}, ValueError),
    ({"timestep": 0.0}, ValueError), ({"tolerance": float("nan")}, ValueError),
    ({"iterations": -3}, ValueError), ([("timestep", 0.1)], TypeError),
])
def test_bad_option_values(options, error, tmp_path):
    source = _write(tmp_path, "p.xml", scenes.PENDULUM)
    with pytest.raises(error):
        tuned_xml(source, options)


@pytest.mark.parametrize("flags, error", [
    ({"disable_set": 16, "disable_clear": 16}, ValueError),
    ({"disable_set": 1 << 40}, ValueError), ({"enable_clear": -1}, ValueError),
    ({"enable_set": 2.0}, TypeError),
])
def test_bad_flags(flags, error, tmp_path):
    source = _write(tmp_path, "p.xml", scenes.PENDULUM)
    with pytest.raises(error):
        tuned_xml(source, {}, **flags)


def test_xml_declaration_is_kept_as_utf8(tmp_path):
    source = tmp_path / "latin.xml"
    source.write_bytes(b'<?xml version="1.0" encoding="ISO-8859-1"?>\n'
                       + FROMTO.replace("kept comment", "caf\xe9").encode("latin-1"))
    out = write_tuned_xml(source, tmp_path / "t.xml", options={"timestep": 0.002})
    raw = open(out, "rb").read()
    assert raw.startswith(b'<?xml version="1.0" encoding="utf-8"?>')
    assert "caf\xe9".encode("utf-8") in raw
    _assert_same_model(source, out, {"options": {"timestep": 0.002}})


def test_source_that_is_not_mjcf_is_a_value_error(tmp_path):
    source = _write(tmp_path, "bad.xml", "<mujoco><worldbody><body>")
    with pytest.raises(ValueError):
        tuned_xml(source, {"timestep": 0.01})


def test_several_options_get_a_trailing_one(tmp_path):
    text = FROMTO.replace("<worldbody>", '<option iterations="3"/>\n  <worldbody>')
    source = _write(tmp_path, "two.xml", text)
    changes = {"options": {"iterations": 8}, "disable_set": int(mjcffi.mjtDisableBit.mjDSBL_CONTACT)}
    result = tuned_mjcf(source, **changes)
    assert result.route == "text"
    assert result.text.endswith('  <option iterations="8">\n    <flag contact="disable"/>\n'
                                "  </option>\n</mujoco>\n")
    assert result.text.startswith(text[:text.index("</mujoco>")])
    _assert_same_model(source, _write(tmp_path, "t.xml", result.text), changes)


def test_text_route_reads_markup_not_patterns(tmp_path):
    # An <option> and a <flag> in comments, '>' and '/>' inside quoted values, CRLF
    # line ends, single quotes and a self-closing tag with a space before '/>'.
    text = ("<mujoco model='a > b'>\r\n"
            "  <!-- <option timestep=\"9\"/> -->\r\n"
            "  <option timestep='0.004' >\r\n"
            "    <!-- <flag gravity=\"enable\"/> -->\r\n"
            "    <flag gravity='disable' />\r\n"
            "  </option>\r\n"
            "  <worldbody><body name=\"x/>y\"><freejoint/><geom size=\".1\"/></body></worldbody>\r\n"
            "</mujoco>\r\n")
    source = tmp_path / "q.xml"
    source.write_bytes(text.encode())
    changes = {"options": {"timestep": 0.002, "iterations": 5},
               "disable_clear": int(mjcffi.mjtDisableBit.mjDSBL_GRAVITY)}
    out = write_tuned_xml(source, tmp_path / "t.xml", **changes)
    got = open(out, "rb").read().decode()
    assert got == text.replace("timestep='0.004' >", "timestep='0.002' iterations=\"5\" >") \
        .replace("gravity='disable' />", "gravity='enable' />")
    _assert_same_model(source, out, changes)


def test_an_option_holding_only_a_comment_gets_its_flag_on_a_line(tmp_path):
    # humanoid.xml's shape: the <flag> goes after the comment, indented like it.
    result = tuned_mjcf(GYM["humanoid"], {}, disable_set=int(mjcffi.mjtDisableBit.mjDSBL_CONTACT))
    lines = result.text.splitlines()
    at = lines.index('        <flag contact="disable"/>')
    assert lines[at - 1].strip().startswith("<!-- <flags") and lines[at + 1] == "    </option>"


def test_no_change_gives_the_source_back(tmp_path):
    assert tuned_xml(GYM["half_cheetah"], {}) == GYM["half_cheetah"].read_text()
