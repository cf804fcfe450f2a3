"""Argument marshalling for MuJoCo's functions: the runtime half of mjcffi/_functions/.

codegen/functions.py writes one plain function per MuJoCo function; each is
a short list of calls into this module, then the guarded C call.  The rules:

- A struct argument takes the wrapper class (MjModel, MjvScene, ...): its
  `_cname` must name the C struct.  `None` is accepted only where the header
  says `Nullable:`.
- An array argument takes NumPy arrays.  An input (const) may be anything
  `np.ascontiguousarray` converts to the exact dtype; an output (non-const)
  must already be a writable, C-contiguous ndarray of the exact dtype, so
  that MuJoCo's result lands in it and never in a silent copy.
- Shapes follow the official bindings: a vector of n is (n,) or (n, 1); an
  (r, c) matrix is (r, c), or (r,) when c is 1; so jacp is (3, nv), never
  flat.  A few arguments that the official bindings check by size alone
  (mju_raySkin's face) take any shape of that size.
- A model/data pair must belong together: `d` made for `m` (the fast path),
  or for a model with the same sizes (the header of mjModel up to `opt`).
- Errors name the argument.  An array the function cannot take raises
  ArgumentError, a TypeError (as the official bindings) that is also a
  ValueError; its message is the official one where the official bindings have
  their own, with the expected shape in a note.  An id out of range raises
  IdError (IndexError and ValueError).  A mju_error inside MuJoCo becomes
  FatalError.

Support module: imports only the compiled module, views, const, stack, errors,
contract (for the flag of a stashed callback error), interrupt (Ctrl-C in the step
loops) and NumPy.
"""

import operator
import os
import reprlib
from typing import NamedTuple

import numpy as np

from . import errors as _errors
from . import official as _bindings
from . import contract as _contract
from . import interrupt as _interrupt
from .errors import FatalError  # noqa: F401  (raised by the generated functions)
from .errors import ArgumentError, IdError, with_note  # noqa: F401  (also for _functions)
from . import stack  # noqa: F401  (for _functions: the calls that release stack arrays)
from .const import wrap_const  # noqa: F401  (for _functions: const struct results)
from .library import ffi, lib
from .views import DTYPES

NULL = ffi.NULL
_INT_MAX = 2 ** 31 - 1
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
# (mjcffi/_support/callbacks.py stashes it; its flag is the only cost when none).
def check(status):
    """After a void guard: raise what the call left (FatalError, a callback's error)."""
    try:
        if status:
            _errors.check(status)
    finally:
        if _contract.pending:
            _contract.raise_stashed()


_STOPPED = lib.MJCFFI_STEP_STOPPED


def check_steps(status, what):
    """After an mj_step loop (mjcffi_step, mjcffi_step_substep): as `check`, and
    KeyboardInterrupt when a SIGINT stopped it before its last step, even when the
    user's SIGINT handler raised nothing: the caller asked for steps it did not get."""
    if status != _STOPPED:
        return check(status)
    try:
        if _contract.pending:
            _contract.raise_stashed()
    finally:                      # the KeyboardInterrupt wins; a callback's error is its context
        _interrupt.stopped(what)


def check_error():
    """After a value-returning guard: raise what the call left, as `check` does."""
    try:
        _errors.raise_pending()
    finally:
        if _contract.pending:
            _contract.raise_stashed()


def _struct_title(cname):
    return cname[0].upper() + cname[1:]


def scalar_error(exc, func, scalars):
    """The error to raise when cffi refused a scalar argument: name the culprit.

    `scalars` maps argument name -> (C type, value).  cffi's own messages
    ("an integer is required") do not say which argument was wrong, so each
    is tried again alone: a wrong type is a TypeError, a number that does not
    fit in its C type a ValueError (never OverflowError), each naming the
    argument.  None is tried first: `ffi.new` would take it as "no initializer".
    """
    for name, (ctype, value) in scalars.items():
        if value is None:
            return TypeError(f"{func}(): {name} must be a number (C {ctype}), not None")
    for name, (ctype, value) in scalars.items():
        try:
            ffi.new(ctype + " *", value)
        except OverflowError:
            return ValueError(f"{func}(): {name}={reprlib.repr(value)} does not fit in a "
                              f"C {ctype}")
        except TypeError:
            return TypeError(f"{func}(): {name} must be a number (C {ctype}), "
                             f"not {type(value).__name__}")
    names = ", ".join(scalars)                # none fails alone: name them all
    if isinstance(exc, OverflowError):
        return ValueError(f"{func}(): a value does not fit in its C type ({names}): {exc}")
    return TypeError(f"{func}(): a scalar argument was refused ({names}): {exc}")


