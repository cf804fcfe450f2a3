"""Named access: `m.geom('ball').rgba`, `d.joint('hinge').qpos`, `d.sensor('s').data`.

MjModel and MjData have one method per name category (mjcffi/_generated/namedinfo.py,
generated from mjModel's name_*adr fields), taking a name or an id.  It
returns an accessor whose attributes are the element's fields, as zero-copy
views; writes go through to C.  Ragged fields follow the element's own size
(a free joint's qpos has 7 entries, a sensor's data `sensor_dim`, an
actuator's ctrl `actuator_ctrlnum`).

Each (side, category) pair has its own accessor class, named as the official
bindings name theirs (`_MjModelGeomViews`), made on first use.  Its fields are
class-level descriptors that cache the view in the instance on first read, so
a later read is a plain attribute read.

Names are mapped to ids once per model and category; accessors are cached on
their owner, so a repeated `d.joint('j').qpos` is two dict lookups and an
attribute read.  An accessor references the C memory (the root cdata), not
its owner's wrapper, so the cache makes no reference cycle.
"""

import difflib

import numpy as np

from .errors import with_note
from .library import ffi
from .._generated.namedinfo import ALIASES, CATEGORIES, MjDataNames, MjModelNames
from .._generated.structinfo import STRUCTS
from .views import DTYPES, view

__all__ = ["Accessor", "MjDataNames", "MjModelNames", "NamedAccess", "accessor_class"]


class Accessor:
    """One named element: its fields as attributes, plus `id` and `name`.

    The base of the accessor classes (see accessor_class).  Attributes are
    built on first read and then cached.  Assigning to one writes into the C
    array (`m.geom('g').rgba = [1, 0, 0, 1]`).
    """

    _side = _category = None
    _fields: dict = {}                 # attribute -> _namedinfo.Field, per class

    def __init__(self, element_id, name, pointer, root, model):
        self.__dict__.update(id=element_id, name=name, _pointer=pointer, _root=root, _m=model)

    def __getattr__(self, attr):       # reached only for attributes no field provides
        exc = AttributeError(f"'{type(self).__name__}' object has no attribute {attr!r}",
                             name=attr, obj=self)
        if not attr.startswith("__"):
            with_note(exc, f"the fields of {_label(self._category)}: "
                      f"{', '.join(sorted(a for a in self._fields if a[0] != '_'))}")
        raise exc

    def __setattr__(self, attr, value):
        field = self._fields.get(attr)
        if field is None or field.kind == "dense":
            raise _no_such_property(self, attr, "setter")
        target = getattr(self, attr)
        try:
            target[...] = value
        except (ValueError, TypeError) as exc:
            raise with_note(exc, f"{_label(self._category)} {attr!r} has shape {target.shape}")

    def __delattr__(self, attr):
        raise _no_such_property(self, attr, "deleter")

    def __dir__(self):
        return sorted(set(dir(type(self))) | {"id", "name"})

    def __repr__(self):
        attrs = sorted(a for a in {*self._fields, "id", "name"} if a[0] != "_")
        lines = [f"<{type(self).__name__}"]
        lines += [f"  {attr}: {getattr(self, attr)!r}" for attr in attrs]
        return "\n".join(lines + [">"])


def _no_such_property(acc, attr, what):
    """The AttributeError of a write or delete of `attr` (as the official words it)."""
    owner = type(acc).__name__
    if attr in acc._fields or attr in ("id", "name"):
        return AttributeError(f"property of '{owner}' object has no {what}")
    return AttributeError(f"'{owner}' object has no attribute {attr!r}", name=attr, obj=acc)


class _FieldView:
    """A field of an accessor class: built on first read, then cached in the
    instance, which a non-data descriptor lets win over the class."""

    __slots__ = ("field",)

    def __init__(self, field):
        self.field = field

    def __get__(self, acc, owner=None):
        if acc is None:
            return self
        field = self.field
        value = _build(acc, field)
        if field.kind != "dense":             # a dense copy is rebuilt on every read
            acc.__dict__[field.attr] = value
        return value


