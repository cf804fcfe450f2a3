"""Load an mjModel from an XML file, XML text or MJB, and a spec's XML, with MuJoCo's
errors as ValueError.

These return raw `mjModel *` cdata owned by the garbage collector
(mj_deleteModel runs when it is collected).  The struct classes wrap them.

Files come from the disk, from `assets` (a dict of file name -> bytes, put
in a private VFS), or from `vfs`, the `mjVFS *` of a caller's MjVfs, never
both.  As in the official bindings, an asset is stored under its file name
without folders, and two assets whose names differ only in folders or case
are refused ("Repeated file name in assets dict: ...").  MuJoCo finds a file
named with folders under its bare name too.

MuJoCo's first-party plugins are registered before the first load
(mjcffi/_support/plugins.py), so that models naming mujoco.pid and the others load.

An MJB, from a file or from bytes (a pickle), is trusted in nothing: its byte
count is checked against its sizes before MuJoCo allocates (mjcffi_check_mjb),
and its model is checked by mjcffi/_support/modelcheck before MuJoCo loads it, so that a
corrupted MJB is a ValueError naming the field, never a crash later.  The
digests of the last MJBs found sound are kept, so that unpickling many MjData
of one model checks the model once.
"""

import hashlib
import os
import threading
from collections import OrderedDict
from collections.abc import Mapping

from . import modelcheck as _modelcheck, plugins
from .errors import FatalError, raise_pending, with_note
from .library import ffi, lib
from .views import guarded_result

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


def _check_assets(assets):
    if assets is not None and not isinstance(assets, Mapping):
        raise TypeError(f"assets must be a dict of file name -> bytes, not "
                        f"{type(assets).__name__}")


def _new_vfs(assets):
    """An mjVFS holding `assets` (name -> bytes), freed when collected."""
    _check_assets(assets)
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
    _check_assets(assets)
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
    """Load the MJB file at `path`, which may also name a file of `assets` or `vfs`:
    its bytes are read as mj_loadModel reads them, then loaded as load_binary_bytes."""
    raw = _fspath(path, "path")
    _check_assets(assets)
    if vfs is None:
        vfs = _new_vfs(assets) if assets else ffi.NULL
    message = "mj_loadModel: failed to load from mjb"
    mjb = _read_resource(raw, vfs)
    if mjb is None:
        raise with_note(ValueError(message),
                        f"MuJoCo could not load {os.fsdecode(raw)!r}: it is missing, "
                        "unreadable, or not an MJB file of MuJoCo 4.0")
    return load_binary_bytes(mjb, message)


def _read_resource(raw, vfs):
    """The bytes of the file `raw` (from `vfs` when it holds it, else the disk), or None."""
    error = ffi.new("char[]", _ERROR_SIZE)
    resource = guarded_result(lib.mjcffi_guard_mju_openResource, b"", raw, vfs, error,
                              _ERROR_SIZE)
    if resource == ffi.NULL:
        return None
    try:
        buffer = ffi.new("const void **")
        size = guarded_result(lib.mjcffi_guard_mju_readResource, resource, buffer)
        return ffi.buffer(buffer[0], size)[:] if size > 0 and buffer[0] != ffi.NULL else None
    finally:
        lib.mjcffi_guard_mju_closeResource(resource)
        raise_pending()


class _Sound:
    """The SHA-256 digests of the last `size` MJBs found sound; finding one makes it
    the newest."""

    def __init__(self, size):
        self._size = size
        self._digests = OrderedDict()
        self._lock = threading.Lock()

    def __contains__(self, digest):
        with self._lock:
            if digest in self._digests:
                self._digests.move_to_end(digest)
                return True
            return False

    def add(self, digest):
        with self._lock:
            self._digests[digest] = None
            while len(self._digests) > self._size:
                self._digests.popitem(last=False)

    def clear(self):
        with self._lock:
            self._digests.clear()


SOUND = _Sound(64)


def _check_mjb(mjb, message):
    """ValueError with `message` and a note unless the MJB bytes hold a model MuJoCo can
    load and simulate safely (mjcffi_check_mjb, then mjcffi/_support/modelcheck)."""
    digest = hashlib.sha256(mjb).digest()     # collision-resistant: no forged "sound"
    if digest in SOUND:
        return
    if lib.mjcffi_check_mjb(mjb, len(mjb), ffi.NULL, 0):    # before MuJoCo allocates
        why = ffi.new("char[]", 160)
        lib.mjcffi_check_mjb(mjb, len(mjb), why, len(why))
        raise with_note(ValueError(message), ffi.string(why).decode("utf-8", "replace"))
    problem = _modelcheck.mjb_problem(mjb)
    if problem is not None:
        raise with_note(ValueError(message), problem)
    SOUND.add(digest)


def load_binary_bytes(mjb, message):
    """An mjModel from MJB bytes (immutable: what is checked is what MuJoCo loads),
    owned by the garbage collector; a ValueError with `message` and a note naming
    what is wrong when the bytes are no model MuJoCo can load and simulate safely."""
    mjb = bytes(mjb)                # the same object when it is bytes already
    plugins.load_bundled()          # a pickled model may use them
    _check_mjb(mjb, message)
    try:
        root = guarded_result(lib.mjcffi_guard_mj_loadModelBuffer, mjb, len(mjb))
    except FatalError as error:          # mju_error in MuJoCo's own checks
        raise with_note(ValueError(message), f"MuJoCo: {error}") from None
    if root == ffi.NULL:
        raise with_note(ValueError(message), "MuJoCo refused it: a header, size or "
                        "reference of another version, or out of range (its warning says "
                        "which)")
    return ffi.gc(root, lib.mj_deleteModel)


def save_xml_string(spec):
    """The XML of mjSpec `spec` (a cdata pointer), as str; MuJoCo's error as ValueError."""
    size = 1 << 16
    while True:
        xml = ffi.new("char[]", size)
        error = ffi.new("char[]", 1024)
        ret = lib.mjcffi_guard_mj_saveXMLString(spec, xml, size, error, 1024)
        raise_pending()
        if ret == 0:
            return ffi.string(xml).decode("utf-8")
        if ret < 0:
            message = ffi.string(error).decode("utf-8", "replace").strip()
            raise ValueError(message or "mj_saveXMLString failed (MuJoCo gave no message)")
        size = ret + 1                  # the size it needs
