"""The passive handle's overlays (set_figures/texts/images and clear_*) and the viewer's
bounded history of states.

The drawing runs in a subprocess under a display (Xvfb when there is none), as in
test_viewer.py: each overlay must change the captured frame where it belongs, only
there, and go after clear_*.  Frames are waited for by count (the viewer's meter),
with a generous deadline only as an upper bound.  The argument checks, the history's
bound and the managed viewer's stepping back need no window and run here.
"""

import inspect
import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

import mjcffi

glfw = pytest.importorskip("glfw", reason="the viewer needs the glfw package (pip install glfw)")

from mjcffi.viewer import _history, _user_overlays          # noqa: E402
from mjcffi.viewer._managed import Simulation               # noqa: E402

from .test_viewer import PREAMBLE, _script                   # noqa: E402

SCENE = """<mujoco><worldbody><light pos='0 0 3'/><geom type='plane' size='2 2 .1'/>
<body pos='0 0 .5'><freejoint/><geom size='.2'/></body></worldbody></mujoco>"""

OVERLAYS = PREAMBLE + f"""
import time
from mjcffi.viewer import _history
_history.MAX_STATES = 5                 # a small bound, to see it hold
m = mjcffi.MjModel.from_xml_string({SCENE!r})
d = mjcffi.MjData(m)
h = mjcffi.viewer.launch_passive(m, d, show_left_ui=False, show_right_ui=False)
v = h._viewer
v.show_info = False
H, W = 480, 640

def wait_frames(count, deadline=120):
    # frames drawn by the viewer's own loop, counted; the deadline is only an upper bound
    target, end = v.meter.frames + count, time.monotonic() + deadline
    while v.meter.frames < target:
        if time.monotonic() > end or not h.is_running():
            raise SystemExit(f"the viewer drew {{v.meter.frames}} of {{target}} frames")
        time.sleep(0.01)

def box(rect):
    # a window rect (from the bottom left) as image rows and columns (from the top left)
    return (slice(H - rect.bottom - rect.height, H - rect.bottom),
            slice(rect.left, rect.left + rect.width))

def changed(a, b):
    return (a != b).any(axis=-1)

def report(name, frame, rect=None, region=None):
    # changed pixels inside `region` (image rows, cols) and outside it
    mask = changed(frame, base)
    inside = np.zeros_like(mask)
    inside[region if region is not None else box(rect)] = True
    out[name] = [int(mask[inside].sum()), int(mask[~inside].sum())]

wait_frames(2)
base = v.capture()
out["base_again"] = int(changed(v.capture(), base).sum())     # frames are repeatable

# texts: placed by gridpos in the 3D view, the font and gridpos defaults the official's
h.set_texts((mjcffi.mjtFont.mjFONT_BIG, mjcffi.mjtGridPos.mjGRID_TOPRIGHT, "OVERLAY", "TEXT"))
report("text_topright", v.capture(), region=(slice(0, H // 4), slice(W // 2, W)))
h.set_texts([(None, None, "Left", None)])
report("text_default", v.capture(), region=(slice(0, H // 4), slice(0, W // 2)))
h.set_texts([(mjcffi.mjtFont.mjFONT_NORMAL, mjcffi.mjtGridPos.mjGRID_BOTTOMRIGHT, "a", "b"),
             (mjcffi.mjtFont.mjFONT_NORMAL, mjcffi.mjtGridPos.mjGRID_BOTTOMLEFT, "c", "d")])
frame = v.capture()
out["text_two"] = [int(changed(frame, base)[-H // 4:, W // 2:].sum()),
                   int(changed(frame, base)[-H // 4:, :W // 2].sum())]
h.clear_texts()
out["text_cleared"] = int(changed(v.capture(), base).sum())

# images: each fills its viewport, its first row at the top
rect = mjcffi.MjrRect(40, 60, 64, 48)
image = np.zeros((48, 64, 3), np.uint8)
image[:24] = (255, 0, 0)                # top half red
image[24:] = (0, 0, 255)                # bottom half blue
image[:, :8] = (0, 255, 0)              # a green band on the left
h.set_images((rect, image))
image[:] = 0                            # copied at set_images: this does not show
frame = v.capture()
report("image", frame, rect)
drawn = frame[box(rect)].astype(int)
expected = np.zeros((48, 64, 3), int)
expected[:24], expected[24:], expected[:, :8] = (255, 0, 0), (0, 0, 255), (0, 255, 0)
out["image_maxdiff"] = int(np.abs(drawn - expected).max())
h.clear_images()
out["image_cleared"] = int(changed(v.capture(), base).sum())

# figures: an opaque green figure fills its viewport; set again replaces the list
def green(img):
    return ((img[..., 1] > 200) & (img[..., 0] < 60) & (img[..., 2] < 60))
fig = mjcffi.MjvFigure()
fig.figurergba[:] = (0, 1, 0, 1)
fig.panergba[:] = (0, 1, 0, 1)
fig.linepnt[0] = 3
fig.linedata[0][:6] = (0, 0, 1, 1, 2, 0)
first = mjcffi.MjrRect(380, 20, 200, 150)
h.set_figures((first, fig))
fig.figurergba[:] = (1, 0, 1, 1)        # copied at set_figures: this does not show
fig.panergba[:] = (1, 0, 1, 1)
frame = v.capture()
report("figure", frame, first)
out["figure_green"] = float(green(frame[box(first)]).mean())
second = mjcffi.MjrRect(20, 300, 160, 120)
fig.figurergba[:] = (0, 1, 0, 1)
fig.panergba[:] = (0, 1, 0, 1)
h.set_figures([(second, fig)])
frame = v.capture()
report("figure_replaced", frame, second)
out["figure_first_gone"] = int(changed(frame, base)[box(first)].sum())
h.clear_figures()
out["figure_cleared"] = int(changed(v.capture(), base).sum())

# all three at once, drawn by the loop's own frames too, then all cleared
h.set_figures((first, fig))
h.set_texts((None, mjcffi.mjtGridPos.mjGRID_TOP, "all", None))
h.set_images((rect, expected.astype(np.uint8)))
wait_frames(3)
frame = v.capture()
out["all_figure"] = float(green(frame[box(first)]).mean())
out["all_image"] = int(np.abs(frame[box(rect)].astype(int) - expected).max())
out["all_text"] = int(changed(frame, base)[:H // 4, W // 4:3 * W // 4].sum())
h.clear_figures(); h.clear_texts(); h.clear_images()
wait_frames(2)
out["all_cleared"] = int(changed(v.capture(), base).sum())
out["viewport"] = [h.viewport.left, h.viewport.bottom, h.viewport.width, h.viewport.height]

# the history: the launch state and one a sync, the newest `capacity` of them
syncs = []
for _ in range(12):
    mjcffi.mj_step(m, d)
    h.sync()
    syncs.append((d.time, d.qpos.copy()))
state = np.empty(mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_INTEGRATION))
mjcffi.mj_getState(m, d, state, mjcffi.mjtState.mjSTATE_INTEGRATION)
out["history_len"] = len(h.history)
out["history_capacity"] = h.history.capacity
out["history_times"] = h.history.times().tolist()
out["sync_times"] = [t for t, _ in syncs]
out["history_newest_is_state"] = bool(np.array_equal(h.history[-1], state))
replay = mjcffi.MjData(m)
mjcffi.mj_setState(m, replay, h.history[0], mjcffi.mjtState.mjSTATE_INTEGRATION)
out["history_oldest_qpos"] = float(np.abs(replay.qpos - syncs[-5][1]).max())

out["frames"] = v.meter.frames
h.close()
out["closed"] = not h.is_running()
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def overlays(tmp_path_factory):
    return _script(tmp_path_factory, "overlays", OVERLAYS)


def test_frames_are_repeatable_so_changes_are_the_overlays(overlays):
    out, stderr = overlays
    assert out["base_again"] == 0
    assert "Traceback" not in stderr and "raised an exception" not in stderr


def test_texts_are_drawn_at_their_gridpos_and_cleared(overlays):
    out, _ = overlays
    inside, outside = out["text_topright"]
    assert inside > 100 and outside == 0
    inside, outside = out["text_default"]       # None, None: the official's top left
    assert inside > 20 and outside == 0
    assert all(count > 10 for count in out["text_two"])
    assert out["text_cleared"] == 0


def test_images_fill_their_viewport_top_row_first_and_are_cleared(overlays):
    out, _ = overlays
    inside, outside = out["image"]
    assert inside > 0.9 * 48 * 64 and outside == 0
    assert out["image_maxdiff"] <= 2             # the caller's later edit did not show
    assert out["image_cleared"] == 0


def test_figures_fill_their_viewport_are_replaced_and_cleared(overlays):
    out, _ = overlays
    inside, outside = out["figure"]
    assert inside > 0.5 * 200 * 150 and outside == 0
    assert out["figure_green"] > 0.5             # the caller's later edit did not show
    inside, outside = out["figure_replaced"]
    assert inside > 0.5 * 160 * 120 and outside == 0
    assert out["figure_first_gone"] == 0
    assert out["figure_cleared"] == 0


def test_all_overlays_together_in_the_loop_then_cleared(overlays):
    out, _ = overlays
    assert out["all_figure"] > 0.5 and out["all_image"] <= 2 and out["all_text"] > 10
    assert out["all_cleared"] == 0
    assert out["viewport"] == [0, 0, 640, 480]
    assert out["closed"]


def test_passive_history_keeps_the_newest_states_within_its_bound(overlays):
    out, _ = overlays
    assert out["history_capacity"] == 5
    assert out["history_len"] == 5               # launch + 12 syncs, the newest 5 kept
    assert out["history_times"] == out["sync_times"][-5:]
    assert out["history_newest_is_state"]
    assert out["history_oldest_qpos"] == 0


SCREEN = PREAMBLE + f"""
import glob, time
m = mjcffi.MjModel.from_xml_string({SCENE!r})
d = mjcffi.MjData(m)
h = mjcffi.viewer.launch_passive(m, d, show_left_ui=False, show_right_ui=False)
v = h._viewer

