"""MuJoCo's string tables as tuples of str: mjDISABLESTRING, mjVISSTRING, ...

mujoco.h declares them as `extern const char*` arrays, indexed by an enum
(mjDISABLESTRING[mjDSBL_ACTUATION] == 'Actuation').  Their text is data of
libmujoco, so it is read from the library, once, when this module loads.  A
two-dimensional table (mjVISSTRING, mjRNDSTRING) is a tuple of tuples: for
each flag its name, its default ('0' or '1') and its keyboard shortcut.
"""

from .library import ffi, lib

# every `extern const char*` array of mujoco.h (tests/test_public_names.py checks the cdef)
NAMES = ("mjDISABLESTRING", "mjENABLESTRING", "mjTIMERSTRING", "mjLABELSTRING",
         "mjFRAMESTRING", "mjVISSTRING", "mjRNDSTRING", "mjTOPICSTRING")

__all__ = list(NAMES)


def _read(table):
    """A C array of `const char *` (of any rank) as nested tuples of str."""
    if ffi.typeof(table).item.kind == "array":
        return tuple(_read(row) for row in table)
    return tuple(ffi.string(text).decode("utf-8") for text in table)


for _name in NAMES:
    globals()[_name] = _read(getattr(lib, _name))
del _name
