"""The MuJoCo functions whose Python form is written by hand.

mjcffi/functions/__init__.py puts these in place of generated ones (codegen skips them);
codegen/functions.py's OVERRIDES table says why each is here.  They follow
the official bindings' documented Python signatures where those exist, and
return the hand-written MjModel/MjData classes where MuJoCo returns a new
mjModel/mjData.  Each docstring holds the Python notes only: mjcffi/functions/__init__.py
puts the signature line (SIGNATURES) and the header's doc comment above it.

Like the generated functions they call only guarded C functions, so that a
mju_error raises FatalError.  Each has `prepare` (mjcffi/_support/prepared.py):
mj_step, mj_forward and mj_name2id check their arguments once, as the generated
functions do; the others (`preparable(None)`) bind their arguments, and each
call runs the function, checks and all.
"""

import numpy as np

from .._support import marshal as _m
from .._support import mjr as _mjr
from .._support import loading as _loading
from .._support import prepared as _p
from .._support import contract as _contract
from .._support import stack as _stack
from .. import warning_errors as _warnings
from .._generated.enums import mjtObj
from .._support.errors import ArgumentError, with_note
from .._support.library import ffi, lib
from .._support.views import int_argument
from .._support import checks as _checks, handles as _handles
# MuJoCo's UI functions, hand-written in their own module (their mjuiDef arrays)
from ._mjui import SIGNATURES as _MJUI_SIGNATURES
from ._mjui import (mjui_add, mjui_addToSection, mjui_event, mjui_render, mjui_resize,
                    mjui_update)

__all__ = ["mj_step", "mj_forward", "mj_name2id", "mj_loadXML", "mj_loadModel", "mj_loadModelBuffer",
           "mj_compile", "mj_copyModel", "mj_embedAssets", "mj_makeData", "mj_defaultVFS",
           "mj_deleteVFS", "mj_loadTexture", "mj_saveXMLString", "mj_printSchema",
           "mjs_getDouble", "mjr_findRect", "mju_getXMLDependencies", "mju_getLogConfig",
           "mjv_makeScene", "mjv_freeScene", "mjv_defaultScene", "mj_mountVFS", "mj_unmountVFS",
           "mj_deleteFileVFS", "mju_malloc", "mju_free", "mjr_makeContext", "mjr_freeContext",
           "mjr_readPixels", "mjr_drawPixels", "mjui_add", "mjui_addToSection", "mjui_resize",
           "mjui_update", "mjui_event", "mjui_render"]

_step = lib.mjcffi_step

_M, _D = "mujoco._structs.MjModel", "mujoco._structs.MjData"
_VFS, _SPEC = "mujoco._structs.MjVFS", "mujoco._structs.MjSpec"
_SCN = "mujoco._structs.MjvScene"
_CON, _RECT = "mujoco._structs.MjrContext", "mujoco._structs.MjrRect"
_RGB = "numpy.typing.NDArray[numpy.uint8]"
_DEPTH = "numpy.typing.NDArray[numpy.float32]"

