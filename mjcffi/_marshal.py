"""Argument marshalling for MuJoCo's functions: the runtime half of mjcffi/_functions.py.

codegen/functions.py writes one plain function per MuJoCo function; each is
a short list of calls into this module, then the guarded C call.  The rules:

- A struct argument takes the wrapper class (MjModel, MjvScene, ...): its
  `_cname` must name the C struct.  `None` is accepted only where the header
  says `Nullable:`.
- An array argument takes NumPy arrays.  An input (const) may be anything
  `np.ascontiguousarray` converts to the exact dtype; an output (non-const)
  must already be a writable, C-contiguous ndarray of the exact dtype, so
  that MuJoCo's result lands in it and never in a silent copy.
- An array matches the expected dims when it has the same number of
  elements and, unless it is flat, the same shape once axes of length 1 are
  dropped: jacp for (3, nv) may be (3, nv) or flat (3*nv,), never (nv, 3).
- A model/data pair must belong together: `d` made for `m` (the fast path),
  or for a model with the same sizes (the header of mjModel up to `opt`).
- Errors name the argument: TypeError for a wrong type or dtype, ValueError
  for a wrong value, shape, layout or size.  A mju_error inside MuJoCo
  becomes FatalError.

Support module: imports only the compiled module, _views, _errors, callbacks (for
the flag of a stashed callback error) and NumPy.
"""

import operator
import os
from typing import NamedTuple

import numpy as np

from . import _errors
from . import callbacks as _callbacks
from ._errors import FatalError  # noqa: F401  (raised by the generated functions)
from ._library import ffi, lib
from ._views import DTYPES

NULL = ffi.NULL
_ERROR_SIZE = 1024          # as the official bindings: MuJoCo's messages are shorter


class Elem(NamedTuple):
    """An array element type: its NumPy dtype and the cffi array type it is passed as."""
    dtype: np.dtype
    ctype: object


def _elem(cname):
    return Elem(DTYPES[cname], ffi.typeof(f"{cname}[]"))


NUM = _elem("mjtNum")
FLOAT = _elem("float")
INT = _elem("int")
BYTE = _elem("mjtByte")
SIZE = _elem("mjtSize")
BOOL = _elem("mjtBool")


# ------------------------------------------------------------------ errors

# After every guarded call: a caught mju_error becomes FatalError, and an
# exception that a Python callback raised during the call is raised here
# (mjcffi/callbacks.py stashes it; its flag is the only cost when none).
def check(status):
    """After a void guard: raise what the call left (FatalError, a callback's error)."""
    try:
        if status:
            _errors.check(status)
    finally:
        if _callbacks._pending:
            _callbacks._raise_stashed()


def check_error():
    """After a value-returning guard: raise what the call left, as `check` does."""
    try:
        _errors.raise_pending()
    finally:
        if _callbacks._pending:
            _callbacks._raise_stashed()


def _struct_title(cname):
    return cname[0].upper() + cname[1:]


def scalar_error(exc, func, scalars):
    """The error to raise when cffi refused a scalar argument: name the culprit.

    `scalars` maps argument name -> (C type, value).  cffi's own messages
    ("an integer is required") do not say which argument was wrong, so each
    is tried again alone; `exc` itself comes back when none fails.
    """
    for name, (ctype, value) in scalars.items():
        try:
            ffi.new(ctype + " *", value)
        except OverflowError:
            return ValueError(f"{func}(): {name}={value!r} does not fit in a C {ctype}")
        except TypeError:
            return TypeError(f"{func}(): {name} must be a number (C {ctype}), "
                             f"not {type(value).__name__}")
    return exc


# ---------------------------------------------------------------- structs

_POINTER_TYPES: dict = {}


def _pointer_type(cname):
    ctype = _POINTER_TYPES.get(cname)
    if ctype is None:
        ctype = _POINTER_TYPES[cname] = ffi.typeof(cname + " *")
    return ctype


def struct(value, cname, name):
    """The C pointer of wrapper `value`, which must wrap a `cname`.

    A raw cffi pointer of exactly that type is taken too (struct fields such
    as MjsBody.element are raw pointers), but never NULL.
    """
    if getattr(value, "_cname", None) == cname:
        return value._ptr
    if isinstance(value, ffi.CData) and ffi.typeof(value) is _pointer_type(cname):
        if value == NULL:
            raise ValueError(f"{name} must not be NULL")
        return value
    raise TypeError(f"{name} must be {_struct_title(cname)}, not {type(value).__name__}")


def opt_struct(value, cname, name):
    """As `struct`, with None meaning NULL (the header says Nullable)."""
    if value is None:
        return NULL
    return struct(value, cname, name)


