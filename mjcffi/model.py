"""MjModel: a compiled MuJoCo model, loaded from XML or MJB.

The fields come from the generated class (mjcffi/structs/mjmodel.py); this
adds what MuJoCo cannot say in a header: how a model is loaded, copied and
pickled.
"""

from ._support import loading as _loading
from ._support import official_pickle as _official_pickle
from ._support import official_objects as _official_objects
from . import vfs as _vfs
from ._support.library import ffi, lib
from ._support.views import guarded_result
from ._support import bind as _bind
from ._support.callbacks import _register_class, _track
from ._support.named import MjModelNames, NamedAccess
from .structs import mjmodel

_NOT_MJB = "MuJoCo could not load these bytes as an MJB model of MuJoCo 4.0"




@_register_class        # callbacks wrap foreign pointers with it
class MjModel(NamedAccess, MjModelNames, mjmodel.MjModel):
    """A compiled model (mjModel).

    MjModel has no constructor: use `MjModel.from_xml_path`,
    `MjModel.from_xml_string` or `MjModel.from_binary_path`.  Arrays such as
    `m.body_pos` are zero-copy NumPy views of the model's memory; sizes such
    as `m.nq` are read-only.  Named access: `m.geom('ball').rgba`, and one such
    method per name category (mjcffi/_support/named.py).
    """

    @classmethod
    def _from_root(cls, root):
        self = cls.__new__(cls)
        self._init_root(root)
        _track(self)            # so that callbacks receive this very object
        return self

    @classmethod
    def from_xml_string(cls, xml, assets=None, vfs=None):
        """Compile a model from MJCF/URDF text.

        Other files it names come from the disk, from `assets` (a dict of file
        name -> bytes) or from `vfs` (an MjVfs), not both.
        """
        with _vfs.using(vfs, assets) as pointer:
            return cls._from_root(_loading.load_xml_string(xml, assets, pointer))

    @classmethod
    def from_xml_path(cls, filename, assets=None, vfs=None):
        """Compile the MJCF/URDF file `filename`, which may be a file of `vfs`.

        Other files it names come from the disk, from `assets` (a dict of file
        name -> bytes) or from `vfs` (an MjVfs), not both.
        """
        with _vfs.using(vfs, assets) as pointer:
            return cls._from_root(_loading.load_xml_path(filename, assets, pointer))

    @classmethod
    def from_binary_path(cls, filename, assets=None, vfs=None):
        """Load an MJB file saved by mj_saveModel; `filename` may name a file of
        `assets` (a dict of file name -> bytes) or of `vfs` (an MjVfs)."""
        with _vfs.using(vfs, assets) as pointer:
            return cls._from_root(_loading.load_binary_path(filename, assets, pointer))

    @classmethod
    def from_official(cls, m) -> "MjModel":
        """A zero-copy mjcffi view of `m`, an MjModel of the official bindings
        (`import mujoco`) in this process.

        The view and `m` share the C mjModel: a write through either is seen by the
        other.  The view holds `m` (and so its memory) alive, and never frees it.
        Both bindings must run on the one loaded libmujoco (the official package and
        mujoco-core installed together do); otherwise ValueError.  Anything but an
        official MjModel is a TypeError.  Pickling the view gives a plain mjcffi
        MjModel of the same contents.  See also `to_official`.
        """
        root = _official_objects.borrow(m, "mjModel", "m")
        self = cls._from_root(root)
        self.__dict__["_official"] = m      # MjData.to_official's default model
        return self

    def to_official(self):
        """A new MjModel of the official bindings with this model's contents: a copy
        (made from MJB bytes, then mj_copyModel, so that the fields MJB leaves out
        such as `signature` are copied too), also when this model is a
        `from_official` view.

        `mujoco` is imported here, on first use; it must run on mjcffi's libmujoco
        (ValueError), and be the official package, not mjcffi under its name
        (ImportError)."""
        mujoco = _official_objects.official_package()
        name = "model.mjb"
        copy = mujoco.MjModel.from_binary_path(name, {name: self.to_bytes()})
        _official_objects.copy_model(copy, self._ptr)
        return copy

    def to_bytes(self):
        """This model as MJB bytes (mj_saveModel), as `from_bytes` reads them."""
        size = lib.mj_sizeModel(self._ptr)
        buffer = ffi.new("char[]", size)
        lib.mj_saveModel(self._ptr, ffi.NULL, buffer, size)
        return ffi.buffer(buffer, size)[:]

    @classmethod
    def from_bytes(cls, mjb):
        """A model from MJB bytes, such as `to_bytes` returns.

        Bytes that are no model MuJoCo can load and simulate safely (a corrupted
        pickle) raise ValueError, with a note naming the field and value that is
        wrong (mjcffi/_support/modelcheck)."""
        if not isinstance(mjb, (bytes, bytearray, memoryview)):
            raise TypeError(f"mjb must be bytes, not {type(mjb).__name__}")
        return cls._from_root(_loading.load_binary_bytes(bytes(mjb), _NOT_MJB))

    def bind(self, specs):
        """The model fields of a spec element's compiled counterpart: `m.bind(geom).size`.

        `specs` is an element (MjsGeom, MjsJoint, ...) of the MjSpec this
        model was compiled from, unchanged since: its named-access
        accessor (the same as `m.geom(id)`), or, for a list of elements, an
        object whose fields join their values in one array (a view when their ids
        are ascending and consecutive, else a copy; assigning to a field writes
        every element's value either way).  See mjcffi/_support/bind.py.
        """
        return _bind.bind(self, specs)

    @property
    def _address(self):
        """The address of the mjModel in memory, as an int (as the official's)."""
        return int(ffi.cast("uintptr_t", self._ptr))

    def __copy__(self):
        root = guarded_result(lib.mjcffi_guard_mj_copyModel, ffi.NULL, self._ptr)
        return type(self)._from_root(ffi.gc(root, lib.mj_deleteModel))

    def __deepcopy__(self, memo):
        return self.__copy__()

    def __reduce__(self):
        return (type(self).from_bytes, (self.to_bytes(),))

    def __setstate__(self, state):
        """Load an official bindings' pickle of an MjModel: it names
        `mujoco._structs.MjModel`, which is this class under `sys.modules['mujoco'] =
        mjcffi` (mjcffi/_support/official_pickle.py).  mjcffi's own pickles never
        come here (__reduce__)."""
        if "_ptr" in self.__dict__:
            raise ValueError("Invalid serialized mjModel: the MjModel is loaded already")
        root = _loading.load_binary_bytes(_official_pickle.model_mjb(state), _NOT_MJB)
        self._init_root(root)
        _track(self)

    def _repr_html_(self):
        """Jupyter's display: the model's name, its sizes (nq, nv, nu, nbody and the
        other nonzero ones) and main options, as an HTML table
        (mjcffi/_support/display.py, imported on first display)."""
        from ._support import display
        return display.safe(self, lambda: display.model_html(self))
