"""Spec elements as Python objects: their str, char, vector and enum attributes, the
one wrapper of each element, its end when the element is freed, and add_*.

Hand-written support of the generated mjcffi/structs/mjspec.py (as _handles.py
and _checks.py are); codegen/structs.py writes, for the fields of the spec
structs, the builders below:

- `string_field`: an mjString as str (mjs_getString / mjs_setString);
- `char_array`: a fixed char array (compiler.eulerseq, texture.gridlayout) as an
  MjCharVec, a sequence of 1-character str read and written in place;
- `vector_field`: an mjDoubleVec, mjFloatVec or mjIntVec as an MjDoubleVec,
  MjFloatVec or MjIntVec: a live sequence of the numbers the spec holds, as in
  the official bindings (`site.userdata[0] = 1` writes the spec), which NumPy
  takes as an array (a copy); an mjStringVec as a live MjStringVec of str; an
  mjByteVec reads as bytes, an mjIntVecVec or mjFloatVecVec as a list of arrays
  (copies, written whole; the last two once, as MuJoCo only appends to them).
  A str is taken for an mjStringVec as a list of it.  MuJoCo's C API reads
  only strings and double vectors back, so the others are read from the
  std::vector that mjspec.h hides behind `void`: three pointers
  (begin, end, capacity), and a std::string as libc++ lays it out (see
  _read_string; tests/test_spec_elements.py checks each kind against what was
  written and against the official binding);
- `enum_field`: an mjt* field as its IntEnum, taking any int;
- `element_name`: the element's name (mjs_getName / mjs_setName; a name MuJoCo
  refuses raises ValueError with MuJoCo's own message);
- `member_ref`: a pointer to a struct the element owns (its mjsElement, a
  default's geom): one wrapper, kept on the element's;
- `element_setattr`: `__setattr__` of the spec structs: a fixed array takes a
  sequence of exactly its length (as the official), quickly;
- `adder`: `add_*` and `wrap_*` methods over the mjs_add* / mjs_wrap* functions,
  taking keyword arguments for the new element's attributes (see `configure`
  for the official's rules: euler=, axisangle=, xyaxes=, zaxis= and their i*
  forms, size=[r] padded); `frame_adder` the add_* of a frame, which add to its
  body and place the element in the frame.

Memory.  Every element reached through these has one wrapper (`wrap`), which
keeps its spec alive.  MuJoCo frees an element when it is deleted (mjs_delete
frees it at once, a body with its subtree and what refers to it).  Before that:

- `check_releasable` refuses (ValueError naming them) while NumPy views of the
  memory to be freed are held outside their wrappers (`s = geom.size`, or any
  array made from one).  Such a view points into the element and cannot be
  ended; each is cached on the wrapper of the struct it views, with a base (a
  cffi buffer) of its own, to which NumPy collapses the base of every view or
  slice made from it, so `held_views` tells from the reference counts of the
  view and of its base whether anything else holds one.  Nothing is freed then
  and nothing lost: the caller drops (or copies) the arrays and tries again;
- `take` reads the values of each wrapper to be freed.

After it, `invalidate_missing` (or `invalidate`, before) ends each wrapper whose
element is gone: it becomes a DeletedElement of its own class, which reads the
values taken (`body.name` of a deleted body, as the official; arrays as
read-only copies) and raises DeletedElementError on anything else, writes
included (they would be lost).  The vectors, MjCharVec and MjStringVec read
from an element reach it through its wrapper on every use, so they raise too.
`doomed` and `prepare_delete` give the wrappers a delete may free (a body's or a
frame's subtree, and the kinds MuJoCo removes with it), to the safe side.
"""

import operator
import sys
import weakref

import numpy as np
from numpy.lib.mixins import NDArrayOperatorsMixin

from .. import _errors, _marshal
from .._library import ffi, lib
from .._views import FixedArray, Nested, Struct, _scalar_error, view

NULL = ffi.NULL


class DeletedElementError(ValueError, RuntimeError):
    """A wrapper of a spec element that MuJoCo freed (spec.delete) was used, or
    something read from it: a ValueError, and a RuntimeError as mjcffi raised
    before."""


# ------------------------------------------------------------------- strings

def _where(self, name):
    return f"{type(self).__name__}.{name}"


def _text(self, name, value):
    """`value` as NUL-terminated UTF-8 for MuJoCo."""
    if not isinstance(value, str):
        raise TypeError(f"{_where(self, name)} takes a str, not {type(value).__name__}")
    if "\0" in value:
        raise ValueError(f"{_where(self, name)} cannot hold a NUL character")
    return value.encode()


_get_string = lib.mjs_getString
_STRING_BYTES = 24          # sizeof(std::string) in libc++


def _string_reader(key, address):
    """The getter of an mjString: `address(self)` gives the mjString * (fixed for the
    element's life).  The text read last is kept on the wrapper under `key` with
    the string's 24 bytes: a short string (up to 22 bytes) lies wholly in them,
    so while they are unchanged the text is too, and is returned without calling
    MuJoCo.  A long string is read through mjs_getString every time, and so is
    every string should the layout not be libc++'s (each cached text is checked
    against it when kept)."""
    def get(self):
        entry = self.__dict__.get(key)
        if entry is not None and entry[0].tobytes() == entry[1]:
            return entry[2]
        return _read_text(self, key, address)
    return get


def _read_text(self, key, address):
    state = self.__dict__
    entry = state.get(key)
    if entry is None:
        pointer = address(self)
        if pointer == NULL:
            return ""                 # a string MuJoCo never made (body.plugin.info)
        entry = state[key] = [memoryview(ffi.buffer(pointer, _STRING_BYTES)), None, None,
                              pointer]
    raw = entry[0].tobytes()
    data = ffi.string(_get_string(entry[3]))
    text = data.decode()
    if not raw[0] & 1 and raw[1:1 + (raw[0] >> 1)] == data:
        entry[1], entry[2] = raw, text        # short, and laid out as libc++ does
    return text