def struct_value(value, cname, name):
    """A struct passed by value (mjrRect viewport): the wrapper's C struct itself."""
    return struct(value, cname, name)[0]


def opaque(value, name, nullable=False):
    """A handle MuJoCo declares as `void` or an incomplete struct (mjString *, ...).

    Only a cffi pointer is accepted: cffi would also take bytes for a `void *`
    and let MuJoCo write into them.  MuJoCo's typedefs make mjString,
    mjDoubleVec, ... all `void`, so which handle it is cannot be checked.
    """
    if value is None and nullable:
        return NULL
    if not isinstance(value, ffi.CData) or ffi.typeof(value).kind != "pointer":
        raise TypeError(f"{name} must be a cffi pointer (a raw MuJoCo handle), "
                        f"not {type(value).__name__}")
    if value == NULL and not nullable:
        raise ValueError(f"{name} must not be NULL")
    return value


# -------------------------------------------------------------- model/data

# The head of mjModel, up to `opt`: every size an mjData is laid out from.
_SIZES = ffi.offsetof("mjModel", "opt")


def model_data(m, d, mname="m", dname="d"):
    """C pointers of an MjModel and an MjData made for it (or for a model of its sizes)."""
    try:
        if d._model is m:
            return m._ptr, d._ptr
    except AttributeError:
        pass
    return struct(m, "mjModel", mname), data_of(m, d, mname, dname)


def data_of(m, d, mname="m", dname="d"):
    """The C pointer of MjData `d`, checked against MjModel `m` (already checked)."""
    pointer = struct(d, "mjData", dname)
    model = getattr(d, "_model", None)
    if model is None or model is m:
        return pointer           # a wrapper that does not know its model: trust it
    if ffi.buffer(model._ptr, _SIZES)[:] != ffi.buffer(m._ptr, _SIZES)[:]:
        raise ValueError(f"{dname} was made for a model of other sizes than {mname} "
                         f"(nq {model._ptr.nq} vs {m._ptr.nq}, nv {model._ptr.nv} vs "
                         f"{m._ptr.nv}, nbody {model._ptr.nbody} vs {m._ptr.nbody}, ...)")
    return pointer


# ---------------------------------------------------------------- strings

def text(value, name):
    """A `const char *` argument: str (UTF-8), bytes or os.PathLike, without NUL."""
    if isinstance(value, str):
        raw = value.encode("utf-8")
    elif isinstance(value, bytes):
        raw = value
    elif isinstance(value, os.PathLike):
        raw = os.fsencode(value)
    else:
        raise TypeError(f"{name} must be str or bytes, not {type(value).__name__}")
    if b"\0" in raw:
        raise ValueError(f"{name} contains a NUL character")
    return raw


def opt_text(value, name):
    return NULL if value is None else text(value, name)


def string(pointer):
    """A returned `const char *` as str, or None for NULL."""
    if pointer == NULL:
        return None
    return ffi.string(pointer).decode("utf-8", "replace")


def error_buffer():
    """A fresh `char error[1024]` for the (error, error_sz) arguments."""
    return ffi.new("char[]", _ERROR_SIZE), _ERROR_SIZE


def error_text(buffer, func):
    message = ffi.string(buffer).decode("utf-8", "replace").strip()
    return message or f"{func} failed (MuJoCo gave no message)"


# ----------------------------------------------------------------- arrays

_ndarray = np.ndarray
_from_buffer = ffi.from_buffer


def _convert(value, dtype, name):
    if value is None:
        raise TypeError(f"{name} must be an array, not None")
    try:
        return np.ascontiguousarray(value, dtype=dtype)
    except (TypeError, ValueError) as exc:
        raise type(exc)(f"{name} cannot be converted to a {dtype} array: {exc}") from None


def array_in(value, elem, name, dims=None):
    """An input array: (ndarray, C pointer); converted to `elem`'s dtype when needed.

    `dims`: the expected number of elements (an int) or shape (a tuple), checked.
    """
    dtype, ctype = elem
    if type(value) is not _ndarray or value.dtype is not dtype or \
            not value.flags.c_contiguous:
        value = _convert(value, dtype, name)
    if dims is not None:
        if dims.__class__ is int:
            if value.size != dims:
                _wrong_shape(value, (dims,), name)
        else:
            shape(value, dims, name)
    return value, _from_buffer(ctype, value)


def opt_in(value, elem, name, dims=None):
    """As `array_in`, with None meaning NULL (the header says Nullable)."""
    if value is None:
        return None, NULL
    dtype, ctype = elem
    if type(value) is not _ndarray or value.dtype is not dtype or \
            not value.flags.c_contiguous:
        value = _convert(value, dtype, name)
    if dims is not None:
        shape(value, dims, name)
    return value, _from_buffer(ctype, value)


