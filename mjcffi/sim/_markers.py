"""mujoco-py's markers: extra decor geoms a render context adds to every frame.

`add_marker(pos=(0, 0, 1), size=(.1, .1, .1), rgba=(1, 0, 0, 1), label="goal")`
names mjvGeom fields.  A marker starts as mujoco-py's default (a white box of
half-size 0.1 at the origin, decor, no material) and takes the given fields;
arrays are reshaped to the field's shape (a 9-vector `mat` is a 3x3).  The
values are checked when the marker is added, so a bad one fails there, not
in the middle of a frame.
"""

import numpy as np

from .._generated.enums import mjtCatBit, mjtGeom, mjtObj
from ..structs import MjvGeom

_DEFAULTS = {
    "type": int(mjtGeom.mjGEOM_BOX), "dataid": -1, "objtype": int(mjtObj.mjOBJ_UNKNOWN),
    "objid": -1, "category": int(mjtCatBit.mjCAT_DECOR), "matid": -1, "texid": -1,
    "texuniform": 0, "texcoord": 0, "segid": -1,
    "size": np.full(3, 0.1), "pos": np.zeros(3), "mat": np.eye(3), "rgba": np.ones(4),
    "emission": 0.0, "specular": 0.5, "shininess": 0.5, "reflectance": 0.0,
    "texrepeat": np.ones(2), "castshadow": 1, "label": "",
    "camdist": 0.0, "modelrbound": 0.0, "transparent": 0,
}
FIELDS = MjvGeom._fields


def _assign(geom, key, value):
    current = getattr(geom, key)
    if isinstance(current, np.ndarray):
        value = np.asarray(value)
        if value.size == current.size:
            value = value.reshape(current.shape)
    setattr(geom, key, value)


def make(params):
    """An MjvGeom holding mujoco-py's marker defaults updated by `params`."""
    unknown = sorted(set(params) - set(FIELDS))
    if unknown:
        raise ValueError(f"add_marker: mjvGeom has no field {unknown[0]!r}; its fields are "
                         f"{', '.join(FIELDS)}")
    geom = MjvGeom()
    for key, value in _DEFAULTS.items():
        _assign(geom, key, value)
    for key, value in params.items():
        if key == "label" and value is None:
            value = ""
        try:
            _assign(geom, key, value)
        except (TypeError, ValueError) as error:
            raise type(error)(f"add_marker: {key}: {error}") from None
    return geom


def add_to_scene(scn, marker):
    """Append `marker` to the scene's geoms; RuntimeError once maxgeom are there."""
    n = scn.ngeom
    if n >= scn.maxgeom:
        raise RuntimeError(f"the scene is full: {scn.maxgeom} geoms (maxgeom), no room for a "
                           f"marker")
    target = scn.geoms[n]
    for key in FIELDS:
        setattr(target, key, getattr(marker, key))
    scn.ngeom = n + 1