def string_field(name, doc):
    """A `mjString *name` field as str, read and written through MuJoCo."""
    def set_value(self, value):
        text = _text(self, name, value)
        lib.mjs_setString(_made(self, name, getattr(self._ptr, name)), text)
    get = _string_reader("_s_" + name, lambda self: getattr(self._ptr, name))
    get.c_string = name                     # for _assign_values
    return property(get, set_value, doc=doc)


def _made(self, name, pointer):
    """`pointer`, the string or vector of field `name`; ValueError for NULL: MuJoCo
    leaves some unmade (the `info` of a body's plugin), and they read as empty."""
    if pointer == NULL:
        raise ValueError(f"{_where(self, name)} cannot be set: MuJoCo made no "
                         f"{ffi.typeof(pointer).item.cname} for it here")
    return pointer


_set_name = lib.mjcffi_guard_mjs_setName
_take_error = lib.mjcffi_take_error


def element_name(doc="the element's name"):
    """The `name` of an element: mjs_getName / mjs_setName on its mjsElement.  A name
    MuJoCo refuses (one its kind already has) raises ValueError with MuJoCo's
    message, as the official does ("Error: repeated name 'a' in geom")."""
    def set_value(self, value):
        if value.__class__ is not str or "\0" in value:
            _text(self, "name", value)            # raises, naming the problem
        element = self._ptr.element
        failed = _set_name(element, value.encode())
        message = _take_error()
        if message != NULL:
            _raise_taken(message)
        if failed:
            raise ValueError(_spec_error(element) or
                             f"{_where(self, 'name')}: MuJoCo refused the name {value!r}")
    return property(_string_reader("_name", lambda self: lib.mjs_getName(self._ptr.element)),
                    set_value, doc=doc)


def _raise_taken(message):
    """Raise what a guarded call caught, whose message `message` was taken already
    (as _errors.raise_pending would have)."""
    text = ffi.string(message).decode("utf-8", "replace")
    kind = lib.mjcffi_error_kind()
    if kind == lib.MJCFFI_ERROR_FATAL:
        raise _errors.FatalError(text)
    raise _errors._refusal(kind, text)


def _spec_error(element):
    """The last error MuJoCo recorded on the spec of `element` (mjs_getError)."""
    spec = lib.mjcffi_guard_mjs_getSpec(element)
    _marshal.check_error()
    if spec == NULL:
        return ""
    return _marshal.string(lib.mjs_getError(spec)) or ""


# --------------------------------------------------------------- char arrays

class MjCharVec:
    """A fixed char array of a spec struct (compiler.eulerseq, texture.gridlayout):
    a sequence of its characters, each a 1-character str ('\\x00' where unset),
    read and written in place, as the official MjCharVec.  It reaches the memory
    through its struct's wrapper on every use, so that of a deleted element
    raises DeletedElementError."""

    __slots__ = ("_owner", "_field", "_size")

    def __init__(self, owner, field, size):
        self._owner, self._field, self._size = owner, field, size

    def _chars(self):
        return getattr(self._owner._ptr, self._field)

    def __len__(self):
        return self._size

    def _index(self, index):
        try:
            i = operator.index(index)
        except TypeError:
            raise TypeError(f"{self._name()} indices must be integers, "
                            f"not {type(index).__name__}") from None
        if not 0 <= i < self._size:
            raise IndexError("Index out of range.")
        return i

    def __getitem__(self, index):
        return self._chars()[self._index(index)].decode("latin-1")

    def __setitem__(self, index, value):
        i = self._index(index)
        self._chars()[i] = _char(self._name(), value)

    def __iter__(self):
        return iter(ffi.unpack(self._chars(), self._size).decode("latin-1"))

    def __eq__(self, other):
        if isinstance(other, (MjCharVec, list, tuple)):
            return list(self) == list(other)
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]  # mutable

    def _name(self):
        return f"{type(self._owner).__name__}.{self._field}"

    def __repr__(self):
        return f"MjCharVec({''.join(self)!r})"


def _char(where, value):
    """One character for a char array: a 1-character str (Latin-1)."""
    if not isinstance(value, str):
        raise TypeError(f"{where} takes 1-character str, not {type(value).__name__}")
    if len(value) != 1:
        raise ValueError("Expected a character, but multi-character string found")
    try:
        return value.encode("latin-1")
    except UnicodeEncodeError:
        raise ValueError(f"{where} takes Latin-1 characters, not {value!r}") from None


def char_array(name, size, doc):
    """A `char name[size]` field of a spec struct as an MjCharVec.  It takes a str or
    a sequence of 1-character str of at most `size` characters; the rest is
    filled with NUL."""
    def get(self):
        return MjCharVec(self, name, size)

    def set_value(self, value):
        where = _where(self, name)
        if isinstance(value, (bytes, bytearray)) or not hasattr(value, "__iter__"):
            raise TypeError(f"{where} takes a str or a sequence of 1-character str, "
                            f"not {type(value).__name__}")
        chars = [_char(where, c) for c in value]
        if len(chars) > size:
            raise ValueError(f"{name} may have at most {size} characters")
        ffi.memmove(ffi.addressof(self._ptr, name), b"".join(chars).ljust(size, b"\0"), size)
    get.char_size = size                    # for the keyword rule (_keyword_value)
    return property(get, set_value, doc=doc)


def _char_keyword(cls, name, size, value):
    """A char array given as a keyword of add_*: as the official, a str or a list of
    1-character str of exactly `size` characters."""
    if isinstance(value, str):
        chars = list(value)
    elif isinstance(value, list):
        if not all(isinstance(c, str) and len(c) == 1 for c in value):
            raise ValueError(f"{name} list elements must be single characters.")
        chars = value
    else:
        raise TypeError(f"{name} must be a string or a list of single-character strings.")
    if len(chars) != size:
        raise ValueError(f"{name} should have length {size}, got {len(chars)}.")
    return chars


