"""MuJoCo's first-party plugins (mujoco.pid, mujoco.sdf.*, mujoco.sensor.*, ...).

The mujoco-core wheel ships them as shared libraries in its `plugin/` folder;
each registers its plugins with MuJoCo when it is loaded.  The official
bindings load them all at import.  mjcffi loads them on first use instead (the
first model loaded, or the first MuJoCo function looked up), so that
`import mjcffi` stays cheap: `load_bundled()` does it, once per process.

`PLUGIN_HANDLES` (the loaded libraries, as ctypes.CDLL), `PLUGINS_DIR` and
`HEADERS_DIR` (the headers to build a plugin against) have the official names
and meanings.  Reading `PLUGIN_HANDLES` loads the plugins first.

Both bindings in one process load the same files: the dynamic loader maps each
library once, so a plugin is never registered twice.
"""

import importlib.machinery
import os
import threading
import warnings

from .library import MUJOCO_LIBRARY

__all__ = ["HEADERS_DIR", "PLUGINS_DIR", "PLUGIN_HANDLES", "load_bundled"]

_LIBRARY_SUFFIXES = (".so", ".dylib", ".dll")


def _core_folder():
    """The folder of the installed `mujoco` package that holds libmujoco.

    Searched on sys.path, not through sys.modules: after
    `sys.modules['mujoco'] = mjcffi`, importlib.util.find_spec('mujoco') is
    mjcffi itself.
    """
    spec = importlib.machinery.PathFinder.find_spec("mujoco")
    folders = list(spec.submodule_search_locations or ()) if spec else []
    for folder in folders:
        if os.path.exists(os.path.join(folder, MUJOCO_LIBRARY)):
            return folder
    # where the compiled module's rpath looks: site-packages/mjcffi/../mujoco
    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))     # mjcffi/
    return os.path.normpath(os.path.join(package, os.pardir, "mujoco"))


_CORE = _core_folder()
HEADERS_DIR = os.path.join(_CORE, "include", "mujoco")
PLUGINS_DIR = os.path.join(_CORE, "plugin")

_handles: list = []         # PLUGIN_HANDLES, filled by load_bundled()
_lock = threading.Lock()
_loaded = False


def _library_paths(folder):
    """Shared libraries under `folder`, in a stable order; other files warn."""
    found = []
    for directory, subdirs, filenames in os.walk(folder):
        subdirs.sort()
        for filename in sorted(filenames):
            path = os.path.join(directory, filename)
            if os.path.splitext(filename)[1] in _LIBRARY_SUFFIXES:
                found.append(path)
            elif filename != "__init__.py":
                warnings.warn(f"{path} is not a plugin library (.so, .dylib or .dll): "
                              "skipped", ImportWarning, stacklevel=3)
    return found


def load_bundled():
    """Load the plugin libraries of mujoco-core's `plugin/` folder, once.

    Called by every model loader; safe to call from many threads.  A library
    that cannot be loaded gives a RuntimeWarning, and the others still load.
    """
    global _loaded
    if _loaded:
        return
    with _lock:
        if _loaded:
            return
        import ctypes       # NumPy has imported it already wherever models are loaded
        for path in _library_paths(PLUGINS_DIR) if os.path.isdir(PLUGINS_DIR) else ():
            try:
                _handles.append(ctypes.CDLL(path))
            except OSError as exc:
                warnings.warn(f"Could not load the MuJoCo plugin library {path}: {exc}",
                              RuntimeWarning, stacklevel=2)
        _loaded = True


def __getattr__(name):
    if name == "PLUGIN_HANDLES":
        load_bundled()
        return _handles
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | {"PLUGIN_HANDLES"})
