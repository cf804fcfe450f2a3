"""mjcffi.Renderer: the official `mujoco.Renderer`'s API, pixel for pixel.

Every scenario that draws runs in a subprocess with MUJOCO_GL set to its
backend, EGL and OSMesa: MUJOCO_GL is read once per process, a missed check
could crash it, and this pytest process stays free of OpenGL libraries.  A
scenario prints one JSON line of what it saw; the assertions are here.  A
backend is skipped only when its system library is missing, naming the Debian
package to install.

The official Renderer needs PyOpenGL for its own GL contexts.  Where PyOpenGL
is missing, the official Renderer draws in an mjcffi GLContext of the same
backend instead (its `gl_context.GLContext` replaced): the frames still come
from the official bindings' scene and context code, on the same libmujoco and
the same OpenGL driver.  Each scenario reports which contexts it used.
"""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import mjcffi
from tests import _gl
from tests._gl import env as _env, outcome as _outcome, skip_reason as _skip_reason

TIMEOUT = 600

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BACKENDS = ("egl", "osmesa")
MODELS = ("humanoid", "ant", "hopper", "half_cheetah")

# a white box under a camera looking straight down from 3 m
BOX = """
<mujoco>
  <statistic extent="1"/>
  <worldbody>
    <light pos="0 0 4"/>
    <camera name="above" pos="0 0 3"/>
    <geom name="floor" type="plane" size="2 2 0.1" rgba="0.3 0.3 0.3 1"/>
    <body name="box" pos="0.5 0 0.25">
      <freejoint/>
      <geom name="box" type="box" size="0.25 0.25 0.25" rgba="1 1 1 1"/>
    </body>
  </worldbody>
</mujoco>
"""


def _run(backend, scenario, *args):
    """Run the scenario, a function of this module, under MUJOCO_GL=backend; its JSON."""
    return _gl.run("tests.test_renderer", backend, scenario, *args, timeout=TIMEOUT)


def _assets():
    import gymnasium
    return os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets")


def _official_gl_context():
    """'official' when the official bindings can make their own GL contexts (PyOpenGL);
    otherwise 'mjcffi', after giving their Renderer mjcffi's GLContext class."""
    try:
        import OpenGL  # noqa: F401
        return "official"
    except ImportError:
        import mujoco.rendering.classic.gl_context as official_gl
        official_gl.GLContext = mjcffi.GLContext
        return "mjcffi"


# ------------------------------------------------------------ pixel identity

def identity_scenario():
    """rgb, depth and segmentation of both Renderers, per model and camera: equal?"""
    import mujoco

    contexts = _official_gl_context()
    found = {}
    for name in MODELS:
        path = os.path.join(_assets(), f"{name}.xml")
        frames = {}
        for lib in (mjcffi, mujoco):
            m = lib.MjModel.from_xml_path(path)
            d = lib.MjData(m)
            d.qpos[:] = m.qpos0 + 0.1 * np.sin(np.arange(m.nq))
            lib.mj_forward(m, d)
            tracking = lib.MjvCamera()
            tracking.type = lib.mjtCamera.mjCAMERA_TRACKING
            tracking.trackbodyid, tracking.distance, tracking.elevation = 1, 3.0, -20.0
            orthographic = lib.MjvCamera()
            lib.mjv_defaultFreeCamera(m, orthographic)
            orthographic.orthographic = 1           # depth is then linear in distance
            cameras = {"free": -1, "tracking": tracking, "orthographic": orthographic,
                       "id 0": 0}
            cameras.update({f"name {m.camera(i).name!r}": m.camera(i).name
                            for i in range(m.ncam) if m.camera(i).name})
            with lib.Renderer(m, 120, 160) as renderer:
                for label, camera in cameras.items():
                    for mode in ("rgb", "depth", "segmentation"):
                        renderer.disable_depth_rendering()
                        renderer.disable_segmentation_rendering()
                        if mode == "depth":
                            renderer.enable_depth_rendering()
                        elif mode == "segmentation":
                            renderer.enable_segmentation_rendering()
                        renderer.update_scene(d, camera=camera)
                        frames.setdefault((label, mode), []).append(renderer.render())
        found[name] = {f"{label}/{mode}": [
            bool(np.array_equal(ours, theirs)), int(np.count_nonzero(ours != theirs)),
            str(ours.dtype), list(ours.shape), str(theirs.dtype), list(theirs.shape),
            int(np.unique(ours.reshape(-1, ours.shape[-1]) if ours.ndim == 3 else ours,
                          axis=0).shape[0])]
            for (label, mode), (ours, theirs) in frames.items()}
    print(json.dumps({"contexts": contexts, "models": found}))


