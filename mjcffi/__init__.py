"""mjcffi: a cffi binding of the MuJoCo physics engine.

Generated from the headers of the mujoco-core wheel.  Code written for the
official bindings runs with `import mjcffi as mujoco`: MjModel, MjData and
the other struct classes, MuJoCo's functions, enums (mjtObj, ...) and
#define constants (mjPI, mjMINVAL, ...) are attributes of this package.
`mjcffi.ffi` and `mjcffi.lib` give the raw C API.

Only the enums, constants and the compiled module load at import; the rest
loads on first use, so that `import mjcffi` stays cheap.
"""

import importlib
import importlib.util
import sys

from ._support import aliases as _aliases
from ._support import hand_written as _hand_written
from ._support import official_source as _official_source
from . import _private_paths
from ._generated.constants import *  # noqa: F401,F403
from ._generated.enums import *  # noqa: F401,F403
from ._support.errors import ArgumentError, FatalError, IdError  # noqa: F401
from ._support.library import ffi, lib  # noqa: F401

# What code means by `mujoco.__version__`: the version of MuJoCo itself (the official
# bindings share MuJoCo's), so version-gated code takes its MuJoCo 4 path.  mjcffi's
# own version, also in the package metadata, is __mjcffi_version__.
__version__ = ffi.string(lib.mj_versionString()).decode()
__mjcffi_version__ = "0.1.0"

# public name -> module that defines it, imported on first use
_LAZY = {
    "MJTNUM_DTYPE": "._support.views", "MJTNUM_BYTES": "._support.views",   # NumPy loads on first use
    "MjModel": ".model",
    "MjData": ".data",
    "MjWarningError": ".warning_errors",
    "set_warnings_as_errors": ".warning_errors",
    "get_warnings_as_errors": ".warning_errors",
    "ignore_warnings": ".warning_errors",
    "set_mjcb_passive": "._support.callbacks", "get_mjcb_passive": "._support.callbacks",
    "set_mjcb_control": "._support.callbacks", "get_mjcb_control": "._support.callbacks",
    "set_mjcb_contactfilter": "._support.callbacks", "get_mjcb_contactfilter": "._support.callbacks",
    "set_mjcb_sensor": "._support.callbacks", "get_mjcb_sensor": "._support.callbacks",
    "set_mjcb_time": "._support.callbacks", "get_mjcb_time": "._support.callbacks",
    "set_mjcb_act_dyn": "._support.callbacks", "get_mjcb_act_dyn": "._support.callbacks",
    "set_mjcb_act_gain": "._support.callbacks", "get_mjcb_act_gain": "._support.callbacks",
    "set_mjcb_act_bias": "._support.callbacks", "get_mjcb_act_bias": "._support.callbacks",
    "install_timer": "._support.callbacks",
    "set_mju_user_warning": ".user_handlers", "get_mju_user_warning": ".user_handlers",
    "set_mju_user_malloc": ".user_handlers", "get_mju_user_malloc": ".user_handlers",
    "set_mju_user_free": ".user_handlers", "get_mju_user_free": ".user_handlers",
    "MjLogConfig": ".log_config",               # the struct class, with get() and set()
    "_functions": ".functions",    # the official mujoco._functions: _realloc_con_efc, ...
    "MjVfs": ".vfs",
    "HEADERS_DIR": "._support.plugins", "PLUGINS_DIR": "._support.plugins",
    "PLUGIN_HANDLES": "._support.plugins",                   # reading it loads the bundled plugins
    "mjDISABLESTRING": "._support.stringtables", "mjENABLESTRING": "._support.stringtables",
    "mjTIMERSTRING": "._support.stringtables", "mjLABELSTRING": "._support.stringtables",
    "mjFRAMESTRING": "._support.stringtables", "mjVISSTRING": "._support.stringtables",
    "mjRNDSTRING": "._support.stringtables", "mjTOPICSTRING": "._support.stringtables",
    "GLContext": ".gl_context",     # reads MUJOCO_GL; absent when it says disable, as official
    "Renderer": ".renderer",        # loads a GL backend on construction, not on import
    "MjSpec": ".spec",              # the hand-written class over the generated mjSpec struct
    "from_zip": ".spec", "to_zip": ".spec",
    "MjStruct": ".structs.mjspec",  # typing.Union of the element classes, as official
    # the live vector attributes of spec elements (body.userdata, texture.cubefiles, ...)
    "MjCharVec": "._support.element_fields",
    **{name: "._support.element_vectors" for name in (
        "MjDoubleVec", "MjFloatVec", "MjIntVec", "MjStringVec")},
    # the element classes, with their hand-written methods (spec/elements.py)
    **{name: ".spec.elements" for name in (
        "MjsBody", "MjsFrame", "MjsSite", "MjsGeom", "MjsJoint", "MjsCamera", "MjsLight",
        "MjsMesh", "MjsSensor", "MjsTendon", "MjsTendonPath", "MjsWrap", "MjsActuator",
        "MjsFlex", "MjsHField", "MjsSkin", "MjsTexture", "MjsMaterial", "MjsPair",
        "MjsExclude", "MjsEquality", "MjsNumeric", "MjsText", "MjsTuple", "MjsKey",
        "MjsPlugin")},
}


