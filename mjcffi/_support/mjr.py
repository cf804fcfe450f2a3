"""What MuJoCo's classic renderer (the mjr_* functions) leaves to its caller, checked.

MuJoCo draws with OpenGL in whatever context is current on the calling thread, and
keeps no record of it.  Found by calling each function in a subprocess:

- before any mjrContext was made in the process, MuJoCo's OpenGL function pointers
  are NULL: mjr_render, mjr_readPixels, mjr_rectangle, mjr_finish, ... segfault;
- an mjr_makeContext with no current context fails with "gladLoadGL error", and so
  does every later one in the process, context or not (MuJoCo's loader runs once);
- once loaded, a call with no current context, or after the GL context was
  destroyed, is a silent no-op of the driver: nothing drawn, mjr_readPixels leaves
  the rgb buffer as it was and flips the depth buffer's garbage;
- with another context current, the context's object names mean other objects, or
  none: mjr_freeContext would delete that context's objects.

So an MjrContext records the OpenGL context it was made in (the handle that
eglGetCurrentContext, OSMesaGetCurrentContext or glXGetCurrentContext returns, asked in
C by mjcffi_gl_current), and every mjr_* function that draws checks, before MuJoCo
runs, that its context was made and not freed, and that the context it was made in is
the one current on this thread; those without a context argument (mjr_rectangle,
mjr_finish, mjr_getError) check that some context is current and that MuJoCo's loader
has run.  A driver may give a new context the handle of a destroyed one (OSMesa does at once):
forget_context(handle), called as a context is destroyed (GLContext.free() is the
place), marks the MjrContexts made in it as lost.  Of a context destroyed without that
call (another binding's, a window's), an MjrContext that outlives it passes for one of
a new context at the same address, and MuJoCo draws with object names it lacks.

Freeing (MjrContext.free(), mjr_freeContext, or collection) deletes the OpenGL objects
when the context it was made in is current; otherwise it frees MuJoCo's memory only,
without an OpenGL call that could reach another context's objects, and the objects go
when their context is destroyed.  A context freed from a thread where its OpenGL
context is not current keeps its skin arrays until it is collected, as a call on the
thread where it is current may still be reading them.
"""

import re
import threading
import weakref

import numpy as np

from .._generated.constants import mjMAXLINEPNT, mjMAXOVERLAY
from . import official as _official
from .errors import FatalError, with_note
from .library import ffi, lib

NULL = ffi.NULL
_HOW = "make a GLContext current first (mjcffi.GLContext(w, h).make_current())"
_PLATFORM = {lib.MJCFFI_GL_EGL: "EGL", lib.MJCFFI_GL_OSMESA: "OSMesa",
             lib.MJCFFI_GL_GLX: "GLX", lib.MJCFFI_GL_UNKNOWN: "unknown"}
_local = threading.local()


# ------------------------------------------------------------ the current context

def _platform_out():
    """This thread's `int *` for mjcffi_gl_current to write the platform into."""
    try:
        return _local.platform
    except AttributeError:
        _local.platform = ffi.new("int *")
        return _local.platform


def current():
    """(platform, handle) of the OpenGL context current on this thread, or None.

    Where the platform cannot be asked (not Linux), (MJCFFI_GL_UNKNOWN, 0): every
    context then looks the same, and the checks let calls through."""
    out = _platform_out()
    handle = lib.mjcffi_gl_current(out)
    if handle == NULL:
        return (out[0], 0) if out[0] == lib.MJCFFI_GL_UNKNOWN else None
    return out[0], int(ffi.cast("uintptr_t", handle))


def _describe(gl):
    return f"{_PLATFORM.get(gl[0], 'OpenGL')} context {gl[1]:#x}"


def no_context(func):
    """The error for a call that needs a current OpenGL context and finds none."""
    return FatalError(f"{func}: no OpenGL context is current on this thread: {_HOW}")


def gl_ready(func):
    """Before an mjr_* function without a context argument that calls OpenGL: some
    context is current, and MuJoCo's OpenGL functions are loaded."""
    if current() is None:
        raise no_context(func)
    if not lib.mjcffi_gl_loader_ready():
        raise FatalError(f"{func}: MuJoCo's OpenGL functions are not loaded yet: make an "
                         f"MjrContext first (MjrContext(m, fontscale), with a GLContext "
                         f"current); until then MuJoCo would call a NULL function pointer")


