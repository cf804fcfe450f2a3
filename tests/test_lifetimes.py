"""Issue 11, items 7-9: memory that a call frees or reallocates, and pointers that
MuJoCo keeps into memory Python owns.

- item 7: mjv_makeScene / mjv_freeScene / mjv_defaultScene give an MjvScene new
  memory, and wrappers and views of the old scene keep it alive; mju_free frees
  only what mju_malloc returned.
- item 8: the raw calls that free spec elements are refused (mjs_delete and the
  world body's double free among them); mj_compile with fusestatic or
  discardvisual compiles a copy, so the spec keeps its elements.
- item 9: an MjVfs or MjVFS keeps the resource providers mounted in it alive
  until they are unmounted (by any path MuJoCo takes for the same one) or the
  VFS is deleted.

What could crash runs in a subprocess under MALLOC_PERTURB_, which fills freed
memory with a pattern: a stale read then sees garbage (or crashes) rather than
the old values.  tests/test_valgrind.py runs the same scenarios under valgrind.
"""

import gc
import os
import subprocess
import sys
import textwrap
import weakref

import pytest

import mjcffi

GEOM_XML = "<mujoco><worldbody><geom size='1'/><geom pos='0 0 3' size='.5'/></worldbody></mujoco>"

SPEC_XML = """<mujoco><compiler {flags}/>
  <asset><material name="mat" rgba="1 0 0 1"/></asset>
  <worldbody>
    <body name="static" pos="1 2 3"><geom size=".1" material="mat"/></body>
    <body name="moving"><freejoint/><geom size=".2"/></body>
  </worldbody>
</mujoco>"""


def run_python(code, perturb=True):
    """Run `code` in a fresh interpreter (with MALLOC_PERTURB_); return the result."""
    env = dict(os.environ)
    if perturb:
        env["MALLOC_PERTURB_"] = "165"
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, env=env, timeout=120)


def assert_clean(result, expected_tail="done"):
    assert result.returncode == 0, (result.returncode, result.stdout, result.stderr[-3000:])
    assert result.stdout.strip().endswith(expected_tail), result.stdout


@pytest.fixture
def model():
    return mjcffi.MjModel.from_xml_string(GEOM_XML)


# ------------------------------------------------------------------ item 7

def test_item7_geom_wrapper_outlives_freeScene():
    result = run_python("""
        import gc, mjcffi
        m = mjcffi.MjModel.from_xml_string(%r)
        scn = mjcffi.MjvScene(m, 1000)
        g = scn.geoms[0]
        g.size[:] = [1, 2, 3]
        order = scn.geomorder
        order[:] = 7
        mjcffi.mjv_freeScene(scn)
        gc.collect()
        x = [bytearray(256000) for _ in range(20)]       # reuse of freed memory
        assert list(g.size) == [1, 2, 3], g.size
        assert (order == 7).all()
        g.size[0] = 5                                     # writes go to live memory
        assert scn.maxgeom == 0 and len(scn.geoms) == 0
        del scn; gc.collect()
        assert g.size[0] == 5
        print("done")
        """ % GEOM_XML)
    assert_clean(result)


def test_item7_geom_wrapper_outlives_a_second_makeScene():
    result = run_python("""
        import gc, mjcffi
        m = mjcffi.MjModel.from_xml_string(%r)
        d = mjcffi.MjData(m)
        scn = mjcffi.MjvScene(m, 1000)
        g = scn.geoms[0]
        g.size[:] = [1, 2, 3]
        rec = scn.geoms.records()
        mjcffi.mjv_makeScene(m, scn, 10)
        gc.collect()
        x = [bytearray(256000) for _ in range(20)]
        assert list(g.size) == [1, 2, 3] and list(rec[0]["size"]) == [1, 2, 3]
        assert scn.maxgeom == 10 and len(scn.geoms) == 10 and scn.geomorder.shape == (10,)
        mjcffi.mjv_updateScene(m, d, mjcffi.MjvOption(), None, mjcffi.MjvCamera(), 0xffff, scn)
        assert scn.ngeom == 2 and scn.geoms[1].size[0] == 0.5, scn.geoms[1].size
        assert list(g.size) == [1, 2, 3]                  # the old scene, untouched
        print("done")
        """ % GEOM_XML)
    assert_clean(result)


def test_item7_defaultScene_keeps_old_views_and_loses_nothing(model):
    scn = mjcffi.MjvScene(model, 50)
    g = scn.geoms[3]
    g.rgba[:] = [1, 0, 0, 1]
    old_root = weakref.ref(scn._root)
    mjcffi.mjv_defaultScene(scn)
    assert scn.maxgeom == 0 and scn.ngeom == 0
    assert list(g.rgba) == [1, 0, 0, 1]
    gc.collect()
    assert old_root() is not None                        # g keeps the old scene alive
    del g
    gc.collect()
    assert old_root() is None                            # ... and only g


