"""MuJoCo's UI from Python: mjui_add's checks, and the viewer's Panels drawn offscreen.

The official bindings have no Python mjui functions, so nothing here is compared
with them.  Drawing runs in subprocesses (tests/_gl.py): one GL backend per process,
and a crash fails the test instead of ending pytest.
"""

import ctypes
import os
import subprocess
import sys

import numpy as np
import pytest

import mjcffi
from mjcffi import mjtItem as I
from mjcffi._support.library import ffi
from tests import _gl

SECTION = (I.mjITEM_SECTION, "Section", 1)


def _ui():
    return mjcffi.MjUI()


def _nsect_nitem(ui):
    return ui.nsect, [ui.sect[i].nitem for i in range(ui.nsect)]


# ------------------------------------------------------------ mjui_add without OpenGL

def test_add_accepts_tuples_dicts_and_python_owned_buffers():
    ui = _ui()
    flag, value, text = np.zeros(1, np.int32), np.zeros(1), np.zeros(40, np.uint8)
    mjcffi.mjui_add(ui, [
        SECTION,
        (I.mjITEM_CHECKINT, "check", 2, flag, " c"),
        dict(type=I.mjITEM_SLIDERNUM, name="slider", pdata=value, other="0 1"),
        (I.mjITEM_SELECT, "select", 2, ffi.new("int *"), "a\nb\nc"),
        (I.mjITEM_EDITNUM, "edit", 2, (ctypes.c_double * 3)(), "3"),
        (I.mjITEM_EDITTXT, "text", 2, text),
        (I.mjITEM_BUTTON, "button", 2, None, " b"),
    ])
    assert _nsect_nitem(ui) == (1, [6])
    items = ui.sect[0].item
    assert [items[i].type for i in range(6)] == [3, 9, 7, 11, 13, 2]
    assert items[2].multi.nelem == 3 and items[3].edit.nelem == 3
    assert int(ffi.cast("uintptr_t", items[0].pdata)) == flag.ctypes.data
    mjcffi.mjui_addToSection(ui, 0, [(I.mjITEM_SLIDERINT, "n", 2, np.zeros(1, np.int32),
                                      "0 10")])
    assert _nsect_nitem(ui) == (1, [7])


def test_add_keeps_buffers_alive_and_pinned():
    import gc
    import weakref
    ui = _ui()
    value = np.zeros(1)
    ref = weakref.ref(value)
    mjcffi.mjui_add(ui, [SECTION, (I.mjITEM_SLIDERNUM, "s", 2, value, "0 1")])
    del value
    gc.collect()
    kept = ref()
    assert kept is not None                      # the MjUI holds it
    with pytest.raises(ValueError):              # exported to the UI: no reallocation
        kept.resize(100, refcheck=False)


def test_a_pdata_array_cannot_be_resized_even_without_refcheck():
    """A cffi buffer export does not stop NumPy's resize(refcheck=False): the MjUI
    holds a weak reference to the array, for which NumPy refuses it (the test above
    holds one itself)."""
    ui = _ui()
    value = np.zeros(1)
    mjcffi.mjui_add(ui, [SECTION, (I.mjITEM_SLIDERNUM, "s", 2, value, "0 1")])
    with pytest.raises(ValueError, match="resize"):
        value.resize(10**6, refcheck=False)
    assert int(ffi.cast("uintptr_t", ui.sect[0].item[0].pdata)) == value.ctypes.data


