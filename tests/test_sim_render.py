"""mujoco-py's rendering in mjcffi.sim: MjSim.render, MjRenderContextOffscreen, the modders.

Everything that makes an OpenGL context runs in a subprocess per backend (EGL and
OSMesa): MUJOCO_GL is read once per process, and this pytest process stays free of
OpenGL libraries.  A scenario prints one JSON line of what it saw; the assertions are
here.  A backend is skipped only when its system library is missing, naming the
Debian package.  The reference images come from mjcffi's own mjv_updateScene +
mjr_render + mjr_readPixels and from the official `mujoco.Renderer`.
"""

import functools
import json
import os
import subprocess
import sys

import numpy as np
import pytest
from tests import _gl
from tests._gl import env as _env, outcome as _outcome, skip_reason as _skip_reason

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TIMEOUT = 600

BACKENDS = ("egl", "osmesa")
W, H = 160, 120

# a box seen from straight above by a named camera: its top is 2.7 from the camera
BOX = """
<mujoco>
  <asset>
    <texture name="grid" type="2d" builtin="checker" width="32" height="32"
             rgb1="0.9 0.2 0.2" rgb2="0.2 0.3 0.9"/>
    <material name="grid" texture="grid" texrepeat="2 2"/>
  </asset>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1"/>
    <camera name="top" pos="0 0 3"/>
    <geom name="box" type="box" size="0.3 0.3 0.3" material="grid"/>
  </worldbody>
</mujoco>
"""


def _run(backend, scenario):
    """Run the scenario, a function of this module, under MUJOCO_GL=backend; its JSON."""
    return _gl.run("tests.test_sim_render", backend, scenario, timeout=TIMEOUT)


def _humanoid():
    import gymnasium
    return os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets",
                        "humanoid.xml")


# ------------------------------------------------------------ running a backend

@functools.lru_cache(maxsize=None)
def _cached(backend, scenario):
    return _run(backend, scenario)


@pytest.fixture(params=BACKENDS)
def backend(request):
    reason = _skip_reason(request.param)
    if reason:
        pytest.skip(reason)
    return request.param


def _digest(array):
    return [list(array.shape), str(array.dtype), float(np.asarray(array, np.float64).std())]


# ------------------------------------------------------------ the reference image

def _direct(model, data, cam, width=W, height=H):
    """rgb, depth of one frame drawn with mjcffi's own functions, in a GL context of its
    own: mjv_updateScene + mjr_render + mjr_readPixels."""
    import mjcffi
    gl = mjcffi.GLContext(width, height)
    with gl.as_current():
        con = mjcffi.MjrContext(model, mjcffi.mjtFontScale.mjFONTSCALE_150)
        mjcffi.mjr_setBuffer(mjcffi.mjtFramebuffer.mjFB_OFFSCREEN, con)
        scn = mjcffi.MjvScene(model, 10000)
        mjcffi.mjv_updateScene(model, data, mjcffi.MjvOption(), mjcffi.MjvPerturb(), cam,
                               mjcffi.mjtCatBit.mjCAT_ALL, scn)
        rect = mjcffi.MjrRect(0, 0, width, height)
        mjcffi.mjr_render(rect, scn, con)
        rgb = np.zeros((height, width, 3), np.uint8)
        depth = np.zeros((height, width), np.float32)
        mjcffi.mjr_readPixels(rgb, depth, rect, con)
        con.free()
    gl.free()
    return rgb, depth


def _official(path, qpos, camera):
    """The official mujoco.Renderer's frame of the same state (top row first).

    The official GL backends need PyOpenGL, which this project does not use; the
    official Renderer is given mjcffi's GLContext class instead (same driver, same
    libmujoco): what is compared is MuJoCo's drawing and the Renderer's readout."""
    import mujoco
    import mujoco.rendering.classic.gl_context as official_gl

    import mjcffi
    official_gl.GLContext = mjcffi.GLContext
    model = mujoco.MjModel.from_xml_path(path)
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    renderer = mujoco.Renderer(model, H, W)
    try:
        renderer.update_scene(data, camera=camera)
        return renderer.render().copy()
    finally:
        renderer.close()


