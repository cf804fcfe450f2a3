"""PyMjVFS: mujoco-py's virtual file system, with the file order it reported.

mujoco-py's `mj_findFileVFS(vfs, name)` gave a file's index in the VFS.
MuJoCo 4 keeps its files in an opaque mjVFS, asked only whether it holds a
name (mj_containsFileVFS, mj_containsBufferVFS), and has no mj_findFileVFS.
So a PyMjVFS remembers the order in which files were added through
mjcffi.sim.functions, and `find` answers from that order and from what MuJoCo
says it holds.  Files are MuJoCo's all the same: a PyMjVFS is an mjcffi
MjVfs, usable wherever a VFS is taken.
"""

import os

from .. import functions as _mj
from ..vfs import MjVfs

__all__ = ["PyMjVFS"]

# MuJoCo names a file added from disk by its file name alone, without the path.
_SEPARATORS = ("/", "\\")


def _file_key(filename):
    """The name MuJoCo 4 files `filename` under: the part after its last separator."""
    for separator in _SEPARATORS:
        filename = filename.rsplit(separator, 1)[-1]
    return filename


def _as_str(name, what):
    if isinstance(name, os.PathLike):
        name = os.fspath(name)
    if isinstance(name, bytes):
        name = name.decode("utf-8")
    if not isinstance(name, str):
        raise TypeError(f"{what} must be str or bytes, not {type(name).__name__}")
    return name


class PyMjVFS(MjVfs):
    """mujoco-py's VFS: an MjVfs that also remembers the order of its files.

    Pass it to mjcffi.sim.functions' mj_defaultVFS, mj_addFileVFS,
    mj_addBufferVFS, mj_findFileVFS, mj_deleteFileVFS and mj_deleteVFS.
    """

    def __init__(self):
        super().__init__()
        self._order = []        # ("file" | "buffer", the name MuJoCo files it under)

    def _holds(self, entry):
        kind, key = entry
        if kind == "file":
            return _mj.mj_containsFileVFS(self, "", key) == 1
        return _mj.mj_containsBufferVFS(self, key) == 1

    def _added(self, kind, name):
        """Record a file MuJoCo has just added (it reported 0)."""
        self._order.append((kind, _file_key(name) if kind == "file" else name))

    def _forget_all(self):
        self._order.clear()

    def find(self, name):
        """The index of file `name` among the files in the order they were
        added, or -1 if the VFS does not hold it.

        Files MuJoCo no longer holds are dropped from the order first; a file
        MuJoCo holds but that was added some other way (`vfs[name] = data`)
        takes the next index when first found."""
        name = _as_str(name, "filename")
        self._order = [entry for entry in self._order if self._holds(entry)]
        for index, (kind, key) in enumerate(self._order):
            if key == (_file_key(name) if kind == "file" else name):
                return index
        for entry in (("buffer", name), ("file", _file_key(name))):
            if self._holds(entry):
                self._order.append(entry)
                return len(self._order) - 1
        return -1