BAD = [
    ("not a sequence", 5, TypeError, "sequence of definitions"),
    ("a str", "abc", TypeError, "sequence of definitions"),
    ("an int entry", [SECTION, 7], TypeError, r"def_\[1\] must be an MjuiDef"),
    ("type not int", [("section", "x")], TypeError, r"def_\[0\]\.type must be an int"),
    ("unknown type", [SECTION, (99, "x")], ValueError, "no mjtItem"),
    ("end marker", [SECTION, (I.mjITEM_END,)], ValueError, "mjITEM_END"),
    ("unknown key", [dict(type=-1, nam="x")], TypeError, "unknown keys"),
    ("long name", [SECTION, (I.mjITEM_BUTTON, "x" * 40)], ValueError, "at most 39"),
    ("non-ASCII", [SECTION, (I.mjITEM_BUTTON, "\u00e9")], ValueError, "ASCII"),
    ("11 sections", [SECTION] * 11, ValueError, r"mjMAXUISECT"),
    ("201 items", [SECTION] + [(I.mjITEM_BUTTON, "b")] * 201, ValueError, "mjMAXUIITEM"),
    ("no pdata", [SECTION, (I.mjITEM_CHECKINT, "c", 1)], TypeError, "edits a value"),
    ("pdata on a button", [SECTION, (I.mjITEM_BUTTON, "b", 1, np.zeros(1, np.int32))],
     TypeError, "has no data"),
    ("a list as pdata", [SECTION, (I.mjITEM_CHECKINT, "c", 1, [0])], TypeError,
     "NumPy array"),
    ("an int address", [SECTION, (I.mjITEM_CHECKINT, "c", 1, 12345)], TypeError,
     "NumPy array"),
    ("wrong dtype", [SECTION, (I.mjITEM_CHECKINT, "c", 1, np.zeros(1))], TypeError,
     "int32"),
    ("too small", [SECTION, (I.mjITEM_EDITNUM, "e", 1, np.zeros(2), "3")], ValueError,
     "24 bytes"),
    ("text too small", [SECTION, (I.mjITEM_EDITTXT, "t", 1, np.zeros(8, np.uint8))],
     ValueError, "40 bytes"),
    ("read-only", [SECTION, (I.mjITEM_SLIDERNUM, "s", 1,
                             np.frombuffer(b"\0" * 8), "0 1")], ValueError, "read-only"),
    ("strided", [SECTION, (I.mjITEM_EDITNUM, "s", 1, np.zeros(6)[::2], "3")], ValueError,
     "C-contiguous"),
    ("raw cffi pointer", [SECTION, (I.mjITEM_CHECKINT, "c", 1, ffi.cast("int *", 64))],
     TypeError, "ffi.new"),
    ("ctypes from_address", [SECTION, (I.mjITEM_CHECKINT, "c", 1,
                                       ctypes.c_int.from_address(64))], TypeError,
     "does not own"),
    ("slider without range", [SECTION, (I.mjITEM_SLIDERNUM, "s", 1, np.zeros(1), "x")],
     ValueError, "min max"),
    ("edit counts", [SECTION, (I.mjITEM_EDITNUM, "e", 1, np.zeros(7), "2 0 1")],
     ValueError, "range numbers"),
    ("bad shortcut", [SECTION, (I.mjITEM_BUTTON, "b", 1, None, "Xy")], ValueError,
     "shortcut"),
    ("empty choices", [SECTION, (I.mjITEM_RADIO, "r", 1, np.zeros(1, np.int32), "")],
     ValueError, "choices"),
    ("empty choice", [SECTION, (I.mjITEM_RADIO, "r", 1, np.zeros(1, np.int32), "a\n\nb")],
     ValueError, "1 to 38"),
    ("section state", [(I.mjITEM_SECTION, "s", 7)], ValueError, "section state"),
    ("negative state", [SECTION, (I.mjITEM_BUTTON, "b", -1)], ValueError, "item state"),
    ("MjuiDef with data type", [SECTION, mjcffi.MjuiDef()], None, None),
]


@pytest.mark.parametrize("label, defs, error, match", BAD, ids=[b[0] for b in BAD])
def test_bad_definitions_raise_and_leave_the_ui_as_it_was(label, defs, error, match):
    ui = _ui()
    mjcffi.mjui_add(ui, [(I.mjITEM_SECTION, "first", 1), (I.mjITEM_BUTTON, "b", 1)])
    before = ffi.buffer(ui._ptr, ffi.sizeof("mjUI"))[:]
    if error is None:            # a default MjuiDef is a separator: fine
        mjcffi.mjui_add(ui, defs)
        return
    with pytest.raises(error, match=match):
        mjcffi.mjui_add(ui, defs)
    assert ffi.buffer(ui._ptr, ffi.sizeof("mjUI"))[:] == before


