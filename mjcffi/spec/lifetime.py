"""What becomes of element wrappers when MuJoCo frees elements of a spec.

The element layer (structs/_elements.py) keeps the one wrapper of each element in
a registry per spec and ends a wrapper on request (`invalidate_missing`): its use
then raises instead of reading freed memory.  MuJoCo frees elements in delete (a
body's whole subtree, and what refers to it), fuse_static, discard_visual,
dedup_assets and a compile that fuses or discards.  `freeing` runs such an
operation and then ends the wrapper of every element that is gone, in the spec's
registry and in those of the specs attached to it (their elements moved into it).

Before such an operation, if the spec has wrappers, the operation is first run on
a copy of the spec (mj_copySpec keeps the order of every list; a copy costs about
as much as listing the elements) to learn exactly which elements it frees: those
of a body's subtree, and also those that refer to them (an actuator of a deleted
joint).  A wrapper of one of them whose NumPy views are still held cannot be ended
safely, those arrays pointing into the element: the element layer refuses the
operation (ValueError).  The others have their values taken before the free, so
that they still read as they were, as official.
"""

import weakref

from .._support import marshal as _m
from .._support.library import ffi, lib
from .._support import elements as _elements
from ..structs.mjspec import MjsDefault
from .._support import spec_kinds as kinds


def address(pointer):
    """The address of a C pointer, as the registries key wrappers."""
    return int(ffi.cast("uintptr_t", pointer))


def wrap(spec, pointer):
    """The one wrapper of element `pointer` (an mjs* struct or its mjsElement) of
    `spec`; None for NULL."""
    return _elements.wrap(pointer, spec)


# ------------------------------------------------------------- spec memory

class _Release:
    """The destructor of a spec's root (mj_deleteSpec), holding the roots of the
    specs that must live as long as it does.

    Attaching an element by reference makes two specs share it: the element points
    to the spec that holds it now (for its name, its parent, the errors MuJoCo
    reports) and to the compiler of the spec that made it, while both specs list
    it.  Each spec must then keep the other alive, or a use of the survivor reads
    freed memory.  cffi traverses a root's destructor for the garbage collector,
    so two roots that keep each other this way are freed together, as a cycle,
    once nothing else uses either."""

    __slots__ = ("kept", "__weakref__")

    def __init__(self):
        self.kept = {}

    def __call__(self, pointer):
        lib.mj_deleteSpec(pointer)


# spec address -> the _Release of its root
_RELEASES: weakref.WeakValueDictionary = weakref.WeakValueDictionary()


def own_spec(pointer):
    """The root of a new mjSpec * (not NULL): a pointer that frees it when collected,
    which `keep_together` can bind to another."""
    release = _Release()
    root = ffi.gc(pointer, release)
    _RELEASES[address(pointer)] = release
    return root


def keep_together(a_root, b_root):
    """Keep the specs of two roots alive as long as either is; False (nothing done)
    when a root was not made by `own_spec`."""
    a, b = _RELEASES.get(address(a_root)), _RELEASES.get(address(b_root))
    if a is None or b is None:
        return False
    a.kept[address(b_root)] = b_root
    b.kept[address(a_root)] = a_root
    return True


# ------------------------------------------------------------------ survey

def elements_in_order(c_spec):
    """Every listed element of a spec: {mjtObj: [mjsElement *, ...]} in list order."""
    found = {}
    for type_ in kinds.BY_TYPE:
        items = found[type_] = []
        element = lib.mjcffi_guard_mjs_firstElement(c_spec, type_)
        while element != ffi.NULL:
            items.append(element)
            element = lib.mjcffi_guard_mjs_nextElement(c_spec, element)
    _m.check_error()
    return found


def _wraps(tendon):
    """The mjsWrap elements of a tendon's path, in order."""
    c_tendon = lib.mjs_asTendon(tendon)
    return [lib.mjs_getWrap(c_tendon, i).element for i in range(lib.mjs_getWrapNum(c_tendon))]


def _live(c_spec):
    """Addresses of the listed elements of a spec and of its tendons' wraps."""
    listed = elements_in_order(c_spec)
    live = {address(e) for items in listed.values() for e in items}
    for tendon in listed[int(kinds.mjtObj.mjOBJ_TENDON)]:
        live.update(address(w) for w in _wraps(tendon))
    return live


def family(spec):
    """`spec` and the specs attached to it, at any depth: their registries hold
    wrappers of elements that now live in `spec`."""
    found, todo = [], [spec]
    while todo:
        current = todo.pop()
        if all(current is not f for f in found):
            found.append(current)
            todo.extend(current.__dict__.get("_attached", ()))
    return found


def _registered(specs):
    return [w for s in specs for w in _elements.registered(s)]


def _default_names_of(wrappers):
    """{address: class name} of the default wrappers among `wrappers`: defaults are
    in no list, so a default is found again by its name."""
    return {address(w._ptr.element): w.name for w in wrappers
            if isinstance(w, MjsDefault)}


