"""bind: a spec element's compiled counterpart, `m.bind(geom).size`, `d.bind(joint).qpos`.

`MjModel.bind(element)` and `MjData.bind(element)` take an element of the spec
the model was compiled from (MjsGeom, MjsJoint, ...) and give the named-access
accessor of its compiled id (mjcffi/_support/named.py): `d.bind(geom)` is `d.geom(id)`,
so its fields are the same zero-copy views and writes go through to C.  As in
the official bindings:

- the id is the one MuJoCo gave the element when it compiled (mjs_getId), so
  unnamed elements bind as well as named ones;
- the element's spec must be the one the model was compiled from, unchanged
  since: its signature must be the model's, else ValueError ("The mjSpec does
  not match mjModel. Please recompile the mjSpec.");
- an element deleted from its spec, or one the compiler dropped, has id -1:
  IndexError ("Invalid index -1 ...");
- anything else (a frame, which the compiler folds into its children, a
  default, a number) is a TypeError.

A list (or tuple) of elements binds to a `_MjBindModel` / `_MjBindData`, whose
`elements` are the accessors, `id` and `name` lists, and whose fields are the
elements' values joined in one array:

- when every element's value has one shape, they are stacked: (n, *shape),
  and (n,) for a one-number field, so `d.bind(spec.geoms).xpos` is (ngeom, 3)
  and `d.bind(hinges).qpos` is (n,);
- otherwise (a free joint's 7 qpos beside a hinge's 1) they are concatenated:
  rows of one width end to end ((7, 6) for the cdof of a free joint and a
  hinge), or else one flat array (8 numbers for that qpos).  The official
  bindings give one flat list in every case.

The array is a zero-copy view when the values lie back to back in the C array,
as they do for ascending consecutive ids (spec.geoms of a model compiled from
XML, say); else it is a copy.  Writing through a list binding works in both
cases when you assign to the attribute: `d.bind(joints).qpos = [0.1, 0.2]`,
and `d.bind(joints).qpos += 0.1`, write every element's value, because
assignment writes the copy back.  Writing into the array a read returned
(`d.bind(joints).qpos[0] = 1`) reaches C only when that array is a view.  A
value must have the shape of the array a read gives, or hold one value per
element, as the official bindings take it; a scalar or a wrong length is a
ValueError and writes nothing.  Sparse rows (an actuator's `moment`) are read-only copies.
"""

import math
import re
from collections.abc import Sequence

import numpy as np

from . import marshal as _marshal
from . import official as _official
from .errors import with_note
from .library import ffi, lib
from .._generated.namedinfo import ALIASES, CATEGORIES
from .views import DTYPES, Struct, view
from . import spec_kinds as kinds

__all__ = ["bind"]

_MISMATCH = "The mjSpec does not match mjModel. Please recompile the mjSpec."

# mjtObj of an element -> its named-access category (mjOBJ_JOINT -> 'jnt')
_LONG_TO_CATEGORY = {long: short for short, long in ALIASES.items()}
_CATEGORY_OF = {int(obj): lookup if lookup in CATEGORIES else _LONG_TO_CATEGORY[lookup]
                for _, lookup, obj, _ in kinds.KINDS if obj != kinds.mjtObj.mjOBJ_FRAME}
_KIND_OF_SUFFIX = {suffix: int(obj) for _, _, obj, suffix in kinds.KINDS}


def bind(owner, target):
    """What `owner.bind(target)` gives: `owner` is an MjModel or MjData, `target` a
    spec element (its accessor) or a sequence of them (a _MjBindModel or _MjBindData)."""
    if isinstance(target, Struct):            # an element: the common case first
        return _bind_one(owner, target)
    if isinstance(target, Sequence) and not isinstance(target, (str, bytes)):
        accessors = [_bind_one(owner, element) for element in target]
        cls = _MjBindModel if owner._cname == "mjModel" else _MjBindData
        return cls(accessors)
    return _bind_one(owner, target)


