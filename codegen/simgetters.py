"""Write mjcffi/sim/generated/getters.py: mujoco-py's named getters, as two mixins.

`SimModelGetters` (for an MjModel subclass) has, per named category of
mjModel, `<name>_name2id`, `<name>_id2name` and the property `<name>_names`,
`get_joint_qpos_addr` / `get_joint_qvel_addr` and the userdata names.
`SimDataGetters` (for an MjData subclass) has the `get_<object>_<quantity>`
getters listed in DATA below, the joint, mocap, sensor and userdata getters
and setters, and the whole-array attributes of BATCH (`body_xpos`,
`site_jacp`, ...).  Jacobians are flat (3 * nv,) and velocities are
Jacobian @ qvel, as in mujoco-py.

The categories come from mjModel's `name_*adr` fields (as for named access).
The methods call the hand-written helpers of mjcffi/sim/_getter_support.py; the
tables below are the only special cases.
"""

import textwrap

from . import named, outputs

# The names mujoco-py gave the categories whose mjModel prefix differs.
PUBLIC = {"jnt": "joint", "cam": "camera", "tex": "texture", "mat": "material",
          "eq": "equality", "key": "keyframe"}

# Data getters: object -> (category, Jacobian function or None,
# [(quantity, mjData field, kind)]).  Kinds: "copy" (a copy of the row), "mat"
# (a 3x3 copy of a 9-wide row).  mj_jac: at the frame's position on its body.
DATA = {
    "body": ("body", "mj_jacBody",
             [("xpos", "xpos", "copy"), ("xquat", "xquat", "copy"), ("xmat", "xmat", "mat"),
              ("xipos", "xipos", "copy"), ("ximat", "ximat", "mat")]),
    "geom": ("geom", "mj_jacGeom",
             [("xpos", "geom_xpos", "copy"), ("xmat", "geom_xmat", "mat")]),
    "site": ("site", "mj_jacSite",
             [("xpos", "site_xpos", "copy"), ("xmat", "site_xmat", "mat")]),
    "camera": ("cam", "mj_jac",
               [("xpos", "cam_xpos", "copy"), ("xmat", "cam_xmat", "mat")]),
    "light": ("light", None,
              [("xpos", "light_xpos", "copy"), ("xdir", "light_xdir", "copy")]),
    "joint": ("jnt", None,
              [("xanchor", "xanchor", "copy"), ("xaxis", "xaxis", "copy")]),
}

# Objects whose Jacobian getters mujoco-py had (a camera has velocities only).
JACOBIANS = ("body", "geom", "site")

# Whole-array attributes of mujoco-py's PyMjData: object -> (size, {attribute
# suffix: the mjData field it is a view of}); each also has jacp, jacr, xvelp
# and xvelr, one row per object.
BATCH = {"body": ("nbody", {"xpos": "xpos", "xquat": "xquat", "xmat": "xmat"}),
         "geom": ("ngeom", {}),
         "site": ("nsite", {})}

# Getters mujoco-py refused with a RuntimeError naming the one to call instead.
RENAMED = {"get_xpos": "get_body_xpos", "get_xquat": "get_body_xquat",
           "get_xmat": "get_body_xmat", "get_xipos": "get_body_xipos",
           "get_ximat": "get_body_ximat", "get_xanchor": "get_joint_xanchor",
           "get_xaxis": "get_joint_xaxis", "get_sensordata": "get_sensor"}

# Short names also given to data getters (get_cam_xpos is get_camera_xpos).
DATA_ALIASES = {"camera": "cam"}

