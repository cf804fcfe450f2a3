"""The official bindings' MjModel and MjData as mjcffi objects, and back.

`MjModel.from_official(m)` and `MjData.from_official(d)` wrap the official
object's C struct (its `_address`) without copying or owning it: the root cdata
of the wrapper is a cast of that address whose `ffi.gc` destructor does nothing
but hold the official object, so every view keeps it alive, and nothing ever
frees memory the official bindings own.  `to_official()` copies the other way.

Sharing memory is only sound when both bindings run on one loaded libmujoco: a
second copy of the library has its own globals (error handlers, the plugin
table) and may be another version with another struct layout.  The check asks
the dynamic loader for `mj_step` in the dependencies of mjcffi's compiled module
and of the official extension module that made the object (dlopen with
RTLD_NOLOAD, then dlsym, which searches a handle's own dependencies): one loaded
library gives one address.  (mjcffi's `ffi.addressof(lib, ...)` cannot serve: in
cffi's API mode it is the address of a stub inside the compiled module.)

Support module: imports the compiled module, the standard library and the
support layer; the official `mujoco` package only inside `official_package`.
"""

import os
import sys

from .errors import with_note
from .library import ffi, lib
from .official import is_official, type_name
from .views import guarded_result

# The head of mjModel, up to `opt`: every size an mjData is laid out from
_SIZES = ffi.offsetof("mjModel", "opt")
_SYMBOL = "mj_step"
_TITLES = {"mjModel": "MjModel", "mjData": "MjData"}
_resolved: dict = {}    # shared object path -> address of _SYMBOL through its dependencies


class _Holds:
    """The `ffi.gc` destructor of a borrowed root: it frees nothing, and only holds
    the official object, so that whatever holds the root keeps that object alive."""
    __slots__ = ("official",)

    def __init__(self, official):
        self.official = official

    def __call__(self, pointer):
        pass


# ------------------------------------------------------------- one libmujoco

def _symbol_address(path):
    """The address of `_SYMBOL` as the loaded shared object `path` resolves it (its
    own or its dependencies'), or a str saying why there is none."""
    if path in _resolved:
        return _resolved[path]
    import ctypes
    noload = getattr(os, "RTLD_NOLOAD", None)
    if noload is None:
        return "this platform's loader cannot look up a loaded library (no RTLD_NOLOAD)"
    try:       # NOLOAD: only a library already loaded, never a new copy
        handle = ctypes.CDLL(path, mode=noload | os.RTLD_NOW)
        address = ctypes.cast(getattr(handle, _SYMBOL), ctypes.c_void_p).value
    except (OSError, AttributeError) as error:
        return f"the loader could not resolve {_SYMBOL} through {path}: {error}"
    _resolved[path] = address
    return address


def _file_at(address):
    """The file mapped at `address` in this process (for messages), or '?'."""
    try:
        with open("/proc/self/maps") as maps:
            for line in maps:
                parts = line.split(None, 5)
                low, _, high = parts[0].partition("-")
                if int(low, 16) <= address < int(high, 16) and len(parts) == 6:
                    return parts[5].strip()
    except (OSError, ValueError):
        pass
    return "?"


def _describe(address):
    return f"{_SYMBOL} at {address:#x} in {_file_at(address)}" if isinstance(address, int) \
        else address


def check_library(module_name):
    """Raise ValueError unless the official extension module `module_name`
    ('mujoco._structs') runs on the very libmujoco that mjcffi's compiled module
    runs on (see the module docstring)."""
    module = sys.modules.get(module_name)
    path = getattr(module, "__file__", None)
    theirs = _symbol_address(path) if path else f"{module_name} has no file to look up"
    from .. import _mjcffi
    ours = _symbol_address(_mjcffi.__file__)
    if isinstance(ours, int) and ours == theirs:
        return
    raise with_note(ValueError(
        "the official bindings do not run on mjcffi's libmujoco, so their objects cannot be "
        "shared: mjcffi and the official mujoco package must load one libmujoco.so.4.0.0 "
        "in this process.  To copy between them instead, pickle, or pass MJB bytes "
        "(m.to_bytes() / MjModel.from_bytes)"),
        f"mjcffi: {_describe(ours)}; {module_name}: {_describe(theirs)}")