def _bind_one(owner, element):
    """The accessor of `element`'s compiled counterpart in `owner`."""
    try:
        c_element = element._ptr.element
        empty = c_element == ffi.NULL         # the plugin slot of a body holds none
        category = None if empty else _CATEGORY_OF[c_element.elemtype]
    except Exception:        # not an element, one with no counterpart, or a deleted one
        return _refuse(owner, element)
    if empty or lib.mjs_getCompiler(c_element) == ffi.NULL:
        # no element, or a default class's template (default.geom): in no spec
        raise TypeError(f"cannot bind {_label(element)}: it is no element of a spec "
                        f"(a default class's template or an empty plugin slot)")
    model = owner if owner._cname == "mjModel" else owner._model
    spec = lib.mjcffi_guard_mjs_getSpec(c_element)
    _marshal.check_error()
    if spec == ffi.NULL or spec.element.signature != model._ptr.signature:
        raise with_note(ValueError(_MISMATCH),
                        f"{_label(element)} is not in this model: its spec changed since the "
                        f"model was compiled, or the model was compiled from another spec")
    element_id = lib.mjcffi_guard_mjs_getId(c_element)
    _marshal.check_error()
    try:
        return owner._named_ids[category][element_id]      # the accessor made before
    except (AttributeError, KeyError):
        pass
    if owner._cname == "mjData" and not CATEGORIES[category].data:
        raise _no_data_fields(element, category)
    try:
        return owner._accessor(category, element_id)
    except IndexError as exc:
        raise with_note(exc, f"{_label(element)} is not in the compiled model "
                             f"(deleted from its spec, or dropped by the compiler)")


def _refuse(owner, element):
    """The error for what _bind_one cannot bind: a deleted element (IndexError, as
    its id is -1), an element with no compiled counterpart, or no element."""
    deleted = _deleted_kind(element)
    if deleted is not None:
        category = _CATEGORY_OF.get(deleted)
        if category is not None and (owner._cname == "mjModel" or CATEGORIES[category].data):
            try:
                owner._accessor(category, -1)         # the official error for id -1
            except IndexError as exc:
                raise with_note(exc, f"{_label(element)} was deleted from its spec")
        raise IndexError(f"Invalid index -1: {_label(element)} was deleted from its spec")
    try:
        elemtype = element._ptr.element.elemtype
    except Exception:
        if _official.is_official(element):   # both bindings have an MjsGeom: say which
            raise _official.not_accepted("the element", "Mjs", element) from None
        raise TypeError(f"bind takes a spec element (MjsGeom, MjsJoint, ...) or a list of "
                        f"them, not {type(element).__name__}") from None
    if elemtype == lib.mjOBJ_FRAME:
        why = "the compiler folds a frame into the poses of its children"
    else:
        why = "it has no compiled counterpart"
    raise TypeError(f"cannot bind {_label(element)}: {why}; bind a body, geom, joint, site, "
                    f"actuator, sensor or another element the model holds")


def _deleted_kind(element):
    """The mjtObj of a wrapper whose element was deleted from its spec (-1 when its
    label names none); None when `element` is no such wrapper.  The element layer
    (structs/_elements.py) labels such a wrapper in `_deleted`: "MjsBody 'arm'"."""
    state = getattr(element, "__dict__", None)
    label = state.get("_deleted") if isinstance(state, dict) else None
    if not isinstance(label, str):
        return None
    found = re.search(r"Mjs(\w+)", label)
    return _KIND_OF_SUFFIX.get(found.group(1), -1) if found else -1


def _no_data_fields(element, category):
    return TypeError(f"MjData has no fields of a {_long_name(category)}: bind "
                     f"{_label(element)} to the MjModel instead (model.bind(element))")


def _label(element):
    """`MjsGeom 'ball'` (the class, and the name when it has one)."""
    name = ""
    try:
        name = element.name
    except Exception:        # a deleted wrapper, or one with no name
        label = getattr(element, "__dict__", {}).get("_deleted")
        if isinstance(label, str):
            return label
    kind = type(element).__name__
    if isinstance(name, str) and name:
        return f"{kind} {name!r}"
    return f"an unnamed {kind}" if kind.startswith("Mjs") else f"an {kind}"


