"""The one wrapper of each spec element, and what becomes of it when MuJoCo frees
the element.

Every element reached through the spec classes has one wrapper (`wrap`), of the
class `register` recorded for its kind (the generated classes of
mjcffi/structs/mjspec.py, the hand-written subclasses of mjcffi/spec/elements.py);
the registry of its spec holds it weakly (`Registry`, `registered`), and it keeps
its spec alive.

MuJoCo frees an element when it is deleted (mjs_delete frees it at once, a body
with its subtree and what refers to it).  Before that:

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

import sys
import weakref

import numpy as np

from . import marshal as _marshal
from .library import ffi, lib
from .views import Struct, view

NULL = ffi.NULL


# ----------------------------------------------------------- one per element

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


# ------------------------------------------------------ when MuJoCo frees it

class DeletedElementError(ValueError, RuntimeError):
    """A wrapper of a spec element that MuJoCo freed (spec.delete) was used, or
    something read from it: a ValueError, and a RuntimeError as mjcffi raised
    before."""


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
    copies; the live sequences of _element_fields.py and _element_vectors.py as
    their `_frozen` gives them (vectors as arrays, char arrays and string vectors
    as lists)."""
    if isinstance(value, np.ndarray):
        value = np.array(value)
        value.flags.writeable = False
        return value
    frozen = getattr(type(value), "_frozen", None)
    return value if frozen is None else frozen(value)


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
    Struct._forget_memory(wrapper)      # no C read of the freed element (views.Holder)
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
