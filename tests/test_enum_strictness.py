"""Enum-valued arguments: which values mjcffi refuses, and which it takes as the official
bindings do (CONFORMANCE.md, "Strictness beyond the official bindings").

The rule: refuse what would crash or read or write out of bounds; take what MuJoCo
handles safely, exactly as the official bindings do.  The official bindings take any C
int for the mjr_* enum arguments (font, gridpos, framebuffer, fontscale), and MuJoCo
handles every value; mjcffi now takes them too, and draws the same pixels.  The mjs_*
functions that the official bindings do not expose take what MuJoCo's own default
branches handle; mjs_findElement keeps refusing what MuJoCo indexes its object lists with.

The drawing runs in a subprocess per OpenGL backend (tests/_gl.py), with mjcffi and the
official bindings in one process and one OpenGL context, as tests/test_mjr.py does.
"""

import json
import os
import shutil
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import mjcffi
from codegen import functions as table
from mjcffi import functions as F
from mjcffi import scenes
from tests import _gl

TIMEOUT = 300
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BACKENDS = ("egl", "osmesa")

# the values tried for every mjr_* argument that now takes any int
_ANY = (150, -1, 10**6, 2**31 - 1, -2**31)
# and for the mjs_* ones, whose C type cffi makes unsigned
_ANY_UNSIGNED = (27, 99, 101, 102, 150, 10**6, 2**31 - 1, 2**32 - 1)


def _run(code, env=None):
    """(returncode, stdout, stderr) of `code` in a fresh interpreter (a missed check
    may crash it)."""
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=TIMEOUT)
    return done.returncode, done.stdout, done.stderr


# ------------------------------------------------------------ the tables

def test_only_mjs_findElement_keeps_an_enum_check():
    from codegen import headers, parse
    decls = parse.parse(headers.mujoco_declarations())
    checked = table.derive_enums(decls, set(table.OVERRIDES) | set(table.UNSUPPORTED))
    assert checked == {"mjs_findElement": {"type": "mjtObj"}}
    assert table.ENUM_INTS == {}
    assert set(table.ENUM_EXCEPTIONS) == {("mjs_firstChild", "type"),
                                          ("mjs_firstElement", "type"),
                                          ("mjs_makeMesh", "builtin")}
    assert all(reason for reason in table.ENUM_EXCEPTIONS.values())


def test_docstrings_no_longer_promise_a_refusal():
    for name, arg in (("mjr_text", "font"), ("mjr_overlay", "font"), ("mjr_overlay", "gridpos"),
                      ("mjr_label", "font"), ("mjr_setBuffer", "framebuffer"),
                      ("mjr_changeFont", "fontscale"), ("mjs_firstChild", "type"),
                      ("mjs_firstElement", "type"), ("mjs_makeMesh", "builtin")):
        assert f"{arg} must be a value of" not in getattr(F, name).__doc__, name
    assert "type must be a value of mjtObj" in F.mjs_findElement.__doc__


# ------------------------------------------------------------ refused: mjs_findElement

