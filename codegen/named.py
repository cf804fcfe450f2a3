"""Write mjcffi/_generated/namedinfo.py: the tables and methods of named access.

The categories are the `name_<category>adr` fields of mjModel.  A category's
fields are the mjModel and mjData arrays whose rows are counted by
`n<category>` (body_pos: nbody rows), shown without the category prefix
(m.body('b').pos).  Some fields are ragged instead, one span per element: a
joint's qpos and dofs, a sensor's data, an actuator's controls...  The tables
below name those spans; they are the only special cases.
"""

from . import outputs
from .structs import _NUMERIC_OR_CHAR

# Ragged fields by the rows that count them: (category, address field, length field).
SPANS = {
    "m.nsensordata": ("sensor", "sensor_adr", "sensor_dim"),
    "m.nnumericdata": ("numeric", "numeric_adr", "numeric_size"),
    "m.ntextdata": ("text", "text_adr", "text_size"),
    "m.ntupledata": ("tuple", "tuple_adr", "tuple_size"),
    "m.nJten": ("tendon", "ten_J_rowadr", "ten_J_rownnz"),
    "m.nmeshvert": ("mesh", "mesh_vertadr", "mesh_vertnum"),
}

# Fields that are one image per element: (category, address field, shape fields).
IMAGES = {
    "hfield_data": ("hfield", "hfield_adr", ("hfield_nrow", "hfield_ncol")),
    "tex_data": ("tex", "tex_adr", ("tex_height", "tex_width", "tex_nchannel")),
}

# An actuator's controls (nu rows) and force outputs (nout rows): since MuJoCo 4.0
# an actuator may have several of each.  (category, address field, count field)
GROUPS = {
    "m.nu": ("actuator", "actuator_ctrladr", "actuator_ctrlnum"),
    "m.nout": ("actuator", "actuator_outadr", "actuator_outnum"),
}

# Sparse rows, shown dense (a read-only copy, not a view): (category, the rows'
# GROUPS size, rowadr, rownnz, colind).  An actuator has one row per force output.
DENSE = {"actuator_moment": ("actuator", "m.nout", "moment_rowadr", "moment_rownnz",
                             "moment_colind")}

# mjData.plastic, shared by the elements that have a plasticadr (-1: none).
PLASTIC = {"jnt": "jnt_plasticadr", "tendon": "tendon_plasticadr"}

# Other prefixes a category's fields carry, and attributes named otherwise.
PREFIXES = {"tendon": ("tendon_", "ten_"), "jnt": ("jnt_", "dof_")}
RENAMES = {"sensordata": "data"}

# Where a joint field and a dof field strip to the same name, the joint's wins,
# except for these, which the official bindings take from the dofs.
PREFER_DOF = {"bodyid"}

# Fields whose name starts with these prefixes are also offered as `_<attr>`:
# the official bindings name the older tendon_* fields so (m.tendon(0)._limited).
PRIVATE = {"tendon": "tendon_"}

# Other names for categories, as the official bindings document them.
ALIASES = {"jnt": "joint", "cam": "camera", "tex": "texture", "mat": "material",
           "eq": "equality", "tendon": "ten", "key": "keyframe"}


def categories(described):
    """[(category, count field)] in mjModel's order, from its name_*adr fields."""
    model = {f.name for f in described["mjModel"]}
    out = []
    for f in described["mjModel"]:
        if f.name.startswith("name_") and f.name.endswith("adr"):
            category = f.name[len("name_"):-len("adr")]
            if "n" + category in model:
                out.append((category, "n" + category))
    return out


def _attr(category, name):
    if name in RENAMES:
        return RENAMES[name]
    for prefix in PREFIXES.get(category, (category + "_",)):
        if name.startswith(prefix):
            return name[len(prefix):]
    return name


