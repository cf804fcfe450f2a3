"""The OpenGL context a mujoco-py render context draws in, and its `device_id`.

mujoco-py's `MjRenderContextOffscreen(sim, device_id)` made its own OpenGL
context, on the GPU that `device_id` named (-1: the default).  Here the
backend is the one MUJOCO_GL names (see `context`), and `device_id` means
something to EGL only: with OSMesa or GLFW there is one device, and it is
ignored, as mujoco-py ignored it there.

EGL opens one display per process, on the device that MUJOCO_EGL_DEVICE_ID
names when it is first needed.  So `device_id=k` is honoured by setting
MUJOCO_EGL_DEVICE_ID=k in this process's environment before EGL's first
context (child processes inherit it); afterwards a `device_id` must agree
with the device chosen, else ValueError: one process renders on one GPU.
"""

import operator
import os

from ..rendering import _current
from ..rendering import context as _context

_ENV = "MUJOCO_EGL_DEVICE_ID"


def device_id(value):
    """`value` as an int of -1 or more; TypeError or ValueError naming device_id."""
    if isinstance(value, bool) or not hasattr(value, "__index__"):
        raise TypeError(f"device_id must be an int, not {type(value).__name__}")
    value = operator.index(value)
    if value < -1:
        raise ValueError(f"device_id must be -1 (the default device) or a device number, "
                         f"not {value}")
    return value


def context_class():
    """The GLContext class of MUJOCO_GL's backend; RuntimeError when rendering is off."""
    try:
        return _context.GLContext
    except AttributeError:
        raise RuntimeError(f"rendering is disabled: MUJOCO_GL="
                           f"{os.environ.get('MUJOCO_GL', '')!r}.  Set MUJOCO_GL to egl, "
                           f"osmesa or glfw before the first render") from None


def check_backend(name):
    """mujoco-py's `opengl_backend`: None, or the backend MUJOCO_GL chose (ValueError else)."""
    if name is None:
        return
    chosen = getattr(context_class(), "backend", "")
    if name != chosen:
        raise ValueError(f"opengl_backend={name!r}, but this process renders with "
                         f"{chosen!r} (MUJOCO_GL): MuJoCo takes its OpenGL functions from one "
                         f"backend per process; set MUJOCO_GL={name} before the first render")


def _egl_display_open():
    from ..rendering import _egl  # loaded already: the backend is EGL
    return _egl._display is not None


def _egl_device(device, width, height, cls):
    """An EGL GLContext on `device`, choosing the process's device if not chosen yet."""
    with _current.LOCK:
        chosen = os.environ.get(_ENV)
        if chosen is None and not _egl_display_open():
            os.environ[_ENV] = str(device)
            try:
                return cls(width, height)
            except RuntimeError as error:
                del os.environ[_ENV]
                raise ValueError(f"device_id={device}: {error}") from None
        if chosen is None:
            chosen = "0"           # the default display: the first device of EGL's order
        if chosen.strip() != str(device):
            raise ValueError(f"device_id={device}, but this process already renders on EGL "
                             f"device {chosen.strip()} ({_ENV}): EGL opens one device per "
                             f"process; render on another device in another process")
    return cls(width, height)


def gl_context(device, width, height):
    """A new GLContext of at least width x height pixels, on `device` (checked) for EGL."""
    device = device_id(device)
    cls = context_class()
    if device >= 0 and getattr(cls, "backend", "") == "egl":
        return _egl_device(device, width, height, cls)
    return cls(width, height)