# The first line of each docstring, in the official bindings' shape (the
# signature); mjcffi/functions/__init__.py puts the header's doc comment after it.
SIGNATURES = {
    "mj_step": f"mj_step(m: {_M}, d: {_D}, nstep: int = 1) -> None",
    "mj_forward": f"mj_forward(m: {_M}, d: {_D}) -> None",
    "mj_name2id": f"mj_name2id(m: {_M}, type: int, name: str) -> int",
    "mj_loadXML": f"mj_loadXML(filename: str, vfs: {_VFS} | None = None) -> {_M}",
    "mj_loadModel": f"mj_loadModel(filename: str, vfs: {_VFS} | None = None) -> {_M}",
    "mj_loadModelBuffer": f"mj_loadModelBuffer(buffer: bytes) -> {_M}",
    "mj_compile": f"mj_compile(s: {_SPEC}, vfs: {_VFS} | None = None) -> {_M}",
    "mj_copyModel": f"mj_copyModel(dest: {_M} | None, src: {_M}) -> {_M}",
    "mj_embedAssets": f"mj_embedAssets(m: {_M}) -> {_M}",
    "mj_makeData": f"mj_makeData(m: {_M}) -> {_D}",
    "mj_defaultVFS": f"mj_defaultVFS(vfs: {_VFS}) -> None",
    "mj_deleteVFS": f"mj_deleteVFS(vfs: {_VFS}) -> None",
    "mj_loadTexture": f"mj_loadTexture(m: {_M}, id: int) -> tuple[numpy.typing.NDArray["
                      "numpy.uint8], int]",
    "mj_saveXMLString": f"mj_saveXMLString(s: {_SPEC}) -> str",
    "mj_printSchema": "mj_printSchema(flg_html: bool, flg_pad: bool) -> str",
    "mjs_getDouble": "mjs_getDouble(source: mjcffi._support.handles.MjDoubleVecHandle) -> "
                     "numpy.typing.NDArray[numpy.float64]",
    "mjr_findRect": "mjr_findRect(x: int, y: int, nrect: int, rect: mujoco._structs.MjrRect | "
                    "list[mujoco._structs.MjrRect]) -> int",
    "mju_getXMLDependencies": "mju_getXMLDependencies(filename: str) -> list[str]",
    "mju_getLogConfig": "mju_getLogConfig() -> mujoco._structs.MjLogConfig",
    "mjv_makeScene": f"mjv_makeScene(m: {_M}, scn: {_SCN}, maxgeom: int) -> None",
    "mjv_freeScene": f"mjv_freeScene(scn: {_SCN}) -> None",
    "mjv_defaultScene": f"mjv_defaultScene(scn: {_SCN}) -> None",
    "mj_mountVFS": f"mj_mountVFS(vfs: {_VFS}, filepath: str, provider: "
                   "mujoco._structs.MjpResourceProvider) -> int",
    "mj_unmountVFS": f"mj_unmountVFS(vfs: {_VFS}, filename: str) -> int",
    "mj_deleteFileVFS": f"mj_deleteFileVFS(vfs: {_VFS}, filename: str) -> int",
    "mju_malloc": "mju_malloc(size: int) -> Any",
    "mju_free": "mju_free(ptr: Any) -> None",
    "mjr_makeContext": f"mjr_makeContext(m: {_M}, con: {_CON}, fontscale: int) -> None",
    "mjr_freeContext": f"mjr_freeContext(con: {_CON}) -> None",
    "mjr_readPixels": f"mjr_readPixels(rgb: {_RGB} | None, depth: {_DEPTH} | None, "
                      f"viewport: {_RECT}, con: {_CON}) -> None",
    "mjr_drawPixels": f"mjr_drawPixels(rgb: {_RGB} | None, depth: {_DEPTH} | None, "
                      f"viewport: {_RECT}, con: {_CON}) -> None",
}

SIGNATURES.update(_MJUI_SIGNATURES)


def _mj_step(m, d, nstep=1, *, prepare=False):
    """mj_step's checks; returns its call (for mj_step.prepare)."""
    c_m, c_d = _m.model_data(m, d)
    if prepare:
        _m.check_scalars("mj_step", {"nstep": ("int", nstep)})

    def call():
        if _contract.warnings_as_errors:
            return _step_checked(m, d, nstep)
        try:
            status = _step(c_m, c_d, nstep)
        except (TypeError, OverflowError) as exc:
            raise _m.scalar_error(exc, "mj_step", {"nstep": ("int", nstep)}) from None
        if _stack.live:                  # a bad state's reset empties the stack
            _stack.sweep(d)
        if status or _contract.pending:
            _m.check_steps(status, "mj_step")
    return call


@_p.preparable(_mj_step)
def mj_step(m, d, nstep=1):
    """Optionally, repeat nstep times.

    Python: the `nstep` steps loop in C under one guard with the GIL released.
    d must be made for m (or a model of the same sizes).  With
    mjcffi.set_warnings_as_errors(True), a MuJoCo warning during the call raises
    MjWarningError."""
    try:                                 # the hot path: d made for m, no warnings check
        fast = d._model is m and not _contract.warnings_as_errors
    except AttributeError:
        fast = False
    if not fast:
        return _step_checked(m, d, nstep)
    try:
        status = _step(m._ptr, d._ptr, nstep)
    except (TypeError, OverflowError) as exc:
        raise _m.scalar_error(exc, "mj_step", {"nstep": ("int", nstep)}) from None
    if _stack.live:                      # a bad state's reset empties the stack
        _stack.sweep(d)
    if status or _contract.pending:      # an error, a callback's error, or Ctrl-C
        _m.check_steps(status, "mj_step")


def _step_checked(m, d, nstep):
    """mj_step for any other case: checks m and d, and warnings when asked."""
    c_m, c_d = _m.model_data(m, d)
    before = _warnings.before_call(d) if _contract.warnings_as_errors else None
    try:
        try:
            status = _step(c_m, c_d, nstep)
        except (TypeError, OverflowError) as exc:
            raise _m.scalar_error(exc, "mj_step", {"nstep": ("int", nstep)}) from None
        if _stack.live:
            _stack.sweep(d)
        _m.check_steps(status, "mj_step")
    except BaseException:
        if before is not None:
            _warnings.restore(d, before)      # keep the counts under the exception
        raise
    _warnings.after_call(d, before)