def array_out(value, elem, name, dims=None):
    """An output array: (ndarray, C pointer); it must be writable, C-contiguous, of `elem`."""
    dtype, ctype = elem
    if type(value) is not _ndarray or value.dtype is not dtype or not value.flags.carray:
        _check_output(value, dtype, name)
    if dims is not None:
        if dims.__class__ is int:
            if value.size != dims:
                _wrong_shape(value, (dims,), name)
        else:
            shape(value, dims, name)
    return value, _from_buffer(ctype, value)


def _check_output(value, dtype, name):
    """Why `value` cannot receive MuJoCo's output (or nothing: a subclass, say)."""
    if not isinstance(value, _ndarray):
        raise TypeError(f"{name} is an output: it must be a writable NumPy array of "
                        f"dtype {dtype}, not {type(value).__name__}")
    if value.dtype != dtype:
        raise TypeError(f"{name} must have dtype {dtype}, not {value.dtype}")
    if not value.flags.c_contiguous:
        raise ValueError(f"{name} must be C-contiguous (MuJoCo writes into its memory)")
    if not value.flags.writeable:
        raise ValueError(f"{name} is read-only; MuJoCo writes into it")
    if not value.flags.aligned:
        raise ValueError(f"{name} must be aligned")


def opt_out(value, elem, name, dims=None):
    """As `array_out`, with None meaning NULL (the header says Nullable)."""
    if value is None:
        return None, NULL
    dtype, ctype = elem
    if type(value) is not _ndarray or value.dtype is not dtype or not value.flags.carray:
        _check_output(value, dtype, name)
    if dims is not None:
        shape(value, dims, name)
    return value, _from_buffer(ctype, value)


def buffer_in(value, name):
    """A `const void *` with a byte count: any bytes-like object; (C pointer, nbytes)."""
    try:
        view = memoryview(value)
    except TypeError:
        raise TypeError(f"{name} must be bytes-like, not {type(value).__name__}") from None
    if not view.c_contiguous:
        raise ValueError(f"{name} must be C-contiguous")
    return ffi.from_buffer(value), view.nbytes


def buffer_out(value, name):
    """A writable `void *` or `char *` with a byte count: bytearray, NumPy array, ..."""
    try:
        view = memoryview(value)
    except TypeError:
        raise TypeError(f"{name} must be a writable bytes-like object (bytearray, "
                        f"NumPy array), not {type(value).__name__}") from None
    if view.readonly:
        raise ValueError(f"{name} is read-only; MuJoCo writes into it")
    if not view.c_contiguous:
        raise ValueError(f"{name} must be C-contiguous")
    return ffi.from_buffer(value), view.nbytes


def opt_buffer_in(value, name):
    return (NULL, 0) if value is None else buffer_in(value, name)


def opt_buffer_out(value, name):
    return (NULL, 0) if value is None else buffer_out(value, name)


def dim(array, ndims, axis, factor, name):
    """A size deduced from `array` (None if it is None): its length along `axis`
    of an `ndims`-D layout (its size when ndims is 1), divided by `factor`."""
    if array is None:
        return None
    if ndims == 1:
        length = array.size
    elif array.ndim == ndims:
        length = array.shape[axis]
    else:
        raise ValueError(f"{name} must be a {ndims}-D array, got shape {array.shape}")
    if length % factor:
        raise ValueError(f"{name} must have a multiple of {factor} elements along "
                         f"axis {axis}, got shape {array.shape}")
    return length // factor


def _squeezed(shape):
    return tuple(n for n in shape if n != 1)


def _wrong_shape(array, dims, name):
    expected = dims[0] if len(dims) == 1 else dims
    raise ValueError(f"{name} must have shape {expected}, got {array.shape}")


def shape(array, dims, name):
    """Check that `array` (None is skipped) holds `dims`: a size (int) or a shape (tuple)."""
    if array is None or array.shape == dims:
        return
    if dims.__class__ is int:
        dims = (dims,)
    size = 1
    for n in dims:
        if n < 0:
            raise ValueError(f"{name}: expected shape {dims} has a negative extent")
        size *= n
    if array.size != size or (array.ndim > 1 and len(dims) > 1
                              and _squeezed(array.shape) != _squeezed(dims)):
        _wrong_shape(array, dims, name)


def index(value, count, name, low=0):
    """An id argument: an int within low..count-1 (MuJoCo does not check it)."""
    try:
        value = operator.index(value)
    except TypeError:
        raise TypeError(f"{name} must be an int, not {type(value).__name__}") from None
    if not low <= value < count:
        raise ValueError(f"{name}={value} is out of range: {low} <= {name} < {count}")
    return value