def test_add_to_section_checks_the_section_and_the_room():
    ui = _ui()
    with pytest.raises(ValueError, match="before any section"):
        mjcffi.mjui_add(ui, [(I.mjITEM_BUTTON, "b")])
    mjcffi.mjui_add(ui, [SECTION] + [(I.mjITEM_BUTTON, "b")] * 199)
    with pytest.raises(ValueError, match="sections 0..0"):
        mjcffi.mjui_addToSection(ui, 1, [(I.mjITEM_BUTTON, "b")])
    with pytest.raises(ValueError, match="is a section"):
        mjcffi.mjui_addToSection(ui, 0, [SECTION])
    with pytest.raises(ValueError, match="mjMAXUIITEM"):
        mjcffi.mjui_addToSection(ui, 0, [(I.mjITEM_BUTTON, "b")] * 2)
    with pytest.raises(TypeError, match="sect must be an int"):
        mjcffi.mjui_addToSection(ui, None, [(I.mjITEM_BUTTON, "b")])
    with pytest.raises(TypeError, match="must be an MjUI"):
        mjcffi.mjui_add(ui._ptr, [SECTION])
    assert _nsect_nitem(ui) == (1, [199])


def test_drawing_calls_refuse_without_a_context_before_mujoco():
    ui, state, con = _ui(), mjcffi.MjuiState(), mjcffi.MjrContext()
    for call in (lambda: mjcffi.mjui_resize(ui, con),
                 lambda: mjcffi.mjui_update(-1, -1, ui, state, con),
                 lambda: mjcffi.mjui_event(ui, state, con),
                 lambda: mjcffi.mjui_render(ui, state, con)):
        with pytest.raises(ValueError, match="was not made by mjr_makeContext"):
            call()
    with pytest.raises(TypeError, match="must be an MjUI"):
        mjcffi.mjui_event(None, state, con)


# ------------------------------------------------------------ with OpenGL, in subprocesses

BACKENDS = ["egl", "osmesa"]
W, H = 900, 700


def _humanoid():
    import gymnasium
    return os.path.join(os.path.dirname(gymnasium.__file__), "envs/mujoco/assets/humanoid.xml")


def _offscreen(m):
    m.vis.global_.offwidth, m.vis.global_.offheight = W, H   # the offscreen buffer's size
    ctx = mjcffi.GLContext(W, H)
    ctx.make_current()
    con = mjcffi.MjrContext(m, mjcffi.mjtFontScale.mjFONTSCALE_100)
    mjcffi.mjr_setBuffer(mjcffi.mjtFramebuffer.mjFB_OFFSCREEN, con)
    return ctx, con


def _pixels(con):
    rgb = np.zeros((H, W, 3), np.uint8)
    mjcffi.mjr_readPixels(rgb, None, mjcffi.MjrRect(0, 0, W, H), con)
    return rgb


def _center(panels, rectid, section, item):
    """Window coordinates of the center of an item of a panel (y up)."""
    ui, rect = panels.uis[rectid], panels._state.rect[rectid]
    r = ui.sect[section].item[item].rect
    top = rect.bottom + rect.height - ui.height          # ui coordinates start here
    if ui.height > rect.height:                          # scrolled by ui.scroll
        top += ui.scroll
    return rect.left + r.left + r.width / 2, top + r.bottom + r.height / 2, r


def _mouse(state, kind, x, y, left):
    state.type, state.x, state.y = kind, x, y
    state.button, state.left = mjcffi.mjtButton.mjBUTTON_LEFT, left