def identity_scenario():
    import mjcffi
    from mjcffi.sim import MjRenderContextOffscreen, MjSim, load_model_from_path
    path = _humanoid()
    sim = MjSim(load_model_from_path(path))
    sim.data.qpos[:] = sim.model.qpos0 + 0.05 * np.sin(np.arange(sim.model.nq))
    sim.forward()
    track = sim.model.camera("track").id

    # no camera name at first: mujoco-py's free camera, at the model's extent from the
    # geoms' median (later calls without a name keep the camera the last one set)
    free_rgb = sim.render(W, H)
    rgb, depth = sim.render(W, H, camera_name="track", depth=True)
    kept_rgb = sim.render(W, H)
    context = MjRenderContextOffscreen(sim, device_id=-1)
    context.render(W, H, camera_id=track)
    ctx_rgb, ctx_depth = context.read_pixels(W, H, depth=True)
    fixed = mjcffi.MjvCamera()
    fixed.type, fixed.fixedcamid = mjcffi.mjtCamera.mjCAMERA_FIXED, track
    ref_rgb, ref_depth = _direct(sim.model, sim.data, fixed)

    free = mjcffi.MjvCamera()
    free.lookat[:] = np.median(sim.data.geom_xpos, axis=0)
    free.distance = sim.model.stat.extent
    ref_free, _ = _direct(sim.model, sim.data, free)

    official = _official(path, sim.data.qpos.copy(), "track")
    print(json.dumps({
        "rgb": _digest(rgb), "depth": _digest(depth),
        "sim_rgb": bool(np.array_equal(rgb, ref_rgb)),
        "sim_depth": bool(np.array_equal(depth, ref_depth)),
        "ctx_rgb": bool(np.array_equal(ctx_rgb, ref_rgb)),
        "ctx_depth": bool(np.array_equal(ctx_depth, ref_depth)),
        "free": bool(np.array_equal(free_rgb, ref_free)),
        "free_differs": bool(not np.array_equal(free_rgb, rgb)),
        "kept": bool(np.array_equal(kept_rgb, rgb)),
        "official_flipped": bool(np.array_equal(official[::-1], rgb)),
        "official_unflipped": bool(np.array_equal(official, rgb)),
        "contexts": len(sim.render_contexts),
        "cached": sim._render_context_offscreen is sim.render_contexts[0],
    }))


def test_sim_render_equals_mjr_render_and_the_official_renderer_flipped(backend):
    out = _cached(backend, "identity_scenario")
    assert out["rgb"][:2] == [[H, W, 3], "uint8"] and out["rgb"][2] > 10
    assert out["sim_rgb"] and out["sim_depth"]
    assert out["ctx_rgb"] and out["ctx_depth"]
    # mujoco-py's row order: the official Renderer's image upside down
    assert out["official_flipped"] and not out["official_unflipped"]
    assert out["free"] and out["free_differs"] and out["kept"]
    assert out["contexts"] == 2 and out["cached"]


# ------------------------------------------------------------ depth, segmentation, extras