def _mj_forward(m, d, *, prepare=False):
    """mj_forward's checks; returns its call (for mj_forward.prepare)."""
    c_m, c_d = _m.model_data(m, d)
    guard = lib.mjcffi_guard_mj_forward

    def call():
        if _contract.warnings_as_errors:
            return _forward_checked(m, d)
        status = guard(c_m, c_d)
        if status or _contract.pending:
            _m.check(status)
    return call


@_p.preparable(_mj_forward)
def mj_forward(m, d):
    """Python: d must be made for m (or a model of the same sizes).  With
    mjcffi.set_warnings_as_errors(True), a MuJoCo warning during the call raises
    MjWarningError."""
    try:                                 # the hot path, as mj_step's
        fast = d._model is m and not _contract.warnings_as_errors
    except AttributeError:
        fast = False
    if not fast:
        return _forward_checked(m, d)
    status = lib.mjcffi_guard_mj_forward(m._ptr, d._ptr)
    if status or _contract.pending:
        _m.check(status)


def _forward_checked(m, d):
    """mj_forward for any other case: checks m and d, and warnings when asked."""
    c_m, c_d = _m.model_data(m, d)
    before = _warnings.before_call(d) if _contract.warnings_as_errors else None
    try:
        _m.check(lib.mjcffi_guard_mj_forward(c_m, c_d))
    except BaseException:
        if before is not None:
            _warnings.restore(d, before)      # keep the counts under the exception
        raise
    _warnings.after_call(d, before)


# ------------------------------------------------------------ names
#
# mj_name2id is asked the same question again and again (a controller looks up its
# sites every step).  MuJoCo's answer depends on the model's name tables alone, so an
# MjModel keeps a memo of the answers MuJoCo gave it: a repeated (type, name) is one
# dict lookup.  The tables are taken as fixed once compiled, as the named-access
# methods of both bindings take them; mj_copyModel into a model forgets its memo.

_MEMO_SIZE = 4096        # answers kept per model: a bound for code that asks many names
_OBJECT_TYPES = (int, mjtObj)


def _mj_name2id(m, type, name, *, prepare=False):
    """mj_name2id's checks; returns its call (for mj_name2id.prepare, which asks MuJoCo
    at every call)."""
    c_m = _m.struct(m, "mjModel", "m")
    c_name = _m.text(name, "name")
    if prepare:
        _m.check_scalars("mj_name2id", {"type": ("int", type)})
    guard = lib.mjcffi_guard_mj_name2id

    def call():
        try:
            ret = guard(c_m, type, c_name)
        except (TypeError, OverflowError) as exc:
            raise _m.scalar_error(exc, "mj_name2id", {"type": ("int", type)}) from None
        if not ret or _contract.pending:
            _m.check_error()
        return ret
    return call


@_p.preparable(_mj_name2id)
def mj_name2id(m, type, name):
    """Python: a repeated (type, name) is answered from the MjModel's memo of MuJoCo's
    own answers (mjcffi/functions/_overrides.py); name is str or bytes, without NUL."""
    if type.__class__ in _OBJECT_TYPES and name.__class__ is str:
        try:
            return m._name2id[type, name]
        except (AttributeError, KeyError):
            pass
        answer = _mj_name2id(m, type, name)()
        memo = getattr(m, "__dict__", None)
        if memo is not None and getattr(m, "_cname", None) == "mjModel":
            memo = memo.setdefault("_name2id", {})
            if len(memo) < _MEMO_SIZE:
                memo[type, name] = answer
        return answer
    return _mj_name2id(m, type, name)()


def forget_names(model):
    """Drop what a model wrapper remembers of its names (the mj_name2id memo, the named
    accessors, mujoco-py's name tuples and dicts), for when its mjModel is overwritten
    in place."""
    state = getattr(model, "__dict__", {})
    for cache in ("_name2id", "_name_ids", "_named", "_named_ids", "_sim_names"):
        state.pop(cache, None)


# ------------------------------------------------------------ new models

def _model(pointer):
    """An MjModel owning `pointer`, a new mjModel."""
    from ..model import MjModel       # the hand-written layer: imported on use
    root = ffi.gc(pointer, lib.mj_deleteModel)
    return MjModel._wrap(root, root)