def official_package():
    """The official `mujoco` package, imported now (never at mjcffi's import), with
    its library checked.  Under `sys.modules['mujoco'] = mjcffi` there is none."""
    import mujoco  # type: ignore[import-untyped]  # the official bindings
    structs = getattr(mujoco, "MjModel", None)
    if not isinstance(structs, type) or not is_official(structs):
        raise ImportError("the official mujoco bindings are not importable here: "
                          f"`import mujoco` gives {getattr(mujoco, '__name__', mujoco)!r} "
                          f"({getattr(mujoco, '__file__', '?')}), not the official package")
    check_library(structs.__module__)
    return mujoco


# ------------------------------------------------------------- wrapping

def borrow(value, cname, name, wrapping=True):
    """A root cdata for official object `value`, which must wrap a `cname`
    ('mjModel'): a `cname *` at its address that owns nothing and holds `value`.
    `wrapping`: the caller makes a view (an mjcffi object needs none: say so)."""
    title = _TITLES[cname]
    base = None if isinstance(value, type) else next(       # a subclass of it is taken too
        (c for c in type(value).__mro__ if c.__name__ == title and is_official(c)), None)
    if base is None:
        ours = getattr(value, "_cname", None) == cname and not isinstance(value, type)
        if ours and wrapping:
            raise TypeError(f"{name} is an mjcffi.{title} already, not an official "
                            f"mujoco.{title}: use it as it is")
        what = f"the class {type_name(value)} itself" if isinstance(value, type) else \
            f"mjcffi.{title}" if ours else type_name(value)
        raise TypeError(f"{name} must be an official mujoco.{title} (from `import mujoco`), "
                        f"not {what}")
    check_library(base.__module__)
    address = value._address
    if not isinstance(address, int) or not address:
        raise ValueError(f"{name} has no {cname} (its _address is {address!r})")
    return ffi.gc(ffi.cast(f"{cname} *", address), _Holds(value))


def model_pointer(value, name, wrapping=True):
    """The C mjModel of an official MjModel (checked as `borrow` does); the caller
    holds `value` for as long as it uses the pointer."""
    return ffi.cast("mjModel *", borrow(value, "mjModel", name, wrapping))


def check_sizes(model_ptr, made_for_ptr, dname, mname):
    """Raise ValueError unless C models `model_ptr` and `made_for_ptr` (the one data
    `dname` was made for) have the same sizes, every one an mjData is laid out from."""
    if model_ptr == made_for_ptr or \
            ffi.buffer(model_ptr, _SIZES)[:] == ffi.buffer(made_for_ptr, _SIZES)[:]:
        return
    a, b = made_for_ptr, model_ptr
    raise ValueError(f"{dname} was made for a model of other sizes than {mname} (nq {a.nq} vs "
                     f"{b.nq}, nv {a.nv} vs {b.nv}, nbody {a.nbody} vs {b.nbody}, "
                     f"...)")


def copy_model(official_model, source):
    """Copy C mjModel `source` into the official MjModel `official_model`, made with
    the same sizes (mj_copyModel into its existing buffer: everything, the signature
    too, which MJB bytes leave out)."""
    dest = ffi.cast("mjModel *", official_model._address)
    guarded_result(lib.mjcffi_guard_mj_copyModel, dest, source)


def copy_data(official_model, official_data, source):
    """Copy C mjData `source` into the official MjData `official_data`, made for the
    official MjModel `official_model` (mj_copyData into its existing buffers)."""
    dest = ffi.cast("mjData *", official_data._address)
    model = ffi.cast("mjModel *", official_model._address)
    guarded_result(lib.mjcffi_guard_mj_copyData, dest, model, source)