def test_item7_old_scene_is_freed_with_its_last_view(model):
    scn = mjcffi.MjvScene(model, 100)
    roots = []
    for maxgeom in (10, 20, 30):
        roots.append(weakref.ref(scn._root))
        mjcffi.mjv_makeScene(model, scn, maxgeom)
    gc.collect()
    assert [r() for r in roots] == [None, None, None]    # nothing held them: freed at once
    view = scn.geoms[5].pos
    held = weakref.ref(scn._root)
    mjcffi.mjv_freeScene(scn)
    gc.collect()
    assert held() is not None
    del view
    gc.collect()
    assert held() is None


def test_item7_cached_views_follow_the_new_scene(model):
    scn = mjcffi.MjvScene(model, 10)
    old_translate, old_lights = scn.translate, scn.lights
    mjcffi.mjv_makeScene(model, scn, 20)
    assert scn.translate is not old_translate and scn.lights is not old_lights
    scn.translate[:] = [1, 2, 3]
    scn.lights[0].pos[:] = [4, 5, 6]
    assert list(scn._ptr.translate) == [1, 2, 3]
    assert list(scn._ptr.lights[0].pos) == [4, 5, 6]
    assert list(old_translate) == [0, 0, 0]
    scn.ngeom = 20                                        # bounds follow the new maxgeom
    with pytest.raises(ValueError):
        scn.ngeom = 21


def test_item7_failed_makeScene_keeps_the_scene(model):
    scn = mjcffi.MjvScene(model, 10)
    g = scn.geoms[0]
    address = scn._address
    with pytest.raises(TypeError):
        mjcffi.mjv_makeScene(model, scn, "many")
    with pytest.raises(TypeError):
        mjcffi.mjv_makeScene(None, scn, 5)
    assert scn._address == address and scn.maxgeom == 10
    assert g._root is scn._root


def test_item7_makeScene_that_cannot_allocate_keeps_the_scene():
    result = run_python("""
        import mjcffi
        m = mjcffi.MjModel.from_xml_string(%r)
        scn = mjcffi.MjvScene(m, 10)
        try:
            mjcffi.mjv_makeScene(m, scn, 2**31 - 1)
        except mjcffi.FatalError as exc:
            print("FatalError", exc)
        assert scn.maxgeom == 10 and len(scn.geoms) == 10
        scn.geoms[9].pos[:] = 1
        print("done")
        """ % GEOM_XML)
    assert_clean(result)


def test_item7_raw_scene_pointer_is_refused(model):
    scn = mjcffi.MjvScene(model, 10)
    for function, args in ((mjcffi.mjv_makeScene, (model, scn._ptr, 5)),
                           (mjcffi.mjv_freeScene, (scn._ptr,)),
                           (mjcffi.mjv_defaultScene, (scn._ptr,))):
        with pytest.raises(TypeError, match="raw mjvScene pointer"):
            function(*args)
    with pytest.raises(TypeError):
        mjcffi.mjv_freeScene(mjcffi.MjvOption())
    assert scn.maxgeom == 10


def test_item7_geoms_list_taken_before_makeScene_keeps_the_new_scene_alive():
    result = run_python("""
        import gc, mjcffi
        m = mjcffi.MjModel.from_xml_string(%r)
        scn = mjcffi.MjvScene(m, 100)
        geoms = scn.geoms
        mjcffi.mjv_makeScene(m, scn, 1000)
        g, rec, part = geoms[500], geoms.records(), geoms[400:]
        g.size[:] = [1, 2, 3]
        del scn, geoms; gc.collect()
        x = [bytearray(1 << 20) for _ in range(20)]
        assert list(g.size) == [1, 2, 3] and list(rec[500]["size"]) == [1, 2, 3]
        assert list(part[100].size) == [1, 2, 3]
        print("done")
        """ % GEOM_XML)
    assert_clean(result)


def test_item7_mju_free_frees_only_what_mju_malloc_returned():
    pointer = mjcffi.mju_malloc(64)
    mjcffi.mju_free(pointer)
    with pytest.raises(ValueError, match="was not returned by mju_malloc, or was freed"):
        mjcffi.mju_free(pointer)                          # twice
    s = mjcffi.mj_makeSpec()
    body = mjcffi.mjs_findBody(s, "world")
    m = mjcffi.MjModel.from_xml_string(GEOM_XML)
    for foreign in (body.element, body._ptr, m._ptr, mjcffi.ffi.new("int *")):
        with pytest.raises(ValueError, match="mju_malloc"):
            mjcffi.mju_free(foreign)
    with pytest.raises(TypeError):
        mjcffi.mju_free(b"bytes")
    assert mjcffi.mjs_findBody(s, "world").pos.tolist() == [0, 0, 0]


