"""MjrContext and the mjr_* functions, drawing for real with an OpenGL context.

Each scenario runs in a subprocess with MUJOCO_GL set to its backend (EGL, and
OSMesa where installed): a missed check could crash the process, MUJOCO_GL is read
once per process, and this pytest process stays free of OpenGL libraries.  A
scenario prints one JSON line of what it saw; the assertions are here.  A backend
is skipped only when its system library is missing, naming the Debian package.
"""

import json
import os

import pytest

import mjcffi
from mjcffi import functions as F
from mjcffi import scenes
from tests import _gl
from tests._gl import outcome as _outcome

TIMEOUT = 300
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BACKENDS = ("egl", "osmesa")

# A textured plane and box, a mesh and a height field, seen from a fixed camera.
TEXTURED = """
<mujoco>
  <asset>
    <texture name="grid" type="2d" builtin="checker" width="32" height="32"
             rgb1="0.9 0.2 0.2" rgb2="0.2 0.3 0.9"/>
    <material name="grid" texture="grid" texrepeat="2 2"/>
    <mesh name="tet" vertex="0 0 0  0.2 0 0  0 0.2 0  0 0 0.2"/>
    <hfield name="bumps" nrow="4" ncol="4" size="0.3 0.3 0.1 0.02"/>
  </asset>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1"/>
    <camera name="top" pos="0 0 2.2"/>
    <geom type="plane" size="1 1 0.1" material="grid"/>
    <geom type="box" pos="0.4 0.4 0.1" size="0.1 0.1 0.1" material="grid"/>
    <geom type="mesh" mesh="tet" pos="-0.5 0.4 0" rgba="0.2 0.8 0.2 1"/>
    <geom type="hfield" hfield="bumps" pos="-0.4 -0.4 0.02" rgba="0.8 0.8 0.2 1"/>
  </worldbody>
</mujoco>
"""


def _run(backend, scenario):
    """Run the scenario, a function of this module, under MUJOCO_GL=backend; its JSON."""
    return _gl.run("tests.test_mjr", backend, scenario, timeout=TIMEOUT)


def _setup(xml, width=160, height=120, maxgeom=1000):
    """(m, d, ctx, con, scn): a model, its data forwarded, a current GLContext, an
    MjrContext on the offscreen buffer and a scene."""
    import mjcffi
    m = mjcffi.MjModel.from_xml_string(xml)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    ctx = mjcffi.GLContext(width, height)
    ctx.make_current()
    con = mjcffi.MjrContext(m, mjcffi.mjtFontScale.mjFONTSCALE_150)
    mjcffi.mjr_setBuffer(mjcffi.mjtFramebuffer.mjFB_OFFSCREEN, con)
    return m, d, ctx, con, mjcffi.MjvScene(m, maxgeom)


def _frame(m, d, con, scn, camera, width=160, height=120):
    """rgb, depth of one frame of `camera` (an MjvCamera)."""
    import numpy as np

    import mjcffi
    mjcffi.mjv_updateScene(m, d, mjcffi.MjvOption(), None, camera,
                           mjcffi.mjtCatBit.mjCAT_ALL, scn)
    viewport = mjcffi.MjrRect(0, 0, width, height)
    mjcffi.mjr_render(viewport, scn, con)
    rgb = np.zeros((height, width, 3), np.uint8)
    depth = np.zeros((height, width), np.float32)
    mjcffi.mjr_readPixels(rgb, depth, viewport, con)
    return rgb, depth


def _fixed(camid):
    import mjcffi
    cam = mjcffi.MjvCamera()
    cam.type, cam.fixedcamid = mjcffi.mjtCamera.mjCAMERA_FIXED, camid
    return cam


# ------------------------------------------------------------ no OpenGL context

def no_context_scenario():
    """Every mjr_* function with no OpenGL context current raises; MjrContext then says
    how to get one, and does not spoil the process for a context made afterwards."""
    import numpy as np

    import mjcffi
    m = mjcffi.MjModel.from_xml_string(scenes.DEFAULT)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    out = {}
    try:
        mjcffi.MjrContext(m, 150)
        out["make"] = "ok"
    except mjcffi.FatalError as exc:
        out["make"] = str(exc)
        out["make_notes"] = getattr(exc, "__notes__", [])
    textured = mjcffi.MjModel.from_xml_string(TEXTURED)      # one texture, mesh, hfield
    con, scn = mjcffi.MjrContext(), mjcffi.MjvScene(textured, 100)
    rect = mjcffi.MjrRect(0, 0, 10, 10)
    calls = _every_drawing_call(textured, con, scn, rect, np)
    out["calls"] = {name: _outcome(call) for name, call in calls.items()}
    out["not_drawing"] = {"mjr_findRect": F.mjr_findRect(5, 5, 1, rect)}
    ctx = mjcffi.GLContext(64, 48)
    ctx.make_current()
    con = mjcffi.MjrContext(m, 150)          # the failed attempt above spoiled nothing
    scn = mjcffi.MjvScene(m, 100)
    rgb, _ = _frame(m, d, con, scn, mjcffi.MjvCamera(), 64, 48)
    out["after"] = {"offWidth": con.offWidth, "mean": float(rgb.mean())}
    print(json.dumps(out))


