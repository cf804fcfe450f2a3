"""Zero-copy NumPy views of MuJoCo memory, and the pieces the generated struct
classes (mjcffi/structs/) are made of.

A support module: it imports the compiled modules (the cffi one, and
_descriptors: the C field descriptors), _errors and NumPy.
Every view keeps the memory it shows alive by referencing the *root* cdata
(the gc-owned `mjData *`, `mjModel *` or `ffi.new` struct), never a Python
wrapper, so a view cached on a wrapper makes no cycle (see `view`).
"""

import functools
import keyword
import operator
import types
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from .._descriptors import Field, Holder
from . import official as _official
from .errors import ArgumentError, check, raise_pending, with_note
from .library import ffi

# C element type (MuJoCo's name or cffi's resolved one) -> NumPy dtype.
_TYPES = {
    "mjtNum": np.float64, "double": np.float64, "float": np.float32,
    "int": np.int32, "unsigned int": np.uint32, "mjtSize": np.int64, "int64_t": np.int64,
    "size_t": np.uintp, "uintptr_t": np.uintp, "uint64_t": np.uint64,
    "mjtByte": np.uint8, "unsigned char": np.uint8, "char": np.int8,
    "mjtBool": np.bool_, "_Bool": np.bool_,
}
DTYPES = {name: np.dtype(t) for name, t in _TYPES.items()}

# the NumPy type of mjtNum, under the official bindings' names
MJTNUM_DTYPE = np.float64
MJTNUM_BYTES = DTYPES["mjtNum"].itemsize


class _KeepAlive:
    """A no-op destructor whose only job is to reference the root."""
    __slots__ = ("root",)

    def __init__(self, root):
        self.root = root

    def __call__(self, pointer):
        pass


def view(pointer, dtype, shape, root, fill=0):
    """A writable view of `shape` elements of `dtype` at `pointer` (a C pointer).

    The view's base is a cffi buffer, which keeps its pointer cdata alive; that
    cdata is an `ffi.gc` copy whose destructor references `root`.  So the view
    keeps the memory's owner alive, at half the cost of an array-interface
    holder.  Memory not allocated (NULL) reads as a new array of `fill`, as in
    the official bindings (-1 for index arrays whose "none" is -1).
    """
    if pointer == ffi.NULL or 0 in shape:
        return np.full(shape, fill, dtype) if fill else np.zeros(shape, dtype)
    count = shape[0]
    for n in shape[1:]:
        count *= n
    flat = np.frombuffer(ffi.buffer(ffi.gc(pointer, _KeepAlive(root)), count * dtype.itemsize),
                         dtype)
    return flat if len(shape) == 1 else flat.reshape(shape)


def record_view(pointer, dtype, count, root):
    """A view of `count` structs as a structured array (see record_dtype).

    Through a buffer, as `view`: the array interface cannot describe the
    overlapping fields of an anonymous union (mjuiItem)."""
    return view(pointer, dtype, (count,), root)


# ------------------------------------------------------------ struct records

_RECORD_DTYPES: dict = {}


def _field_dtype(ctype):
    if ctype.kind == "primitive":
        return DTYPES.get(ctype.cname) or np.dtype(f"V{ffi.sizeof(ctype)}")
    if ctype.kind == "array":
        return np.dtype((_field_dtype(ctype.item), (ctype.length,)))
    if ctype.kind == "struct":
        return record_dtype(ctype)
    if ctype.kind == "enum":
        return np.dtype(np.int32)
    return np.dtype(np.uintp)          # pointers and function pointers: addresses


def record_dtype(ctype):
    """The NumPy structured dtype with the C layout of a struct type."""
    ctype = ffi.typeof(ctype) if isinstance(ctype, str) else ctype
    cached = _RECORD_DTYPES.get(ctype)
    if cached is None:
        names, formats, offsets = [], [], []
        for name, field in ctype.fields:
            if not name:
                continue
            names.append(name)
            formats.append(_field_dtype(field.type))
            offsets.append(field.offset)
        cached = np.dtype({"names": names, "formats": formats, "offsets": offsets,
                           "itemsize": ffi.sizeof(ctype)})
        _RECORD_DTYPES[ctype] = cached
    return cached


# -------------------------------------------------------------------- fields
#
# Fields whose value never moves (model-sized arrays, fixed arrays, nested
# structs) are built on first read and cached in the instance __dict__: they
# are non-data descriptors, so later reads find the cached value first.  The
# few fields read every step (mjData.qpos, ...) are built when the struct is
# wrapped instead and have no class attribute at all: CPython 3.11 reads an
# instance attribute some 10 ns faster when no class attribute shadows it.
# Fields that move are cached too, and checked on every read (see DynamicArray).

class _Cached:
    """Base of the cached fields: build once, then store on the instance."""

    def __get__(self, obj, cls=None):
        if obj is None:
            return self
        value = obj.__dict__[self.attr] = self.build(obj)
        return value

    @property
    def attr(self):
        """The Python attribute name: C keywords get a trailing '_' (vis.global_)."""
        return _attr(self.name)


def _attr(name):
    return name + "_" if keyword.iskeyword(name) else name


def _dtype(elem):
    """A C element type's dtype; 'S40' (a row of char[35][40]) is a bytes string."""
    return DTYPES.get(elem) or np.dtype(elem)


class Array(_Cached):
    """An array field: a zero-copy view of the memory it points to.

    `fill` is what unallocated (NULL) memory reads as: -1 for the index arrays
    whose header says "-1: none", else 0.
    """

    def __init__(self, name, elem, shape, doc="", fill=0):
        self.name, self.dtype, self.shape, self.__doc__ = name, _dtype(elem), shape, doc
        self.fill = fill

    def build(self, obj):
        return view(getattr(obj._ptr, self.name), self.dtype, self.shape(obj), obj._root,
                    self.fill)


class FixedArray(Array):
    """An array embedded in the struct itself, such as mjOption.gravity[3]."""

    def build(self, obj):
        return view(ffi.addressof(obj._ptr, self.name), self.dtype, self.shape(obj),
                    _keeper(obj))