# ------------------------------------------------------------------ item 8

def test_item8_mjs_delete_is_refused_and_the_element_stays():
    result = run_python("""
        import gc, mjcffi
        s = mjcffi.mj_makeSpec()
        b = mjcffi.mjs_addBody(mjcffi.mjs_findBody(s, "world"), None)
        b.pos[:] = [1, 2, 3]
        child = mjcffi.mjs_addGeom(b, None)
        for element in (b.element, child.element):
            try:
                mjcffi.mjs_delete(s, element)
            except NotImplementedError as exc:
                assert "MjSpec.delete" in str(exc), exc
            else:
                raise AssertionError("mjs_delete was not refused")
        gc.collect()
        x = [bytearray(4096) for _ in range(200)]
        assert list(b.pos) == [1, 2, 3] and child.size[0] == 0
        print("done")
        """)
    assert_clean(result)


def test_item8_deleting_the_world_body_cannot_crash_the_spec():
    # MuJoCo's own bug: mjs_delete of the world body succeeds, and mj_deleteSpec
    # then crashes; refusing mjs_delete leaves no way there
    result = run_python("""
        import gc, mjcffi
        s = mjcffi.mj_makeSpec()
        world = mjcffi.mjs_findBody(s, "world")
        try:
            mjcffi.mjs_delete(s, world.element)
        except NotImplementedError:
            pass
        assert mjcffi.mj_compile(s, None).nbody == 1
        del s, world; gc.collect()
        print("done")
        """)
    assert_clean(result)


@pytest.mark.parametrize("name", ["mjs_delete", "mjs_fuseStatic", "mjs_discardVisual",
                                  "mjs_dedupAssets"])
def test_item8_raw_calls_that_free_elements_are_refused(name):
    s = mjcffi.mj_parseXMLString(SPEC_XML.format(flags=""), None)
    args = {"mjs_delete": (s, mjcffi.mjs_findBody(s, "static").element),
            "mjs_fuseStatic": (s, None), "mjs_discardVisual": (s, None),
            "mjs_dedupAssets": (s,)}[name]
    with pytest.raises(NotImplementedError, match="MjSpec"):
        getattr(mjcffi, name)(*args)
    assert getattr(mjcffi.lib, name)                      # the raw C function stays
    assert mjcffi.mjs_findBody(s, "static").pos.tolist() == [1, 2, 3]


@pytest.mark.parametrize("flags", ['fusestatic="true"', 'discardvisual="true"',
                                   'fusestatic="true" discardvisual="true"'])
def test_item8_compile_that_deletes_elements_compiles_a_copy(flags):
    xml = SPEC_XML.format(flags=flags)
    result = run_python("""
        import gc, pickle, mjcffi
        xml = %r
        s = mjcffi.mj_parseXMLString(xml, None)
        body = mjcffi.mjs_findBody(s, "static")
        material = mjcffi.mjs_asMaterial(mjcffi.mjs_findElement(s, mjcffi.mjtObj.mjOBJ_MATERIAL,
                                                                "mat"))
        m = mjcffi.mj_compile(s, None)
        gc.collect()
        x = [bytearray(4096) for _ in range(200)]
        assert list(body.pos) == [1, 2, 3] and list(material.rgba) == [1, 0, 0, 1]
        reference = mjcffi.MjModel.from_xml_string(xml)   # compiled in place, by MuJoCo
        assert pickle.dumps(m) == pickle.dumps(reference)
        assert mjcffi.mj_compile(s, None).nbody == m.nbody  # again: the spec is unchanged
        print("done", m.nbody, m.nmat)
        """ % xml)
    assert result.returncode == 0, result.stderr[-3000:]
    nbody, nmat = map(int, result.stdout.split()[-2:])
    assert nbody == (2 if "fusestatic" in flags else 3)
    assert nmat == (0 if "discardvisual" in flags else 1)


def test_item8_compile_without_those_flags_compiles_the_spec_itself():
    s = mjcffi.mj_parseXMLString(SPEC_XML.format(flags=""), None)
    m = mjcffi.mj_compile(s, None)
    body = mjcffi.mjs_findBody(s, "static")
    assert m.nbody == 3 and mjcffi.mjs_getId(body.element) == 1
    assert "static" in mjcffi.mj_saveXMLString(s)       # compiled: it can be written


# ------------------------------------------------------------------ item 9

def test_item9_vfs_keeps_a_mounted_provider_alive():
    result = run_python("""
        import gc, mjcffi
        for make in (mjcffi.MjVfs, mjcffi.MjVFS):
            vfs = make()
            assert mjcffi.mj_mountVFS(vfs, "x", mjcffi.MjpResourceProvider()) == 0
            gc.collect()
            x = [bytearray(120) for _ in range(1000)]     # reuse of the provider's memory
            del vfs; gc.collect()
        vfs = mjcffi.MjVfs()
        mjcffi.mj_mountVFS(vfs, "y", mjcffi.MjpResourceProvider())
        gc.collect(); x = [bytearray(120) for _ in range(1000)]
        vfs.close()
        left = [mjcffi.MjVfs(), mjcffi.MjVFS()]           # collected at interpreter exit
        for i, v in enumerate(left):
            mjcffi.mj_mountVFS(v, "z", mjcffi.MjpResourceProvider())
        print("done")
        """)
    assert_clean(result)