def _every_drawing_call(m, con, scn, rect, np):
    rgb, depth = np.zeros((10, 10, 3), np.uint8), np.zeros((10, 10), np.float32)
    return {
        "mjr_render": lambda: F.mjr_render(rect, scn, con),
        "mjr_readPixels": lambda: F.mjr_readPixels(rgb, depth, rect, con),
        "mjr_drawPixels": lambda: F.mjr_drawPixels(rgb, depth, rect, con),
        "mjr_setBuffer": lambda: F.mjr_setBuffer(1, con),
        "mjr_restoreBuffer": lambda: F.mjr_restoreBuffer(con),
        "mjr_changeFont": lambda: F.mjr_changeFont(100, con),
        "mjr_addAux": lambda: F.mjr_addAux(0, 8, 8, 1, con),
        "mjr_setAux": lambda: F.mjr_setAux(0, con),
        "mjr_blitAux": lambda: F.mjr_blitAux(0, rect, 0, 0, con),
        "mjr_blitBuffer": lambda: F.mjr_blitBuffer(rect, rect, 1, 0, con),
        "mjr_resizeOffscreen": lambda: F.mjr_resizeOffscreen(20, 20, con),
        "mjr_uploadTexture": lambda: F.mjr_uploadTexture(m, con, 0),
        "mjr_uploadMesh": lambda: F.mjr_uploadMesh(m, con, 0),
        "mjr_uploadHField": lambda: F.mjr_uploadHField(m, con, 0),
        "mjr_text": lambda: F.mjr_text(0, "hi", con, 0.1, 0.1, 1, 1, 1),
        "mjr_overlay": lambda: F.mjr_overlay(0, 0, rect, "a", "b", con),
        "mjr_label": lambda: F.mjr_label(rect, 0, "a", 1, 1, 1, 1, 0, 0, 0, con),
        "mjr_figure": lambda: F.mjr_figure(rect, mjcffi.MjvFigure(), con),
        "mjr_maxViewport": lambda: F.mjr_maxViewport(con),
        "mjr_rectangle": lambda: F.mjr_rectangle(rect, 1, 0, 0, 1),
        "mjr_finish": lambda: F.mjr_finish(),
        "mjr_getError": lambda: F.mjr_getError(),
    }


@pytest.mark.parametrize("backend", BACKENDS)
def test_no_current_context_raises_and_says_how_to_get_one(backend):
    out = _run(backend, "no_context_scenario")
    assert "make a GLContext current first (mjcffi.GLContext(w, h).make_current())" \
        in out["make"]
    assert any("gladLoadGL error" in note for note in out["make_notes"])
    without = ("mjr_rectangle", "mjr_finish", "mjr_getError")
    for name, outcome in out["calls"].items():
        if name in without:
            assert outcome.startswith("FatalError") and "no OpenGL context is current" \
                in outcome, (name, outcome)
        else:
            assert outcome.startswith("ValueError") and "con was not made" in outcome, \
                (name, outcome)
    drawing = {name for name in F.NAMES if name.startswith("mjr_")} - {
        "mjr_defaultContext", "mjr_defaultRendererInfo", "mjr_getRendererInfo",
        "mjr_findRect", "mjr_makeContext", "mjr_freeContext"}
    assert set(out["calls"]) == drawing
    assert out["not_drawing"]["mjr_findRect"] == 0
    assert out["after"]["offWidth"] == 640 and out["after"]["mean"] > 0


def test_no_gl_library_in_this_process_refuses_before_mujoco():
    """This pytest process loads no OpenGL library: a context cannot even be tried."""
    m = mjcffi.MjModel.from_xml_string(scenes.DEFAULT)
    with pytest.raises(mjcffi.FatalError, match="make a GLContext current first|OpenGL "
                                                  "platform library"):
        mjcffi.MjrContext(m, 150)
    with pytest.raises(mjcffi.FatalError, match="no OpenGL context is current"):
        F.mjr_finish()
    with pytest.raises(ValueError, match="con was not made"):
        F.mjr_maxViewport(mjcffi.MjrContext())


# ------------------------------------------------------------ lifetimes

def lifetime_scenario():
    """MjrContext.free(), use after free, contexts released, freed or collected."""
    import gc

    import numpy as np

    import mjcffi
    m, d, ctx, con, scn = _setup(scenes.DEFAULT)
    out = {"repr_made": repr(con)[:60], "fields": [con.offWidth, con.offHeight,
                                                   con.fontScale, con.ntexture]}
    out["model_off"] = [m.vis.global_.offwidth, m.vis.global_.offheight]
    con.free()
    out["repr_freed"] = repr(con)[:40]
    out["free_twice"] = _outcome(con.free)
    out["after_free"] = _outcome(lambda: _frame(m, d, con, scn, mjcffi.MjvCamera()))
    out["freed_fields"] = [con.offWidth, con.nskin]
    # mjr_makeContext into the same MjrContext, then mjr_freeContext
    F.mjr_makeContext(m, con, 100)
    rgb, _ = _frame(m, d, con, scn, mjcffi.MjvCamera())
    out["remade"] = [con.fontScale, float(rgb.mean())]
    F.mjr_freeContext(con)
    out["freeContext"] = _outcome(lambda: F.mjr_setBuffer(1, con))
    # the GL context given up: no context current, then another one
    con = mjcffi.MjrContext(m, 150)
    other = mjcffi.GLContext(32, 32)
    with other.as_current():
        out["other_current"] = _outcome(lambda: F.mjr_setBuffer(1, con))
    ctx.free()                              # con's context is gone
    out["ctx_freed"] = _outcome(lambda: F.mjr_setBuffer(1, con))
    out["ctx_freed_rectangle"] = _outcome(lambda: F.mjr_rectangle(
        mjcffi.MjrRect(0, 0, 4, 4), 1, 1, 1, 1))
    out["free_after_ctx_freed"] = _outcome(con.free)
    # collected after its GL context was freed, with another context current
    third = mjcffi.GLContext(32, 32)
    third.make_current()
    kept = mjcffi.MjrContext(m, 150)
    out["collected"] = kept.offWidth
    fourth = mjcffi.GLContext(32, 32)
    fourth.make_current()
    third.free()
    del kept
    gc.collect()
    # a view of a collected context keeps its memory, freed when the view goes
    view = mjcffi.MjrContext(m, 150).fogRGBA
    gc.collect()
    out["view_after_collect"] = [float(x) for x in view]
    out["model_fog"] = [float(x) for x in m.vis.rgba.fog]
    del view
    gc.collect()
    # a context destroyed and its handle forgotten (what GLContext.free() is to call): an
    # MjrContext made in it is lost, even where a new context gets its address
    from mjcffi._support import mjr as _mjr
    fifth = mjcffi.GLContext(32, 32)
    fifth.make_current()
    lost = mjcffi.MjrContext(m, 150)
    handle = _mjr.current()[1]
    fifth.free()
    _mjr.forget_context(handle)
    sixth = mjcffi.GLContext(32, 32)
    sixth.make_current()
    out["same_address"] = _mjr.current()[1] == handle
    out["lost"] = _outcome(lambda: F.mjr_setBuffer(1, lost))
    out["lost_free"] = _outcome(lost.free)
    fourth.make_current()
    # a context made in `fourth` still draws after all that
    con = mjcffi.MjrContext(m, 150)
    F.mjr_setBuffer(1, con)
    rgb, depth = _frame(m, d, con, mjcffi.MjvScene(m, 1000), mjcffi.MjvCamera())
    out["still_draws"] = [float(rgb.mean()), float(np.asarray(depth).mean())]
    print(json.dumps(out))


