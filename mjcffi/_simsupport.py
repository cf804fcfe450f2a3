"""What the generated mujoco-py getters (mjcffi/_simgetters.py) call.

A support module: name and id lookups through named access's tables, joint
spans, copies and checked writes, velocities and Jacobians.  It imports no
generated code: the getters hand it the MuJoCo functions it calls.
"""

import numpy as np

from ._namedinfo import CATEGORIES
from .named import _joint_span, _name_of, _names, _unknown_name


class UnknownNameError(KeyError, ValueError):
    """No element of a category has this name: a ValueError, as in mujoco-py,
    and a KeyError, as in named access."""

    def __str__(self):
        return str(self.args[0]) if self.args else ""


def _id(model, category, name):
    if not isinstance(name, str):
        raise TypeError(f"expected a {category} name (str), not {type(name).__name__}")
    element_id = _names(model, category).get(name)
    if element_id is None:
        raise UnknownNameError(_unknown_name(model, category, name))
    return element_id


def _name(model, category, element_id):
    count = getattr(model, CATEGORIES[category].size)
    if isinstance(element_id, (bool, np.bool_)) or not hasattr(element_id, "__index__"):
        raise TypeError(f"expected a {category} id (int), not {type(element_id).__name__}")
    element_id = element_id.__index__()
    if not 0 <= element_id < count:
        raise IndexError(f"{category} id {element_id} is out of range: the model has {count}")
    return _name_of(model, category, element_id) or None


def _all_names(model, category):
    cache = model.__dict__.setdefault("_sim_names", {})
    names = cache.get(category)
    if names is None:
        names = cache[category] = tuple(_name(model, category, i)
                                        for i in range(getattr(model, CATEGORIES[category].size)))
    return names


def _span(model, joint_id, what):
    """(start, width) of a joint in qpos or qvel."""
    start, width = _joint_span(model._ptr, joint_id, "qpos" if what == "qpos" else "dof")
    return int(start), width


def _addr(model, name, what):
    start, width = _span(model, _id(model, "jnt", name), what)
    return start if width == 1 else (start, start + width)


def _get(array, start, width):
    return array[start] if width == 1 else array[start:start + width].copy()


def _set(array, start, width, value, what):
    value = np.asarray(value, dtype=np.float64)
    if width == 1:
        if value.size != 1:
            raise ValueError(f"{what} takes 1 value, got shape {value.shape}")
        array[start] = value.reshape(())
    else:
        if value.shape != (width,):
            raise ValueError(f"{what} takes shape ({width},), got {value.shape}")
        array[start:start + width] = value


def _velocity(data, function, objtype, element_id):
    """(linear, angular) world-frame velocity of an object's frame, by `function`
    (mj_objectVelocity, which the generated getters hand down)."""
    res = np.empty(6)
    function(data.model, data, objtype, element_id, res, 0)
    return res[3:].copy(), res[:3].copy()     # MuJoCo orders it (rot, lin)


def _jacobian(data, function, element_id, which):
    jac = np.zeros((3, data.model.nv))
    if which == "p":
        function(data.model, data, jac, None, element_id)
    else:
        function(data.model, data, None, jac, element_id)
    return jac


def _mocap_id(model, name):
    mocap_id = int(model.body_mocapid[_id(model, "body", name)])
    if mocap_id < 0:
        raise ValueError(f"body {name!r} is not a mocap body")
    return mocap_id


def _set_row(array, row, value, width, what):
    value = np.asarray(value, dtype=np.float64)
    if value.shape != (width,):
        raise ValueError(f"{what} takes shape ({width},), got {value.shape}")
    array[row] = value
