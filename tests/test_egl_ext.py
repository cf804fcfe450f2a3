"""mjcffi.egl.egl_ext, the official `mujoco.egl.egl_ext`: PyOpenGL's EGL with device
enumeration, compared with the official module in the same process.

Each scenario runs in a subprocess (tests/_gl.py): PyOpenGL picks its platform once.
"""

import json
import pathlib
import subprocess
import sys

import pytest

from tests import _gl

MODULE = "tests.test_egl_ext"


def scenario_devices():
    from mjcffi.egl import egl_ext as ours
    from mujoco.egl import egl_ext as theirs
    found = {}
    for name, module in (("ours", ours), ("theirs", theirs)):
        devices = module.eglQueryDevicesEXT()
        display = module.eglGetPlatformDisplayEXT(module.EGL_PLATFORM_DEVICE_EXT, devices[0],
                                                  None)
        found[name] = {"devices": len(devices), "one": len(module.eglQueryDevicesEXT(1)),
                       "initialized": int(module.eglInitialize(display, None, None)),
                       "constants": [module.EGL_PLATFORM_DEVICE_EXT, module.EGL_CUDA_DEVICE_NV],
                       "cuda": _gl.outcome(lambda: module.eglQueryDeviceAttribEXT(
                           devices[0], module.EGL_CUDA_DEVICE_NV)).split("(")[0]}
    # every name of the official module is there (theirs star-imports OpenGL.EGL too)
    public = {name for name in dir(theirs) if name.startswith(("egl", "EGL"))}
    found["missing"] = sorted(public - set(dir(ours)))
    print(json.dumps(found))


def test_egl_ext_enumerates_devices_as_the_official_module_does():
    found = _gl.run(MODULE, "egl", "scenario_devices")
    assert found["missing"] == []
    assert found["ours"] == found["theirs"]
    assert found["ours"]["devices"] >= 1 and found["ours"]["one"] == 1
    assert found["ours"]["initialized"] == 1
    assert found["ours"]["constants"] == [0x313F, 0x323A]


def test_importing_mjcffi_egl_does_not_import_pyopengl():
    code = ("import sys, mjcffi.egl; print('OpenGL' in sys.modules)")
    reason = _gl.skip_reason("egl")
    if reason:
        pytest.skip(reason)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=_gl.env("egl"), timeout=120, cwd=_gl.ROOT)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["False"]


def test_without_pyopengl_the_import_error_names_the_extra():
    code = ("import sys; sys.modules['OpenGL'] = None\n"
            "try:\n    import mjcffi.egl.egl_ext\n"
            "except ImportError as error:\n    print(error)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, cwd=pathlib.Path(_gl.ROOT))
    assert done.returncode == 0, done.stderr[-2000:]
    assert "pip install 'mjcffi[egl-ext]'" in done.stdout
