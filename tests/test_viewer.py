"""mjcffi.viewer under an X server: the passive handle, the managed loop, the app.

Each scenario runs in a subprocess (a window, OpenGL, threads: a crash must not take
pytest down) under the display there is, or under Xvfb started with xvfb-run.  The
scripts drive the viewer through its GLFW callbacks with synthetic events, on the
viewer's thread (Viewer.call), and print their findings as JSON on the last line.
"""

import json
import os
import shutil
import subprocess
import sys
import textwrap

import pytest

import mjcffi

pytest.importorskip("glfw", reason="the viewer needs the glfw package (pip install glfw)")
gymnasium = pytest.importorskip("gymnasium")

HUMANOID = os.path.join(os.path.dirname(gymnasium.__file__), "envs/mujoco/assets/humanoid.xml")
HOPPER = os.path.join(os.path.dirname(gymnasium.__file__), "envs/mujoco/assets/hopper.xml")


def _display_prefix():
    """The command prefix that gives a subprocess an X display."""
    if os.environ.get("DISPLAY"):
        return []
    if shutil.which("xvfb-run") is None:
        pytest.skip("no DISPLAY and no xvfb-run: install the xvfb package (apt-get install xvfb)")
    return ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24"]


def _run(args, timeout=60, env=None):
    environment = {**os.environ, "MUJOCO_GL": "egl", "PYTHONDONTWRITEBYTECODE": "1",
                   **(env or {})}
    result = subprocess.run(_display_prefix() + [sys.executable, *args], capture_output=True,
                            text=True, timeout=timeout, env=environment)
    return result


def _script(tmp_path_factory, name, body):
    """Run a Python script under a display; (its JSON findings, its stderr)."""
    path = tmp_path_factory.mktemp("viewer") / f"{name}.py"
    path.write_text(textwrap.dedent(body), encoding="utf-8")
    result = _run([str(path)])
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    return json.loads(result.stdout.strip().splitlines()[-1]), result.stderr


PREAMBLE = f"""
import json, os, sys
import numpy as np
import glfw
import mjcffi
from mjcffi.viewer import _viewer
_viewer.DEFAULT_SIZE = (640, 480)       # within the model's offscreen buffer
import mjcffi.viewer
HUMANOID = {HUMANOID!r}
HOPPER = {HOPPER!r}
out = {{}}
"""