# ------------------------------------------------------------ an MjrContext's record

class Record:
    """What one MjrContext's memory holds: 'default' (never made), 'made' (in the
    OpenGL context `gl`, for a model of `layout`) or 'freed'.  Its `finalize` is the
    memory's destructor, so it must not refer to the memory itself."""

    __slots__ = ("state", "gl", "handle", "layout", "skinface", "kept", "lost", "__weakref__")

    def __init__(self):
        self.state, self.gl, self.layout, self.skinface = "default", None, None, NULL
        self.handle = NULL           # gl's handle as a pointer: the per-call comparison
        self.kept = False            # freed away from its context, skin arrays kept
        self.lost = False            # its OpenGL context was destroyed (forget_context)

    def finalize(self, pointer):
        """Free what a collected MjrContext holds (never raises: it runs in the GC)."""
        try:
            release_context(pointer, self, collected=True)
        except Exception:            # noqa: BLE001  (interpreter shutdown, a caught mju_error)
            pass


def new_context():
    """(root, record): a default mjrContext in new memory, freed through the record."""
    record = Record()
    root = ffi.new("mjrContext *")
    lib.mjr_defaultContext(root)
    return ffi.gc(root, record.finalize), record


def record_of(con, name="con"):
    """The Record of MjrContext `con`; a raw pointer has none and is refused."""
    record = getattr(con, "__dict__", {}).get("_mjr")
    if record is None:
        if _official.is_official(con):
            raise _official.not_accepted(name, "MjrContext", con)
        given = "a raw mjrContext pointer" if isinstance(con, ffi.CData) else \
            type(con).__name__
        raise TypeError(f"{name} must be an MjrContext, not {given}: mjcffi must know the "
                        f"OpenGL context it was made in")
    return record


def layout(m):
    """What an mjrContext made for C mjModel `m` holds per object: the counts that size
    its tables, and the faces of each skin (its face buffers)."""
    counts = (m.ntex, m.nmat, m.nmesh, m.nhfield, m.nskin)
    return counts, tuple(ffi.unpack(m.skin_facenum, m.nskin)) if m.nskin else ()


_LAYOUT_NAMES = ("ntex", "nmat", "nmesh", "nhfield", "nskin")


def make_context(pointer, record, m, fontscale):
    """mjr_makeContext(m, pointer, fontscale) in the current OpenGL context, recorded.

    With no context current, the guard's C precheck refuses before MuJoCo runs (its
    loader would fail, and never run again in the process): the error says how to
    get one, with the precheck's text where no OpenGL library is loaded at all."""
    gl = current()
    if record.state == "made":
        release_context(pointer, record)   # mjr_makeContext would free it in *this* context
    record.kept = False              # skin arrays a detached free kept: left to leak
    lib.mjr_defaultContext(pointer)  # and keep the last context's window capabilities
    status = lib.mjcffi_guard_mjr_makeContext(m, pointer, fontscale)
    if status:
        message = lib.mjcffi_take_error()
        text = ffi.string(message).decode("utf-8", "replace") if message != NULL else \
            "mjr_makeContext failed"
        if gl is None:
            raise _not_current(text)
        lib.mjcffi_guard_mjr_freeContext(pointer)    # what it made before failing
        lib.mjcffi_take_error()
        error = FatalError(text)
        if "gladLoadGL" in text:
            with_note(error, "MuJoCo's OpenGL loader failed once in this process (an "
                             "mjr_makeContext with no current OpenGL context, by the "
                             "official bindings perhaps) and does not run again: render in "
                             "a new process")
        raise error
    counts, faces = layout(m)
    record.state, record.gl, record.layout = "made", current(), counts
    record.handle, record.lost = lib.mjcffi_gl_current(_platform_out()), False
    with _release_lock:
        _made_in.setdefault(record.gl[1], weakref.WeakSet()).add(record)
    record.skinface = ffi.new("int[]", faces) if faces else NULL
    lib.mjcffi_gl_loader_ready()     # latch: MuJoCo's loader has run


