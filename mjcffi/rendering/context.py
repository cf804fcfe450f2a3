"""`GLContext`: the backend that the environment variable MUJOCO_GL names.

MUJOCO_GL is read once, on first use of `GLContext` here (through
`mjcffi.GLContext` or `import mjcffi.gl_context`, never at `import mjcffi`):

- `egl`, `osmesa`: that backend;
- `glfw` (or `glx`): the GLFW backend;
- unset, empty, `1`, `true`, `on`, `enable(d)`: the official bindings take
  GLFW here and nothing else.  mjcffi also takes GLFW when the glfw package
  is installed and a display is set (DISPLAY or WAYLAND_DISPLAY), and where
  the official bindings would fail, goes on to EGL, then OSMesa;
- `0`, `false`, `off`, `disable(d)`: no GLContext at all, as official
  (`mjcffi.GLContext` raises AttributeError);
- anything else: RuntimeError.

When the chosen backend's library is missing, `GLContext` is still a class,
whose construction raises ImportError naming what to install, as official.
"""

import importlib
import os

from ._base import GLContextBase

_DISABLED = ("disable", "disabled", "off", "false", "0")
_DEFAULT = ("", "enable", "enabled", "on", "true", "1")
_NAMED = {"egl": "egl", "osmesa": "osmesa", "glfw": "glfw", "glx": "glfw"}


def backends(value):
    """The backends to try in turn for a MUJOCO_GL value; () when rendering is disabled."""
    value = value.strip().lower()
    if value in _DISABLED:
        return ()
    if value in _NAMED:
        return (_NAMED[value],)
    if value in _DEFAULT:
        display = os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
        return ("glfw", "egl", "osmesa") if display else ("egl", "osmesa")
    raise RuntimeError(f"invalid value for environment variable MUJOCO_GL: {value!r} "
                       "(mjcffi knows egl, osmesa, glfw or glx, or disable)")


def load(backend):
    """The GLContext class of one backend ('egl', 'osmesa', 'glfw'); ImportError if missing."""
    return importlib.import_module(f"._{backend}", __package__).GLContext


def _missing(reasons):
    """A GLContext class whose construction raises ImportError with `reasons`."""
    text = "; ".join(reasons)

    class GLContext(GLContextBase):
        """Placeholder: no OpenGL backend could be loaded (see the ImportError)."""

        backend = "none"

        def __init__(self, max_width, max_height):
            raise ImportError(f"no OpenGL backend for MUJOCO_GL="
                              f"{os.environ.get('MUJOCO_GL', '')!r}: {text}")

    return GLContext


def choose(value):
    """The GLContext class for a MUJOCO_GL value, or None when rendering is disabled."""
    names = backends(value)
    if not names:
        return None
    reasons = []
    for name in names:
        try:
            return load(name)
        except ImportError as error:
            reasons.append(f"{name}: {error}")
    return _missing(reasons)


def __getattr__(name):
    # GLContext is chosen on first use, so that importing this module for
    # `backends` or `choose` loads no library
    if name == "GLContext":
        chosen = choose(os.environ.get("MUJOCO_GL", ""))
        if chosen is not None:
            globals()["GLContext"] = chosen
            return chosen
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