PASSIVE = PREAMBLE + """
m = mjcffi.MjModel.from_xml_path(HUMANOID)
d = mjcffi.MjData(m)
keys = []
def key_callback(key):
    keys.append(key)
    if key == glfw.KEY_B:
        raise ValueError("boom from key_callback")

h = mjcffi.viewer.launch_passive(m, d, key_callback=key_callback,
                                 show_left_ui=False, show_right_ui=False)
v = h._viewer
for _ in range(100):
    mjcffi.mj_step(m, d)
    h.sync()
out["time"] = d.time
out["private_time"] = v.data.time
out["running"] = h.is_running()

# the window's frame against an offscreen Renderer of the same scene and camera
v.show_info = False
window = v.capture()
with mjcffi.Renderer(m, 480, 640) as renderer:
    renderer.update_scene(d, h.cam)
    offscreen = renderer.render()
diff = np.abs(window.astype(int) - offscreen.astype(int)).max(axis=-1)
out["shape"] = list(window.shape)
out["mean_diff"] = float(diff.mean())
out["frac_diff"] = float((diff > 16).mean())
out["window_mean"] = float(window.mean())

# the info overlay draws in the bottom-left corner
v.show_info = True
with_info = v.capture()
out["info_changed"] = int((with_info[-80:, :200] != window[-80:, :200]).any(axis=-1).sum())
v.show_info = False

# a user_scn geom: a big pure-red sphere in front of the humanoid
def red(img):
    return int(((img[..., 0] > 200) & (img[..., 1] < 40) & (img[..., 2] < 40)).sum())
out["red_before"] = red(window)
with h.lock():
    mjcffi.mjv_initGeom(h.user_scn.geoms[0], mjcffi.mjtGeom.mjGEOM_SPHERE, [0.3, 0, 0],
                        d.xpos[1], np.eye(3).ravel(), np.array([1, 0, 0, 1], np.float32))
    h.user_scn.ngeom = 1
    h.user_scn.flags[mjcffi.mjtRndFlag.mjRND_SHADOW] = 0
    h.user_scn.flags[mjcffi.mjtRndFlag.mjRND_REFLECTION] = 0
h.sync()
out["red_after"] = red(v.capture())
out["scene_shadow_flag"] = int(v.scene.flags[mjcffi.mjtRndFlag.mjRND_SHADOW])
# a flag changed in the GUI comes back to user_scn at sync
v.call(lambda: v.scene.flags.__setitem__(mjcffi.mjtRndFlag.mjRND_WIREFRAME, 1))
h.sync()
out["user_wireframe"] = int(h.user_scn.flags[mjcffi.mjtRndFlag.mjRND_WIREFRAME])
v.call(lambda: v.scene.flags.__setitem__(mjcffi.mjtRndFlag.mjRND_WIREFRAME, 0))
with h.lock():
    h.user_scn.ngeom = 0
h.sync()

# a left drag rotates the camera, a right drag pans it, the wheel zooms
before = (h.cam.azimuth, h.cam.elevation, h.cam.lookat.copy(), h.cam.distance)
def drag(button, mods, start, end):
    v.on_move(*start)
    v.on_button(button, glfw.PRESS, mods)
    v.on_move(*end)
    v.on_button(button, glfw.RELEASE, mods)
v.call(lambda: drag(glfw.MOUSE_BUTTON_LEFT, 0, (300, 200), (360, 230)))
out["azimuth_moved"] = h.cam.azimuth - before[0]
out["elevation_moved"] = h.cam.elevation - before[1]
v.call(lambda: drag(glfw.MOUSE_BUTTON_RIGHT, 0, (300, 200), (340, 260)))
out["lookat_moved"] = float(np.linalg.norm(h.cam.lookat - before[2]))
v.call(lambda: v.on_scroll(0, 2))
out["distance_moved"] = h.cam.distance - before[3]

# camera cycling: ] to the model's first camera, [ back to the free one
v.call(lambda: v.on_key(glfw.KEY_RIGHT_BRACKET, 0, glfw.PRESS, 0))
out["after_next"] = [int(h.cam.type), int(h.cam.fixedcamid)]
v.call(lambda: v.on_key(glfw.KEY_LEFT_BRACKET, 0, glfw.PRESS, 0))
out["after_prev"] = [int(h.cam.type), int(h.cam.fixedcamid)]
out["ncam"] = m.ncam

# key_callback: called with the key; its exception is reported, the viewer goes on
v.call(lambda: v.on_key(glfw.KEY_A, 0, glfw.PRESS, 0))
v.call(lambda: v.on_key(glfw.KEY_B, 0, glfw.PRESS, 0))
out["keys"] = keys
out["running_after_error"] = h.is_running()

# double-click the torso at the window's centre, then ctrl+right drag pushes it
with h.lock():
    h.cam.lookat[:] = d.xpos[1]
    h.cam.distance = 3.0
h.sync()
def double_click():
    v.on_move(320, 240)
    for _ in range(2):
        v.on_button(glfw.MOUSE_BUTTON_LEFT, glfw.PRESS, 0)
        v.on_button(glfw.MOUSE_BUTTON_LEFT, glfw.RELEASE, 0)
v.call(double_click)
body = int(h.perturb.select)
out["selected"] = body
reference = mjcffi.MjData(m)
mjcffi.mj_copyData(reference, m, d)
def push_start():
    v.on_move(320, 240)
    v.on_button(glfw.MOUSE_BUTTON_RIGHT, glfw.PRESS, glfw.MOD_CONTROL)
    v.on_move(420, 240)
v.call(push_start)
out["pert_active"] = int(h.perturb.active)
out["xfrc_before_sync"] = float(np.abs(d.xfrc_applied).sum())
h.sync()
out["xfrc_after_sync"] = float(np.abs(d.xfrc_applied[body]).sum())
for _ in range(100):
    mjcffi.mj_step(m, d)
    mjcffi.mj_step(m, reference)
    h.sync()
out["pushed_by"] = float(np.linalg.norm(d.xpos[body] - reference.xpos[body]))
v.call(lambda: v.on_button(glfw.MOUSE_BUTTON_RIGHT, glfw.RELEASE, glfw.MOD_CONTROL))
h.sync()
out["xfrc_after_release"] = float(np.abs(d.xfrc_applied).sum())

# state_only sync copies the integration state
d.qpos[0] += 0.5
h.sync(state_only=True)
out["state_only_qpos"] = float(v.data.qpos[0] - d.qpos[0])

out["frames"] = v.meter.frames
h.close()
out["closed"] = not h.is_running()
out["thread_ended"] = not h._thread.is_alive()
h.sync()                    # after close: a no-op, no error
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def passive(tmp_path_factory):
    return _script(tmp_path_factory, "passive", PASSIVE)


def test_passive_syncs_the_callers_physics_into_the_window(passive):
    out, _ = passive
    assert out["running"] and out["time"] > 0
    assert out["private_time"] == out["time"]
    assert out["frames"] > 0


def test_window_frame_matches_an_offscreen_render(passive):
    out, _ = passive
    assert out["shape"] == [480, 640, 3]
    assert out["window_mean"] > 20             # a scene, not a blank buffer
    assert out["mean_diff"] < 1.0
    assert out["frac_diff"] < 0.01             # antialiased edges may differ


def test_info_overlay_and_user_geoms_are_drawn(passive):
    out, _ = passive
    assert out["info_changed"] > 50
    assert out["red_before"] < 50 and out["red_after"] > 1000
    assert out["scene_shadow_flag"] == 0
    assert out["user_wireframe"] == 1


def test_mouse_moves_the_camera_and_brackets_cycle_cameras(passive):
    out, _ = passive
    assert out["azimuth_moved"] != 0 and out["elevation_moved"] != 0
    assert out["lookat_moved"] > 1e-3
    assert out["distance_moved"] > 0           # scrolling up backs away, as MuJoCo's samples
    if out["ncam"]:
        assert out["after_next"] == [mjcffi.mjtCamera.mjCAMERA_FIXED, 0]
    assert out["after_prev"] == [mjcffi.mjtCamera.mjCAMERA_FREE, -1]


def test_key_callback_errors_are_reported_and_the_viewer_survives(passive):
    out, stderr = passive
    import glfw
    # every key pressed reaches it, the viewer's own ([ ]) too
    assert out["keys"] == [glfw.KEY_RIGHT_BRACKET, glfw.KEY_LEFT_BRACKET, glfw.KEY_A, glfw.KEY_B]
    assert "ValueError: boom from key_callback" in stderr and "Traceback" in stderr
    assert out["running_after_error"]


def test_ctrl_drag_perturbation_pushes_the_selected_body_after_sync(passive):
    out, _ = passive
    assert out["selected"] > 0
    assert out["pert_active"] == mjcffi.mjtPertBit.mjPERT_TRANSLATE
    assert out["xfrc_before_sync"] == 0        # the caller's data waits for sync()
    assert out["xfrc_after_sync"] > 0
    assert out["pushed_by"] > 1e-3
    assert out["xfrc_after_release"] == 0


def test_state_only_sync_and_close(passive):
    out, _ = passive
    assert out["state_only_qpos"] == 0
    assert out["closed"] and out["thread_ended"]


MANAGED = PREAMBLE + """
import time
from mjcffi.viewer._managed import Simulation, file_loader
sim = Simulation(loader=file_loader(HUMANOID))
sim.open()
v = sim.viewer
def frames(n):
    for _ in range(n):
        sim.frame()
