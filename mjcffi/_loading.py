"""Load an mjModel from an XML file or string, with MuJoCo's errors as ValueError.

These return raw `mjModel *` cdata owned by the garbage collector
(mj_deleteModel runs when it is collected).  The struct classes wrap them.
"""

import os

from ._library import ffi, lib


_ERROR_SIZE = 1024
_XML_NAME = b"model.xml"    # name of an XML string inside its private VFS


def _owned_model(pointer, error):
    if pointer == ffi.NULL:
        message = ffi.string(error).decode("utf-8", "replace").strip()
        raise ValueError(message or "MuJoCo could not load the model (it gave no message)")
    return ffi.gc(pointer, lib.mj_deleteModel)


def _fspath(path, what):
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"{what} must be a str or os.PathLike, not {type(path).__name__}")
    raw = os.fsencode(path)
    if b"\0" in raw:
        raise ValueError(f"{what} contains a NUL character: {path!r}")
    return raw


def _new_vfs(assets):
    """An mjVFS holding `assets` (name -> bytes), freed when collected."""
    vfs = ffi.gc(ffi.new("mjVFS *"), lib.mj_deleteVFS)
    lib.mj_defaultVFS(vfs)
    for name, content in (assets or {}).items():
        if not isinstance(content, (bytes, bytearray, memoryview)):
            raise TypeError(f"asset {name!r} must be bytes, not {type(content).__name__}")
        content = bytes(content)
        status = lib.mj_addBufferVFS(vfs, _fspath(name, "asset name"), content, len(content))
        if status == 2:
            raise ValueError(f"asset {name!r} is given twice")
        if status != 0:
            raise ValueError(f"MuJoCo could not add asset {name!r} to its VFS")
    return vfs


def load_xml_path(path, assets=None):
    """Compile the MJCF/URDF file at `path`; `assets` (name -> bytes) go in the VFS."""
    raw = _fspath(path, "path")
    vfs = _new_vfs(assets) if assets else ffi.NULL
    error = ffi.new("char[]", _ERROR_SIZE)
    return _owned_model(lib.mj_loadXML(raw, vfs, error, _ERROR_SIZE), error)


def load_xml_string(xml, assets=None):
    """Compile an MJCF/URDF model given as text; `assets` (name -> bytes) go in the VFS."""
    if not isinstance(xml, (str, bytes)):
        raise TypeError(f"xml must be str or bytes, not {type(xml).__name__}")
    text = xml.encode("utf-8") if isinstance(xml, str) else xml
    if b"\0" in text:
        raise ValueError("xml contains a NUL character")
    assets = dict(assets or {})
    if os.fsdecode(_XML_NAME) in assets:
        raise ValueError(f"asset name {os.fsdecode(_XML_NAME)!r} is reserved for the XML text")
    vfs = _new_vfs(assets)
    status = lib.mj_addBufferVFS(vfs, _XML_NAME, text, len(text))
    if status != 0:
        raise ValueError("MuJoCo could not add the XML text to its VFS")
    error = ffi.new("char[]", _ERROR_SIZE)
    return _owned_model(lib.mj_loadXML(_XML_NAME, vfs, error, _ERROR_SIZE), error)


def load_binary_path(path, assets=None):
    """Load the MJB file at `path`; `assets` (name -> bytes) go in the VFS."""
    raw = _fspath(path, "path")
    vfs = _new_vfs(assets) if assets else ffi.NULL
    model = lib.mj_loadModel(raw, vfs)
    if model == ffi.NULL:
        raise ValueError(f"MuJoCo could not load the MJB model {os.fsdecode(raw)!r} "
                         "(missing, unreadable, or not an MJB file of MuJoCo 4.0)")
    return ffi.gc(model, lib.mj_deleteModel)