@pytest.mark.parametrize("backend", BACKENDS)
def test_free_and_contexts_given_up_raise_never_crash(backend):
    out = _run(backend, "lifetime_scenario")
    assert out["repr_made"].startswith("<MjrContext (made in ")
    assert out["fields"][:2] == out["model_off"] and out["fields"][2] == 150
    assert out["repr_freed"].startswith("<MjrContext (freed)")
    assert out["free_twice"] == "ok"
    assert out["after_free"].startswith("ValueError") and "con was freed" in out["after_free"]
    assert out["freed_fields"] == [0, 0]
    assert out["remade"][0] == 100 and out["remade"][1] > 0
    assert out["freeContext"].startswith("ValueError: mjr_setBuffer: con was freed")
    assert out["other_current"].startswith("FatalError") and \
        "made in another OpenGL context" in out["other_current"]
    # GLContext.free() marks the MjrContexts made in it lost (_mjr.forget_context)
    assert out["ctx_freed"].startswith("FatalError: mjr_setBuffer: the OpenGL context con "
                                       "was made in has been freed")
    assert out["ctx_freed_rectangle"].startswith("FatalError")
    assert out["free_after_ctx_freed"] == "ok"
    assert out["view_after_collect"] == pytest.approx(out["model_fog"])
    assert out["collected"] == 640
    assert out["lost"].startswith("FatalError: mjr_setBuffer: the OpenGL context con was "
                                  "made in has been freed")
    assert out["lost_free"] == "ok"
    assert out["still_draws"][0] > 0


def threads_scenario():
    """A context drawn with on one thread and freed from another: no crash, and the
    drawing thread's next call raises."""
    import threading

    import mjcffi
    m = mjcffi.MjModel.from_xml_string(SKINNED)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    ctx = mjcffi.GLContext(64, 48)
    made, freed = threading.Event(), threading.Event()
    box, out = {}, {"frames": 0}

    def draw():
        ctx.make_current()
        con = box["con"] = mjcffi.MjrContext(m, 150)
        scn = mjcffi.MjvScene(m, 100)
        F.mjr_setBuffer(1, con)
        made.set()
        try:
            while True:
                _frame(m, d, con, scn, mjcffi.MjvCamera(), 64, 48)
                out["frames"] += 1
                if freed.is_set() and out["frames"] > 1000:
                    break
        except ValueError as exc:
            out["drawer"] = str(exc)
        ctx.free()

    worker = threading.Thread(target=draw)
    worker.start()
    made.wait(60)
    con = box["con"]
    out["from_main"] = _outcome(lambda: F.mjr_setBuffer(1, con))
    while out["frames"] < 3:
        pass
    con.free()                               # while the worker draws
    freed.set()
    worker.join(120)
    out["alive"] = worker.is_alive()
    out["kept_skin"] = con.nskin
    del con, box["con"]
    import gc
    gc.collect()                             # the kept skin arrays go now
    print(json.dumps(out))


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_context_freed_from_another_thread_while_drawing(backend):
    out = _run(backend, "threads_scenario")
    assert out["from_main"].startswith("FatalError: mjr_setBuffer: no OpenGL context")
    assert not out["alive"]
    assert out["drawer"].endswith("con was freed (MjrContext.free()): make a new MjrContext")
    assert out["kept_skin"] == 1


# ------------------------------------------------------------ mjr_readPixels, drawPixels