def _not_current(precheck):
    """mjr_makeContext's error with no current context; `precheck` is the C text."""
    message = f"mjr_makeContext: no OpenGL context is current on this thread: {_HOW}"
    if "no OpenGL context is current" not in precheck:   # no library, or a spent renderer
        message += f"; {precheck}"
    return with_note(FatalError(message),
                     'MuJoCo would raise FatalError("gladLoadGL error"), and its OpenGL loader '
                     'would then fail for the rest of the process, with a context or not')


def context_repr(con, text):
    """The struct's repr, with the context's state: made (in which OpenGL context),
    default or freed."""
    record = con.__dict__.get("_mjr")
    state = record.state if record is not None else "raw"
    if state == "made":
        state = f"made in {_describe(record.gl)}"
    return text.replace(f"<{type(con).__name__} ", f"<{type(con).__name__} ({state}) ", 1)


# the fields that name OpenGL objects, which a free away from their context must not pass
_NAMES = ("offFBO", "offFBO_r", "offColor", "offColor_r", "offDepthStencil",
          "offDepthStencil_r", "shadowFBO", "shadowTex", "basePlane", "baseMesh",
          "baseHField", "baseBuiltin", "baseFontNormal", "baseFontShadow", "baseFontBig",
          "rangePlane", "rangeMesh", "rangeHField", "rangeBuiltin", "rangeFont")
_NAME_ARRAYS = ("auxFBO", "auxFBO_r", "auxColor", "auxColor_r", "texture")
_SKIN_ARRAYS = ("skinvertVBO", "skinnormalVBO", "skintexcoordVBO", "skinfaceVBO")


# re-entrant: a garbage collection inside a `with` block (an allocation in make_context)
# may run an old GLContext.__del__, whose forget_context takes the lock again
_release_lock = threading.RLock()
_made_in: dict = {}      # OpenGL context handle -> the Records made in it (weak)


def forget_context(handle):
    """Mark the MjrContexts made in the OpenGL context `handle` (its address, as
    eglGetCurrentContext, OSMesaGetCurrentContext or glXGetCurrentContext returns it)
    as lost: a GLContext calls this as it destroys its context.  A context made later
    at the same address (OSMesa reuses it at once) is then not taken for theirs."""
    with _release_lock:
        for record in _made_in.pop(int(handle), ()):
            record.lost = True


def release_context(pointer, record, collected=False):
    """Free what the mjrContext at `pointer` holds; it is then 'freed' (and default).

    In the OpenGL context it was made in, mjr_freeContext frees it all; that context is
    current on no other thread, so no other call can be drawing with it.  Elsewhere
    (another context current, or none) the object names are zeroed first (_detach).
    Another thread may then still be inside a call with it, in its own context: its
    skin arrays, which such a call reads, are kept until the MjrContext is collected."""
    with _release_lock:              # once, even from two threads
        state = record.state
        if state == "made":
            record.state, record.skinface = "freed", NULL
        elif not (collected and record.kept):
            return
    if state == "made" and not record.lost and current() == record.gl:
        _free(pointer)
        return
    if collected or not pointer.nskin:
        _detach(pointer)
        _free(pointer)
        record.kept = False
    else:                            # skin buffers stay named: a draw may be binding them
        _detach(pointer, skins=False)
        record.kept = True


def _free(pointer):
    lib.mjcffi_guard_mjr_freeContext(pointer)
    lib.mjcffi_take_error()


def _detach(pointer, skins=True):
    """Zero every object name, so that mjr_freeContext frees MuJoCo's memory (the skin
    arrays) and makes no OpenGL call that names an object: in whatever context is
    current, OpenGL ignores name 0.  One texture of name 0 stays, so that MuJoCo still
    counts the context as one that held resources and forgets it.  The skin buffers'
    names stay while another thread may draw with them (`skins` False): bound as 0,
    OpenGL would read vertices and indices from client memory at address 0."""
    for name in _NAMES:
        setattr(pointer, name, 0)
    for name in _NAME_ARRAYS:
        array = getattr(pointer, name)
        ffi.memmove(array, bytes(ffi.sizeof(array)), ffi.sizeof(array))
    pointer.ntexture = 1
    for name in _SKIN_ARRAYS if skins else ():
        array = getattr(pointer, name)
        if array != NULL and pointer.nskin > 0:
            ffi.memmove(array, bytes(4 * pointer.nskin), 4 * pointer.nskin)


