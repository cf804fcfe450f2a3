"""Checks of the generated functions beyond mjcffi/_support/marshal.py's: the value of an
argument declared as a C enum, and a scene against the model it is used with.

Hand-written, beside the generated modules of mjcffi/structs/ (the scene's
constructor records what it was made for, and zeroes its fresh buffers, here); imports
only numpy, the compiled module and official.py.
"""

import operator
import reprlib
import weakref

import numpy as np

from . import official as _official
from .library import ffi

NULL = ffi.NULL


# ------------------------------------------------------------------ enums

def enum_value(value, values, name, enum):
    """`value` as an int, which must be one of `values`, the members of C enum `enum`
    (MuJoCo follows such an argument unchecked: mjs_findElement's mjtObj type)."""
    try:
        number = operator.index(value)
    except TypeError:
        raise TypeError(f"{name} must be an int (a value of {enum}), "
                        f"not {type(value).__name__}") from None
    if number not in values:
        raise ValueError(f"{name}={reprlib.repr(number)} is not a value of {enum}: it must be "
                         f"within {_spans(values)} (mjcffi.{enum})")
    return number


def _spans(values):
    """'0..26 or 100..102': the sorted values as runs."""
    runs, ordered = [], sorted(values)
    start = previous = ordered[0]
    for value in ordered[1:] + [None]:
        if value is not None and value == previous + 1:
            previous = value
            continue
        runs.append(f"{start}..{previous}" if previous > start else str(start))
        if value is not None:
            start = previous = value
    return " or ".join(runs)


# ------------------------------------------------------------------ scenes
#
# mjv_makeScene sizes a scene's flex and skin buffers by its model, and MuJoCo
# then writes a model's flexes and skins into them unchecked (mjv_updateScene,
# mjv_updateSkin; mjv_select reads them).  So an MjvScene records, when made,
# what sized them, and those functions check it against their model.

_FLEX_SIZES = ("nflex", "nflexvert", "nflexedge", "nflexelem")
# per flex, what mjv_makeScene counts the faces it allocates from (ints)
_FLEX_ARRAYS = ("flex_dim", "flex_elemadr", "flex_elemnum", "flex_shellnum")
_INT = ffi.sizeof("int")


def _ints(pointer, count):
    return ffi.buffer(pointer, count * _INT)[:] if count else b""


def layout(model):
    """(flex, skin) of C mjModel `model` (or NULL): what mjv_makeScene sizes a scene's
    flex and skin buffers by; None for a part the model does not have."""
    if model == NULL:
        return None, None
    flex = skin = None
    nflex = model.nflex
    if nflex:
        flex = (tuple(getattr(model, name) for name in _FLEX_SIZES)
                + tuple(_ints(getattr(model, name), nflex) for name in _FLEX_ARRAYS)
                + (_ints(model.flex_elemlayer, model.nflexelem),))
    if model.nskin:
        skin = (model.nskin, model.nskinvert)
    return flex, skin


def _buffers(scn, nflex):
    """The scene's buffers and the face addresses MuJoCo writes at, which only a remake
    outside mjcffi or writes into scn.flexfaceadr / flexfacenum change."""
    state = (scn.flexvert, scn.flexface, scn.skinvert)
    if not nflex:
        return state
    return state + (_ints(scn.flexfaceadr, nflex), _ints(scn.flexfacenum, nflex))


class _Made:
    """What an MjvScene was made for: the layout, its buffers then, and the last model
    found to fit (a weak reference: a model freed since cannot pass for a new one)."""
    __slots__ = ("layout", "buffers", "fits")

    def __init__(self, layout, buffers):
        self.layout, self.buffers, self.fits = layout, buffers, None


# mjv_makeScene mallocs the scene's geoms and the buffers that mjv_updateScene fills
# later, and leaves them as the heap had them.  A client that fills a marker geom
# field by field (not through mjv_initGeom) then hands mjr_render whatever was there
# (a matid of 0x55xx from a freed block); zeroed, such a client sees the same scene
# each run, as it did where the heap happened to be fresh.  The buffers that MuJoCo
# fills from the model (flexedgeadr, skinvertnum, ...) are left as it set them.
def _zero(pointer, count, ctype):
    """Zero `count` items of C type `ctype` at `pointer` (cffi has no memset)."""
    if count > 0:
        np.frombuffer(ffi.buffer(pointer, count * ffi.sizeof(ctype)), np.uint8)[:] = 0