frames(3)
out["nbody"] = sim.model.nbody
start = time.monotonic()
while sim.data.time < 0.05 and time.monotonic() - start < 20:
    sim.frame()
out["ran"] = sim.data.time
v.on_key(glfw.KEY_SPACE, 0, glfw.PRESS, 0)
out["paused"] = sim.paused
t = sim.data.time
frames(5)
out["paused_advance"] = sim.data.time - t
v.on_key(glfw.KEY_RIGHT, 0, glfw.PRESS, 0)
out["single_step"] = sim.data.time - t
out["timestep"] = sim.model.opt.timestep
v.on_key(glfw.KEY_SPACE, 0, glfw.PRESS, 0)
t = sim.data.time
frames(5)
out["resumed_advance"] = sim.data.time - t
v.on_key(glfw.KEY_BACKSPACE, 0, glfw.PRESS, 0)
out["after_reset"] = sim.data.time
frames(2)
v.on_drop([HOPPER])
frames(2)
out["dropped_nbody"] = sim.model.nbody
frames(3)
v.on_key(glfw.KEY_L, 0, glfw.PRESS, glfw.MOD_CONTROL)
before = sim.data
frames(1)
out["reloaded"] = sim.data is not before and sim.model.nbody == out["dropped_nbody"]
v.on_drop(["/nonexistent/model.xml"])
frames(1)
out["message"] = v.message
out["nbody_after_bad_drop"] = sim.model.nbody
out["fps"] = v.meter.fps
out["panels"] = v.panels is not None and v.panels.alive
v.destroy()
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def managed(tmp_path_factory):
    return _script(tmp_path_factory, "managed", MANAGED)


def test_managed_viewer_steps_pauses_steps_once_and_resets(managed):
    out, _ = managed
    assert out["nbody"] == 14 and out["ran"] >= 0.05
    assert out["paused"] is True
    assert out["paused_advance"] == 0
    assert out["single_step"] == pytest.approx(out["timestep"])
    assert out["resumed_advance"] > 0
    assert out["after_reset"] == 0


def test_managed_viewer_loads_dropped_files_and_reloads(managed):
    out, stderr = managed
    assert out["dropped_nbody"] != out["nbody"]
    assert out["reloaded"]
    assert "load failed" in out["message"] and "nonexistent" in stderr
    assert out["nbody_after_bad_drop"] == out["dropped_nbody"]
    assert "UI panels" not in stderr           # the panels, when there, raised nothing


def test_standalone_app_renders_and_closes_cleanly():
    # closed after 1 s and 10 frames: a count of events, not a guess of how many frames a
    # loaded machine draws in a given time (it drew 1 in 3 s at a load of 10)
    result = _run(["-m", "mjcffi.viewer", "--mjcf", HUMANOID],
                  env={"MJCFFI_VIEWER_CLOSE_AFTER": "1", "MJCFFI_VIEWER_MIN_FRAMES": "10"})
    assert result.returncode == 0, result.stderr[-3000:]
    line = [s for s in result.stdout.splitlines() if s.startswith("mjcffi.viewer: closed")]
    assert line, result.stdout + result.stderr
    frames = int(line[0].split("after ")[1].split()[0])
    assert frames >= 10
    assert "nbody 14" in line[0]
    assert "Traceback" not in result.stderr
