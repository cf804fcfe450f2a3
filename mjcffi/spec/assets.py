"""An `assets` dict (file name -> bytes) as the MjVfs that MuJoCo's parser and
compiler read, as the official `assets=` arguments."""

from ..vfs import MjVfs


def vfs_of(assets):
    """A new MjVfs holding `assets`, or None for no assets."""
    if not assets:
        return None
    if not isinstance(assets, dict):
        raise TypeError(f"assets must be a dict of file name to bytes, "
                        f"not {type(assets).__name__}")
    vfs = MjVfs()
    for name, content in assets.items():
        # text assets (an .obj written as str) are taken as UTF-8, as official
        vfs[name] = content.encode("utf-8") if isinstance(content, str) else content
    return vfs
