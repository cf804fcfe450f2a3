"""One thread at a time per spec: the Python side of mjcffi/_c/claims.c.

Every guarded MuJoCo call that takes a spec or one of its elements holds the spec in
C; another thread's call on it raises RuntimeError (MuJoCo's spec functions keep no
lock, and two threads on one spec crash the process).  What mjcffi reads or writes
through MuJoCo outside a guarded call asks here first:

- `check(element, what)`: an element's strings and vectors, before MuJoCo reads or
  writes them.  It costs one memory read while no spec is held anywhere;
- `holding(spec, what)`: an MjSpec method that makes several calls (compile, to_xml,
  copy, ...) holds its spec for the whole method.  The holding thread may nest.

The element's plain fields (`geom.size`, `body.pos`) are NumPy views of the spec's
memory: no call is made, and nothing can refuse them.

Support module: imports only the compiled module and errors.py.
"""

from .errors import raise_pending
from .library import ffi, lib

NULL = ffi.NULL
_HOLDS = ffi.addressof(lib, "mjcffi_spec_holds")    # specs held now, all threads


def check(struct, what):
    """RuntimeError if another thread's call holds the spec of `struct` (a spec
    struct's wrapper); `what` (bytes) names the access."""
    if _HOLDS[0] and lib.mjcffi_element_check(element_of(struct), what):
        raise_pending()


def element_of(struct):
    """The `mjsElement *` of a spec struct wrapper: its own, or for a struct nested in
    an element (a body's plugin, a default's geom) its element's; NULL if none."""
    pointer = struct._ptr
    if hasattr(pointer, "element"):
        return pointer.element
    keep = struct.__dict__.get("_keep")
    owner = keep[1] if isinstance(keep, tuple) else None
    return element_of(owner) if owner is not None else NULL


class holding:
    """`with holding(spec, what):` holds `spec` (an `mjSpec *`) for the block;
    RuntimeError if another thread's call holds it.

    A KeyboardInterrupt may come at any bytecode: taking the spec and recording
    that it was taken are one C-level step (`list.extend` over `map`, no bytecode
    between), anything after it in __enter__ releases on the way out, and the
    release forgets the record before the C call with no bytecode that could
    raise between them.  An __exit__ interrupted before it ran (at its entry)
    releases when this object is collected."""

    _taken = ()                    # until __init__ has run: nothing to release

    def __init__(self, spec, what):
        self._spec = spec
        self._what = what
        self._taken = []           # [0] while held; [1] refused

    def __enter__(self):
        taken = self._taken
        try:
            taken.extend(map(_enter, (self._spec,), (self._what,)))
            if taken[0]:
                raise_pending()    # refused: nothing held
        except BaseException:
            if taken == _HELD:
                del taken[:]
                _leave(self._spec)
            raise
        return self

    def __exit__(self, *exc_info):
        taken = self._taken
        if taken == _HELD:
            del taken[:]           # no bytecode between this and the call can raise
            _leave(self._spec)

    def __del__(self):             # the fallback: an __exit__ interrupted at its entry
        taken = self._taken
        if taken == _HELD:
            del taken[:]
            _leave(self._spec)


_HELD = [0]
_enter = lib.mjcffi_spec_enter
_leave = lib.mjcffi_spec_leave