def check_scalars(func, scalars):
    """Raise the error naming the first of `scalars` that its C type refuses (a prepared
    call converts its scalars at every call: a bad one is refused when it is prepared)."""
    bad = bad_scalar(func, scalars)
    if bad is not None:
        raise bad


def bad_scalar(func, scalars):
    """The error naming the first of `scalars` (as scalar_error takes them) that its C
    type refuses, or None.  For a check that runs before the call converts them (the
    renderer's OpenGL state): a wrong argument is named before the state is blamed."""
    for name, (ctype, value) in scalars.items():
        try:
            if value is None:
                raise TypeError
            ffi.new(ctype + " *", value)
        except (TypeError, OverflowError):
            return scalar_error(None, func, {name: (ctype, value)})
    return None


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
        try:
            return value._ptr
        except AttributeError:           # the class itself, not an instance
            pass
    if isinstance(value, ffi.CData) and ffi.typeof(value) is _pointer_type(cname):
        if value == NULL:
            raise ValueError(f"{name} must not be NULL")
        return value
    if _bindings.is_official(value):       # both bindings have an MjModel: say which
        raise _bindings.not_accepted(name, _struct_title(cname), value)
    if isinstance(value, type):
        raise TypeError(f"{name} must be {_struct_title(cname)}, not the class "
                        f"{value.__name__} itself")
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


class _Raw:
    """A raw C pointer where a wrapper is expected (its `_ptr`)."""
    __slots__ = ("_ptr",)

    def __init__(self, pointer):
        self._ptr = pointer


def data_of(m, d, mname="m", dname="d"):
    """The C pointer of MjData `d`, checked against MjModel `m` (already checked)."""
    pointer = struct(d, "mjData", dname)
    model = getattr(d, "_model", None)
    if model is None or model is m:
        return pointer           # a wrapper that does not know its model: trust it
    if isinstance(m, ffi.CData):
        m = _Raw(m)              # a raw mjModel * is taken too
    if ffi.buffer(model._ptr, _SIZES)[:] != ffi.buffer(m._ptr, _SIZES)[:]:
        raise ValueError(f"{dname} was made for a model of other sizes than {mname} "
                         f"(nq {model._ptr.nq} vs {m._ptr.nq}, nv {model._ptr.nv} vs "
                         f"{m._ptr.nv}, nbody {model._ptr.nbody} vs {m._ptr.nbody}, ...)")
    return pointer


# ---------------------------------------------------------------- strings

def text(value, name):
    """A `const char *` argument: str (UTF-8), bytes or os.PathLike, without NUL."""
    if value.__class__ is str:               # the common case: a NUL test on str is cheaper
        if "\0" in value:
            raise ValueError(f"{name} contains a NUL character")
        return value.encode("utf-8")
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

def _official(message, axis):
    """The official message for a failure along `axis`: `message` is a str, or
    ((axis, message), ...) in the order the official bindings check the axes."""
    if message is None or message.__class__ is str:
        return message
    for checked, text in message:
        if checked == axis:
            return text
    return None


def _fail(detail, message=None, axis=0):
    """Raise ArgumentError: the official message with `detail` as a note, or `detail`."""
    official = _official(message, axis)
    if official is None:
        raise ArgumentError(detail)
    raise with_note(ArgumentError(official), detail)


_ndarray = np.ndarray
_from_buffer = ffi.from_buffer


def _convert(value, dtype, name):
    if value is None:
        raise ArgumentError(f"{name} must be an array, not None")
    try:
        return np.ascontiguousarray(value, dtype=dtype)
    except (TypeError, ValueError, OverflowError) as exc:    # 2**40 for an int32 array
        raise ArgumentError(f"{name} cannot be converted to a {dtype} array: {exc}") from None