def pixels_scenario():
    """Shapes and dtypes mjr_readPixels takes; what it refuses, before MuJoCo writes."""
    import numpy as np

    import mjcffi
    m, d, ctx, con, scn = _setup(scenes.DEFAULT)
    rgb, depth = _frame(m, d, con, scn, mjcffi.MjvCamera())
    rect = mjcffi.MjrRect(0, 0, 160, 120)
    out = {"frame": [float(rgb.mean()), float(depth.min()), float(depth.max())]}
    flat = np.zeros(160 * 120 * 3, np.uint8)
    flat_depth = np.zeros(160 * 120, np.float32)
    F.mjr_readPixels(flat, flat_depth, rect, con)
    out["flat_same"] = bool(np.array_equal(flat.reshape(rgb.shape), rgb)
                            and np.array_equal(flat_depth.reshape(depth.shape), depth))
    bigger = np.zeros((200, 200, 3), np.uint8)
    F.mjr_readPixels(bigger, None, rect, con)
    out["bigger_same"] = bool(np.array_equal(bigger.reshape(-1)[:rgb.size], rgb.reshape(-1)))
    out["none_none"] = _outcome(lambda: F.mjr_readPixels(None, None, rect, con))

    block = np.full(160 * 120 * 3 + 64, 7, np.uint8)
    too_small = block[:160 * 120 * 3 - 1]
    dblock = np.full(160 * 120 + 16, 7, np.float32)
    bad = {
        "rgb_small": lambda: F.mjr_readPixels(too_small, None, rect, con),
        "depth_small": lambda: F.mjr_readPixels(None, dblock[:160 * 120 - 1], rect, con),
        "rgb_float": lambda: F.mjr_readPixels(np.zeros((120, 160, 3), np.float32), None,
                                              rect, con),
        "depth_f64": lambda: F.mjr_readPixels(None, np.zeros((120, 160)), rect, con),
        "rgb_strided": lambda: F.mjr_readPixels(np.zeros((240, 320, 3), np.uint8)[::2, ::2],
                                                None, rect, con),
        "rgb_readonly": lambda: F.mjr_readPixels(np.frombuffer(bytes(rgb.size), np.uint8),
                                                 None, rect, con),
        "rgb_list": lambda: F.mjr_readPixels([0] * rgb.size, None, rect, con),
        "negative": lambda: F.mjr_readPixels(None, None, mjcffi.MjrRect(0, 0, -1, 5), con),
        "huge": lambda: F.mjr_readPixels(np.zeros(3, np.uint8), None,
                                         mjcffi.MjrRect(0, 0, 65536, 65536), con),
        # left + width past INT_MAX: the driver crashed reading there
        "overflow": lambda: F.mjr_readPixels(np.zeros(200 * 10 * 3, np.uint8), None,
                                             mjcffi.MjrRect(2 ** 31 - 100, 0, 200, 10), con),
        "draw_small": lambda: F.mjr_drawPixels(np.zeros(10, np.uint8), None, rect, con),
        "draw_depth_small": lambda: F.mjr_drawPixels(None, np.zeros(10, np.float32), rect,
                                                     con),
    }
    out["bad"] = {name: _outcome(call) for name, call in bad.items()}
    out["untouched"] = bool((block == 7).all() and (dblock == 7).all())
    # con.readPixelFormat set to RGBA: four bytes a pixel, and the buffer must hold them
    con.readPixelFormat = 0x1908
    out["rgba_in_rgb"] = _outcome(lambda: F.mjr_readPixels(rgb.copy(), None, rect, con))
    rgba = np.zeros((120, 160, 4), np.uint8)
    F.mjr_readPixels(rgba, None, rect, con)
    out["rgba_matches"] = bool(np.array_equal(rgba[..., :3], rgb))
    con.readPixelFormat = 0x1234
    out["unknown_format"] = _outcome(lambda: F.mjr_readPixels(rgba, None, rect, con))
    con.readPixelFormat = 0x1907
    # drawPixels writes what readPixels reads back, from (h, w, 3) or flat input (after
    # a 2D call: mjr_render leaves depth testing on, which would hide the drawn pixels)
    F.mjr_rectangle(rect, 0, 0, 0, 1)
    pattern = np.zeros((120, 160, 3), np.uint8)
    pattern[:60] = (10, 200, 30)
    F.mjr_drawPixels(pattern, None, rect, con)
    back = np.zeros_like(pattern)
    F.mjr_readPixels(back, None, rect, con)
    out["draw_read"] = bool(np.array_equal(back, pattern))
    F.mjr_drawPixels(list(pattern.reshape(-1)), None, rect, con)     # converted input
    out["draw_list"] = "ok"
    print(json.dumps(out))


@pytest.mark.parametrize("backend", BACKENDS)
def test_read_pixels_shapes_dtypes_and_sizes(backend):
    out = _run(backend, "pixels_scenario")
    assert out["frame"][0] > 0 and out["frame"][1] < out["frame"][2] <= 1.0
    assert out["flat_same"] and out["bigger_same"] and out["none_none"] == "ok"
    bad = out["bad"]
    assert bad["rgb_small"].startswith("ArgumentError: rgb buffer is too small for viewport")
    assert bad["depth_small"].startswith("ArgumentError: depth buffer is too small")
    assert bad["rgb_float"].startswith("ArgumentError: rgb must be") and "uint8" in \
        bad["rgb_float"]
    assert "float32" in bad["depth_f64"]
    assert bad["rgb_strided"] == "ArgumentError: rgb buffer must be C-contiguous"
    assert "read-only" in bad["rgb_readonly"]
    assert bad["rgb_list"].startswith("ArgumentError: rgb must be a writable NumPy array")
    assert bad["negative"] == "ValueError: viewport width and height must be non-negative"
    assert bad["huge"].startswith("ArgumentError: rgb buffer is too small")
    assert bad["overflow"].startswith("ValueError: viewport: left + width and bottom + "
                                      "height must fit in a C int")
    assert bad["draw_small"].startswith("ArgumentError: rgb buffer is too small")
    assert bad["draw_depth_small"].startswith("ArgumentError: depth buffer is too small")
    assert out["untouched"], "MuJoCo wrote into a buffer refused as too small"
    assert out["rgba_in_rgb"].startswith("ArgumentError: rgb buffer is too small")
    assert out["rgba_matches"]
    assert out["unknown_format"].startswith("ValueError: con.readPixelFormat=0x1234")
    assert out["draw_read"] and out["draw_list"] == "ok"


# ------------------------------------------------------------ pixel identity

_GYM_MODELS = ("hopper.xml", "ant.xml")