# ------------------------------------------------------------------- vectors

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


def _cast(self, name, array, dtype):
    """`array` (numbers) as `dtype`, refusing what would change a value: a fraction
    for ints (TypeError), an int out of the type's range (ValueError)."""
    if dtype.kind in "iu" and array.size and array.dtype.kind in "fiu":
        if array.dtype.kind == "f" and not np.all(array == np.round(array)):
            raise TypeError(f"{_where(self, name)} takes ints")
        limits = np.iinfo(dtype)
        if array.min() < limits.min or array.max() > limits.max:
            raise _errors.ArgumentError(f"{_where(self, name)}: a value is out of range "
                                        f"for C {dtype} ({limits.min}..{limits.max})")
    return np.ascontiguousarray(array, dtype)


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
            pointer = getattr(self._ptr, name)
            return read(pointer) if pointer != NULL else read_empty()
        read_empty = {"mjByteVec": bytes}.get(kind, list)

    def set_value(self, value):
        write(self, name, _made(self, name, getattr(self._ptr, name)), value)
    return property(get, set_value, doc=doc)


# --------------------------------------------------------------------- enums

def enum_field(name, enum, doc):
    """An mjt* field as its IntEnum (an int for a value that is no member, such as a
    bitmask); it takes any int."""
    members = None

    def get(self):
        nonlocal members
        if members is None:
            from .. import _enums
            members = {int(m): m for m in getattr(_enums, enum)}
        value = getattr(self._ptr, name)
        return members.get(value, value)

    def set_value(self, value):
        try:
            number = operator.index(value)
        except TypeError:
            raise TypeError(f"{_where(self, name)} takes an {enum} or int, "
                            f"not {type(value).__name__}") from None
        try:
            setattr(self._ptr, name, number)
        except OverflowError as exc:
            raise _scalar_error(self, name, number, exc) from None
    return property(get, set_value, doc=doc)


# ---------------------------------------------------------- struct members

class _MemberRef:
    """A pointer field to a struct its element owns (its mjsElement, a default's
    mjsGeom): the one wrapper of it, built on first read and kept on the element's
    wrapper (so that the element's end ends it too); None for NULL.  Read-only."""

    def __init__(self, name, wrapper, doc):
        self.name, self.wrapper, self.__doc__ = name, wrapper, doc

    def __get__(self, obj, cls=None):
        if obj is None:
            return self
        pointer = getattr(obj._ptr, self.name)
        if pointer == NULL:
            return None
        generated = self.wrapper()
        cls = _BY_KIND.get(generated.__name__[3:], generated)
        value = obj.__dict__[self.name] = cls._wrap(pointer, obj._root)
        return value


def member_ref(name, wrapper, doc):
    """The `_MemberRef` of field `name`; `wrapper()` gives its generated class (the
    class registered for that kind is used where there is one)."""
    return _MemberRef(name, wrapper, doc)


# ------------------------------------------------------------- fixed arrays

_SEQUENCES = (list, tuple)
_SETTERS: dict = {}         # class -> {attribute: its setter(self, value)}

# fixed arrays that take a scalar too, which fills them (frame.scale = 2)
_SCALABLE = {("mjsFrame", "scale")}


def _array_length(field):
    """The length of a 1-D numeric FixedArray, else None."""
    if isinstance(field, FixedArray) and field.dtype.kind in "biuf":
        shape = field.shape(None)
        if len(shape) == 1:
            return shape[0]
    return None


def _setters(cls):
    table = _SETTERS.get(cls)
    if table is None:
        table = _SETTERS[cls] = {}
        for attr in cls._fields + ("name",):
            field = getattr(cls, attr, None)
            length = _array_length(field)
            if length is not None:
                table[attr] = _array_setter(attr, length, field.dtype,
                                            (cls._cname, attr) in _SCALABLE)
            elif isinstance(field, property) and field.fset is not None:
                table[attr] = field.fset
            elif isinstance(field, Nested) and not field.wrapper()._plain:
                table[attr] = _nested_setter(attr)
    return table


_SPEC_POINTER = ffi.typeof("mjSpec *")


def _nested_setter(name):
    """The setter of a nested struct holding pointers (body.plugin = plugin): its
    values are copied, as the official does, never its pointers (`_assign_values`)."""
    def set_nested(self, value):
        _assign_values(getattr(self, name), value, _where(self, name))
    return set_nested


def _assign_values(target, source, where):
    """Copy the values of `source` into `target`, structs of one kind: scalars,
    arrays and strings (where both have one: MuJoCo leaves some unmade), not the
    pointers to other structs, which would share memory that its owner frees."""
    cls = type(target)
    if not isinstance(source, Struct) or source._cname != cls._cname:
        raise TypeError(f"{where} takes {cls.__name__}, not {type(source).__name__}")
    if source._ptr == target._ptr:
        return
    if ffi.typeof(source._root) is not _SPEC_POINTER:
        raise TypeError(f"{where}: this {cls.__name__} holds pointers that no spec made, "
                        f"which cannot be read")
    for attr in cls._fields:
        field = getattr(cls, attr, None)
        if isinstance(field, _MemberRef):
            continue
        string = getattr(getattr(field, "fget", None), "c_string", None)
        if string is not None and (getattr(source._ptr, string) == NULL or
                                   getattr(target._ptr, string) == NULL):
            continue
        setattr(target, attr, getattr(source, attr))


def _array_setter(name, length, dtype, scalable):
    """The setter of a 1-D fixed array: a list or tuple of `length` numbers goes
    through cffi, anything else is checked by `_exactly` and written into the view."""
    def set_array(self, value):
        if value.__class__ in _SEQUENCES and len(value) == length:
            try:
                setattr(self._ptr, name, value)
                return
            except (TypeError, OverflowError):
                pass                        # _exactly names the problem
        getattr(self, name)[...] = _exactly(self, name, value, length, dtype, scalable)
    return set_array


