"""MjData: the state and the computed quantities of a simulation of an MjModel.

The fields come from the generated class (mjcffi/structs/mjdata.py); this
adds construction from a model, copying and pickling.
"""

import copy

from ._support.errors import FatalError, with_note
from ._support.library import ffi, lib
from ._support.views import guarded_result, struct_pointer
from ._support import bind as _bind
from ._support.callbacks import _register_class, _track
from ._support.named import MjDataNames, NamedAccess
from ._support import official_pickle as _official_pickle
from ._support import official_objects as _official_objects
from ._support.official import is_official
from .model import MjModel
from .structs import mjdata

_HEADER_SIZE = lib.mjcffi_data_header_size()
_LAYOUT_SIZE = lib.mjcffi_data_layout_size()
_new_unzeroed = ffi.new_allocator(should_clear_after_alloc=False)




@_register_class        # callbacks wrap foreign pointers with it
class MjData(NamedAccess, MjDataNames, mjdata.MjData):
    """The simulation state of a model (mjData): `MjData(model)`.

    Arrays such as `d.qpos` are zero-copy NumPy views, built on first use and
    cached; `d.contact` and the `efc_*` arrays are cached too, and checked on
    each read against their count and address, which a step may change (a new
    view then).  `d.model` is the model it was
    made for.  Named access: `d.joint('hinge').qpos`, and one such method per
    name category that has mjData fields (mjcffi/_support/named.py).
    """

    def __init__(self, model):
        pointer = struct_pointer(model, "mjModel", "model")
        root = guarded_result(lib.mjcffi_guard_mj_makeData, pointer)
        if root == ffi.NULL:
            raise MemoryError("mj_makeData could not allocate the mjData")
        self._init_root(ffi.gc(root, lib.mj_deleteData), _model=model)
        _track(self)            # so that callbacks receive this very object

    @classmethod
    def from_official(cls, d, model=None) -> "MjData":
        """A zero-copy mjcffi view of `d`, an MjData of the official bindings
        (`import mujoco`) in this process.

        The view and `d` share the C mjData: a write through either (`qpos`, a step)
        is seen by the other.  The view holds `d` alive, and never frees it.
        `model` is the view's `.model`: by default `MjModel.from_official(d.model)`;
        or an official MjModel (wrapped so); or an mjcffi MjModel, such as a
        `from_official` view of `d.model`.  It must have the sizes of the model `d`
        was made for (ValueError).  Both bindings must run on the one loaded
        libmujoco (ValueError); anything but an official MjData is a TypeError.
        Pickling the view gives a plain mjcffi MjData (and MjModel) of the same
        contents.  See also `to_official`.
        """
        root = _official_objects.borrow(d, "mjData", "d")
        made_for = d.model            # the official MjModel that d was made for
        if model is None:
            model = MjModel.from_official(made_for)
        elif is_official(model):
            _official_objects.borrow(model, "mjModel", "model")    # errors name `model`
            model = MjModel.from_official(model)
        elif not isinstance(model, MjModel):
            raise TypeError(f"model must be an mjcffi.MjModel or an official "
                            f"mujoco.MjModel, not {type(model).__name__}")
        made_for_ptr = _official_objects.model_pointer(made_for, "d.model")
        _official_objects.check_sizes(model._ptr, made_for_ptr, "d", "model")
        self = cls.__new__(cls)
        self._init_root(root, _model=model)
        _track(self)
        return self

    def to_official(self, model=None):
        """A new MjData of the official bindings with this data's contents (a copy,
        by mj_copyData, also when this data is a `from_official` view).

        `model` is the official MjModel the copy is made for; it must have the sizes
        of this data's model (ValueError).  By default: the official MjModel that
        `self.model` views when it came from `MjModel.from_official` (so a view of
        an official data copies back onto the very official model), else a new one,
        `self.model.to_official()`.  `mujoco` is imported here, on first use (see
        MjModel.to_official).
        """
        mujoco = _official_objects.official_package()
        if model is None:
            model = self._model.__dict__.get("_official")
            if model is None:
                model = self._model.to_official()
        pointer = _official_objects.model_pointer(model, "model", wrapping=False)
        _official_objects.check_sizes(pointer, self._model._ptr, "this data", "model")
        copy = mujoco.MjData(model)
        _official_objects.copy_data(model, copy, self._ptr)
        return copy

    @property
    def model(self):
        """The MjModel this data was made for."""
        return self._model

    def bind(self, specs):
        """The data fields of a spec element's compiled counterpart: `d.bind(geom).xpos`.

        `specs` is an element (MjsGeom, MjsJoint, ...) of the MjSpec this
        data's model was compiled from, unchanged since: its named-access
        accessor (the same as `d.geom(id)`), or, for a list of elements, an
        object whose fields join their values in one array (a view when their ids
        are ascending and consecutive, else a copy; assigning to a field writes
        every element's value either way).  See mjcffi/_support/bind.py.
        """
        return _bind.bind(self, specs)

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
        # (model, header, buffer, used arena, layout): no address anywhere (see _helper.h)
        p = self._ptr
        header = ffi.buffer(p, _HEADER_SIZE)[:]
        layout = _new_unzeroed("char[]", _LAYOUT_SIZE)
        if lib.mjcffi_save_layout(p, layout):     # a thread pool, or a stack in use: not ours
            header = bytearray(header)
            lib.mjcffi_clear_local(ffi.from_buffer(header))
            header = bytes(header)
        return (_unpickle, (self._model, header, ffi.buffer(p.buffer, p.nbuffer)[:],
                            ffi.buffer(p.arena, p.parena)[:], ffi.buffer(layout)[:]))

    def __setstate__(self, state):
        """Load an official bindings' pickle of an MjData (with its model): it names
        `mujoco._structs.MjData`, which is this class under `sys.modules['mujoco'] =
        mjcffi` (mjcffi/_support/official_pickle.py).  mjcffi's own pickles never
        come here (__reduce__)."""
        if "_ptr" in self.__dict__:
            raise ValueError("Invalid serialized mjData: the MjData is made already")
        mjb, reader = _official_pickle.split_data(state)
        model = MjModel.from_bytes(mjb)
        _made(self, model)
        parts = _official_pickle.data_parts(model._ptr, self._ptr, reader)
        _restore(self, model, *parts)