def array_in(value, elem, name, dims=None, message=None, live=False):
    """An input array: (ndarray, C pointer); converted to `elem`'s dtype when needed.

    `dims`: the expected extents, checked (see `shape`); `message`: the official
    message for a wrong shape.  `live` (a prepared call, which reads the array at
    every call): an array that would be copied is refused instead.
    """
    dtype, ctype = elem
    given = value
    if type(value) is not _ndarray or value.dtype is not dtype:
        value = _convert(value, dtype, name)
    if dims is not None:
        if dims.__class__ is int:
            if value.size != dims or value.ndim != 1:
                _vector(value, dims, name, message)
        else:
            shape(value, dims, name, message)
    try:
        pointer = _from_buffer(ctype, value)
    except ValueError:               # not C-contiguous: cheaper to learn here than by flags
        value = _convert(value, dtype, name)
        pointer = _from_buffer(ctype, value)
    if live and value is not given and not (isinstance(given, _ndarray)
                                            and np.may_share_memory(given, value)):
        raise ArgumentError(f"{name} must be a C-contiguous NumPy array of dtype {dtype} to be "
                            f"prepared, not {_kind_of(given)}: a prepared call reads it at "
                            f"every call, and a converted copy would never see later changes")
    return value, pointer


def _kind_of(value):
    if isinstance(value, _ndarray):
        layout = "C-contiguous" if value.flags.c_contiguous else "non-contiguous"
        return f"a {layout} {value.dtype} array"
    return type(value).__name__


def opt_in(value, elem, name, dims=None, message=None, live=False):
    """As `array_in`, with None meaning NULL (the header says Nullable)."""
    if value is None:
        return None, NULL
    return array_in(value, elem, name, dims, message, live)


def array_out(value, elem, name, dims=None, message=None):
    """An output array: (ndarray, C pointer); it must be writable, C-contiguous, of `elem`."""
    dtype, ctype = elem
    if type(value) is not _ndarray or value.dtype is not dtype or not value.flags.carray:
        _check_output(value, dtype, name)
    if dims is not None:
        if dims.__class__ is int:
            if value.size != dims or value.ndim != 1:
                _vector(value, dims, name, message)
        else:
            shape(value, dims, name, message)
    return value, _from_buffer(ctype, value)


def _check_output(value, dtype, name):
    """Why `value` cannot receive MuJoCo's output (or nothing: a subclass, say)."""
    if not isinstance(value, _ndarray):
        raise ArgumentError(f"{name} is an output: it must be a writable NumPy array of "
                            f"dtype {dtype}, not {type(value).__name__}")
    if value.dtype != dtype:
        raise ArgumentError(f"{name} must have dtype {dtype}, not {value.dtype}")
    if not value.flags.c_contiguous:
        raise ArgumentError(f"{name} must be C-contiguous (MuJoCo writes into its memory)")
    if not value.flags.writeable:
        raise ArgumentError(f"{name} is read-only; MuJoCo writes into it")
    if not value.flags.aligned:
        raise ArgumentError(f"{name} must be aligned")


def opt_out(value, elem, name, dims=None, message=None):
    """As `array_out`, with None meaning NULL (the header says Nullable)."""
    if value is None:
        return None, NULL
    return array_out(value, elem, name, dims, message)


def buffer_in(value, name):
    """A `const void *` with a byte count: any bytes-like object; (C pointer, nbytes)."""
    try:
        view = memoryview(value)
    except TypeError:
        raise TypeError(f"{name} must be bytes-like, not {type(value).__name__}") from None
    if not view.c_contiguous:
        raise ArgumentError(f"{name} must be C-contiguous")
    return ffi.from_buffer(value), view.nbytes


def buffer_out(value, name):
    """A writable `void *` or `char *` with a byte count: bytearray, NumPy array, ..."""
    try:
        view = memoryview(value)
    except TypeError:
        raise TypeError(f"{name} must be a writable bytes-like object (bytearray, "
                        f"NumPy array), not {type(value).__name__}") from None
    if view.readonly:
        raise ArgumentError(f"{name} is read-only; MuJoCo writes into it")
    if not view.c_contiguous:
        raise ArgumentError(f"{name} must be C-contiguous")
    return ffi.from_buffer(value), view.nbytes


def opt_buffer_in(value, name):
    return (NULL, 0) if value is None else buffer_in(value, name)


def opt_buffer_out(value, name):
    return (NULL, 0) if value is None else buffer_out(value, name)


# The layouts accepted, as the official bindings' (pybind11's Eigen) conversions:
# a vector of n is (n,) or (n, 1); an (r, c) matrix is (r, c), or (r,) when c is 1.
# A few arguments that the official bindings check by size alone take any shape
# of the right size (`size`).