def identity_scenario():
    """The same frames from mjcffi and from the official bindings, in one process, one
    OpenGL context: rgb and depth, byte for byte."""
    import numpy as np

    import mujoco

    import mjcffi
    models = [("default", scenes.DEFAULT, None)]
    try:
        import gymnasium
        assets = os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets")
        models += [(name, None, os.path.join(assets, name)) for name in _GYM_MODELS]
    except ImportError:
        pass
    ctx = mjcffi.GLContext(200, 150)
    ctx.make_current()
    rect_ours, rect_theirs = mjcffi.MjrRect(0, 0, 200, 150), mujoco.MjrRect(0, 0, 200, 150)
    out = {}
    for name, xml, path in models:
        ours_m = mjcffi.MjModel.from_xml_string(xml) if xml else \
            mjcffi.MjModel.from_xml_path(path)
        theirs_m = mujoco.MjModel.from_xml_string(xml) if xml else \
            mujoco.MjModel.from_xml_path(path)
        ours_d, theirs_d = mjcffi.MjData(ours_m), mujoco.MjData(theirs_m)
        for data, model, lib in ((ours_d, ours_m, mjcffi), (theirs_d, theirs_m, mujoco)):
            data.qpos[:] = model.qpos0 + 0.05 * np.sin(np.arange(model.nq))
            lib.mj_forward(model, data)
        ours_con = mjcffi.MjrContext(ours_m, 150)
        theirs_con = mujoco.MjrContext(theirs_m, 150)
        mjcffi.mjr_setBuffer(1, ours_con)
        mujoco.mjr_setBuffer(1, theirs_con)
        ours_scn, theirs_scn = mjcffi.MjvScene(ours_m, 2000), mujoco.MjvScene(theirs_m, 2000)
        same = []
        for view in range(3):
            frames = []
            for lib, m, d, scn, con, rect in (
                    (mjcffi, ours_m, ours_d, ours_scn, ours_con, rect_ours),
                    (mujoco, theirs_m, theirs_d, theirs_scn, theirs_con, rect_theirs)):
                cam = lib.MjvCamera()
                if view == 1:
                    cam.lookat[:] = (0, 0, 0.5)
                    cam.distance, cam.azimuth, cam.elevation = 3.0, 120.0, -25.0
                elif view == 2:
                    cam.type = lib.mjtCamera.mjCAMERA_TRACKING
                    cam.trackbodyid, cam.distance = 1, 2.0
                lib.mjv_updateScene(m, d, lib.MjvOption(), None, cam,
                                    lib.mjtCatBit.mjCAT_ALL, scn)
                lib.mjr_setBuffer(1, con)    # two contexts share the OpenGL context's binding
                lib.mjr_render(rect, scn, con)
                rgb = np.zeros((150, 200, 3), np.uint8)
                depth = np.zeros((150, 200), np.float32)
                lib.mjr_readPixels(rgb, depth, rect, con)
                frames.append((rgb, depth))
            (rgb1, depth1), (rgb2, depth2) = frames
            same.append([bool(np.array_equal(rgb1, rgb2)), bool(np.array_equal(depth1, depth2)),
                         float(rgb1.std()), int(np.count_nonzero(rgb1 != rgb2))])
        out[name] = same
        ours_con.free()
        theirs_con.free()
    print(json.dumps(out))


@pytest.mark.parametrize("backend", BACKENDS)
def test_frames_are_pixel_identical_to_the_official_bindings(backend):
    out = _run(backend, "identity_scenario")
    assert "default" in out
    for name, views in out.items():
        for view, (rgb_same, depth_same, std, differ) in enumerate(views):
            assert std > 1.0, (name, view, "a blank frame proves nothing")
            assert rgb_same and depth_same, (name, view, f"{differ} bytes differ")


# ------------------------------------------------------------ uploads

def upload_scenario():
    """Edits to the model show after an upload, and the original data restores the frame;
    bad ids and a model of other sizes raise."""
    import numpy as np

    import mjcffi
    m, d, ctx, con, scn = _setup(TEXTURED)
    cam = _fixed(0)
    first, _ = _frame(m, d, con, scn, cam)
    out = {}
    original = m.tex_data.copy()
    m.tex_data[:] = 255 - original
    out["edited_before_upload"] = bool(np.array_equal(_frame(m, d, con, scn, cam)[0], first))
    F.mjr_uploadTexture(m, con, 0)
    edited, _ = _frame(m, d, con, scn, cam)
    out["texture_changed"] = int(np.count_nonzero(edited != first))
    m.tex_data[:] = original
    F.mjr_uploadTexture(m, con, 0)
    out["texture_restored"] = bool(np.array_equal(_frame(m, d, con, scn, cam)[0], first))
    heights = m.hfield_data.copy()
    m.hfield_data[:] = 1.0
    F.mjr_uploadHField(m, con, 0)
    out["hfield_changed"] = int(np.count_nonzero(_frame(m, d, con, scn, cam)[0] != first))
    m.hfield_data[:] = heights
    F.mjr_uploadHField(m, con, 0)
    vert = m.mesh_vert.copy()
    m.mesh_vert[:] *= 2.0
    F.mjr_uploadMesh(m, con, 0)
    out["mesh_changed"] = int(np.count_nonzero(_frame(m, d, con, scn, cam)[0] != first))
    m.mesh_vert[:] = vert
    F.mjr_uploadMesh(m, con, 0)
    out["all_restored"] = bool(np.array_equal(_frame(m, d, con, scn, cam)[0], first))
    bad = {}
    for func, count in ((F.mjr_uploadTexture, m.ntex), (F.mjr_uploadMesh, m.nmesh),
                        (F.mjr_uploadHField, m.nhfield)):
        for value in (-1, count, 2 ** 31 - 1, -2 ** 31):
            bad[f"{func.__name__}({value})"] = _outcome(lambda: func(m, con, value))
    out["bad_ids"] = bad
    other = mjcffi.MjModel.from_xml_string(
        "<mujoco><asset><mesh name='a' vertex='0 0 0 1 0 0 0 1 0 0 0 1'/><mesh name='b' "
        "vertex='0 0 0 2 0 0 0 2 0 0 0 2'/></asset><worldbody><geom type='mesh' mesh='a'/>"
        "<geom type='mesh' mesh='b'/></worldbody></mujoco>")
    out["other_model"] = _outcome(lambda: F.mjr_uploadMesh(other, con, 0))
    print(json.dumps(out))


