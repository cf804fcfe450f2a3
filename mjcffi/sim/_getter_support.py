"""What the generated mujoco-py getters (mjcffi/sim/generated/getters.py) call.

A support module: name and id lookups through named access's tables, joint
spans, copies and checked writes, Jacobians and the velocities they give,
userdata names.  It imports no generated code: the getters hand it the MuJoCo
functions it calls.
"""

import numpy as np

from .._generated.namedinfo import CATEGORIES
from .._support.named import _joint_span, _name_of, _names, _unknown_name


class UnknownNameError(KeyError, ValueError):
    """No element of a category has this name: a ValueError, as in mujoco-py,
    and a KeyError, as in named access."""

    def __str__(self):
        return str(self.args[0]) if self.args else ""


class UnknownIdError(IndexError, ValueError):
    """An id out of a category's range: a ValueError, as in mujoco-py, and an
    IndexError."""


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
        raise UnknownIdError(f"{category} id {element_id} is out of range: the model has {count}")
    return _name_of(model, category, element_id) or None


def _all_names(model, category):
    """The names of the named elements, in id order (unnamed ones are left out, as
    mujoco-py left them out: a position in the tuple is an id only when all are named)."""
    cache = model.__dict__.setdefault("_sim_names", {})
    names = cache.get(category)
    if names is None:
        id2name = _name_dicts(model, category)[1]
        names = cache[category] = tuple(name for name in id2name.values() if name is not None)
    return names


def _name_dicts(model, category):
    """({name: id}, {id: name or None}): mujoco-py's `_<kind>_name2id` and
    `_<kind>_id2name`, made once per model, the same dicts on every read."""
    cache = model.__dict__.setdefault("_sim_names", {})
    dicts = cache.get((category, "dicts"))
    if dicts is None:
        count = getattr(model, CATEGORIES[category].size)
        id2name = {i: _name_of(model, category, i) or None for i in range(count)}
        name2id = {name: i for i, name in id2name.items() if name is not None}
        dicts = cache[(category, "dicts")] = (name2id, id2name)
    return dicts


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


def _jacobian(data, function, element_id, which, out=None, point=None):
    """The translational ("p") or rotational ("r") Jacobian of an object's frame, flat
    (3 * nv,) as mujoco-py returned it, written into `out` when given.

    `function` is mj_jacBody, mj_jacGeom or mj_jacSite (called with the id), or
    mj_jac (called with `point` on body `element_id`)."""
    nv = data.model.nv
    if out is None:
        out = np.zeros(3 * nv)
    elif not isinstance(out, np.ndarray):
        raise TypeError(f"jac{which} must be a numpy array, not {type(out).__name__}")
    elif out.dtype != np.float64 or out.shape != (3 * nv,) or not out.flags.c_contiguous \
            or not out.flags.writeable:
        raise ValueError(f"jac{which} must be a writeable C-contiguous float64 array of shape "
                         f"({3 * nv},) (3 * nv), got {out.dtype} {out.shape}")
    jac = out.reshape(3, nv)                  # a view: MuJoCo writes into `out`
    pair = (jac, None) if which == "p" else (None, jac)
    if point is None:
        function(data.model, data, *pair, element_id)
    else:
        function(data.model, data, *pair, point, element_id)
    return out


def _jacobians(data, function, count, which):
    """(count, 3 * nv): the Jacobians of every object of a kind, one per row."""
    jacs = np.zeros((count, 3 * data.model.nv))
    for element_id in range(count):
        _jacobian(data, function, element_id, which, jacs[element_id])
    return jacs


def _velocity(jac, data):
    """jac @ qvel: the world-frame velocity the Jacobian (flat, or one per row) gives
    at the current qvel, as mujoco-py computed xvelp and xvelr."""
    nv = data.model.nv
    return jac.reshape(*jac.shape[:-1], 3, nv) @ data.qvel


def _camera_jacobian(data, function, camera_id, which, out=None):
    """The Jacobian of a camera's frame (mj_jac at d.cam_xpos on the camera's body)."""
    point = np.array(data.cam_xpos[camera_id])
    return _jacobian(data, function, int(data.model.cam_bodyid[camera_id]), which, out, point)


def _userdata_names(model):
    return list(model.__dict__.get("_sim_userdata", ()))


def _set_userdata_names(model, names):
    """Name d.userdata's first entries, as mujoco-py did (AssertionError as it raised)."""
    assert isinstance(names, (list, tuple)), \
        f"userdata names must be a list or tuple, not {type(names).__name__}"
    assert len(names) <= model.nuserdata, \
        f"{len(names)} userdata names, but the model has nuserdata={model.nuserdata}"
    for name in names:
        assert isinstance(name, str), f"userdata names must be str, not {type(name).__name__}"
    model.__dict__["_sim_userdata"] = tuple(names)


def _userdata_id(model, name):
    names = model.__dict__.get("_sim_userdata", ())
    if name not in names:
        raise UnknownNameError(f"no userdata named {name!r}; the userdata names are "
                               f"{list(names)} (set_userdata_names)")
    return names.index(name)


def _userdata_name(model, userdata_id):
    names = model.__dict__.get("_sim_userdata", ())
    if isinstance(userdata_id, (bool, np.bool_)) or not hasattr(userdata_id, "__index__"):
        raise TypeError(f"expected a userdata id (int), not {type(userdata_id).__name__}")
    if not 0 <= userdata_id.__index__() < len(names):
        raise UnknownIdError(f"userdata id {userdata_id} has no name: "
                             f"{len(names)} are named (set_userdata_names)")
    return names[userdata_id.__index__()]


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
