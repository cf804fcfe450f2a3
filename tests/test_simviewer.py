"""mjcffi.sim's MjViewer and MjViewerBasic (mujoco-py's viewers) under an X server.

Each scenario runs in a subprocess under the display there is, or under Xvfb (the
helpers of test_viewer).  The scripts drive the viewer from the caller's loop, as
mujoco-py's users did (`sim.step(); viewer.render()`), press its keys through
`key_callback` with GLFW's key codes, and print their findings as JSON on the
last line.
"""

import json
import os
import subprocess
import sys
import textwrap

import pytest

from tests.test_viewer import HUMANOID, _run  # skips without glfw or gymnasium

import mjcffi

PREAMBLE = f"""
import json, os, sys, time
import numpy as np
import glfw
from mjcffi.viewer import _viewer
_viewer.DEFAULT_SIZE = (640, 480)       # the humanoid's offscreen buffer, for comparison
import mjcffi
from mjcffi.sim import MjSim, MjViewer, MjViewerBasic, MjRenderContextOffscreen, \\
    load_model_from_path
HUMANOID = {HUMANOID!r}
out = {{}}

def release(viewer, key, mods=0):
    viewer.key_callback(viewer.window, key, 0, glfw.PRESS, mods)
    viewer.key_callback(viewer.window, key, 0, glfw.RELEASE, mods)

def red(image):
    return int(((image[..., 0] > 200) & (image[..., 1] < 40) & (image[..., 2] < 40)).sum())
"""

