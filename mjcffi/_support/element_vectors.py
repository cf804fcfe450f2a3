"""The std::vector fields of spec elements: `vector_field`, what codegen/structs.py
builds them with in the generated mjcffi/structs/mjspec.py.

An mjDoubleVec, mjFloatVec or mjIntVec reads as an MjDoubleVec, MjFloatVec or
MjIntVec: a live sequence of the numbers the spec holds, as in the official
bindings (`site.userdata[0] = 1` writes the spec), which NumPy takes as an array
(a copy); an mjStringVec as a live MjStringVec of str; an mjByteVec as bytes, an
mjIntVecVec or mjFloatVecVec as a list of arrays (copies, written whole; the
last two once, as MuJoCo only appends to them).  A str is taken for an
mjStringVec as a list of it.  MuJoCo's C API reads only strings and double
vectors back, so the others are read from the std::vector that mjspec.h hides
behind `void`: three pointers (begin, end, capacity), and a std::string as
libc++ lays it out (see _read_string; tests/test_spec_elements.py checks each
kind against what was written and against the official binding).
"""

import operator

import numpy as np
from numpy.lib.mixins import NDArrayOperatorsMixin

from . import marshal as _marshal
from . import spec_claims as _claims
from .library import ffi, lib
from .element_fields import _cast, _made, _text, _where

NULL = ffi.NULL


class _NumberVector(NDArrayOperatorsMixin):
    """A std::vector of numbers that a spec element holds (body.userdata): a live
    sequence, as the official MjDoubleVec.  Indexing reads and writes the spec;
    NumPy takes it as an array (a copy, np.asarray(v)), and arithmetic gives
    arrays; `v[i:j] = x` and in-place operators (`v += 1`) write back, keeping
    the length (assign to the attribute to change it).  It reaches the vector
    through the element's wrapper on every use, so that of a deleted element
    raises DeletedElementError."""

    __slots__ = ("_owner", "_field", "_key")
    dtype: np.dtype
    _ctype = ""
    __hash__ = None  # type: ignore[assignment]  # mutable

    def _span(self):
        """(pointer to the first number, how many)."""
        owner = self._owner
        _claims.check(owner, b"a spec vector")
        state = owner.__dict__
        vector = state.get(self._key)
        if vector is None:
            pointer = getattr(owner._ptr, self._field)
            if pointer == NULL:
                return NULL, 0
            vector = state[self._key] = ffi.cast(self._ctype, pointer)
        begin = vector[0]
        return begin, vector[1] - begin

    def __len__(self):
        return self._span()[1]

    def __array__(self, dtype=None, copy=None):
        if copy is False:
            raise ValueError(f"{type(self).__name__} cannot be viewed without a copy")
        begin, size = self._span()
        if not size:
            array = np.zeros(0, self.dtype)
        else:
            array = np.frombuffer(ffi.buffer(begin, size * self.dtype.itemsize),
                                  self.dtype).copy()
        return array if dtype is None else array.astype(dtype)

    def tolist(self):
        begin, size = self._span()
        return ffi.unpack(begin, size) if size else []

    def copy(self):
        """The numbers as a new NumPy array."""
        return self.__array__()

    @property
    def shape(self):
        return (len(self),)

    @property
    def size(self):
        return len(self)

    ndim = 1

    def _item(self, index):
        begin, size = self._span()
        i = operator.index(index)
        if not -size <= i < size:
            raise IndexError(f"index {i} is out of range for {size} entries")
        return begin, i % size

    def __getitem__(self, index):
        if isinstance(index, (int, np.integer)):
            begin, i = self._item(index)
            return begin[i]
        return self.__array__()[index]

    def __setitem__(self, index, value):
        if isinstance(index, (int, np.integer)):
            begin, i = self._item(index)
            try:
                begin[i] = value
            except (TypeError, OverflowError):
                begin[i] = _numbers(self._owner, self._field, [value], self.dtype)[0]
            return
        array = self.__array__()
        array[index] = value
        begin, size = self._span()
        if size != array.size:
            raise ValueError(f"{self._name()} changed length while being written")
        ffi.memmove(begin, ffi.from_buffer(array), array.nbytes)

    def __iter__(self):
        return iter(self.tolist())

    def __array_ufunc__(self, ufunc, method, *inputs, out=None, **kwargs):
        inputs = tuple(np.asarray(x) if isinstance(x, _NumberVector) else x for x in inputs)
        if out is None:
            return getattr(ufunc, method)(*inputs, **kwargs)
        arrays = tuple(np.asarray(o) if isinstance(o, _NumberVector) else o for o in out)
        result = getattr(ufunc, method)(*inputs, out=arrays, **kwargs)
        for target, array in zip(out, arrays):
            if isinstance(target, _NumberVector):
                target[...] = array
        return out[0] if len(out) == 1 and isinstance(out[0], _NumberVector) else result

    def _name(self):
        return f"{type(self._owner).__name__}.{self._field}"

    def _frozen(self):
        """What the deleted wrapper of its element keeps (_elements.take): a read-only
        array."""
        array = np.array(self)
        array.flags.writeable = False
        return array

    def __repr__(self):
        return f"{type(self).__name__}({self.tolist()})"