@_p.preparable(None)
def mj_loadXML(filename, vfs=None):
    """Python: returns an MjModel; MuJoCo's error message becomes ValueError."""
    c_filename = _m.text(filename, "filename")
    c_vfs = _m.opt_struct(vfs, "mjVFS", "vfs")
    error, error_sz = _m.error_buffer()
    ret = lib.mjcffi_guard_mj_loadXML(c_filename, c_vfs, error, error_sz)
    _m.check_error()
    if ret == _m.NULL:
        raise ValueError(_m.error_text(error, "mj_loadXML"))
    return _model(ret)


@_p.preparable(None)
def mj_loadModel(filename, vfs=None):
    """Python: returns an MjModel; ValueError if MuJoCo cannot load the file."""
    c_filename = _m.text(filename, "filename")
    c_vfs = _m.opt_struct(vfs, "mjVFS", "vfs")
    ret = lib.mjcffi_guard_mj_loadModel(c_filename, c_vfs)
    _m.check_error()
    if ret == _m.NULL:
        raise ValueError(f"MuJoCo could not load the MJB file {filename!r}")
    return _model(ret)


@_p.preparable(None)
def mj_loadModelBuffer(buffer):
    """Python: takes bytes-like MJB content (buffer_sz is its length); returns an MjModel."""
    c_buffer, nbytes = _m.buffer_in(buffer, "buffer")
    ret = lib.mjcffi_guard_mj_loadModelBuffer(c_buffer, nbytes)
    _m.check_error()
    if ret == _m.NULL:
        raise ValueError("MuJoCo could not load the MJB buffer")
    return _model(ret)


@_p.preparable(None)
def mj_compile(s, vfs=None):
    """Python: returns an MjModel; on failure, mjs_getError's message becomes ValueError.

    With s.compiler.fusestatic or s.compiler.discardvisual set, MuJoCo deletes
    the fused bodies or the visual assets from the spec while it compiles, and
    every wrapper and view of them would point at freed memory: mjcffi then
    compiles a copy of s (mj_copySpec), which gives the same model and leaves s
    as it was, elements and all, and not compiled."""
    c_s = _m.struct(s, "mjSpec", "s")
    c_vfs = _m.opt_struct(vfs, "mjVFS", "vfs")
    if c_s.compiler.fusestatic or c_s.compiler.discardvisual:
        copy = lib.mjcffi_guard_mj_copySpec(c_s)
        _m.check_error()
        if copy == _m.NULL:
            raise ValueError("mj_compile: MuJoCo could not copy the spec")
        c_s = ffi.gc(copy, lib.mj_deleteSpec)
    ret = lib.mjcffi_guard_mj_compile(c_s, c_vfs)
    _m.check_error()
    if ret == _m.NULL:
        raise ValueError(_m.string(lib.mjs_getError(c_s)) or "mj_compile failed")
    return _model(ret)


@_p.preparable(None)
def mj_copyModel(dest, src):
    """Python: dest None returns a new MjModel; otherwise dest, an MjModel of the
    same sizes as src, receives the copy and is returned."""
    c_src = _m.struct(src, "mjModel", "src")
    if dest is None:
        ret = lib.mjcffi_guard_mj_copyModel(_m.NULL, c_src)
        _m.check_error()
        return _model(ret)
    c_dest = _m.struct(dest, "mjModel", "dest")
    if ffi.buffer(c_dest, _m._SIZES)[:] != ffi.buffer(c_src, _m._SIZES)[:]:
        raise ValueError("dest must have the same sizes as src")
    lib.mjcffi_guard_mj_copyModel(c_dest, c_src)
    forget_names(dest)                  # its names may be other ones now
    _m.check_error()
    return dest


@_p.preparable(None)
def mj_embedAssets(m):
    """Python: returns a new MjModel; MuJoCo's error message becomes ValueError."""
    c_m = _m.struct(m, "mjModel", "m")
    error, error_sz = _m.error_buffer()
    ret = lib.mjcffi_guard_mj_embedAssets(c_m, error, error_sz)
    _m.check_error()
    if ret == _m.NULL:
        raise ValueError(_m.error_text(error, "mj_embedAssets"))
    return _model(ret)


@_p.preparable(None)
def mj_makeData(m):
    """Python: returns MjData(m)."""
    from ..data import MjData
    return MjData(m)


# ----------------------------------------------------------------- VFS
#
# An mjVFS keeps a pointer to each resource provider mounted in it and reads it
# until the provider is unmounted or the VFS deleted: mjcffi/vfs.py keeps the
# providers alive that long.

@_p.preparable(None)
def mj_defaultVFS(vfs):
    """Python: an MjVFS is initialized when made and freed when collected; this
    empties it (what it held is freed, providers are unmounted), and it stays usable."""
    from .. import vfs as _vfs
    _vfs.reset(vfs)


