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

import numpy as np

from ._errors import check, raise_pending
from ._library import ffi

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


class _Memory:
    """The base of a record view: describes the memory and keeps its root alive."""
    __slots__ = ("__array_interface__", "root")

    def __init__(self, address, shape, dtype, root):
        self.root = root
        self.__array_interface__ = {"data": (address, False), "shape": shape,
                                    "typestr": dtype.str, "descr": dtype.descr, "version": 3}


class _KeepAlive:
    """A no-op destructor whose only job is to reference the root."""
    __slots__ = ("root",)

    def __init__(self, root):
        self.root = root

    def __call__(self, pointer):
        pass


def view(pointer, dtype, shape, root):
    """A writable view of `shape` elements of `dtype` at `pointer` (a C pointer).

    The view's base is a cffi buffer, which keeps its pointer cdata alive; that
    cdata is an `ffi.gc` copy whose destructor references `root`.  So the view
    keeps the memory's owner alive, at half the cost of an array-interface
    holder.
    """
    if pointer == ffi.NULL or 0 in shape:
        return np.zeros(shape, dtype)     # nothing allocated: zeros, as the official bindings
    count = shape[0]
    for n in shape[1:]:
        count *= n
    flat = np.frombuffer(ffi.buffer(ffi.gc(pointer, _KeepAlive(root)), count * dtype.itemsize),
                         dtype)
    return flat if len(shape) == 1 else flat.reshape(shape)


def record_view(pointer, dtype, count, root):
    """A view of `count` structs as a structured array (see record_dtype)."""
    if pointer == ffi.NULL or count == 0:
        return np.zeros((count,), dtype)
    address = int(ffi.cast("uintptr_t", pointer))
    return np.asarray(_Memory(address, (count,), dtype, root))


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
        return self.name + "_" if keyword.iskeyword(self.name) else self.name


class Array(_Cached):
    """An array field: a zero-copy view of the memory it points to."""

    def __init__(self, name, elem, shape, doc=""):
        self.name, self.dtype, self.shape, self.__doc__ = name, DTYPES[elem], shape, doc

    def build(self, obj):
        return view(getattr(obj._ptr, self.name), self.dtype, self.shape(obj), obj._root)


class FixedArray(Array):
    """An array embedded in the struct itself, such as mjOption.gravity[3]."""

    def build(self, obj):
        return view(ffi.addressof(obj._ptr, self.name), self.dtype, self.shape(obj), obj._root)


class Nested(_Cached):
    """A struct embedded in another (mjModel.opt): a wrapper sharing its memory."""

    def __init__(self, name, wrapper, doc=""):
        self.name, self.wrapper, self.__doc__ = name, wrapper, doc

    def build(self, obj):
        return self.wrapper()._wrap(ffi.addressof(obj._ptr, self.name), obj._root)


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


class Records:
    """A pointed-to array of structs whose count changes (mjData.contact: ncon).

    A read-only data descriptor giving a fresh StructArray on every read.
    """

    def __init__(self, name, wrapper, count, doc=""):
        self.name, self.wrapper, self.count, self.__doc__ = name, wrapper, count, doc

    def __get__(self, obj, cls=None):
        if obj is None:
            return self
        return StructArray(self.wrapper(), getattr(obj._ptr, self.name), self.count(obj),
                           obj._root)

    def __set__(self, obj, value):
        raise AttributeError(f"{type(obj).__name__}.{self.name} cannot be assigned")


def assign(target, value, name):
    """Write `value` into the view `target`, naming the field on a bad shape."""
    try:
        target[...] = value
    except (ValueError, TypeError) as exc:
        raise type(exc)(f"cannot assign to {name} of shape {target.shape}: {exc}") from None


# ------------------------------------------------------------- struct arrays