def test_mjs_findElement_refuses_the_types_mujoco_indexes_past_its_object_lists():
    # on a compiled spec mjCModel::FindObject indexes object_lists_[type] (mjNOBJECT long):
    # the raw call with type 10**9 or mjOBJ_DEFAULT segfaults.  In a subprocess, in case
    # the refusal were lost.
    code, out, err = _run("""
        import json
        import mjcffi
        from mjcffi import functions as F
        s = F.mj_makeSpec()
        body = F.mjs_addBody(F.mjs_findBody(s, "world"), None)
        F.mjs_setName(body.element, "b")
        F.mjs_addGeom(body, None).size[0] = 0.1
        F.mj_compile(s, None)
        out = {}
        O = mjcffi.mjtObj
        for value in (26, 27, 99, 101, 102, O.mjOBJ_DEFAULT, O.mjOBJ_MODEL, O.mjNOBJECT,
                      103, 10**6, 10**9, 2**31 - 1, -1, 2**32 - 1, 2**64):
            try:
                F.mjs_findElement(s, value, "b")
                out[str(int(value))] = "ok"
            except Exception as exc:
                out[str(int(value))] = f"{type(exc).__name__}: {exc}"
        found = F.mjs_findElement(s, O.mjOBJ_BODY, "b")
        out["body"] = int(found.elemtype)
        out["frame"] = repr(F.mjs_findElement(s, O.mjOBJ_FRAME, "b"))
        out["plugin"] = repr(F.mjs_findElement(s, O.mjOBJ_PLUGIN, "b"))
        print(json.dumps(out))
    """)
    assert code == 0, err[-3000:]
    out = json.loads(out.strip().splitlines()[-1])
    assert out.pop("body") == 1 and out.pop("frame") == "None" and out.pop("plugin") == "None"
    for value, outcome in out.items():
        assert outcome.startswith("ValueError: type="), (value, outcome)
        assert "mjtObj" in outcome, (value, outcome)
    for value in ("26", "101", "102"):              # values of mjtObj it cannot take
        assert "below mjNOBJECT or mjOBJ_FRAME" in out[value]


def test_mjs_findElement_still_takes_the_object_types_and_refuses_non_integers():
    s = F.mj_makeSpec()
    body = F.mjs_addBody(F.mjs_findBody(s, "world"), None)
    F.mjs_setName(body.element, "b")
    assert int(F.mjs_findElement(s, mjcffi.mjtObj.mjOBJ_BODY, "b").elemtype) == 1
    assert int(F.mjs_findElement(s, np.int64(1), "b").elemtype) == 1
    for kind in range(int(mjcffi.mjtObj.mjNOBJECT)):
        F.mjs_findElement(s, kind, "nothing")           # no error: None or an element
    for bad in ("1", 1.0, None):
        with pytest.raises(TypeError, match=r"^type must be an int \(a value of mjtObj"):
            F.mjs_findElement(s, bad, "b")


# ------------------------------------------------------------ accepted: mjs_*

def _spec():
    s = F.mj_makeSpec()
    body = F.mjs_addBody(F.mjs_findBody(s, "world"), None)
    F.mjs_setName(body.element, "b")
    F.mjs_addGeom(F.mjs_addBody(body, None), None)
    return s, body


def test_mjs_firstChild_takes_any_type_and_fails_as_for_an_unsupported_one():
    # mjCBody::NextChild's default branch: the spec's error, and NULL
    for value in _ANY_UNSIGNED:
        s, body = _spec()
        assert F.mjs_firstChild(body, mjcffi.mjtObj.mjOBJ_ACTUATOR, 1) is None
        expected = F.mjs_getError(s)
        assert "NextChild supports the types" in expected
        s, body = _spec()
        assert F.mjs_firstChild(body, value, 1) is None, value
        assert F.mjs_getError(s) == expected, value
    s, body = _spec()
    assert int(F.mjs_firstChild(body, mjcffi.mjtObj.mjOBJ_BODY, 1).elemtype) == 1


def test_mjs_firstElement_takes_any_type_and_finds_nothing():
    # mjCModel::NextObject's default branch returns NULL, as for mjOBJ_DOF
    s, _ = _spec()
    assert F.mjs_firstElement(s, mjcffi.mjtObj.mjOBJ_DOF) is None
    for value in _ANY_UNSIGNED:
        assert F.mjs_firstElement(s, value) is None, value
    assert F.mjs_getError(s) == ""
    assert int(F.mjs_firstElement(s, mjcffi.mjtObj.mjOBJ_GEOM).elemtype) == \
        int(mjcffi.mjtObj.mjOBJ_GEOM)
    with pytest.raises(ValueError, match="mjOBJ_UNKNOWN"):        # it throws in C++
        F.mjs_firstElement(s, 0)


