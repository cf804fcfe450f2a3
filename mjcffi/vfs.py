"""MjVfs: a virtual file system of named in-memory files for loading models.

`vfs["mesh.obj"] = data` adds a file, `del vfs[name]` removes it, `name in vfs`
asks for it; `MjModel.from_xml_path(name, vfs=vfs)` and `from_xml_string` read
from it.  `close()` frees the files (twice is safe), after which every use
raises RuntimeError; `with MjVfs() as vfs:` closes it at the end.

MjVfs is the generated MjVFS struct class (mjcffi/structs/mjmodel.py) with
this interface on top, so each MuJoCo function that takes an mjVFS
(mj_addFileVFS, mj_loadXML, mj_compile, ...) takes an MjVfs too.

An mjVFS keeps a pointer to each resource provider mounted in it
(mj_mountVFS) and reads it until the provider is unmounted or the VFS is
deleted.  So the memory of an MjVfs or MjVFS is freed by a `_Memory`, which
deletes the mjVFS and only then lets go of the providers it kept alive;
`mount`, `unmount`, `delete_file` and `reset` below are what mj_mountVFS,
mj_unmountVFS, mj_deleteFileVFS and mj_defaultVFS/mj_deleteVFS call.
"""

import contextlib
import os
import threading

from ._support import marshal as _m
from ._support.library import ffi, lib
from ._support.views import guarded, guarded_result
from .structs.mjmodel import MjVFS

__all__ = ["MjVfs", "using"]

_CLOSED = "VFS is closed"
_MAX_SIZE = 2**31 - 1         # mj_addBufferVFS counts bytes in an int


# ------------------------------------------------------- memory and mounts

_MEMORY: dict = {}               # address of a live mjVFS -> its _Memory
_MOUNTING = threading.RLock()    # mounts of a VFS that has no lock of its own


class _Memory:
    """The destructor of an mjVFS's root: mj_deleteVFS, then let go of the resource
    providers mounted in it, which MuJoCo reads until then (their unmount callbacks)."""

    __slots__ = ("address", "mounts")

    def __init__(self, address):
        self.address = address
        self.mounts = []         # (filepath as given, provider object, its C pointer)

    # the defaults keep what it needs alive for a collection at interpreter exit
    def __call__(self, pointer, _delete=lib.mj_deleteVFS, _registry=_MEMORY):
        _delete(pointer)
        if _registry.get(self.address) is self:
            del _registry[self.address]
        self.mounts.clear()


def _address(pointer):
    return int(ffi.cast("uintptr_t", pointer))


def _new_root():
    """A new, empty mjVFS, freed by its _Memory when collected."""
    root = ffi.new("mjVFS *")
    lib.mj_defaultVFS(root)
    memory = _Memory(_address(root))
    _MEMORY[memory.address] = memory
    return ffi.gc(root, memory)


def _memory(vfs):
    """(C pointer, _Memory) of the MjVfs or MjVFS `vfs`.

    A plain MjVFS comes with mj_deleteVFS as its destructor: it gets a _Memory
    on first use here.  A raw `mjVFS *` is refused unless an MjVFS owns it: the
    providers mounted in it could not be kept alive."""
    pointer = _m.struct(vfs, "mjVFS", "vfs")
    memory = _MEMORY.get(_address(pointer))
    if memory is not None:
        return pointer, memory
    state = getattr(vfs, "__dict__", {})
    if not isinstance(vfs, MjVFS) or state.get("_root") is not state.get("_ptr"):
        raise TypeError("vfs must be an MjVfs or MjVFS, not a raw mjVFS pointer: a mounted "
                        "resource provider must be kept alive as long as the VFS holds it")
    old = state["_root"]
    ffi.gc(old, None)                   # its mj_deleteVFS now runs from the _Memory
    memory = _Memory(_address(pointer))
    root = ffi.gc(old, memory)
    _MEMORY[memory.address] = memory
    vfs._adopt(root, root, {})
    return root, memory


def _lock(vfs):
    return vfs._lock if isinstance(vfs, MjVfs) else _MOUNTING


# A provider with no callbacks: mounting it tells whether a path is still mounted.
_PROBE = ffi.new("mjpResourceProvider *")
lib.mjp_defaultProvider(_PROBE)


def _prune(pointer, memory):
    """Let go of the providers that MuJoCo no longer holds: those whose path can be
    mounted again (MuJoCo's path normalization decides; the probe is unmounted at
    once).  A path still taken, even by a file, keeps its provider: the safe side."""
    for entry in list(memory.mounts):
        status = guarded_result(lib.mjcffi_guard_mj_mountVFS, pointer, entry[0], _PROBE)
        if status == 0:
            guarded_result(lib.mjcffi_guard_mj_unmountVFS, pointer, entry[0])
            memory.mounts.remove(entry)


def mount(vfs, filepath, provider):
    """mj_mountVFS: the VFS keeps `provider` alive while it holds it."""
    with _lock(vfs):
        pointer, memory = _memory(vfs)
        c_provider = _m.struct(provider, "mjpResourceProvider", "provider")
        c_filepath = _m.text(filepath, "filepath")
        status = guarded_result(lib.mjcffi_guard_mj_mountVFS, pointer, c_filepath, c_provider)
        if status == 0:
            memory.mounts.append((c_filepath, provider, c_provider))
        return status


def unmount(vfs, filename):
    """mj_unmountVFS: the VFS lets go of the provider it unmounts."""
    with _lock(vfs):
        pointer, memory = _memory(vfs)
        status = guarded_result(lib.mjcffi_guard_mj_unmountVFS, pointer,
                                _m.text(filename, "filename"))
        if status == 0:
            _prune(pointer, memory)
        return status


def delete_file(vfs, filename):
    """mj_deleteFileVFS: it unmounts a provider mounted at that path too."""
    with _lock(vfs):
        pointer, memory = _memory(vfs)
        status = guarded_result(lib.mjcffi_guard_mj_deleteFileVFS, pointer,
                                _m.text(filename, "filename"))
        if status == 0:
            _prune(pointer, memory)
        return status


def reset(vfs):
    """mj_defaultVFS and mj_deleteVFS: empty the VFS (its files freed, its providers
    unmounted and let go of); it stays usable."""
    with _lock(vfs):
        pointer = _m.struct(vfs, "mjVFS", "vfs")
        guarded(lib.mjcffi_guard_mj_deleteVFS, pointer)     # deleted, then made anew:
        guarded(lib.mjcffi_guard_mj_defaultVFS, pointer)    # empty and usable
        memory = _MEMORY.get(_address(pointer))
        if memory is not None:
            memory.mounts.clear()


# ------------------------------------------------------------------ MjVfs

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
        self._closed = False            # before _ptr is read
        self._lock = threading.RLock()
        self._init_root(_new_root())

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
        with self._locked():
            status = delete_file(self, raw)
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
            reset(self)     # empty again, so that the mj_deleteVFS run at collection is harmless
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