# ------------------------------------------------------------ checks before a call

def context(con, name, func):
    """Before an mjr_* function that draws with `con`: it was made, not freed, in the
    OpenGL context that is current on this thread."""
    record = record_of(con, name)
    if record.state == "made":       # the usual case, in one C call
        handle = lib.mjcffi_gl_current(_platform_out())
        if handle == record.handle and handle != NULL and not record.lost:
            return record
        if record.lost:
            raise FatalError(f"{func}: the OpenGL context {name} was made in has been "
                             f"freed: make a new MjrContext, with a GLContext current")
    else:
        if record.state == "freed":
            raise ValueError(f"{func}: {name} was freed (MjrContext.free()): make a new "
                             f"MjrContext")
        raise ValueError(f"{func}: {name} was not made by mjr_makeContext: MjrContext(m, "
                         f"fontscale) makes one, with a GLContext current")
    gl = current()
    if gl != record.gl:
        if gl is None:
            raise no_context(func)
        raise FatalError(f"{func}: {name} was made in another OpenGL context "
                         f"({_describe(record.gl)}) than the one current on this thread "
                         f"({_describe(gl)}): make that one current again; one freed "
                         f"since cannot be used")
    return record


def same_model(m, con, name="con"):
    """mjr_upload*: `m` must be a model of the sizes `con` was made for (its tables and
    display lists are sized by them)."""
    record = record_of(con, name)
    if record.state != "made":
        return                       # context() refuses it, after the argument checks
    counts, _ = layout(m)
    if counts != record.layout:
        have = ", ".join(f"{n} {v}" for n, v in zip(_LAYOUT_NAMES, record.layout))
        need = ", ".join(f"{n} {v}" for n, v in zip(_LAYOUT_NAMES, counts))
        raise ValueError(f"{name} was made for a model of other sizes ({have}), not this "
                         f"one ({need}): make an MjrContext for it")


_INT_MAX = 2 ** 31 - 1


def rect_fits(rect, name):
    """A rectangle whose far edges MuJoCo computes (left + width, bottom + height) in C
    int: past INT_MAX they overflow, and mjr_readPixels then crashes in the driver."""
    if rect.left + rect.width > _INT_MAX or rect.bottom + rect.height > _INT_MAX:
        raise ValueError(f"{name}: left + width and bottom + height must fit in a C int "
                         f"(at most {_INT_MAX}), got ({rect.left} + {rect.width}, "
                         f"{rect.bottom} + {rect.height})")


def ascii_text(raw, name):
    """Text MuJoCo draws: it indexes its 127-entry font width tables by each byte, so
    every byte must be ASCII."""
    if raw == NULL:
        return
    if not raw.isascii():
        raise ValueError(f"{name} must be ASCII text: MuJoCo's fonts have 128 characters, "
                         f"and it reads their widths past its tables for others")


_MAXOVERLAY = mjMAXOVERLAY


def overlay_text(raw, name):
    """mjr_overlay copies each line of the first mjMAXOVERLAY characters into a buffer of
    mjMAXOVERLAY, and its terminator one past it when that first line fills it."""
    if raw == NULL:
        return
    ascii_text(raw, name)
    if len(raw) >= _MAXOVERLAY and b"\n" not in raw[:_MAXOVERLAY]:
        raise ValueError(f"{name}: a line of {_MAXOVERLAY} characters or more (mjMAXOVERLAY) "
                         f"overflows MuJoCo's line buffer: break it with newlines")


# a printf format MuJoCo gives one float: at most one %f/%e/%g/%a conversion, no `*`
_FORMAT = re.compile(rb"(?:[^%]|%%)*(?:%[-+ #0]*[0-9]{0,2}(?:\.[0-9]{0,2})?[eEfFgGaA]"
                     rb"(?:[^%]|%%)*)?")
_MAXLINEPNT = mjMAXLINEPNT


