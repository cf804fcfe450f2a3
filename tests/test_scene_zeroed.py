"""A scene mjcffi makes starts zeroed (issue 36, item 4).

MuJoCo's mjv_makeScene mallocs the geom buffer (and geomorder, and the flex and
skin buffers that mjv_updateScene fills later) and leaves them as the heap had
them.  The official bindings do no more: `mujoco.MjvScene(m, maxgeom)` calls
mjv_makeScene, so its geoms past ngeom hold whatever a freed block left there,
and are zeros only when the allocator happened to hand out fresh memory.  A
client that fills a marker geom field by field (`scn.geoms[scn.ngeom]`, without
mjv_initGeom) and never sets matid then draws with a leftover matid (0x55xx,
part of a free-list pointer), which mjcffi's mjr_render check refuses.  mjcffi
zeroes those buffers whenever it makes a scene (the MjvScene constructor, its
mjv_makeScene, the Renderer's scene), so such a client sees the same scene every
run.

The heap is churned first: scenes of the same sizes are made, filled with 0x55
bytes and freed, so that the new scene's blocks are reused ones.  Drawing runs in
a subprocess under EGL (and OSMesa where installed), as in tests/test_mjr.py.
"""

import gc
import json

import numpy as np
import pytest

import mjcffi
from mjcffi._support.library import ffi
from tests import _gl
from tests._gl import outcome as _outcome
from tests.test_mjr import FLEX, SKINNED

BACKENDS = ("egl", "osmesa")
TIMEOUT = 300

# A grey floor under a camera looking straight down from 3 m; nothing red.
FLOOR = """
<mujoco>
  <statistic extent="1"/>
  <worldbody>
    <light pos="0 0 4"/>
    <camera name="above" pos="0 0 3"/>
    <geom type="plane" size="2 2 0.1" rgba="0.5 0.5 0.5 1"/>
  </worldbody>
</mujoco>
"""

# the buffers that mjv_makeScene allocates and leaves unset
_UNSET = ("geoms", "geomorder", "flexfaceused", "flexvert", "flexface", "flexnormal",
          "flextexcoord", "skinvert", "skinnormal")


def _bytes(scn, name):
    """The raw bytes of scene buffer `name` (a writable uint8 view), empty if none."""
    c = scn._ptr
    pointer = getattr(c, name)
    if pointer == ffi.NULL:
        return np.zeros(0, np.uint8)
    if name in ("geoms", "geomorder"):
        count = c.maxgeom
    else:
        count = getattr(scn, name).size
    size = count * ffi.sizeof(ffi.typeof(pointer).item)
    return np.frombuffer(ffi.buffer(pointer, size), np.uint8) if size else np.zeros(0, np.uint8)


def churn(model, maxgeom, rounds=3, count=20):
    """Make, fill with 0x55 bytes and free many scenes like MjvScene(model, maxgeom), so
    that the next scene's buffers are likely blocks freed here."""
    for _ in range(rounds):
        scenes = [mjcffi.MjvScene(model, maxgeom) for _ in range(count)]
        for scn in scenes:
            for name in _UNSET:
                _bytes(scn, name)[:] = 0x55
        del scenes, scn
        gc.collect()


def _nonzero(scn):
    """{buffer: count of nonzero bytes} over the unset buffers of `scn`; {} if all zero."""
    counts = {name: int(np.count_nonzero(_bytes(scn, name))) for name in _UNSET}
    return {name: n for name, n in counts.items() if n}


# ------------------------------------------------------------ no OpenGL

@pytest.mark.parametrize("maxgeom", [1, 10, 1000, 10000])
def test_constructor_zeroes_geoms_after_heap_churn(maxgeom):
    m = mjcffi.MjModel.from_xml_string(FLOOR)
    churn(m, maxgeom)
    scn = mjcffi.MjvScene(m, maxgeom)
    assert _bytes(scn, "geoms").size == maxgeom * ffi.sizeof("mjvGeom")
    assert _nonzero(scn) == {}
    assert scn.geoms[maxgeom - 1].matid == 0 and scn.geoms[0].label == ""


def test_mjv_makeScene_zeroes_a_remade_scene():
    m = mjcffi.MjModel.from_xml_string(FLOOR)
    churn(m, 500)
    scn = mjcffi.MjvScene()
    mjcffi.mjv_makeScene(m, scn, 500)
    assert scn.maxgeom == 500 and _nonzero(scn) == {}
    # filled, then made again: the new buffers are zeroed too
    _bytes(scn, "geoms")[:] = 0x55
    churn(m, 500)
    mjcffi.mjv_makeScene(m, scn, 500)
    assert _nonzero(scn) == {}