@pytest.mark.parametrize("backend", BACKENDS)
def test_uploads_show_model_edits_and_restore_them(backend):
    out = _run(backend, "upload_scenario")
    assert out["edited_before_upload"], "the frame changed before the upload"
    assert out["texture_changed"] > 1000
    assert out["texture_restored"]
    assert out["hfield_changed"] > 0 and out["mesh_changed"] > 0
    assert out["all_restored"]
    for call, outcome in out["bad_ids"].items():
        assert outcome.startswith("IdError") and "is out of range" in outcome, (call, outcome)
    assert out["other_model"].startswith("ValueError: con was made for a model of other sizes")


# ------------------------------------------------------------ what mjr_render follows

SKINNED = """
<mujoco>
  <worldbody>
    <light pos="0 0 3"/>
    <body name="box" pos="0 0 1">
      <freejoint/>
      <geom type="sphere" size="0.1"/>
    </body>
  </worldbody>
  <deformable>
    <skin name="tri" vertex="0 0 0  0.2 0 0  0 0.2 0" face="0 1 2">
      <bone body="box" bindpos="0 0 0" bindquat="1 0 0 0" vertid="0 1 2" vertweight="1 1 1"/>
    </skin>
  </deformable>
</mujoco>
"""


FLEX = """
<mujoco>
  <worldbody>
    <light pos="0 0 3"/>
    <flexcomp name="cloth" type="grid" count="3 3 1" spacing=".1 .1 .1" pos="0 0 1" dim="2"
              radius=".01"/>
  </worldbody>
</mujoco>
"""


def scene_scenario():
    """A scene whose contents point past the scene's or the context's buffers is refused."""
    import mjcffi
    m, d, ctx, con, scn = _setup(SKINNED)
    rect = mjcffi.MjrRect(0, 0, 160, 120)
    mjcffi.mjv_updateScene(m, d, mjcffi.MjvOption(), None, mjcffi.MjvCamera(),
                           mjcffi.mjtCatBit.mjCAT_ALL, scn)
    out = {"good": _outcome(lambda: F.mjr_render(rect, scn, con))}
    skin = next(i for i in range(scn.ngeom) if scn.geoms[i].type == mjcffi.mjtGeom.mjGEOM_SKIN)

    def tampered(edit, undo):
        edit()
        try:
            return _outcome(lambda: F.mjr_render(rect, scn, con))
        finally:
            undo()

    geom = scn.geoms[0]
    out["matid"] = tampered(lambda: setattr(geom, "matid", 5000),
                            lambda: setattr(geom, "matid", -1))
    out["texid"] = tampered(lambda: setattr(geom, "texid", 10 ** 6),
                            lambda: setattr(geom, "texid", -1))
    sg = scn.geoms[skin]
    out["skin_objid"] = tampered(lambda: setattr(sg, "objid", 7), lambda: setattr(sg, "objid", 0))
    vertadr = int(scn.skinvertadr[0])
    out["skinvertadr"] = tampered(lambda: scn.skinvertadr.__setitem__(0, 10 ** 6),
                                  lambda: scn.skinvertadr.__setitem__(0, vertadr))
    facenum = int(scn.skinfacenum[0])
    out["skinfacenum"] = tampered(lambda: scn.skinfacenum.__setitem__(0, 10 ** 6),
                                  lambda: scn.skinfacenum.__setitem__(0, facenum))
    label = bytes(ffi_label(geom))
    out["label"] = tampered(lambda: set_label(geom, b"x" * 100), lambda: set_label(geom, label))
    out["good_again"] = _outcome(lambda: F.mjr_render(rect, scn, con))
    # a context for a model without skins cannot draw this scene's skin
    plain = mjcffi.MjModel.from_xml_string(scenes.DEFAULT)
    out["skinless_context"] = _outcome(lambda: F.mjr_render(
        rect, scn, mjcffi.MjrContext(plain, 150)))
    # a viewport larger than the offscreen buffer: OpenGL clips it
    big = mjcffi.MjrRect(0, 0, 4000, 3000)
    out["big_viewport"] = _outcome(lambda: F.mjr_render(big, scn, con))
    # flexes: a scene not yet filled holds garbage face counts; edges index vertices
    fm = mjcffi.MjModel.from_xml_string(FLEX)
    fd = mjcffi.MjData(fm)
    mjcffi.mj_forward(fm, fd)
    fcon, fscn = mjcffi.MjrContext(fm, 150), mjcffi.MjvScene(fm, 100)
    fscn.flexfaceused[0] = 10 ** 6              # what mjv_makeScene may leave there
    out["flex_unfilled"] = _outcome(lambda: F.mjr_render(rect, fscn, fcon))
    opt = mjcffi.MjvOption()
    opt.flags[mjcffi.mjtVisFlag.mjVIS_FLEXVERT] = 1
    opt.flags[mjcffi.mjtVisFlag.mjVIS_FLEXEDGE] = 1
    mjcffi.mjv_updateScene(fm, fd, opt, None, mjcffi.MjvCamera(), mjcffi.mjtCatBit.mjCAT_ALL,
                           fscn)
    out["flex_good"] = _outcome(lambda: F.mjr_render(rect, fscn, fcon))
    edge = int(fscn.flexedge[1])
    fscn.flexedge[1] = 10 ** 6
    out["flex_edge"] = _outcome(lambda: F.mjr_render(rect, fscn, fcon))
    fscn.flexedge[1] = edge
    out["flex_good_again"] = _outcome(lambda: F.mjr_render(rect, fscn, fcon))
    print(json.dumps(out))


