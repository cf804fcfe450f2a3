"""MjVfs: a virtual file system of named in-memory files for loading models.

`vfs["mesh.obj"] = data` adds a file, `del vfs[name]` removes it, `name in vfs`
asks for it; `MjModel.from_xml_path(name, vfs=vfs)` and `from_xml_string` read
from it.  `close()` frees the files (twice is safe), after which every use
raises RuntimeError; `with MjVfs() as vfs:` closes it at the end.

MjVfs is the generated MjVFS struct class (mjcffi/structs/mjmodel.py) with
this interface on top, so each MuJoCo function that takes an mjVFS
(mj_addFileVFS, mj_loadXML, mj_compile, ...) takes an MjVfs too.
"""

import contextlib
import os
import threading

from ._library import ffi, lib
from ._views import guarded, guarded_result
from .structs.mjmodel import MjVFS

__all__ = ["MjVfs", "using"]

_CLOSED = "VFS is closed"
_MAX_SIZE = 2**31 - 1         # mj_addBufferVFS counts bytes in an int


def _file_name(name):
    """A VFS file name as C bytes: str (or os.PathLike), without NUL."""
    if isinstance(name, os.PathLike):
        name = os.fspath(name)
    if not isinstance(name, str):
        raise TypeError(f"MjVfs file names are str, not {type(name).__name__}")
    raw = name.encode("utf-8")
    if b"\0" in raw:
        raise ValueError(f"MjVfs file name contains a NUL character: {name!r}")
    return raw


def _content(name, content):
    if not isinstance(content, (bytes, bytearray, memoryview)):
        raise TypeError(f"MjVfs file {name!r} must be bytes, not {type(content).__name__}")
    content = bytes(content)
    if len(content) > _MAX_SIZE:
        raise ValueError(f"MjVfs file {name!r} is {len(content)} bytes: MuJoCo takes at most "
                         f"{_MAX_SIZE}")
    return content


class MjVfs(MjVFS):
    """A virtual file system (mjVFS): named in-memory files that models load from.

    `vfs[name] = bytes` adds a file (ValueError if the name is taken),
    `del vfs[name]` removes one (KeyError if absent), `name in vfs` asks.
    Pass it as `vfs=` to `MjModel.from_xml_path`, `from_xml_string` or
    `from_binary_path`, or to any MuJoCo function that takes an mjVFS.
    `close()` frees its files; use it as a context manager to close it at
    the end.  Loads and changes from several threads are serialized.
    """

    def __init__(self):
        self._closed = False            # before the base class's __init__ reads _ptr
        self._lock = threading.RLock()
        super().__init__()

    @property
    def _ptr(self):
        # every MuJoCo function reaches the mjVFS through here: none once closed
        if self._closed:
            raise RuntimeError(_CLOSED)
        return self.__dict__["_ptr"]

    @property
    def closed(self):
        """True once `close()` has freed the files."""
        return self._closed

    @contextlib.contextmanager
    def _locked(self):
        """The mjVFS pointer, kept open and unchanged while the block runs."""
        with self._lock:
            yield self._ptr

    def __setitem__(self, name, content):
        raw = _file_name(name)
        content = _content(name, content)
        with self._locked() as pointer:
            status = guarded_result(lib.mjcffi_guard_mj_addBufferVFS, pointer, raw, content,
                                    len(content))
        if status == 2:
            raise ValueError(f"Repeated file name in VFS: {name}")
        if status != 0:
            raise ValueError(f"MuJoCo could not add the file {name!r} to the VFS")

    def __delitem__(self, name):
        raw = _file_name(name)
        with self._locked() as pointer:
            status = guarded_result(lib.mjcffi_guard_mj_deleteFileVFS, pointer, raw)
        if status != 0:
            raise KeyError(name)

    def __contains__(self, name):
        try:
            raw = _file_name(name)
        except ValueError:          # a name with NUL: no file can have it
            raw = None
        with self._locked() as pointer:
            if raw is None:
                return False
            return guarded_result(lib.mjcffi_guard_mj_containsBufferVFS, pointer, raw) == 1

    def close(self):
        """Free the files; later uses raise RuntimeError.  Closing twice is safe."""
        with self._lock:
            if self._closed:
                return
            pointer = self._ptr
            guarded(lib.mjcffi_guard_mj_deleteVFS, pointer)
            # empty again, so that the mj_deleteVFS run at collection is harmless
            guarded(lib.mjcffi_guard_mj_defaultVFS, pointer)
            self._closed = True

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self.close()

    def __repr__(self):
        state = "closed" if self._closed else "open"
        return f"<MjVfs {state} at {hex(int(ffi.cast('uintptr_t', self.__dict__['_ptr'])))}>"

    def __reduce__(self):
        raise TypeError("cannot pickle 'MjVfs' object")

    def __copy__(self):
        raise TypeError("an MjVfs cannot be copied: its files live in MuJoCo's memory")

    def __deepcopy__(self, memo):
        return self.__copy__()


@contextlib.contextmanager
def using(vfs, assets=None):
    """The `mjVFS *` of `vfs` for a model loader (None for no VFS), kept open
    while the block runs; ValueError when both `vfs` and `assets` are given."""
    if vfs is None:
        yield None
        return
    if assets is not None:
        raise ValueError("Cannot specify both 'assets' and 'vfs'.")
    if isinstance(vfs, MjVfs):
        with vfs._locked() as pointer:
            yield pointer
    elif getattr(vfs, "_cname", None) == "mjVFS":      # the plain generated MjVFS
        yield vfs._ptr
    else:
        raise TypeError(f"vfs must be an MjVfs, not {type(vfs).__name__}")
