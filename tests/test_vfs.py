"""MjVfs, and models loaded from memory: `vfs=` and the `assets=` dict."""

import copy
import pickle
import threading
import time

import pytest

import mjcffi
from mjcffi import MjModel, MjVfs

BOX_OBJ = b"""v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
f 1 2 3 4
f 5 8 7 6
f 1 5 6 2
f 2 6 7 3
f 3 7 8 4
f 4 8 5 1
"""

MESH_XML = """<mujoco>
  <asset><mesh name="box" file="{file}"/></asset>
  <worldbody><body><geom type="mesh" mesh="box"/></body></worldbody>
</mujoco>"""

TWO_GEOMS = b'<mujoco><worldbody><geom size=".1"/><geom size=".2"/></worldbody></mujoco>'


# ------------------------------------------------------------------ lifecycle

def test_files_are_added_asked_for_and_removed():
    with MjVfs() as vfs:
        assert "a.xml" not in vfs
        vfs["a.xml"] = b"<mujoco/>"
        vfs["dir/b.obj"] = bytearray(BOX_OBJ)
        vfs["c.bin"] = memoryview(b"\x00\x01")
        assert "a.xml" in vfs and "dir/b.obj" in vfs and "c.bin" in vfs
        assert "b.obj" not in vfs              # names are whole paths
        del vfs["a.xml"]
        assert "a.xml" not in vfs


def test_a_repeated_name_and_a_missing_one_raise():
    with MjVfs() as vfs:
        vfs["a.xml"] = b"<mujoco/>"
        with pytest.raises(ValueError, match=r"^Repeated file name in VFS: a.xml$"):
            vfs["a.xml"] = b"<mujoco/>"
        with pytest.raises(KeyError, match="nonexistent"):
            del vfs["nonexistent"]


@pytest.mark.parametrize("name, content, error", [
    (3, b"x", TypeError), (None, b"x", TypeError), ("a.xml", "text", TypeError),
    ("a.xml", None, TypeError), ("a\0b", b"x", ValueError)])
def test_bad_names_and_contents(name, content, error):
    with MjVfs() as vfs:
        with pytest.raises(error):
            vfs[name] = content
        if isinstance(name, str):
            assert name not in vfs


def test_close_twice_is_safe_and_later_uses_raise():
    vfs = MjVfs()
    vfs["a.xml"] = b"<mujoco/>"
    assert not vfs.closed and "open" in repr(vfs)
    vfs.close()
    vfs.close()
    assert vfs.closed and "closed" in repr(vfs)
    uses = [lambda: vfs.__setitem__("b.xml", b""), lambda: "a.xml" in vfs,
            lambda: vfs.__delitem__("a.xml"), lambda: MjModel.from_xml_path("a.xml", vfs=vfs),
            lambda: MjModel.from_xml_string("<mujoco/>", vfs=vfs),
            lambda: mjcffi.mj_containsBufferVFS(vfs, "a.xml")]
    for use in uses:
        with pytest.raises(RuntimeError, match="VFS is closed"):
            use()


def test_the_context_manager_closes():
    with MjVfs() as vfs:
        vfs["a.xml"] = b"<mujoco/>"
    with pytest.raises(RuntimeError, match="VFS is closed"):
        vfs["b.xml"] = b""


def test_an_mjvfs_is_neither_copied_nor_pickled():
    with MjVfs() as vfs:
        for action in (copy.copy, copy.deepcopy, pickle.dumps):
            with pytest.raises(TypeError):
                action(vfs)


# ------------------------------------------------------------------ loading

def test_from_xml_path_reads_the_model_and_its_mesh_from_the_vfs():
    with MjVfs() as vfs:
        vfs["scene.xml"] = MESH_XML.format(file="box.obj").encode()
        vfs["box.obj"] = BOX_OBJ
        model = MjModel.from_xml_path("scene.xml", vfs=vfs)
    assert model.nmesh == 1 and model.mesh_vertnum[0] == 8


def test_from_xml_string_leaves_the_vfs_as_it_was():
    with MjVfs() as vfs:
        vfs["box.obj"] = BOX_OBJ
        vfs["model_.xml"] = TWO_GEOMS       # the name the text would take first
        model = MjModel.from_xml_string(MESH_XML.format(file="box.obj"), vfs=vfs)
        assert model.nmesh == 1
        assert "model_.xml" in vfs and "model__.xml" not in vfs
        included = MjModel.from_xml_string(
            '<mujoco><include file="model_.xml"/></mujoco>', vfs=vfs)
        assert included.ngeom == 2           # the caller's model_.xml was not replaced


def test_from_binary_path_reads_an_mjb_from_the_vfs():
    mjb = MjModel.from_xml_string(TWO_GEOMS).to_bytes()
    with MjVfs() as vfs:
        vfs["two.mjb"] = mjb
        assert MjModel.from_binary_path("two.mjb", vfs=vfs).ngeom == 2
    assert MjModel.from_binary_path("some/dir/two.mjb", assets={"two.mjb": mjb}).ngeom == 2


