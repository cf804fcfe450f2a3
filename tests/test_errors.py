"""Bad input gets a Python exception that names the problem; the process lives."""

import pathlib
import subprocess
import sys
import types

import pytest
from hypothesis import given, settings, strategies as st

import mjcffi
from mjcffi._support import library as _library, loading as _loading

GOOD_XML = '<mujoco><worldbody><geom size=".1"/></worldbody></mujoco>'


def test_missing_file_gives_mujocos_message(tmp_path):
    missing = tmp_path / "no_such_model.xml"
    with pytest.raises(ValueError, match="no_such_model.xml"):
        _loading.load_xml_path(missing)


def test_bad_xml_text_gives_mujocos_message():
    with pytest.raises(ValueError, match="XML_ERROR_MISMATCHED_ELEMENT"):
        _loading.load_xml_string("<mujoco><worldbody></body></mujoco>")


def test_invalid_model_gives_mujocos_message():
    with pytest.raises(ValueError, match="unrecognized attribute.*'bogus'|bogus"):
        _loading.load_xml_string('<mujoco><worldbody><geom bogus="1"/></worldbody></mujoco>')


def test_bad_xml_file_gives_mujocos_message(tmp_path):
    path = tmp_path / "broken.xml"
    path.write_text("<mujoco><worldbody><geom type='sphere'/></worldbody>")
    with pytest.raises(ValueError, match="XML"):
        _loading.load_xml_path(path)


@pytest.mark.parametrize("bad, error", [(3, TypeError), (None, TypeError), ("a\0b", ValueError)])
def test_bad_path_argument(bad, error):
    with pytest.raises(error, match="path"):
        _loading.load_xml_path(bad)


@pytest.mark.parametrize("bad, error", [(3, TypeError), (["<mujoco/>"], TypeError),
                                        ("<mujoco/>\0", ValueError)])
def test_bad_xml_argument(bad, error):
    with pytest.raises(error, match="xml"):
        _loading.load_xml_string(bad)


def test_bad_assets():
    with pytest.raises(TypeError, match="asset 'mesh.obj' must be bytes"):
        _loading.load_xml_string(GOOD_XML, assets={"mesh.obj": "text"})
    with pytest.raises(TypeError, match="asset name must be a str"):
        _loading.load_xml_string(GOOD_XML, assets={3: b""})
    with pytest.raises(ValueError, match="Repeated file name in assets dict: mesh.obj"):
        _loading.load_xml_string(GOOD_XML, assets={"a/mesh.obj": b"", "b/MESH.obj": b""})


def test_messages_are_mujocos_own_text():
    # as the official binding's: MuJoCo's text unchanged, its final newline included
    with pytest.raises(ValueError) as info:
        _loading.load_xml_string('<mujoco><worldbody><geom bogus="1"/></worldbody></mujoco>')
    assert str(info.value) == ("XML Error: Schema violation: unrecognized attribute: 'bogus'\n"
                               "Element 'geom', line 1\n")


def test_a_failed_mjb_load_has_the_official_message_and_a_note(tmp_path):
    with pytest.raises(ValueError) as info:
        _loading.load_binary_path(tmp_path / "missing.mjb")
    assert str(info.value) == "mj_loadModel: failed to load from mjb"
    assert "missing.mjb" in info.value.__notes__[0]


def test_assets_go_through_the_vfs():
    included = '<mujoco><worldbody><include file="part.xml"/></worldbody></mujoco>'
    part = b'<mujoco><geom size=".1"/><geom size=".2" pos="1 0 0"/></mujoco>'
    model = _loading.load_xml_string(included, assets={"part.xml": part})
    assert model.ngeom == 2


def test_good_model_loads_from_string_and_path(tmp_path):
    path = tmp_path / "ok.xml"
    path.write_text(GOOD_XML)
    assert _loading.load_xml_string(GOOD_XML).ngeom == 1
    assert _loading.load_xml_path(path).ngeom == 1
    assert _loading.load_xml_path(str(path)).ngeom == 1


@settings(max_examples=300, deadline=None, derandomize=True)
@given(st.text(max_size=200))
def test_arbitrary_text_never_kills_the_process(text):
    try:
        model = _loading.load_xml_string(text)
    except ValueError as exc:
        assert str(exc)
    else:
        assert model.nbody >= 1


@settings(max_examples=100, deadline=None, derandomize=True)
@given(st.lists(st.sampled_from(["<mujoco>", "</mujoco>", "<worldbody>", "</worldbody>",
                                 "<body>", "</body>", '<geom size="0.1"/>', "<joint/>",
                                 '<geom type="box"/>', "<freejoint/>", '<option timestep="-1"/>',
                                 '<site pos="a b c"/>']), max_size=12))
def test_arbitrary_element_soup_never_kills_the_process(parts):
    try:
        _loading.load_xml_string("".join(parts))
    except ValueError as exc:
        assert str(exc)


def test_missing_mujoco_core_names_version_and_fix(monkeypatch):
    monkeypatch.setattr(_library.importlib.util, "find_spec", lambda name: None)
    with pytest.raises(ImportError) as info:
        _library._mujoco_library_path()
    assert "4.0.0" in str(info.value) and "pip install 'mujoco-core==4.0.0'" in str(info.value)


def test_version_mismatch_names_version_and_fix(monkeypatch):
    fake_lib = types.SimpleNamespace(mj_version=lambda: 3030000,
                                     mjcffi_header_version=lambda: 4000000)
    fake = types.SimpleNamespace(ffi=mjcffi.ffi, lib=fake_lib)
    monkeypatch.setattr(_library, "_import_compiled", lambda: fake)
    with pytest.raises(ImportError) as info:
        _library.load()
    message = str(info.value)
    assert "4.0.0" in message and "3030000" in message
    assert "pip install 'mujoco-core==4.0.0'" in message


def test_import_without_mujoco_core_raises_importerror(tmp_path):
    # A `mujoco` package without libmujoco.so.4.0.0 shadows the real one.
    fake = tmp_path / "mujoco"
    fake.mkdir()
    (fake / "__init__.py").write_text("")
    probe = ("import sys\n"
             "try:\n    import mjcffi\nexcept ImportError as e:\n    print('ImportError:', e)\n"
             "else:\n    print('imported')\n")
    repo = pathlib.Path(mjcffi.__file__).resolve().parent.parent
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                            env={"PYTHONPATH": f"{tmp_path}:{repo}", "PATH": "/usr/bin:/bin"})
    assert result.returncode == 0, result.stderr
    # An installed mjcffi reaches the real libmujoco through its rpath
    # (site-packages/mjcffi/../mujoco); an editable one has only the preload.
    compiled = pathlib.Path(mjcffi._support.library._import_compiled().__file__)
    if (compiled.parent.parent / "mujoco" / _library.MUJOCO_LIBRARY).exists():
        assert result.stdout.strip() == "imported"
    else:
        assert result.stdout.startswith("ImportError:")
        assert "pip install 'mujoco-core==4.0.0'" in result.stdout
