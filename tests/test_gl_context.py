"""GLContext: EGL, OSMesa and GLFW (under Xvfb) contexts that MuJoCo really renders with.

Every check that loads a GL library runs in a subprocess, one per backend:
MUJOCO_GL is read once per process, two GL backends should not share one, and
this pytest process must stay free of GL libraries (MjrContext without OpenGL
is tested elsewhere).  A backend is skipped only when its system library is
missing, with the Debian package to install; CI installs them all.
"""

import json
import os
import shutil
import subprocess
import importlib.util
import sys
import textwrap
import threading

import pytest

from mjcffi.rendering import _base, _current, _egl_devices, context
from tests._gl import env as _env, skip_reason as _skip_reason

TIMEOUT = 300


@pytest.fixture(scope="module")
def xvfb():
    """DISPLAY of a private Xvfb server, for the GLFW backend."""
    if shutil.which("Xvfb") is None:
        pytest.skip("Xvfb is missing: apt-get install xvfb")
    read, write = os.pipe()
    server = subprocess.Popen(["Xvfb", "-displayfd", str(write), "-screen", "0", "640x480x24",
                               "-nolisten", "tcp"], pass_fds=(write,),
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write)
    with os.fdopen(read) as pipe:
        number = pipe.readline().strip()
    assert number.isdigit(), "Xvfb did not report its display"
    yield f":{number}"
    server.terminate()
    server.wait(timeout=30)


def _run(code, env, *args):
    """Run `code` in a fresh interpreter; its last stdout line is JSON."""
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(code), *args], env=env,
                          capture_output=True, text=True, timeout=TIMEOUT)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


# ------------------------------------------------------------- the probe
#
# One subprocess per backend makes a context, renders the default scene through
# the raw mjr_* functions, and tries every rule; the tests below read its findings.