_CLASSES: dict = {}                     # (side, category) -> accessor class


def accessor_class(side, category):
    """The accessor class of one category's `side` ('model' or 'data') fields,
    named as the official bindings name theirs (_MjModelGeomViews)."""
    cls = _CLASSES.get((side, category))
    if cls is None:
        fields = {f.attr: f for f in getattr(CATEGORIES[category], side)}
        owner = "MjModel" if side == "model" else "MjData"
        name = f"_{owner}{_long_name(category).capitalize()}Views"
        namespace = {attr: _FieldView(f) for attr, f in fields.items()}
        namespace.update(
            __doc__=f"The {side} fields of one {_long_name(category)} "
                    f"({owner}.{category}(name or id)), as zero-copy views.",
            __module__=__name__, __qualname__=name,
            _side=side, _category=category, _fields=fields)
        cls = _CLASSES[side, category] = type(name, (Accessor,), namespace)
    return cls


def _long_name(category):
    """The category's long name (jnt: joint), which the official class names use."""
    return max(category, ALIASES.get(category, category), key=len)


def _label(category):
    alias = ALIASES.get(category)
    return f"{category} ({alias})" if alias else category


# ------------------------------------------------------------- field views

def _build(acc, field):
    """The view (or, for a dense row, the copy) of one field of one element."""
    m, i = acc._m, acc.id
    dtype = DTYPES[field.elem]
    pointer = getattr(acc._pointer, field.name)
    columns = field.columns if isinstance(field.columns, int) else field.columns(m)
    kind = field.kind
    if kind == "row":
        return view(pointer + i * columns, dtype, (columns,), acc._root)
    if kind == "rows":
        adr, num = (getattr(m, name)[i] for name in field.params)
        return view(pointer + adr * columns, dtype, _rows_shape(num, columns), acc._root)
    if kind in ("qpos", "dof"):
        adr, width = _joint_span(m, i, kind)
        shape = (width,) if columns == 1 else (width, columns)
        return view(pointer + adr * columns, dtype, shape, acc._root)
    if kind == "span":
        adr, size = (getattr(m, name)[i] for name in field.params)
        shape = (size,) if columns == 1 else (size, columns)
        return view(pointer + adr * columns, dtype, shape, acc._root)
    if kind == "image":
        address, dims = field.params
        shape = tuple(getattr(m, name)[i] for name in dims)
        return view(pointer + getattr(m, address)[i], dtype, shape, acc._root)
    if kind == "plastic":
        adr, width = _plastic_span(m, i, field.params[0])
        return view(pointer + max(adr, 0), dtype, (width,), acc._root)
    if kind == "dense":
        return _dense(acc, field, pointer, dtype)
    raise ValueError(f"unknown kind of named field {kind!r}")


def _rows_shape(num, columns):
    """An actuator's `num` rows of a field: a single row keeps the shape of one
    row, as in the official bindings (a motor's gear is (6,), not (1, 6))."""
    if num == 1:
        return (columns,)
    return (num,) if columns == 1 else (num, columns)


def _dense(acc, field, values, dtype):
    """An element's rows of a sparse matrix (actuator_moment), dense and read-only."""
    m, i = acc._m, acc.id
    adr_name, num_name, rowadr_name, rownnz_name, colind_name = field.params
    adr, num = getattr(m, adr_name)[i], getattr(m, num_name)[i]
    rowadr, rownnz, colind = (getattr(acc._pointer, name)
                              for name in (rowadr_name, rownnz_name, colind_name))
    dense = np.zeros((num, m.nv), dtype)
    for row in range(num):
        start = rowadr[adr + row]
        for k in range(start, start + rownnz[adr + row]):
            dense[row, colind[k]] = values[k]
    if num == 1:
        dense = dense[0]
    dense.flags.writeable = False
    return dense


_QPOS_WIDTH = {0: 7, 1: 4}      # mjJNT_FREE, mjJNT_BALL; slide and hinge take 1
_DOF_WIDTH = {0: 6, 1: 3}