def _long_name(category):
    return max(category, ALIASES.get(category, category), key=len)


# ------------------------------------------------------------- list binding

class _MjBind:
    """Several spec elements bound to a model or data: their fields as arrays.

    `elements` are the elements' accessors, `id` and `name` lists of their ids
    and names; any other attribute is a field of their category, the elements'
    values joined in one array: stacked when they share a shape, else
    concatenated (see mjcffi/_support/bind.py).  The array is a zero-copy view when
    the values lie back to back in C (ascending consecutive ids), else a copy.
    Assigning to a field writes every element's value in both cases."""

    def __init__(self, elements):
        object.__setattr__(self, "elements", elements)

    @property
    def id(self):
        """The elements' ids in the compiled model, as a list."""
        return [accessor.id for accessor in self.elements]

    @property
    def name(self):
        """The elements' names, as a list ('' for an unnamed element)."""
        return [accessor.name for accessor in self.elements]

    def __getattr__(self, attr):          # reached only for fields not read before
        if attr.startswith("__"):
            raise AttributeError(attr)
        elements = self.__dict__["elements"]
        if not elements:                  # as the official: nothing to read, of any name
            return np.zeros(0)
        self._field(attr)
        value, is_view = _gather(elements, attr)
        if is_view:                       # a view stays right: cache it
            self.__dict__[attr] = value
        return value

    def __setattr__(self, attr, value):
        if attr in ("elements", "id", "name"):
            raise AttributeError(f"{attr!r} of '{type(self).__name__}' cannot be set")
        elements = self.elements
        if not elements:
            if np.size(value) != 0:
                raise ValueError(f"Expected 0 values, got {np.size(value)}")
            return
        if self._field(attr).kind == "dense":
            raise AttributeError(f"{attr!r} of '{type(self).__name__}' is read-only "
                                 f"(a dense copy of sparse rows)")
        target = self.__dict__.get(attr)       # a view read before
        is_view = target is not None
        if not is_view:
            target, is_view = _gather(elements, attr)
        try:
            # the exact shape, as the official: no broadcasting of a scalar or a row
            if np.shape(value) != target.shape:
                raise ValueError(f"Expected {target.shape} values for {attr!r}, "
                                 f"got shape {np.shape(value)}")
            target[...] = value
        except (ValueError, TypeError) as exc:
            if _assign_each(elements, attr, value):       # one value per element
                return
            raise with_note(exc, f"{attr!r} of these {len(elements)} elements has shape "
                                 f"{target.shape}; give that shape, or one value per element")
        if is_view:
            self.__dict__[attr] = target
        else:
            _scatter(elements, attr, target)

    def _field(self, attr):
        """The named-access Field of `attr` (that of the first element's class),
        after checking that every element's accessor class has one."""
        found = None
        for cls in dict.fromkeys(type(accessor) for accessor in self.elements):
            field = cls._fields.get(attr)
            if field is None:
                exc = AttributeError(f"'{type(self).__name__}' object has no attribute "
                                     f"{attr!r}", name=attr, obj=self)
                raise with_note(exc, f"the fields of {_long_name(cls._category)}: "
                                     f"{', '.join(sorted(cls._fields))}")
            found = found or field
        return found

    def __dir__(self):
        fields = {attr for accessor in self.elements for attr in type(accessor)._fields}
        return sorted(set(object.__dir__(self)) | fields)

    def __repr__(self):
        elements = self.elements
        kinds_ = sorted({_long_name(type(a)._category) for a in elements})
        what = "/".join(kinds_) or "element"
        shown = [a.name or a.id for a in elements[:8]]
        more = ", ..." if len(elements) > 8 else ""
        listed = ", ".join(map(repr, shown))
        return f"<{type(self).__name__} of {len(elements)} {what}(s): [{listed}{more}]>"


