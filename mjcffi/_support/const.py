"""Read-only wrappers for the structs MuJoCo returns as `const`.

`mjp_getPluginAtSlot`, `mjc_getSDF`, `mjp_findProvider` and the like return MuJoCo's
own global tables, declared `const` in the headers and shared by the whole process:
a write into one (a plugin's `nattribute`) breaks every later model that uses it.
Their wrappers are instances of a read-only subclass of the struct's class: an
assignment raises AttributeError, array fields come back as read-only views, and a
nested struct as another read-only wrapper.  `isinstance(p, MjpPlugin)` still holds.

Support module: imports only views.py (and NumPy).
"""

import numpy as np

from .library import ffi
from .views import Struct

_CLASSES: dict = {}       # struct class -> its read-only subclass
_MADE: set = set()        # the read-only subclasses


def wrap_const(cls, pointer, owner):
    """A returned `const` struct pointer as a read-only `cls` wrapper (None for NULL),
    keeping `owner`'s memory alive as views.wrap does."""
    if pointer == ffi.NULL:
        return None
    return const_class(cls)._wrap(pointer, getattr(owner, "_root", pointer))


def const_class(cls):
    """The read-only subclass of struct class `cls`, made once."""
    made = _CLASSES.get(cls)
    if made is None:
        made = _CLASSES[cls] = type(cls.__name__, (cls,), {
            "__slots__": (), "__module__": cls.__module__, "__qualname__": cls.__qualname__,
            "__doc__": f"{cls.__doc__}\n\nRead-only: MuJoCo returned it as const.",
            "__setattr__": _refuse, "__getattribute__": _read_only,
            "__copy__": _writable_copy, "__deepcopy__": lambda self, memo: _writable_copy(self),
            "__reduce__": _reduce_as_base})
        _MADE.add(made)
    return made


def _base(self):
    return type(self).__mro__[1]


def _refuse(self, name, value):
    if name.startswith("_"):              # the wrapper's own state (its pointer, caches)
        object.__setattr__(self, name, value)
        return
    raise AttributeError(f"{type(self).__name__}.{name} cannot be assigned: MuJoCo returned "
                         f"this {self._cname} as const (it is MuJoCo's own, shared by the "
                         f"whole process)")


def _read_only(self, name):
    value = object.__getattribute__(self, name)
    if name.startswith("_"):
        return value
    if isinstance(value, np.ndarray) and value.flags.writeable:
        value = value.view()
        value.flags.writeable = False
    elif isinstance(value, Struct) and type(value) not in _MADE:
        value = const_class(type(value))._wrap(value._ptr, value._root)
    return value


def _writable_copy(self):
    """A copy is the caller's own: a plain, writable wrapper."""
    return _base(self)._from_bytes(self._bytes())


def _reduce_as_base(self):
    return (_base(self)._from_bytes, (self._bytes(),))