def test_mjs_makeMesh_takes_any_builtin_and_fails_as_unsupported():
    for value in (14, *_ANY_UNSIGNED):
        s = F.mj_makeSpec()
        mesh = F.mjs_addMesh(s, None)
        assert F.mjs_makeMesh(mesh, value, np.ones(4)) == 1, value
        assert F.mjs_getError(s).startswith("Error: Unsupported mesh type"), value
        assert len(mesh.uservert) == 0
    s = F.mj_makeSpec()
    mesh = F.mjs_addMesh(s, None)
    assert F.mjs_makeMesh(mesh, mjcffi.mjtMeshBuiltin.mjMESH_BUILTIN_SPHERE, np.ones(1)) == 0
    assert len(mesh.uservert) > 0


def test_the_accepted_mjs_arguments_take_what_their_c_type_holds_and_only_integers():
    # cffi gives these enums an unsigned C type: a negative number does not fit
    s, body = _spec()
    mesh = F.mjs_addMesh(s, None)
    calls = {"type": (lambda v: F.mjs_firstChild(body, v, 1), "mjtObj"),
             "type ": (lambda v: F.mjs_firstElement(s, v), "mjtObj"),
             "builtin": (lambda v: F.mjs_makeMesh(mesh, v, np.ones(4)), "mjtMeshBuiltin")}
    for name, (call, ctype) in calls.items():
        name = name.strip()
        for bad in (-1, 2**32, 2**64):
            with pytest.raises(ValueError, match=rf"{name}={bad} does not fit in a C {ctype}"):
                call(bad)
        for bad in ("1", 1.0, None):
            with pytest.raises(TypeError, match=rf"{name} must be a number \(C {ctype}\)"):
                call(bad)


# ------------------------------------------------------------ accepted: mjr_*

_FONTS = (0, 1, 2, 3, *_ANY)
_GRIDPOS = (*range(8), 8, *_ANY)
_FRAMEBUFFERS = (0, 1, 2, *_ANY)
_FONTSCALES = (77, 0, 350, -1, 10**6, 2**31 - 1)


def drawing_scenario():
    """For mjcffi and the official bindings in turn, in one OpenGL context: each call's
    outcome and a digest of the pixels it drew, with the enum arguments out of range."""
    import hashlib

    import mujoco

    width, height = 160, 120
    ctx = mjcffi.GLContext(width, height)
    ctx.make_current()
    out = {}
    for name, lib in (("ours", mjcffi), ("theirs", mujoco)):
        m = lib.MjModel.from_xml_string(scenes.DEFAULT)
        con = lib.MjrContext(m, lib.mjtFontScale.mjFONTSCALE_150)
        full = lib.MjrRect(0, 0, width, height)
        box = lib.MjrRect(10, 10, 120, 30)

        def outcome(call):
            try:
                call()
            except Exception as exc:     # noqa: BLE001  (recorded, for the test to judge)
                return f"{type(exc).__name__}: {str(exc).splitlines()[0]}"
            return "ok"

        def frame(draw):
            lib.mjr_setBuffer(1, con)        # two contexts share the OpenGL binding
            lib.mjr_rectangle(full, 0, 0, 0, 1)   # clears; leaves the viewport full
            result = outcome(draw)
            rgb = np.zeros((height, width, 3), np.uint8)
            lib.mjr_readPixels(rgb, None, full, con)
            return [result, hashlib.sha1(rgb.tobytes()).hexdigest(), int(np.count_nonzero(rgb))]

        cases = {}
        fonts = [(str(v), v) for v in _FONTS] + [("FONTSCALE_150", lib.mjtFontScale.mjFONTSCALE_150)]
        for key, v in fonts:
            cases[f"text font={key}"] = frame(
                lambda: lib.mjr_text(v, "Hello", con, 0.1, 0.5, 1, 1, 1))
            cases[f"overlay font={key}"] = frame(
                lambda: lib.mjr_overlay(v, 0, full, "Hello", "world", con))
            cases[f"label font={key}"] = frame(
                lambda: lib.mjr_label(box, v, "Hello", .2, .2, .2, 1, 1, 1, 1, con))
        for v in _GRIDPOS:
            cases[f"overlay gridpos={v}"] = frame(
                lambda: lib.mjr_overlay(0, v, full, "Hello", "world", con))
        cases["buffers"] = [int(con.windowAvailable), int(bool(con.offFBO))]
        for v in _FRAMEBUFFERS:
            result = outcome(lambda: lib.mjr_setBuffer(v, con))
            cases[f"setBuffer {v}"] = [result, int(con.currentBuffer)]
        for v in _FONTSCALES:
            result = outcome(lambda: lib.mjr_changeFont(v, con))
            state = [int(con.rangeFont), int(con.fontScale)]
            blank = frame(lambda: lib.mjr_text(0, "Hello", con, 0.1, 0.5, 1, 1, 1))
            lib.mjr_changeFont(150, con)
            again = frame(lambda: lib.mjr_text(0, "Hello", con, 0.1, 0.5, 1, 1, 1))
            cases[f"changeFont {v}"] = [result, state, blank, again]
        for bad in ("1", 1.5, None):
            cases[f"text font={bad!r}"] = [outcome(
                lambda: lib.mjr_text(bad, "Hello", con, 0.1, 0.5, 1, 1, 1)).split(":")[0]]
        out[name] = cases
        con.free()
    print(json.dumps(out))


