"""mujoco-py's `mujoco_py.functions`: MuJoCo's functions, called mujoco-py's way.

`functions.mj_step(model, data)`, `functions.mju_quat2Mat(res, quat)`,
`functions.mj_saveLastXML("saved.xml", model, "", 0)`, ...: every function of
mujoco-py 2.1's module, with mujoco-py's parameters in its order (`__all__`
lists them).  They are generated from mujoco-py's own wrappers
(mjcffi/sim/generated/functions.py, by codegen/simfunctions.py) and call
mjcffi's functions (mjcffi.functions, the official bindings' signatures),
taking SimModel and SimData (mjcffi's MjModel and MjData): flat NumPy arrays
are viewed in the shapes mjcffi takes, size arguments are checked and cut the
arrays, error buffers (`error, error_sz`) are accepted and ignored, `uintptr_t`
arguments are addresses of C ints (or int32 arrays).  Where MuJoCo 4 changed
a function's meaning or dropped it, the function raises NotImplementedError
saying why (`REMOVED`); `CHANGED` says how the others whose arguments are
mapped differ.

A MuJoCo error in any of them (mjcffi.FatalError) goes to the error callback
set with `cymj.set_error_callback`, as in mujoco-py; with none set it is raised.

The VFS functions are written here and keep mujoco-py's return codes on a
PyMjVFS: `mj_addFileVFS(vfs, directory, filename)` gives 0, 2 for a name
already held, -1 for a file that cannot be read (MuJoCo 4 would add a missing
file and fail only when it is read: it is looked for on disk first, as MuJoCo 2
did); `mj_findFileVFS(vfs, name)`, which MuJoCo 4 no longer has, gives the
file's index in the order the files were added, or -1 (see _vfs.py).
`mj_addBufferVFS(vfs, name, buffer)`, which mujoco-py did not have, is here too.

mjcffi's other functions, which mujoco-py's module did not have (mj_jacDot,
mju_mulMatVec3, ...), are here as well, with the official bindings' signature
and the same error routing; they are looked up on first use and are not in
`__all__`.  Where both have a function, mujoco-py's signature is the one here.
"""

import functools
import os

from .. import functions as _mj
from .._support.errors import FatalError
from ..structs.mjmodel import MjVFS
from ._vfs import PyMjVFS, _as_str
from .generated import functions as _generated

CHANGED = _generated.CHANGED    # {name: how its arguments differ from mjcffi's}
REMOVED = _generated.REMOVED    # {name: why it raises NotImplementedError}

_WRITTEN_HERE = ("mj_defaultVFS", "mj_deleteVFS", "mj_addFileVFS", "mj_addBufferVFS",
                 "mj_deleteFileVFS", "mj_findFileVFS")

if not set(_generated.HAND_WRITTEN) <= set(_WRITTEN_HERE):
    raise ImportError(f"mjcffi.sim.generated.functions leaves "
                      f"{sorted(set(_generated.HAND_WRITTEN) - set(_WRITTEN_HERE))} to this "
                      f"module, which does not write them")

__all__ = list(_generated.NAMES)


def _routed(function):
    """`function`, with a MuJoCo error handed to mujoco-py's error callback."""
    @functools.wraps(function)
    def call(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        except FatalError as error:
            from ._callbacks import handle_fatal   # imported on first error
            return handle_fatal(error)
    return call


for _name in _generated.NAMES:
    if _name not in _WRITTEN_HERE:
        globals()[_name] = _routed(getattr(_generated, _name))
del _name


def __getattr__(name):
    """mjcffi's functions that mujoco-py's module did not have, on first use."""
    if name in _mj.NAMES:
        value = _routed(getattr(_mj, name))
        globals()[name] = value         # later lookups skip __getattr__
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__) | set(_mj.NAMES))


# ------------------------------------------------------------------ VFS

def _disk_path(directory, filename):
    """The file mj_addFileVFS reads: directory, a separator unless it ends in
    one, then filename (MuJoCo's own joining)."""
    if directory and not directory.endswith(("/", "\\")):
        directory += "/"
    return (directory or "") + filename


@_routed
def mj_defaultVFS(vfs):
    """Empty `vfs`: what it held is freed, and it stays usable."""
    _mj.mj_defaultVFS(vfs)
    if isinstance(vfs, PyMjVFS):
        vfs._forget_all()


@_routed
def mj_deleteVFS(vfs):
    """Free the files of `vfs`; it stays usable (empty), and its memory goes when
    it is collected."""
    _mj.mj_deleteVFS(vfs)
    if isinstance(vfs, PyMjVFS):
        vfs._forget_all()


@_routed
def mj_addFileVFS(vfs, directory, filename):
    """Add the file directory/filename under its name; 0: added, 2: a file of
    that name is held already, -1: no file there to read."""
    directory = "" if directory is None else _as_str(directory, "directory")
    filename = _as_str(filename, "filename")
    held = _mj.mj_containsFileVFS(vfs, directory, filename) == 1   # checks vfs too
    if not held and not os.path.isfile(_disk_path(directory, filename)):
        return -1
    status = _mj.mj_addFileVFS(vfs, directory, filename)
    if status == 0 and isinstance(vfs, PyMjVFS):
        vfs._added("file", filename)
    return status


@_routed
def mj_addBufferVFS(vfs, name, buffer):
    """Add `buffer` (bytes) as the file `name`; 0: added, 2: name held already."""
    status = _mj.mj_addBufferVFS(vfs, name, buffer)
    if status == 0 and isinstance(vfs, PyMjVFS):
        vfs._added("buffer", _as_str(name, "name"))
    return status


@_routed
def mj_deleteFileVFS(vfs, filename):
    """Remove the file `filename`; 0: removed, -1: not held."""
    return _mj.mj_deleteFileVFS(vfs, filename)


@_routed
def mj_findFileVFS(vfs, filename):
    """The index of the file `filename` in `vfs` (in the order files were
    added), or -1 if it holds none of that name.  `vfs` is a PyMjVFS: MuJoCo 4
    keeps no order of its own."""
    if not isinstance(vfs, PyMjVFS):
        kind = "an MjVFS other than PyMjVFS" if isinstance(vfs, MjVFS) else type(vfs).__name__
        raise TypeError(f"mj_findFileVFS needs a PyMjVFS, not {kind}: MuJoCo 4 has no "
                        f"mj_findFileVFS, and the order of files is kept by PyMjVFS")
    return vfs.find(filename)
