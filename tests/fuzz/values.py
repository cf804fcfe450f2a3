"""The bad values, by argument kind.

Each kind has an ordered table `label -> maker(ctx)`.  A maker builds the
value from `ctx` (the call's Env, the argument's metadata and its valid
value); it raises `NotApplicable` where the variation means nothing for this
argument (a transposed vector, say).  Labels are stable: a call is named by
(target, argument, label), and replaying that name rebuilds the same value.

Valid arrays and most bad ones are placed against a guard page (guard.py), so
that a wrapper that lets MuJoCo read or write past them faults at once.
"""

import math
import pathlib
from dataclasses import dataclass, field

import numpy as np

from . import guard


class NotApplicable(Exception):
    """This variation does not apply to this argument."""


@dataclass
class Ctx:
    env: object                 # the call's Env
    kind: str                   # see KINDS
    valid: object = None        # the argument's valid value
    elem: str = ""              # C element type: 'mjtNum', 'mjModel', ...
    const: bool = True          # an input (arrays, buffers)
    count: object = None        # for an id: the count it must stay below
    extra: dict = field(default_factory=dict)


def _na(message="not applicable"):
    raise NotApplicable(message)


class _Unconvertible:
    """An object that NumPy, cffi and int() all refuse."""

    def __repr__(self):
        return "<object>"


# ------------------------------------------------------------------ scalars

def _count(ctx, extra=0):
    if ctx.count is None:
        _na("no count")
    return int(ctx.count) + extra


COMMON = {
    "None": lambda c: None,
    "str": lambda c: "1",
    "object": lambda c: _Unconvertible(),
    "list": lambda c: [1],
}

INT = {
    **COMMON,
    "-1": lambda c: -1,
    "-2": lambda c: -2,
    "count": lambda c: _count(c),
    "count+1": lambda c: _count(c, 1),
    "2**31-1": lambda c: 2**31 - 1,
    "-2**31": lambda c: -2**31,
    "2**31": lambda c: 2**31,
    "-2**31-1": lambda c: -2**31 - 1,
    "2**63": lambda c: 2**63,
    "-2**63-1": lambda c: -2**63 - 1,
    "2**64": lambda c: 2**64,
    "10**9": lambda c: 10**9,
    "1.5": lambda c: 1.5,
    "nan": lambda c: math.nan,
    "inf": lambda c: math.inf,
    "np.int64(2**40)": lambda c: np.int64(2**40),
    "np.uint64(2**64-1)": lambda c: np.uint64(2**64 - 1),
    "np.float64(1)": lambda c: np.float64(1.0),
    "np.array([1, 2])": lambda c: np.array([1, 2]),
    "True": lambda c: True,
}

FLOAT = {
    **COMMON,
    "nan": lambda c: math.nan,
    "inf": lambda c: math.inf,
    "-inf": lambda c: -math.inf,
    "1e308": lambda c: 1e308,
    "-1e308": lambda c: -1e308,
    "2**1100": lambda c: 2**1100,
    "1+2j": lambda c: 1 + 2j,
    "np.array([1., 2.])": lambda c: np.array([1.0, 2.0]),
    "np.float32(nan)": lambda c: np.float32("nan"),
    "-1": lambda c: -1.0,
    "0": lambda c: 0.0,
}

TEXT = {
    "None": lambda c: None,
    "int": lambda c: 5,
    "object": lambda c: _Unconvertible(),
    "nul": lambda c: "a\0b",
    "empty": lambda c: "",
    "long": lambda c: "x" * 100_000,
    "format": lambda c: "%s%s%s%s%n%n%x%x%p",
    "newlines": lambda c: "a\nb\r\n\t",
    "non-utf8 bytes": lambda c: b"\xff\xfe\x80",
    "surrogate": lambda c: "\ud800",
    "unicode": lambda c: "\u00e9\u4e2d\U0001f600",
    "path": lambda c: pathlib.Path("nowhere") / "x.xml",
    "bytes": lambda c: b"x",
    "bytearray": lambda c: bytearray(b"x"),
    "list": lambda c: ["x"],
}


# ----------------------------------------------------------------- structs

def _wrong_struct(ctx):
    env = ctx.env
    return env.d if ctx.elem != "mjData" else env.m


def _other_model(ctx):
    if ctx.elem == "mjModel":
        return ctx.env.m_other
    if ctx.elem == "mjData":
        return ctx.env.d_other
    _na()


def _raw_null(ctx):
    from mjcffi import ffi
    if "." in ctx.elem:                     # a nested anonymous struct (mjVisual.global)
        _na("no C type name")
    return ffi.cast(ctx.elem + " *", 0)


def _raw_pointer(ctx):
    """The valid struct's own raw cffi pointer (struct fields hand these out)."""
    if ctx.valid is None or not hasattr(ctx.valid, "_ptr"):
        _na()
    return ctx.valid._ptr


