"""Laying out an mjData's arena for given counts: the official bindings' private
`mujoco._functions._realloc_con_efc` and `_realloc_island`.

MuJoCo allocates the contacts, the constraint rows and the islands of a step in
the mjData's arena.  Code that computes them elsewhere (MJX, MuJoCo Warp) and
copies them into an mjData first makes room for them with these functions; the
generated mjcffi/_functions/__init__.py imports them, so that they are found where the
official bindings have them.  The layout itself is C (mjcffi_realloc_con_efc
and mjcffi_realloc_island in _helper.c), from mjxmacro.h's lists.

A support module: it imports only the compiled module and the support modules.
"""

from .errors import FatalError, with_note
from .library import ffi, lib
from .views import int_argument, struct_pointer

_INT_MAX = 2**31 - 1


def _count(value, argname):
    value = int_argument(value, argname)
    if value > _INT_MAX:
        raise TypeError(f"{argname} must fit in a C int, not {value}")
    return value


def _overflow(d, function, counts):
    """MuJoCo's message when the arena is too small; the request in a note."""
    size = ffi.string(lib.mju_writeNumBytes(d.narena)).decode()
    error = FatalError(f'Insufficient arena memory, currently allocated memory="{size}". '
                       f'Increase using <size memory="X"/>.')
    request = ", ".join(f"{name}={value}" for name, value in counts.items())
    negative = any(value < (-1 if name == "nJ" else 0) for name, value in counts.items())
    why = ("a negative count" if negative else
           f"more than the {d.narena - d.pstack} bytes of arena that the stack leaves")
    return with_note(error, f"{function}({request}) needs {why}; its counts are now 0")


def _realloc_con_efc(d, ncon, nefc, nJ=-1):
    """Lay out d's arena for ncon contacts and nefc constraint rows with nJ Jacobian
    entries (nJ -1: keep d.nJ), as MuJoCo does: d.contact has ncon entries and the
    efc_* arrays nefc rows (efc_J nJ entries).  Every other arena array (islands,
    dual solver products, effective metric) is dropped and its count set to 0.

    Raises FatalError when the arena is too small; then d.ncon, d.nefc, d.nJ and
    every other count of rows are 0.
    """
    c_d = struct_pointer(d, "mjData", "d")
    counts = {"ncon": _count(ncon, "ncon"), "nefc": _count(nefc, "nefc"), "nJ": _count(nJ, "nJ")}
    if lib.mjcffi_realloc_con_efc(d.model._ptr, c_d, *counts.values()):
        raise _overflow(c_d, "_realloc_con_efc", counts)


def _realloc_island(d, nisland, nidof):
    """Lay out d's island arrays for nisland islands over nidof dofs, as MuJoCo does.

    The old island arrays' memory is reused when nothing follows them in the
    arena; otherwise the new ones go after everything, so that arrays laid out
    later (the dual solver's efc_Y, the effective metric's efm_*) stay intact.
    Raises FatalError when the arena is too small; then d.nisland = d.nidof = 0.
    """
    c_d = struct_pointer(d, "mjData", "d")
    counts = {"nisland": _count(nisland, "nisland"), "nidof": _count(nidof, "nidof")}
    if lib.mjcffi_realloc_island(d.model._ptr, c_d, *counts.values()):
        raise _overflow(c_d, "_realloc_island", counts)