def _zero_buffers(scn, model):
    """Zero what mjv_makeScene allocated in C mjvScene `scn` (made for C mjModel `model`,
    or NULL) and left unset: geoms, geomorder and the flex and skin output buffers."""
    _zero(scn.geoms, scn.maxgeom, "mjvGeom")
    _zero(scn.geomorder, scn.maxgeom, "int")
    if model == NULL:
        return                            # no flexes or skins were allocated
    if scn.nflex:
        nface = sum(scn.flexfacenum[f] for f in range(scn.nflex))
        _zero(scn.flexfaceused, scn.nflex, "int")
        _zero(scn.flexvert, 3 * model.nflexvert, "float")
        if nface:                         # else MuJoCo leaves the face buffers NULL
            _zero(scn.flexface, 9 * nface, "float")
            _zero(scn.flexnormal, 9 * nface, "float")
            _zero(scn.flextexcoord, 6 * nface, "float")
    if scn.nskin:
        _zero(scn.skinvert, 3 * model.nskinvert, "float")
        _zero(scn.skinnormal, 3 * model.nskinvert, "float")


def made_for(scene, model):
    """Record in MjvScene `scene` that mjv_makeScene made it for C mjModel `model`
    (NULL: none), as its constructor and mjcffi's mjv_makeScene do right after making
    it; first zero the buffers that MuJoCo left unset (_zero_buffers)."""
    _zero_buffers(scene._ptr, model)
    made = layout(model)
    nflex = made[0][0] if made[0] else 0
    scene.__dict__["_made_for"] = _Made(made, _buffers(scene._ptr, nflex))


def scene(model, scn, c_scn, name="scn"):
    """Check that scene `scn` (its C pointer `c_scn`) was made for a model with the flex
    and skin layout of C mjModel `model`, which the call writes into its buffers."""
    if not model.nflex and not model.nskin:
        return                        # nothing of the model's goes into the buffers
    made = getattr(scn, "__dict__", {}).get("_made_for")
    if made is None:
        if _official.is_official(scn):
            raise _official.not_accepted(name, "MjvScene", scn)
        given = "a raw mjvScene pointer" if isinstance(scn, ffi.CData) else type(scn).__name__
        raise TypeError(f"{name} must be an MjvScene made by MjvScene(m, maxgeom) or "
                        f"mjv_makeScene, not {given}: for a model with flexes or skins, what "
                        f"its buffers were made for must be known")
    flex = made.layout[0]
    if _buffers(c_scn, flex[0] if flex else 0) != made.buffers:
        raise ValueError(f"{name}'s buffers were changed outside mjcffi (a raw "
                         f"lib.mjv_makeScene, or writes into {name}.flexfaceadr or "
                         f"{name}.flexfacenum): MuJoCo would write past them; make it again "
                         f"with mjv_makeScene(m, {name}, maxgeom)")
    if made.fits is not None and made.fits() is model:
        return                        # the model of the last call, checked then
    _fits(made.layout, layout(model), name)
    try:
        made.fits = weakref.ref(model)
    except TypeError:                 # a cdata that takes no weak reference: check each time
        made.fits = None


def _fits(have, need, name):
    for part, made, needed in (("flexes", have[0], need[0]), ("skins", have[1], need[1])):
        if needed is not None and made != needed:
            raise ValueError(f"{name} was made for {_model(have)}, not for this model "
                             f"({_counts(*need)}): MuJoCo would write this model's {part} past "
                             f"its buffers; make it for this model with MjvScene(m, maxgeom) "
                             f"or mjv_makeScene(m, {name}, maxgeom)")


def _model(made):
    if made == (None, None):
        return "no model, or one without flexes and skins"
    return f"another model ({_counts(*made)})"


def _counts(flex, skin):
    nflex, nflexvert = (flex[0], flex[1]) if flex else (0, 0)
    nskin, nskinvert = skin if skin else (0, 0)
    return f"nflex {nflex}, nflexvert {nflexvert}, nskin {nskin}, nskinvert {nskinvert}"