class StructArray(Sequence):
    """A sequence of struct wrappers over C memory, e.g. `d.contact`.

    `arr[i]` is a wrapper sharing memory; `arr.field` is a NumPy view of that
    field across all entries, e.g. `d.contact.dist` of shape (ncon,).
    """

    def __init__(self, wrapper, pointer, count, root):
        self._wrapper, self._pointer, self._count, self._root = wrapper, pointer, count, root

    def __len__(self):
        return self._count

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(self._count))]
        try:
            index = int(index.__index__())
        except AttributeError:
            raise TypeError(f"indices must be integers or slices, not {type(index).__name__}") \
                from None
        if not -self._count <= index < self._count:
            raise IndexError(f"index {index} out of range for {self._count} "
                             f"{self._wrapper.__name__} entries")
        return self._wrapper._wrap(self._pointer + (index % self._count), self._root)

    def records(self):
        """All entries as one structured NumPy view (zero-copy)."""
        return record_view(self._pointer, record_dtype(self._wrapper._ctype), self._count,
                           self._root)

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        try:
            return self.records()[name]
        except (ValueError, KeyError):
            raise AttributeError(f"{self._wrapper.__name__} has no field {name!r}") from None

    def __repr__(self):
        return f"<{len(self)} {self._wrapper.__name__} entries>"


# ------------------------------------------------------------------ the base

class Struct:
    """Base of the generated struct classes: a pointer, and what keeps it alive.

    `_ptr` is the cdata pointer to the C struct; `_root` the cdata that owns
    the memory (the struct itself, or the mjModel/mjData it lives in).
    Assigning to an array or nested-struct field writes into C memory; an
    unknown attribute is an AttributeError rather than a silent new one.
    """

    _cname: str = ""              # C type name, e.g. 'mjOption'
    _ctype: object = None         # its cffi type
    _repr_fields: tuple = ()      # fields shown by repr()
    _plain: bool = True           # no pointers inside: copy and pickle by bytes
    _bounds: dict = {}            # scalar -> the scalar bounding it (ngeom <= maxgeom)
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
        if type(other) is not type(self):
            raise TypeError(f"expected {type(self).__name__}, got {type(other).__name__}")
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
            f"<{type(self).__name__} at {hex(int(ffi.cast('uintptr_t', self._ptr)))}>"



# ------------------------------------------------- field factories for codegen

def struct_type(cname):
    """The cffi type of struct `cname`; 'mjVisual.global' names a nested anonymous one."""
    outer, *path = cname.split(".")
    ctype = ffi.typeof(outer) if not outer.endswith("_") else ffi.typeof(f"struct {outer}")
    for name in path:
        ctype = dict(ctype.fields)[name].type
    return ctype


def scalar(name, doc, readonly=False):
    """A property reading and writing one scalar field of the C struct."""
    def set_value(self, value):
        limit = self._bounds.get(name)
        if limit is not None and not 0 <= operator.index(value) <= getattr(self._ptr, limit):
            raise ValueError(f"{type(self).__name__}.{name} must be within 0..{limit} "
                             f"({getattr(self._ptr, limit)}), not {value}")
        try:
            setattr(self._ptr, name, value)
        except (TypeError, OverflowError) as exc:
            raise type(exc)(f"{type(self).__name__}.{name}: {exc}") from None
    return property(operator.attrgetter("_ptr." + name), None if readonly else set_value,
                    doc=doc)


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


def chars(name, count, doc):
    """A char* field of known extent (mjModel.names) as bytes, read-only."""
    def get_value(self):
        pointer, n = getattr(self._ptr, name), count(self)
        return ffi.unpack(pointer, n) if n and pointer != ffi.NULL else b""
    return property(get_value, doc=doc)


def pointer(name, doc):
    """A field shown as its raw cdata (pointers of unknown extent, callbacks)."""
    return property(operator.attrgetter("_ptr." + name), doc=doc)


# ------------------------------------------------------- argument checking

def struct_pointer(obj, cname, argname):
    """The C pointer of wrapper `obj`, which must wrap a `cname`."""
    if getattr(obj, "_cname", None) != cname:
        raise TypeError(f"{argname} must be {cname[0].upper() + cname[1:]}, "
                        f"not {type(obj).__name__}")
    return obj._ptr


def int_argument(value, argname):
    try:
        return operator.index(value)
    except TypeError:
        raise TypeError(f"{argname} must be an int, not {type(value).__name__}") from None


def guarded(guard, *args):
    """Call a void `mjcffi_guard_*` function; a caught mju_error becomes FatalError."""
    check(guard(*args))


def guarded_result(guard, *args):
    """Call a value-returning `mjcffi_guard_*`; a caught mju_error becomes FatalError."""
    result = guard(*args)
    raise_pending()
    return result
