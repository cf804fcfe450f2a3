"""MjSim.save: the model's MJCF text with the current state added as a keyframe."""

import io
import os
import xml.etree.ElementTree as ElementTree

import numpy as np

SAVED_KEY = "saved_state"


def _is_text(file):
    return isinstance(file, io.TextIOBase)


def _numbers(values):
    return " ".join(repr(float(v)) for v in np.ravel(values))


def _xml_with_key(model, data):
    """The model's MJCF text with one more <key> holding the data's state."""
    source = getattr(model, "_xml", None)
    if source is None:
        raise ValueError("MjSim.save needs a model loaded from XML (load_model_from_xml or "
                         "load_model_from_path); this one has no source text")
    root = ElementTree.fromstring(source)
    if root.tag != "mujoco":
        raise ValueError(f"MjSim.save writes MJCF only, not <{root.tag}>")
    path = getattr(model, "_xml_path", None)
    if path is not None:    # let relative asset paths still resolve from the saved copy
        folder = os.path.dirname(path)
        compiler = root.find("compiler")
        if compiler is None:
            compiler = ElementTree.Element("compiler")
            root.insert(0, compiler)
        for attribute in ("meshdir", "texturedir", "assetdir"):
            if attribute in compiler.attrib and not os.path.isabs(compiler.attrib[attribute]):
                compiler.set(attribute, os.path.join(folder, compiler.attrib[attribute]))
        if "assetdir" not in compiler.attrib:
            compiler.set("assetdir", folder)
    keyframes = root.findall("keyframe")
    keyframe = keyframes[-1] if keyframes else ElementTree.SubElement(root, "keyframe")
    names = {k.get("name") for k in root.iter("key")}
    name, n = SAVED_KEY, 1
    while name in names:
        name, n = f"{SAVED_KEY}_{n}", n + 1
    key = ElementTree.SubElement(keyframe, "key")
    key.set("name", name)
    key.set("time", repr(float(data.time)))
    key.set("qpos", _numbers(data.qpos))
    key.set("qvel", _numbers(data.qvel))
    if model.na:
        key.set("act", _numbers(data.act))
    return ElementTree.tostring(root, encoding="unicode")
