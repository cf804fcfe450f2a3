"""MjData: the state and the computed quantities of a simulation of an MjModel.

The fields come from the generated class (mjcffi/structs/mjdata.py); this
adds construction from a model, copying and pickling.
"""

import copy

import numpy as np

from . import _structinfo
from ._library import ffi, lib
from ._views import guarded_result, struct_pointer
from .callbacks import _track
from .structs import mjdata

# Unpickling rebases mjData's pointer fields, seen as 8-byte words of the struct.
_SIZE = ffi.sizeof("mjData")
_WORD = {name: ffi.offsetof("mjData", name) // 8 for name in ("buffer", "arena", "nbuffer",
                                                                "narena")}
_POINTER_WORDS = np.array([ffi.offsetof("mjData", f.name) // 8
                           for f in _structinfo.STRUCTS["mjData"] if f.kind == "pointer"])


class MjData(mjdata.MjData):
    """The simulation state of a model (mjData): `MjData(model)`.

    Arrays such as `d.qpos` are zero-copy NumPy views, built on first use and
    cached; `d.contact` and the `efc_*` arrays are rebuilt on each read
    because their size changes every step.  `d.model` is the model it was
    made for.
    """

    def __init__(self, model):
        pointer = struct_pointer(model, "mjModel", "model")
        root = guarded_result(lib.mjcffi_guard_mj_makeData, pointer)
        if root == ffi.NULL:
            raise MemoryError("mj_makeData could not allocate the mjData")
        self._init_root(ffi.gc(root, lib.mj_deleteData), _model=model)
        _track(self)            # so that callbacks receive this very object

    @property
    def model(self):
        """The MjModel this data was made for."""
        return self._model

    def _adopt_copy(self, model):
        """A new MjData for `model` holding a copy of this one (mj_copyData)."""
        root = guarded_result(lib.mjcffi_guard_mj_copyData, ffi.NULL, model._ptr, self._ptr)
        other = type(self).__new__(type(self))
        other._init_root(ffi.gc(root, lib.mj_deleteData), _model=model)
        _track(other)
        return other

    def __copy__(self):
        return self._adopt_copy(self._model)

    def __deepcopy__(self, memo):
        return self._adopt_copy(copy.deepcopy(self._model, memo))

    def __reduce__(self):
        p = self._ptr
        header = ffi.buffer(p, _SIZE)[:]
        buffer = ffi.buffer(p.buffer, p.nbuffer)[:]
        arena = ffi.buffer(p.arena, p.parena)[:]      # the stack above is scratch
        return (_unpickle, (self._model, header, buffer, arena))


def _unpickle(model, header, buffer, arena):
    """Rebuild an MjData from its pickled bytes, with its pointers rebased.

    The saved struct is copied whole (scalars, counters, fixed arrays); each
    pointer field is then moved from the saved buffer or arena onto the new
    data's own, as one vectorized operation over the struct's pointer words.
    """
    data = MjData(model)
    new = data._ptr
    if len(header) != _SIZE:
        raise ValueError(f"pickled mjData header has {len(header)} bytes, expected {_SIZE}")
    saved = np.frombuffer(header, np.uint64)
    words = np.frombuffer(ffi.buffer(new, _SIZE), np.uint64)
    sizes = saved[_WORD["nbuffer"]], saved[_WORD["narena"]]
    if sizes != (new.nbuffer, new.narena) or len(buffer) != new.nbuffer:
        raise ValueError("pickled MjData does not fit its model (buffer or arena sizes differ)")
    old_buffer, old_arena = saved[_WORD["buffer"]], saved[_WORD["arena"]]
    new_buffer, new_arena = words[_WORD["buffer"]], words[_WORD["arena"]]
    pointers = saved[_POINTER_WORDS]
    in_buffer = (pointers >= old_buffer) & (pointers < old_buffer + sizes[0])
    in_arena = (pointers >= old_arena) & (pointers < old_arena + sizes[1])
    rebased = np.where(in_buffer, pointers - old_buffer + new_buffer,
                       np.where(in_arena, pointers - old_arena + new_arena, 0))
    words[:] = saved
    words[_POINTER_WORDS] = rebased
    new.threadpool = 0
    ffi.memmove(new.buffer, buffer, len(buffer))
    ffi.memmove(new.arena, arena, len(arena))
    return data
