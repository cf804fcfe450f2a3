"""The attributes of spec elements, kind by kind: what codegen/structs.py builds the
fields of the generated mjcffi/structs/mjspec.py with (hand-written support of it,
as _handles.py and _checks.py are).

- `string_field`: an mjString as str (mjs_getString / mjs_setString);
- `element_name`: the element's name (mjs_getName / mjs_setName; a name MuJoCo
  refuses raises ValueError with MuJoCo's own message);
- `char_array`: a fixed char array (compiler.eulerseq, texture.gridlayout) as an
  MjCharVec, a sequence of 1-character str read and written in place;
- `enum_field`: an mjt* field as its IntEnum, taking any int;
- `member_ref`: a pointer to a struct the element owns (its mjsElement, a
  default's geom): one wrapper, kept on the element's;
- `element_setattr`: `__setattr__` of the spec structs: a fixed array takes a
  sequence of exactly its length, flat or as a column (as the official), quickly.

The std::vector fields are _element_vectors.py's (`vector_field`, which checks its
values with `_where`, `_text`, `_made` and `_cast` from here), the add_* methods
_element_adders.py's, and the one wrapper of each element _elements.py's.
"""

import numbers
import operator

import numpy as np

from . import errors as _errors, marshal as _marshal, spec_claims as _claims
from .library import ffi, lib
from .views import FixedArray, Nested, Struct, _scalar_error
from .elements import _BY_KIND

NULL = ffi.NULL


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
    _claims.check(self, b"reading a spec string")
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
        _claims.check(self, b"writing a spec string")
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
        if self.__dict__.get("_in_default"):
            # MuJoCo would look for the spec, which a default's template has not
            raise TypeError(f"{_where(self, 'name')}: a default class's template has no "
                            f"name of its own; name the class (spec.add_default(name))")
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
    raise _errors.taken_error(message)


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

    def _frozen(self):
        """What the deleted wrapper of its element keeps (_elements.take): a list."""
        return list(self)

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
    get.char_size = size                    # for _element_adders._keyword_rule
    return property(get, set_value, doc=doc)


# --------------------------------------------------------------------- enums

def enum_field(name, enum, doc):
    """An mjt* field as its IntEnum (an int for a value that is no member, such as a
    bitmask); it takes any int."""
    members = None

    def get(self):
        nonlocal members
        if members is None:
            from .._generated import enums as _enums
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
        if obj._cname == "mjsDefault":
            # a template (see element_name); it keeps its default's wrapper alive, so
            # that deleting the default ends the template with it (_elements._end)
            value.__dict__.update(_in_default=True, _owner=obj)
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
    """`value` as `length` numbers of `dtype`, by the official's rules: a sequence or
    array of shape (length,) or a column (length, 1) (the official's setters take an
    Eigen vector: body.fullinertia = np.full((6, 1), np.nan)), nested lists too; a
    scalar where `scalable`.  Anything else raises ArgumentError (a TypeError, as the
    official's setters raise, and a ValueError, as its scalable ones raise).

    Stricter than the official on values, where it would change them: numbers only
    (it parses strings, takes None as NaN and drops imaginary parts), and for int
    fields whole numbers in range (`_cast`; it truncates 1.5 and stores NaN as
    INT_MIN)."""
    where = _where(self, name)
    wanted = f"a scalar or a list/array of size {length}" if scalable else \
        f"a list/array of size {length}"
    shapes = f"shape ({length},) or ({length}, 1)"
    if isinstance(value, (str, bytes)):
        raise _errors.ArgumentError(f"{where} takes {wanted}, not {type(value).__name__}")
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as exc:          # ragged nesting, a failing __array__
        raise _errors.ArgumentError(f"{where} takes {wanted} ({shapes}): {exc}") from None
    if array.dtype.kind == "O":
        array = _real_numbers(array)
    if array.dtype.kind not in "biuf":
        raise _errors.ArgumentError(f"{where} takes real numbers, not {_items(array)}")
    if array.ndim == 0 and scalable:
        array = np.full(length, array)
    if array.shape == (length, 1):
        array = array.reshape(length)
    if array.shape != (length,):
        got = "a scalar" if array.ndim == 0 else f"shape {array.shape}"
        raise _errors.ArgumentError(f"{where} takes {wanted} ({shapes}), not {got}")
    return _cast(self, name, array, dtype)


def _real_numbers(array):
    """An object array (np.array([1, 2.5], dtype=object), a list of Fractions) as
    float64 where every item is a real number; else unchanged, for the caller to refuse."""
    items = array.ravel().tolist()
    if items and all(isinstance(item, (numbers.Real, np.bool_)) for item in items):
        return array.astype(np.float64)
    return array


def _items(array):
    """What the items of a refused array are, for a message: 'str', 'NoneType', ..."""
    if array.dtype.kind != "O":
        return {"U": "str", "S": "bytes", "c": "complex"}.get(array.dtype.kind,
                                                               str(array.dtype))
    kinds = sorted({type(item).__name__ for item in array.ravel().tolist()
                    if not isinstance(item, (numbers.Real, np.bool_))})
    return ", ".join(kinds) or "object"


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
