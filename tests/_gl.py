"""What the rendering tests share: whether a GL backend can run here (else the
reason to skip, naming the Debian package), the environment of a subprocess
that renders with it, and running a scenario there.

Rendering runs in subprocesses: one GL backend per process (MUJOCO_GL is read
once), and a crash fails a test instead of ending pytest.
"""

import functools
import importlib.util
import json
import os
import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
TIMEOUT = 300

# Variables that would pick another backend, display or GPU for the subprocess.
_CHOOSERS = ("MUJOCO_GL", "PYOPENGL_PLATFORM", "DISPLAY", "WAYLAND_DISPLAY",
             "MUJOCO_EGL_DEVICE_ID")


def _loads(*names):
    """Whether cffi can dlopen one of the shared libraries `names`, tried in a subprocess."""
    code = ("import cffi, sys\nfor n in sys.argv[1:]:\n    try: cffi.FFI().dlopen(n)\n"
            "    except OSError: continue\n    sys.exit(0)\nsys.exit(1)")
    return subprocess.run([sys.executable, "-c", code, *names], timeout=60).returncode == 0


@functools.lru_cache(maxsize=None)
def skip_reason(backend):
    """None where `backend` can run here; else why not, naming what to install."""
    if backend == "egl" and not _loads("libEGL.so.1"):
        return "libEGL is missing: apt-get install libegl1 libgl1-mesa-dri"
    if backend == "osmesa" and not _loads("libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"):
        return "libOSMesa is missing: apt-get install libosmesa6"
    if backend == "glfw" and importlib.util.find_spec("glfw") is None:
        return "the glfw package is missing: pip install 'mjcffi[glfw]'"
    if backend == "glfw" and shutil.which("Xvfb") is None:
        return "Xvfb is missing: apt-get install xvfb"
    return None


def env(backend, display=None, **extra):
    """os.environ for a subprocess rendering with `backend` (PYOPENGL_PLATFORM too, for
    the official bindings' own contexts), on `display` if given."""
    out = {k: v for k, v in os.environ.items() if k not in _CHOOSERS}
    out.update(MUJOCO_GL=backend, PYTHONDONTWRITEBYTECODE="1")
    if backend in ("egl", "osmesa"):            # PyOpenGL's names for them
        out["PYOPENGL_PLATFORM"] = backend
    if display:
        out["DISPLAY"] = display
    out.update(extra)
    return out


def run(module, backend, scenario, *args, timeout=TIMEOUT):
    """Run `scenario(*args)`, a function of the test module `module`, under `backend`
    in a fresh interpreter; the JSON of its last line of output."""
    import pytest
    reason = skip_reason(backend)
    if reason:
        pytest.skip(reason)
    call = f"from {module} import {scenario}; {scenario}(*{list(args)!r})"
    done = subprocess.run([sys.executable, "-c", call], cwd=ROOT, env=env(backend),
                          capture_output=True, text=True, timeout=timeout)
    assert done.returncode == 0, f"exit {done.returncode}\n{done.stderr[-4000:]}"
    return json.loads(done.stdout.strip().splitlines()[-1])


def outcome(call):
    """'ok', or 'ExceptionName: message' of `call()`, for a test to judge."""
    try:
        call()
    except Exception as exc:         # noqa: BLE001  (returned, for the test to judge)
        return f"{type(exc).__name__}: {exc}"
    return "ok"