PROBE = r"""
import gc, importlib, json, sys, threading, weakref
import numpy as np
import mjcffi
from mjcffi import scenes

backend = sys.argv[1]
lib, ffi = mjcffi.lib, mjcffi.ffi
W, H = 160, 120
found = {}

def attempt(call):
    try:
        call()
    except Exception as error:
        return [type(error).__name__, str(error)]
    return None

def on_thread(call):
    out = []
    thread = threading.Thread(target=lambda: out.append(call()))
    thread.start()
    thread.join()
    return out[0]

# the official import paths, also through `import mujoco.<backend>` with mujoco -> mjcffi
module = importlib.import_module(f"mjcffi.{backend}")
import mjcffi.gl_context
sys.modules["mujoco"] = mjcffi
aliased = importlib.import_module(f"mujoco.{backend}")
found["paths"] = {
    "top": mjcffi.GLContext is module.GLContext,
    "gl_context": mjcffi.gl_context.GLContext is module.GLContext,
    "alias": aliased.GLContext is module.GLContext,
    "backend": module.GLContext.backend,
}

m = mjcffi.MjModel.from_xml_string(scenes.DEFAULT)
d = mjcffi.MjData(m)
mjcffi.mj_forward(m, d)
scene, camera, option = mjcffi.MjvScene(m, 1000), mjcffi.MjvCamera(), mjcffi.MjvOption()
mjcffi.mjv_defaultFreeCamera(m, camera)
viewport = ffi.new("mjrRect *", [0, 0, W, H])[0]

def render(con):
    mjcffi.mjv_updateScene(m, d, option, None, camera, mjcffi.mjtCatBit.mjCAT_ALL, scene)
    lib.mjr_setBuffer(mjcffi.mjtFramebuffer.mjFB_OFFSCREEN, con._ptr)
    lib.mjr_render(viewport, scene._ptr, con._ptr)
    rgb, depth = np.zeros((H, W, 3), np.uint8), np.zeros((H, W), np.float32)
    lib.mjr_readPixels(ffi.cast("unsigned char *", rgb.ctypes.data),
                       ffi.cast("float *", depth.ctypes.data), viewport, con._ptr)
    return rgb, depth

def red(rgb):
    return int(((rgb[..., 0] > 150) & (rgb[..., 1] < 60) & (rgb[..., 2] < 60)).sum())

ctx = mjcffi.GLContext(W, H)
found["repr_new"] = repr(ctx)
with ctx.as_current():          # nothing was current: released at the end
    con = mjcffi.MjrContext(m, mjcffi.mjtFontScale.mjFONTSCALE_150)
    rgb, depth = render(con)
found["repr_released"] = repr(ctx)
found["render"] = {"colors": len(np.unique(rgb.reshape(-1, 3), axis=0)),
                   "depth": [float(depth.min()), float(depth.max())], "red": red(rgb)}

# released by as_current: a worker thread draws the same pixels, and on its end
# gives the context up, so the main thread takes it back
found["worker_same_pixels"] = on_thread(
    lambda: (ctx.make_current(), bool(np.array_equal(render(con)[0], rgb)))[1])
found["repr_after_worker"] = repr(ctx)

# four threads contend for it, each drawing only inside `with ctx.as_current():`;
# a thread that finds it taken gets RuntimeError, one that holds it the same pixels
tally = {"same": 0, "other": 0, "refused": 0, "unexpected": []}

def contend():
    for _ in range(50):
        try:
            with ctx.as_current():
                key = "same" if np.array_equal(render(con)[0], rgb) else "other"
        except RuntimeError as error:
            key = "refused" if "current on thread" in str(error) else None
            if key is None:
                tally["unexpected"].append(str(error))
                continue
        tally[key] += 1

workers = [threading.Thread(target=contend) for _ in range(4)]
for worker in workers:
    worker.start()
for worker in workers:
    worker.join()
found["contention"] = tally

ctx.make_current()
found["main_after_worker"] = bool(np.array_equal(render(con)[0], rgb))
m.geom_rgba[1:] = [1, 0, 0, 1]                     # every geom but the floor
found["red_after_recolour"] = red(render(con)[0])

# current here: other threads are refused, the context still works here
found["refused"] = {
    "make_current": on_thread(lambda: attempt(ctx.make_current)),
    "as_current": on_thread(lambda: attempt(lambda: ctx.as_current().__enter__())),
    "free": on_thread(lambda: attempt(ctx.free)),
}
found["still_renders"] = red(render(con)[0]) == found["red_after_recolour"]

# sizes
found["sizes"] = {repr(args): attempt(lambda: mjcffi.GLContext(*args))
                  for args in [(0, 10), (10, -1), (2.5, 10), ("64", 10), (True, 10), (None, 10),
                               (10, 10**6)]}

# freed: refused, free twice harmless
spent = mjcffi.GLContext(8, 8)
spent.make_current()
spent.free()
found["freed"] = {"second_free": attempt(spent.free),
                  "make_current": attempt(spent.make_current),
                  "as_current": attempt(lambda: spent.as_current().__enter__()),
                  "repr": repr(spent)}

# a context current on a thread stays alive there; switching frees it
ctx.make_current()
ref = weakref.ref(ctx)
del ctx
gc.collect()
found["alive_while_current"] = ref() is not None
other = mjcffi.GLContext(8, 8)
other.make_current()
gc.collect()
found["collected_after_switch"] = ref() is None

if backend == "glfw":   # GLFW makes windows on the main thread only
    found["glfw_off_main"] = on_thread(lambda: attempt(lambda: mjcffi.GLContext(8, 8)))
    loose = mjcffi.GLContext(8, 8)
    found["glfw_free_off_main"] = on_thread(lambda: attempt(loose.free))
    found["glfw_after"] = attempt(lambda: mjcffi.GLContext(8, 8).free())

# freeing the GL context before the MjrContext that was made with it
other.free()
del con
gc.collect()
found["end"] = True
print(json.dumps(found))
"""


_PROBED = {}


def _probe(backend, request):
    """The probe's findings for `backend`, run once per test session."""
    reason = _skip_reason(backend)
    if reason:
        pytest.skip(reason)
    if backend not in _PROBED:
        display = request.getfixturevalue("xvfb") if backend == "glfw" else None
        _PROBED[backend] = _run(PROBE, _env(backend, display), backend)
    return _PROBED[backend]


@pytest.fixture(scope="module", params=["egl", "osmesa", "glfw"])
def probe(request):
    return _probe(request.param, request)


def test_the_official_import_paths_give_the_backend_class(probe):
    paths = probe["paths"]
    assert paths["top"] and paths["gl_context"] and paths["alias"]
    assert paths["backend"] in ("egl", "osmesa", "glfw")


def test_mujoco_renders_real_pixels(probe):
    found = probe["render"]
    assert found["colors"] > 20                          # shaded geoms, not a cleared buffer
    low, high = found["depth"]
    assert 0.0 < low < high <= 1.0                       # geoms nearer than the far plane
    assert found["red"] == 0
    assert probe["red_after_recolour"] > 50              # model edits reach the pixels


def test_a_context_handed_to_another_thread_draws_the_same_pixels(probe):
    assert probe["worker_same_pixels"] is True
    assert probe["main_after_worker"] is True
    for state in ("repr_new", "repr_released", "repr_after_worker"):
        assert "not current" in probe[state], state


def test_threads_contending_for_a_context_never_share_it(probe):
    tally = probe["contention"]
    assert tally["unexpected"] == [] and tally["other"] == 0
    assert tally["same"] > 0 and tally["same"] + tally["refused"] == 200