def _exactly(self, name, value, length, dtype, scalable):
    """`value` as `length` numbers of `dtype`: the official takes a sequence of that
    length only (and a scalar where `scalable`); ArgumentError otherwise."""
    where = _where(self, name)
    wanted = f"a scalar or a list/array of size {length}" if scalable else \
        f"a list/array of size {length}"
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{where} takes {wanted}, not {type(value).__name__}")
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{where} takes {wanted}: {exc}") from None
    if array.dtype.kind not in "biuf":
        raise TypeError(f"{where} takes numbers, not {array.dtype}")
    if array.ndim == 0 and scalable:
        array = np.full(length, array)
    if array.shape != (length,):
        got = "a scalar" if array.ndim == 0 else f"shape {array.shape}"
        raise _errors.ArgumentError(f"{where} takes {wanted}, not {got}")
    return _cast(self, name, array, dtype)


def element_setattr():
    """`__setattr__` of the spec structs: each field's setter found in one look-up;
    a fixed array takes exactly its length.  Anything else goes through
    Struct.__setattr__, which names the field."""
    return _setattr


def _setattr(self, name, value):
    try:
        setter = _SETTERS[self.__class__][name]
    except KeyError:
        setter = _setters(self.__class__).get(name)
        if setter is None:
            Struct.__setattr__(self, name, value)
            return
    setter(self, value)


# -------------------------------------------------------------------- wrappers

# mjtObj -> (the element's class name, its mjs_as* function)
_KINDS = {
    "mjOBJ_BODY": "Body", "mjOBJ_XBODY": "Body", "mjOBJ_JOINT": "Joint", "mjOBJ_GEOM": "Geom",
    "mjOBJ_SITE": "Site", "mjOBJ_CAMERA": "Camera", "mjOBJ_LIGHT": "Light",
    "mjOBJ_FLEX": "Flex", "mjOBJ_MESH": "Mesh", "mjOBJ_SKIN": "Skin", "mjOBJ_HFIELD": "HField",
    "mjOBJ_TEXTURE": "Texture", "mjOBJ_MATERIAL": "Material", "mjOBJ_PAIR": "Pair",
    "mjOBJ_EXCLUDE": "Exclude", "mjOBJ_EQUALITY": "Equality", "mjOBJ_TENDON": "Tendon",
    "mjOBJ_ACTUATOR": "Actuator", "mjOBJ_SENSOR": "Sensor", "mjOBJ_NUMERIC": "Numeric",
    "mjOBJ_TEXT": "Text", "mjOBJ_TUPLE": "Tuple", "mjOBJ_KEY": "Key", "mjOBJ_PLUGIN": "Plugin",
    "mjOBJ_FRAME": "Frame",
}
_BY_TYPE = {getattr(lib, obj): kind for obj, kind in _KINDS.items() if hasattr(lib, obj)}

# spec address -> {element address: its wrapper}
_REGISTRIES: dict = {}


_UINTPTR = ffi.typeof("uintptr_t")
_ELEMENT = ffi.typeof("mjsElement *")


def _address(pointer):
    return int(ffi.cast(_UINTPTR, pointer))


class Registry:
    """Element address -> its wrapper, held weakly: a mapping like WeakValueDictionary,
    but with plain weak references (no callback when a wrapper dies, which add_*
    would pay for every element it makes); dead entries read as absent and are
    swept as the table grows."""

    __slots__ = ("_refs", "_sweep_at")

    def __init__(self):
        self._refs, self._sweep_at = {}, 64

    def get(self, key, default=None):
        ref = self._refs.get(key)
        wrapper = None if ref is None else ref()
        return default if wrapper is None else wrapper

    def __getitem__(self, key):
        wrapper = self.get(key)
        if wrapper is None:
            raise KeyError(key)
        return wrapper

    def __setitem__(self, key, wrapper):
        refs = self._refs
        refs[key] = weakref.ref(wrapper)
        if len(refs) > self._sweep_at:
            for dead in [k for k, ref in refs.items() if ref() is None]:
                del refs[dead]
            self._sweep_at = max(64, 2 * len(refs))

    def __delitem__(self, key):
        del self._refs[key]

    def pop(self, key, default=None):
        ref = self._refs.pop(key, None)
        wrapper = None if ref is None else ref()
        return default if wrapper is None else wrapper

    def items(self):
        return [(key, wrapper) for key, ref in list(self._refs.items())
                if (wrapper := ref()) is not None]

    def keys(self):
        return [key for key, _ in self.items()]

    def values(self):
        return [wrapper for _, wrapper in self.items()]

    def __contains__(self, key):
        return self.get(key) is not None

    def __iter__(self):
        return iter(self.keys())

    def __len__(self):
        return len(self.items())


def _registry(root):
    key = int(ffi.cast(_UINTPTR, root))
    registry = _REGISTRIES.get(key)
    if registry is None:
        registry = _REGISTRIES[key] = Registry()
    return registry


def wrap(pointer, owner):
    """The one wrapper of the element `pointer` points to (an mjs* struct or its
    mjsElement), of its class (MjsGeom for a geom), keeping `owner`'s spec alive;
    None for NULL."""
    if pointer == NULL:
        return None
    root = getattr(owner, "_root", owner)
    ctype = ffi.typeof(pointer)
    if ctype is _ELEMENT:
        element = pointer
        kind = _BY_TYPE.get(element.elemtype)
        if kind is None:
            raise ValueError(f"no element wrapper for element type {element.elemtype}")
        cls = _BY_KIND[kind]
    else:
        element = pointer.element
        cls = _CLASSES.get(ctype) or _class_of(ctype)
    registry = _registry(root)
    key = int(ffi.cast(_UINTPTR, element))
    found = registry.get(key)
    if found is not None and type(found) is cls:
        return found
    if ctype is _ELEMENT:
        pointer = _as_kind(kind)(element)
    # Struct._wrap without its general steps: element classes have no eager fields
    # and no capacities (add_* makes one wrapper per call, so this is hot)
    made = cls.__new__(cls)
    made.__dict__.update(_ptr=pointer, _root=root)
    registry[key] = made
    return made