def outputs_scenario():
    from mjcffi.sim import MjSim, load_model_from_xml
    sim = MjSim(load_model_from_xml(BOX))
    model = sim.model
    rgb_only = sim.render(W, H, camera_name="top")
    rgb, depth = sim.render(W, H, camera_name="top", depth=True)
    extent = model.stat.extent
    near, far = model.vis.map.znear * extent, model.vis.map.zfar * extent
    centre = float(depth[H // 2, W // 2])
    seg = sim.render(W, H, camera_name="top", segmentation=True)
    after_seg = sim.render(W, H, camera_name="top")
    box = model.geom("box").id
    context = sim._render_context_offscreen
    buffer = np.zeros((H, W), np.float32)
    context.read_pixels_depth(buffer)
    calls = []
    sim.render_callback = lambda s, c: calls.append((s is sim, c is context))
    sim.render(W, H, camera_name="top")
    sim.render_callback = None
    context.add_marker(pos=(0.0, 0.0, 0.6), size=(0.1, 0.1, 0.1), rgba=(0, 1, 0, 1),
                       label="goal")
    marked = sim.render(W, H, camera_name="top")
    wide = marked.astype(int)
    green = int(np.count_nonzero((wide[..., 1] > wide[..., 0] + 40)
                                 & (wide[..., 1] > wide[..., 2] + 40)))
    context.add_overlay(0, "overlay", "text")
    overlaid = sim.render(W, H, camera_name="top")
    context.update_offscreen_size(800, 600)
    big = sim.render(800, 600, camera_name="top")
    print(json.dumps({
        "rgb_only": [type(rgb_only).__name__, *_digest(rgb_only)],
        "rgb": _digest(rgb), "depth": _digest(depth),
        "same_rgb": bool(np.array_equal(rgb, rgb_only)),
        "depth_range": [float(depth.min()), float(depth.max())],
        "corner": float(depth[0, 0]),
        "distance": float(near / (1 - centre * (1 - near / far))),
        "seg": _digest(seg), "seg_values": np.unique(seg.reshape(-1, 2), axis=0).tolist(),
        "box": box, "after_seg": bool(np.array_equal(after_seg, rgb)),
        "depth_buffer": bool(np.array_equal(buffer, depth)),
        "calls": calls, "green": green,
        "marker_changes": bool(not np.array_equal(marked, rgb)),
        "overlay_changes": bool(not np.array_equal(overlaid, marked)),
        "big": _digest(big), "offwidth": [model.vis.global_.offwidth,
                                          model.vis.global_.offheight],
    }))


def test_depth_is_the_raw_depth_buffer_in_opengl_row_order(backend):
    out = _cached(backend, "outputs_scenario")
    assert out["rgb_only"][:3] == ["ndarray", [H, W, 3], "uint8"]
    assert out["rgb"][:2] == [[H, W, 3], "uint8"] and out["same_rgb"]
    assert out["depth"][:2] == [[H, W], "float32"]
    low, high = out["depth_range"]
    assert 0.0 < low < high <= 1.0
    assert out["corner"] == 1.0                        # nothing drawn: the far plane
    assert out["distance"] == pytest.approx(2.7, abs=0.01)   # the documented formula
    assert out["depth_buffer"]


def test_segmentation_gives_object_type_and_id(backend):
    out = _cached(backend, "outputs_scenario")
    assert out["seg"][:2] == [[H, W, 2], "int32"]
    geom_type = 5                                      # mjOBJ_GEOM
    assert out["seg_values"] == [[-1, -1], [geom_type, out["box"]]]
    assert out["after_seg"]                            # the flags are restored


def test_callback_markers_overlays_and_a_bigger_buffer(backend):
    out = _cached(backend, "outputs_scenario")
    assert out["calls"] == [[True, True]]
    assert out["marker_changes"] and out["green"] > 50
    assert out["overlay_changes"]
    assert out["big"][:2] == [[600, 800, 3], "uint8"] and out["offwidth"] == [800, 600]


# ------------------------------------------------------------ textures and materials

def texture_scenario():
    from mjcffi.sim import MaterialModder, MjSim, TextureModder, load_model_from_path
    sim = MjSim(load_model_from_path(_humanoid()))
    model = sim.model
    before = sim.render(W, H, camera_name="track")
    textures = TextureModder(sim, random_state=0)
    original = model.tex_data.copy()
    floor = textures.get_texture("floor")
    textures.set_rgb("floor", (255, 0, 0))
    red = sim.render(W, H, camera_name="track")
    model.tex_data[:] = original
    textures.upload_texture("floor")
    restored = sim.render(W, H, camera_name="track")
    # without an upload, an edit stays invisible
    textures.get_texture("floor").bitmap[:] = 0
    not_uploaded = sim.render(W, H, camera_name="track")
    model.tex_data[:] = original
    textures.upload_texture("floor")
    # a second render context gets the upload too
    from mjcffi.sim import MjRenderContextOffscreen
    second = MjRenderContextOffscreen(sim)
    textures.set_checker("floor", (255, 255, 0), (0, 0, 255))
    second.render(W, H, camera_id=model.camera("track").id)
    second_rgb = second.read_pixels(W, H, depth=False)
    first_rgb = sim.render(W, H, camera_name="track")
    model.tex_data[:] = original
    textures.upload_texture("floor")
    materials = MaterialModder(sim, random_state=1)
    materials.set_texrepeat("floor", 3, 3)
    repeated = sim.render(W, H, camera_name="track")
    bad = {
        "geom": _outcome(lambda: textures.set_rgb("no_such_geom", (1, 2, 3))),
        "colour": _outcome(lambda: textures.set_rgb("floor", (1, 2, 300))),
        "shininess": _outcome(lambda: materials.set_shininess("floor", 1.5)),
        "tex_id": _outcome(lambda: sim.render_contexts[0].upload_texture(model.ntex)),
    }
    print(json.dumps({
        "floor": [floor.type, floor.width, floor.height],
        "red_changes": int(np.count_nonzero(np.any(red != before, axis=2))),
        "restored": bool(np.array_equal(restored, before)),
        "not_uploaded": bool(np.array_equal(not_uploaded, before)),
        "both_contexts": bool(np.array_equal(second_rgb, first_rgb)
                              and not np.array_equal(first_rgb, before)),
        "texrepeat_changes": bool(not np.array_equal(repeated, before)),
        "bad": bad,
    }))


def test_a_texture_upload_changes_the_pixels_and_the_original_restores_them(backend):
    out = _cached(backend, "texture_scenario")
    assert out["floor"][0] == "2d"
    assert out["red_changes"] > 1000
    assert out["restored"]
    assert out["not_uploaded"]
    assert out["both_contexts"]
    assert out["texrepeat_changes"]


def test_modders_refuse_bad_names_and_values(backend):
    bad = _cached(backend, "texture_scenario")["bad"]
    assert bad["geom"] == "ValueError: the model has no geom named 'no_such_geom'"
    assert bad["colour"].startswith("ValueError: rgb must be three numbers from 0 to 255")
    assert bad["shininess"] == "ValueError: shininess must be from 0 to 1, not 1.5"
    assert bad["tex_id"].startswith("ValueError: tex_id must be from 0 to ")


# ------------------------------------------------------------ bad input

def bad_input_scenario():
    import threading

    from mjcffi.sim import _render_checks as _simchecks
    from mjcffi.sim import MjRenderContext, MjRenderContextOffscreen, MjSim, \
        load_model_from_xml
    sim = MjSim(load_model_from_xml(BOX))
    offwidth = sim.model.vis.global_.offwidth
    offheight = sim.model.vis.global_.offheight
    out = {
        "camera_name": _outcome(lambda: sim.render(W, H, camera_name="side")),
        "camera_type": _outcome(lambda: sim.render(W, H, camera_name=3)),
        "zero": _outcome(lambda: sim.render(0, H)),
        "negative": _outcome(lambda: sim.render(W, -5)),
        "float": _outcome(lambda: sim.render(16.5, H)),
        "huge": _outcome(lambda: sim.render(_simchecks.MAX_BUFFER + 1, H)),
        "mode": _outcome(lambda: sim.render(W, H, mode="screen")),
        "device": _outcome(lambda: sim.render(W, H, device_id=-2)),
    }
    out["made_before_ok"] = len(sim.render_contexts)
    # as in mujoco-py, a larger image grows the sim's buffer and the model's sizes
    wide = sim.render(offwidth + 1, H)
    high = sim.render(W, offheight + 1)
    out["grown"] = [list(wide.shape), list(high.shape), sim.model.vis.global_.offwidth,
                    sim.model.vis.global_.offheight]
    sim.render(W, H)                               # the sim's own context
    context = MjRenderContextOffscreen(sim)        # and a second one
    out.update({
        "camera_id": _outcome(lambda: context.render(W, H, camera_id=1)),
        "read_wide": _outcome(lambda: context.read_pixels(
            sim.model.vis.global_.offwidth + 1, H)),
        "marker": _outcome(lambda: context.add_marker(colour=(1, 0, 0, 1))),
        "marker_shape": _outcome(lambda: context.add_marker(size=(1, 2))),
        "resize": _outcome(lambda: context.update_offscreen_size(0, 10)),
        "depth_buffer": _outcome(lambda: context.read_pixels_depth(np.zeros((4, 4)))),
        "backend": _outcome(lambda: MjRenderContext(sim, opengl_backend="wgl")),
        "not_a_sim": _outcome(lambda: MjRenderContextOffscreen(object())),
    })
    # another thread holds the context's GLContext: a clear error, not a shared context
    held, release = threading.Event(), threading.Event()

    def hold():
        with context.opengl_context.as_current():
            held.set()
            release.wait(60)

    thread = threading.Thread(target=hold)
    thread.start()
    held.wait(60)
    out["other_thread"] = _outcome(lambda: context.render(W, H))
    release.set()
    thread.join()
    out["after_thread"] = _outcome(lambda: context.render(W, H))
    # two threads rendering one sim take turns and get the same image
    images = []
    threads = [threading.Thread(target=lambda: images.append(
        sim.render(W, H, camera_name="top"))) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    out["threads_same"] = len(images) == 2 and bool(np.array_equal(*images))
    # use after free
    cached = sim._render_context_offscreen
    out["cached_first"] = cached is sim.render_contexts[0] and cached is not context
    cached.free()
    out.update({
        "freed_render": _outcome(lambda: cached.render(W, H)),
        "freed_read": _outcome(lambda: cached.read_pixels(W, H)),
        "freed_upload": _outcome(lambda: cached.upload_texture(0)),
        "free_twice": _outcome(cached.free),
        "forgotten": cached not in sim.render_contexts,
        "replaced_by": sim._render_context_offscreen is context,
    })
    context.free()
    out["new_after_free"] = _outcome(lambda: sim.render(W, H))
    out["contexts_after"] = len(sim.render_contexts)
    # the GLContext freed underneath
    fresh = sim._render_context_offscreen
    fresh.opengl_context.free()
    out["gl_freed"] = _outcome(lambda: fresh.render(W, H))
    print(json.dumps(out))


def test_bad_input_raises_naming_the_problem(backend):
    out = _cached(backend, "bad_input_scenario")
    assert out["camera_name"] == "ValueError: unknown camera name 'side': the model's " \
                                 "cameras are 'top'"
    assert out["camera_type"].startswith("TypeError: camera_name must be a str")
    assert out["zero"] == "ValueError: width must be a positive number of pixels, not 0"
    assert out["negative"] == "ValueError: height must be a positive number of pixels, not -5"
    assert out["float"].startswith("TypeError: width must be an int")
    assert out["huge"].startswith("ValueError: width must be"), out["huge"]
    assert out["grown"] == [[H, 641, 3], [481, W, 3], 641, 481]
    assert out["read_wide"].startswith("ValueError: an image of ") and \
        "does not fit the offscreen buffer of 641x481" in out["read_wide"] and \
        "update_offscreen_size" in out["read_wide"], out["read_wide"]
    assert out["mode"] == "ValueError: mode must be 'offscreen' or 'window', not 'screen'"
    assert out["device"].startswith("ValueError: device_id must be -1")
    assert out["made_before_ok"] == 0                  # refused before any OpenGL work
    assert out["camera_id"].startswith("ValueError: camera_id must be -1 (the free camera) "
                                       "or a camera id from 0 to 0, not 1")
    assert out["marker"].startswith("ValueError: add_marker: mjvGeom has no field 'colour'")
    assert out["marker_shape"].startswith("ValueError: add_marker: size:")
    assert out["resize"] == "ValueError: width must be a positive number of pixels, not 0"
    assert out["depth_buffer"].startswith("TypeError: buffer must be a writable")
    assert out["backend"].startswith("ValueError: opengl_backend='wgl'")
    assert out["not_a_sim"] == "TypeError: sim must be an MjSim, not object"


def test_threads_and_use_after_free_raise_never_crash(backend):
    out = _cached(backend, "bad_input_scenario")
    assert out["other_thread"].startswith("RuntimeError: this GLContext is current on thread")
    assert out["after_thread"] == "ok"
    assert out["threads_same"]
    for key in ("freed_render", "freed_read", "freed_upload"):
        assert out[key] == "RuntimeError: this MjRenderContextOffscreen was freed: make a " \
                           "new one (sim.render makes one itself)", out[key]
    assert out["free_twice"] == "ok" and out["cached_first"]
    assert out["forgotten"] and out["replaced_by"]
    assert out["new_after_free"] == "ok" and out["contexts_after"] == 1
    assert out["gl_freed"].startswith("RuntimeError: this GLContext has been freed")


# ------------------------------------------------------------ device_id

def device_scenario():
    from mjcffi.sim import MjRenderContextOffscreen, MjSim, load_model_from_xml
    sim = MjSim(load_model_from_xml(BOX))
    out = {"none": _outcome(lambda: MjRenderContextOffscreen(sim, device_id=1000)),
           "env_after_none": os.environ.get("MUJOCO_EGL_DEVICE_ID")}
    out["zero"] = _outcome(lambda: MjRenderContextOffscreen(sim, device_id=0))
    out["env_after_zero"] = os.environ.get("MUJOCO_EGL_DEVICE_ID")
    out["other"] = _outcome(lambda: MjRenderContextOffscreen(sim, device_id=1))
    out["image"] = _digest(sim.render(W, H, camera_name="top", device_id=0))
    print(json.dumps(out))


def test_device_id_picks_the_egl_device_once_per_process():
    out = _run("egl", "device_scenario")
    assert out["none"].startswith("ValueError: device_id=1000: MUJOCO_EGL_DEVICE_ID")
    assert out["env_after_none"] is None               # a failed choice is not kept
    assert out["zero"] == "ok" and out["env_after_zero"] == "0"
    assert out["other"].startswith("ValueError: device_id=1, but this process already "
                                   "renders on EGL device 0")
    assert out["image"][:2] == [[H, W, 3], "uint8"] and out["image"][2] > 10


def test_device_id_is_ignored_where_there_is_one_device():
    out = _run("osmesa", "device_scenario")
    assert out["none"] == out["zero"] == out["other"] == "ok"
    assert out["env_after_zero"] is None


# ------------------------------------------------------------ the example

def test_the_texture_randomization_example_runs(backend, tmp_path):
    run = subprocess.run([sys.executable, os.path.join(ROOT, "examples",
                                                       "texture_randomization.py"),
                          "--frames", "3", "--out", str(tmp_path)],
                         cwd=ROOT, env=_env(backend), capture_output=True, text=True,
                         timeout=TIMEOUT)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stdout.startswith("3 frames of 160x120, 3 distinct, ")
    files = sorted(p.name for p in tmp_path.iterdir())
    assert files == ["frame_0000.png", "frame_0001.png", "frame_0002.png"]
    assert (tmp_path / "frame_0000.png").read_bytes().startswith(b"\x89PNG\r\n\x1a\n")


# ------------------------------------------------------------ without OpenGL

def test_refusals_before_any_opengl_work_in_this_process():
    """This pytest process loads no OpenGL library: what is refused is refused first."""
    from mjcffi.sim import MjRenderContext, MjRenderContextOffscreen, MjSim, load_model_from_xml
    sim = MjSim(load_model_from_xml(BOX))
    with pytest.raises(ValueError, match="unknown camera name 'nope'"):
        sim.render(W, H, camera_name="nope")
    with pytest.raises(NotImplementedError, match="MjViewer"):
        MjRenderContext(sim, offscreen=False)          # a window is an MjViewer
    with pytest.raises(ValueError, match="width must be a positive number of pixels"):
        sim.render(-1, H)
    with pytest.raises(TypeError, match="sim must be an MjSim"):
        MjRenderContextOffscreen(sim.model)
    with pytest.raises(TypeError, match="render_context must be an MjRenderContext"):
        sim.add_render_context(object())
    assert sim.render_contexts == [] and sim._render_context_offscreen is None


def test_rendering_disabled_by_mujoco_gl_says_so():
    code = ("from tests.test_sim_render import BOX\nfrom mjcffi.sim import MjSim, "
            "load_model_from_xml\nsim = MjSim(load_model_from_xml(BOX))\ntry:\n"
            "    sim.render(16, 16)\nexcept RuntimeError as e:\n    print(e)\n")
    run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=_env("disable"),
                         capture_output=True, text=True, timeout=TIMEOUT)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stdout.startswith("rendering is disabled: MUJOCO_GL='disable'")


def test_modders_need_no_opengl_without_render_contexts():
    """With no render context yet, an edit needs no upload: a context made later reads
    the model's textures when it is made."""
    from mjcffi.sim import MaterialModder, MjSim, TextureModder, load_model_from_xml
    sim = MjSim(load_model_from_xml(BOX))
    textures = TextureModder(sim, random_state=3)
    bitmap = textures.set_checker("box", (255, 0, 0), (0, 0, 255))
    assert bitmap.shape == (32, 32, 3)
    # mujoco-py's phase: the second colour at the first pixel
    assert bitmap[0, 0].tolist() == [0, 0, 255] and bitmap[0, 1].tolist() == [255, 0, 0]
    assert bitmap[1, 0].tolist() == [255, 0, 0]
    gradient = textures.set_gradient("box", (0, 0, 0), (255, 255, 255), vertical=True)
    assert gradient[0, 5].tolist() == [0, 0, 0] and gradient[-1, 5].tolist() == [255] * 3
    assert np.all(np.diff(gradient[:, 0, 0].astype(int)) >= 0)
    noise = textures.set_noise("box", (0, 0, 0), (255, 255, 255), fraction=0.5)
    share = float(np.mean(noise[..., 0] == 255))
    assert 0.3 < share < 0.7
    rgb = textures.set_rgb("box", (10, 20, 30))
    assert np.all(sim.model.tex_data[:32 * 32 * 3].reshape(32, 32, 3) == [10, 20, 30])
    assert rgb.base is not None                        # a live view of model.tex_data
    materials = MaterialModder(sim, random_state=4)
    materials.rand_all("box")
    material = sim.model.geom_matid[sim.model.geom("box").id]
    assert 0.1 <= sim.model.mat_specular[material] <= 0.3
    with pytest.raises(ValueError, match="the model has no skybox texture"):
        textures.get_texture("skybox")


def test_modders_name_what_a_geom_lacks():
    from mjcffi.sim import MaterialModder, MjSim, TextureModder, load_model_from_xml
    sim = MjSim(load_model_from_xml("""
        <mujoco><asset><material name="red" rgba="1 0 0 1"/></asset><worldbody>
          <geom name="plain" size="0.1"/><geom name="painted" size="0.1" material="red"/>
        </worldbody></mujoco>"""))
    textures, materials = TextureModder(sim), MaterialModder(sim)
    with pytest.raises(ValueError, match="geom 'plain' has no material"):
        textures.set_rgb("plain", (1, 2, 3))
    with pytest.raises(ValueError, match="the material of geom 'painted' has no .rgb. texture"):
        textures.set_rgb("painted", (1, 2, 3))
    with pytest.raises(ValueError, match="geom 'plain' has no material"):
        materials.set_reflectance("plain", 0.5)
    with pytest.raises(ValueError, match="the model has no geom named ''"):
        materials.set_reflectance("", 0.5)
    with pytest.raises(ValueError, match="texture repeats must be positive"):
        materials.set_texrepeat("painted", 0, 1)
    textures.randomize()                               # nothing textured: nothing to do
    materials.set_rgba("painted", (0, 1, 0, 1))
    assert sim.model.mat_rgba[0].tolist() == [0, 1, 0, 1]
