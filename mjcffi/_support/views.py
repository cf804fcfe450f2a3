"""Zero-copy NumPy views of MuJoCo memory, and the pieces the generated struct
classes (mjcffi/structs/) are made of.

A support module: it imports only the compiled module, _errors and NumPy.
Every view keeps the memory it shows alive by referencing the *root* cdata
(the gc-owned `mjData *`, `mjModel *` or `ffi.new` struct), never a Python
wrapper, so a view cached on a wrapper makes no cycle (see `view`).
"""

import keyword
import operator
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

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
# Fields that move are data descriptors, rebuilt on every read.

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


class DynamicArray(Array):
    """An array whose size or address changes (nefc, the arena, scene.ngeom).

    A data descriptor: the view is rebuilt on every read.
    """

    def __get__(self, obj, cls=None):
        return self if obj is None else self.build(obj)

    def __set__(self, obj, value):
        assign(self.build(obj), value, self.name)


class AllocatedArray(DynamicArray):
    """A DynamicArray sized by counts that other arrays hold (a scene's flexedge has
    2*sum(flexedgenum) entries), in memory that mj*_make<Struct> allocated.

    Those counts are writable views, so the size is checked against what was
    allocated, recorded when the struct was wrapped (Struct._remade): a count
    written past it raises ValueError instead of showing memory beyond the block.
    """

    def build(self, obj):
        shape = self.shape(obj)
        size = 1
        for n in shape:
            size *= n
        state = obj.__dict__
        if not 0 <= size <= state["_allocated"][self.name]:
            if obj._reallocated():
                return self.build(obj)
            raise ValueError(f"{type(obj).__name__}.{self.name} would show {size} entries, "
                             f"not within the 0..{state['_allocated'][self.name]} allocated: "
                             f"the counts that size it were written past their allocation")
        return view(getattr(obj._ptr, self.name), self.dtype, shape, obj._root, self.fill)


class Records:
    """A pointed-to array of structs (mjData.contact: ncon, mjvScene.geoms: maxgeom).

    A read-only data descriptor.  The StructArray it gives reads the address and
    the count on each use: one taken before a step holds the contacts that the
    step finds, and one of a scene remade by mjv_makeScene its new geoms.
    """

    def __init__(self, name, wrapper, count, doc=""):
        self.name, self.wrapper, self.count, self.__doc__ = name, wrapper, count, doc

    def __get__(self, obj, cls=None):
        if obj is None:
            return self
        return LiveStructArray(self.wrapper(), obj, self.name, self.count)

    def __set__(self, obj, value):
        raise AttributeError(f"{type(obj).__name__}.{self.name} cannot be assigned")


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

class StructArray(Sequence):
    """A sequence of struct wrappers over C memory, e.g. `d.warning`.

    `arr[i]` is a wrapper sharing memory (a negative i counts from the end),
    `arr[a:b:c]` a StructArray of those entries, and `arr.field` a NumPy view
    of that field across the entries, e.g. `d.contact.dist` of shape (ncon,).
    Two are equal when they hold equal structs in the same order.
    """

    __slots__ = ("_wrapper", "_pointer", "_count", "_root", "_step")
    __hash__ = None  # type: ignore[assignment]  # equal by value, and mutable

    def __init__(self, wrapper, pointer, count, root, step=1):
        self._wrapper, self._pointer, self._count, self._root = wrapper, pointer, count, root
        self._step = step

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

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)     # not built yet (copy, pickle): no recursion
        if name not in self._wrapper._fields:
            raise AttributeError(f"{self._name()!r} object has no attribute {name!r}")
        try:
            return self.records()[_cname_of(name)]
        except (KeyError, ValueError):     # a member of an anonymous union (mjuiItem)
            raise AttributeError(f"{name!r} of {self._name()} has no view across entries; "
                                 f"read it from each entry") from None

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
    """A StructArray that reads its address and count from its owner on each use."""

    __slots__ = ("_owner", "_field", "_counter")

    def __init__(self, wrapper, owner, field, counter):
        super().__init__(wrapper, None, 0, owner._root)
        self._owner, self._field, self._counter = owner, field, counter

    def _span(self):
        owner = self._owner
        self._root = owner._root     # the owner's memory as of now (mjv_makeScene gives new)
        return getattr(owner._ptr, self._field), self._counter(owner), 1


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

class StructType(type):
    """The metaclass of the struct classes.

    `dir(cls)` also lists the fields that exist on instances only (the
    `_eager` ones, such as MjData.qpos), as the official classes do: wrappers
    that build properties from `dir(mujoco.MjData)` find them.  Attribute
    access never passes through here, so the hot path pays nothing.
    """

    def __dir__(cls):
        return sorted(set(super().__dir__()) | set(cls._eager))


class Struct(metaclass=StructType):
    """Base of the generated struct classes: a pointer, and what keeps it alive.

    `_ptr` is the cdata pointer to the C struct; `_root` the cdata that owns
    the memory (the struct itself, or the mjModel/mjData it lives in).
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
        state.update(_ptr=pointer, _root=root, **extra)
        for name, field in self._eager.items():
            state[name] = field.build(self)
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

    def __setattr__(self, name, value):
        field = type(self)._eager.get(name) or getattr(type(self), name, None)
        if isinstance(field, Nested):
            getattr(self, name)._copy_from(value)
        elif isinstance(field, Array) and not isinstance(field, DynamicArray):
            assign(getattr(self, name), value, name)
        elif name.startswith("_") or isinstance(field, (property, DynamicArray, Records)):
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


def scalar(name, doc, readonly=False, boolean=False, mirror=None):
    """A property reading and writing one scalar field of the C struct.

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
    return property(operator.attrgetter("_ptr." + name), None if readonly else set_value,
                    doc=doc)


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


def _field_type(ctype, name):
    """The cffi type of field `name` of struct type `ctype`, in anonymous unions too."""
    for field_name, field in ctype.fields:
        if field_name == name:
            return field.type
        if not field_name and field.type.kind in ("struct", "union"):
            found = _field_type(field.type, name)
            if found is not None:
                return found
    return None


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
    ctype = _field_type(ffi.typeof(self._ptr).item, name)
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
