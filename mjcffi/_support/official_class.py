"""What the official MjModel and MjData classes show that the generated classes add by
these helpers (called from mjcffi/structs/, generated).

- The fields in the class's own `__dict__`.  The official classes hold every field
  there; mjcffi's public MjModel and MjData are hand-written subclasses of the
  generated classes (mjcffi/model.py, data.py), so their fields would live on the
  base only, and code that reads the class dict would find none (MJX's
  `get_data_into` copies only the fields in `mujoco.MjData.__dict__`).  `hoist`
  puts into a subclass's dict the very objects its lookups find, so nothing about
  reading or writing a field changes.  The hot fields (MjData.qpos, ...) are slots
  of the generated class: a slot reads as fast as a plain instance attribute, where
  any other class attribute of that name would slow every read of it.
- `MjModel._sizes` (`sizes`), which MJX reads.
- Writable constraint counts (`efc_count`): the official MjData lets every count be
  written; MJX's `get_data_into` writes ne, nf, nl, ncon and nefc.  These take the
  writes that keep memory safe (see efc_count); the other counts stay read-only.

Support module: imports only the compiled module and the tables.
"""

import operator

import numpy as np

from .library import ffi
from .views import Scalar, _scalar_error
from .._generated.structinfo import STRUCTS

# private names the official class dicts hold that mjcffi has too
_PRIVATE = ("_address", "_sizes")


def hoist(cls):
    """Put into `cls.__dict__` every public attribute (and those of _PRIVATE) that
    `cls` has through its bases, as the object its lookups find there."""
    for klass in cls.__mro__[1:]:
        if klass is object:
            continue
        for name in vars(klass):
            if (name.startswith("_") and name not in _PRIVATE) or name in vars(cls):
                continue
            for owner in cls.__mro__:        # the first in the MRO is what lookups find
                if name in vars(owner):
                    setattr(cls, name, vars(owner)[name])
                    break


def sizes(pointer, count):
    """The `count` mjtSize fields at the head of the struct `pointer` points to (nq
    ... nbuffer of mjModel), as a new read-only int64 array, as the official
    `MjModel._sizes`."""
    values = np.frombuffer(ffi.buffer(pointer, count * ffi.sizeof("mjtSize")),
                           dtype=np.int64).copy()
    values.flags.writeable = False
    return values


# mjData's counts of equality, friction and limit rows: the first rows of efc_*
_ROWS = ("ne", "nf", "nl")
# mjData's arrays with one row per constraint (efc_*[nefc]): (name, bytes per row)
_EFC_ARRAYS = tuple(
    (f.name, ffi.sizeof(f.elem) * int(f.extents[1]))
    for f in STRUCTS["mjData"] if f.kind == "pointer" and f.extents[:1] == ("d.nefc",))


def _rows_fit(pointer, rows):
    """Whether rows 0..rows-1 of every efc_* array lie inside the mjData's arena: what
    MuJoCo reads when it indexes them with ne + nf + nl (mjv_updateScene does)."""
    start = int(ffi.cast("uintptr_t", pointer.arena))
    end = start + pointer.narena
    for name, row in _EFC_ARRAYS:
        at = int(ffi.cast("uintptr_t", getattr(pointer, name)))
        if at and not start <= at + rows * row <= end:
            return False
    return True


def efc_count(name, doc):
    """A property for mjData's `name` (ne, nf, nl, ncon or nefc) that reads it and
    writes it where that keeps memory safe.

    ne, nf and nl label the first rows of the efc_* arrays (equality, friction,
    limit): any values >= 0 whose rows lie inside the arena.  Their sum may exceed
    nefc, as MJX writes them (its nl counts the limit rows that are not active, its
    nefc only the active ones) and the official bindings take them; a step recounts
    them.  ncon and nefc size the arena's arrays: only the value they hold (MJX writes
    them after laying out the arena with `mujoco._functions._realloc_con_efc`, which
    changes them)."""
    def set_value(self, value):
        pointer = self._ptr
        try:
            ffi.new("int *", value)             # a number that a C int holds
        except (TypeError, OverflowError) as error:
            raise _scalar_error(self, name, value, error) from None
        value = operator.index(value)
        if name in _ROWS:
            rows = value + sum(getattr(pointer, row) for row in _ROWS if row != name)
            if value < 0 or not _rows_fit(pointer, rows):
                raise ValueError(
                    f"MjData.{name} = {value} would make ne + nf + nl = {rows} rows, which "
                    f"the efc_* arrays laid out in the arena ({pointer.nefc} rows, "
                    f"{pointer.narena} bytes of arena) cannot hold: the counts must be "
                    f">= 0 and their rows inside the arena")
        elif value != getattr(pointer, name):
            raise ValueError(
                f"MjData.{name} sizes the arrays laid out in the arena: it cannot be set "
                f"to {value} (it is {getattr(pointer, name)}); lay out the arena for new "
                f"counts with mujoco._functions._realloc_con_efc(d, ncon, nefc, nJ)")
        setattr(pointer, name, value)
    # ncon and nefc size views, and keep their value: tests/test_hardening_structs.py
    set_value.keeps_value = name not in _ROWS
    return Scalar(name, operator.attrgetter("_ptr." + name), set_value, doc)