VIEWER = PREAMBLE + """
TMP = sys.argv[1]
sim = MjSim(load_model_from_path(HUMANOID))
viewer = MjViewer(sim)
out["registered"] = [c is viewer for c in sim.render_contexts].count(True)
out["window_context"] = sim._render_context_window is viewer

# the caller's loop
frames = []
original_frame = viewer._render_frame
def counted():
    frames.append(sim.data.time)
    original_frame()
viewer._render_frame = counted
for _ in range(50):
    sim.step()
    viewer.render()
out["time"] = sim.data.time
out["frames_in_loop"] = len(frames)

# the window's frame against an offscreen render of the same camera
viewer._hide_overlay = True
window = viewer.capture()
offscreen = MjRenderContextOffscreen(sim)
for name in ("type", "fixedcamid", "trackbodyid", "distance", "azimuth", "elevation"):
    setattr(offscreen.cam, name, getattr(viewer.cam, name))
offscreen.cam.lookat[:] = viewer.cam.lookat
offscreen.render(640, 480)
reference = offscreen.read_pixels(640, 480, depth=False)[::-1]
diff = np.abs(window.astype(int) - reference.astype(int)).max(axis=-1)
out["shape"] = list(window.shape)
out["window_mean"] = float(window.mean())
out["mean_diff"] = float(diff.mean())
out["frac_diff"] = float((diff > 16).mean())

# the menu (H hides it) is drawn at the top left
viewer._hide_overlay = False
viewer._create_full_overlay()
with_menu = viewer.capture()
viewer._overlay.clear()
out["menu_pixels"] = int((with_menu[:200, :320] != window[:200, :320]).any(axis=-1).sum())
release(viewer, glfw.KEY_H)
out["hide_after_h"] = viewer._hide_overlay
release(viewer, glfw.KEY_H)
out["hide_after_hh"] = viewer._hide_overlay

# a marker is drawn in the next render() only, as mujoco-py's MjViewer
viewer._hide_overlay = True
viewer._render_every_frame = True
viewer.add_marker(type=mjcffi.mjtGeom.mjGEOM_SPHERE, size=[0.3, 0.3, 0.3],
                  pos=sim.data.xpos[1], rgba=[1, 0, 0, 1])
out["red_with_marker"] = red(viewer.capture())
viewer.render()
out["markers_after_render"] = len(viewer._markers)
out["red_after_render"] = red(viewer.capture())

# TAB steps through the model's cameras back to the free camera
cams = []
for _ in range(sim.model.ncam + 1):
    release(viewer, glfw.KEY_TAB)
    cams.append([int(viewer.cam.type), int(viewer.cam.fixedcamid)])
out["cams"] = cams
out["ncam"] = sim.model.ncam

# PRESS alone does nothing: mujoco-py's keys act on release
viewer.key_callback(viewer.window, glfw.KEY_S, 0, glfw.PRESS, 0)
out["speed_after_press"] = viewer._run_speed
release(viewer, glfw.KEY_S)
out["speed_after_s"] = viewer._run_speed
release(viewer, glfw.KEY_F)
release(viewer, glfw.KEY_F)
out["speed_after_sff"] = viewer._run_speed

flags = viewer.vopt.flags
V = mjcffi.mjtVisFlag
def flag_states(*names):
    return [int(flags[getattr(V, n)]) for n in names]
contacts = ("mjVIS_CONTACTPOINT", "mjVIS_CONTACTFORCE")
out["contacts"] = [flag_states(*contacts)]
release(viewer, glfw.KEY_C)
out["contacts"].append(flag_states(*contacts))
release(viewer, glfw.KEY_C)
out["contacts"].append(flag_states(*contacts))
out["transparent"] = [flag_states("mjVIS_TRANSPARENT")[0]]
release(viewer, glfw.KEY_R)
out["transparent"].append(flag_states("mjVIS_TRANSPARENT")[0])
out["inertia"] = [flag_states("mjVIS_INERTIA")[0]]
release(viewer, glfw.KEY_M)
out["inertia"].append(flag_states("mjVIS_INERTIA")[0])
out["frame"] = [int(viewer.vopt.frame)]
release(viewer, glfw.KEY_E)
out["frame"].append(int(viewer.vopt.frame))
out["group1"] = [int(viewer.vopt.geomgroup[1])]
release(viewer, glfw.KEY_1)
out["group1"].append(int(viewer.vopt.geomgroup[1]))
out["every_frame"] = [viewer._render_every_frame]
release(viewer, glfw.KEY_D)
out["every_frame"].append(viewer._render_every_frame)
release(viewer, glfw.KEY_D)
# the inertia boxes show in the picture
before = viewer.capture()
release(viewer, glfw.KEY_M)
out["inertia_changes_picture"] = int((viewer.capture() != before).any(axis=-1).sum())

# SPACE: render() keeps drawing, the physics untouched, until SPACE again
def hook_after(n, key):
    count = [0]
    def frame():
        count[0] += 1
        original_frame()
        if count[0] == n:
            release(viewer, key)
    viewer._render_frame = frame
    return count
viewer._render_frame = original_frame
release(viewer, glfw.KEY_SPACE)
out["paused"] = viewer._paused
t = sim.data.time
count = hook_after(5, glfw.KEY_SPACE)
viewer.render()
out["paused_frames"] = count[0]
out["paused_after"] = viewer._paused
out["paused_time_moved"] = sim.data.time - t
# RIGHT while paused: render() returns after a frame, still paused, for one step
release(viewer, glfw.KEY_SPACE)
count = hook_after(3, glfw.KEY_RIGHT)
viewer.render()
out["right_frames"] = count[0]
out["right_paused"] = viewer._paused
t = sim.data.time
sim.step()
count = hook_after(2, glfw.KEY_SPACE)
viewer.render()
out["one_step"] = sim.data.time - t
out["timestep"] = sim.model.opt.timestep
out["resumed"] = viewer._paused is False
viewer._render_frame = original_frame

# T: a png of the window
viewer._image_path = os.path.join(TMP, "frame_%07d.png")
release(viewer, glfw.KEY_T)
out["png"] = os.path.join(TMP, "frame_0000000.png")
out["png_exists"] = os.path.exists(out["png"])
out["image_idx"] = viewer._image_idx

# V: frames recorded while on, to a gif through imageio
viewer._video_path = os.path.join(TMP, "video_%07d.gif")
release(viewer, glfw.KEY_V)
out["recording"] = viewer._record_video
for _ in range(4):
    sim.step()
    viewer.render()
release(viewer, glfw.KEY_V)
out["video_frames"] = viewer._video_frame_count
out["video"] = os.path.join(TMP, "video_0000000.gif")
out["video_exists"] = os.path.exists(out["video"])
out["video_idx"] = viewer._video_idx
# no writer for the path: the frames are kept, and the viewer says so
viewer._video_path = os.path.join(TMP, "missing-dir", "video_%07d.gif")
release(viewer, glfw.KEY_V)
for _ in range(3):
    sim.step()
    viewer.render()
release(viewer, glfw.KEY_V)
out["kept_frames"] = len(viewer._video_frames)
out["kept_shape"] = list(viewer._video_frames[0].shape)

# the mouse: left drag rotates, right drag pans, the wheel zooms
cam = viewer.cam
before = (cam.azimuth, cam.elevation, cam.lookat.copy(), cam.distance)
def drag(button, start, end):
    viewer.on_move(*start)
    viewer.on_button(button, glfw.PRESS, 0)
    viewer.on_move(*end)
    viewer.on_button(button, glfw.RELEASE, 0)
drag(glfw.MOUSE_BUTTON_LEFT, (300, 200), (360, 230))
out["azimuth_moved"] = cam.azimuth - before[0]
out["elevation_moved"] = cam.elevation - before[1]
drag(glfw.MOUSE_BUTTON_RIGHT, (300, 200), (340, 260))
out["lookat_moved"] = float(np.linalg.norm(cam.lookat - before[2]))
viewer.on_scroll(0, 2)
out["distance_moved"] = cam.distance - before[3]

# closing the window: the next render() frees the viewer and raises SystemExit(0)
glfw.set_window_should_close(viewer.window, True)
try:
    sim.step()
    viewer.render()
    out["exit_code"] = "no exit"
except SystemExit as exit:
    out["exit_code"] = exit.code
out["window_after_close"] = viewer.window is None
out["registered_after_close"] = [c is viewer for c in sim.render_contexts].count(True)
out["window_context_after_close"] = sim._render_context_window is None
viewer.render()                        # freed: nothing, no error
out["offscreen_still_renders"] = float(sim.render(64, 48).mean())
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def viewer(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("simviewer_files")
    return _script_with_args(tmp_path_factory, "simviewer", VIEWER, [str(tmp)])


def _script_with_args(tmp_path_factory, name, body, args):
    """test_viewer's _script, with arguments for the script."""
    path = tmp_path_factory.mktemp("simviewer") / f"{name}.py"
    path.write_text(textwrap.dedent(body), encoding="utf-8")
    result = _run([str(path), *args], timeout=120)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    return json.loads(result.stdout.strip().splitlines()[-1]), result.stdout, result.stderr