@_p.preparable(None)
def mj_deleteVFS(vfs):
    """Python: frees the files in the VFS and leaves it empty and usable: a
    deleted VFS that MuJoCo reads again would crash, and the MjVFS frees its
    memory when collected."""
    mj_defaultVFS(vfs)


@_p.preparable(None)
def mj_mountVFS(vfs, filepath, provider):
    """Python: vfs is an MjVfs or MjVFS, which keeps `provider` (an
    MjpResourceProvider) alive while it is mounted: MuJoCo reads it until then."""
    from .. import vfs as _vfs
    return _vfs.mount(vfs, filepath, provider)


@_p.preparable(None)
def mj_unmountVFS(vfs, filename):
    """Python: the VFS lets go of the provider it kept alive."""
    from .. import vfs as _vfs
    return _vfs.unmount(vfs, filename)


@_p.preparable(None)
def mj_deleteFileVFS(vfs, filename):
    """Python: a provider mounted at `filename` is unmounted too, as in MuJoCo,
    and the VFS lets go of it."""
    from .. import vfs as _vfs
    return _vfs.delete_file(vfs, filename)


# -------------------------------------------------------------- scenes
#
# mjv_makeScene and mjv_freeScene free the scene's buffers (geoms, flex and
# skin data), which wrappers and views taken from it (scn.geoms[0],
# scn.flexvert, ...) point into.  So these functions never free a scene in
# place: they give the MjvScene a new mjvScene in new memory, and the old one
# is freed with its root, i.e. when the last wrapper or view into it goes.

def _scene(scn):
    """The MjvScene wrapper `scn`, which must own its mjvScene."""
    _m.struct(scn, "mjvScene", "scn")             # TypeError for anything else
    state = getattr(scn, "__dict__", {})
    if "_root" not in state or state["_root"] is not state.get("_ptr"):
        raise TypeError("scn must be an MjvScene, not a raw mjvScene pointer: the scene's "
                        "buffers are freed by this call, and only the MjvScene can keep "
                        "them alive for the wrappers and views that point into them")
    return scn


def _renew(scn, make=None, model=_m.NULL):
    """Give the MjvScene `scn` a new mjvScene, zeroed (mjv_defaultScene) and then
    filled by make(pointer), for C mjModel `model` (recorded: see structs/_checks.py);
    if that raises, scn keeps its scene."""
    root = ffi.gc(ffi.new("mjvScene *"), lib.mjv_freeScene)
    if make is not None:
        make(root)
    from .._support.views import _Cached
    cls = type(scn)
    scn._adopt(root, root, {})
    _checks.made_for(scn, model)
    stale = [name for name in scn.__dict__ if isinstance(getattr(cls, name, None), _Cached)]
    for name in stale:                  # views cached from the old scene (scn.translate, ...)
        scn.__dict__.pop(name, None)


@_p.preparable(None)
def mjv_makeScene(m, scn, maxgeom):
    """Python: scn gets a new mjvScene, so that wrappers and views taken from its old
    one (scn.geoms[0], ...) keep that one alive and valid; it is freed when the last
    of them goes.  If MuJoCo fails, scn keeps its old scene."""
    c_m = _m.struct(m, "mjModel", "m")
    _scene(scn)

    def make(pointer):
        try:
            status = lib.mjcffi_guard_mjv_makeScene(c_m, pointer, maxgeom)
        except (TypeError, OverflowError) as exc:
            raise _m.scalar_error(exc, "mjv_makeScene", {"maxgeom": ("int", maxgeom)}) from None
        _m.check(status)
    _renew(scn, make, c_m)


@_p.preparable(None)
def mjv_freeScene(scn):
    """Python: scn gets a new, empty mjvScene (as mjv_freeScene leaves it); its old
    one is freed when the last wrapper or view taken from it (scn.geoms[0], ...)
    goes, so these stay valid.  An MjvScene is also freed when collected."""
    _renew(_scene(scn))


@_p.preparable(None)
def mjv_defaultScene(scn):
    """Python: as mjv_freeScene: scn gets a new, zeroed mjvScene, and its old one is
    freed when the last wrapper or view taken from it goes (MuJoCo's mjv_defaultScene
    would zero it in place and lose its buffers)."""
    _renew(_scene(scn))


# ------------------------------------------------------------------ memory

_ALLOCATED: set = set()      # addresses that mju_malloc returned and mju_free has not freed