def _closed(ctx):
    env = ctx.env
    if ctx.elem == "mjVFS":
        import mjcffi
        vfs = mjcffi.MjVfs()
        vfs.close()
        ctx.extra["allowed"] = (RuntimeError,)      # MjVfs's documented error after close
        return vfs
    if ctx.elem == "mjvScene":
        import mjcffi
        scn = mjcffi.MjvScene(env.m, maxgeom=10)
        mjcffi.mjv_freeScene(scn)
        return scn
    _na()


def _struct_class(ctx):
    if ctx.valid is None:
        _na()
    return type(ctx.valid)


def _deleted_element(ctx):
    """A spec element whose object was deleted with mjs_delete (for mjs* structs)."""
    if not (ctx.elem.startswith("mjs") and ctx.elem not in ("mjsDefault", "mjsOrientation",
                                                            "mjsPlugin", "mjsWrap")):
        _na()
    from mjcffi import functions as F
    from .env import _SPEC_MAKERS
    if ctx.elem not in _SPEC_MAKERS:
        _na()
    env = ctx.env
    s, world, body = env.spec
    if ctx.elem in ("mjsElement", "mjsBody"):
        victim = F.mjs_addBody(world, None)
    else:
        victim = _SPEC_MAKERS[ctx.elem](F, s, world, body)
    element = victim if ctx.elem == "mjsElement" else victim.element
    try:
        F.mjs_delete(s, element)
    except NotImplementedError:
        _na("mjs_delete is not supported")
    return victim


def _other_spec_element(ctx):
    """The element of another spec (for mjs* structs and mjsElement)."""
    if not ctx.elem.startswith("mjs"):
        _na()
    from .env import Env
    other = Env(ctx.env.workdir)
    ctx.extra["keep"] = other
    return other.struct(ctx.elem)


STRUCT = {
    "None": lambda c: None,
    "int": lambda c: 0,
    "str": lambda c: "m",
    "object": lambda c: _Unconvertible(),
    "wrong struct": _wrong_struct,
    "other model": _other_model,
    "raw NULL": _raw_null,
    "raw pointer": _raw_pointer,
    "class": _struct_class,
    "closed/freed": _closed,
    "deleted element": _deleted_element,
    "other spec": _other_spec_element,
}


# ------------------------------------------------------------------ arrays

def _shape(ctx):
    if ctx.valid is None or not isinstance(ctx.valid, np.ndarray):
        _na("no valid array")
    return ctx.valid.shape


def _g(values, dtype, ctx, **kw):
    """`values` against a guard page; read-only for an input, so that a write faults."""
    return guard.guarded(values, dtype, readonly=kw.pop("readonly", ctx.const), **kw)


def _fill(shape, dtype, value=1):
    out = np.empty(shape, dtype)
    out[...] = value
    return out


def _resized(ctx, axis, delta):
    shape = list(_shape(ctx))
    if axis >= len(shape):
        _na()
    shape[axis] += delta
    if shape[axis] < 0:
        _na()
    return _g(_fill(shape, ctx.valid.dtype), None, ctx)


def _empty(ctx):
    _shape(ctx)
    return _g(np.zeros((0,), ctx.valid.dtype), None, ctx)


def _three_d(ctx):
    v = ctx.valid
    _shape(ctx)
    return _g(v.reshape((1,) + v.shape + ((1,) if v.ndim == 1 else ())), None, ctx)


def _transposed(ctx):
    v = ctx.valid
    if v is None or v.ndim != 2 or v.shape[0] == v.shape[1]:
        _na()
    return _g(np.ascontiguousarray(v.T), None, ctx)


def _flat(ctx):
    v = ctx.valid
    if v is None or v.ndim != 2:
        _na()
    return _g(v.ravel(), None, ctx)


def _matrix(ctx):
    v = ctx.valid
    if v is None or v.ndim != 1:
        _na()
    return _g(np.ones((v.shape[0], 2), v.dtype), None, ctx)


def _wrong_dtype(ctx):
    v = ctx.valid
    _shape(ctx)
    other = np.int32 if v.dtype != np.int32 else np.float64
    return _g(np.ones(v.shape, other), None, ctx)


def _float32(ctx):
    v = ctx.valid
    _shape(ctx)
    if v.dtype == np.float32:
        return _g(np.ones(v.shape, np.float64), None, ctx)
    return _g(np.ones(v.shape, np.float32), None, ctx)


def _int64(ctx):
    _shape(ctx)
    return _g(np.ones(ctx.valid.shape, np.int64), None, ctx)


def _object_dtype(ctx):
    _shape(ctx)
    out = np.empty(ctx.valid.shape, object)
    out[...] = 1
    return out


def _bigendian(ctx):
    v = ctx.valid
    _shape(ctx)
    return np.ones(v.shape, v.dtype.newbyteorder(">"))


def _fortran(ctx):
    v = ctx.valid
    if v is None or v.ndim != 2 or 1 in v.shape:
        _na()
    return np.asfortranarray(np.ones(v.shape, v.dtype))


def _strided(ctx):
    v = ctx.valid
    _shape(ctx)
    if v.size == 0:
        _na()
    base = np.ones((v.size * 2,), v.dtype)
    return base[::2].reshape(v.shape)