_CASTS: dict = {}          # 'Geom' -> mjs_asGeom


def _as_kind(kind):
    cast = _CASTS.get(kind)
    if cast is None:
        cast = _CASTS[kind] = getattr(lib, "mjs_as" + kind)
    return cast


_CLASSES: dict = {}        # cffi type `mjs* *` -> its element class (see `register`)
_BY_KIND: dict = {}        # 'Geom' -> MjsGeom


def register(*classes):
    """Record the element classes (mjspec.py calls this once, and the hand-written
    subclasses again), so that a pointer of any element finds its class."""
    for cls in classes:
        _CLASSES[ffi.typeof(ffi.getctype(cls._ctype, "*"))] = cls
        _BY_KIND[cls.__name__[3:]] = cls
        # a view keeps its wrapper alive, so `held_views` sees every view in use
        cls._views_hold_wrapper = True


def _class_of(ctype):
    """The element class of a `mjs* *` cffi type."""
    cls = _CLASSES.get(ctype)
    if cls is None:
        raise TypeError(f"{ctype.cname} is no spec element")
    return cls


def registered(owner):
    """The live wrappers of `owner`'s spec."""
    return list(_registry(getattr(owner, "_root", owner)).values())


class DeletedElement(Struct):
    """What the wrapper of a freed element becomes (and those of the structs in it,
    such as its `alt`), as a subclass of its own class (`_deleted_class`).

    Where its values were taken before MuJoCo freed it (`take`, `prepare_delete`),
    they read as they were, as the official's deleted elements do (`body.name`;
    arrays as read-only copies, nested structs as deleted wrappers themselves), and
    `parent` and `frame` read None.  Anything else, and any write (it would be
    lost), raises DeletedElementError."""

    def __getattribute__(self, name):
        if name.startswith("__") or name in ("_deleted", "_taken"):
            return object.__getattribute__(self, name)
        taken = object.__getattribute__(self, "__dict__").get("_taken")
        if taken is not None and name in taken:
            value = taken[name]
            return list(value) if type(value) is list else value
        raise DeletedElementError(f"{object.__getattribute__(self, '_deleted')} was deleted "
                                  f"from its spec: its wrapper cannot be used")

    def __setattr__(self, name, value):
        raise DeletedElementError(f"{self.__dict__['_deleted']} was deleted from its spec: "
                                  f"its {name} cannot be written")

    def __repr__(self):
        return f"<{self._deleted} (deleted)>"

    def __eq__(self, other):
        return self is other

    __hash__ = object.__hash__


_DELETED: dict = {}          # class -> its DeletedElement subclass


def _deleted_class(cls):
    """The class a wrapper of `cls` becomes when its element is freed: still an
    instance of `cls` (isinstance, the kind a function dispatches on), with
    DeletedElement's behaviour."""
    if issubclass(cls, DeletedElement):
        return cls
    dead = _DELETED.get(cls)
    if dead is None:
        dead = _DELETED[cls] = type(cls.__name__, (DeletedElement, cls),
                                    {"__module__": cls.__module__, "__slots__": ()})
    return dead


def _label(wrapper, taken=None):
    """'MjsGeom' and its name, for messages: "MjsGeom 'arm'"."""
    label = type(wrapper).__name__
    if taken is not None:
        name = taken.get("name", "")
    else:
        try:
            name = wrapper.name
        except (AttributeError, DeletedElementError):
            name = ""
    return f"{label} {name!r}" if isinstance(name, str) and name else label


def _members(wrapper):
    """(attribute, value) of what the wrapper keeps of the struct's own memory: the
    views of its fixed arrays and the wrappers of its nested structs and members."""
    state = wrapper.__dict__
    for attr in type(wrapper)._fields:
        value = state.get(attr)
        if value is not None:
            yield attr, value


def _value(value):
    """A value read from a struct, as a deleted wrapper keeps it: arrays as read-only
    copies, vectors and char arrays as arrays and lists."""
    if isinstance(value, (np.ndarray, _NumberVector)):
        value = np.array(value)
        value.flags.writeable = False
        return value
    if isinstance(value, (MjCharVec, MjStringVec)):
        return list(value)
    return value


def take(wrapper):
    """The values of `wrapper`'s fields (and name), read now, for the deleted wrapper
    it becomes once MuJoCo has freed its element (see DeletedElement).  Nested
    structs and members are taken too, into their wrappers' own."""
    if isinstance(wrapper, DeletedElement):
        return wrapper.__dict__.get("_taken")
    taken = {}
    cls = type(wrapper)
    for attr in cls._fields + ("name",):
        if not hasattr(cls, attr):
            continue
        try:
            value = getattr(wrapper, attr)
        except (AttributeError, TypeError, ValueError):
            continue
        if isinstance(value, Struct):
            value.__dict__["_taking"] = take(value)
        taken[attr] = _value(value)
    for attr in ("parent", "frame"):
        if hasattr(cls, attr):
            taken[attr] = None            # a deleted element is in no body or frame
    return taken


def _end(wrapper, label, taken=None):
    if isinstance(wrapper, DeletedElement):
        return
    members = [(member, f"{label}.{attr}") for attr, member in _members(wrapper)
               if isinstance(member, Struct)]
    if taken is not None:
        members += [(member, f"{label}.{attr}") for attr, member in taken.items()
                    if isinstance(member, Struct)]
    state = wrapper.__dict__
    nested = state.get("_taking")
    state.clear()
    state["_deleted"] = label
    if nested is not None or taken is not None:
        state["_taken"] = taken if taken is not None else nested
    wrapper.__class__ = _deleted_class(type(wrapper))
    for member, member_label in members:
        _end(member, member_label, member.__dict__.get("_taking"))