@_p.preparable(None)
def mju_malloc(size):
    """Python: returns a raw cffi `void *` (None if MuJoCo returns NULL), which only
    mju_free frees."""
    try:
        ret = lib.mjcffi_guard_mju_malloc(size)
    except (TypeError, OverflowError) as exc:
        raise _m.scalar_error(exc, "mju_malloc", {"size": ("size_t", size)}) from None
    _m.check_error()
    if ret == _m.NULL:
        return None
    _ALLOCATED.add(int(ffi.cast("uintptr_t", ret)))
    return ret


@_p.preparable(None)
def mju_free(ptr):
    """Python: ptr must be a pointer that mju_malloc returned and that was not freed
    yet (ValueError otherwise): any other pointer is memory that MuJoCo or Python
    owns and frees itself, such as a spec element's or a struct field's."""
    owned = getattr(ptr, "_ptr", None)          # a struct wrapper or a spec handle
    c_ptr = _m.opaque(ptr if owned is None else owned, "ptr", False)
    address = int(ffi.cast("uintptr_t", c_ptr))
    try:
        _ALLOCATED.remove(address)
    except KeyError:
        raise ValueError(f"mju_free: ptr ({hex(address)}) was not returned by mju_malloc, or "
                         f"was freed already") from None
    _m.check(lib.mjcffi_guard_mju_free(c_ptr))


# ----------------------------------------------------------- other shapes

@_p.preparable(None)
def mj_loadTexture(m, id):
    """Python: returns (pixels, colorspace), pixels a uint8 array of shape
    (height, width, nchannel), as the official bindings; ValueError on failure."""
    c_m = _m.struct(m, "mjModel", "m")
    _m.index(id, c_m.ntex, "id")
    data = ffi.new("mjtByte **")
    width, height, colorspace = ffi.new("int *"), ffi.new("int *"), ffi.new("int *")
    error, error_sz = _m.error_buffer()
    ret = lib.mjcffi_guard_mj_loadTexture(c_m, id, data, width, height, colorspace,
                                          error, error_sz)
    try:
        _m.check_error()
        if ret != 0:
            raise ValueError(_m.error_text(error, "mj_loadTexture"))
        nchannel = c_m.tex_nchannel[id]
        pixels = np.frombuffer(ffi.buffer(data[0], height[0] * width[0] * nchannel),
                               np.uint8).reshape(height[0], width[0], nchannel).copy()
    finally:
        if data[0] != _m.NULL:
            lib.mju_free(data[0])
    return pixels, colorspace[0]


@_p.preparable(None)
def mj_saveXMLString(s):
    """Python: returns the XML as str; MuJoCo's error message becomes ValueError."""
    return _loading.save_xml_string(_m.struct(s, "mjSpec", "s"))


@_p.preparable(None)
def mj_printSchema(flg_html, flg_pad):
    """Python: mj_printSchema(flg_html, flg_pad) returns the schema as str, as the
    official bindings (no file, no buffer)."""
    size = 1 << 16
    while True:
        buffer = ffi.new("char[]", size)
        try:
            ret = lib.mjcffi_guard_mj_printSchema(_m.NULL, buffer, size, flg_html, flg_pad)
        except (TypeError, OverflowError) as exc:
            raise _m.scalar_error(exc, "mj_printSchema", {"flg_html": ("int", flg_html),
                                                          "flg_pad": ("int", flg_pad)}) from None
        _m.check_error()
        if ret < size - 1:
            return ffi.string(buffer, ret).decode("utf-8")
        size *= 4


@_p.preparable(None)
def mjs_getDouble(source):
    """Python: returns a NumPy copy of the mjDoubleVec `source`, a handle (a spec field
    such as MjsBody.userdata), never a raw pointer."""
    c_source = _handles.argument(source, "mjDoubleVec", "source")
    size = ffi.new("int *")
    ret = lib.mjcffi_guard_mjs_getDouble(c_source, size)
    _m.check_error()
    return _m.copy_array(ret, size[0], _m.NUM)


@_p.preparable(None)
def mjr_findRect(x, y, nrect, rect):
    """Python: rect is one MjrRect or a sequence of at least nrect of them."""
    rects = list(rect) if isinstance(rect, (list, tuple)) else [rect]
    nrect = _m.count(nrect, "nrect")
    if nrect > len(rects):
        raise ValueError(f"nrect={nrect} but rect holds {len(rects)} rectangles")
    array = ffi.new("mjrRect[]", max(len(rects), 1))
    for i, r in enumerate(rects):
        array[i] = _m.struct_value(r, "mjrRect", f"rect[{i}]")
    try:
        ret = lib.mjcffi_guard_mjr_findRect(x, y, nrect, array)
    except (TypeError, OverflowError) as exc:
        raise _m.scalar_error(exc, "mjr_findRect", {"x": ("int", x), "y": ("int", y)}) from None
    _m.check_error()
    return ret


