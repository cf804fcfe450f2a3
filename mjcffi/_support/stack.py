"""Arrays on an mjData's stack: what mj_stackAllocNum, mj_stackAllocInt and
mj_stackAllocByte return.

Each is a NumPy view of exactly the size asked for, in the mjData's arena, and it
keeps the MjData alive, so it never shows memory outside that arena.

MuJoCo releases the allocation later: mj_freeStack pops the frame it was made in,
and mj_resetData (also when mj_step, mj_step1, mj_step2, mj_checkPos/Vel/Acc, a
rollout or MjSimPool.step reset a bad state), mj_resetDataDebug,
mj_resetDataKeyframe, mj_copyData and mjv_copyData empty the whole stack.  MuJoCo
then hands those bytes out again, to the next allocation or to its own
temporaries.  So when one of those calls releases an array, mjcffi makes it
read-only: a write raises ValueError, and a read shows whatever MuJoCo has put
there since.  A view taken from the array before the release (`a[2:]`) does not
follow: keep the array itself, not views of it.  A raw `lib` call that releases
them does not freeze them either.

A prepared call (prepared.py) would keep writing through its pointer after the
release, into the array allocated there next: prepare refuses stack arrays (`of`).

Support module: imports only the compiled module, views.py and NumPy.
"""

import weakref

import numpy as np

from .library import ffi
from .views import view

live = False       # some stack array may be unreleased: the releasing calls sweep
_arrays: dict = {}  # mjData address -> [(weakref to the array, d->pstack just after it)]
made: dict = {}     # id -> weakref of every stack array alive, released or not (for prepare)


def _data(d):
    """(the mjData pointer, what keeps it alive) of an MjData or a raw `mjData *` cdata
    (which the functions take too: its caller keeps it alive, as for any raw call)."""
    pointer = getattr(d, "_ptr", None)
    return (d, d) if pointer is None else (pointer, d._root)


def array(d, pointer, count, dtype):
    """The view of `count` `dtype` elements that a stack allocation of `d` returned."""
    global live
    data, owner = _data(d)
    a = view(pointer, dtype, (count,), owner)
    if count:
        key = int(ffi.cast("uintptr_t", data))
        _arrays.setdefault(key, []).append((weakref.ref(a), data.pstack))
        made[id(a)] = weakref.ref(a, lambda _, key=id(a): made.pop(key, None))
        live = True
    return a


def of(array):
    """The stack array whose memory `array` (an ndarray) shares, or None.  A view of
    a stack array (`a[1:]`) has the same memory but not the array as its base."""
    for ref in list(made.values()):
        a = ref()
        if a is not None and np.may_share_memory(array, a):
            return a
    return None


def sweep(d):
    """After a call that may have released `d`'s stack: make the arrays it released
    read-only.  An allocation ends `pstack` bytes below the stack's bottom; it is
    released once d->pstack is below that."""
    global live
    data, _ = _data(d)
    key = int(ffi.cast("uintptr_t", data))
    entries = _arrays.get(key)
    if not entries:
        return
    pstack = data.pstack
    kept = []
    for ref, top in entries:
        a = ref()
        if a is None:
            continue
        if pstack < top:
            a.flags.writeable = False
        else:
            kept.append((ref, top))
    if kept:
        _arrays[key] = kept
    else:
        del _arrays[key]
        live = bool(_arrays)