def _matrix(array):
    """`array`'s shape as a matrix: (r, c), or None if it cannot be one."""
    if array.ndim == 2:
        return array.shape
    if array.ndim == 1:
        return array.shape[0], 1
    return None


def dim(array, ndims, axis, factor, name, message=None):
    """A size deduced from `array` (None if it is None): its length along `axis`
    of an `ndims`-D layout, divided by `factor`."""
    if array is None:
        return None
    if ndims == 1:
        if array.ndim == 1:
            length = array.size
        elif array.ndim == 2 and array.shape[1] == 1:
            length = array.shape[0]
        else:
            _fail(f"{name} must be a vector, shape (n,) or (n, 1), got {array.shape}")
    else:
        extents = _matrix(array)
        if extents is None:
            _fail(f"{name} must be a 2-D array, got shape {array.shape}")
        length = extents[axis]
    if length % factor:
        _fail(f"{name} must have a multiple of {factor} elements along axis {axis}, "
              f"got shape {array.shape}", message, axis)
    return length // factor


def _vector(array, n, name, message=None):
    """Check that `array` is a vector of `n`: shape (n,) or (n, 1)."""
    if array.shape == (n,) or array.shape == (n, 1):
        return
    if n < 0:
        raise ValueError(f"{name}: expected size {n} is negative")
    _fail(f"{name} must have shape ({n},), got {array.shape}", message)


def shape(array, dims, name, message=None):
    """Check that `array` (None is skipped) holds `dims`: a vector size (int) or a shape."""
    if array is None:
        return
    if dims.__class__ is int:
        if array.size != dims or array.ndim != 1:
            _vector(array, dims, name, message)
        return
    if array.shape == dims:
        return
    if len(dims) == 1:
        _vector(array, dims if dims.__class__ is int else dims[0], name, message)
        return
    for n in dims:
        if n < 0:
            raise ValueError(f"{name}: expected shape {dims} has a negative extent")
    extents = _matrix(array)
    if extents is None:
        _fail(f"{name} must have shape {dims}, got {array.shape}", message)
    for axis in _axes(message):
        if extents[axis] != dims[axis]:
            _fail(f"{name} must have shape {dims}, got {array.shape}", message, axis)


def _axes(message):
    """The axes in the order the official bindings check them (see `_official`)."""
    if message is None or message.__class__ is str:
        return (0, 1)
    listed = tuple(axis for axis, _ in message)
    return listed + tuple(axis for axis in (0, 1) if axis not in listed)


def size(array, n, name, message=None):
    """Check that `array` (None is skipped) has `n` elements, in any 1-D or 2-D shape."""
    if array is None:
        return
    if array.ndim > 2:
        _fail(f"{name} must be a 1-D or 2-D array, got shape {array.shape}")
    if array.size != n:
        _fail(f"{name} must have {n} elements, got shape {array.shape}", message)


def index(value, count, name, low=0, message=None):
    """An id argument: an int within low..count-1 (MuJoCo does not check it)."""
    try:
        value = operator.index(value)
    except TypeError:
        raise TypeError(f"{name} must be an int, not {type(value).__name__}") from None
    if not low <= value < count:
        detail = f"{name}={value} is out of range: {low} <= {name} < {count}"
        raise IdError(detail) if message is None else with_note(IdError(message), detail)
    return value


def count(value, name, message=None):
    """A size argument the caller passes (mj_multiRay's nray): a non-negative int."""
    try:
        value = operator.index(value)
    except TypeError:
        raise TypeError(f"{name} must be an int, not {type(value).__name__}") from None
    if value < 0:
        detail = f"{name} must not be negative, got {value}"
        raise ValueError(detail) if message is None else with_note(ValueError(message), detail)
    if value > _INT_MAX:
        raise ValueError(f"{name}={reprlib.repr(value)} does not fit in a C int")
    return value


# What the generated fast paths read (codegen/fastpath.py): an exception of these
# while their arguments are checked and converted sends the call down the slow path.
ndarray = np.ndarray
from_buffer = ffi.from_buffer
SLOW = (AttributeError, TypeError, ValueError, KeyError, BufferError)


