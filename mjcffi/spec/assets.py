"""The files a spec reads: an `assets` dict (file name -> bytes) as the MjVfs that
MuJoCo's parser and compiler read, as the official `assets=` arguments, or the
caller's own MjVfs; and the renaming of a child spec's asset files when it is
attached with a prefix and a suffix."""

import contextlib
import posixpath

from .._support import marshal as _m
from ..vfs import MjVfs


def check_assets(assets, name="assets"):
    """`assets` as a new dict after checking it is one of str -> bytes or str."""
    if not isinstance(assets, dict):
        raise TypeError(f"{name} must be a dict of file name to bytes, "
                        f"not {type(assets).__name__}")
    for key, content in assets.items():
        if not isinstance(key, str):
            raise TypeError(f"{name}: file names are str, not {type(key).__name__}")
        if not isinstance(content, (bytes, bytearray, memoryview, str)):
            raise TypeError(f"{name}: file {key!r} must be bytes, "
                            f"not {type(content).__name__}")
    return dict(assets)


def vfs_of(assets):
    """A new MjVfs holding `assets`, or None for no assets."""
    if not assets:
        return None
    assets = check_assets(assets)
    vfs = MjVfs()
    for name, content in assets.items():
        # text assets (an .obj written as str) are taken as UTF-8, as official
        vfs[name] = content.encode("utf-8") if isinstance(content, str) else bytes(content)
    return vfs


@contextlib.contextmanager
def vfs_pointer(assets, vfs):
    """The `mjVFS *` (NULL for none) that MuJoCo reads: `vfs` (an MjVfs), or one made
    from `assets` and closed at the end.  Both at once is a ValueError, as official;
    a closed `vfs` a RuntimeError."""
    if vfs is not None:
        if assets:
            raise ValueError("Cannot specify both 'vfs' and 'assets'.")
        yield _m.struct(vfs, "mjVFS", "vfs")
        return
    own = vfs_of(assets)
    try:
        yield _m.opt_struct(own, "mjVFS", "vfs")
    finally:
        if own is not None:
            own.close()


def attached_name(path, prefix, suffix):
    """The name a child's asset file takes in its parent: `prefix` before the file's
    base name, `suffix` before its extension ('meshes/a.obj' -> 'meshes/pa_s.obj')."""
    cut = max(path.rfind("/"), path.rfind("\\")) + 1
    folder, base = path[:cut], path[cut:]
    dot = base.rfind(".")
    stem, extension = (base[:dot], base[dot:]) if dot >= 0 else (base, "")
    return folder + prefix + stem + suffix + extension


def relative_names(files, root):
    """`files` (name -> content) named relative to folder `root` of a zip archive."""
    return {posixpath.relpath(name, root) if root else name: content
            for name, content in files.items()}