# What the generated methods call, from the hand-written mjcffi/sim/_getter_support.py.
_SUPPORT = ('UnknownIdError', 'UnknownNameError', '_addr', '_all_names', '_camera_jacobian',
            '_get', '_id', '_jacobian', '_jacobians', '_mocap_id', '_name', '_name_dicts', '_set',
            '_set_row', '_set_userdata_names', '_span', '_userdata_id', '_userdata_name',
            '_userdata_names', '_velocity')


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
        # mujoco-py's PyMjModel kept these dicts, and environment code reads them
        lines += ["    @property"]
        lines += _method(f"_{public}_name2id", "self",
                         f"{{name: id}} of the named {public} elements (mujoco-py's dict).",
                         [f"return _name_dicts(self, {category!r})[0]"])
        lines += ["    @property"]
        lines += _method(f"_{public}_id2name", "self",
                         f"{{id: name}} of every {public}, None where unnamed (mujoco-py's dict).",
                         [f"return _name_dicts(self, {category!r})[1]"])
    for what, dofs in (("qpos", "qpos"), ("qvel", "qvel and qacc")):
        lines += _method(f"get_joint_{what}_addr", "self, name",
                         f"Where joint `name` lies in {dofs}: an int for a 1-wide joint, else "
                         f"(start, end).",
                         [f"return _addr(self, name, {what!r})"])
    if {"userdata_names", "set_userdata_names"} & model_fields:
        raise ValueError("the userdata names would hide an mjModel field")
    lines += ["    @property"]
    lines += _method("userdata_names", "self",
                     "The names given to d.userdata's first entries (set_userdata_names), a list.",
                     ["return _userdata_names(self)"])
    lines += _method("set_userdata_names", "self, names",
                     "Name d.userdata's first entries (a list or tuple of str); AssertionError, "
                     "as mujoco-py, when there are more names than nuserdata.",
                     ["_set_userdata_names(self, names)"])
    lines += _method("userdata_name2id", "self, name",
                     "The userdata index named `name`; UnknownNameError if none is.",
                     ["return _userdata_id(self, name)"])
    lines += _method("userdata_id2name", "self, id",
                     "The name of userdata index `id`; UnknownIdError if it has none.",
                     ["return _userdata_name(self, id)"])
    return lines


def _jac_call(obj, jac, find, which, out="None"):
    """The expression of the flat Jacobian of `obj` `name`."""
    if obj == "camera":
        return f"_camera_jacobian(self, {jac}, {find}, {which!r}, {out})"
    return f"_jacobian(self, {jac}, {find}, {which!r}, {out})"


def _object_methods(obj, category, jac, quantities, data_fields, names):
    lines = []
    find = f"_id(self.model, {category!r}, name)"
    for quantity, field, kind in quantities:
        if field not in data_fields:
            raise ValueError(f"mjData has no field {field}")
        shaped = ".reshape(3, 3)" if kind == "mat" else ""
        doc = f"d.{field} of {obj} `name`" + (" as 3x3" if kind == "mat" else "") + ", a copy."
        names.append((obj, quantity))
        lines += _method(f"get_{obj}_{quantity}", "self, name", doc,
                         [f"return self.{field}[{find}]{shaped}.copy()"])
    if not jac:
        return lines
    for p_or_r, what, kind in (("p", "translational", "linear"), ("r", "rotational", "angular")):
        if obj in JACOBIANS:
            names.append((obj, f"jac{p_or_r}"))
            lines += _method(f"get_{obj}_jac{p_or_r}", f"self, name, jac{p_or_r}=None",
                             f"The {what} Jacobian of {obj} `name` ({jac}), flat (3 * nv,); "
                             f"written into `jac{p_or_r}` (float64, 3 * nv) when given.",
                             [f"return {_jac_call(obj, jac, find, p_or_r, 'jac' + p_or_r)}"])
        names.append((obj, f"xvel{p_or_r}"))
        lines += _method(f"get_{obj}_xvel{p_or_r}", "self, name",
                         f"The world-frame {kind} velocity of {obj} `name`'s frame: its "
                         f"Jacobian @ qvel.",
                         [f"return _velocity({_jac_call(obj, jac, find, p_or_r)}, self)"])
    return lines