def test_vfs_and_assets_together_raise():
    with MjVfs() as vfs:
        for assets in ({"a": b"b"}, {}):
            for load in (MjModel.from_xml_string, MjModel.from_xml_path):
                with pytest.raises(ValueError, match=r"^Cannot specify both 'assets' and 'vfs'\.$"):
                    load("<mujoco/>", assets=assets, vfs=vfs)


def test_vfs_must_be_a_vfs():
    with pytest.raises(TypeError, match="vfs must be an MjVfs, not dict"):
        MjModel.from_xml_string("<mujoco/>", vfs={"a": b""})


def test_the_generated_mjvfs_class_and_the_mj_functions_interoperate():
    vfs = MjVfs()
    assert isinstance(vfs, mjcffi.MjVFS)
    assert mjcffi.mj_addBufferVFS(vfs, "m.xml", TWO_GEOMS) == 0
    assert "m.xml" in vfs and mjcffi.mj_containsBufferVFS(vfs, "m.xml") == 1
    assert mjcffi.mj_loadXML("m.xml", vfs).ngeom == 2
    plain = mjcffi.MjVFS()
    mjcffi.mj_addBufferVFS(plain, "m.xml", TWO_GEOMS)
    assert MjModel.from_xml_path("m.xml", vfs=plain).ngeom == 2
    vfs.close()


def test_a_close_waits_for_loads_on_other_threads():
    vfs = MjVfs()
    vfs["box.obj"] = BOX_OBJ
    xml = MESH_XML.format(file="box.obj")
    outcomes, errors = [], []

    def load_until_closed():
        try:
            while True:
                outcomes.append(MjModel.from_xml_string(xml, vfs=vfs).nmesh)
        except RuntimeError as exc:
            errors.append(str(exc))

    threads = [threading.Thread(target=load_until_closed) for _ in range(4)]
    for thread in threads:
        thread.start()
    deadline = time.monotonic() + 60
    while len(outcomes) < 8 and time.monotonic() < deadline:
        time.sleep(0.001)
    vfs.close()
    for thread in threads:
        thread.join()
    assert set(outcomes) == {1} and errors == ["VFS is closed"] * 4


# ----------------------------------------------------------- the assets dict

def test_the_assets_dict_still_works():
    model = MjModel.from_xml_string(MESH_XML.format(file="box.obj"), assets={"box.obj": BOX_OBJ})
    assert model.nmesh == 1


@pytest.mark.parametrize("file, key", [("box.obj", "meshes/box.obj"),
                                       ("meshes/box.obj", "box.obj"),
                                       ("Box.obj", "box.obj"), ("box.obj", "BOX.OBJ")])
def test_assets_are_found_by_their_file_name(file, key):
    model = MjModel.from_xml_string(MESH_XML.format(file=file), assets={key: BOX_OBJ})
    assert model.nmesh == 1


@pytest.mark.parametrize("first, second, stored", [
    ("asset.xml", "path/asset.xml", "asset.xml"), ("a/Asset.xml", "b/asset.xml", "asset.xml"),
    ("X/ABC.XML", "abc.xml", "abc.xml"), ("a.xml", "./a.xml", "a.xml"),
    ("dir\\b.xml", "b.xml", "b.xml")])
def test_assets_with_one_file_name_are_refused(first, second, stored):
    with pytest.raises(ValueError, match=rf"^Repeated file name in assets dict: {stored}$"):
        MjModel.from_xml_string("<mujoco/>", {first: b"1", second: b"2"})


def test_the_xml_text_takes_a_name_no_asset_has():
    part = b'<mujoco><worldbody><geom size=".1"/></worldbody></mujoco>'
    for names in (["model.xml"], ["model_.xml"], ["model_.xml", "model__.xml"]):
        xml = "<mujoco>" + "".join(f'<include file="{n}"/>' for n in names) + "</mujoco>"
        model = MjModel.from_xml_string(xml, {n: part for n in names})
        assert model.ngeom == len(names)


def test_loading_errors_match_the_official_messages(mujoco, tmp_path):
    cases = [lambda m: m.from_xml_string(""),
             lambda m: m.from_xml_string("<mujoco><worldbody></body></mujoco>"),
             lambda m: m.from_xml_string('<mujoco><geom bogus="1"/></mujoco>'),
             lambda m: m.from_xml_string('<mujoco><include file="nope.xml"/></mujoco>'),
             lambda m: m.from_xml_path(str(tmp_path / "missing.xml")),
             lambda m: m.from_binary_path(str(tmp_path / "missing.mjb")),
             lambda m: m.from_xml_string("<mujoco/>", {"a.xml": b"", "b/A.xml": b""})]
    for case in cases:
        with pytest.raises(ValueError) as official:
            case(mujoco.MjModel)
        with pytest.raises(ValueError) as ours:
            case(MjModel)
        assert str(ours.value) == str(official.value)
