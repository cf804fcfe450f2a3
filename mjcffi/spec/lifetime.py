"""The element wrappers a spec hands out, and what becomes of them when MuJoCo frees
their elements (delete, and a body's whole subtree with it).

A spec hands out one wrapper per element (`spec.body('a') is spec.body('a')`), kept
in a weak registry keyed by the mjsElement's address.  When MuJoCo frees elements,
every registered wrapper whose element is gone has its pointer replaced by a
`Deleted` marker: reading or writing a field, or passing it to a MuJoCo function,
then raises instead of touching freed memory.  Every wrapper also holds the spec's
own memory (its `_root`), so a spec collected while wrappers exist stays allocated.
"""

import weakref

from .._library import ffi


class DeletedElementError(ValueError):
    """A wrapper of an element that MuJoCo freed was used."""


class Deleted:
    """Stands in for the C pointer of a wrapper whose element was freed."""

    __slots__ = ("_what",)

    def __init__(self, what):
        object.__setattr__(self, "_what", what)

    def _fail(self, *args):
        raise DeletedElementError(f"this {self._what} was deleted from its spec: "
                                  f"it can no longer be used")

    def __getattr__(self, name):
        self._fail()

    __setattr__ = __getitem__ = __setitem__ = _fail

    def __eq__(self, other):
        return self is other

    __hash__ = object.__hash__


def address(pointer):
    return int(ffi.cast("uintptr_t", pointer))


class Registry:
    """The live wrappers of one spec's elements, by mjsElement address."""

    def __init__(self):
        self._wrappers = weakref.WeakValueDictionary()

    def get(self, element_address):
        return self._wrappers.get(element_address)

    def add(self, element_address, wrapper):
        self._wrappers[element_address] = wrapper

    def invalidate_missing(self, live_addresses):
        """Mark dead every wrapper whose element is not among `live_addresses`."""
        for element_address in list(self._wrappers.keys()):
            if element_address not in live_addresses:
                wrapper = self._wrappers.pop(element_address, None)
                if wrapper is not None:
                    invalidate(wrapper)


_DEAD_CLASSES: dict = {}


def _dead_class(cls):
    """The subclass of `cls` that a wrapper of a freed element becomes: every
    attribute read or write raises, so does passing it to a MuJoCo function (which
    reads its `_cname` and `_ptr`)."""
    dead = _DEAD_CLASSES.get(cls)
    if dead is None:
        name = cls.__name__

        def fail(self, *args):
            raise DeletedElementError(f"this {name} was deleted from its spec: "
                                      f"it can no longer be used")

        def getattribute(self, attr):
            if attr in ("__class__", "__dict__"):
                return object.__getattribute__(self, attr)
            fail(self)

        dead = type(name, (cls,), {
            "__getattribute__": getattribute, "__setattr__": fail, "__delattr__": fail,
            "__repr__": lambda self: f"<{name} (deleted)>", "__module__": cls.__module__,
            "__eq__": lambda self, other: self is other, "__hash__": object.__hash__,
            "__reduce__": fail, "__reduce_ex__": fail, "_deleted": True})
        _DEAD_CLASSES[cls] = dead
    return dead


def invalidate(wrapper):
    """Make any later use of `wrapper` raise DeletedElementError."""
    wrapper.__dict__["_ptr"] = Deleted(type(wrapper).__name__)
    object.__setattr__(wrapper, "__class__", _dead_class(type(wrapper)))


def is_deleted(wrapper):
    return isinstance(getattr(wrapper, "__dict__", {}).get("_ptr"), Deleted)


# The generated element layer (structs/_elements.py) keeps one registry per spec for
# every wrapper it makes, add_* included; where it is present, wrappers come from it
# and so do their ends.  Otherwise each MjSpec keeps a Registry of its own.
try:
    from ..structs import _elements as _generated
    _generated.wrap, _generated.invalidate_missing        # noqa: B018
except (ImportError, AttributeError):
    _generated = None  # type: ignore[assignment]


def wrap_element(spec, element, type_, make):
    """The one wrapper of `element` (an mjsElement *, not NULL) of `spec`; `make()`
    builds it when neither registry has one."""
    if _generated is not None:
        return _generated.wrap(element, spec)
    key = address(element)
    wrapper = spec._registry.get(key)
    if wrapper is None:
        wrapper = make()
        spec._registry.add(key, wrapper)
    return wrapper


def end_missing(spec, live_addresses):
    """End every wrapper of `spec`'s elements that MuJoCo freed."""
    if _generated is not None:
        _generated.invalidate_missing(spec, live_addresses)
    spec._registry.invalidate_missing(live_addresses)


def deleted(wrapper):
    """Whether `wrapper` was ended (by either layer)."""
    return is_deleted(wrapper) or "_deleted" in wrapper.__dict__