def ffi_label(geom):
    from mjcffi._support.library import ffi
    return ffi.buffer(geom._ptr.label)


def set_label(geom, raw):
    from mjcffi._support.library import ffi
    ffi.memmove(geom._ptr.label, raw, len(raw))


@pytest.mark.parametrize("backend", BACKENDS)
def test_render_refuses_scenes_that_point_past_their_buffers(backend):
    out = _run(backend, "scene_scenario")
    assert out["good"] == "ok" and out["good_again"] == "ok"
    expected = {"matid": "matid=5000 is past", "texid": "uses texture 1000000",
                "skin_objid": "is skin 7", "skinvertadr": "skinvertadr",
                "skinfacenum": "skinfacenum=1000000", "label": "label has no terminating NUL"}
    for name, text in expected.items():
        assert out[name].startswith("ValueError: mjr_render:") and text in out[name], \
            (name, out[name])
    assert out["skinless_context"].startswith("ValueError") and "skins" in \
        out["skinless_context"]
    assert out["big_viewport"] == "ok"
    assert "flexfaceused" in out["flex_unfilled"] and out["flex_unfilled"].startswith(
        "ValueError: mjr_render: flex 0")
    assert out["flex_good"] == "ok" and out["flex_good_again"] == "ok"
    assert out["flex_edge"].startswith("ValueError: mjr_render: flex 0: edge")


# ------------------------------------------------------------ text, figures, enums

def drawing_scenario():
    """2D drawing: rectangles, text, overlays, labels and figures draw, the arguments
    MuJoCo follows unchecked are refused, and enum values MuJoCo handles are taken."""
    import numpy as np

    import mjcffi
    m, d, ctx, con, scn = _setup(scenes.DEFAULT)
    full = mjcffi.MjrRect(0, 0, 160, 120)
    F.mjr_rectangle(full, 0, 0, 0, 1)
    F.mjr_rectangle(mjcffi.MjrRect(10, 20, 30, 40), 0, 0, 1, 1)
    rgb = np.zeros((120, 160, 3), np.uint8)
    F.mjr_readPixels(rgb, None, full, con)
    expected = np.zeros_like(rgb)
    expected[20:60, 10:40, 2] = 255
    out = {"rectangle": bool(np.array_equal(rgb, expected))}
    F.mjr_rectangle(full, 0, 0, 0, 1)
    F.mjr_text(mjcffi.mjtFont.mjFONT_BIG, "Hello", con, 0.1, 0.5, 1, 1, 1)
    F.mjr_overlay(0, mjcffi.mjtGridPos.mjGRID_TOPLEFT, full, "left", "right", con)
    F.mjr_label(mjcffi.MjrRect(0, 0, 60, 20), 0, "label", 0.2, 0.2, 0.2, 1, 1, 1, 1, con)
    fig = mjcffi.MjvFigure()
    fig.linepnt[0] = 3
    fig.linedata[0][:6] = (0, 0, 1, 1, 2, 0)
    F.mjr_figure(mjcffi.MjrRect(80, 0, 80, 60), fig, con)
    F.mjr_readPixels(rgb, None, full, con)
    out["drawn"] = int(np.count_nonzero(rgb))
    out["maxViewport"] = list(map(int, (F.mjr_maxViewport(con).width,
                                        F.mjr_maxViewport(con).height)))
    out["getError"] = F.mjr_getError()
    out["finish"] = _outcome(F.mjr_finish)
    out["aux"] = _outcome(lambda: (F.mjr_addAux(0, 32, 32, 0, con), F.mjr_setAux(0, con),
                                   F.mjr_restoreBuffer(con), F.mjr_blitAux(0, full, 0, 0, con)))
    out["resize"] = _outcome(lambda: F.mjr_resizeOffscreen(200, 100, con))
    out["resized"] = [con.offWidth, con.offHeight]
    info = mjcffi.MjrRendererInfo()
    F.mjr_getRendererInfo(info)
    out["info"] = [info.renderer, info.backend]
    bad = {
        "text_unicode": lambda: F.mjr_text(2, "héllo", con, 0.1, 0.1, 1, 1, 1),
        "label_unicode": lambda: F.mjr_label(full, 2, "\u00ff", 1, 1, 1, 1, 0, 0, 0, con),
        "overlay_line": lambda: F.mjr_overlay(0, 0, full, "x" * 500, None, con),
        "overlay2_line": lambda: F.mjr_overlay(0, 0, full, "a", "y" * 600, con),
        "aux_index": lambda: F.mjr_setAux(10, con),
        "resize_negative": lambda: F.mjr_resizeOffscreen(-1, 80, con),
    }
    out["overlay_none"] = _outcome(lambda: F.mjr_overlay(0, 0, full, "one column", None, con))
    out["overlay_broken_long"] = _outcome(lambda: F.mjr_overlay(
        0, 0, full, ("x" * 100 + "\n") * 6, None, con))
    for name, edit in (("linepnt", lambda f: f.linepnt.__setitem__(3, 5000)),
                       ("linepnt_negative", lambda f: f.linepnt.__setitem__(3, -1)),
                       # MjvFigure refuses it; a raw write does not
                       ("legendoffset", lambda f: setattr(f._ptr, "legendoffset", -5)),
                       ("xformat", lambda f: _set_chars(f._ptr.xformat, b"%s")),
                       ("yformat_star", lambda f: _set_chars(f._ptr.yformat, b"%*f")),
                       ("xformat_two", lambda f: _set_chars(f._ptr.xformat, b"%f %f")),
                       ("xlabel", lambda f: _set_chars(f._ptr.xlabel, b"z" * 100))):
        fig = mjcffi.MjvFigure()
        edit(fig)
        bad["figure_" + name] = (lambda fig: lambda: F.mjr_figure(full, fig, con))(fig)
    out["bad"] = {name: _outcome(call) for name, call in bad.items()}
    # values outside their enum: MuJoCo handles them, and the official bindings take
    # them (tests/test_enum_strictness.py); an unknown fontscale is MuJoCo's FatalError
    out["enum_ints"] = {name: _outcome(call) for name, call in {
        "font": lambda: F.mjr_text(7, "hi", con, 0.1, 0.1, 1, 1, 1),
        "gridpos": lambda: F.mjr_overlay(0, 9, full, "a", None, con),
        "framebuffer": lambda: F.mjr_setBuffer(2, con),
        "fontscale": lambda: F.mjr_changeFont(77, con),
        "fontscale_again": lambda: F.mjr_changeFont(150, con)}.items()}
    F.mjr_setBuffer(mjcffi.mjtFramebuffer.mjFB_OFFSCREEN, con)
    fig = mjcffi.MjvFigure()
    _set_chars(fig._ptr.xformat, b"%.1f%%")
    out["percent_format"] = _outcome(lambda: F.mjr_figure(full, fig, con))
    print(json.dumps(out))


