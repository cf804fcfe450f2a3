"""Typed handles of the values a spec owns that mjspec.h declares as `void`.

mjspec.h declares mjString, mjStringVec, mjIntVec, mjDoubleVec, ... as
`typedef void`, so cffi sees every one as `void *` and MuJoCo would take any
pointer for any of them: another kind of handle, an mjData stack pointer or
memory of ffi.new would crash it.  Here each kind has its class; a handle holds
the pointer and the spec's memory (`_root`), so it keeps the spec alive.  The
generated struct classes give handles for their fields of these types, the
generated functions return them and take, for an argument of one kind, only a
handle of that kind (codegen/functions.py and codegen/structs.py write the
calls below).

Hand-written, beside the generated modules of mjcffi/structs/ that use it (as
is _checks.py); it imports only the compiled module.  The spec elements' str and
list attributes are built on these handles (_element_fields.py,
_element_vectors.py); `handle` gives the handle of such a field for the raw functions.
"""

from .library import ffi

NULL = ffi.NULL


class Handle:
    """A pointer to a value of one kind that a spec owns (an mjString, ...).

    Handles compare equal when they are of one kind and point to one value.
    They are made by the struct fields and functions that give them, never
    from Python, and hold an address: they cannot be copied or pickled.
    """

    __slots__ = ("_ptr", "_root")
    _kind = ""                    # the C type, as mjspec.h names it

    def __init__(self, *args, **kwargs):
        raise TypeError(f"{type(self).__name__} has no constructor: spec elements and "
                        f"functions such as mjs_getName hand them out")

    @classmethod
    def _wrap(cls, pointer, root):
        self = object.__new__(cls)
        self._ptr = pointer
        self._root = root
        return self

    @property
    def _address(self):
        return int(ffi.cast("uintptr_t", self._ptr))

    def __eq__(self, other):
        if not isinstance(other, Handle):
            return NotImplemented
        return other._kind == self._kind and other._ptr == self._ptr

    def __hash__(self):
        return hash((self._kind, self._address))

    def __repr__(self):
        return f"<{type(self).__name__} ({self._kind} *) at {hex(self._address)}>"

    def __reduce__(self):
        raise TypeError(f"{type(self).__name__} holds an address into its spec: it cannot be "
                        f"copied or pickled")


class MjStringHandle(Handle):
    """mjString *: a string that a spec owns (MjsBody.childclass, mjs_getName)."""
    __slots__ = ()
    _kind = "mjString"


class MjStringVecHandle(Handle):
    """mjStringVec *: a vector of strings that a spec owns (MjsTexture.cubefiles)."""
    __slots__ = ()
    _kind = "mjStringVec"


class MjIntVecHandle(Handle):
    """mjIntVec *: a vector of ints that a spec owns (MjsFlex.elem)."""
    __slots__ = ()
    _kind = "mjIntVec"


class MjIntVecVecHandle(Handle):
    """mjIntVecVec *: a vector of int vectors that a spec owns."""
    __slots__ = ()
    _kind = "mjIntVecVec"


class MjFloatVecHandle(Handle):
    """mjFloatVec *: a vector of floats that a spec owns (MjsMesh.uservert)."""
    __slots__ = ()
    _kind = "mjFloatVec"


class MjFloatVecVecHandle(Handle):
    """mjFloatVecVec *: a vector of float vectors that a spec owns."""
    __slots__ = ()
    _kind = "mjFloatVecVec"


class MjDoubleVecHandle(Handle):
    """mjDoubleVec *: a vector of doubles that a spec owns (MjsBody.userdata)."""
    __slots__ = ()
    _kind = "mjDoubleVec"


class MjByteVecHandle(Handle):
    """mjByteVec *: a vector of bytes that a spec owns (MjsTexture.data)."""
    __slots__ = ()
    _kind = "mjByteVec"


# C type -> its class; tests/test_hardening_functions.py checks that these are
# exactly the `typedef void` types of the headers.
KINDS = {cls._kind: cls for cls in (
    MjStringHandle, MjStringVecHandle, MjIntVecHandle, MjIntVecVecHandle, MjFloatVecHandle,
    MjFloatVecVecHandle, MjDoubleVecHandle, MjByteVecHandle)}


# ------------------------------------------------------- for the generated code

def handle_field(name, kind, doc):
    """A struct field `kind *name` (MjsBody.childclass): read-only, its handle, or None
    for NULL.  Read anew each time, so a value MuJoCo moves is never stale."""
    cls = KINDS[kind]

    def get(self):
        pointer = getattr(self._ptr, name)
        return None if pointer == NULL else cls._wrap(pointer, self._root)
    return property(get, doc=doc)


def handle(obj, name):
    """The handle in field `name` of the spec struct `obj` (MjsBody.childclass as an
    MjStringHandle), for the raw mjs_* functions: the attributes themselves read
    and write these fields as str, arrays and lists (_element_fields.py,
    _element_vectors.py)."""
    from .._generated.structinfo import STRUCTS
    kind = next(f.elem for f in STRUCTS[obj._cname] if f.name == name)
    pointer = getattr(obj._ptr, name)
    return None if pointer == NULL else KINDS[kind]._wrap(pointer, obj._root)


def struct_ref(name, wrapper, doc):
    """A struct field pointing to another struct of the same spec (MjsBody.element): its
    wrapper, which keeps the spec alive, or None for NULL; read-only."""
    def get(self):
        pointer = getattr(self._ptr, name)
        return None if pointer == NULL else wrapper()._wrap(pointer, self._root)
    return property(get, doc=doc)


def argument(value, kind, name, nullable=False):
    """The pointer of `value`, which must be a handle of `kind` (None: NULL where the
    header allows it).  Raw pointers are refused: MuJoCo cannot tell the kinds apart."""
    if value.__class__ is KINDS[kind]:
        return value._ptr
    if value is None and nullable:
        return NULL
    expected = f"{name} must be {_article(kind)} {kind} handle ({KINDS[kind].__name__})"
    if isinstance(value, Handle):
        given = f"{_article(value._kind)} {value._kind} handle"
    elif isinstance(value, ffi.CData):
        given = (f"a raw cffi pointer ({ffi.typeof(value).cname}): MuJoCo declares its "
                 f"handles as void and cannot tell them apart, so only the handles of spec "
                 f"fields and functions are taken")
    elif value is None:
        given = "None"
    else:
        given = type(value).__name__
    raise TypeError(f"{expected}, not {given}")


def result(pointer, kind, owner):
    """A returned `kind *` as its handle, keeping `owner`'s spec alive; None for NULL."""
    if pointer == NULL:
        return None
    return KINDS[kind]._wrap(pointer, getattr(owner, "_root", owner))


def _article(word):
    return "an" if word.startswith("mj") else "a"     # "an mjString" (em-jay)