class Nested(_Cached):
    """A struct embedded in another (mjModel.opt): a wrapper sharing its memory."""

    def __init__(self, name, wrapper, doc=""):
        self.name, self.wrapper, self.__doc__ = name, wrapper, doc

    def build(self, obj):
        inner = self.wrapper()._wrap(ffi.addressof(obj._ptr, self.name), obj._root)
        if obj._views_hold_wrapper or "_keep" in obj.__dict__:
            inner.__dict__["_keep"] = _keeper(obj)
        return inner


def _keeper(obj):
    """What a view of `obj`'s memory keeps alive: its root; for a spec element (and the
    structs nested in one) also the element's wrapper, so that the spec finds the
    views still in use before MuJoCo frees the element (structs/_elements.py)."""
    if obj._views_hold_wrapper:
        return (obj._root, obj)
    return obj.__dict__.get("_keep", obj._root)


class FixedRecords(_Cached):
    """An array of structs embedded in the struct (mjData.warning) as a StructArray."""

    def __init__(self, name, wrapper, count, doc=""):
        self.name, self.wrapper, self.count, self.__doc__ = name, wrapper, count, doc

    def build(self, obj):
        cls = self.wrapper()
        pointer = ffi.cast(ffi.getctype(cls._ctype, "*"), ffi.addressof(obj._ptr, self.name))
        return StructArray(cls, pointer, self.count, obj._root)


def eager(*fields):
    """The `_eager` table of a class: fields built as soon as it is wrapped."""
    return {field.attr: field for field in fields}


# ---------------------------------------------------------------- moving memory
#
# Arrays whose size or address changes (mjData's contacts and efc_* arrays, which
# live in its arena; a scene's geoms) are cached with the words of their struct
# that define them: the pointer, and the counts that size it.  A read compares
# those words with a copy taken when the view was made: for a DynamicArray in
# Field's C get (mjcffi/_c/descriptors.c, a few ns), for a LiveStructArray as a
# memoryview over the struct (20 ns); making a view costs a microsecond.  A view
# is made again only when they differ, and then never handed out again.

_WORD = np.dtype(f"i{ffi.sizeof('void *')}")


def _words(obj):
    """The memory of struct wrapper `obj` as pointer-sized ints, made once (and again
    when the struct moves: Struct._moved).  It references obj._ptr."""
    words = obj.__dict__.get("_words")
    if words is None:
        size = ffi.sizeof(obj._ctype) // _WORD.itemsize * _WORD.itemsize
        words = obj.__dict__["_words"] = np.frombuffer(ffi.buffer(obj._ptr, size), _WORD)
    return words


class _One(int):
    """1 as a count that a shape function reads from a _Probe; [1] as the ints that
    a pointer to counts points to (see total)."""

    def __new__(cls):
        return super().__new__(cls, 1)

    def __getitem__(self, index):
        return [1]


class _Reads:
    """Stands for a struct pointer (s._ptr): appends the fields read to `seen`."""

    def __init__(self, seen):
        self._seen = seen

    def __getattr__(self, name):
        self._seen.append(name)
        return _One()


class _Probe:
    """Stands for a wrapper `s` in a shape or count function: what it reads of its
    own struct (s._ptr) goes to `seen`; of its model (s._model._ptr), nowhere."""

    def __init__(self, seen):
        self._ptr = _Reads(seen)
        self._model = _Probe.__new__(_Probe)
        self._model._ptr = _Reads([])