def wait_frames(count, deadline=120):
    target, end = v.meter.frames + count, time.monotonic() + deadline
    while v.meter.frames < target:
        if time.monotonic() > end or not h.is_running():
            raise SystemExit(f"the viewer drew {{v.meter.frames}} of {{target}} frames")
        time.sleep(0.01)

def green_on_screen():
    # Xvfb's screen memory, an XWD file under -fbdir: what the window has swapped to it
    raw = open(glob.glob(os.environ["FBDIR"] + "/Xvfb_screen0")[0], "rb").read()
    header = np.frombuffer(raw[:80], ">u4")
    size, width, height, line, ncolors = (int(header[i]) for i in (0, 4, 5, 12, 19))
    pixels = np.frombuffer(raw, np.uint8, line * height, size + 12 * ncolors)
    pixels = pixels.reshape(height, line)[:, :4 * width].reshape(height, width, 4)
    return int(((pixels[..., 1] == 255) & (pixels[..., 0] == 0) & (pixels[..., 2] == 0)).sum())

wait_frames(3)
out["before"] = green_on_screen()
image = np.zeros((40, 50, 3), np.uint8)
image[..., 1] = 255
h.set_images((mjcffi.MjrRect(30, 30, 50, 40), image))
wait_frames(3)
out["set"] = green_on_screen()
h.clear_images()
wait_frames(3)
out["cleared"] = green_on_screen()
h.close()
print(json.dumps(out))
"""


def test_overlays_reach_the_screen_through_the_render_loop(tmp_path):
    # what the loop swaps to the window, read from Xvfb's screen memory, not a capture()
    if shutil.which("xvfb-run") is None:
        pytest.skip("needs xvfb-run (apt-get install xvfb)")
    script = tmp_path / "screen.py"
    script.write_text(SCREEN, encoding="utf-8")
    fbdir = tmp_path / "fb"
    fbdir.mkdir()
    env = {**os.environ, "MUJOCO_GL": "egl", "FBDIR": str(fbdir)}
    env.pop("DISPLAY", None)
    result = subprocess.run(["xvfb-run", "-a", "-s", f"-screen 0 1280x1024x24 -fbdir {fbdir}",
                             sys.executable, str(script)], capture_output=True, text=True,
                            timeout=300, env=env)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    out = json.loads(result.stdout.strip().splitlines()[-1])
    assert out == {"before": 0, "set": 40 * 50, "cleared": 0}


# ---------------------------------------------------------------- no window needed

def test_handle_methods_have_the_official_signatures():
    official = pytest.importorskip("mujoco.viewer")
    for name in ("set_figures", "clear_figures", "set_texts", "clear_texts",
                 "set_images", "clear_images"):
        ours = inspect.signature(getattr(mjcffi.viewer.Handle, name))
        theirs = inspect.signature(getattr(official.Handle, name))
        assert list(ours.parameters) == list(theirs.parameters), name
    assert isinstance(mjcffi.viewer.Handle.viewport, property)
    assert isinstance(official.Handle.viewport, property)


def _error(call, *args):
    with pytest.raises((TypeError, ValueError)) as info:
        call(*args)
    return info.type, str(info.value)


def test_figure_arguments_are_checked():
    rect, fig = mjcffi.MjrRect(0, 0, 100, 50), mjcffi.MjvFigure()
    check = _user_overlays.check_figures
    assert len(check((rect, fig))) == 1
    assert len(check([(rect, fig), [rect, fig]])) == 2
    assert len(check(((rect, fig) for _ in range(3)))) == 3
    assert check([]) == ()
    copied = check((rect, fig))[0]
    assert copied[0] is not rect and copied[1] is not fig
    assert _error(check, None)[0] is TypeError
    kind, text = _error(check, [(rect, fig, 1)])
    assert kind is TypeError and "entry 0 must be a pair" in text
    kind, text = _error(check, [(rect, fig), ((0, 0, 1, 1), fig)])
    assert kind is TypeError and "entry 1" in text and "MjrRect" in text
    kind, text = _error(check, (rect, 3))
    assert kind is TypeError and "MjvFigure" in text
    bad = mjcffi.MjvFigure()
    bad.linepnt[2] = 5000                         # mjr_figure would read past linedata
    kind, text = _error(check, (rect, bad))
    assert kind is ValueError and "linepnt[2]" in text
    huge = mjcffi.MjrRect(2**31 - 10, 0, 100, 10)
    assert _error(check, (huge, fig))[0] is ValueError


def test_text_arguments_are_checked():
    check = _user_overlays.check_texts
    font, grid = mjcffi.mjtFont, mjcffi.mjtGridPos
    assert check((None, None, None, None)) == (
        (int(mjcffi.mjtFontScale.mjFONTSCALE_150), int(grid.mjGRID_TOPLEFT), b"", b""),)
    assert check([[font.mjFONT_BIG, grid.mjGRID_TOP, "a", b"b"]]) == (
        (2, int(grid.mjGRID_TOP), b"a", b"b"),)
    assert check([(np.int64(1), True, "a", "b")])[0][:2] == (1, 1)   # as the official
    assert check([(0, 99, "a", "b")])[0][1] == 99                    # MuJoCo draws it safely
    assert _error(check, None)[0] is TypeError
    assert _error(check, 5)[0] is TypeError
    kind, text = _error(check, [(0, 0, "a")])
    assert kind is ValueError and "4 values" in text                 # as the official
    kind, text = _error(check, [(0.5, 0, "a", "b")])
    assert kind is TypeError and "font" in text
    kind, text = _error(check, [(0, "top", "a", "b")])
    assert kind is TypeError and "gridpos" in text
    kind, text = _error(check, [(2**40, 0, "a", "b")])
    assert kind is ValueError and "C int" in text
    kind, text = _error(check, [(0, 0, 5, "b")])
    assert kind is TypeError and "text1" in text
    kind, text = _error(check, [(0, 0, "a", "caf\u00e9")])
    assert kind is ValueError and "text2" in text and "ASCII" in text
    kind, text = _error(check, [(0, 0, "x" * 600, None)])
    assert kind is ValueError and "mjMAXOVERLAY" in text


def test_image_arguments_are_checked():
    rect = mjcffi.MjrRect(5, 5, 4, 2)
    check = _user_overlays.check_images
    image = np.arange(24, dtype=np.uint8).reshape(2, 4, 3)
    (copied_rect, pixels), = check((rect, image))
    assert np.array_equal(pixels, image[::-1]) and pixels.flags.c_contiguous
    assert copied_rect is not rect
    assert len(check([(rect, np.zeros((2, 8, 3), np.uint8)[:, ::2])])) == 1
    assert check([(rect, np.ones((2, 4, 3), bool))])[0][1].dtype == np.uint8
    kind, text = _error(check, (rect, np.zeros((4, 2, 3), np.uint8)))
    assert kind is ValueError and "(4, 2)" in text and "(2, 4)" in text   # as the official
    kind, text = _error(check, (rect, np.zeros((2, 4), np.uint8)))
    assert kind is ValueError and "3 dimensions" in text
    kind, text = _error(check, (rect, np.zeros((2, 4, 4), np.uint8)))
    assert kind is ValueError and "3 channels" in text
    kind, text = _error(check, (rect, np.zeros((2, 4, 3), np.float32)))
    assert kind is ValueError and "uint8" in text
    assert _error(check, (rect, [[0]]))[0] is TypeError
    assert _error(check, ((5, 5, 4, 2), image))[0] is TypeError
    assert _error(check, [(rect, image, 0)])[0] is TypeError


SMALL = """<mujoco><worldbody><body><joint type='slide'/><geom size='.1'/></body>
</worldbody></mujoco>"""


def test_history_is_a_ring_of_the_newest_states():
    m = mjcffi.MjModel.from_xml_string(SMALL)
    d = mjcffi.MjData(m)
    history = _history.History(m, capacity=4)
    assert len(history) == 0 and history.capacity == 4
    with pytest.raises(IndexError):
        history[0]
    for _ in range(10):
        mjcffi.mj_step(m, d)
        history.record(m, d)
        assert len(history) <= 4
    steps = m.opt.timestep * np.arange(7, 11)
    assert len(history) == 4
    np.testing.assert_allclose(history.times(), steps)
    np.testing.assert_allclose([history[i][0] for i in (0, 1, -2, -1)], steps[[0, 1, 2, 3]])
    with pytest.raises(IndexError):
        history[4]
    with pytest.raises(IndexError):
        history[-5]
    with pytest.raises(TypeError):
        history[1.0]
    assert history.states().shape == (4, history.state_size)
    history[0][0] = -1                              # a copy
    assert history[0][0] == steps[0]
    history.restore(m, d, 1)
    assert d.time == steps[1]
    history.drop_newest(2)
    np.testing.assert_allclose(history.times(), steps[:2])
    history.record(m, d)
    assert len(history) == 3 and history[-1][0] == steps[1]
    history.clear()
    assert len(history) == 0


def test_history_capacity_is_bounded_in_bytes(monkeypatch):
    m = mjcffi.MjModel.from_xml_string(SMALL)
    size = mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_INTEGRATION)
    assert _history.History(m).capacity == _history.MAX_STATES == 2000
    monkeypatch.setattr(_history, "MAX_BYTES", 10 * size * 8 + 7)
    history = _history.History(m)
    assert history.capacity == 10 and history.nbytes <= _history.MAX_BYTES
    monkeypatch.setattr(_history, "MAX_BYTES", 1)    # never below one state
    assert _history.History(m).capacity == 1


def test_managed_viewer_steps_back_and_forward_through_its_history():
    m = mjcffi.MjModel.from_xml_string(SMALL)
    d = mjcffi.MjData(m)
    d.qvel[0] = 1.0
    sim = Simulation(m, d)                          # no window: keys go straight to it
    dt = m.opt.timestep
    sim._on_key(glfw.KEY_SPACE, 0)                  # pause
    for _ in range(5):
        sim._on_key(glfw.KEY_RIGHT, 0)              # one step each, each recorded
    assert len(sim.history) == 6 and d.time == pytest.approx(5 * dt)
    sim._on_key(glfw.KEY_LEFT, 0)
    sim._on_key(glfw.KEY_LEFT, 0)
    assert sim.viewer.scrub == -2 and d.time == pytest.approx(3 * dt)
    assert d.qpos[0] == pytest.approx(sim.history[-3][1])
    sim._on_key(glfw.KEY_RIGHT, 0)                  # forward in the history, no step
    assert sim.viewer.scrub == -1 and d.time == pytest.approx(4 * dt)
    for _ in range(10):
        sim._on_key(glfw.KEY_LEFT, 0)               # stops at the oldest
    assert sim.viewer.scrub == -5 and d.time == 0
    sim._on_key(glfw.KEY_RIGHT, 0)
    sim._on_key(glfw.KEY_SPACE, 0)                  # resume from t = dt: newer states go
    assert sim.viewer.scrub == 0 and not sim.paused
    np.testing.assert_allclose(sim.history.times(), [0, dt])
    sim._on_key(glfw.KEY_SPACE, 0)
    sim._on_key(glfw.KEY_RIGHT, 0)                  # at the newest: a step
    np.testing.assert_allclose(sim.history.times(), [0, dt, 2 * dt])
    sim._on_key(glfw.KEY_LEFT, 0)
    sim._on_key(glfw.KEY_BACKSPACE, 0)              # reset: back to the present
    assert sim.viewer.scrub == 0 and d.time == 0
