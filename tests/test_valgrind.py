"""Issue 11, items 7-9 under valgrind's memcheck: no invalid read, write or free.

Each scenario of tests/test_lifetimes.py that once touched freed memory (a geom
of a freed scene, a deleted spec element, a VFS destructor reading a collected
provider) runs as a tiny script under `valgrind --tool=memcheck`.  The scripts
run in parallel, once for the file (valgrind makes Python some 30 times slower).

Python itself is not clean under valgrind (ld.so, the interpreter), so an error
counts only when one of its stacks, where it happened or where its block was
allocated or freed, passes through MuJoCo or mjcffi's compiled module, and it
did not happen inside the dynamic loader (whose string scans valgrind reports
when a library with an $ORIGIN rpath, such as a MuJoCo plugin, is opened): a read
of freed scene memory happens in NumPy, but the block was freed by
libmujoco's mjv_freeScene.  `--undef-value-errors=no` leaves out the
uninitialised-value checks, the noisiest and slowest part, which are not what
these items are about.  A control script that does read freed memory, through
the raw C function, must be caught: the filter is tested along with the code.

Skipped when valgrind is absent (Debian package `valgrind`; .ci/run installs it).
"""

import concurrent.futures
import os
import re
import shutil
import subprocess
import sys
import textwrap
import xml.etree.ElementTree as ET

import pytest

VALGRIND = shutil.which("valgrind")
pytestmark = pytest.mark.skipif(
    VALGRIND is None, reason="valgrind is not installed (Debian package: valgrind)")

# Code of ours: an error in a stack that passes through these is a finding,
OURS = re.compile(r"libmujoco|_mjcffi|/mujoco/plugin/")
# unless it happened in the dynamic loader (ld.so's known false positives).
LOADER = re.compile(r"/ld-linux[^/]*\.so|/ld\.so|/ld-[0-9.]+\.so")
ERROR_EXIT = 97

_PRELUDE = """
import gc
import mjcffi
XML = "<mujoco><worldbody><geom size='1'/></worldbody></mujoco>"
"""

SCRIPTS = {
    # item 7: wrappers and views of a scene that mjv_freeScene, mjv_makeScene or
    # mjv_defaultScene replaced, read and written after the old scene is gone
    "item7": """
        m = mjcffi.MjModel.from_xml_string(XML)
        d = mjcffi.MjData(m)
        scn = mjcffi.MjvScene(m, 1000)
        g, order = scn.geoms[0], scn.geomorder
        mjcffi.mjv_freeScene(scn)
        g.size[0] = 1.0
        print(g.size, order[:3])
        mjcffi.mjv_makeScene(m, scn, 10)
        g2, translate = scn.geoms[5], scn.translate
        mjcffi.mjv_makeScene(m, scn, 20)
        mjcffi.mjv_updateScene(m, d, mjcffi.MjvOption(), None, mjcffi.MjvCamera(), 0xffff, scn)
        g2.pos[:] = translate
        mjcffi.mjv_defaultScene(scn)
        del scn; gc.collect()
        print(g.size, g2.pos)
        p = mjcffi.mju_malloc(64)
        mjcffi.mju_free(p)
        for ptr in (p, m._ptr):
            try:
                mjcffi.mju_free(ptr)
            except ValueError:
                pass
    """,
    # item 8: the raw calls that free spec elements are refused; compiling with
    # fusestatic and discardvisual leaves the spec's elements in place
    "item8": """
        s = mjcffi.mj_makeSpec()
        world = mjcffi.mjs_findBody(s, "world")
        b = mjcffi.mjs_addBody(world, None)
        for element in (b.element, world.element):
            try:
                mjcffi.mjs_delete(s, element)
            except NotImplementedError:
                pass
        print(b.pos)
        xml = '''<mujoco><compiler fusestatic="true" discardvisual="true"/>
          <asset><material name="mat"/></asset>
          <worldbody><body name="s"><geom size=".1" material="mat"/></body></worldbody></mujoco>'''
        spec = mjcffi.mj_parseXMLString(xml, None)
        static = mjcffi.mjs_findBody(spec, "s")
        mat = mjcffi.mjs_asMaterial(mjcffi.mjs_findElement(spec, mjcffi.mjtObj.mjOBJ_MATERIAL,
                                                           "mat"))
        print(mjcffi.mj_compile(spec, None).nbody)
        print(static.pos, mat.rgba)
        del s, world, spec; gc.collect()
        print(b.pos, static.pos)
    """,
    # item 9: a VFS outlives the provider objects mounted in it
    "item9": """
        for make in (mjcffi.MjVfs, mjcffi.MjVFS):
            vfs = make()
            mjcffi.mj_mountVFS(vfs, "x", mjcffi.MjpResourceProvider())
            mjcffi.mj_mountVFS(vfs, "a/./b", mjcffi.MjpResourceProvider())
            gc.collect()
            mjcffi.mj_unmountVFS(vfs, "a/b")
            gc.collect()
            del vfs; gc.collect()
        vfs = mjcffi.MjVfs()
        mjcffi.mj_mountVFS(vfs, "y", mjcffi.MjpResourceProvider())
        gc.collect()
        vfs.close()
        del vfs; gc.collect()
    """,
    # the control: a real use after free (through the raw C function) is caught
    "control": """
        m = mjcffi.MjModel.from_xml_string(XML)
        scn = mjcffi.MjvScene(m, 1000)
        g = scn.geoms[0]
        mjcffi.lib.mjv_freeScene(scn._ptr)
        print(g.size)
    """,
}


