"""mujoco-py's `mujoco_py.functions`: MuJoCo's functions, called mujoco-py's way.

`functions.mj_step(model, data)`, `functions.mju_quat2Mat(mat, quat)`, ...:
every public function of mjcffi (mjcffi.functions), taking SimModel and
SimData (mjcffi's MjModel and MjData) and NumPy arrays.  A MuJoCo error in
any of them (mjcffi.FatalError) goes to the error callback set with
`cymj.set_error_callback`, as in mujoco-py; with none set it is raised.

The VFS functions keep mujoco-py's return codes on a PyMjVFS:
`mj_addFileVFS(vfs, directory, filename)` gives 0, 2 for a name already
held, -1 for a file that cannot be read (MuJoCo 4 would add a missing file
and fail only when it is read: it is looked for on disk first, as MuJoCo 2
did); `mj_findFileVFS(vfs, name)`, which MuJoCo 4 no longer has, gives the
file's index in the order the files were added, or -1 (see _vfs.py).

The functions are mjcffi's, looked up on first use; only the VFS ones are
written here.
"""

import functools
import os

from .. import functions as _mj
from .._support.errors import FatalError
from ..structs.mjmodel import MjVFS
from ._vfs import PyMjVFS, _as_str

_WRITTEN_HERE = ("mj_defaultVFS", "mj_deleteVFS", "mj_addFileVFS", "mj_addBufferVFS",
                 "mj_deleteFileVFS", "mj_findFileVFS")

__all__ = sorted(set(_mj.NAMES) | set(_WRITTEN_HERE))


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


def __getattr__(name):
    if name in _mj.NAMES:
        value = _routed(getattr(_mj, name))
        globals()[name] = value         # later lookups skip __getattr__
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))


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