def _fields(category, struct, described):
    """(attribute, field, kind, params) of one category in mjModel or mjData."""
    count = f"m.n{category}"
    found = {}
    for f in described[struct]:
        if f.kind != "pointer" or f.moves or not f.extents or f.elem not in _NUMERIC_OR_CHAR:
            continue
        if f.name.startswith("name_") or f.name in ("names", "paths"):
            continue
        first = f.extents[0]
        attr = _attr(category, f.name)
        if first == count:
            entry = ("row", ())
        elif first in GROUPS and GROUPS[first][0] == category:
            entry = ("rows", GROUPS[first][1:])
        elif category == "jnt" and first == "m.nq":
            entry = ("qpos", ())
        elif category == "jnt" and first == "m.nv" and (struct == "mjData" or
                                                       f.name.startswith("dof_")):
            entry = ("dof", ())       # mjModel's other nv rows index the mass matrix
        elif first in SPANS and SPANS[first][0] == category:
            entry = ("span", SPANS[first][1:])
        elif f.name in IMAGES and IMAGES[f.name][0] == category:
            entry = ("image", (IMAGES[f.name][1], IMAGES[f.name][2]))
        elif f.name in DENSE and DENSE[f.name][0] == category:
            rows_size = DENSE[f.name][1]
            entry = ("dense", GROUPS[rows_size][1:] + DENSE[f.name][2:])
        elif f.name == "plastic" and category in PLASTIC:
            entry = ("plastic", (PLASTIC[category],))
        else:
            continue
        kind, params = entry
        if attr in found:
            keep_dof = attr in PREFER_DOF
            if (kind == "dof") != keep_dof:
                continue
        found[attr] = (attr, f.name, f.elem, kind, _columns(f.extents), params)
    prefix = PRIVATE.get(category)
    if prefix:
        for attr, entry in list(found.items()):
            if entry[1].startswith(prefix):
                found["_" + attr] = ("_" + attr,) + entry[1:]
    return [found[name] for name in sorted(found)]


def _columns(extents):
    """Python text for the number of columns of a field, given the mjModel `m`."""
    columns = extents[1] if len(extents) > 1 else 1
    return str(columns) if isinstance(columns, int) else f"lambda m: {columns}"


def _entry(entry):
    attr, name, elem, kind, columns, params = entry
    return f"        Field({attr!r}, {name!r}, {elem!r}, {kind!r}, {columns}, {params!r}),"


def generate(described):
    """{"mjcffi/_generated/namedinfo.py": text}."""
    model_fields = {f.name for f in described["mjModel"]}
    data_fields = {f.name for f in described["mjData"]}
    lines = [outputs.HEADER_PY.rstrip("\n"),
             '"""Named access: its categories, their fields, and the methods that reach them.',
             "",
             "The kinds of fields are read by mjcffi/_support/named.py.  The methods find a cached",
             "accessor in `self._named` (by name) or `self._named_ids` (by id), or else",
             "call `self._accessor(category, name)`, which mjcffi/_support/named.py gives MjModel",
             "and MjData.  As in the official bindings, the argument is a name or an id,",
             "and defaults to the empty name (which no element has: a KeyError).",
             '"""',
             "",
             "from typing import NamedTuple",
             "",
             "",
             "class Field(NamedTuple):",
             "    attr: str            # the accessor's attribute",
             "    name: str            # the mjModel or mjData field",
             "    elem: str            # its C element type",
             "    kind: str            # row, rows, qpos, dof, span, image, dense or plastic",
             "    columns: object      # values per row: an int, or a function of the mjModel",
             "    params: tuple        # the kind's parameters (address fields, ...)",
             "",
             "",
             "class Category(NamedTuple):",
             "    size: str            # the mjModel size counting its elements",
             "    model: tuple         # fields of mjModel",
             "    data: tuple          # fields of mjData",
             "",
             "",
             "CATEGORIES = {"]
    cats = categories(described)
    methods = {"model": [], "data": []}
    for category, count in cats:
        model = _fields(category, "mjModel", described)
        data = _fields(category, "mjData", described)
        lines.append(f"    {category!r}: Category({count!r}, (")
        lines += [_entry(entry) for entry in model]
        lines.append("    ), (")
        lines += [_entry(entry) for entry in data]
        lines.append("    )),")
        for side, fields, taken in (("model", model, model_fields),
                                    ("data", data, data_fields)):
            if fields and category not in taken:      # m.plugin is a field, not a category
                methods[side].append(category)
    lines.append("}")
    lines += ["", f"ALIASES = {ALIASES!r}", ""]
    for side, struct in (("model", "MjModel"), ("data", "MjData")):
        lines += ["", f"class {struct}Names:",
                  f'    """The named-access methods of {struct}: one per category, and aliases."""',
                  ""]
        for category in methods[side]:
            lines += [f'    def {category}(self, name=""):',
                      f'        """The {category} named or numbered `name` (str or int): an accessor of'
                      f' its {side} fields."""',
                      "        try:",
                      "            if type(name) is str:",
                      f"                return self._named[{category!r}][name]",
                      "            if type(name) is int:",
                      f"                return self._named_ids[{category!r}][name]",
                      "        except (KeyError, AttributeError):",
                      "            pass",
                      f"        return self._accessor({category!r}, name)",
                      ""]
            if category in ALIASES:
                lines += [f"    {ALIASES[category]} = {category}", ""]
    return {"mjcffi/_generated/namedinfo.py": "\n".join(lines).rstrip("\n") + "\n"}