def _batch_methods(data_fields):
    lines = []
    for obj, (size, views) in BATCH.items():
        jac = DATA[obj][1]
        attrs = {f"{obj}_{suffix}" for suffix in (*views, "jacp", "jacr", "xvelp", "xvelr")}
        if attrs & data_fields:
            raise ValueError(f"{sorted(attrs & data_fields)} would hide mjData fields")
        for suffix, field in views.items():
            lines += ["    @property"]
            lines += _method(f"{obj}_{suffix}", "self",
                             f"d.{field} itself (a view, not a copy), one row per {obj}.",
                             [f"return self.{field}"])
        for p_or_r, what in (("p", "translational"), ("r", "rotational")):
            lines += ["    @property"]
            lines += _method(f"{obj}_jac{p_or_r}", "self",
                             f"The {what} Jacobians of every {obj} ({jac}): "
                             f"({size}, 3 * nv), computed on each read.",
                             [f"return _jacobians(self, {jac}, self.model.{size}, {p_or_r!r})"])
            lines += ["    @property"]
            lines += _method(f"{obj}_xvel{p_or_r}", "self",
                             f"The world-frame velocities of every {obj}: ({size}, 3), "
                             f"{obj}_jac{p_or_r} @ qvel.",
                             [f"return _velocity(self.{obj}_jac{p_or_r}, self)"])
    return lines


def _data_methods(data_fields):
    lines = []
    names = []
    for obj, (category, jac, quantities) in DATA.items():
        lines += _object_methods(obj, category, jac, quantities, data_fields, names)
    lines += _batch_methods(data_fields)
    for name, instead in RENAMED.items():
        lines += _method(name, "self, name",
                         f"Not a mujoco-py getter: RuntimeError, call {instead}.",
                         [f"raise RuntimeError("
                          f"{f'{name} is not a mujoco-py getter: call {instead} instead'!r})"])
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
    lines += _method("get_userdata", "self, name",
                     "d.userdata at the index named `name` (SimModel.set_userdata_names).",
                     ["return self.userdata[self.model.userdata_name2id(name)]"])
    if "active_contacts_efc_pos" in data_fields:
        raise ValueError("active_contacts_efc_pos would hide an mjData field")
    lines += ["    @property"]
    lines += _method("active_contacts_efc_pos", "self",
                     "d.efc_pos of the constraints after the equality ones (ne:nefc), a view.",
                     ["return self.efc_pos[self.ne:self.nefc]"])
    for obj, short in DATA_ALIASES.items():
        lines += [f"    get_{short}_{quantity} = get_{obj}_{quantity}"
                  for o, quantity in names if o == obj]
    return lines


def generate(described, decls):
    """{"mjcffi/sim/generated/getters.py": text}."""
    cats = named.categories(described)
    model_fields = {f.name for f in described["mjModel"]}
    data_fields = {f.name for f in described["mjData"]}
    lines = [outputs.HEADER_PY.rstrip("\n"),
             '"""mujoco-py\'s named getters: mixins for MjModel and MjData subclasses.',
             "",
             "Getters take a name (str); an unknown one raises UnknownNameError, a",
             "ValueError (as mujoco-py raised) and a KeyError.  Positions and",
             "orientations are copies; xmat-like fields come as 3x3.  Jacobians are",
             "flat (3 * nv,), as mujoco-py's; velocities are world-frame, of the",
             "object's frame (a body's at d.xpos), Jacobian @ qvel: they follow qvel",
             "as it is now, with the positions of the last mj_forward (or mj_step).",
             '"""',
             "",
             "from ..._functions import mj_jac, mj_jacBody, mj_jacGeom, mj_jacSite",
             "from .._getter_support import (  # noqa: F401  (the errors: for users)",
             *textwrap.wrap(", ".join(_SUPPORT) + ")", 90, initial_indent="    ",
                            subsequent_indent="    "),
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
    return {"mjcffi/sim/generated/getters.py": "\n".join(lines).rstrip("\n") + "\n"}