def _joint_span(m, i, kind):
    widths = _QPOS_WIDTH if kind == "qpos" else _DOF_WIDTH
    adr = m.jnt_qposadr[i] if kind == "qpos" else m.jnt_dofadr[i]
    return adr, widths.get(m.jnt_type[i], 1)


# Every mjModel field that places an element's state in mjData.plastic, with the
# size that counts its elements: (jnt_plasticadr, njnt), (flex_plasticadr, nflex), ...
_PLASTIC_STARTS = tuple((f.name, f.extents[0][2:]) for f in STRUCTS["mjModel"]
                        if f.name.endswith("_plasticadr"))


def _plastic_span(m, i, adr_field):
    """Where element i's plastic state starts in mjData.plastic, and its length:
    up to the next address any element (joint, flex, tendon) starts at, or to
    nplastic."""
    adr = getattr(m, adr_field)[i]
    if adr < 0:
        return 0, 0
    starts = [a for name, count in _PLASTIC_STARTS
              for a in ffi.unpack(getattr(m, name), getattr(m, count)) if a > adr]
    return adr, min(starts + [m.nplastic]) - adr


# --------------------------------------------------------------- the mixins

def _names(model, category):
    """name -> id for a category of `model` (an MjModel), built once."""
    cache = model.__dict__.setdefault("_name_ids", {})
    table = cache.get(category)
    if table is None:
        m, names = model._ptr, model.names
        count = getattr(m, CATEGORIES[category].size)
        adr = ffi.unpack(getattr(m, f"name_{category}adr"), count)
        table = {}
        for element_id, start in enumerate(adr):
            name = names[start:names.index(b"\0", start)].decode("utf-8")
            if name:
                table.setdefault(name, element_id)
        cache[category] = table
    return table


class NamedAccess:
    """What the generated methods need: the cache, and the accessor on a miss."""

    def _accessor(self, category, key):
        model = self if self._cname == "mjModel" else self._model
        element_id = _element_id(model, category, key)
        # The generated methods look in these first, by the key's exact type
        # (a float or a bool equal to an id must not find it).
        by_id = self.__dict__.setdefault("_named_ids", {}).setdefault(category, {})
        accessor = by_id.get(element_id)
        if accessor is None:
            name = _name_of(model, category, element_id)
            side = "model" if self is model else "data"
            cls = accessor_class(side, category)
            accessor = by_id[element_id] = cls(element_id, name, self._ptr, self._root,
                                               model._ptr)
            if name:
                self.__dict__.setdefault("_named", {}).setdefault(category, {})[name] = accessor
        return accessor


def _element_id(model, category, key):
    """The id that `key` (a name or an id) names, with the official errors."""
    if isinstance(key, bytes):                    # the official bindings take bytes too
        key = key.decode("utf-8")
    if isinstance(key, str):
        element_id = _names(model, category).get(key)
        if element_id is None:
            raise with_note(KeyError(f"Invalid name {key!r}. "
                                     f"Valid names: {sorted(_names(model, category))}"),
                            _unknown_name(model, category, key))
        return element_id
    if isinstance(key, (bool, np.bool_)) or not hasattr(key, "__index__"):
        raise TypeError(f"{category}() takes a name (str) or an id (int), "
                        f"not {type(key).__name__}")
    element_id = key.__index__()
    count = getattr(model._ptr, CATEGORIES[category].size)
    if not 0 <= element_id < count:
        raise with_note(IndexError(f"Invalid index {element_id}. "
                                   f"Valid indices from 0 to {count - 1}"),
                        f"{_label(category)} id {element_id} is out of range: "
                        f"the model has {count}")
    return element_id


def _name_of(model, category, element_id):
    m = model._ptr                 # read one name, not a copy of all of them
    start = getattr(m, f"name_{category}adr")[element_id]
    return ffi.string(m.names + start).decode("utf-8")


def _unknown_name(model, category, key):
    known = list(_names(model, category))
    close = difflib.get_close_matches(key, known, n=3)
    hint = f"; did you mean {', '.join(map(repr, close))}?" if close else \
        f"; the model has {len(known)} named" if known else "; the model names none"
    return f"no {_label(category)} named {key!r}{hint}"