def _forget(wrapper):
    """Take `wrapper` out of every registry (before it is ended)."""
    key = _address(wrapper._ptr.element)
    for registry in _REGISTRIES.values():
        if registry.get(key) is wrapper:
            del registry[key]


def invalidate(elements):
    """End the wrappers of `elements` (wrappers, or mjs* / mjsElement pointers) before
    MuJoCo frees them: their values are taken first (see DeletedElement), and
    their names go into the error their later use raises."""
    for item in elements:
        if isinstance(item, DeletedElement):
            continue
        if isinstance(item, Struct):
            wrapper = item
        else:
            element = item if ffi.typeof(item) is ffi.typeof("mjsElement *") else item.element
            wrapper = None
            for registry in _REGISTRIES.values():
                wrapper = registry.get(_address(element))
                if wrapper is not None:
                    break
            if wrapper is None:
                continue
        taken = take(wrapper)
        _forget(wrapper)
        _end(wrapper, _label(wrapper, taken), taken)


def invalidate_missing(owner, alive, taken=None):
    """After MuJoCo freed elements (delete of a subtree, fuse_static): end every
    wrapper of `owner`'s spec whose element address is not in `alive`.  `taken`
    (from `prepare_delete`, before the free) gives the values they keep."""
    registry = _registry(getattr(owner, "_root", owner))
    taken = taken or {}
    for key, wrapper in list(registry.items()):
        if key not in alive:
            del registry[key]
            values = taken.get(key)
            label = _label(wrapper, values) if values is not None else \
                f"a {type(wrapper).__name__}"
            _end(wrapper, label, values)
    for key, values in taken.items():
        if key in alive:              # taken in case, and kept: forget what was read
            for value in values.values():
                if isinstance(value, Struct):
                    _drop_taking(value)


def _drop_taking(struct):
    taking = struct.__dict__.pop("_taking", None)
    for value in (taking or {}).values():
        if isinstance(value, Struct):
            _drop_taking(value)


# ----------------------------------------------------- views of freed memory

def _references(state, attr):
    """The reference counts of the view state[attr] and of its base, as seen here."""
    array = state[attr]
    base = array.base
    return sys.getrefcount(array), sys.getrefcount(base) if base is not None else 0


_ALONE: list = []            # _references of a view that nothing else holds


def _alone():
    """Calibrate `_references` on a view made as the wrappers make theirs, held by
    nothing but a dict, in this interpreter."""
    if not _ALONE:
        memory = ffi.new("double[3]")
        _ALONE.extend(_references({"v": view(memory, np.dtype(np.float64), (3,), memory)},
                                  "v"))
    return _ALONE


def _held(struct, label, found):
    """Add to `found` the held views of `struct` and of the structs in it.  No local
    name here refers to a view: the counts are compared with `_alone`'s."""
    state = struct.__dict__
    for attr in type(struct)._fields:
        kind = type(state.get(attr))
        if kind is np.ndarray:
            if any(n > alone for n, alone in zip(_references(state, attr), _alone())):
                found.append(f"{label}.{attr}")
        elif issubclass(kind, Struct) and not issubclass(kind, DeletedElement):
            _held(state[attr], f"{label}.{attr}", found)
    return found


def held_views(wrappers):
    """The fixed-array views of `wrappers`' memory that something outside the wrappers
    still holds (the view itself, or any array made from it: a slice, a reshape),
    as "MjsGeom 'g'.size"; the nested structs' views too ("MjsBody 'b'.alt.euler")."""
    found = []
    for wrapper in wrappers:
        if not isinstance(wrapper, DeletedElement):
            _held(wrapper, _label(wrapper), found)
    return found


def check_releasable(wrappers, action):
    """Raise ValueError, before MuJoCo frees the elements of `wrappers` (see `doomed`),
    if a NumPy view of their memory is still held: it would read and write freed
    memory.  `action` says what was refused ("delete MjsBody 'arm'")."""
    held = held_views(wrappers)
    if held:
        raise ValueError(f"cannot {action}: NumPy arrays still view the memory it would "
                         f"free ({', '.join(held)}); drop them (del), or keep a copy "
                         f"(arr.copy()), and try again")


# What MuJoCo may free besides a body's subtree when it deletes the body (or a frame,
# which deletes the bodies in it): every keyframe, and the pairs, excludes,
# tendons (with their wraps), equalities, actuators and sensors that refer to
# anything in it, and the plugins only they used.  Deleting a geom, mesh, actuator
# or sensor frees the plugin instance it alone used.
_WITH_BODY = ("Key", "Pair", "Exclude", "Tendon", "Wrap", "Equality", "Actuator", "Sensor",
              "Plugin")
_WITH_OWNER = ("Plugin",)


def doomed(owner, element):
    """The wrappers of `owner`'s spec whose elements MuJoCo may free with `element` (a
    wrapper): itself; for a body or a frame, every registered wrapper of the
    elements below it (placed in it, or in a body or frame below it) and of the
    kinds `_WITH_BODY` (which it frees where they refer to the subtree: taken all,
    to be safe); for a geom, mesh, actuator or sensor, the plugins."""
    target = _address(element._ptr.element)
    kind = type(element)._cname[3:]
    extra = _WITH_BODY if kind in ("Body", "Frame") else \
        _WITH_OWNER if kind in ("Geom", "Mesh", "Actuator", "Sensor") else ()
    extra = tuple(_BY_KIND[k]._cname for k in extra if k in _BY_KIND)
    found = [element]
    for wrapper in registered(owner):
        if wrapper is element or isinstance(wrapper, DeletedElement):
            continue
        if type(wrapper)._cname in extra or kind in ("Body", "Frame") and \
                target in _ancestors(wrapper._ptr.element):
            found.append(wrapper)
    return found


