"""SimModel and SimData, mujoco-py's model and data, and the three ways to load a model."""

import os
import warnings

from ..functions._overrides import mj_saveXMLString
from .generated.getters import SimDataGetters, SimModelGetters
from ..data import MjData
from ..model import MjModel


class SimModel(SimModelGetters, MjModel):
    """An MjModel that remembers the XML it was compiled from (`_xml`), for MjSim.save
    and get_xml."""

    _xml = None          # the MJCF text, when loaded from XML
    _xml_path = None     # the file it came from, when loaded from a path

    def get_xml(self):
        """This model as MJCF text, includes expanded, with the values changed in the
        model since it was loaded written back (as mujoco-py's mj_saveLastXML).

        Parses the XML the model was loaded from again (the file, so that relative
        paths resolve), compiles it and copies this model's values back.  A model
        loaded from MJB has no XML: ValueError."""
        with warnings.catch_warnings():   # the compiler's warnings were given at load
            warnings.simplefilter("ignore", UserWarning)
            spec = self._source_spec()
            spec.compile()
        spec.copy_back(self)
        return mj_saveXMLString(spec)

    def _source_spec(self):
        from ..spec import MjSpec        # the spec package is imported on first use only
        if self._xml_path is not None:
            return MjSpec.from_file(self._xml_path)
        if self._xml is not None:
            return MjSpec.from_string(self._xml)
        raise ValueError("get_xml needs a model loaded from MJCF (load_model_from_xml or "
                         "load_model_from_path); this one was loaded from MJB")

    def get_mjb(self):
        """This model as MJB bytes (mj_saveModel); load_model_from_mjb reads them."""
        return self.to_bytes()

    def _carried(self):
        return {key: self.__dict__[key] for key in _CARRIED if key in self.__dict__}

    def __copy__(self):
        copy = super().__copy__()
        copy.__dict__.update(self._carried())
        return copy

    def __reduce__(self):
        return (_unpickle, (self.to_bytes(), self._carried(), int(self._ptr.signature)))


# What a copy or a pickle of a SimModel keeps besides the mjModel: its XML source
# (for get_xml and MjSim.save) and its userdata names.
_CARRIED = ("_xml", "_xml_path", "_sim_userdata")


def _unpickle(mjb, carried, signature):
    model = SimModel.from_bytes(mjb)
    if not model._ptr.signature:     # MJB does not keep it; get_xml's mj_copyBack checks it
        model._ptr.signature = signature
    model.__dict__.update(carried)
    return model


class SimData(SimDataGetters, MjData):
    """The MjData that MjSim makes for its model.

    As in mujoco-py, `act` is None when the model has no activations (na == 0);
    every other array keeps the official shape, empty where its size is 0."""

    @property
    def act(self):
        """actuator activation (na), or None when the model has none, as in mujoco-py"""
        return super().act if self._model._ptr.na else None   # MjData's slot


def load_model_from_path(path):
    """A SimModel compiled from an MJCF/URDF file, or loaded from an .mjb file."""
    path = os.fspath(path)
    if str(path).lower().endswith(".mjb"):
        return SimModel.from_binary_path(path)
    model = SimModel.from_xml_path(path)
    with open(path, encoding="utf-8") as f:
        model._xml = f.read()
    model._xml_path = os.path.abspath(path)
    return model


def load_model_from_xml(xml_string):
    """A SimModel compiled from MJCF text; the text is kept as `model._xml`."""
    model = SimModel.from_xml_string(xml_string)
    model._xml = xml_string
    return model


def load_model_from_mjb(mjb):
    """A SimModel from MJB bytes, or from the path of an .mjb file."""
    if isinstance(mjb, (bytes, bytearray, memoryview)):
        return SimModel.from_bytes(mjb)
    return SimModel.from_binary_path(os.fspath(mjb))