def count(value, name):
    """A size argument the caller passes (mj_multiRay's nray): a non-negative int."""
    try:
        value = operator.index(value)
    except TypeError:
        raise TypeError(f"{name} must be an int, not {type(value).__name__}") from None
    if value < 0:
        raise ValueError(f"{name} must not be negative, got {value}")
    return value


def object_id(model, objtype, objid, name="objid"):
    """Check `objid` against the count of its `objtype` (others are MuJoCo's to refuse)."""
    try:
        objtype = operator.index(objtype)
    except TypeError:
        return                   # cffi refuses it, and scalar_error names it
    # mjOBJ_BODY, mjOBJ_XBODY, mjOBJ_GEOM, mjOBJ_SITE, mjOBJ_CAMERA: the types these accept
    counts = {1: model.nbody, 2: model.nbody, 5: model.ngeom, 6: model.nsite, 7: model.ncam}
    limit = counts.get(objtype)
    if limit is not None:
        index(objid, limit, name)


def require(condition, message):
    """A custom check of the tables in codegen/functions.py."""
    if not condition:
        raise ValueError(message)


def below(array, limit, name):
    """Every entry of the int array `array` is within 0..limit-1 (indices MuJoCo follows)."""
    if array.size and (array.min() < 0 or array.max() >= limit):
        raise ValueError(f"{name} holds indices outside 0..{limit - 1}")


def csr(rownnz, rowadr, colind, nnz, ncol, names=("rownnz", "rowadr", "colind")):
    """A sparse (CSR) structure whose rows lie within `nnz` and columns below `ncol`."""
    if rownnz.size != rowadr.size:
        raise ValueError(f"{names[0]} and {names[1]} must have the same size")
    if rownnz.size and (rownnz.min() < 0 or rowadr.min() < 0
                        or int((rowadr.astype(np.int64) + rownnz).max()) > nnz):
        raise ValueError(f"{names[0]}/{names[1]} address elements beyond the {nnz} given")
    if colind.size < nnz:
        raise ValueError(f"{names[2]} must have at least {nnz} elements")
    if ncol is not None:
        below(colind[:nnz], ncol, names[2])


def state_size(model, sig, name="sig"):
    """mj_stateSize(m, sig); a sig that MuJoCo refuses is a ValueError naming it."""
    try:
        sig = operator.index(sig)
    except TypeError:
        raise TypeError(f"{name} must be an int, not {type(sig).__name__}") from None
    try:
        size = lib.mjcffi_guard_mj_stateSize(model, sig)
    except OverflowError:
        raise ValueError(f"{name}={sig} does not fit in a C int") from None
    message = lib.mjcffi_take_error()
    if message != NULL:
        raise ValueError(f"{name}={sig} is not a valid mjtState signature: "
                         f"{ffi.string(message).decode('utf-8', 'replace')}")
    return size


def band_size(ntotal, nband, ndense):
    """Elements of a band-dense matrix (mju_cholFactorBand), its sizes checked."""
    for name, value in (("ntotal", ntotal), ("nband", nband), ("ndense", ndense)):
        if operator.index(value) < 0:
            raise ValueError(f"{name} must not be negative")
    if ndense > ntotal or nband > ntotal - ndense:
        raise ValueError(f"need ndense <= ntotal and nband <= ntotal - ndense, got "
                         f"ntotal={ntotal}, nband={nband}, ndense={ndense}")
    return (ntotal - ndense) * nband + ndense * ntotal


def copy_array(pointer, count, elem):
    """A NumPy copy of `count` elements at `pointer`, or None for NULL."""
    if pointer == NULL:
        return None
    out = np.empty(count, elem.dtype)
    ffi.memmove(ffi.from_buffer(elem.ctype, out), pointer, out.nbytes)
    return out


# ---------------------------------------------------------------- returns

def wrap(cls, pointer, owner):
    """A returned struct pointer as a `cls` wrapper that keeps `owner`'s memory alive."""
    if pointer == NULL:
        return None
    return cls._wrap(pointer, getattr(owner, "_root", pointer))


def own(cls, pointer, deleter):
    """A returned new struct, owned by its wrapper: `deleter` runs when it is collected."""
    if pointer == NULL:
        return None
    root = ffi.gc(pointer, deleter)
    return cls._wrap(root, root)


def struct_copy(cls, value):
    """A struct returned by value (mjvGLCamera) as a new `cls` wrapper."""
    root = ffi.new(ffi.getctype(cls._ctype, "*"), value)
    return cls._wrap(root, root)


