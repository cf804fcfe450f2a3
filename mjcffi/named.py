"""Named access: `m.geom('ball').rgba`, `d.joint('hinge').qpos`, `d.sensor('s').data`.

MjModel and MjData have one method per name category (mjcffi/_namedinfo.py,
generated from mjModel's name_*adr fields), taking a name or an id.  It
returns an accessor whose attributes are the element's fields, as zero-copy
views; writes go through to C.  Ragged fields follow the element's own size
(a free joint's qpos has 7 entries, a sensor's data `sensor_dim`).

Names are mapped to ids once per model and category; accessors are cached on
their owner, so a repeated `d.joint('j').qpos` is two dict lookups and an
attribute read.  An accessor references the C memory (the root cdata), not
its owner's wrapper, so the cache makes no reference cycle.
"""

import difflib

import numpy as np

from ._library import ffi
from ._namedinfo import ALIASES, CATEGORIES, MjDataNames, MjModelNames
from ._views import DTYPES, view

__all__ = ["Accessor", "MjDataNames", "MjModelNames", "NamedAccess"]


class Accessor:
    """One named element: its fields as attributes, plus `id` and `name`.

    Attributes are built on first read and then cached.  Assigning to one
    writes into the C array (`m.geom('g').rgba = [1, 0, 0, 1]`).
    """

    def __init__(self, side, category, element_id, name, pointer, root, model):
        state = self.__dict__
        state.update(id=element_id, name=name, _side=side, _category=category,
                     _pointer=pointer, _root=root, _m=model)
        state["_fields"] = {f.attr: f for f in getattr(CATEGORIES[category], side)}

    def __getattr__(self, attr):
        field = self.__dict__.get("_fields", {}).get(attr)
        if field is None:
            raise AttributeError(f"{self._category} accessor has no field {attr!r}; "
                                 f"fields: {', '.join(sorted(self._fields))}")
        value = _build(self, field)
        if field.kind != "dense":             # a dense copy is rebuilt on every read
            self.__dict__[attr] = value
        return value

    def __setattr__(self, attr, value):
        if attr not in self._fields or self._fields[attr].kind == "dense":
            raise AttributeError(f"{self._category} accessor field {attr!r} cannot be assigned")
        target = getattr(self, attr)
        try:
            target[...] = value
        except (ValueError, TypeError) as exc:
            raise type(exc)(f"cannot assign to {self._category} {attr} of shape "
                            f"{target.shape}: {exc}") from None

    def __dir__(self):
        return sorted(set(self._fields) | {"id", "name"})

    def __repr__(self):
        owner = "MjModel" if self._side == "model" else "MjData"
        return f"<{owner} {self._category} {self.name!r} (id {self.id})>"


def _build(acc, field):
    """The view (or, for a dense row, the copy) of one field of one element."""
    m, i = acc._m, acc.id
    dtype = DTYPES[field.elem]
    pointer = getattr(acc._pointer, field.name)
    columns = field.columns if isinstance(field.columns, int) else field.columns(m)
    kind = field.kind
    if kind == "row":
        return view(pointer + i * columns, dtype, (columns,), acc._root)
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
        rowadr, rownnz, colind = (getattr(acc._pointer, name) for name in field.params)
        dense = np.zeros(m.nv)
        start, count = rowadr[i], rownnz[i]
        for k in range(start, start + count):
            dense[colind[k]] = pointer[k]
        return dense
    raise ValueError(f"unknown kind of named field {kind!r}")


_QPOS_WIDTH = {0: 7, 1: 4}      # mjJNT_FREE, mjJNT_BALL; slide and hinge take 1
_DOF_WIDTH = {0: 6, 1: 3}


def _joint_span(m, i, kind):
    widths = _QPOS_WIDTH if kind == "qpos" else _DOF_WIDTH
    adr = m.jnt_qposadr[i] if kind == "qpos" else m.jnt_dofadr[i]
    return adr, widths.get(m.jnt_type[i], 1)


def _plastic_span(m, i, adr_field):
    """Where element i's plastic state starts in mjData.plastic, and its length:
    up to the next address any joint or tendon starts at, or to nplastic."""
    adr = getattr(m, adr_field)[i]
    if adr < 0:
        return 0, 0
    starts = [a for name, count in (("jnt_plasticadr", m.njnt), ("tendon_plasticadr", m.ntendon))
              for a in ffi.unpack(getattr(m, name), count) if a > adr]
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
        count = getattr(model._ptr, CATEGORIES[category].size)
        if isinstance(key, str):
            element_id = _names(model, category).get(key)
            if element_id is None:
                raise KeyError(_unknown_name(model, category, key))
        elif isinstance(key, (bool, np.bool_)) or not hasattr(key, "__index__"):
            raise TypeError(f"{category}() takes a name (str) or an id (int), "
                            f"not {type(key).__name__}")
        else:
            element_id = key.__index__()
            if not 0 <= element_id < count:
                raise IndexError(f"{category} id {element_id} is out of range: the model has "
                                 f"{count} (ids 0 to {count - 1})")
        # The generated methods look in these first, by the key's exact type
        # (a float or a bool equal to an id must not find it).
        by_id = self.__dict__.setdefault("_named_ids", {}).setdefault(category, {})
        accessor = by_id.get(element_id)
        if accessor is None:
            name = _name_of(model, category, element_id)
            side = "model" if self is model else "data"
            accessor = by_id[element_id] = Accessor(side, category, element_id, name,
                                                    self._ptr, self._root, model._ptr)
            if name:
                self.__dict__.setdefault("_named", {}).setdefault(category, {})[name] = accessor
        return accessor


def _name_of(model, category, element_id):
    m = model._ptr                 # read one name, not a copy of all of them
    start = getattr(m, f"name_{category}adr")[element_id]
    return ffi.string(m.names + start).decode("utf-8")


def _unknown_name(model, category, key):
    known = list(_names(model, category))
    close = difflib.get_close_matches(key, known, n=3)
    hint = f"; did you mean {', '.join(map(repr, close))}?" if close else \
        f"; the model has {len(known)} named" if known else "; the model names none"
    alias = ALIASES.get(category)
    label = f"{category} ({alias})" if alias else category
    return f"no {label} named {key!r}{hint}"