def _field_text(fig, field, size, name):
    raw = ffi.buffer(getattr(fig, field))[:]
    chunks = [raw[i:i + size] for i in range(0, len(raw), size)]
    for i, chunk in enumerate(chunks):
        if b"\0" not in chunk:
            where = f"{name}[{i}]" if len(chunks) > 1 else name
            raise ValueError(f"fig.{where} has no terminating NUL: MuJoCo reads it up to one")
    return chunks[0].split(b"\0", 1)[0]


def figure_fields(fig, name="fig"):
    """mjr_figure follows the figure's line counts and prints its tick formats with
    snprintf, unchecked."""
    counts = np.frombuffer(ffi.buffer(fig.linepnt), np.intc)
    bad = np.flatnonzero((counts < 0) | (counts > _MAXLINEPNT))
    if bad.size:
        line = int(bad[0])
        raise ValueError(f"{name}.linepnt[{line}]={int(counts[line])} is outside "
                         f"0..mjMAXLINEPNT ({_MAXLINEPNT}): MuJoCo draws that many points "
                         f"of linedata[{line}]")
    if fig.legendoffset < 0:
        raise ValueError(f"{name}.legendoffset={fig.legendoffset} must not be negative: "
                         f"MuJoCo reads linename[legendoffset]")
    for field in ("xformat", "yformat"):
        text = _field_text(fig, field, 20, field)
        if not _FORMAT.fullmatch(text):
            raise ValueError(f"{name}.{field}={text!r} must be a printf format of one float "
                             f"at most (%g, %.2f, ...: flags, width and precision of two "
                             f"digits or fewer): MuJoCo prints a float with it")
    _field_text(fig, "minwidth", 20, "minwidth")
    _field_text(fig, "xlabel", 100, "xlabel")
    _field_text(fig, "linename", 100, "linename")


def _scene_sizes(scn, c_scn, name):
    """The sizes mjcffi_check_render takes: what the scene's buffers were made for
    (mjcffi/_support/checks.py records it), cached on the scene until it is remade."""
    from . import checks as _checks
    made = getattr(scn, "__dict__", {}).get("_made_for")
    if made is None:
        if c_scn.nflex or c_scn.nskin:
            raise TypeError(f"{name} must be an MjvScene made by MjvScene(m, maxgeom) or "
                            f"mjv_makeScene, not a raw pointer: what its flex and skin "
                            f"buffers were made for must be known")
        return ffi.new("int[6]")
    flex, skin = made.layout
    nflex = flex[0] if flex else 0
    if _checks._buffers(c_scn, nflex) != made.buffers:
        raise ValueError(f"{name}'s buffers were changed outside mjcffi (a raw "
                         f"lib.mjv_makeScene, or writes into {name}.flexfaceadr or "
                         f"{name}.flexfacenum): make it again with mjv_makeScene")
    nface = int(np.frombuffer(made.buffers[4], np.intc).sum()) if nflex else 0
    sizes = ffi.new("int[6]", [nflex, flex[1] if flex else 0, flex[2] if flex else 0, nface,
                               skin[0] if skin else 0, skin[1] if skin else 0])
    if flex is None and skin is None:
        scn.__dict__["_mjr_sizes"] = (made, sizes)   # nothing of it can change but a remake
    return sizes


def render_scene(scn, c_scn, con, c_con, name="scn"):
    """mjr_render: what the scene holds stays within its buffers and the context's."""
    state = getattr(scn, "__dict__", None)
    cached = state.get("_mjr_sizes") if state is not None else None
    if cached is not None and cached[0] is state.get("_made_for"):
        sizes = cached[1]
    else:
        sizes = _scene_sizes(scn, c_scn, name)
    record = getattr(con, "__dict__", {}).get("_mjr")
    if record is None or record.state != "made":
        return                       # context() refuses it, before MuJoCo runs
    skinface = record.skinface
    if skinface == NULL and c_scn.nskin:
        raise ValueError(f"{name} holds {c_scn.nskin} skins, and the context none: make "
                         f"the context for the scene's model")
    try:
        why = _local.why
    except AttributeError:
        why = _local.why = ffi.new("char[]", 512)
    if lib.mjcffi_check_render(c_scn, c_con, sizes, skinface, why, 512):
        raise ValueError("mjr_render: " + ffi.string(why).decode("utf-8", "replace"))
