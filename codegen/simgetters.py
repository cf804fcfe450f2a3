"""Write mjcffi/_simgetters.py: mujoco-py's named getters, as two mixins.

`SimModelGetters` (for an MjModel subclass) has, per named category of
mjModel, `<name>_name2id`, `<name>_id2name` and the property `<name>_names`,
plus `get_joint_qpos_addr` / `get_joint_qvel_addr`.  `SimDataGetters` (for an
MjData subclass) has the `get_<object>_<quantity>` getters listed in DATA
below, the joint, mocap and sensor getters and setters.

The categories come from mjModel's `name_*adr` fields (as for named access),
the object types from the mjtObj enum.  The methods call the hand-written
helpers of mjcffi/_simsupport.py; the tables below are the only special
cases.
"""

import textwrap

from . import named, outputs

# The names mujoco-py gave the categories whose mjModel prefix differs.
PUBLIC = {"jnt": "joint", "cam": "camera", "tex": "texture", "mat": "material",
          "eq": "equality", "key": "keyframe"}

# Data getters: object -> (category, mjtObj for velocities or None,
# Jacobian function or None, [(quantity, mjData field, kind)]).  Kinds: "copy"
# (a copy of the row), "mat" (a 3x3 copy of a 9-wide row).
DATA = {
    "body": ("body", "mjOBJ_XBODY", "mj_jacBody",
             [("xpos", "xpos", "copy"), ("xquat", "xquat", "copy"), ("xmat", "xmat", "mat"),
              ("xipos", "xipos", "copy"), ("ximat", "ximat", "mat")]),
    "geom": ("geom", "mjOBJ_GEOM", "mj_jacGeom",
             [("xpos", "geom_xpos", "copy"), ("xmat", "geom_xmat", "mat")]),
    "site": ("site", "mjOBJ_SITE", "mj_jacSite",
             [("xpos", "site_xpos", "copy"), ("xmat", "site_xmat", "mat")]),
    "camera": ("cam", "mjOBJ_CAMERA", None,
               [("xpos", "cam_xpos", "copy"), ("xmat", "cam_xmat", "mat")]),
    "light": ("light", None, None,
              [("xpos", "light_xpos", "copy"), ("xdir", "light_xdir", "copy")]),
    "joint": ("jnt", None, None,
              [("xanchor", "xanchor", "copy"), ("xaxis", "xaxis", "copy")]),
}

# Short names also given to data getters (get_cam_xpos is get_camera_xpos).
DATA_ALIASES = {"camera": "cam"}

# What the generated methods call, from the hand-written mjcffi/_simsupport.py.
_SUPPORT = ('UnknownNameError', '_addr', '_all_names', '_get', '_id', '_jacobian', '_mocap_id', '_name', '_set', '_set_row', '_span', '_velocity')



def _public(category):
    return PUBLIC.get(category, category)


def _method(name, args, doc, body):
    return [f"    def {name}({args}):", f'        """{doc}"""', *(f"        {b}" for b in body), ""]


def _model_methods(cats, model_fields):
    lines = []
    for category, _ in cats:
        public = _public(category)
        for attr in (f"{public}_name2id", f"{public}_id2name", f"{public}_names"):
            if attr in model_fields:
                raise ValueError(f"{attr} would hide the mjModel field of that name")
        lines += _method(f"{public}_name2id", "self, name",
                         f"The id of the {public} named `name`; UnknownNameError (a ValueError "
                         f"and a KeyError) if none is.",
                         [f"return _id(self, {category!r}, name)"])
        lines += _method(f"{public}_id2name", "self, id",
                         f"The name of {public} `id`, or None if it has none.",
                         [f"return _name(self, {category!r}, id)"])
        lines += ["    @property"]
        lines += _method(f"{public}_names", "self",
                         f"The names of the {public} elements in id order (None where unnamed).",
                         [f"return _all_names(self, {category!r})"])
    for what, dofs in (("qpos", "qpos"), ("qvel", "qvel and qacc")):
        lines += _method(f"get_joint_{what}_addr", "self, name",
                         f"Where joint `name` lies in {dofs}: an int for a 1-wide joint, else "
                         f"(start, end).",
                         [f"return _addr(self, name, {what!r})"])
    return lines