def _ancestors(element):
    """Addresses of the bodies and frames that hold `element`, up to the world."""
    seen, stack = set(), [element]
    while stack:
        item = stack.pop()
        for up in (lib.mjcffi_guard_mjs_getParent(item), lib.mjcffi_guard_mjs_getFrame(item)):
            _marshal.check_error()
            if up != NULL and up.element != NULL:
                key = _address(up.element)
                if key not in seen:
                    seen.add(key)
                    stack.append(up.element)
    return seen


def prepare_delete(owner, element, action=None):
    """Before mjs_delete(`element`): refuse (ValueError, see `check_releasable`) while
    a NumPy view of memory it may free is held, and take the values of the
    wrappers it may free; give them to `invalidate_missing` after the delete, so
    that those freed keep them (`body.name` of a deleted body, as the official):

        taken = prepare_delete(spec, body)
        mjs_delete(...)
        invalidate_missing(spec, live_addresses, taken)
    """
    wrappers = doomed(owner, element)
    check_releasable(wrappers, action or f"delete {_label(element)}")
    return {_address(w._ptr.element): take(w) for w in wrappers}


# ----------------------------------------------------------------------- add_*

# the keywords that set an alternative orientation (the official's): for `alt`,
# and `ialt` (a body's inertial frame) with an 'i' in front
_ORIENTATIONS = {"axisangle": "mjORIENTATION_AXISANGLE", "xyaxes": "mjORIENTATION_XYAXES",
                 "zaxis": "mjORIENTATION_ZAXIS", "euler": "mjORIENTATION_EULER"}
_ORIENTATION_SIZES = {"axisangle": 4, "xyaxes": 6, "zaxis": 3, "euler": 3}

# fixed arrays whose keyword takes 1 to all of their numbers, the rest left 0, or a
# number (the official's: geom size=[r] for a sphere, damping=d of a joint)
_PADDED = {("mjsGeom", "size"), ("mjsSite", "size"), ("mjsFlex", "size"),
           ("mjsJoint", "damping"), ("mjsJoint", "stiffness"), ("mjsTendon", "damping"),
           ("mjsTendon", "stiffness"), ("mjsActuator", "damping")}

# add_* that take only some of their element's attributes (the official's)
_ONLY = {"mjs_addFreeJoint": ("align", "group", "name")}


def _keywords(cls):
    """The keywords add_* takes for an element of `cls`: its attributes, and the
    orientation keywords of its `alt` and `ialt`."""
    valid = set(cls._fields) - {"element"} | {"name"}
    for field, prefix in (("alt", ""), ("ialt", "i")):
        if field in cls._fields:
            valid |= {prefix + key for key in _ORIENTATIONS}
    return valid


def _orientations(cls, attrs):
    """Take the orientation keywords out of `attrs`: [(field, type, key, numbers)]."""
    found = []
    for field, prefix in (("alt", ""), ("ialt", "i")):
        given = [key for key in _ORIENTATIONS if prefix + key in attrs]
        if len(given) > 1:
            names = [prefix + key for key in _ORIENTATIONS]
            raise ValueError(f"Only one of: {', '.join(names[:-1])}, or {names[-1]} "
                             f"can be set.")
        for key in given:
            value = attrs.pop(prefix + key)
            found.append((field, getattr(lib, _ORIENTATIONS[key]), key,
                           _sized(cls, prefix + key, value, _ORIENTATION_SIZES[key])))
    return found


def _sized(cls, key, value, length, padded=False, scalable=False):
    """A fixed array's keyword, by the official's rules: `length` numbers; 1 to
    `length` if `padded` (zeros after), or a number; a number if `scalable`."""
    if isinstance(value, (int, float, np.number)) and not isinstance(value, bool):
        if padded:
            return [value] + [0] * (length - 1)
        if scalable:
            return [value] * length
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
        raise TypeError(f"{cls.__name__}.{key} takes a list/array of size {length}, "
                        f"not {type(value).__name__}")
    size = len(value)
    if padded:
        if not 1 <= size <= length:
            raise ValueError(f"{key} should be a list/array of size 1 to {length}.")
        return list(value) + [0] * (length - size)
    if size != length:
        scalar = "a scalar or " if scalable else ""
        raise ValueError(f"{key} should be {scalar}a list/array of size {length}.")
    return value


def _keyword_rule(cls, key):
    """How a keyword's value is converted by the official's keyword rules: a fixed
    array's ("array", length, padded, scalable) (see `_sized`), a char array's
    ("chars", size) (see `_char_keyword`), or None: taken as the attribute takes it."""
    field = getattr(cls, key, None)
    length = _array_length(field)
    if length is not None:
        return ("array", length, (cls._cname, key) in _PADDED, (cls._cname, key) in _SCALABLE)
    size = getattr(field, "fget", None) and getattr(field.fget, "char_size", None)
    if size is not None:
        return ("chars", size)
    return None


_PLANS: dict = {}          # class -> (its keywords, its orientation keywords)


def _plan(cls):
    plan = _PLANS.get(cls)
    if plan is None:
        valid = frozenset(_keywords(cls))
        orientation = frozenset(prefix + key for prefix in ("", "i")
                                for key in _ORIENTATIONS) & valid
        plan = _PLANS[cls] = (valid, orientation)
    return plan


_KEYWORD_SETTERS: dict = {}   # class -> {keyword: set(element, value) by keyword rules}


def _keyword_setters(cls):
    """The keyword setters of `cls`'s attributes (the orientation keywords aside):
    each converts by `_keyword_rule` and sets as the attribute does, in one call."""
    table = _KEYWORD_SETTERS.get(cls)
    if table is None:
        setters = _setters(cls)
        table = _KEYWORD_SETTERS[cls] = {
            key: _keyword_setter(cls, key, setters.get(key)) for key in _plan(cls)[0]}
    return table