def _misaligned(ctx):
    v = ctx.valid
    _shape(ctx)
    if v.dtype.itemsize == 1 or v.size == 0:
        _na()
    raw = np.zeros(v.nbytes + 1, np.uint8)
    out = raw[1:].view(v.dtype).reshape(v.shape)
    out[...] = 1
    return out


def _readonly(ctx):
    v = ctx.valid
    _shape(ctx)
    return _g(v, None, ctx, readonly=True)


def _front(ctx):
    v = ctx.valid
    _shape(ctx)
    return guard.guarded(v, front=True)


def _as_list(ctx):
    _shape(ctx)
    return ctx.valid.tolist()


def _nan_filled(ctx):
    v = ctx.valid
    _shape(ctx)
    if v.dtype.kind != "f":
        _na()
    return _g(_fill(v.shape, v.dtype, np.nan), None, ctx)


def _inf_filled(ctx):
    v = ctx.valid
    _shape(ctx)
    if v.dtype.kind != "f":
        _na()
    return _g(_fill(v.shape, v.dtype, np.inf), None, ctx)


def _int_filled(value):
    def make(ctx):
        v = ctx.valid
        _shape(ctx)
        if v.dtype.kind not in "iu" or v.dtype.itemsize < 4:
            _na()
        return _g(_fill(v.shape, v.dtype, value), None, ctx)
    return make


def _byte_filled(ctx):
    v = ctx.valid
    _shape(ctx)
    if v.dtype.itemsize != 1:
        _na()
    return _g(_fill(v.shape, v.dtype, 255), None, ctx)


def _subclass(ctx):
    _shape(ctx)
    return _g(ctx.valid, None, ctx).view(np.matrix) if ctx.valid.ndim == 2 else _na()


ARRAY = {
    "None": lambda c: None,
    "scalar": lambda c: 1.0,
    "str": lambda c: "abc",
    "object": lambda c: _Unconvertible(),
    "short": lambda c: _resized(c, 0, -1),
    "long": lambda c: _resized(c, 0, 1),
    "short cols": lambda c: _resized(c, 1, -1),
    "long cols": lambda c: _resized(c, 1, 1),
    "empty": _empty,
    "3-D": _three_d,
    "transposed": _transposed,
    "flat": _flat,
    "(n, 2)": _matrix,
    "wrong dtype": _wrong_dtype,
    "float32/64": _float32,
    "int64": _int64,
    "object dtype": _object_dtype,
    "big-endian": _bigendian,
    "fortran": _fortran,
    "strided": _strided,
    "misaligned": _misaligned,
    "read-only": _readonly,
    "front guard": _front,
    "list": _as_list,
    "ragged list": lambda c: [[1.0], [1.0, 2.0]],
    "nan": _nan_filled,
    "inf": _inf_filled,
    "ints -1": _int_filled(-1),
    "ints 2**31-1": _int_filled(2**31 - 1),
    "ints -2**31": _int_filled(-2**31),
    "bytes 255": _byte_filled,
    "np.matrix": _subclass,
}


# ----------------------------------------------------------------- buffers

# ------------------------------------------------------------ raw handles

def _stack_pointer(ctx):
    import mjcffi
    return mjcffi.mj_stackAllocNum(ctx.env.d, 3)


def _cffi_owned(ctx):
    from mjcffi import ffi
    out = ffi.new("char[]", 64)
    ctx.extra["keep"] = out
    return ffi.cast("void *", out)


def _wrong_handle(ctx):
    value = ctx.env.wrong_opaque(ctx.elem)
    if value is None:
        _na()
    return value


OPAQUE = {
    "None": lambda c: None,
    "int": lambda c: 0,
    "bytes": lambda c: b"abc",
    "bytearray": lambda c: bytearray(8),
    "object": lambda c: _Unconvertible(),
    "NULL": lambda c: __import__("mjcffi").ffi.NULL,
    "raw: wrong handle type": _wrong_handle,
    "raw: mjData stack pointer": _stack_pointer,
    "raw: cffi-owned memory": _cffi_owned,
}


def _noncontig_bytes(ctx):
    return np.zeros(16, np.uint8)[::2]


BUFFER = {
    "None": lambda c: None,
    "str": lambda c: "abc",
    "int": lambda c: 16,
    "object": lambda c: _Unconvertible(),
    "empty": lambda c: bytearray() if not c.const else b"",
    "one byte": lambda c: bytearray(1) if not c.const else b"\0",
    "read-only bytes": lambda c: b"\0" * 64,
    "non-contiguous": _noncontig_bytes,
    "guarded 1 byte": lambda c: guard.zeros((1,), np.uint8),
    "float array": lambda c: np.zeros(8),
    "list": lambda c: [0, 1, 2],
    "raw: mjData stack pointer": lambda c: _stack_pointer(c),
    "raw: cffi-owned memory": lambda c: _cffi_owned(c),
}


# Per kind: the variation table.
KINDS = {
    "int": INT,
    "float": FLOAT,
    "text": TEXT,
    "struct": STRUCT,
    "array": ARRAY,
    "buffer": BUFFER,
    "opaque": OPAQUE,
}


def table(kind):
    return KINDS.get(kind, COMMON)