def panels_scenario():
    import json

    from mjcffi.viewer._ui import Panels
    m = mjcffi.MjModel.from_xml_path(_humanoid())
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    ctx, con = _offscreen(m)
    panels = Panels(m, d)
    panels.resize(con, W, H)
    mjcffi.mjr_rectangle(mjcffi.MjrRect(0, 0, W, H), 0, 0, 0, 1)
    panels.render(con)
    rgb = _pixels(con)
    left, right = panels.uis[1].width, panels.uis[2].width
    out = {"left": float(rgb[:, :left].mean()), "right": float(rgb[:, W - right:].mean()),
           "middle": float(rgb[:, left + 5:W - right - 5].mean())}

    # click the pause checkbox: press and release at its center
    state = mjcffi.MjuiState()
    state.rect[0].width, state.rect[0].height = W, H
    x, y, _ = _center(panels, 1, 0, 0)
    out["paused_before"] = panels.paused
    _mouse(state, mjcffi.mjtEvent.mjEVENT_PRESS, x, y, 1)
    out["press_taken"] = panels.event(state)
    _mouse(state, mjcffi.mjtEvent.mjEVENT_RELEASE, x, y, 0)
    panels.event(state)
    out["paused_after"] = panels.paused
    out["actions"] = list(panels.actions)

    # drag the first control slider from its left end to its right end, scrolled down
    # to the Control section (the humanoid's joints fill more than the window)
    section = 1
    ui = panels.uis[2]
    ui.scroll = max(0, ui.height - H)
    x, y, r = _center(panels, 2, section, 0)
    low, high = m.actuator_ctrlrange[0]
    before = float(d.ctrl[0])
    _mouse(state, mjcffi.mjtEvent.mjEVENT_PRESS, x - r.width / 2 + 1, y, 1)
    panels.event(state)
    out["ctrl_before_sync"] = float(d.ctrl[0]) == before     # the UI edits its own buffer
    _mouse(state, mjcffi.mjtEvent.mjEVENT_MOVE, x + r.width / 2 - 1, y, 1)
    panels.event(state)
    _mouse(state, mjcffi.mjtEvent.mjEVENT_RELEASE, x + r.width / 2 - 1, y, 0)
    panels.event(state)
    panels.sync_to(m, d)
    out["ctrl"] = float(d.ctrl[0])
    out["ctrlrange"] = [float(low), float(high)]
    out["ctrl_changed_only"] = bool(np.all(np.asarray(d.ctrl)[1:] == 0))
    out["last_actions"] = panels.actions[-3:]

    # a mouse event over the 3D view is not the panels'
    _mouse(state, mjcffi.mjtEvent.mjEVENT_PRESS, W / 2, H / 2, 1)
    out["view_taken"] = panels.event(state)
    _mouse(state, mjcffi.mjtEvent.mjEVENT_RELEASE, W / 2, H / 2, 0)
    panels.event(state)
    panels.render(con)
    print(json.dumps(out))


@pytest.mark.parametrize("backend", BACKENDS)
def test_panels_draw_click_and_drag(backend):
    pytest.importorskip("gymnasium", reason="the humanoid model comes from gymnasium")
    out = _gl.run("tests.test_mjui", backend, "panels_scenario")
    assert out["left"] > 10 and out["right"] > 10, out      # the panels are drawn
    assert out["middle"] == 0, out                          # and nothing between them
    assert out["paused_before"] is False and out["paused_after"] is True, out
    assert out["press_taken"] is True and out["actions"] == ["pause"], out
    assert out["ctrl_before_sync"] is True, out
    low, high = out["ctrlrange"]
    assert high - (high - low) * 0.02 <= out["ctrl"] <= high, out
    assert out["ctrl_changed_only"] is True, out
    assert out["last_actions"][-1] == "ctrl", out
    assert out["view_taken"] is False, out