def end_missing(specs, defaults, taken=None):
    """End every wrapper in the registries of `specs` whose element MuJoCo freed;
    `defaults` is _default_names_of the wrappers from before the operation, `taken`
    the values the freed ones keep (by element address)."""
    alive = set()
    for s in specs:
        alive |= _live(s._ptr)
        for name in defaults.values():
            found = lib.mjs_findDefault(s._ptr, name.encode())
            if found != ffi.NULL:
                alive.add(address(found.element))
    for s in specs:
        _elements.invalidate_missing(s, alive, taken)


# ----------------------------------------------------- freeing operations

def _identity(pointer):
    return pointer


class _Counterparts:
    """Maps an element of a spec to the same element of its copy (same list, same
    place; a default by name; a wrap by its tendon and place).  A kind whose list
    the copy does not keep whole (mj_copySpec leaves the plugins out) is not
    mapped: its elements are `unmapped`."""

    def __init__(self, c_spec, c_copy):
        self.c_copy = c_copy
        self.pairs, self.unmapped = {}, set()
        ours, theirs = elements_in_order(c_spec), elements_in_order(c_copy)
        for type_, items in ours.items():
            if len(items) == len(theirs[type_]):
                self.pairs.update((address(a), b) for a, b in zip(items, theirs[type_]))
            else:
                self.unmapped.update(address(a) for a in items)
        tendons = int(kinds.mjtObj.mjOBJ_TENDON)
        if len(ours[tendons]) == len(theirs[tendons]):
            for a, b in zip(ours[tendons], theirs[tendons]):
                self.pairs.update((address(x), y) for x, y in zip(_wraps(a), _wraps(b)))

    def element(self, pointer):
        """The copy's mjsElement * of `pointer` (an mjsElement * of the original)."""
        if int(pointer.elemtype) == int(kinds.mjtObj.mjOBJ_DEFAULT):
            found = lib.mjs_findDefault(self.c_copy, lib.mjs_getString(lib.mjs_getName(pointer)))
            if found == ffi.NULL:
                raise KeyError("the default is not in the copy")
            return found.element
        return self.pairs[address(pointer)]


def _freed_by(spec, operation, wrappers):
    """The wrappers among `wrappers` whose elements `operation` would free, learned
    by running it on a copy of the spec.  Where that cannot be learned they all
    count as freed, the safe side (their views refused, their values taken): those
    of an unmapped kind, and all of them for a spec attached to another by
    reference (MuJoCo refuses to copy one whose body was attached, and a copy of
    one attached whole crashes when edited; MuJoCo refuses these operations on an
    attached spec anyway)."""
    if spec.__dict__.get("_by_reference"):
        return list(wrappers)
    c_copy = lib.mjcffi_guard_mj_copySpec(spec._ptr)
    _m.check_error()
    if c_copy == ffi.NULL:
        return list(wrappers)
    c_copy = ffi.gc(c_copy, lib.mj_deleteSpec)
    counterparts = _Counterparts(spec._ptr, c_copy)
    defaults = _default_names_of(wrappers)
    try:
        operation(c_copy, counterparts.element)
    except Exception:       # noqa: BLE001  the real run raises it again, or not
        pass
    survivors = _live(c_copy)
    doomed = []
    for wrapper in wrappers:
        key = address(wrapper._ptr.element)
        if key in defaults:
            gone = lib.mjs_findDefault(c_copy, defaults[key].encode()) == ffi.NULL
        elif key in counterparts.pairs:
            gone = address(counterparts.pairs[key]) not in survivors
        else:
            gone = key in counterparts.unmapped
        if gone:
            doomed.append(wrapper)
    return doomed


def freeing(spec, action, operation, rehearsal=None):
    """Run `operation(c_spec, counterpart)`, which may free elements of `spec`, and
    return its result; `counterpart(element)` is the element itself here, its
    copy's in the dry run, which runs `rehearsal` (default: `operation`).

    The dry run tells which wrappers lose their element.  If one of them still
    has NumPy views held, the element layer refuses (ValueError, naming `action`)
    and nothing is freed; otherwise their values are taken, so that after the
    operation they read as they were (`body.name`, as official) while any other
    use raises.  Every wrapper of a freed element is ended, even if the
    operation raised."""
    specs = family(spec)
    wrappers = [w for w in _registered(specs) if not is_deleted(w)]
    doomed = _freed_by(spec, rehearsal or operation, wrappers) if wrappers else []
    _elements.check_releasable(doomed, action)
    taken = {address(w._ptr.element): _elements.take(w) for w in doomed}
    defaults = _default_names_of(wrappers)
    try:
        return operation(spec._ptr, _identity)
    finally:
        end_missing(specs, defaults, taken)


def is_deleted(wrapper):
    """Whether `wrapper` is the ended wrapper of an element that MuJoCo freed."""
    return isinstance(wrapper, _elements.DeletedElement)