# ------------------------------------------------------------ the renderer
#
# An MjrContext records the OpenGL context it was made in (mjcffi/_support/mjr.py), which
# every mjr_* function that draws checks.

@_p.preparable(None)
def mjr_makeContext(m, con, fontscale):
    """Python: con must be an MjrContext (MjrContext(m, fontscale) does the same in
    one step).  An OpenGL context must be current (FatalError otherwise: make a
    GLContext current first); what con held is freed first, as by con.free()."""
    c_m = _m.struct(m, "mjModel", "m")
    record = _mjr.record_of(con)
    fontscale = int_argument(fontscale, "fontscale", "int")
    _mjr.make_context(con._ptr, record, c_m, fontscale)


@_p.preparable(None)
def mjr_freeContext(con):
    """Python: as con.free(): OpenGL objects are deleted only while the OpenGL context con
    was made in is current (elsewhere MuJoCo's memory alone is freed); freeing twice does
    nothing."""
    _mjr.release_context(_m.struct(con, "mjrContext", "con"), _mjr.record_of(con))


# bytes per pixel of the OpenGL formats mjr_readPixels may read with (con.readPixelFormat):
# GL_RED, GREEN, BLUE, ALPHA, RGB, RGBA, LUMINANCE, LUMINANCE_ALPHA, RG, BGR, BGRA
_PIXEL_BYTES = {0x1903: 1, 0x1904: 1, 0x1905: 1, 0x1906: 1, 0x1907: 3, 0x1908: 4, 0x1909: 1,
                0x190A: 2, 0x8227: 2, 0x80E0: 3, 0x80E1: 4}
_BYTE, _FLOAT = np.dtype(np.uint8), np.dtype(np.float32)


def _viewport(viewport):
    rect = _m.struct_value(viewport, "mjrRect", "viewport")
    if rect.width < 0 or rect.height < 0:
        raise ValueError("viewport width and height must be non-negative")
    _mjr.rect_fits(rect, "viewport")
    return rect


def _pixel_buffer(value, dtype, name, output):
    """(array, C pointer) of a pixel buffer, or (None, NULL); the official messages."""
    if value is None:
        return None, _m.NULL
    if not output:                   # an input: converted, as the generated functions do
        return _m.array_in(value, _m.BYTE if dtype == _BYTE else _m.FLOAT, name)
    if not isinstance(value, np.ndarray) or value.dtype != dtype:
        raise ArgumentError(f"{name} must be a writable NumPy array of dtype {dtype}, not "
                            f"{getattr(value, 'dtype', type(value).__name__)}")
    if not value.flags.c_contiguous:
        raise with_note(ArgumentError(f"{name} buffer must be C-contiguous"),
                        f"MuJoCo {'writes' if output else 'reads'} it as one block")
    if output and not value.flags.writeable:
        raise ArgumentError(f"{name} is read-only; MuJoCo writes into it")
    return value, ffi.from_buffer((_m.BYTE if dtype == _BYTE else _m.FLOAT)[1], value)


def _enough(array, needed, name):
    if array is not None and array.size < needed:
        raise with_note(ArgumentError(f"{name} buffer is too small for viewport"),
                        f"{name} has {array.size} elements; the viewport needs {needed}, which "
                        f"MuJoCo writes or reads unchecked")


@_p.preparable(None)
def mjr_readPixels(rgb, depth, viewport, con):
    """Python: rgb (uint8) and depth (float32) are writable C-contiguous arrays of any
    shape, such as (height, width, 3) and (height, width), or None; they must hold the
    viewport's pixels: width*height*3 bytes of rgb (the bytes per pixel of
    con.readPixelFormat when that is set to another format), width*height floats of
    depth.  Row 0 is the bottom of the image, as OpenGL reads it."""
    rect = _viewport(viewport)
    rgb, c_rgb = _pixel_buffer(rgb, _BYTE, "rgb", True)
    depth, c_depth = _pixel_buffer(depth, _FLOAT, "depth", True)
    c_con = _m.struct(con, "mjrContext", "con")
    _mjr.context(con, "con", "mjr_readPixels")
    pixels = rect.width * rect.height
    if rgb is not None:
        fmt = 0x1907 if c_con.currentBuffer == 0 else c_con.readPixelFormat   # GL_RGB
        size = 3 if c_con.currentBuffer == 0 else _PIXEL_BYTES.get(fmt)
        if size is None:
            raise ValueError(f"con.readPixelFormat={fmt:#x} is not an OpenGL format mjcffi "
                             f"knows the pixel size of: set it to GL_RGB (0x1907) or GL_RGBA "
                             f"(0x1908)")
        _enough(rgb, pixels * size, "rgb")
    _enough(depth, pixels, "depth")
    _m.check(lib.mjcffi_guard_mjr_readPixels(c_rgb, c_depth, rect, c_con))