# submodules offered as attributes: the official `mujoco.rollout`, `mujoco.batch` and
# `mujoco.minimize`, the mujoco-py interface, and mjcffi.tune (callable as a function)
_SUBMODULES = ("rollout", "batch", "minimize", "sim", "tune")

# the official bindings' private modules that code names (`mujoco._enums.mjtGeom`,
# `mujoco._structs._MjContactList`), attributes as `_functions` is: files of their own,
# and the modules mjcffi/_private_paths.py makes
_PRIVATE_MODULES = ("_enums", "_constants", "_structs", *_private_paths.MODULES)

# the official GL backends' modules, attributes once imported; absent (AttributeError)
# where the backend cannot load, as official.  dir() lists glfw where it is installed,
# as the official's does with MUJOCO_GL unset (its gl_context imports mujoco.glfw).
_GL_SUBMODULES = ("egl", "osmesa", "glfw")


def __getattr__(name):
    if name == "__all__":
        value = globals()["__all__"] = _public_names()
        return value
    if name in _SUBMODULES or name in _PRIVATE_MODULES:
        value = globals()[name] = importlib.import_module(f".{name}", __name__)
        return value
    if name in _GL_SUBMODULES:
        try:
            value = globals()[name] = importlib.import_module(f".{name}", __name__)
        except ImportError as error:
            raise AttributeError(f"module 'mjcffi' has no attribute {name!r}: {error}") from None
        return value
    module = _LAZY.get(name)
    if module is None and name.startswith("mj"):
        functions = importlib.import_module(".functions", __name__)
        if name in functions.NAMES:
            _plugins().load_bundled()       # before the first model a function may load
            value = globals()[name] = getattr(functions, name)
            return value
    if module is None:
        # `from . import _x` asks here first for a submodule not yet loaded
        structs = importlib.import_module(".structs", __name__)
        if name.startswith("_") or name not in structs.MODULES:
            raise AttributeError(f"module 'mjcffi' has no attribute {name!r}")
        module = ".structs"
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value


def _plugins():
    return importlib.import_module("._support.plugins", __name__)


def _public_names():
    """`mjcffi.__all__`, made on first use (it imports the function and struct tables):
    every public name of the package, the submodules left out (import them by name)."""
    names = __dir__()                    # imports the tables, and so some submodules
    left_out = set(_SUBMODULES) | set(_GL_SUBMODULES) | {"importlib", "sys"}
    loaded = {name for name, value in globals().items()
              if value is not None and value is sys.modules.get(f"{__name__}.{name}")}
    return sorted(name for name in names if not name.startswith("_")
                  and name not in left_out | loaded)


# `import mujoco.rollout` after `sys.modules['mujoco'] = mjcffi` gives mjcffi.rollout
_aliases.install()
# mjcffi.sysid, .usd, .msh2obj, .introspect and .mjx: the official package's Python
# source, run on mjcffi (mjcffi/_support/official_source.py)
_official_source.install()
_private_paths.install()

# mjcffi._functions.mj_step, as the official mujoco._functions.mj_step: the generated
# layer asks for the hand-written functions here (mjcffi/_support/hand_written.py), the
# way mjcffi.mj_step resolves
_hand_written.resolve = __getattr__


def __dir__():
    structs = importlib.import_module(".structs", __name__)
    functions = importlib.import_module(".functions", __name__)
    gl = {"glfw"} if importlib.util.find_spec("glfw") is not None else set()
    return sorted(set(globals()) | set(_LAZY) | set(_SUBMODULES) | set(structs.MODULES)
                  | set(functions.NAMES) | gl)
