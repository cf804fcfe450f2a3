"""MjModel: a compiled MuJoCo model, loaded from XML or MJB.

The fields come from the generated class (mjcffi/structs/mjmodel.py); this
adds what MuJoCo cannot say in a header: how a model is loaded, copied and
pickled.
"""

from . import _loading
from ._library import ffi, lib
from ._views import guarded_result
from .callbacks import _track
from .named import MjModelNames, NamedAccess
from .structs import mjmodel


class MjModel(NamedAccess, MjModelNames, mjmodel.MjModel):
    """A compiled model (mjModel).

    MjModel has no constructor: use `MjModel.from_xml_path`,
    `MjModel.from_xml_string` or `MjModel.from_binary_path`.  Arrays such as
    `m.body_pos` are zero-copy NumPy views of the model's memory; sizes such
    as `m.nq` are read-only.  Named access: `m.geom('ball').rgba`, and one such
    method per name category (mjcffi/named.py).
    """

    @classmethod
    def _from_root(cls, root):
        self = cls.__new__(cls)
        self._init_root(root)
        _track(self)            # so that callbacks receive this very object
        return self

    @classmethod
    def from_xml_string(cls, xml, assets=None):
        """Compile a model from MJCF/URDF text; `assets` maps file names to bytes."""
        return cls._from_root(_loading.load_xml_string(xml, assets))

    @classmethod
    def from_xml_path(cls, filename, assets=None):
        """Compile the MJCF/URDF file `filename`; `assets` maps file names to bytes."""
        return cls._from_root(_loading.load_xml_path(filename, assets))

    @classmethod
    def from_binary_path(cls, filename, assets=None):
        """Load an MJB file saved by mj_saveModel; `assets` maps file names to bytes."""
        return cls._from_root(_loading.load_binary_path(filename, assets))

    def to_bytes(self):
        """This model as MJB bytes (mj_saveModel), as `from_bytes` reads them."""
        size = lib.mj_sizeModel(self._ptr)
        buffer = ffi.new("char[]", size)
        lib.mj_saveModel(self._ptr, ffi.NULL, buffer, size)
        return ffi.buffer(buffer, size)[:]

    @classmethod
    def from_bytes(cls, mjb):
        """A model from MJB bytes, such as `to_bytes` returns."""
        if not isinstance(mjb, (bytes, bytearray, memoryview)):
            raise TypeError(f"mjb must be bytes, not {type(mjb).__name__}")
        root = guarded_result(lib.mjcffi_guard_mj_loadModelBuffer, bytes(mjb), len(mjb))
        if root == ffi.NULL:
            raise ValueError("MuJoCo could not load these bytes as an MJB model of MuJoCo 4.0")
        return cls._from_root(ffi.gc(root, lib.mj_deleteModel))

    def __copy__(self):
        root = guarded_result(lib.mjcffi_guard_mj_copyModel, ffi.NULL, self._ptr)
        return type(self)._from_root(ffi.gc(root, lib.mj_deleteModel))

    def __deepcopy__(self, memo):
        return self.__copy__()

    def __reduce__(self):
        return (type(self).from_bytes, (self.to_bytes(),))