def _keyword_setter(cls, key, setter):
    rule = _keyword_rule(cls, key)
    if setter is None:
        def setter(element, value):
            setattr(element, key, value)
    if rule is None:
        return setter
    if rule[0] == "array":
        length = rule[1]

        def set_array(element, value):
            if value.__class__ in _SEQUENCES and len(value) == length:
                try:
                    setattr(element._ptr, key, value)     # the common case, through cffi
                    return
                except (TypeError, OverflowError):
                    pass
            setter(element, _sized(cls, key, value, *rule[1:]))
        return set_array

    def set_chars(element, value):
        setter(element, _char_keyword(cls, key, rule[1], value))
    return set_chars


def configure(element, attrs, valid=None):
    """Set `attrs` on a new element, naming the attribute in any error; `valid` limits
    the keywords taken (all of the element's attributes, and the orientation
    keywords euler=, axisangle=, xyaxes=, zaxis= and their i* forms)."""
    cls = type(element)
    known, orientation_keys = _plan(cls)
    allowed = known if valid is None else valid
    for key in attrs:
        if key not in allowed:
            raise TypeError(f"Invalid {key} keyword argument. Valid options are: "
                            f"{', '.join(sorted(allowed))}.")
    orientations = ()
    if not orientation_keys.isdisjoint(attrs):
        attrs = dict(attrs)
        orientations = _orientations(cls, attrs)
    setters = _KEYWORD_SETTERS.get(cls) or _keyword_setters(cls)
    for key, value in attrs.items():
        try:
            setters[key](element, value)
        except (TypeError, ValueError) as exc:
            text = str(exc)
            if key not in text:
                text = f"{cls.__name__}.{key}: {text}"
            raise type(exc)(text) from None
    for field, kind, key, value in orientations:
        alt = getattr(element, field)
        alt.type = kind
        setattr(alt, key, value)
    return element


def _discard(element):
    """Delete a new element whose keywords were refused: only its wrapper knows it."""
    pointer = element._ptr.element
    invalidate([element])
    lib.mjcffi_guard_mjs_delete(lib.mjs_getSpec(pointer), pointer)


def _argument(value, kind, name):
    """The C value of one argument of an mjs_add* / mjs_wrap* function after the first:
    `kind` is 'text', 'double' or the mjs* struct it points to (None: NULL)."""
    if kind == "text":
        return _marshal.text(value, name)
    if kind == "double":
        try:
            return float(value)
        except (TypeError, ValueError):
            raise TypeError(f"{name} takes a number, not {type(value).__name__}") from None
    return _marshal.opt_struct(value, kind, name)


def adder(function, result, params, doc):
    """A method over the mjs_add* / mjs_wrap* function `function` giving a `result()`:
    `params` are (name, kind) of its arguments after the first, kind 'default' for the
    mjsDefault that `default=` gives; the others are taken by position or name (a
    struct may be left out: NULL).  Other keywords set the new element's attributes
    (see `configure`)."""
    guard = getattr(lib, "mjcffi_guard_" + function)
    named = [(n, k) for n, k in params if k != "default"]
    takes_default = len(named) < len(params)
    default_at = [k for _, k in params].index("default") if takes_default else None
    only = _ONLY.get(function)

    plain = (NULL,) if takes_default else ()    # the C arguments of add_*() alone

    def add(self, *args, default=None, **attrs):
        if args or named or default is not None:
            c_args = arguments(args, default, attrs)
        else:
            c_args = plain
        pointer = guard(self._ptr, *c_args)
        _marshal.check_error()
        element = wrap(pointer, self)
        if attrs:
            try:
                configure(element, attrs, only)
            except BaseException:
                _discard(element)       # no half-set element left in the spec
                raise
        return element

    def arguments(args, default, attrs):
        """The C arguments after the parent; takes its own keywords out of `attrs`."""
        if takes_default and len(args) > len(named):     # the official's first: default
            if default is not None:
                raise TypeError(f"{function[4:]} got two default classes")
            default, args = args[0], args[1:]
        elif default is not None and not takes_default and not args and named and \
                named[0][1].startswith("mjs") and named[0][0] not in attrs:
            default, args = None, (default,)        # the official's add_frame(default=frame)
        if len(args) > len(named):
            raise TypeError(f"{function[4:]} takes {len(named)} positional arguments, "
                            f"not {len(args)}")
        if default is not None and not takes_default:
            raise TypeError(f"{function} takes no default class")
        values = list(args)
        for name, kind in named[len(args):]:
            if name in attrs and (kind in ("text", "double") or name not in result()._fields):
                values.append(attrs.pop(name))
            elif kind in ("text", "double"):
                raise TypeError(f"{function[4:]} needs its argument {name!r}")
            else:
                values.append(None)
        c_args = [_argument(v, k, n) for v, (n, k) in zip(values, named)]
        if takes_default:
            c_args.insert(default_at, NULL if default is None else
                          _marshal.opt_struct(default, "mjsDefault", "default"))
        return c_args
    add.__doc__ = doc
    add.__name__ = function
    return add


def frame_adder(function, result, params, doc):
    """A method of MjsFrame over the body's `function` (mjs_addGeom): the element is
    added to the frame's body and placed in the frame (mjs_setFrame); add_frame
    makes a child frame.  Arguments as for `adder`."""
    add_to_body = adder(function, result, params, doc)
    nested = function == "mjs_addFrame"

    def add(self, *args, default=None, **attrs):
        body = wrap(lib.mjs_getParent(self._ptr.element), self)
        if nested:
            return add_to_body(body, *(args or (self,)), default=default, **attrs)
        element = add_to_body(body, *args, default=default, **attrs)
        failed = lib.mjcffi_guard_mjs_setFrame(element._ptr.element, self._ptr)
        try:
            _marshal.check_error()
            if failed:
                raise ValueError(f"{function[4:]}: MuJoCo refused the frame")
        except BaseException:
            _discard(element)
            raise
        return element
    add.__doc__ = f"{doc} (in this frame)"
    add.__name__ = function
    return add
