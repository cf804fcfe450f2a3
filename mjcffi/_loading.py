"""Load an mjModel from an XML file, XML text or MJB, with MuJoCo's errors as ValueError.

These return raw `mjModel *` cdata owned by the garbage collector
(mj_deleteModel runs when it is collected).  The struct classes wrap them.

Files come from the disk, from `assets` (a dict of file name -> bytes, put
in a private VFS), or from `vfs`, the `mjVFS *` of a caller's MjVfs, never
both.  As in the official bindings, an asset is stored under its file name
without folders, and two assets whose names differ only in folders or case
are refused ("Repeated file name in assets dict: ...").  MuJoCo finds a file
named with folders under its bare name too.

MuJoCo's first-party plugins are registered before the first load
(mjcffi/plugins.py), so that models naming mujoco.pid and the others load.
"""

import os

from . import plugins
from ._errors import with_note
from ._library import ffi, lib

_ERROR_SIZE = 1024
_XML_NAME = "model_.xml"      # the file name XML text gets inside a VFS, as the official's


def _owned_model(pointer, error):
    if pointer == ffi.NULL:
        message = ffi.string(error).decode("utf-8", "replace")
        raise ValueError(message if message.strip()
                         else "MuJoCo could not load the model (it gave no message)")
    return ffi.gc(pointer, lib.mj_deleteModel)


def _fspath(path, what):
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"{what} must be a str or os.PathLike, not {type(path).__name__}")
    raw = os.fsencode(path)
    if b"\0" in raw:
        raise ValueError(f"{what} contains a NUL character: {path!r}")
    return raw


def _asset_name(name):
    """The name an asset is stored under: its file name, folders dropped, lower case."""
    text = os.fsdecode(_fspath(name, "asset name"))
    return text.replace("\\", "/").rsplit("/", 1)[-1].lower()


def _new_vfs(assets):
    """An mjVFS holding `assets` (name -> bytes), freed when collected."""
    vfs = ffi.gc(ffi.new("mjVFS *"), lib.mj_deleteVFS)
    lib.mj_defaultVFS(vfs)
    for name, content in (assets or {}).items():
        if not isinstance(content, (bytes, bytearray, memoryview)):
            raise TypeError(f"asset {name!r} must be bytes, not {type(content).__name__}")
        content = bytes(content)
        stored = _asset_name(name)
        status = lib.mj_addBufferVFS(vfs, stored.encode("utf-8"), content, len(content))
        if status == 2:
            raise ValueError(f"Repeated file name in assets dict: {stored}")
        if status != 0:
            raise ValueError(f"Asset failed to load: {stored}")
    return vfs


def _free_name(vfs):
    """A file name for XML text that no file in `vfs` has: model_.xml, model__.xml, ..."""
    stem, ext = os.path.splitext(_XML_NAME)
    name = _XML_NAME
    while lib.mj_containsBufferVFS(vfs, name.encode()):
        stem += "_"
        name = stem + ext
    return name.encode()


def _text(xml):
    if not isinstance(xml, (str, bytes)):
        raise TypeError(f"xml must be str or bytes, not {type(xml).__name__}")
    text = xml.encode("utf-8") if isinstance(xml, str) else xml
    if b"\0" in text:
        raise ValueError("xml contains a NUL character")
    return text


def load_xml_path(path, assets=None, vfs=None):
    """Compile the MJCF/URDF file at `path`, reading other files from `assets`
    (name -> bytes) or `vfs` (an `mjVFS *`) where given."""
    raw = _fspath(path, "path")
    plugins.load_bundled()
    if vfs is None:
        vfs = _new_vfs(assets) if assets else ffi.NULL
    error = ffi.new("char[]", _ERROR_SIZE)
    return _owned_model(lib.mj_loadXML(raw, vfs, error, _ERROR_SIZE), error)


def load_xml_string(xml, assets=None, vfs=None):
    """Compile an MJCF/URDF model given as text; `assets` or `vfs` as for load_xml_path.

    The text is put in the VFS under a free name for the load, and taken out
    of a caller's `vfs` again afterwards.
    """
    text = _text(xml)
    plugins.load_bundled()
    if vfs is None:
        vfs = _new_vfs(assets)
    name = _free_name(vfs)
    if lib.mj_addBufferVFS(vfs, name, text, len(text)) != 0:
        raise ValueError("MuJoCo could not add the XML text to its VFS")
    try:
        error = ffi.new("char[]", _ERROR_SIZE)
        return _owned_model(lib.mj_loadXML(name, vfs, error, _ERROR_SIZE), error)
    finally:
        lib.mj_deleteFileVFS(vfs, name)


def load_binary_path(path, assets=None, vfs=None):
    """Load the MJB file at `path`, which may also name a file of `assets` or `vfs`."""
    raw = _fspath(path, "path")
    plugins.load_bundled()
    if vfs is None:
        vfs = _new_vfs(assets) if assets else ffi.NULL
    model = lib.mj_loadModel(raw, vfs)
    if model == ffi.NULL:
        raise with_note(ValueError("mj_loadModel: failed to load from mjb"),
                        f"MuJoCo could not load {os.fsdecode(raw)!r}: it is missing, "
                        "unreadable, or not an MJB file of MuJoCo 4.0")
    return ffi.gc(model, lib.mj_deleteModel)