# mjtObj -> the mjModel count of its objects (mjOBJ_XBODY counts bodies).
_OBJECT_COUNTS = (
    ("BODY", "nbody"), ("XBODY", "nbody"), ("JOINT", "njnt"), ("DOF", "nv"), ("GEOM", "ngeom"),
    ("SITE", "nsite"), ("CAMERA", "ncam"), ("LIGHT", "nlight"), ("FLEX", "nflex"),
    ("MESH", "nmesh"), ("SKIN", "nskin"), ("HFIELD", "nhfield"), ("TEXTURE", "ntex"),
    ("MATERIAL", "nmat"), ("PAIR", "npair"), ("EXCLUDE", "nexclude"), ("EQUALITY", "neq"),
    ("TENDON", "ntendon"), ("ACTUATOR", "nu"), ("SENSOR", "nsensor"), ("NUMERIC", "nnumeric"),
    ("TEXT", "ntext"), ("TUPLE", "ntuple"), ("KEY", "nkey"), ("PLUGIN", "nplugin"))
COUNT_OF = {getattr(lib, "mjOBJ_" + kind): field
            for kind, field in _OBJECT_COUNTS if hasattr(lib, "mjOBJ_" + kind)}


def object_id(model, objtype, objid, name="objid"):
    """Check `objid` against the count of its `objtype` (an unknown type is MuJoCo's
    to refuse); `model` is the C mjModel."""
    try:
        objtype = operator.index(objtype)
    except TypeError:
        return                   # cffi refuses it, and scalar_error names it
    field = COUNT_OF.get(objtype)
    if field is not None:
        index(objid, getattr(model, field), name)


def model_of(data, name="d"):
    """The C mjModel that MjData `data` was made for (for ids of d-only functions)."""
    model = getattr(data, "_model", None)
    if model is None:
        raise TypeError(f"{name} must be an MjData that knows its model (made by MjData(m)), "
                        f"not {type(data).__name__}: its ids cannot be checked otherwise")
    return model._ptr


def camera(model, cam, name="cam", fixed=True):
    """The ids an mjvCamera `cam` (its C pointer) holds for its type, within C mjModel
    `model`: a tracking camera's trackbodyid and, unless `fixed` is False (MuJoCo
    checks it), a fixed camera's fixedcamid."""
    kind = cam.type
    if kind == lib.mjCAMERA_FIXED and fixed:
        index(cam.fixedcamid, model.ncam, name + ".fixedcamid")
    elif kind == lib.mjCAMERA_TRACKING:
        index(cam.trackbodyid, model.nbody, name + ".trackbodyid", -1)


def perturb(model, pert, name="pert"):
    """The ids an mjvPerturb (its C pointer, or NULL) selects, which MuJoCo follows
    unchecked when they are not negative: body, flex and skin."""
    if pert == NULL:
        return
    for field, count in (("select", model.nbody), ("flexselect", model.nflex),
                         ("skinselect", model.nskin)):
        value = getattr(pert, field)
        if value >= count:
            raise IdError(f"{name}.{field}={value} is out of range: {name}.{field} < {count} "
                          f"(or negative: none)")


def require(condition, message):
    """A custom check of the tables in codegen/functions.py."""
    if not condition:
        raise ValueError(message)


def below(array, limit, name, message=None):
    """Every entry of the int array `array` is within 0..limit-1 (indices MuJoCo follows)."""
    if array.size and (array.min() < 0 or array.max() >= limit):
        detail = f"{name} holds indices outside 0..{limit - 1}"
        raise ValueError(detail) if message is None else with_note(ValueError(message), detail)


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
        count(value, name)
    if ndense > ntotal or nband > ntotal - ndense:
        raise ValueError(f"need ndense <= ntotal and nband <= ntotal - ndense, got "
                         f"ntotal={ntotal}, nband={nband}, ndense={ndense}")
    return (ntotal - ndense) * nband + ndense * ntotal


def fill(out, pointer, count):
    """`out` holding the `count` values at `pointer` (copied unless it is `out` itself).

    mj_readCtrl and mj_readSensor return a pointer into mjData, or NULL after
    writing into `out`; either way the value ends in `out`, as in the official
    bindings, which return it.
    """
    if pointer != NULL:
        target = _from_buffer(ffi.typeof(pointer), out)
        if target != pointer:
            ffi.memmove(target, pointer, count * ffi.sizeof(ffi.typeof(pointer).item))
    return out


def stack_array(d, pointer, count, elem):
    """A stack allocation of `d` (mj_stackAllocNum, ...) as a view of `count` `elem`s
    that keeps d alive; made read-only when a later call releases it (stack.py)."""
    return stack.array(d, pointer, operator.index(count), elem.dtype)


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