def tamper_scenario():
    """Writes into the mjUI from Python that would send MuJoCo astray, each refused."""
    import json
    m = mjcffi.MjModel.from_xml_string("<mujoco><worldbody/></mujoco>")
    ctx, con = _offscreen(m)
    ui = mjcffi.MjUI()
    ui.spacing, ui.color = mjcffi.mjui_themeSpacing(0), mjcffi.mjui_themeColor(0)
    ui.rectid = 1
    choice, value = np.zeros(1, np.int32), np.zeros(1)
    mjcffi.mjui_add(ui, [SECTION, (I.mjITEM_SELECT, "sel", 2, choice, "a\nb"),
                         (I.mjITEM_SLIDERNUM, "s", 2, value, "0 1"),
                         (I.mjITEM_EDITNUM, "e", 2, np.zeros(1), "1")])
    state = mjcffi.MjuiState()
    state.nrect = 2
    state.rect[0].width = state.rect[0].height = state.rect[1].height = 200
    mjcffi.mjui_resize(ui, con)
    state.rect[1].width = ui.width
    mjcffi.mjr_addAux(0, ui.width, ui.maxheight, ui.spacing.samples, con)
    out = {"ok": _gl.outcome(lambda: mjcffi.mjui_update(-1, -1, ui, state, con))}
    render = lambda: mjcffi.mjui_render(ui, state, con)       # noqa: E731
    item = ui.sect[0].item

    def attempt(name, edit, undo):
        edit()
        out[name] = _gl.outcome(render)
        undo()

    attempt("choice", lambda: choice.__setitem__(0, 7), lambda: choice.__setitem__(0, 0))
    attempt("type", lambda: setattr(item[1], "type", int(I.mjITEM_EDITTXT)),
            lambda: setattr(item[1], "type", int(I.mjITEM_SLIDERNUM)))
    attempt("nelem", lambda: setattr(item[2].edit, "nelem", 5),
            lambda: setattr(item[2].edit, "nelem", 1))
    attempt("mouse", lambda: setattr(ui, "mousesect", 5), lambda: setattr(ui, "mousesect", 0))
    attempt("rect", lambda: setattr(ui, "rectid", 3), lambda: setattr(ui, "rectid", 1))
    attempt("aux", lambda: setattr(ui, "auxid", 10), lambda: setattr(ui, "auxid", 0))
    attempt("name", lambda: setattr(item[0], "name", "\u00e9t\u00e9"),
            lambda: setattr(item[0], "name", "sel"))
    out["update_section"] = _gl.outcome(lambda: mjcffi.mjui_update(3, -1, ui, state, con))
    out["after"] = _gl.outcome(render)
    print(json.dumps(out))


@pytest.mark.parametrize("backend", BACKENDS)
def test_python_writes_that_would_send_mujoco_astray_are_refused(backend):
    out = _gl.run("tests.test_mjui", backend, "tamper_scenario")
    assert out.pop("ok") == "ok" and out.pop("after") == "ok", out
    expected = {"choice": "no index of its 2 choices", "type": "edits char",
                "nelem": "40 bytes", "mouse": "mousesect=5", "rect": "state.nrect=2",
                "aux": "mjNAUX", "name": "ASCII", "update_section": "section=3"}
    for key, text in expected.items():
        assert out[key].startswith(("ValueError", "TypeError")) and text in out[key], \
            (key, out[key])


def test_a_crash_prone_misuse_in_a_subprocess_raises_instead():
    """Without mjcffi's checks these would write through a NULL or freed pdata; here the
    process lives and says why."""
    code = (
        "import numpy as np, mjcffi\n"
        "from mjcffi import mjtItem as I\n"
        "ui = mjcffi.MjUI()\n"
        "for defs in ([(-1, 's', 1), (I.mjITEM_EDITTXT, 't', 1, np.zeros(1, np.uint8))],\n"
        "             [(-1, 's', 1), (I.mjITEM_CHECKINT, 'c', 1, None)]):\n"
        "    try: mjcffi.mjui_add(ui, defs)\n"
        "    except (TypeError, ValueError) as e: print(type(e).__name__)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["ValueError", "TypeError"]
