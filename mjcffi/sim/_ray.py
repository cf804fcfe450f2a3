"""MjSim.ray: mujoco-py's ray cast, on mj_ray, with its meaning of "static" geoms."""

import operator

import numpy as np

from .._generated.constants import mjNGROUP
from .._generated.enums import mjtGeom
from .._functions import mj_ray, mj_rayHfield, mj_rayMesh, mju_rayGeom


def ray(model, data, pnt, vec, include_static_geoms, exclude_body, group_filter):
    """(distance, geom id) of the first geom hit, as MjSim.ray documents; the arguments
    checked first (TypeError / ValueError naming the one that is wrong)."""
    pnt = _vector3(pnt, "pnt")
    vec = _vector3(vec, "vec")
    if group_filter is not None:
        group_filter = _groups(group_filter)
    exclude_body = _body(exclude_body, model.nbody)
    if include_static_geoms:
        return _ray(model, data, pnt, vec, group_filter, exclude_body)
    return _ray_off_world(model, data, pnt, vec, group_filter, exclude_body)


def _ray(model, data, pnt, vec, groups, exclude_body):
    geomid = np.full(1, -1, dtype=np.int32)
    distance = mj_ray(model, data, pnt, vec, groups, 1, exclude_body, geomid)
    return float(distance), int(geomid[0])


def _ray_off_world(model, data, pnt, vec, groups, exclude_body):
    """mj_ray skipping the world body's own geoms, mujoco-py's "static" geoms.

    (MuJoCo's flg_static=0 now also skips every body welded to the world.)  mj_ray
    excludes one body: the nearest hit off both the world and `exclude_body` is that of
    one of two calls, unless the world blocks the one and `exclude_body` the other;
    then each remaining geom is intersected on its own."""
    if exclude_body in (-1, 0):
        return _ray(model, data, pnt, vec, groups, 0)
    body = model.geom_bodyid
    hit = _ray(model, data, pnt, vec, groups, exclude_body)
    if hit[1] < 0 or body[hit[1]] != 0:
        return hit
    hit = _ray(model, data, pnt, vec, groups, 0)
    if hit[1] < 0 or body[hit[1]] != exclude_body:
        return hit
    return _ray_each_geom(model, data, pnt, vec, groups, (0, exclude_body))


def _ray_each_geom(model, data, pnt, vec, groups, skipped_bodies):
    """The nearest visible geom, of the groups, outside `skipped_bodies`, one by one."""
    best = (-1.0, -1)
    for geom in range(model.ngeom):
        if model.geom_bodyid[geom] in skipped_bodies or not _visible(model, geom, groups):
            continue
        kind = model.geom_type[geom]
        if kind == mjtGeom.mjGEOM_MESH:
            distance = mj_rayMesh(model, data, geom, pnt, vec)
        elif kind == mjtGeom.mjGEOM_HFIELD:
            distance = mj_rayHfield(model, data, geom, pnt, vec)
        else:
            distance = mju_rayGeom(data.geom_xpos[geom], data.geom_xmat[geom],
                                   model.geom_size[geom], pnt, vec, kind)
        if distance >= 0 and (best[1] < 0 or distance < best[0]):
            best = (float(distance), geom)
    return best


def _visible(model, geom, groups):
    """What mj_ray asks of a geom besides its body: a visible colour, an enabled group."""
    if groups is not None and not groups[min(max(model.geom_group[geom], 0), mjNGROUP - 1)]:
        return False
    material = model.geom_matid[geom]
    alpha = model.mat_rgba[material][3] if material >= 0 else model.geom_rgba[geom][3]
    return alpha != 0


def _vector3(value, name):
    """`value` as a contiguous float64 array of 3 numbers, or ValueError / TypeError."""
    try:
        array = np.ascontiguousarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be 3 numbers: {exc}") from None
    if array.shape != (3,):
        raise ValueError(f"{name} must be 3 numbers (x, y, z), not shape {array.shape}")
    return array


def _groups(value):
    """group_filter as mj_ray's geomgroup: mjNGROUP bytes, 1 where the group is used."""
    array = np.asarray(value)
    if array.shape != (mjNGROUP,):
        raise ValueError(f"group_filter must hold {mjNGROUP} booleans (one per geom "
                         f"group), not shape {array.shape}")
    if array.dtype.kind not in "biu":
        raise TypeError(f"group_filter must hold booleans or ints, not {array.dtype}")
    return np.ascontiguousarray(array != 0, dtype=np.uint8)


def _body(value, nbody):
    """exclude_body as a body id from -1 (none) to nbody - 1."""
    if isinstance(value, (bool, np.bool_)) or not hasattr(value, "__index__"):
        raise TypeError(f"exclude_body must be an int (a body id, or -1), not "
                        f"{type(value).__name__}")
    value = operator.index(value)
    if not -1 <= value < nbody:
        raise ValueError(f"exclude_body must be a body id from 0 to {nbody - 1}, or -1 "
                         f"for none, not {value}")
    return value