def test_a_context_is_current_on_one_thread_at_a_time(probe):
    for operation, error in probe["refused"].items():
        assert error is not None, operation
        kind, message = error
        assert kind == "RuntimeError" and "current on thread 'MainThread'" in message
    assert probe["still_renders"] is True


def test_bad_sizes_raise(probe):
    sizes = probe["sizes"]
    assert sizes["(0, 10)"][0] == "ValueError" and "max_width" in sizes["(0, 10)"][1]
    assert sizes["(10, -1)"][0] == "ValueError" and "max_height" in sizes["(10, -1)"][1]
    assert sizes["(10, 1000000)"][0] == "ValueError"
    for args in ["(2.5, 10)", "('64', 10)", "(True, 10)", "(None, 10)"]:
        assert sizes[args][0] == "TypeError" and "max_width must be an int" in sizes[args][1]


def test_a_freed_context_refuses_use_and_frees_once(probe):
    freed = probe["freed"]
    assert freed["second_free"] is None
    for operation in ("make_current", "as_current"):
        assert freed[operation] == ["RuntimeError", "this GLContext has been freed; make a new one"]
    assert "freed" in freed["repr"]


def test_a_current_context_lives_until_its_thread_lets_go(probe):
    assert probe["alive_while_current"] is True
    assert probe["collected_after_switch"] is True
    assert probe["end"] is True           # GL context freed before its MjrContext: no crash


def test_glfw_windows_are_made_on_the_main_thread_only(request):
    probe = _probe("glfw", request)
    kind, message = probe["glfw_off_main"]
    assert kind == "RuntimeError" and "main thread" in message
    assert probe["glfw_free_off_main"] is None and probe["glfw_after"] is None


# ------------------------------------------------------------- MUJOCO_GL


def test_mujoco_gl_names_the_backends(monkeypatch):
    assert context.backends("egl") == ("egl",)
    assert context.backends(" OSMesa ") == ("osmesa",)
    assert context.backends("glfw") == context.backends("glx") == ("glfw",)
    for value in ("disable", "disabled", "off", "false", "0"):
        assert context.backends(value) == ()
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.delenv("DISPLAY", raising=False)
    assert context.backends("") == ("egl", "osmesa")
    monkeypatch.setenv("DISPLAY", ":0")
    assert context.backends("1") == context.backends("") == ("glfw", "egl", "osmesa")
    with pytest.raises(RuntimeError, match="invalid value for environment variable MUJOCO_GL"):
        context.backends("vulkan")


CHOICE = """
import json, mjcffi
try:
    found = mjcffi.GLContext.backend
except Exception as error:
    found = [type(error).__name__, str(error)]
print(json.dumps(found))
"""


@pytest.mark.parametrize("value, expected", [
    ("disable", ["AttributeError", "module 'mjcffi.gl_context' has no attribute 'GLContext'"]),
    ("bogus", ["RuntimeError", "invalid value for environment variable MUJOCO_GL: 'bogus' "
                               "(mjcffi knows egl, osmesa, glfw or glx, or disable)"]),
])
def test_mjcffi_glcontext_follows_mujoco_gl(value, expected):
    found = _run(CHOICE, _env(value))
    assert found[0] == expected[0] and expected[1] in found[1]


def test_without_a_display_the_default_is_egl():
    if _skip_reason("egl"):
        pytest.skip(_skip_reason("egl"))
    assert _run(CHOICE, _env("")) == "egl"


MISSING = """
import cffi, json, sys

def no_library(self, name, flags=0):
    raise OSError(f"{name}: cannot open shared object file")

cffi.FFI.dlopen = no_library
sys.modules["glfw"] = None              # as if the package were not installed
import mjcffi
found = {}
for backend in ("egl", "osmesa", "glfw"):
    try:
        __import__(f"mjcffi.{backend}")
    except ImportError as error:
        found[backend] = str(error)
try:
    mjcffi.GLContext(10, 10)
except ImportError as error:
    found["chosen"] = str(error)
print(json.dumps(found))
"""


def test_a_missing_library_names_what_to_install():
    found = _run(MISSING, _env("osmesa"))
    assert "apt-get install libegl1 libgl1-mesa-dri" in found["egl"]
    assert "apt-get install libosmesa6" in found["osmesa"]
    assert "pip install 'mjcffi[glfw]'" in found["glfw"]
    assert "MUJOCO_GL='osmesa'" in found["chosen"] and "libosmesa6" in found["chosen"]


def test_without_a_display_glfw_says_to_use_xvfb():
    if importlib.util.find_spec("glfw") is None:
        pytest.skip("the glfw package is missing: pip install 'mjcffi[glfw]'")
    found = _run(CHOICE.replace(".backend", "(10, 10)"), _env("glfw"))
    assert found[0] == "RuntimeError"
    assert "GLFW failed to initialise" in found[1] and "xvfb" in found[1]