class MjDoubleVec(_NumberVector):
    """An mjDoubleVec of a spec element (body.userdata, key.qpos): see _NumberVector."""
    __slots__ = ()
    dtype = np.dtype(np.float64)
    _ctype = "double **"


class MjFloatVec(_NumberVector):
    """An mjFloatVec of a spec element (mesh.uservert): see _NumberVector."""
    __slots__ = ()
    dtype = np.dtype(np.float32)
    _ctype = "float **"


class MjIntVec(_NumberVector):
    """An mjIntVec of a spec element (mesh.userface): see _NumberVector."""
    __slots__ = ()
    dtype = np.dtype(np.int32)
    _ctype = "int **"


class MjStringVec:
    """An mjStringVec of a spec element (texture.cubefiles, flex.material): a live
    sequence of str, as the official MjStringVec: `v[i] = 'name'` writes the spec
    (mjs_setInStringVec), indices from 0 to len(v) - 1.  Assign a list (or a str:
    a list of it) to the attribute to change its length.  It reaches the vector
    through the element's wrapper on every use, so that of a deleted element
    raises DeletedElementError."""

    __slots__ = ("_owner", "_field")
    __hash__ = None  # type: ignore[assignment]  # mutable

    def _pointer(self):
        _claims.check(self._owner, b"a spec string vector")
        return getattr(self._owner._ptr, self._field)

    def __len__(self):
        pointer = self._pointer()
        return _span(pointer)[1] // 24 if pointer != NULL else 0

    def _index(self, index):
        try:
            i = operator.index(index)
        except TypeError:
            raise TypeError(f"{self._name()} indices must be integers, "
                            f"not {type(index).__name__}") from None
        if not 0 <= i < len(self):
            raise IndexError("Index out of range.")
        return i

    def __getitem__(self, index):
        i = self._index(index)
        return _read_string(_span(self._pointer())[0] + 24 * i)

    def __setitem__(self, index, value):
        text = _text(self._owner, self._field, value)
        i = self._index(index)
        lib.mjcffi_guard_mjs_setInStringVec(self._pointer(), i, text)
        _marshal.check_error()

    def __iter__(self):
        pointer = self._pointer()
        return iter(_read_strings(pointer) if pointer != NULL else [])

    def __eq__(self, other):
        if isinstance(other, (MjStringVec, list, tuple)):
            return list(self) == list(other)
        return NotImplemented

    def _name(self):
        return f"{type(self._owner).__name__}.{self._field}"

    def _frozen(self):
        """What the deleted wrapper of its element keeps (_elements.take): a list."""
        return list(self)

    def __repr__(self):
        return f"MjStringVec({list(self)})"


# std::vector<T>: begin, end, end of storage
def _span(pointer):
    begin, end = ffi.cast("char **", pointer)[0:2]
    return begin, int(ffi.cast("uintptr_t", end)) - int(ffi.cast("uintptr_t", begin))


def _read_numbers(pointer, ctype, dtype):
    vector = ffi.cast(ctype, pointer)
    begin = vector[0]
    if begin == NULL:                  # an empty vector that never held anything
        return np.zeros(0, dtype)
    return np.array(ffi.unpack(begin, vector[1] - begin), dtype)


