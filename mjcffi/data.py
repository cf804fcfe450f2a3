"""MjData: the state and the computed quantities of a simulation of an MjModel.

The fields come from the generated class (mjcffi/structs/mjdata.py); this
adds construction from a model, copying and pickling.
"""

import copy

from ._library import ffi, lib
from ._views import guarded_result, struct_pointer
from .callbacks import _track
from .named import MjDataNames, NamedAccess
from .structs import mjdata

_SIZE = ffi.sizeof("mjData")


class MjData(NamedAccess, MjDataNames, mjdata.MjData):
    """The simulation state of a model (mjData): `MjData(model)`.

    Arrays such as `d.qpos` are zero-copy NumPy views, built on first use and
    cached; `d.contact` and the `efc_*` arrays are rebuilt on each read
    because their size changes every step.  `d.model` is the model it was
    made for.  Named access: `d.joint('hinge').qpos`, and one such method per
    name category that has mjData fields (mjcffi/named.py).
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

    @property
    def _address(self):
        """The address of the mjData in memory, as an int (as the official's)."""
        return int(ffi.cast("uintptr_t", self._ptr))

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
    """Rebuild an MjData from its pickled bytes (mjcffi_restore_data moves its
    pointers onto the new data's own memory)."""
    data = MjData(model)
    p = data._ptr
    if len(header) != _SIZE or len(buffer) != p.nbuffer:
        raise ValueError("pickled MjData does not fit its model (struct or buffer sizes differ)")
    # The plugin instances that mj_makeData just made stay this data's own: the
    # pickled addresses belong to the original data (or to another process), and
    # two datas holding one instance would both free it.  Plugin state proper
    # (plugin_state) is in the buffer and is restored.
    instances = [p.plugin_data[i] for i in range(p.nplugin)]
    if lib.mjcffi_restore_data(p, header, buffer, arena, len(arena)):
        raise ValueError("pickled MjData does not fit its model (buffer or arena sizes differ)")
    for i, address in enumerate(instances):
        p.plugin_data[i] = address
    return data