def _invalid(detail):
    return with_note(ValueError("Invalid serialized mjData"), detail)


def _unpickle(model, header, buffer, arena, layout=None):
    """Rebuild an MjData from its pickled parts, trusting none of them.

    A fresh MjData of `model` supplies every buffer pointer and its own plugin
    instances; mjcffi_restore_data checks every count against the model and the
    arena, and every arena offset against the arena bytes, before it copies.
    """
    if getattr(model, "_cname", None) != "mjModel":
        raise _invalid(f"the model is a {type(model).__name__}, not an MjModel")
    if layout is None:
        raise _invalid("no layout: pickled by an mjcffi older than this one")
    parts = (("header", header), ("buffer", buffer), ("arena", arena), ("layout", layout))
    for name, part in parts:
        if type(part) is not bytes:
            raise _invalid(f"the {name} is a {type(part).__name__}, not bytes")
    data = MjData.__new__(MjData)
    _made(data, model)
    _restore(data, model, header, buffer, arena, layout)
    return data


def _made(data, model):
    """Make `data` (not yet initialized) a fresh MjData of `model`."""
    try:
        MjData.__init__(data, model)
    except (MemoryError, FatalError) as error:   # the model's sizes come from the pickle too
        raise _invalid(f"its model's MjData cannot be made: {error}") from None


def _restore(data, model, header, buffer, arena, layout):
    """Copy checked pickled parts into `data`, a fresh MjData of `model`."""
    args = (model._ptr, data._ptr, header, len(header), buffer, len(buffer), arena, len(arena),
            layout, len(layout))
    if lib.mjcffi_restore_data(*args, ffi.NULL, 0):
        why = ffi.new("char[]", 256)          # refused, data untouched: ask again for why
        lib.mjcffi_restore_data(*args, why, len(why))
        raise _invalid(ffi.string(why).decode("utf-8", "replace"))