def _mounted(vfs, path):
    provider = mjcffi.MjpResourceProvider()
    assert mjcffi.mj_mountVFS(vfs, path, provider) == 0
    held = weakref.ref(provider)
    del provider
    gc.collect()
    assert held() is not None
    return held


@pytest.mark.parametrize("make", [mjcffi.MjVfs, mjcffi.MjVFS])
def test_item9_unmount_lets_go_of_the_provider(make):
    vfs = make()
    held = _mounted(vfs, "x")
    assert mjcffi.mj_unmountVFS(vfs, "y") == -1           # another path: still held
    gc.collect()
    assert held() is not None
    assert mjcffi.mj_unmountVFS(vfs, "x") == 0
    gc.collect()
    assert held() is None
    held = _mounted(vfs, "a/./b")                         # MuJoCo's own path normalization
    other = _mounted(vfs, "c")
    assert mjcffi.mj_unmountVFS(vfs, "a/z/../b") == 0
    gc.collect()
    assert held() is None and other() is not None
    assert mjcffi.mj_mountVFS(vfs, "a/b", mjcffi.MjpResourceProvider()) == 0   # free again


def test_item9_deleting_the_path_or_the_vfs_lets_go():
    vfs = mjcffi.MjVfs()
    held = _mounted(vfs, "mesh.obj")
    assert mjcffi.mj_deleteFileVFS(vfs, "mesh.obj") == 0  # MuJoCo unmounts it too
    gc.collect()
    assert held() is None
    held = _mounted(vfs, "dir")
    mjcffi.mj_deleteVFS(vfs)
    gc.collect()
    assert held() is None
    held = _mounted(vfs, "dir")
    vfs.close()
    gc.collect()
    assert held() is None
    plain = mjcffi.MjVFS()
    held = _mounted(plain, "dir")
    mjcffi.mj_defaultVFS(plain)
    gc.collect()
    assert held() is None
    held = _mounted(plain, "dir")
    del plain
    gc.collect()
    assert held() is None


def test_item9_a_path_taken_by_a_file_keeps_the_provider():
    # the probe that tells whether a path is still mounted errs on the safe side
    vfs = mjcffi.MjVfs()
    held = _mounted(vfs, "dir")
    assert mjcffi.mj_unmountVFS(vfs, "dir") == 0
    vfs["dir"] = b"data"
    other = _mounted(vfs, "other")
    mjcffi.mj_unmountVFS(vfs, "other")
    gc.collect()
    assert held() is None and other() is None
    assert "dir" in vfs


def test_item9_raw_vfs_pointer_and_closed_vfs_are_refused():
    vfs = mjcffi.MjVFS()
    provider = mjcffi.MjpResourceProvider()
    with pytest.raises(TypeError, match="raw mjVFS pointer"):
        mjcffi.mj_mountVFS(vfs._ptr, "x", provider)
    with pytest.raises(TypeError):
        mjcffi.mj_mountVFS(vfs, "x", mjcffi.MjvOption())
    with pytest.raises(TypeError):
        mjcffi.mj_mountVFS(vfs, 3, provider)
    closed = mjcffi.MjVfs()
    closed.close()
    with pytest.raises(RuntimeError, match="VFS is closed"):
        mjcffi.mj_mountVFS(closed, "x", provider)
    assert mjcffi.mj_mountVFS(vfs, "x", provider) == 0
    assert mjcffi.mj_mountVFS(vfs, "x", provider) == 2    # repeated: held once
    from mjcffi import vfs as vfs_module
    assert len(vfs_module._MEMORY[vfs._address].mounts) == 1


def test_item9_mounts_and_loads_from_threads():
    import threading
    vfs = mjcffi.MjVfs()
    vfs["model.xml"] = GEOM_XML.encode()
    errors = []

    def work(i):
        try:
            for j in range(20):
                path = f"t{i}/{j}"
                assert mjcffi.mj_mountVFS(vfs, path, mjcffi.MjpResourceProvider()) == 0
                mjcffi.MjModel.from_xml_path("model.xml", vfs=vfs)
                assert mjcffi.mj_unmountVFS(vfs, path) == 0
        except Exception as exc:       # noqa: BLE001  (reported below)
            errors.append(exc)
    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    from mjcffi import vfs as vfs_module
    assert vfs_module._MEMORY[vfs._address].mounts == []