@_p.preparable(None)
def mjr_drawPixels(rgb, depth, viewport, con):
    """Python: rgb (uint8, width*height*3 values, as (height, width, 3) or flat) and
    depth (float32, width*height) are converted when needed, or None; rows from the
    bottom, as OpenGL draws them."""
    rect = _viewport(viewport)
    rgb, c_rgb = _pixel_buffer(rgb, _BYTE, "rgb", False)
    depth, c_depth = _pixel_buffer(depth, _FLOAT, "depth", False)
    pixels = rect.width * rect.height
    _enough(rgb, pixels * 3, "rgb")
    _enough(depth, pixels, "depth")
    c_con = _m.struct(con, "mjrContext", "con")
    _mjr.context(con, "con", "mjr_drawPixels")
    _m.check(lib.mjcffi_guard_mjr_drawPixels(c_rgb, c_depth, rect, c_con))


# ------------------------------------------------------------ string lists

@_p.preparable(None)
def mju_getXMLDependencies(filename):
    """Python: returns the files as a list of str, as the official bindings; FatalError
    if MuJoCo cannot read the model."""
    c_filename = _m.text(filename, "filename")
    spec = ffi.gc(lib.mj_makeSpec(), lib.mj_deleteSpec)
    strings = _string_vec(spec)             # an mjStringVec that the spec owns
    _m.check(lib.mjcffi_guard_mju_getXMLDependencies(c_filename, strings))
    return _read_strings(strings)


def _string_vec(spec):
    """An empty mjStringVec owned by `spec` (a texture's cubefiles): the C API makes none."""
    strings = lib.mjs_addTexture(spec, _m.NULL).cubefiles
    lib.mjs_setStringVec(strings, b"")
    return strings


_STRING_LAYOUT: list = []   # the std::string layout of libmujoco, once checked


def _read_strings(strings):
    """The entries of an mjStringVec (a C++ std::vector<std::string>) as str.

    The C API can write these vectors but not read them.  libmujoco is built
    with libc++, whose vector is (begin, end, capacity) and whose strings are
    24 bytes; the layout is checked once on strings MuJoCo itself wrote, and
    anything else raises NotImplementedError rather than read memory blindly.
    """
    if not _STRING_LAYOUT:
        _STRING_LAYOUT.append(_check_layout())
    begin, end = ffi.cast("uintptr_t *", strings)[0:2]
    return [_libcxx_string(begin + i).decode("utf-8", "replace")
            for i in range(0, end - begin, 24)]


def _libcxx_string(address):
    """The bytes of the libc++ std::string at `address`: short (size in the first
    byte, doubled) or long (capacity with its low bit set, size, data pointer)."""
    words = ffi.cast("uintptr_t *", address)
    if words[0] & 1:
        return ffi.unpack(ffi.cast("char *", words[2]), words[1])
    raw = ffi.cast("unsigned char *", address)
    return ffi.unpack(ffi.cast("char *", address + 1), raw[0] >> 1)


def _check_layout():
    """Check `_libcxx_string` on a short and a long string that MuJoCo stores.

    Nothing is dereferenced until the vector's size and the short string, which
    lies inline, have matched: another layout raises, it does not crash."""
    short, long = b"short", b"a string longer than the twenty-two bytes kept inline"
    spec = ffi.gc(lib.mj_makeSpec(), lib.mj_deleteSpec)
    strings = _string_vec(spec)
    lib.mjs_appendString(strings, short)
    lib.mjs_appendString(strings, long)
    begin, end = ffi.cast("uintptr_t *", strings)[0:2]
    inline = ffi.buffer(ffi.cast("char *", begin), 24)[:]
    if end - begin != 48 or inline[0] != 2 * len(short) or \
            inline[1:1 + len(short)] != short or _libcxx_string(begin + 24) != long:
        raise NotImplementedError("mju_getXMLDependencies: this libmujoco's std::string "
                                  "layout is not libc++'s, which mjcffi reads")
    return True


@_p.preparable(None)
def mju_getLogConfig():
    """Python: a copy, of the public class mjcffi.MjLogConfig (so it has set())."""
    from ..log_config import MjLogConfig     # the hand-written layer: imported on use
    return MjLogConfig.get()