@pytest.mark.parametrize("backend", BACKENDS)
def test_frames_are_pixel_identical_to_the_official_renderer(backend):
    out = _run(backend, "identity_scenario")
    assert set(out["models"]) == set(MODELS)
    expected = {"rgb": ("uint8", 3), "depth": ("float32", 2), "segmentation": ("int32", 3)}
    for name, views in out["models"].items():
        # every model has the free, a tracking, and a named camera
        assert {v.split("/")[0] for v in views} >= {"free", "tracking", "orthographic",
                                                    "name 'track'"}, name
        for view, (same, differ, dtype, shape, their_dtype, their_shape, distinct) in \
                views.items():
            mode = view.split("/")[1]
            assert (dtype, len(shape)) == expected[mode], (name, view)
            assert (dtype, shape) == (their_dtype, their_shape), (name, view)
            assert shape[:2] == [120, 160], (name, view)
            assert distinct > 2, (name, view, "a blank frame proves nothing")
            assert same, (name, view, f"{differ} values differ ({out['contexts']} contexts)")


# ------------------------------------------------------------ what the images hold

def content_scenario():
    """Depth in metres, segmentation ids, `out`, flags, and the recording helper."""
    from mjcffi.rendering import recording
    m = mjcffi.MjModel.from_xml_string(BOX)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    found = {}
    with mjcffi.Renderer(m, 51, 51) as renderer:
        renderer.update_scene(d, camera="above")
        rgb = renderer.render()
        found["rgb"] = [list(rgb.shape), str(rgb.dtype), rgb[25, 25].tolist(),
                        rgb[25, 40].tolist(), rgb[25, 10].tolist()]
        flags = renderer.scene.flags.copy()
        renderer.enable_depth_rendering()
        depth = renderer.render()
        # box top at 0.5 m: the camera sees it 2.5 m away on its right side, the floor 3 m
        found["depth"] = [list(depth.shape), str(depth.dtype), float(depth[25, 10]),
                          float(depth[25, 40])]
        found["flags_kept"] = bool(np.array_equal(flags, renderer.scene.flags))
        renderer.enable_segmentation_rendering()
        seg = renderer.render()
        box, floor = (mjcffi.mj_name2id(m, mjcffi.mjtObj.mjOBJ_GEOM, n) for n in ("box", "floor"))
        found["seg"] = [list(seg.shape), str(seg.dtype), seg[25, 40].tolist(),
                        seg[25, 10].tolist(), box, floor, int(mjcffi.mjtObj.mjOBJ_GEOM)]
        renderer.update_scene(d, camera=-1)
        # the free camera sees the whole model: the sky around it is background
        found["seg_background"] = renderer.render()[0, 0].tolist()
        renderer.disable_segmentation_rendering()
        renderer.update_scene(d, camera="above")
        # out: the same object back, filled; cast for another dtype or a strided array
        out = np.zeros((51, 51, 3), np.uint8)
        back = renderer.render(out=out)
        wide = renderer.render(out=np.zeros((51, 51, 3), np.int64))
        fortran = renderer.render(out=np.asfortranarray(np.zeros((51, 51, 3), np.uint8)))
        renderer.enable_depth_rendering()
        depth64 = renderer.render(out=np.zeros((51, 51), np.float64))
        found["out"] = [back is out, bool(np.array_equal(out, rgb)),
                        bool(np.array_equal(wide, rgb)), str(wide.dtype),
                        bool(np.array_equal(fortran, rgb)),
                        bool(np.array_equal(depth64, depth.astype(np.float64)))]
        # two frames without out are two arrays
        renderer.disable_depth_rendering()
        found["fresh"] = renderer.render() is not renderer.render()
        found["properties"] = [renderer.width, renderer.height, renderer.model is m,
                               isinstance(renderer.scene, mjcffi.MjvScene)]

    # two renderers in turn: each draws its own frame in its own context
    with mjcffi.Renderer(m, 51, 51) as one, mjcffi.Renderer(m, 51, 51) as two:
        one.update_scene(d, camera="above")
        two.update_scene(d, camera=-1)
        first, second = one.render(), two.render()
        found["two"] = [bool(np.array_equal(first, rgb)), bool(np.array_equal(one.render(), rgb)),
                        bool(np.array_equal(two.render(), second)),
                        bool(np.array_equal(first, second))]

    # recording: from qpos and from full states, the same frames as rendered by hand
    qpos, states = [], []
    size = mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
    d.qvel[:3] = (-2.0, 1.0, 3.0)       # thrown: it slides and lands in view
    for _ in range(6):
        for _ in range(20):
            mjcffi.mj_step(m, d)
        qpos.append(d.qpos.copy())
        state = np.empty(size)
        mjcffi.mj_getState(m, d, state, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
        states.append(state)
    by_qpos = recording.render_trajectory(m, qpos, camera="above", height=40, width=50,
                                          progress=False)
    by_state = recording.render_trajectory(m, np.array(states), camera="above", height=40,
                                           width=50, progress=False)
    by_hand = []
    with mjcffi.Renderer(m, 40, 50) as renderer:
        scratch = mjcffi.MjData(m)
        for row in qpos:
            scratch.qpos[:] = row
            mjcffi.mj_forward(m, scratch)
            renderer.update_scene(scratch, camera="above")
            by_hand.append(renderer.render())
        reused = recording.render_trajectory(m, qpos, camera="above", renderer=renderer,
                                             progress=False)
        found["recording_renderer_open"] = _outcome(renderer.render) == "ok"
    found["recording"] = [list(by_qpos.shape), str(by_qpos.dtype),
                          bool(np.array_equal(by_qpos, np.array(by_hand))),
                          bool(np.array_equal(by_state, by_qpos)),
                          bool(np.array_equal(reused, by_qpos)),
                          bool(not np.array_equal(by_qpos[0], by_qpos[-1]))]
    found["recording_errors"] = [
        _outcome(lambda: recording.render_trajectory(m, np.zeros((2, 5)), progress=False)),
        _outcome(lambda: recording.render_trajectory(m, np.zeros(7), progress=False)),
        _outcome(lambda: recording.render_trajectory(
            m, qpos, renderer=mjcffi.Renderer(mjcffi.MjModel.from_xml_string(BOX), 40, 50),
            progress=False))]
    print(json.dumps(found))


@pytest.mark.parametrize("backend", BACKENDS)
def test_images_hold_depth_in_metres_segments_and_fill_out(backend):
    found = _run(backend, "content_scenario")
    shape, dtype, centre, box, floor = found["rgb"]
    assert (shape, dtype) == ([51, 51, 3], "uint8")
    assert sum(box) > sum(floor) + 150, "the white box is brighter than the grey floor"
    shape, dtype, floor, box = found["depth"]
    assert (shape, dtype) == ([51, 51], "float32")
    assert floor == pytest.approx(3.0, abs=0.01) and box == pytest.approx(2.5, abs=0.01)
    assert found["flags_kept"]
    shape, dtype, on_box, on_floor, box_id, floor_id, geom = found["seg"]
    assert (shape, dtype) == ([51, 51, 2], "int32")
    assert on_box == [box_id, geom] and on_floor == [floor_id, geom]
    assert found["seg_background"] == [-1, -1]
    assert found["out"] == [True, True, True, "int64", True, True]
    assert found["fresh"]
    assert found["properties"] == [51, 51, True, True]
    assert found["two"] == [True, True, True, False]
    assert found["recording"] == [[6, 40, 50, 3], "uint8", True, True, True, True]
    assert found["recording_renderer_open"], "a renderer passed in stays open"
    short, flat, other = found["recording_errors"]
    assert short.startswith("ValueError") and "nq (7)" in short
    assert flat.startswith("ValueError") and "2-D" in flat
    assert other.startswith("ValueError") and "another model" in other


# ------------------------------------------------------------ bad input

def errors_scenario():
    """Every misuse raises a Python exception; the process lives on to print them."""
    import gc
    import threading
    m = mjcffi.MjModel.from_xml_string(BOX)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    found = {}
    renderer = mjcffi.Renderer(m, 40, 50)
    found["camera_name"] = _outcome(lambda: renderer.update_scene(d, camera="nowhere"))
    found["camera_low"] = _outcome(lambda: renderer.update_scene(d, camera=-2))
    found["camera_high"] = _outcome(lambda: renderer.update_scene(d, camera=m.ncam))
    found["camera_float"] = _outcome(lambda: renderer.update_scene(d, camera=0.5))
    found["camera_numpy"] = _outcome(lambda: renderer.update_scene(d, camera=np.int64(0)))
    other = mjcffi.MjData(mjcffi.MjModel.from_xml_string("<mujoco/>"))
    found["data_other_model"] = _outcome(lambda: renderer.update_scene(other))
    found["option"] = _outcome(lambda: renderer.update_scene(d, scene_option=5))
    renderer.update_scene(d, camera="above")
    found["out_shape"] = _outcome(lambda: renderer.render(out=np.zeros((50, 40, 3), np.uint8)))
    found["out_dtype"] = _outcome(lambda: renderer.render(out=np.zeros((40, 50, 3), object)))
    found["out_list"] = _outcome(lambda: renderer.render(out=[[0] * 3] * 2000))
    frozen = np.zeros((40, 50, 3), np.uint8)
    frozen.flags.writeable = False
    found["out_readonly"] = _outcome(lambda: renderer.render(out=frozen))
    renderer.enable_depth_rendering()
    flags = renderer.scene.flags.copy()
    found["out_depth_shape"] = _outcome(lambda: renderer.render(out=np.zeros((40, 50, 3))))
    found["flags_after_error"] = bool(np.array_equal(flags, renderer.scene.flags))
    renderer.disable_depth_rendering()

    # another thread, while this one holds the context
    seen = []
    worker = threading.Thread(target=lambda: seen.append(
        [_outcome(renderer.render), _outcome(renderer.close)]), name="worker")
    worker.start()
    worker.join()
    found["thread"] = seen[0]
    found["thread_then_here"] = _outcome(renderer.render)
    renderer.close()
    found["after_close"] = _outcome(renderer.render)
    found["close_twice"] = _outcome(renderer.close)
    found["update_after_close"] = _outcome(lambda: renderer.update_scene(d))

    # a renderer made and used on a thread that ended: usable here
    made = []
    worker = threading.Thread(target=lambda: made.append(mjcffi.Renderer(m, 40, 50)))
    worker.start()
    worker.join()
    made[0].update_scene(d)
    found["made_on_ended_thread"] = _outcome(made[0].render)
    made[0].close()

    # sizes and arguments the constructor refuses, before any OpenGL work
    for label, args in {"negative": (m, -1, 50), "zero": (m, 40, 0), "float": (m, 40.0, 50),
                        "bool": (m, True, 50), "wide": (m, 40, 641), "tall": (m, 481, 50),
                        "model": ("model", 40, 50), "max_geom": (m, 40, 50, -1)}.items():
        found[f"init_{label}"] = _outcome(lambda: mjcffi.Renderer(*args))

    # __del__ of a renderer whose __init__ raised says nothing
    hooked = []
    old, sys.unraisablehook = sys.unraisablehook, hooked.append
    try:
        _outcome(lambda: mjcffi.Renderer(m, 40, 5000))
        gc.collect()
    finally:
        sys.unraisablehook = old
    found["del_after_failed_init"] = [type(h.exc_value).__name__ for h in hooked]

    # a renderer dropped without close(), in a reference cycle, does not disturb another
    keep = mjcffi.Renderer(m, 40, 50)
    keep.update_scene(d, camera="above")
    before = keep.render()
    cycle = []
    cycle.append((cycle, mjcffi.Renderer(m, 40, 50)))
    del cycle
    gc.collect()
    found["cycle_collected"] = bool(np.array_equal(keep.render(), before))
    # its GLContext freed first, then the renderer: still no crash, still no effect
    dropped = mjcffi.Renderer(m, 40, 50)
    dropped._gl_context.free()
    found["render_after_gl_freed"] = _outcome(dropped.render)
    found["close_after_gl_freed"] = _outcome(dropped.close)
    found["keep_after"] = bool(np.array_equal(keep.render(), before))
    keep.close()
    print(json.dumps(found))


@pytest.mark.parametrize("backend", BACKENDS)
def test_bad_input_raises_python_exceptions(backend):
    found = _run(backend, "errors_scenario")
    assert found["camera_name"].startswith("ValueError: The camera \"nowhere\" does not exist")
    assert "'above'" in found["camera_name"], "the message lists the model's cameras"
    assert found["camera_low"].startswith("ValueError") and "-2 is out of range" in \
        found["camera_low"]
    assert found["camera_high"].startswith("ValueError") and "1 is out of range" in \
        found["camera_high"]
    assert found["camera_float"].startswith("TypeError") and "float" in found["camera_float"]
    assert found["camera_numpy"] == "ok"
    assert found["data_other_model"].startswith("ValueError")
    assert found["option"].startswith("TypeError") and "MjvOption" in found["option"]
    assert found["out_shape"].startswith("ValueError") and "(40, 50, 3)" in found["out_shape"]
    assert found["out_dtype"].startswith("TypeError") and "numeric" in found["out_dtype"]
    assert found["out_list"].startswith("TypeError") and "NumPy" in found["out_list"]
    assert found["out_readonly"].startswith("ValueError") and "read-only" in \
        found["out_readonly"]
    assert found["out_depth_shape"].startswith("ValueError") and "(40, 50)" in \
        found["out_depth_shape"]
    assert found["flags_after_error"]
    render, close = found["thread"]
    assert render.startswith("RuntimeError") and "'worker'" in render and \
        "'MainThread'" in render
    assert close.startswith("RuntimeError") and "'MainThread'" in close
    assert found["thread_then_here"] == "ok", "the refused thread left the renderer intact"
    assert found["after_close"].startswith("RuntimeError") and "close" in found["after_close"]
    assert found["close_twice"] == "ok"
    assert found["update_after_close"] == "ok", "the scene outlives the contexts, as official"
    assert found["made_on_ended_thread"] == "ok"
    for label in ("negative", "zero"):
        assert found[f"init_{label}"].startswith("ValueError") and "positive" in \
            found[f"init_{label}"]
    assert found["init_float"].startswith("TypeError") and "height" in found["init_float"]
    assert found["init_bool"].startswith("TypeError")
    assert found["init_wide"].startswith("ValueError") and "offwidth" in found["init_wide"]
    assert "641" in found["init_wide"] and "640" in found["init_wide"]
    assert found["init_tall"].startswith("ValueError") and "offheight" in found["init_tall"]
    assert found["init_model"].startswith("TypeError") and "MjModel" in found["init_model"]
    assert found["init_max_geom"].startswith("ValueError") and "max_geom" in \
        found["init_max_geom"]
    assert found["del_after_failed_init"] == []
    assert found["cycle_collected"]
    assert found["render_after_gl_freed"].startswith("RuntimeError") and "freed" in \
        found["render_after_gl_freed"]
    assert found["close_after_gl_freed"] == "ok"
    assert found["keep_after"]


SIZES_FIRST = """
import sys, pytest, mjcffi
from tests.test_renderer import BOX
m = mjcffi.MjModel.from_xml_string(BOX)
with pytest.raises(ValueError, match=r"(?s)width 700 .*640.*offwidth=\\"700\\""):
    mjcffi.Renderer(m, height=10, width=700)
with pytest.raises(ValueError, match="height"):
    mjcffi.Renderer(m, height=-5)
loaded = [name for name in ("mjcffi.rendering._egl", "mjcffi.rendering._osmesa",
                            "mjcffi.rendering._glfw") if name in sys.modules]
print("loaded:", loaded)
"""


def test_sizes_are_checked_before_any_opengl_work():
    # in a fresh interpreter (other tests load backends into this one): the sizes
    # raise before a GL backend is even imported
    run = subprocess.run([sys.executable, "-c", SIZES_FIRST], cwd=ROOT, capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stdout.strip().splitlines()[-1] == "loaded: []"


def test_the_official_import_paths_name_one_class():
    import mjcffi.renderer
    from mjcffi.rendering.renderer import Renderer
    assert mjcffi.Renderer is mjcffi.renderer.Renderer is Renderer


# ------------------------------------------------------------ gymnasium

GYM_ENVS = ("Hopper-v5", "HalfCheetah-v5", "Ant-v5", "Humanoid-v5")


def gym_scenario(binding, path):
    """Frames of gymnasium's MuJoCo envs in rgb_array mode, with `mujoco` = `binding`."""
    import types
    try:
        import imageio  # noqa: F401
    except ImportError:
        # gymnasium's renderer imports it at the top, and writes images with it only
        # in its interactive viewer: no frame here touches it
        sys.modules["imageio"] = types.ModuleType("imageio")
    contexts = binding
    if binding == "mjcffi":
        sys.modules["mujoco"] = mjcffi
    else:
        try:
            import OpenGL  # noqa: F401
        except ImportError:
            # the official GL context modules need PyOpenGL: give gymnasium mjcffi's
            # context of the same backend, in which the official bindings draw
            backend = os.environ["MUJOCO_GL"]
            stand_in = types.ModuleType(f"mujoco.{backend}")
            stand_in.GLContext = mjcffi.GLContext
            sys.modules[f"mujoco.{backend}"] = stand_in
            contexts = "mjcffi"
    import gymnasium as gym
    frames = {}
    for name in GYM_ENVS:
        env = gym.make(name, render_mode="rgb_array", width=160, height=120)
        env.reset(seed=3)
        rng = np.random.default_rng(3)
        shots = [env.render()]
        for _ in range(12):
            env.step(rng.uniform(-0.5, 0.5, env.action_space.shape).astype(np.float32))
            shots.append(env.render())
        env.close()
        frames[name] = np.array(shots)
    np.savez(path, **frames)
    print(json.dumps({"contexts": contexts, "mujoco": sys.modules["mujoco"].__name__,
                      "env_uses": sys.modules["gymnasium.envs.mujoco.mujoco_env"].mujoco.__name__}))


@pytest.mark.parametrize("backend", BACKENDS)
def test_gymnasium_envs_render_the_same_pixels_with_mjcffi_as_mujoco(backend, tmp_path):
    pytest.importorskip("gymnasium")
    ours = _run(backend, "gym_scenario", "mjcffi", str(tmp_path / "mjcffi.npz"))
    theirs = _run(backend, "gym_scenario", "official", str(tmp_path / "official.npz"))
    assert ours["contexts"] == "mjcffi"
    assert (ours["mujoco"], ours["env_uses"]) == ("mjcffi", "mjcffi")
    assert (theirs["mujoco"], theirs["env_uses"]) == ("mujoco", "mujoco")
    with np.load(tmp_path / "mjcffi.npz") as a, np.load(tmp_path / "official.npz") as b:
        assert sorted(a.files) == sorted(b.files) == sorted(GYM_ENVS)
        for name in GYM_ENVS:
            assert a[name].shape == (13, 120, 160, 3) and a[name].dtype == np.uint8
            assert a[name].std() > 10, (name, "a blank recording proves nothing")
            assert not np.array_equal(a[name][0], a[name][-1]), (name, "the robot moved")
            differ = int(np.count_nonzero(a[name] != b[name]))
            assert differ == 0, (name, f"{differ} values differ ({theirs['contexts']} "
                                       f"contexts for the official bindings)")


# ------------------------------------------------------------ progress bar

PROGRESS = textwrap.dedent("""
    import sys
    if sys.argv[1] == "without":
        sys.modules["tqdm"] = None          # as if tqdm were not installed
    import mjcffi
    from mjcffi.rendering import recording
    from tests.test_renderer import BOX
    m = mjcffi.MjModel.from_xml_string(BOX)
    frames = recording.render_trajectory(m, [m.qpos0] * 7, height=20, width=30)
    print(frames.shape)
""")


@pytest.mark.parametrize("tqdm", ["with", "without"])
def test_recording_shows_a_progress_bar_when_tqdm_is_installed(tqdm):
    if tqdm == "with":
        pytest.importorskip("tqdm", reason="pip install tqdm ('mjcffi[progress]')")
    reason = _skip_reason("egl")
    if reason:
        pytest.skip(reason)
    run = subprocess.run([sys.executable, "-c", PROGRESS, tqdm], cwd=ROOT, env=_env("egl"),
                         capture_output=True, text=True, timeout=TIMEOUT)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stdout.strip().splitlines()[-1] == "(7, 20, 30, 3)"
    if tqdm == "with":
        assert "7/7" in run.stderr and "frame" in run.stderr
    else:
        assert "7/7" not in run.stderr