def _set_chars(array, raw):
    from mjcffi._support.library import ffi
    ffi.memmove(array, raw + b"\0" * (len(array) - len(raw)) if len(raw) < len(array)
                else raw[:len(array)], len(array))


@pytest.mark.parametrize("backend", BACKENDS)
def test_2d_drawing_and_the_arguments_mujoco_follows(backend):
    out = _run(backend, "drawing_scenario")
    assert out["rectangle"], "mjr_rectangle did not draw the expected blue rectangle"
    assert out["drawn"] > 500
    assert out["maxViewport"] == [640, 480]
    assert out["getError"] == 0 and out["finish"] == "ok" and out["aux"] == "ok"
    assert out["resize"] == "ok" and out["resized"] == [200, 100]
    assert out["info"] == ["classic", "opengl"]
    assert out["overlay_broken_long"] == "ok" and out["overlay_none"] == "ok"
    assert out["percent_format"] == "ok"
    expected = {
        "text_unicode": "ValueError: txt must be ASCII",
        "label_unicode": "ValueError: txt must be ASCII",
        "overlay_line": "ValueError: overlay: a line of 500",
        "overlay2_line": "ValueError: overlay2: a line of 500",
        "aux_index": "FatalError: Invalid aux buffer index",
        "resize_negative": "ValueError: width must not be negative",
        "figure_linepnt": "ValueError: fig.linepnt[3]=5000 is outside",
        "figure_linepnt_negative": "ValueError: fig.linepnt[3]=-1 is outside",
        "figure_legendoffset": "ValueError: fig.legendoffset=-5",
        "figure_xformat": "ValueError: fig.xformat=b'%s' must be a printf format",
        "figure_yformat_star": "ValueError: fig.yformat=b'%*f'",
        "figure_xformat_two": "ValueError: fig.xformat=b'%f %f'",
        "figure_xlabel": "ValueError: fig.xlabel has no terminating NUL",
    }
    for name, text in expected.items():
        assert out["bad"][name].startswith(text), (name, out["bad"][name])
    assert out["enum_ints"] == {"font": "ok", "gridpos": "ok", "framebuffer": "ok",
                                "fontscale": "FatalError: Invalid fontscale",
                                "fontscale_again": "ok"}


# ------------------------------------------------------------ without OpenGL at all

def test_default_context_fields_are_readable_and_its_repr_says_so():
    con = mjcffi.MjrContext()
    assert repr(con).startswith("<MjrContext (default) ")
    assert con.offWidth == 0 and con.glInitialized == 0 and con.fogRGBA.shape == (4,)
    assert con.charWidth.shape == (127,)
    con.free()                                   # nothing to free: fine, as official
    with pytest.raises(TypeError, match="together"):
        mjcffi.MjrContext(mjcffi.MjModel.from_xml_string(scenes.DEFAULT))


def test_a_raw_context_pointer_is_refused():
    con = mjcffi.MjrContext()
    with pytest.raises(TypeError, match="must be an MjrContext, not a raw mjrContext pointer"):
        F.mjr_setBuffer(1, con._ptr)


def test_mjui_functions_refuse_none_for_their_ui():
    import inspect
    for name in ("mjui_resize", "mjui_update", "mjui_event", "mjui_render"):
        function = getattr(F, name)
        with pytest.raises(TypeError):
            function(*([None] * len(inspect.signature(function).parameters)))


def test_a_wrong_scalar_is_named_before_the_context_is_blamed():
    con, rect = mjcffi.MjrContext(), mjcffi.MjrRect(0, 0, 4, 4)
    with pytest.raises(TypeError, match=r"mjr_text\(\): x must be a number"):
        F.mjr_text(0, "hi", con, "left", 0.1, 1, 1, 1)
    with pytest.raises(ValueError, match=r"mjr_addAux\(\): width=.* does not fit in a C int"):
        F.mjr_addAux(0, 2 ** 40, 8, 0, con)
    with pytest.raises(TypeError, match=r"mjr_rectangle\(\): a must be a number"):
        F.mjr_rectangle(rect, 1, 1, 1, None)
    with pytest.raises(ValueError, match="con was not made"):       # all arguments right
        F.mjr_addAux(0, 8, 8, 0, con)


def test_forget_context_may_run_while_the_release_lock_is_held():
    # a garbage collection inside make_context's locked block can run an old
    # GLContext.__del__, whose forget_context takes the lock again: no deadlock
    import threading

    from mjcffi._support import mjr as _mjr
    done = []

    def run():
        with _mjr._release_lock:
            _mjr.forget_context(0x12345)
        done.append(True)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(10)
    assert done == [True]
