"""The element kinds of a spec: the official list and lookup names, their mjtObj,
and the suffix of their mjs_as* cast and Mjs* class."""

import operator

from .._generated.enums import mjtObj

# (official list name, lookup name, mjtObj, suffix of the mjs_as* cast and Mjs* class)
KINDS = (
    ("bodies", "body", mjtObj.mjOBJ_BODY, "Body"),
    ("frames", "frame", mjtObj.mjOBJ_FRAME, "Frame"),
    ("geoms", "geom", mjtObj.mjOBJ_GEOM, "Geom"),
    ("joints", "joint", mjtObj.mjOBJ_JOINT, "Joint"),
    ("sites", "site", mjtObj.mjOBJ_SITE, "Site"),
    ("cameras", "camera", mjtObj.mjOBJ_CAMERA, "Camera"),
    ("lights", "light", mjtObj.mjOBJ_LIGHT, "Light"),
    ("flexes", "flex", mjtObj.mjOBJ_FLEX, "Flex"),
    ("meshes", "mesh", mjtObj.mjOBJ_MESH, "Mesh"),
    ("skins", "skin", mjtObj.mjOBJ_SKIN, "Skin"),
    ("hfields", "hfield", mjtObj.mjOBJ_HFIELD, "HField"),
    ("textures", "texture", mjtObj.mjOBJ_TEXTURE, "Texture"),
    ("materials", "material", mjtObj.mjOBJ_MATERIAL, "Material"),
    ("pairs", "pair", mjtObj.mjOBJ_PAIR, "Pair"),
    ("excludes", "exclude", mjtObj.mjOBJ_EXCLUDE, "Exclude"),
    ("equalities", "equality", mjtObj.mjOBJ_EQUALITY, "Equality"),
    ("tendons", "tendon", mjtObj.mjOBJ_TENDON, "Tendon"),
    ("actuators", "actuator", mjtObj.mjOBJ_ACTUATOR, "Actuator"),
    ("sensors", "sensor", mjtObj.mjOBJ_SENSOR, "Sensor"),
    ("numerics", "numeric", mjtObj.mjOBJ_NUMERIC, "Numeric"),
    ("texts", "text", mjtObj.mjOBJ_TEXT, "Text"),
    ("tuples", "tuple", mjtObj.mjOBJ_TUPLE, "Tuple"),
    ("keys", "key", mjtObj.mjOBJ_KEY, "Key"),
    ("plugins", "plugin", mjtObj.mjOBJ_PLUGIN, "Plugin"),
)

BY_LOOKUP = {kind[1]: kind for kind in KINDS}
BY_TYPE = {int(kind[2]): kind for kind in KINDS}


def object_type(value):
    """An mjtObj from an mjtObj or int, or from a lookup name ('site'), as the official
    `find_all` takes either; ValueError naming the valid names otherwise."""
    if isinstance(value, str):
        kind = BY_LOOKUP.get(value)
        if kind is None:
            raise ValueError(f"unknown element type {value!r}; expected one of "
                             f"{', '.join(BY_LOOKUP)}")
        return kind[2]
    try:
        number = operator.index(value)
    except TypeError:
        raise TypeError(f"element type must be an mjtObj or a name such as 'site', "
                        f"not {type(value).__name__}") from None
    if number not in BY_TYPE:
        raise ValueError(f"element type {value!r} has no list in a spec")
    return mjtObj(number)

