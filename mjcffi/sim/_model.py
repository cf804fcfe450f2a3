"""SimModel and SimData, mujoco-py's model and data, and the three ways to load a model."""

import os

from .._simgetters import SimDataGetters, SimModelGetters
from ..data import MjData
from ..model import MjModel


class SimModel(SimModelGetters, MjModel):
    """An MjModel that remembers the XML it was compiled from (`_xml`), for MjSim.save."""

    _xml = None          # the MJCF text, when loaded from XML
    _xml_path = None     # the file it came from, when loaded from a path


class SimData(SimDataGetters, MjData):
    """The MjData that MjSim makes for its model."""


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