def _data_methods(data_fields):
    lines = []
    names = []
    for obj, (category, objtype, jac, quantities) in DATA.items():
        find = f"_id(self.model, {category!r}, name)"
        for quantity, field, kind in quantities:
            if field not in data_fields:
                raise ValueError(f"mjData has no field {field}")
            shaped = ".reshape(3, 3)" if kind == "mat" else ""
            doc = f"d.{field} of {obj} `name`" + (" as 3x3" if kind == "mat" else "") + ", a copy."
            names.append((obj, quantity))
            lines += _method(f"get_{obj}_{quantity}", "self, name", doc,
                             [f"return self.{field}[{find}]{shaped}.copy()"])
        if objtype:
            for quantity, index, what in (("xvelp", 0, "linear"), ("xvelr", 1, "angular")):
                names.append((obj, quantity))
                lines += _method(f"get_{obj}_{quantity}", "self, name",
                                 f"The world-frame {what} velocity of {obj} `name`'s frame "
                                 f"(mj_objectVelocity, {objtype}).",
                                 [f"return _velocity(self, mj_objectVelocity, _OBJ[{objtype!r}], "
                                  f"{find})[{index}]"])
        if jac:
            for quantity, which, what in (("jacp", "p", "translational"),
                                          ("jacr", "r", "rotational")):
                names.append((obj, quantity))
                lines += _method(f"get_{obj}_{quantity}", "self, name",
                                 f"The {what} Jacobian (3, nv) of {obj} `name` ({jac}).",
                                 [f"return _jacobian(self, {jac}, {find}, {which!r})"])
    for what in ("qpos", "qvel"):
        lines += _method(f"get_joint_{what}", "self, name",
                         f"d.{what} of joint `name`: a scalar for a 1-wide joint, else a copy.",
                         [f"return _get(self.{what}, *_span(self.model, "
                          f"_id(self.model, 'jnt', name), {what!r}))"])
        lines += _method(f"set_joint_{what}", "self, name, value",
                         f"Write `value` into d.{what} of joint `name` (its width must match).",
                         [f"start, width = _span(self.model, _id(self.model, 'jnt', name), "
                          f"{what!r})",
                          f"_set(self.{what}, start, width, value, f'joint {{name!r}} {what}')"])
    for what, width in (("pos", 3), ("quat", 4)):
        if f"mocap_{what}" not in data_fields:
            raise ValueError(f"mjData has no field mocap_{what}")
        lines += _method(f"get_mocap_{what}", "self, name",
                         f"d.mocap_{what} of mocap body `name`, a copy.",
                         [f"return self.mocap_{what}[_mocap_id(self.model, name)].copy()"])
        lines += _method(f"set_mocap_{what}", "self, name, value",
                         f"Write `value` ({width} numbers) into d.mocap_{what} of mocap body "
                         f"`name`.",
                         [f"_set_row(self.mocap_{what}, _mocap_id(self.model, name), value, "
                          f"{width}, f'mocap {what} of {{name!r}}')"])
    lines += _method("get_sensor", "self, name",
                     "d.sensordata of sensor `name`: a scalar for a 1-dim sensor, else a copy.",
                     ["sensor_id = _id(self.model, 'sensor', name)",
                      "return _get(self.sensordata, int(self.model.sensor_adr[sensor_id]), "
                      "int(self.model.sensor_dim[sensor_id]))"])
    for obj, short in DATA_ALIASES.items():
        lines += [f"    get_{short}_{quantity} = get_{obj}_{quantity}"
                  for o, quantity in names if o == obj]
    return lines


def generate(described, decls):
    """{"mjcffi/_simgetters.py": text}."""
    cats = named.categories(described)
    model_fields = {f.name for f in described["mjModel"]}
    data_fields = {f.name for f in described["mjData"]}
    objs = dict(decls.enums["mjtObj"].members)
    used = sorted({spec[1] for spec in DATA.values() if spec[1]})
    lines = [outputs.HEADER_PY.rstrip("\n"),
             '"""mujoco-py\'s named getters: mixins for MjModel and MjData subclasses.',
             "",
             "Getters take a name (str); an unknown one raises UnknownNameError, a",
             "ValueError (as mujoco-py raised) and a KeyError.  Positions and",
             "orientations are copies; xmat-like fields come as 3x3.  Velocities are",
             "world-frame, of the object's frame (a body's at d.xpos, as mj_jacBody).",
             '"""',
             "",
             "from ._functions import mj_jacBody, mj_jacGeom, mj_jacSite, mj_objectVelocity",
             "from ._simsupport import (  # noqa: F401  (UnknownNameError: for users)",
             *textwrap.wrap(", ".join(_SUPPORT) + ")", 90, initial_indent="    ",
                            subsequent_indent="    "),
             "",
             f"_OBJ = {dict((k, objs[k]) for k in used)!r}",
             "",
             "",
             "class SimModelGetters:",
             '    """mujoco-py\'s name lookups, for an MjModel subclass."""',
             "",
             *_model_methods(cats, model_fields),
             "",
             "class SimDataGetters:",
             '    """mujoco-py\'s named getters and setters, for an MjData subclass (needs'
             ' self.model)."""',
             "",
             *_data_methods(data_fields)]
    return {"mjcffi/_simgetters.py": "\n".join(lines).rstrip("\n") + "\n"}