@pytest.fixture(scope="module", params=BACKENDS)
def drawn(request):
    return _gl.run("tests.test_enum_strictness", request.param, "drawing_scenario",
                   timeout=TIMEOUT)


def test_mjr_calls_with_any_enum_value_match_the_official_bindings(drawn):
    ours, theirs = drawn["ours"], drawn["theirs"]
    assert ours.keys() == theirs.keys()
    for case in ours:
        assert ours[case] == theirs[case], (case, ours[case], theirs[case])


def test_a_font_outside_mjtFont_draws_as_mjFONT_NORMAL(drawn):
    ours = drawn["ours"]
    for call in ("text", "overlay", "label"):
        normal = ours[f"{call} font=0"]
        assert normal[0] == "ok" and normal[2] > 0, call
        # the test sees the font: mjFONT_BIG draws other pixels
        assert ours[f"{call} font=2"][1] != normal[1], call
        for key in ("3", *map(str, _ANY), "FONTSCALE_150"):
            assert ours[f"{call} font={key}"] == normal, (call, key)
    for bad in ("'1'", "1.5", "None"):
        assert ours[f"text font={bad}"] == ["TypeError"]


def test_a_gridpos_outside_mjtGridPos_draws_in_the_current_viewport(drawn):
    ours = drawn["ours"]
    placed = {ours[f"overlay gridpos={v}"][1] for v in range(8)}
    assert len(placed) == 8                          # each corner and side differs
    other = ours["overlay gridpos=8"]
    assert other[0] == "ok" and other[2] > 0
    for v in _ANY:
        assert ours[f"overlay gridpos={v}"] == other, v


def test_any_framebuffer_is_taken_and_kept_as_mujoco_keeps_it(drawn):
    # mjr_setBuffer ignores the value when only one buffer exists; with both, it stores
    # it, and MuJoCo compares it with mjFB_WINDOW only (the GLFW test below)
    window, offscreen = drawn["ours"]["buffers"]
    for v in _FRAMEBUFFERS:
        expected = v if window and offscreen else 1 if offscreen else 0
        assert drawn["ours"][f"setBuffer {v}"] == ["ok", expected], v


def test_a_fontscale_outside_mjtFontScale_is_mujocos_fatal_error(drawn):
    ours = drawn["ours"]
    for v in _FONTSCALES:
        result, state, blank, again = ours[f"changeFont {v}"]
        assert result == "FatalError: Invalid fontscale", v
        assert state == [0, 150], v                  # the old font freed, as MuJoCo does
        assert blank[0] == "ok" and blank[2] == 0, v  # no font: text draws nothing
        assert again == ours["text font=0"], v        # mjr_changeFont(150) restores it


# ------------------------------------------------------------ both buffers (GLFW)