def _run(name, code, folder):
    """Run one script under memcheck; (returncode, stdout, stderr, findings)."""
    script = folder / f"{name}.py"
    script.write_text(_PRELUDE + textwrap.dedent(code) + "\nprint('script done')\n")
    report = folder / f"{name}.xml"
    env = dict(os.environ, PYTHONMALLOC="malloc")
    run = subprocess.run(
        [VALGRIND, "--tool=memcheck", f"--error-exitcode={ERROR_EXIT}", "--undef-value-errors=no",
         "--leak-check=no", "--show-leak-kinds=none", "--errors-for-leak-kinds=none",
         "--num-callers=40", "--xml=yes", f"--xml-file={report}",
         "--log-file=/dev/null", sys.executable, str(script)],
        capture_output=True, text=True, env=env, timeout=600)
    return run.returncode, run.stdout, run.stderr, _findings(report)


def _findings(report):
    """The errors of a memcheck XML report with a stack through MuJoCo or mjcffi."""
    found = []
    for error in ET.parse(report).getroot().iter("error"):
        if (error.findtext("kind") or "").startswith("Leak_"):
            continue                # leaks are not what this file is about
        objects = [frame.findtext("obj") or "" for frame in error.iter("frame")]
        if objects and LOADER.search(objects[0]):
            continue
        if any(OURS.search(obj) for obj in objects):
            what = error.findtext("what") or error.findtext("xwhat/text") or ""
            aux = [a.text or "" for a in error.iter("auxwhat")]
            stacks = [[frame.findtext("fn") or "?" for frame in stack.iter("frame")][:6]
                      for stack in error.iter("stack")]       # where, then alloc'd/free'd
            found.append(f"{error.findtext('kind')}: {what} {aux} in {stacks}")
    return found


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("valgrind")
    workers = max(1, min(len(SCRIPTS), os.cpu_count() or 1))
    with concurrent.futures.ThreadPoolExecutor(workers) as pool:
        futures = {name: pool.submit(_run, name, code, folder) for name, code in SCRIPTS.items()}
        return {name: future.result() for name, future in futures.items()}


def _assert_clean(result):
    returncode, stdout, stderr, findings = result
    assert "script done" in stdout, (returncode, stdout, stderr[-3000:])
    assert returncode in (0, ERROR_EXIT), (returncode, stderr[-3000:])   # not a crash
    assert not findings, "\n".join(findings)


def test_valgrind_catches_a_read_of_freed_scene_memory(runs):
    returncode, _, stderr, findings = runs["control"]
    assert returncode == ERROR_EXIT, (returncode, stderr[-3000:])
    assert any("free'd" in finding and "mjv_freeScene" in finding for finding in findings), \
        findings


def test_item7_scene_views_under_valgrind(runs):
    _assert_clean(runs["item7"])


def test_item8_spec_elements_under_valgrind(runs):
    _assert_clean(runs["item8"])


def test_item9_vfs_providers_under_valgrind(runs):
    _assert_clean(runs["item9"])