class _MjBindModel(_MjBind):
    __doc__ = (_MjBind.__doc__ or "").replace("a model or data", "an MjModel (model.bind([...]))")


class _MjBindData(_MjBind):
    __doc__ = (_MjBind.__doc__ or "").replace("a model or data", "an MjData (data.bind([...]))")


# ------------------------------------------------------------ join and split

def _gather(elements, attr):
    """(array, is_view): the elements' values of `attr` joined (see the module)."""
    first = elements[0]
    cls = type(first)
    same = all(type(accessor) is cls for accessor in elements)
    ids = [accessor.id for accessor in elements]
    consecutive = same and ids == list(range(ids[0], ids[0] + len(ids)))
    field = cls._fields[attr]
    if consecutive and field.kind == "row":
        rows = _rows_view(first, field, len(ids))
        if rows is not None:
            return rows, True
    pieces = [getattr(accessor, attr) for accessor in elements]
    shape = _joined_shape([piece.shape for piece in pieces])
    if consecutive and field.kind != "dense":
        joined = _adjacent_view(first, field, pieces, shape)
        if joined is not None:
            return joined, True
    joined = np.concatenate([piece.reshape(-1) for piece in pieces]).reshape(shape)
    if field.kind == "dense":
        joined.flags.writeable = False
    return joined, False


def _rows_view(first, field, count):
    """The view of `count` rows of a per-element array from `first`'s id on."""
    columns = field.columns if isinstance(field.columns, int) else field.columns(first._m)
    pointer = getattr(first._pointer, field.name)
    if pointer == ffi.NULL:
        return None
    shape = (count,) if columns == 1 else (count, columns)
    return view(pointer + first.id * columns, DTYPES[field.elem], shape, first._root)


def _adjacent_view(first, field, pieces, shape):
    """One view over `pieces` when they lie back to back in memory, else None."""
    start = end = None
    for piece in pieces:
        if piece.size == 0:
            continue
        if piece.base is None:            # a new array (memory MuJoCo did not allocate)
            return None
        address = int(ffi.cast("uintptr_t", ffi.from_buffer(piece)))
        if end is not None and address != end:
            return None
        start = address if start is None else start
        end = address + piece.nbytes
    dtype = DTYPES[field.elem]
    if start is None:                     # nothing to view: every value is empty
        return np.zeros(shape, dtype)
    pointer = ffi.cast(ffi.getctype(field.elem, "*"), start)
    return view(pointer, dtype, shape, first._root)


def _joined_shape(shapes):
    """The shape of values of `shapes` joined: stacked if they are all one shape
    ((n,) for one number each), else end to end: rows of their common width when
    some are 2-D or more, else flat."""
    first = shapes[0]
    if all(shape == first for shape in shapes):
        return (len(shapes),) if first == (1,) else (len(shapes), *first)
    widths = {shape[-1] for shape in shapes if shape}
    if len(widths) == 1 and any(len(shape) == 2 for shape in shapes) and \
            all(1 <= len(shape) <= 2 for shape in shapes):
        rows = sum(shape[0] if len(shape) == 2 else 1 for shape in shapes)
        return (rows, widths.pop())
    return (sum(math.prod(shape) for shape in shapes),)


def _scatter(elements, attr, joined):
    """Write the joined copy `joined` back, element by element."""
    flat = joined.reshape(-1)
    offset = 0
    for accessor in elements:
        piece = getattr(accessor, attr)
        piece[...] = flat[offset:offset + piece.size].reshape(piece.shape)
        offset += piece.size


def _assign_each(elements, attr, value):
    """Assign one value per element, as the official bindings do; True when done.
    Every value is checked before any is written."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or \
            len(value) != len(elements):
        return False
    staged = []
    for accessor, item in zip(elements, value):
        piece = getattr(accessor, attr)
        trial = piece.copy()
        try:
            trial[...] = item
        except (ValueError, TypeError):
            return False
        staged.append((piece, trial))
    for piece, trial in staged:
        piece[...] = trial
    return True