_BOTH_BUFFERS = """
import json
import numpy as np
import mujoco
import mjcffi
from mjcffi import scenes
ctx = mjcffi.GLContext(64, 48)
ctx.make_current()
out = {}
for name, lib in (("ours", mjcffi), ("theirs", mujoco)):
    m = lib.MjModel.from_xml_string(scenes.DEFAULT)
    con = lib.MjrContext(m, 150)
    full = lib.MjrRect(0, 0, 64, 48)
    seen = [int(con.windowAvailable), int(bool(con.offFBO))]
    for v in (0, 1, 2, 150, -1, 2**31 - 1):
        lib.mjr_setBuffer(v, con)
        lib.mjr_rectangle(full, 0.2, 0.4, 0.6, 1)
        rgb = np.zeros((48, 64, 3), np.uint8)
        lib.mjr_readPixels(rgb, None, full, con)
        seen.append([v, int(con.currentBuffer), rgb[24, 32].tolist(),
                     int(lib.mjr_maxViewport(con).width), int(con.offWidth)])
    out[name] = seen
    con.free()
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def xvfb():
    """DISPLAY of a private Xvfb server, for the GLFW backend."""
    reason = _gl.skip_reason("glfw")
    if reason:
        pytest.skip(reason)
    read, write = os.pipe()
    server = subprocess.Popen([shutil.which("Xvfb"), "-displayfd", str(write), "-screen", "0",
                               "640x480x24", "-nolisten", "tcp"], pass_fds=(write,),
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write)
    with os.fdopen(read) as pipe:
        number = pipe.readline().strip()
    assert number.isdigit(), "Xvfb did not report its display"
    yield f":{number}"
    server.terminate()
    server.wait(timeout=30)


def test_with_a_window_too_any_framebuffer_but_window_means_offscreen(xvfb):
    # both buffers: MuJoCo stores the value in con.currentBuffer and compares it with
    # mjFB_WINDOW only (mjr_readPixels, mjr_restoreBuffer, mjr_maxViewport)
    code, out, err = _run(_BOTH_BUFFERS, env=_gl.env("glfw", xvfb))
    assert code == 0, err[-3000:]
    out = json.loads(out.strip().splitlines()[-1])
    assert out["ours"] == out["theirs"]
    window, offscreen, *rows = out["ours"]
    assert window == 1 and offscreen == 1
    for v, current, pixel, width, off_width in rows:
        assert current == v and pixel == [51, 102, 153], v
        assert width == (64 if v == 0 else off_width), v    # the window's, or offscreen's


# ------------------------------------------------------------ the other way: IntEnum

def test_enum_members_are_ints_unlike_the_official_ones():
    # CONFORMANCE.md, "Differences the other way": what was observed, kept true here
    mujoco = pytest.importorskip("mujoco")
    ours, theirs = mjcffi.mjtJoint.mjJNT_SLIDE, mujoco.mjtJoint.mjJNT_SLIDE
    assert ours == np.int32(2) and isinstance(ours, int)
    assert not (theirs == np.int32(2)) and not isinstance(theirs, int)
    assert np.int32(2) == theirs                  # the official's is asymmetric
    for e in (ours, theirs):                      # what works alike
        assert e == 2 and int(e) == 2 and e.value == 2 and e.name == "mjJNT_SLIDE"
        assert hash(e) == hash(2) and {2: "x"}[e] == "x" and e + 1 == 3 and e | 1 == 3
        assert np.arange(5)[e] == 2 and [0, 1, 2][e] == 2 and "%d" % e == "2"
        assert repr(e) == "<mjtJoint.mjJNT_SLIDE: 2>"
    # what differs: str, truthiness of a 0 member, equality across enums, numpy dtype
    assert str(ours) == "2" and str(theirs) == "mjtJoint.mjJNT_SLIDE"
    assert not mjcffi.mjtJoint.mjJNT_FREE and mujoco.mjtJoint.mjJNT_FREE
    assert ours == mjcffi.mjtGeom(2) and not (theirs == mujoco.mjtGeom(2))
    assert np.array([ours]).dtype.kind == "i" and np.array([theirs]).dtype == object
    assert ours < 3
    with pytest.raises(TypeError):
        theirs < 3                                # noqa: B015