def test_viewer_is_a_render_context_of_the_sim(viewer):
    out, _, _ = viewer
    assert out["registered"] == 1 and out["window_context"]


def test_step_render_loop_runs_and_paces_frames(viewer):
    out, _, _ = viewer
    assert out["time"] == pytest.approx(50 * 0.003)
    assert out["frames_in_loop"] >= 1          # at least one frame was drawn


def test_window_frame_matches_an_offscreen_render(viewer):
    out, _, _ = viewer
    assert out["shape"] == [480, 640, 3]
    assert out["window_mean"] > 20             # a scene, not a blank buffer
    assert out["mean_diff"] < 1.0
    assert out["frac_diff"] < 0.01             # antialiased edges may differ


def test_menu_and_h_key(viewer):
    out, _, _ = viewer
    assert out["menu_pixels"] > 500
    assert out["hide_after_h"] is True and out["hide_after_hh"] is False


def test_markers_last_one_render(viewer):
    out, _, _ = viewer
    assert out["red_with_marker"] > 1000
    assert out["markers_after_render"] == 0 and out["red_after_render"] < 50


def test_tab_cycles_cameras(viewer):
    out, _, _ = viewer
    fixed, free = int(mjcffi.mjtCamera.mjCAMERA_FIXED), int(mjcffi.mjtCamera.mjCAMERA_FREE)
    expected = [[fixed, i] for i in range(out["ncam"])] + [[free, -1]]
    assert out["ncam"] >= 1 and out["cams"] == expected


def test_run_speed_keys(viewer):
    out, _, _ = viewer
    assert out["speed_after_press"] == 1.0
    assert out["speed_after_s"] == 0.5 and out["speed_after_sff"] == 2.0


def test_display_flag_keys(viewer):
    out, _, _ = viewer
    assert out["contacts"] == [[0, 0], [1, 1], [0, 0]]
    assert out["transparent"] == [0, 1]
    assert out["inertia"] == [0, 1]
    assert out["inertia_changes_picture"] > 100
    assert out["frame"] == [0, 1]
    assert out["group1"][0] != out["group1"][1]
    assert out["every_frame"] == [True, False]


def test_space_pauses_render_until_space_and_right_steps_once(viewer):
    out, _, _ = viewer
    assert out["paused"] is True
    assert out["paused_frames"] == 5 and out["paused_after"] is False
    assert out["paused_time_moved"] == 0
    assert out["right_frames"] == 3 and out["right_paused"] is True
    assert out["one_step"] == pytest.approx(out["timestep"])
    assert out["resumed"]