@pytest.mark.parametrize("xml", [FLEX, SKINNED], ids=["flex", "skin"])
def test_flex_and_skin_buffers_are_zeroed_and_model_copies_kept(xml):
    m = mjcffi.MjModel.from_xml_string(xml)
    churn(m, 50)
    scn = mjcffi.MjvScene(m, 50)
    assert _nonzero(scn) == {}
    # what MuJoCo copies from the model stays as MuJoCo set it
    if m.nflex:
        assert _bytes(scn, "flexvert").size and _bytes(scn, "flexface").size
        np.testing.assert_array_equal(scn.flexvertnum, m.flex_vertnum)
        np.testing.assert_array_equal(scn.flexedgeadr, m.flex_edgeadr)
        np.testing.assert_array_equal(scn.flexedge, m.flex_edge.ravel())
        assert scn.flexfacenum[0] > 0 and scn.flexfaceadr[0] == 0
    if m.nskin:
        assert _bytes(scn, "skinvert").size
        np.testing.assert_array_equal(scn.skinvertnum, m.skin_vertnum)
        np.testing.assert_array_equal(scn.skinfacenum, m.skin_facenum)
    # and the scene still fills and draws-checks as before
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    mjcffi.mjv_updateScene(m, d, mjcffi.MjvOption(), None, mjcffi.MjvCamera(),
                           mjcffi.mjtCatBit.mjCAT_ALL, scn)
    assert scn.ngeom > 0


# ------------------------------------------------------------ drawing a marker

def _marker(scn, pos):
    """Fill geom scn.ngeom field by field as some clients do, never setting matid (or
    texid, label, ...), and count it in."""
    g = scn.geoms[scn.ngeom]
    g.type = mjcffi.mjtGeom.mjGEOM_SPHERE
    g.size[:] = 0.3
    g.pos[:] = pos
    g.mat[:] = np.eye(3)
    g.rgba[:] = (1, 0, 0, 1)
    g.category = mjcffi.mjtCatBit.mjCAT_DECOR
    scn.ngeom += 1


def _red(rgb):
    """How many pixels are clearly red."""
    rgb = rgb.astype(int)
    return int(((rgb[..., 0] > 120) & (rgb[..., 1] < 60) & (rgb[..., 2] < 60)).sum())


def marker_scenario():
    """After heap churn: a marker filled field by field draws, with mjr_render and with
    the Renderer; reports the outcomes and the red pixels with and without it."""
    m = mjcffi.MjModel.from_xml_string(FLOOR)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    out = {}
    width, height = 160, 120
    ctx = mjcffi.GLContext(width, height)
    ctx.make_current()
    con = mjcffi.MjrContext(m, mjcffi.mjtFontScale.mjFONTSCALE_150)
    mjcffi.mjr_setBuffer(mjcffi.mjtFramebuffer.mjFB_OFFSCREEN, con)
    churn(m, 1000)
    scn = mjcffi.MjvScene(m, 1000)
    cam = mjcffi.MjvCamera()
    cam.type, cam.fixedcamid = mjcffi.mjtCamera.mjCAMERA_FIXED, 0
    rect = mjcffi.MjrRect(0, 0, width, height)
    rgb = np.zeros((height, width, 3), np.uint8)

    def frame(marker):
        mjcffi.mjv_updateScene(m, d, mjcffi.MjvOption(), None, cam,
                               mjcffi.mjtCatBit.mjCAT_ALL, scn)
        if marker:
            _marker(scn, (0.0, 0.0, 0.5))
            out["matid"] = int(scn.geoms[scn.ngeom - 1].matid)
        mjcffi.mjr_render(rect, scn, con)
        mjcffi.mjr_readPixels(rgb, None, rect, con)
        return _red(rgb)

    out["plain_red"] = frame(False)
    out["mjr_render"] = _outcome(lambda: out.__setitem__("marker_red", frame(True)))
    ctx.free()

    churn(m, 10000)
    renderer = mjcffi.Renderer(m, height, width)
    renderer.update_scene(d, camera="above")
    _marker(renderer.scene, (0.0, 0.0, 0.5))
    out["renderer"] = _outcome(lambda: out.__setitem__("renderer_red", _red(renderer.render())))
    renderer.close()
    print(json.dumps(out))


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_marker_without_matid_draws_after_heap_churn(backend):
    out = _gl.run("tests.test_scene_zeroed", backend, "marker_scenario", timeout=TIMEOUT)
    assert out["mjr_render"] == "ok", out
    assert out["renderer"] == "ok", out
    assert out["matid"] == 0
    assert out["plain_red"] == 0
    # a 0.3 m sphere 2.5 m below the camera covers a good part of the 160x120 frame
    assert out["marker_red"] > 300 and out["renderer_red"] > 300, out