def _sizing(function, ctype, field):
    """What defines the array `field` of struct `ctype`, sized by `function` (a shape
    or count function): (the byte offsets of its defining words, the scalars of the
    struct that size it).

    The words are its pointer and those of the scalars: a 4-byte count shares its
    word with a neighbour, whose change then makes a new view too.  The model's
    sizes never change; counts that another array holds (a scene's flexedgenum) are
    not in the key (see AllocatedArray)."""
    seen = []
    function(_Probe(seen))
    fields = _field_table(ctype)           # name -> (type, offset)
    scalars = tuple(n for n in dict.fromkeys(seen) if fields[n][0].kind != "pointer")
    size = _WORD.itemsize
    offsets = sorted({fields[field][1]} | {fields[n][1] // size * size for n in scalars})
    return offsets, scalars


def _key(words, offsets):
    """A memoryview of the words of `words` at the byte `offsets`: those alone when
    they are evenly spaced, else all the words from the first to the last (more
    than needed: a change of any makes a new view)."""
    index = [offset // _WORD.itemsize for offset in offsets]
    step = index[1] - index[0] if len(index) > 1 else 1
    if index != list(range(index[0], index[-1] + 1, step)):
        step = 1
    return memoryview(words[index[0]:index[-1] + 1:step])


def _snapshot(key):
    """A copy of the words `key` as they are now, compared by `key == copy`.  A new
    one each time, never written: a reader in another thread that holds the old
    copy finds it different and makes its own view."""
    return memoryview(key.tobytes()).cast(key.format)


_DYNAMIC: list = []       # every DynamicArray, at its index in the structs' _dyn lists


class DynamicArray(Field, Array):
    """An array whose size or address changes (the efc_* arrays: nefc, the arena).

    Its view is cached in the struct's `_dyn` list (a slot of the C base, Holder),
    with a copy of its key: the words of the struct that define it (see _sizing).
    A read is the C get of Field (mjcffi/_c/descriptors.c): it compares the key's
    words in the struct with the copy, and returns the cached view while they are
    equal; else it calls `_refresh` (the property's getter), which makes the view
    again only when its pointer or shape changed.  Memory not allocated (NULL)
    reads as a new array of `fill` each time, as in the official bindings; an
    empty view is one cached empty array.
    """

    def __init__(self, name, elem, shape, doc="", fill=0):
        Array.__init__(self, name, elem, shape, doc, fill)
        self._index = len(_DYNAMIC)
        _DYNAMIC.append(self)
        self._sizing = None             # set with the key when its class binds it

        def set_value(obj, value):
            assign(self.__get__(obj), value, name)

        property.__init__(self, self._refresh, set_value, None, doc)
        self.__doc__ = doc

    def _refresh(self, obj):
        """The view as of now, made again unless its pointer and shape are unchanged,
        and recorded with a copy of its key taken before they were read."""
        if not isinstance(obj, self._owner):      # another struct: its words mean else
            raise AttributeError(f"{type(obj).__name__} has no field {self.name!r}")
        entries = obj._dyn
        if entries is None or len(entries) < len(_DYNAMIC):
            entries = (entries or []) + [None] * (len(_DYNAMIC) - len(entries or []))
            obj._dyn = entries
        entry, entries[self._index] = entries[self._index], None    # none stale if this raises
        well_formed = type(entry) is tuple and len(entry) == 4
        value, made = (entry[1], entry[3]) if well_formed else (None, None)
        copy = _words(obj)[self._word_index].tobytes()      # before reading what it defines
        pointer, shape = getattr(obj._ptr, self.name), self._shape(obj)
        fresh = pointer == ffi.NULL and 0 not in shape
        if value is None or (pointer, shape) != made:
            if 0 in shape:
                value = np.zeros(shape, self.dtype)
            elif fresh:
                value = np.full(shape, self.fill, self.dtype)
            else:
                value = view(pointer, self.dtype, shape, obj._root)
        entries[self._index] = (copy if self._told(obj) else None, value,
                                value.copy if fresh else False, (pointer, shape))
        return value.copy() if fresh else value

    def _bind(self, cls):
        """Check the key in C for instances of struct class `cls` (see _sizing)."""
        self._owner, self._sizing = cls, _sizing(self.shape, cls._ctype, self.name)
        self._word_index = np.array(self._sizing[0]) // _WORD.itemsize
        self._bind_moving(cls, self._index, tuple(self._sizing[0]), ffi.sizeof(cls._ctype))

    def _shape(self, obj):
        return self.shape(obj)

    def _told(self, obj):
        """Whether the key alone tells that the view is unchanged: always, here."""
        return True

    def build(self, obj):
        """The view as of now."""
        return self.__get__(obj)


class AllocatedArray(DynamicArray):
    """A DynamicArray sized by counts that other arrays hold (a scene's flexedge has
    2*sum(flexedgenum) entries), in memory that mj*_make<Struct> allocated.

    Those counts are writable views, so the size is checked against what was
    allocated, recorded when the struct was wrapped (Struct._remade): a count
    written past it raises ValueError instead of showing memory beyond the block.
    The key holds the number of counts (nflex), not the counts: it tells the size
    only when there are none, and the size is checked on every read otherwise.
    """

    def _shape(self, obj):
        shape = self.shape(obj)
        size = 1
        for n in shape:
            size *= n
        state = obj.__dict__
        if not 0 <= size <= state["_allocated"][self.name]:
            if obj._reallocated():
                return self._shape(obj)
            raise ValueError(f"{type(obj).__name__}.{self.name} would show {size} entries, "
                             f"not within the 0..{state['_allocated'][self.name]} allocated: "
                             f"the counts that size it were written past their allocation")
        return shape

    def _told(self, obj):
        pointer = obj._ptr
        return all(getattr(pointer, name) == 0 for name in self._sizing[1])


class Records:
    """A pointed-to array of structs (mjData.contact: ncon, mjvScene.geoms: maxgeom).

    The LiveStructArray it gives reads the address and the count on each use:
    one taken before a step holds the contacts that the step finds, and one of a
    scene remade by mjv_makeScene its new geoms.  So it is made once, and cached
    in the instance (a non-data descriptor): `d.contact` is a plain attribute.
    Struct.__setattr__ refuses assignment.
    """

    def __init__(self, name, wrapper, count, doc=""):
        self.name, self.wrapper, self.count, self.__doc__ = name, wrapper, count, doc

    def __get__(self, obj, cls=None):
        if obj is None:
            return self
        wrapper = self.wrapper()
        live = obj.__dict__[_attr(self.name)] = \
            _live_class(wrapper)(wrapper, obj, self.name, self.count)
        return live


def assign(target, value, name):
    """Write `value` into the view `target`, naming the field on a bad shape or value.

    A value that does not fit the dtype (NumPy's OverflowError) is a ValueError; a
    complex array into a real view is a TypeError (NumPy would drop the imaginary part)."""
    if getattr(value, "dtype", None) is not None and value.dtype.kind == "c" and \
            target.dtype.kind != "c":
        raise TypeError(f"cannot assign complex values to {name} of dtype {target.dtype}")
    try:
        target[...] = value
    except (ValueError, TypeError, OverflowError) as exc:
        kind = TypeError if isinstance(exc, TypeError) else ValueError
        raise kind(f"cannot assign to {name} of shape {target.shape} and dtype {target.dtype}: "
                   f"{exc}") from None


# ------------------------------------------------------------- struct arrays

_set = object.__setattr__       # a slot of a StructArray, past its __setattr__
_LAYOUTS: dict = {}


def _layout(wrapper):
    """{C field: (dtype, shape, offset, strides)} of the fields of struct class
    `wrapper` that have a view across entries (all but the members of an anonymous
    union): one entry's field has that element dtype, shape and strides, at that
    offset (mjContact.pos: float64, (3,), 8, (8,)).  From record_dtype, once."""
    ctype = wrapper._ctype
    layout = _LAYOUTS.get(ctype)
    if layout is None:
        layout = {}
        for name, (dtype, offset, *_) in record_dtype(ctype).fields.items():
            strides, step = [], dtype.base.itemsize
            for n in reversed(dtype.shape):
                strides.insert(0, step)
                step *= n
            layout[name] = (dtype.base, dtype.shape, offset, tuple(strides))
        _LAYOUTS[ctype] = layout
    return layout


def _entries(pointer, count, step, root, size):
    """The bytes of `count` entries of `size` bytes, `step` entries apart from
    `pointer` on, as a uint8 array from the lowest; it keeps `root` alive."""
    low = min(0, (count - 1) * step)
    span = (abs((count - 1) * step) + 1) * size
    return np.frombuffer(ffi.buffer(ffi.gc(pointer + low, _KeepAlive(root)), span), np.uint8)


def _across(entries, count, step, size, spec):
    """The view of one field (`spec`, see _layout) across `count` entries, `step`
    apart, in `entries` (see _entries); a new empty array when there are none."""
    dtype, shape, offset, strides = spec
    if entries is None:
        return np.zeros((count,) + shape, dtype)
    first = -min(0, (count - 1) * step) * size
    return np.ndarray((count,) + shape, dtype, buffer=entries, offset=first + offset,
                      strides=(step * size,) + strides)


class StructArray(Sequence):
    """A sequence of struct wrappers over C memory, e.g. `d.warning`.

    `arr[i]` is a wrapper sharing memory (a negative i counts from the end),
    `arr[a:b:c]` a StructArray of those entries, and `arr.field` a NumPy view
    of that field across the entries, e.g. `d.contact.dist` of shape (ncon,),
    made on first read and cached.  Two are equal when they hold equal structs in
    the same order.
    """

    __slots__ = ("_wrapper", "_pointer", "_count", "_root", "_step", "_cache")
    __hash__ = None  # type: ignore[assignment]  # equal by value, and mutable

    def __new__(cls, wrapper=None, *args):
        """An instance of the class of `wrapper`'s arrays (_array_class), whose fields
        are properties: no __getattr__, so that CPython reads its slots at full speed."""
        if cls is StructArray and wrapper is not None:
            cls = _array_class(wrapper)
        return object.__new__(cls)

    def __init__(self, wrapper, pointer, count, root, step=1):
        _set(self, "_wrapper", wrapper)
        _set(self, "_pointer", pointer)
        _set(self, "_count", count)
        _set(self, "_root", root)
        _set(self, "_step", step)

    def _span(self):
        """(pointer to entry 0, number of entries, stride in structs), as of now."""
        return self._pointer, self._count, self._step

    def __len__(self):
        return self._span()[1]

    def __getitem__(self, index):
        pointer, count, step = self._span()
        if isinstance(index, slice):
            start, stop, stride = index.indices(count)
            return StructArray(self._wrapper, pointer + start * step,
                               len(range(start, stop, stride)), self._root, step * stride)
        try:
            index = int(index.__index__())
        except AttributeError:
            raise TypeError(f"indices must be integers or slices, not {type(index).__name__}") \
                from None
        if not -count <= index < count:
            raise IndexError(f"index {index} out of range for {count} "
                             f"{self._wrapper.__name__} entries")
        return self._wrapper._wrap(pointer + (index % count) * step, self._root)

    def __iter__(self):
        pointer, count, step = self._span()
        wrap, root = self._wrapper._wrap, self._root
        for i in range(count):
            yield wrap(pointer + i * step, root)

    def records(self):
        """All entries as one structured NumPy view (zero-copy)."""
        pointer, count, step = self._span()
        dtype = record_dtype(self._wrapper._ctype)
        if count == 0:
            return np.zeros((0,), dtype)
        low = min(0, (count - 1) * step)       # the lowest address, for a negative stride
        whole = record_view(pointer + low, dtype, abs((count - 1) * step) + 1, self._root)
        return whole if step == 1 else whole[::step]

    def _name(self):
        return f"_{self._wrapper.__name__}List"     # the official class name

    def _field_view(self, name):
        """The view of field `name` (a C name) across the entries, made once: the
        entries of a StructArray never move."""
        try:
            cache = self._cache
        except AttributeError:
            cache = {}
            _set(self, "_cache", cache)
        value = cache.get(name)
        if value is None:
            pointer, count, step = self._span()
            size = ffi.sizeof(self._wrapper._ctype)
            entries = _entries(pointer, count, step, self._root, size) \
                if count and pointer != ffi.NULL else None
            value = cache[name] = _across(entries, count, step, size, _layout(self._wrapper)[name])
        return value

    def __setattr__(self, name, value):
        if name.startswith("_"):
            object.__setattr__(self, name, value)     # its own slots (copy.copy)
            return
        if name in self._wrapper._fields:
            raise with_note(AttributeError(f"property of {self._name()!r} object has no setter"),
                            f"write into the view instead: arr.{name}[:] = value")
        raise AttributeError(f"{self._name()!r} object has no attribute {name!r}")

    def __dir__(self):
        return sorted(set(object.__dir__(self)) | set(self._wrapper._fields))

    def __eq__(self, other):
        if not isinstance(other, StructArray) or other._wrapper._cname != self._wrapper._cname:
            return NotImplemented
        return len(self) == len(other) and all(a == b for a, b in zip(self, other))

    def __repr__(self):
        if not self._wrapper._fields:
            return f"<{self._name()} of {len(self)}>"
        return _field_lines(self._name(), [(name, getattr(self, name))
                                           for name in sorted(self._wrapper._fields)])


class LiveStructArray(StructArray):
    """The array of structs that a struct points to (d.contact, scn.geoms), as it is
    on each use: its address and count are read from the owner's struct.

    The field views (`d.contact.dist`) and the entries (`d.contact[0]`) are cached
    with a copy of the owner's words that define the array (its pointer and count,
    see _key), compared on each read: a change of either makes new ones.  It holds
    the owner's pointer and root, not the owner (which caches it: no cycle), and
    follows the owner to new memory (mjv_makeScene; Struct._moved).  Made per
    struct type (_live_class), with a property per field.
    """

    __slots__ = ("_ptr", "_field", "_counter", "_key", "_copy", "_views", "_items", "_base")

    def __init__(self, wrapper, owner, field, counter):
        _set(self, "_wrapper", wrapper)
        _set(self, "_step", 1)
        _set(self, "_field", field)
        _set(self, "_counter", counter)
        self._follow(owner)

    def _follow(self, owner):
        """Read the array of `owner`'s struct from now on."""
        offsets = _live_offsets(owner._ctype, self._field, self._counter)
        _set(self, "_ptr", owner._ptr)            # what the count function reads (s._ptr)
        _set(self, "_root", owner._root)
        _set(self, "_key", _key(_words(owner), offsets))
        self._reset()

    def _reset(self):
        _set(self, "_copy", None)
        _set(self, "_pointer", None)
        _set(self, "_count", 0)
        _set(self, "_views", None)
        _set(self, "_items", None)
        _set(self, "_base", None)

    def _sync(self):
        """Up to date with the owner's struct: new caches if the key changed."""
        if self._key == self._copy:
            return
        _set(self, "_copy", None)
        copy = _snapshot(self._key)               # before reading what it defines
        _set(self, "_pointer", getattr(self._ptr, self._field))
        _set(self, "_count", self._counter(self))
        _set(self, "_views", [None] * len(type(self)._names))
        _set(self, "_items", {})
        _set(self, "_base", None)
        _set(self, "_copy", copy)                 # last: what it checks is all new

    def _span(self):
        self._sync()
        return self._pointer, self._count, 1

    def _live_view(self, index):
        """The view of field number `index` (of _names) across the entries."""
        self._sync()
        value = self._views[index]
        if value is None:
            count, size = self._count, ffi.sizeof(self._wrapper._ctype)
            if self._base is None and count and self._pointer != ffi.NULL:
                _set(self, "_base", _entries(self._pointer, count, 1, self._root, size))
            spec = _layout(self._wrapper)[type(self)._names[index]]
            value = self._views[index] = _across(self._base, count, 1, size, spec)
        return value

    def __getitem__(self, index):
        if index.__class__ is int and self._key == self._copy:
            item = self._items.get(index)
            if item is not None:
                return item
        item = StructArray.__getitem__(self, index)       # in sync now
        if index.__class__ is int:
            self._items[index] = item
        return item

    def __copy__(self):
        other = type(self).__new__(type(self))
        for name in ("_wrapper", "_step", "_field", "_counter", "_ptr", "_root", "_key"):
            _set(other, name, getattr(self, name))
        other._reset()
        return other

    def __deepcopy__(self, memo):
        raise TypeError(f"cannot pickle {self._name()!r} object")   # as the official

    def __reduce__(self):
        raise TypeError(f"cannot pickle {self._name()!r} object")


_LIVE_OFFSETS: dict = {}


def _live_offsets(ctype, field, counter):
    """The byte offsets of the words that define a LiveStructArray (see _sizing)."""
    offsets = _LIVE_OFFSETS.get((ctype, field))
    if offsets is None:
        offsets = _LIVE_OFFSETS[ctype, field] = _sizing(counter, ctype, field)[0]
    return offsets


_CLASSES: dict = {}         # (StructArray or LiveStructArray, struct class) -> its class


def _live_field(index):
    """The getter of field number `index` of a LiveStructArray class."""
    def get(arr):
        if arr._key == arr._copy:
            value = arr._views[index]
            if value is not None:
                return value
        return arr._live_view(index)
    return get


def _static_field(name):
    """The getter of field `name` (a C name) of a StructArray class."""
    def get(arr):
        return arr._field_view(name)
    return get


def _no_view(attr):
    """The getter of a member of an anonymous union (mjuiItem), which has no view."""
    def get(arr):
        raise AttributeError(f"{attr!r} of {arr._name()} has no view across entries; "
                             f"read it from each entry")
    return get


def _array_class(wrapper, base=None):
    """The StructArray (or LiveStructArray) class of struct class `wrapper`, named
    as the official's (_MjContactList), with a property per field."""
    base = base or StructArray
    cls = _CLASSES.get((base, wrapper))
    if cls is None:
        layout = _layout(wrapper)
        names = tuple(_cname_of(attr) for attr in wrapper._fields
                      if _cname_of(attr) in layout)
        body = {"__slots__": (), "__module__": __name__, "_names": names}
        for attr in wrapper._fields:
            name = _cname_of(attr)
            if name not in layout:
                get = _no_view(attr)
            elif base is LiveStructArray:
                get = _live_field(names.index(name))
            else:
                get = _static_field(name)
            body[attr] = property(get, doc=getattr(getattr(wrapper, attr, None), "__doc__", None))
        cls = _CLASSES[base, wrapper] = type(base)(f"_{wrapper.__name__}List", (base,), body)
    return cls


def _live_class(wrapper):
    return _array_class(wrapper, LiveStructArray)


def _cname_of(attr):
    """The C field of a Python attribute (global_ -> global)."""
    return attr[:-1] if attr.endswith("_") and keyword.iskeyword(attr[:-1]) else attr


def _field_lines(title, items):
    """The official bindings' repr: `<Title`, one `  name: value` line each, `>`."""
    lines = [f"<{title}"]
    for name, value in items:
        text = repr(value)
        if isinstance(value, Struct):
            text = text.replace("\n", "\n  ")         # a nested struct, indented
        lines.append(f"  {name}: {text}")
    lines.append(">")
    return "\n".join(lines)


def _same(a, b):
    """Field equality as the official bindings compare: arrays element by element."""
    if isinstance(a, np.ndarray):
        return isinstance(b, np.ndarray) and a.shape == b.shape and bool((a == b).all())
    return a == b


# ------------------------------------------------------------------ the base

@functools.lru_cache(maxsize=None)
def _slot(cls, name):
    """The slot of `cls` that holds the `_eager` field `name` (declared by the generated
    class): written directly, since Struct.__setattr__ assigns into the view and a
    subclass may name a property so (mujoco-py's SimData.act)."""
    return next(vars(k)[name] for k in cls.__mro__
                if isinstance(vars(k).get(name), types.MemberDescriptorType))


class StructType(type):
    """The metaclass of the struct classes.

    `dir(cls)` also lists the `_eager` fields (MjData.qpos, ...: built when an
    instance is wrapped, and kept in slots of the generated class), as the official
    classes do: wrappers that build properties from `dir(mujoco.MjData)` find them.
    A generated class (one with a `_ctype`) binds its fields (Scalar, DynamicArray)
    to itself when it is made: their C get reads only its instances.  Attribute
    access never passes through here, so the hot path pays nothing.
    """

    def __init__(cls, name, bases, namespace, **kwargs):
        super().__init__(name, bases, namespace, **kwargs)
        if namespace.get("_ctype") is not None:   # a generated class: its fields read in C
            for value in namespace.values():
                if isinstance(value, Field) and not value._kind:
                    value._bind(cls)

    def __dir__(cls):
        return sorted(set(super().__dir__()) | set(cls._eager))


class Struct(Holder, metaclass=StructType):
    """Base of the generated struct classes: a pointer, and what keeps it alive.

    `_ptr` is the cdata pointer to the C struct; `_root` the cdata that owns
    the memory (the struct itself, or the mjModel/mjData it lives in).  The C
    base, Holder, keeps the struct's address (from `_locate`, on the first field
    read) and the cached views of its moving memory, for the C field reads.
    Assigning to an array or nested-struct field writes into C memory; an
    unknown attribute is an AttributeError rather than a silent new one.
    Structs that hold pointers (MjModel, MjData, MjvScene, ...) compare by
    identity; ValueStruct below compares the others by value.
    """

    _cname: str = ""              # C type name, e.g. 'mjOption'
    _ctype: object = None         # its cffi type
    _fields: tuple = ()           # the fields' attribute names, in C order
    _repr_fields: tuple = ()      # fields shown by the short repr
    _plain: bool = True           # no pointers inside: copy and pickle by bytes
    _views_hold_wrapper: bool = False   # spec elements: see _keeper
    _bounds: dict = {}            # scalar -> its Bound (ngeom within 0..maxgeom)
    _capacities: tuple = ()       # scalars bounded by their value when wrapped (see Bound)
    _allocated_views: tuple = ()  # AllocatedArray fields, bounded likewise
    _eager: dict = {}             # fields built when wrapped (see above)

    def __init__(self):
        """A new struct of this type, zero-initialized."""
        self._init_root(ffi.new(ffi.getctype(self._ctype, "*")))

    @classmethod
    def _wrap(cls, pointer, root, **extra):
        self = cls.__new__(cls)
        self._adopt(pointer, root, extra)
        return self

    def _init_root(self, root, **extra):
        """Adopt `root`, a new owning cdata pointer to this struct."""
        self._adopt(root, root, extra)

    def _adopt(self, pointer, root, extra):
        state = self.__dict__
        moved = "_ptr" in state
        state.update(_ptr=pointer, _root=root, **extra)
        if moved:
            self._moved()
        for name, field in self._eager.items():
            _slot(type(self), name).__set__(self, field.build(self))
        if self._capacities or self._allocated_views:
            self._remade()

    def _remade(self):
        """Record the sizes MuJoCo allocated (a scene's maxgeom, nflex, nskin), which
        bound what may be written to them.  Wrapping does it, and so does re-pointing
        a wrapper at new memory (mjcffi's mjv_makeScene); call it again after a raw
        `lib` call reallocated the struct in place.

        `_capacity` maps each to [allocated, last value seen]: a value that changed
        behind our back was written by MuJoCo's make or free, and everything is
        recorded again then (see _reallocated), so a scene remade without this
        call stays bounded unless its counts were all written from Python to the
        new values beforehand.  `_allocated` holds the sizes of the
        AllocatedArray fields."""
        pointer, cls = self._ptr, type(self)
        self.__dict__["_capacity"] = {name: [getattr(pointer, name)] * 2
                                      for name in self._capacities}
        self.__dict__["_allocated"] = {}
        for name in self._allocated_views:
            size = 1
            for n in getattr(cls, name).shape(self):
                size *= n
            self.__dict__["_allocated"][name] = size

    def _moved(self):
        """The wrapper now shows a struct in new memory (mjcffi's mjv_makeScene): the
        views of moving memory cached from the old one go (see DynamicArray), and
        the LiveStructArrays it gave follow it."""
        state = self.__dict__
        state.pop("_words", None)
        self._forget_memory()          # its address and _dyn: found again on the next read
        for value in list(state.values()):
            if isinstance(value, LiveStructArray):
                value._follow(self)

    def _reallocated(self):
        """Whether MuJoCo changed a count of `_capacities` behind our back (made or
        freed the struct again); if so, record the new allocation (see _remade)."""
        pointer = self._ptr
        if all(getattr(pointer, name) == seen
               for name, (_, seen) in self.__dict__["_capacity"].items()):
            return False
        self._remade()
        return True

    @property
    def _address(self):
        """The address of the C struct, as an int."""
        return int(ffi.cast("uintptr_t", self._ptr))

    def _locate(self):
        """The address of the C struct, for Holder: asked once, on the first field read
        (and again after _forget_memory).  0 for none: the fields read in Python."""
        return self._address

    def __setattr__(self, name, value):
        field = type(self)._eager.get(name) or getattr(type(self), name, None)
        if isinstance(field, Nested):
            getattr(self, name)._copy_from(value)
        elif isinstance(field, Array) and not isinstance(field, DynamicArray):
            assign(getattr(self, name), value, name)
        elif isinstance(field, Records):
            raise AttributeError(f"{type(self).__name__}.{name} cannot be assigned")
        elif name.startswith("_") or isinstance(field, property):
            object.__setattr__(self, name, value)   # setters, and read-only errors
        elif field is None:
            raise AttributeError(f"{type(self).__name__} has no field {name!r}")
        else:
            raise AttributeError(f"{type(self).__name__}.{name} cannot be assigned")

    def __dir__(self):
        return sorted(set(super().__dir__()) | set(type(self)._eager))

    def _copy_from(self, other):
        """Assignment of a nested struct (`m.opt = other`): all its bytes, in place.

        Refused for a struct holding pointers (a spec's MjsCompiler): the copy would
        share memory that its owner frees.  (Assigning one to itself changes nothing.)"""
        if not isinstance(other, Struct) or other._cname != self._cname:
            raise TypeError(f"expected {type(self).__name__}, got {type(other).__name__}")
        if not self._plain and other._ptr != self._ptr:
            raise TypeError(f"{type(self).__name__} holds pointers: it cannot be assigned as a "
                            f"whole; assign its fields one by one")
        ffi.memmove(self._ptr, other._ptr, ffi.sizeof(self._ctype))

    # copy and pickle of plain structs: their bytes are their whole value
    def _bytes(self):
        if not self._plain:
            raise TypeError(f"{type(self).__name__} holds pointers: it cannot be copied by value")
        return ffi.buffer(self._ptr, ffi.sizeof(self._ctype))[:]

    @classmethod
    def _from_bytes(cls, raw):
        root = ffi.new(ffi.getctype(cls._ctype, "*"))
        if len(raw) != ffi.sizeof(cls._ctype):
            raise ValueError(f"{cls.__name__} needs {ffi.sizeof(cls._ctype)} bytes, got {len(raw)}")
        ffi.memmove(root, raw, len(raw))
        return cls._wrap(root, root)

    def __copy__(self):
        return self._from_bytes(self._bytes())

    def __deepcopy__(self, memo):
        return self.__copy__()

    def __reduce__(self):
        return (type(self)._from_bytes, (self._bytes(),))

    def __repr__(self):
        parts = []
        for name in self._repr_fields:
            value = getattr(self, name)
            if isinstance(value, np.ndarray):
                value = np.array2string(value, threshold=8, separator=", ")
            parts.append(f"{name}={value}")
        return f"<{type(self).__name__} {' '.join(parts)}>" if parts else \
            f"<{type(self).__name__} at {hex(self._address)}>"


class ValueStruct(Struct):
    """A struct of values only (MjOption, MjContact, MjvCamera, ...).

    Equal to another of its type when every field is equal (arrays element by
    element, nested structs recursively), as in the official bindings; hence
    not hashable, its fields being mutable.  Its repr lists every field: the
    others sorted by name, then the nested structs.
    """

    __hash__ = None  # type: ignore[assignment]

    def __eq__(self, other):
        if not isinstance(other, Struct) or other._cname != self._cname:
            return NotImplemented
        return all(_same(getattr(self, name), getattr(other, name)) for name in self._fields)

    def __repr__(self):
        items = [(name, getattr(self, name)) for name in self._fields]
        flat = sorted((item for item in items if not isinstance(item[1], Struct)),
                      key=lambda item: item[0])
        return _field_lines(type(self).__name__,
                            flat + [item for item in items if isinstance(item[1], Struct)])


# ------------------------------------------------- field factories for codegen

def struct_type(cname):
    """The cffi type of struct `cname`; 'mjVisual.global' names a nested anonymous one."""
    outer, *path = cname.split(".")
    ctype = ffi.typeof(outer) if not outer.endswith("_") else ffi.typeof(f"struct {outer}")
    for name in path:
        ctype = dict(ctype.fields)[name].type
    return ctype


class Bound(NamedTuple):
    """The values a scalar field may take: `low` to `high`, both included.

    `high` is an int, the name of another field of the same struct (ngeom within
    0..maxgeom), or None for the field's own value when the struct was wrapped,
    i.e. what MuJoCo allocated (a scene's nflex).  `label` says where the bound
    comes from, for the error message.
    """
    low: int
    high: object
    label: str


# Field's C get reads these scalar kinds (see mjcffi/_c/descriptors.c): (signed, bytes) ->
# its code; floats and _Bool by name.  Others (char, which cffi reads as bytes; pointers)
# stay unbound and read through the Python getter.
_INT_KINDS = {(True, 1): 1, (False, 1): 2, (True, 2): 3, (False, 2): 4, (True, 4): 5,
              (False, 4): 6, (True, 8): 7, (False, 8): 8}
_NAMED_KINDS = {"float": 9, "double": 10, "_Bool": 11}


class Scalar(Field):
    """A scalar field of the C struct: a property whose get (Field's, in C) reads the
    value at its offset, once its class has bound it (StructType); its Python
    getter reads it through cffi where C does not (no address).  `field` is the
    C field's name."""

    def __init__(self, field, fget, fset, doc):
        property.__init__(self, fget, fset, None, doc)
        self.field, self.__doc__ = field, doc

    def _bind(self, cls):
        """Read the field in C from now on, for instances of struct class `cls`, at its
        offset in their struct type."""
        found = _field_at(cls._ctype, self.field)
        kind = found and _scalar_kind(found[0])
        if kind:
            self._bind_scalar(cls, found[1], kind, ffi.sizeof(cls._ctype))


def _field_at(ctype, name):
    """(cffi type, byte offset) of field `name` of struct type `ctype`, in anonymous
    unions too; None if it has none."""
    return _field_table(ctype).get(name)


@functools.lru_cache(maxsize=None)
def _field_table(ctype, base=0):
    """{field: (cffi type, byte offset)} of struct type `ctype`, once per type (cffi
    builds its `fields` list anew on each read)."""
    table = {}
    for field_name, field in ctype.fields:
        if field_name:
            table.setdefault(field_name, (field.type, base + field.offset))
        elif field.type.kind in ("struct", "union"):
            for name, found in _field_table(field.type, base + field.offset).items():
                table.setdefault(name, found)
    return table


@functools.lru_cache(maxsize=None)
def _scalar_kind(ftype):
    """The code of Field's C read of a field of cffi type `ftype` (see _INT_KINDS), or
    None where cffi's read must stay (char, pointers)."""
    if ftype.kind == "primitive" and ftype.cname in _NAMED_KINDS:
        return _NAMED_KINDS[ftype.cname]
    if ftype.kind == "enum" or (ftype.kind == "primitive" and ftype.cname != "char"):
        span = _range(ftype)
        if span is not None:
            return _INT_KINDS.get((span[0] < 0, ffi.sizeof(ftype)))
    return None


def scalar(name, doc, readonly=False, boolean=False, mirror=None):
    """A property reading and writing one scalar field of the C struct (a Scalar).

    A `boolean` field takes any integer, as True or False.  Writing a field
    with a `mirror` also writes 1 or 0 to that one (mjModel.flg_gravcomp sets
    ngravcomp, as the official bindings do).  `_bounds` limits the values.
    A value the C type cannot hold is a ValueError naming the field and the
    type's range (see _scalar_error); a value that is no number, a TypeError.
    """
    def set_value(self, value):
        limit = self._bounds.get(name)
        if limit is not None:
            _check_bound(self, name, value, limit)
        if boolean and not isinstance(value, bool):
            value = _as_bool(self, name, value)
        try:
            setattr(self._ptr, name, value)
        except (TypeError, OverflowError) as exc:
            raise _scalar_error(self, name, value, exc) from None
        if mirror is not None:
            setattr(self._ptr, mirror, 1 if value else 0)
    return Scalar(name, operator.attrgetter("_ptr." + name), None if readonly else set_value,
                  doc)


def _check_bound(self, name, value, limit):
    low, high, label = limit
    capacity = None
    if high is None:                   # what MuJoCo allocated: see Struct._remade
        self._reallocated()
        capacity = self.__dict__["_capacity"][name]
        high = capacity[0]
    elif high.__class__ is str:
        high = getattr(self._ptr, high)
    try:
        number = operator.index(value)
    except TypeError:
        raise TypeError(f"{type(self).__name__}.{name} takes an int, "
                        f"not {type(value).__name__}") from None
    if not low <= number <= high:
        raise ValueError(f"{type(self).__name__}.{name} must be within {low}..{high} "
                         f"({label}), not {value}")
    if capacity is not None:
        capacity[1] = number


def _range(ctype):
    """(low, high) of a C integer or enum type, or None for a floating-point one."""
    if ctype.kind == "primitive" and ctype.cname in ("float", "double", "long double"):
        return None
    bits = 8 * ffi.sizeof(ctype)
    try:
        ffi.new(ffi.getctype(ctype, "*"), -1)
    except OverflowError:
        return 0, (1 << bits) - 1                  # unsigned
    return -(1 << (bits - 1)), (1 << (bits - 1)) - 1


def _scalar_error(self, name, value, exc):
    """What to raise when cffi refused `value` for a scalar field: a ValueError (that
    is also the official TypeError) when it does not fit the C type, naming the
    type's range; a TypeError when it is no number."""
    title = f"{type(self).__name__}.{name}"
    ctype = (_field_at(ffi.typeof(self._ptr).item, name) or (None,))[0]
    if isinstance(exc, TypeError) or ctype is None:
        pointer = ctype is not None and ctype.kind in ("pointer", "function")
        return TypeError(f"{title} takes {'a function pointer' if pointer else 'a number'} "
                         f"(C {ctype.cname if ctype else '?'}), not {type(value).__name__}")
    span = _range(ctype)
    if span is None:               # only an int beyond the double range overflows
        limit = float(np.finfo(np.float64).max)
        where = f"is out of range for a C {ctype.cname} (-{limit:g}..{limit:g})"
    else:
        where = f"is out of range for a C {ctype.cname} ({span[0]}..{span[1]})"
    return ArgumentError(f"{title}: {_short(value)} {where}")


def _short(value):
    """repr(value), with the middle of a long one (an int of 400 digits) left out."""
    text = repr(value)
    return text if len(text) <= 40 else f"{text[:16]}...{text[-8:]} ({len(text)} characters)"


def _as_bool(self, name, value):
    try:
        return bool(operator.index(value))
    except TypeError:
        raise TypeError(f"{type(self).__name__}.{name} takes a bool or an int, "
                        f"not {type(value).__name__}") from None


def text(name, size, doc):
    """A char[size] field as a str property (NUL-terminated, UTF-8)."""
    def get_value(self):
        return ffi.string(getattr(self._ptr, name)).decode("utf-8", "replace")

    def set_value(self, value):
        raw = value.encode("utf-8") if isinstance(value, str) else value
        if not isinstance(raw, bytes):
            raise TypeError(f"{type(self).__name__}.{name} must be str, not {type(value).__name__}")
        if len(raw) >= size or b"\0" in raw:
            raise ValueError(f"{type(self).__name__}.{name} takes at most {size - 1} bytes "
                             f"and no NUL, got {len(raw)}")
        setattr(self._ptr, name, raw + b"\0" * (size - len(raw)))
    return property(get_value, set_value, doc=doc)


def cstring(name, doc):
    """A `const char *` field as a read-only str, None when NULL."""
    def get_value(self):
        pointer = getattr(self._ptr, name)
        return None if pointer == ffi.NULL else ffi.string(pointer).decode("utf-8", "replace")
    return property(get_value, doc=doc)


class _Chars(_Cached):
    """A char* field of known extent as bytes, read once (see chars)."""

    def __init__(self, name, count, doc):
        self.name, self.count, self.__doc__ = name, count, doc

    def build(self, obj):
        pointer, n = getattr(obj._ptr, self.name), self.count(obj)
        return ffi.unpack(pointer, n) if n and pointer != ffi.NULL else b""


def chars(name, count, doc):
    """A char* field of known extent (mjModel.names) as bytes, read once: the
    names of a compiled model never change, and `m.names is m.names`."""
    return _Chars(name, count, doc)


def pointer(name, doc):
    """A field shown as its raw cdata (pointers of unknown extent, callbacks)."""
    return property(operator.attrgetter("_ptr." + name), doc=doc)


def total(pointer, count):
    """The sum of `count` ints at `pointer` (extents such as 9*sum(flexfacenum))."""
    return sum(pointer[0:count]) if count > 0 and pointer != ffi.NULL else 0


# ------------------------------------------------------- argument checking

def struct_pointer(obj, cname, argname):
    """The C pointer of wrapper `obj`, which must wrap a `cname` (an instance, not
    the class)."""
    if getattr(obj, "_cname", None) != cname or isinstance(obj, type):
        if _official.is_official(obj):     # both bindings have an MjModel: say which
            raise _official.not_accepted(argname, cname[0].upper() + cname[1:], obj)
        what = f"the class {obj.__name__}" if isinstance(obj, type) else type(obj).__name__
        raise TypeError(f"{argname} must be {cname[0].upper() + cname[1:]}, not {what}")
    return obj._ptr


def int_argument(value, argname, ctype=None):
    """`value` as a Python int; with `ctype` ('int'), one that C type can hold, or
    a ValueError that is also the official TypeError."""
    try:
        number = operator.index(value)
    except TypeError:
        raise TypeError(f"{argname} must be an int, not {type(value).__name__}") from None
    if ctype is not None:
        low, high = _range(ffi.typeof(ctype))
        if not low <= number <= high:
            raise ArgumentError(f"{argname}={_short(value)} is out of range for a C {ctype} "
                                f"({low}..{high})")
    return number


def guarded(guard, *args):
    """Call a void `mjcffi_guard_*` function; a caught mju_error becomes FatalError."""
    check(guard(*args))


def guarded_result(guard, *args):
    """Call a value-returning `mjcffi_guard_*`; a caught mju_error becomes FatalError."""
    result = guard(*args)
    raise_pending()
    return result