# ------------------------------------------------------------- EGL devices

DEVICE = """
import json, mjcffi
from mjcffi import scenes
try:
    ctx = mjcffi.GLContext(8, 8)
    ctx.make_current()
    con = mjcffi.MjrContext(mjcffi.MjModel.from_xml_string(scenes.DEFAULT), 150)
    from mjcffi.rendering import _egl
    found = _egl.display()[2]
except Exception as error:
    found = [type(error).__name__, str(error)]
print(json.dumps(found))
"""


@pytest.mark.parametrize("device_id, expected", [
    ("0", "EGL device 0 of"),
    ("99", "MUJOCO_EGL_DEVICE_ID must be an integer between 0 and"),
    ("first", "MUJOCO_EGL_DEVICE_ID must be an integer, got 'first'"),
])
def test_mujoco_egl_device_id_picks_a_device(device_id, expected):
    if _skip_reason("egl"):
        pytest.skip(_skip_reason("egl"))
    found = _run(DEVICE, _env("egl", MUJOCO_EGL_DEVICE_ID=device_id))
    if expected.startswith("EGL device"):
        assert isinstance(found, str) and found.startswith(expected), found
    else:
        assert found[0] == "RuntimeError" and expected in found[1], found


def test_egl_devices_follow_cuda_order_when_the_driver_tells_it():
    devices = ["mesa", "gpu_a", "gpu_b"]
    cuda = [None, 1, 0]                      # EGL lists CUDA 1 before CUDA 0
    assert _egl_devices.candidates(devices, cuda, None, None) == ["gpu_b", "gpu_a", "mesa"]
    assert _egl_devices.candidates(devices, cuda, "1", None) == ["gpu_a", "mesa", "gpu_b"]
    assert _egl_devices.candidates(devices, cuda, "1", "0") == ["gpu_a"]   # first visible
    assert _egl_devices.candidates(devices, cuda, None, "1") == ["gpu_a"]  # CUDA id 1
    assert _egl_devices.candidates(devices, cuda, None, "2") == ["mesa"]   # then by order
    # without CUDA ids (Mesa), EGL's own order
    assert _egl_devices.candidates(devices, [None] * 3, "1", "2") == ["gpu_b"]
    # two devices claiming one CUDA id: no mapping
    assert _egl_devices.candidates(devices, [0, 0, None], None, None) == devices
    assert _egl_devices.parse_visible("GPU-1234,0") is None
    with pytest.raises(RuntimeError, match="between 0 and 2"):
        _egl_devices.candidates(devices, cuda, None, "7")
    with pytest.raises(RuntimeError, match="lists no device"):
        _egl_devices.candidates([], [], None, "0")


# ------------------------------------------------------------- the contract, without GL


class FakeContext(_base.GLContextBase):
    """A backend that records the C calls it would make, and on which thread."""

    backend = "fake"

    def _create(self, width, height):
        self.calls = []
        return object()

    def _bind(self):
        self.calls.append(("bind", threading.get_ident()))

    def _unbind(self):
        self.calls.append(("unbind", threading.get_ident()))

    def _destroy(self, native):
        self.calls.append(("destroy", threading.get_ident()))


def test_an_ending_thread_releases_its_context_on_itself():
    ctx = FakeContext(4, 4)
    seen = []

    def work():
        ctx.make_current()
        seen.append(threading.get_ident())

    worker = threading.Thread(target=work)
    worker.start()
    worker.join()
    assert ctx.calls == [("bind", seen[0]), ("unbind", seen[0])]
    assert "not current" in repr(ctx)
    ctx.make_current()
    ctx.free()
    main = threading.get_ident()
    assert ctx.calls[2:] == [("bind", main), ("unbind", main), ("destroy", main)]
    assert _current.current() is None


def test_as_current_restores_the_previous_context():
    first, second = FakeContext(4, 4), FakeContext(4, 4)
    first.make_current()
    with second.as_current():
        assert _current.current() is second and "not current" in repr(first)
    assert _current.current() is first and "not current" in repr(second)
    with first.as_current():             # already current: no C call
        pass
    assert [name for name, _ in first.calls] == ["bind", "bind"]
    first.free()
    second.free()


def test_a_failed_construction_leaves_nothing_to_free():
    class Failing(FakeContext):
        def _create(self, width, height):
            raise RuntimeError("no driver")

    with pytest.raises(RuntimeError, match="no driver"):
        Failing(4, 4)
    with pytest.raises(ValueError, match="max_height must be a positive number of pixels, not 0"):
        FakeContext(4, 0)
    with pytest.raises(ValueError, match=f"max_width must be at most {FakeContext.max_size} "):
        FakeContext(FakeContext.max_size + 1, 4)