def _read_nested(ctype, dtype):
    """A reader of std::vector<std::vector<T>> (mjIntVecVec, mjFloatVecVec): a list of
    arrays, one per inner vector of 24 bytes."""
    def read(pointer):
        begin, size = _span(pointer)
        return [_read_numbers(begin + 24 * i, ctype, dtype) for i in range(size // 24)]
    return read


def _append_nested(append, dtype):
    """A writer of a vector of vectors.  MuJoCo can only append to one, so only an
    empty one is written (as the XML parser fills it, once)."""
    def write(self, name, pointer, value):
        if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
            raise TypeError(f"{_where(self, name)} takes a list of sequences of numbers, "
                            f"not {type(value).__name__}")
        rows = [_numbers(self, name, row, dtype) for row in value]
        if _span(pointer)[1]:
            raise ValueError(f"{_where(self, name)} is set already: MuJoCo can only "
                             f"append to it, so it is written once")
        for row in rows:
            append(pointer, ffi.cast(ctype_of[dtype], ffi.from_buffer(row)), row.size)
    ctype_of = {np.int32: "int *", np.float32: "float *"}
    return write


def _read_bytes(pointer):
    begin, size = _span(pointer)
    return ffi.buffer(begin, size)[:] if size and begin != NULL else b""


def _read_strings(pointer):
    begin, size = _span(pointer)
    return [_read_string(begin + 24 * i) for i in range(size // 24)]


def _read_string(entry):
    """One libc++ std::string (MuJoCo's wheels use libc++): 24 bytes; bit 0 of the first
    byte set for a long string (capacity, size, pointer), clear for a short one (size
    times 2, then the characters in place)."""
    head = ffi.cast("unsigned char *", entry)[0]
    if head & 1:
        words = ffi.cast("size_t *", entry)
        return ffi.unpack(ffi.cast("char **", entry)[2], words[1]).decode()
    return ffi.unpack(ffi.cast("char *", entry) + 1, head >> 1).decode()


def _numbers(self, name, value, dtype):
    """`value`, a sequence of numbers, as a contiguous 1-D array of `dtype`."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") and \
            not isinstance(value, np.ndarray):
        raise TypeError(f"{_where(self, name)} takes a sequence of numbers, "
                        f"not {type(value).__name__}")
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{_where(self, name)} takes a sequence of numbers: {exc}") from None
    if array.size and array.dtype.kind not in "biuf":
        raise TypeError(f"{_where(self, name)} takes numbers, not {array.dtype}")
    if array.ndim > 1:
        array = array.reshape(-1)        # the official takes nested sequences flattened
    if array.ndim != 1:
        raise TypeError(f"{_where(self, name)} takes a sequence, not a scalar")
    return _cast(self, name, array, np.dtype(dtype))


def _write_vector(setter, ctype, dtype):
    def write(self, name, pointer, value):
        array = _numbers(self, name, value, dtype)
        setter(pointer, ffi.cast(ctype, ffi.from_buffer(array)), array.size)
    return write


def _write_bytes(self, name, pointer, value):
    if isinstance(value, str):
        raise TypeError(f"{_where(self, name)} takes bytes, not str")
    try:
        data = bytes(memoryview(value).cast("B")) if not isinstance(value, bytes) else value
    except TypeError:
        data = bytes(_numbers(self, name, value, np.uint8))
    lib.mjs_setBuffer(pointer, data, len(data))


# string vectors of a fixed length: one entry per role (the official's rule)
_STRING_ROLES = {("mjsMaterial", "textures"): ("texture names", lib.mjNTEXROLE)}


def _write_strings(self, name, pointer, value):
    """A list of str; a str alone is a list of it ('' none), as the official takes."""
    roles = _STRING_ROLES.get((self._cname, name))
    if isinstance(value, str) and roles is None:
        value = [value] if value else []
    if isinstance(value, (bytes, bytearray)) or not hasattr(value, "__iter__"):
        raise TypeError(f"{_where(self, name)} takes a str or a list of str, "
                        f"not {type(value).__name__}")
    texts = [_text(self, name, v) for v in value]
    if roles is not None and len(texts) != roles[1]:
        what, count = roles
        raise ValueError(f"{self._cname[3:].lower()}.{name} must have exactly {count} "
                         f"elements, got {len(texts)}. Assign a list of {count} {what} "
                         f"(use empty strings '' for unused slots).")
    lib.mjs_setStringVec(pointer, b"")
    for text in texts:
        lib.mjs_appendString(pointer, text)


_LIVE = {"mjDoubleVec": MjDoubleVec, "mjFloatVec": MjFloatVec, "mjIntVec": MjIntVec,
         "mjStringVec": MjStringVec}

_VECTORS = {
    "mjDoubleVec": (None, _write_vector(lib.mjs_setDouble, "double *", np.float64)),
    "mjFloatVec": (None, _write_vector(lib.mjs_setFloat, "float *", np.float32)),
    "mjIntVec": (None, _write_vector(lib.mjs_setInt, "int *", np.int32)),
    "mjIntVecVec": (_read_nested("int **", np.int32),
                    _append_nested(lib.mjs_appendIntVec, np.int32)),
    "mjFloatVecVec": (_read_nested("float **", np.float32),
                      _append_nested(lib.mjs_appendFloatVec, np.float32)),
    "mjByteVec": (_read_bytes, _write_bytes),
    "mjStringVec": (_read_strings, _write_strings),
}


def vector_field(name, kind, doc):
    """A `kind *name` field (mjDoubleVec, ...): numbers as a live MjDoubleVec (see
    _NumberVector), the others read as a copy; all written whole."""
    read, write = _VECTORS[kind]
    live = _LIVE.get(kind)
    if live is MjStringVec:
        def get(self):
            vector = MjStringVec.__new__(MjStringVec)
            vector._owner, vector._field = self, name
            return vector
    elif live is not None:
        key, new = "_v_" + name, live.__new__

        def get(self):
            vector = new(live)
            vector._owner, vector._field, vector._key = self, name, key
            return vector
    else:
        def get(self):
            _claims.check(self, b"reading a spec vector")
            pointer = getattr(self._ptr, name)
            return read(pointer) if pointer != NULL else read_empty()
        read_empty = {"mjByteVec": bytes}.get(kind, list)

    def set_value(self, value):
        _claims.check(self, b"writing a spec vector")
        write(self, name, _made(self, name, getattr(self._ptr, name)), value)
    return property(get, set_value, doc=doc)