def test_t_writes_a_png(viewer):
    out, stdout, _ = viewer
    imageio = pytest.importorskip("imageio.v2")
    assert out["png_exists"] and out["image_idx"] == 1
    assert out["png"] in stdout
    image = imageio.imread(out["png"])
    assert image.shape[:2] == (480, 640) and image.mean() > 20


def test_v_records_video_frames(viewer):
    out, stdout, _ = viewer
    imageio = pytest.importorskip("imageio.v2")
    assert out["video_frames"] >= 4 and out["video_exists"] and out["video_idx"] == 1
    assert len(imageio.mimread(out["video"])) == out["video_frames"]
    assert out["kept_frames"] >= 3 and out["kept_shape"] == [480, 640, 3]
    assert "kept" in stdout and "_video_frames" in stdout


def test_mouse_moves_the_camera(viewer):
    out, _, _ = viewer
    assert out["azimuth_moved"] != 0 and out["elevation_moved"] != 0
    assert out["lookat_moved"] > 1e-3
    assert out["distance_moved"] > 0


def test_closing_the_window_ends_cleanly(viewer):
    out, _, _ = viewer
    assert out["exit_code"] == 0
    assert out["window_after_close"] and out["registered_after_close"] == 0
    assert out["window_context_after_close"]
    assert out["offscreen_still_renders"] > 0


BASIC = PREAMBLE + """
sim = MjSim(load_model_from_path(HUMANOID))

class Keyed(MjViewerBasic):
    keys = []
    def key_callback(self, window, key, scancode, action, mods):
        self.keys.append((key, action))
        super().key_callback(window, key, scancode, action, mods)

viewer = Keyed(sim)
viewer.add_marker(type=mjcffi.mjtGeom.mjGEOM_SPHERE, size=[0.3, 0.3, 0.3],
                  pos=sim.data.xpos[1], rgba=[1, 0, 0, 1])
for _ in range(5):
    sim.step()
    viewer.render()
out["frames"] = viewer._meter.frames
out["red"] = red(viewer.capture())          # MjViewerBasic keeps its markers
viewer.on_key(glfw.KEY_A, 0, glfw.PRESS, 0)  # as the window delivers a key
out["keys"] = [list(k) for k in viewer.keys]
release(viewer, glfw.KEY_ESCAPE)
try:
    viewer.render()
    out["exit_code"] = "no exit"
except SystemExit as exit:
    out["exit_code"] = exit.code
out["closed"] = viewer.window is None
print(json.dumps(out))
"""


def test_basic_viewer_keeps_markers_forwards_keys_and_quits_on_escape(tmp_path_factory):
    out, _, _ = _script_with_args(tmp_path_factory, "basic", BASIC, [])
    import glfw
    assert out["frames"] == 5
    assert out["red"] > 1000
    assert out["keys"][0] == [glfw.KEY_A, glfw.PRESS]
    assert out["exit_code"] == 0 and out["closed"]


def test_importing_mjcffi_sim_does_not_import_glfw():
    code = ("import sys, mjcffi.sim; assert 'glfw' not in sys.modules, 'glfw imported'; "
            "from mjcffi.sim import MjViewer, MjViewerBasic; "
            "assert issubclass(MjViewer, MjViewerBasic); "
            "assert issubclass(MjViewerBasic, mjcffi.sim.MjRenderContext); "
            "assert 'glfw' in sys.modules; print('ok')")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            timeout=60, env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"})
    assert result.returncode == 0 and result.stdout.strip() == "ok", result.stderr[-2000:]


def test_viewer_refuses_a_non_sim():
    pytest.importorskip("glfw")
    from mjcffi.sim import MjViewer
    with pytest.raises(TypeError, match="sim must be an MjSim"):
        MjViewer(object())


WINDOW_MODE = PREAMBLE + """
sim = MjSim(load_model_from_path(HUMANOID))
out["returned"] = repr(sim.render(mode="window"))      # makes an MjViewer, as mujoco-py
first = sim._render_context_window
sim.step()
sim.render(mode="window")
out["same"] = sim._render_context_window is first
out["kind"] = type(first).__name__
out["registered"] = first in sim.render_contexts
print(json.dumps(out))
"""


def test_render_mode_window_makes_one_viewer_and_reuses_it(tmp_path_factory):
    out, _, _ = _script_with_args(tmp_path_factory, "window_mode", WINDOW_MODE, [])
    assert out == {"returned": "None", "same": True, "kind": "MjViewer", "registered": True}
