"""The references whose category a type decides: a geom's mesh or height field, a
sensor's object and frame, an equality's objects, a tendon wrap's object, a tuple's
objects; and what a sensor writes in sensordata."""

import numpy as np

from ..._generated import enums as _enums
from .fields import CATEGORIES
from .mjb import check_range, covers, fail

_OBJ = _enums.mjtObj
_WORD = {"joint": "jnt", "camera": "cam", "texture": "tex", "material": "mat",
         "equality": "eq", "xbody": "body"}
_OBJ_COUNT = {int(v): CATEGORIES.get(_WORD.get(k[6:].lower(), k[6:].lower()))
              for k, v in _OBJ.__members__.items()}
JOINT, SITE = int(_OBJ.mjOBJ_JOINT), int(_OBJ.mjOBJ_SITE)


def check_object(m, name, k, objtype, objid, lowest=0, none=False):
    """objid is an id of `objtype` (mjtObj) in [lowest, count); with `none`, an object
    of no type (mjOBJ_UNKNOWN) has the id -1."""
    count = _OBJ_COUNT.get(objtype)
    if count is None:
        if none and objid != -1:
            fail(name, k, objid, f"an object of no type ({objtype}) has the id -1")
        return
    n = m.sizes[count]
    if not lowest <= objid < n:
        fail(name, k, objid, f"an id of {_OBJ(objtype).name[6:].lower()} must be in "
             f"[{lowest}, {n})")


_GEOM = _enums.mjtGeom


@covers("geom_dataid", "site_dataid", "pair_signature", "exclude_signature", "hfield_nrow",
        "hfield_ncol", "tex_height", "tex_width", "tex_nchannel")
def check_geoms(m):
    """A geom's data is its mesh or height field; signatures name two bodies; height
    fields and textures fit their data."""
    plugins = m.flat("geom_plugin")
    for g, (t, d) in enumerate(zip(m.flat("geom_type"), m.flat("geom_dataid"))):
        if t == _GEOM.mjGEOM_HFIELD:
            low, n = 0, m.nhfield
        elif t == _GEOM.mjGEOM_MESH:
            low, n = 0, m.nmesh
        elif t == _GEOM.mjGEOM_SDF:             # a mesh, or a plugin's shape (-1)
            low, n = (-1 if plugins[g] >= 0 else 0), m.nmesh
        else:
            low, n = -1, 0
        if not low <= d < n:
            fail("geom_dataid", g, d, f"a geom of type {_GEOM(t).name[7:].lower()} names "
                 + (f"its data in [{low}, {n})" if n else "no data (-1)"))
    check_range(m, "site_dataid", -1, m.nmesh, f"a site's mesh is -1 or in [0, {m.nmesh})")
    for name in ("pair_signature", "exclude_signature"):
        for k, s in enumerate(m.flat(name)):
            if not (0 <= s & 0xFFFF < m.nbody and 0 <= s >> 16 < m.nbody):
                fail(name, k, s, f"body1 << 16 + body2, both in [0, {m.nbody})")
    sizes = (("hfield", ("hfield_nrow", "hfield_ncol"), "nhfielddata"),
             ("tex", ("tex_height", "tex_width", "tex_nchannel"), "ntexdata"))
    for kind, dims, data in sizes:
        adrs = m.flat(f"{kind}_adr")
        for k, shape in enumerate(zip(*(m.flat(d) for d in dims))):
            if min(shape) < 1 or not 0 <= adrs[k] <= m.sizes[data] - int(np.prod(shape)):
                fail(f"{kind}_adr", k, adrs[k], f"its {' x '.join(map(str, shape))} elements "
                     f"run past the {m.sizes[data]} of {data[1:]}")


# ------------------------------------------------------------------ sensors

_SENS = _enums.mjtSensor
_NEEDS_REFERENCE = ("CAMPROJECTION", "INSIDESITE", "TACTILE")


def _sensor_objects():
    """mjtSensor -> (its object types, its reference frame types); None: any."""
    o = {k[6:].lower(): int(v) for k, v in _OBJ.__members__.items()}
    frame = {o["body"], o["xbody"], o["geom"], o["site"], o["camera"]}
    by_prefix = {"JOINT": {o["joint"]}, "BALL": {o["joint"]}, "TENDON": {o["tendon"]},
                 "ACTUATOR": {o["actuator"]}, "SUBTREE": {o["body"]}, "FRAME": frame,
                 "GEOM": {o["body"], o["geom"]}}
    special = {"E_POTENTIAL": ({o["unknown"]}, None), "E_KINETIC": ({o["unknown"]}, None),
               "CLOCK": ({o["unknown"]}, None), "USER": (None, None), "PLUGIN": (None, None),
               "CONTACT": (None, None), "RANGEFINDER": ({o["site"], o["camera"]}, None),
               "CAMPROJECTION": ({o["site"]}, {o["camera"]}), "INSIDESITE": (frame, {o["site"]}),
               "TACTILE": ({o["mesh"]}, {o["geom"]})}
    out = {}
    for key, value in _SENS.__members__.items():
        kind = key[7:]
        obj = next((v for p, v in by_prefix.items() if kind.startswith(p)), {o["site"]})
        obj, ref = special.get(kind, (obj, {o["unknown"]} | frame))
        if kind.startswith("GEOM"):
            obj, ref = {o["body"], o["geom"]}, {o["body"], o["geom"]}
        if ref is not None and kind not in _NEEDS_REFERENCE:
            ref = ref | {o["unknown"]}
        out[int(value)] = (obj, ref)
    return out


_SENSOR_OBJECTS = _sensor_objects()
# The values a sensor type writes (MuJoCo's sensorSize); those not listed write one.
_SENSOR_VALUES = dict.fromkeys(
    ("ACCELEROMETER", "VELOCIMETER", "GYRO", "FORCE", "TORQUE", "MAGNETOMETER", "BALLANGVEL",
     "FRAMEPOS", "FRAMEXAXIS", "FRAMEYAXIS", "FRAMEZAXIS", "FRAMELINVEL", "FRAMEANGVEL",
     "FRAMELINACC", "FRAMEANGACC", "SUBTREECOM", "SUBTREELINVEL", "SUBTREEANGMOM",
     "GEOMNORMAL"), 3) | {"BALLQUAT": 4, "FRAMEQUAT": 4, "GEOMFROMTO": 6, "CAMPROJECTION": 2}
_CONTACT_SIZES = (1, 3, 3, 1, 3, 3, 3, 3, 3)        # mjtConDataField: found, force, ...
_RAY_SIZES = (1, 3, 3, 3, 3, 1)                     # mjtRayDataField: dist, dir, ...


def _spec_size(spec, sizes):
    """The values one slot of a data spec (bits of sizes) holds; 0 if it is invalid."""
    if spec <= 0 or spec >> len(sizes):
        return 0
    return sum(size for bit, size in enumerate(sizes) if spec >> bit & 1)


def _sensor_dim(m, kind, objtype, objid, intprm):
    """The values a sensor writes, or None where its dim decides (user, plugin, ...)."""
    if kind == "CONTACT":
        size = _spec_size(intprm[0], _CONTACT_SIZES)
        return size * intprm[2] if size and intprm[2] > 0 and 0 <= intprm[1] <= 3 else 0
    if kind == "RANGEFINDER":
        rays = 1
        if objtype == _OBJ.mjOBJ_CAMERA:
            width, height = m.arrays["cam_resolution"][objid].tolist()
            rays = width * height if width > 0 and height > 0 else 0
        return _spec_size(intprm[0], _RAY_SIZES) * rays
    if kind in ("USER", "PLUGIN", "TACTILE"):
        return None
    return _SENSOR_VALUES.get(kind, 1)


@covers("sensor_type", "sensor_objtype", "sensor_objid", "sensor_reftype", "sensor_refid",
        "sensor_dim", "sensor_adr", "sensor_intprm", "sensor_plugin", "cam_resolution")
def check_sensors(m):
    """Objects and frames of the types a sensor's type reads, its values as many as it
    writes, one after another in sensordata."""
    objtypes, objids = m.flat("sensor_objtype"), m.flat("sensor_objid")
    reftypes, refids = m.flat("sensor_reftype"), m.flat("sensor_refid")
    dims, adrs, plugins = m.flat("sensor_dim"), m.flat("sensor_adr"), m.flat("sensor_plugin")
    intprms = m.arrays["sensor_intprm"].tolist()
    total = 0
    for s, t in enumerate(m.flat("sensor_type")):
        kind = _SENS(t).name[7:]
        obj, ref = _SENSOR_OBJECTS[t]
        if obj is not None and objtypes[s] not in obj:
            fail("sensor_objtype", s, objtypes[s], f"a {kind} sensor reads another type")
        if ref is not None and reftypes[s] not in ref:
            fail("sensor_reftype", s, reftypes[s], f"a {kind} sensor reads another frame")
        needs_ref = kind in _NEEDS_REFERENCE
        check_object(m, "sensor_objid", s, objtypes[s], objids[s], none=True)
        check_object(m, "sensor_refid", s, reftypes[s], refids[s], none=True,
                     lowest=0 if needs_ref else -1)
        if kind == "PLUGIN" and plugins[s] < 0:
            fail("sensor_plugin", s, plugins[s], "a plugin sensor names its instance")
        values = _sensor_dim(m, kind, objtypes[s], objids[s], intprms[s])
        if dims[s] < 1 or values is not None and dims[s] != values:
            fail("sensor_dim", s, dims[s], f"this {kind} sensor writes {values or 'some'} "
                 f"values (sensor_intprm[{s}] = {intprms[s]})")
        if adrs[s] != total:
            fail("sensor_adr", s, adrs[s], f"sensor {s}'s values start at {total}")
        total += dims[s]
    if total != m.nsensordata:
        fail("nsensordata", None, m.nsensordata, f"the sensors have {total} values")


# ------------------------------------------------------------------ equalities, wraps, tuples

_EQ = _enums.mjtEq
_ROWS_PER_EQ = {_EQ.mjEQ_CONNECT: 3, _EQ.mjEQ_WELD: 7}


@covers("eq_type", "eq_objtype", "eq_obj1id", "eq_obj2id")
def check_equalities(m):
    """Objects by equality type; nemax (3 rows a connect, 7 a weld, 1 the others)."""
    objtypes, one, two = m.flat("eq_objtype"), m.flat("eq_obj1id"), m.flat("eq_obj2id")
    types = m.flat("eq_type")
    for e, t in enumerate(types):
        if t in (_EQ.mjEQ_CONNECT, _EQ.mjEQ_WELD):
            kind = objtypes[e]
            if kind not in (_OBJ.mjOBJ_BODY, _OBJ.mjOBJ_SITE):
                fail("eq_objtype", e, kind, "a connect or weld joins bodies or sites")
            check_object(m, "eq_obj1id", e, kind, one[e])
            check_object(m, "eq_obj2id", e, kind, two[e])
        elif t in (_EQ.mjEQ_JOINT, _EQ.mjEQ_TENDON):
            kind = JOINT if t == _EQ.mjEQ_JOINT else int(_OBJ.mjOBJ_TENDON)
            check_object(m, "eq_obj1id", e, kind, one[e])
            check_object(m, "eq_obj2id", e, kind, two[e], lowest=-1)
        elif t in (_EQ.mjEQ_FLEX, _EQ.mjEQ_FLEXVERT, _EQ.mjEQ_FLEXSTRAIN):
            check_object(m, "eq_obj1id", e, int(_OBJ.mjOBJ_FLEX), one[e])
            if two[e] != -1:
                fail("eq_obj2id", e, two[e], "a flex constraint has one object (-1)")
        else:
            fail("eq_type", e, t, "not an equality type MuJoCo 4.0 simulates")
    rows = sum(_ROWS_PER_EQ.get(t, 1) for t in types)
    if m.nemax != rows:
        fail("nemax", None, m.nemax, f"the equalities have {rows} rows at most")


_WRAP = _enums.mjtWrap
_WRAP_OBJECTS = {_WRAP.mjWRAP_JOINT: JOINT, _WRAP.mjWRAP_SITE: SITE,
                 _WRAP.mjWRAP_SPHERE: int(_OBJ.mjOBJ_GEOM),
                 _WRAP.mjWRAP_CYLINDER: int(_OBJ.mjOBJ_GEOM)}


@covers("wrap_type", "wrap_objid", "tendon_type", "tendon_adr", "tendon_num")
def check_tendons(m):
    """Wrap objects by type; a fixed tendon's path holds slide and hinge joints, a
    spatial tendon's sites, geoms and pulleys."""
    types, ids = m.flat("wrap_type"), m.flat("wrap_objid")
    for w, t in enumerate(types):
        if t in _WRAP_OBJECTS:
            check_object(m, "wrap_objid", w, _WRAP_OBJECTS[t], ids[w])
    jtypes = m.flat("jnt_type")
    for k, (t, adr, num) in enumerate(zip(m.flat("tendon_type"), m.flat("tendon_adr"),
                                          m.flat("tendon_num"))):
        path = range(adr, adr + num)
        if t == 0:
            good = num > 0 and all(types[w] == _WRAP.mjWRAP_JOINT and jtypes[ids[w]] in (2, 3)
                                   for w in path)
        else:
            good = num > 1 and all(types[w] in (_WRAP.mjWRAP_SITE, _WRAP.mjWRAP_PULLEY,
                                                _WRAP.mjWRAP_SPHERE, _WRAP.mjWRAP_CYLINDER)
                                   for w in path)
        if not good:
            fail("tendon_type", k, t, f"its path of {num} holds wraps of types "
                 f"{[types[w] for w in path]}")


@covers("tuple_objtype", "tuple_objid")
def check_tuples(m):
    for k, (t, i) in enumerate(zip(m.flat("tuple_objtype"), m.flat("tuple_objid"))):
        check_object(m, "tuple_objid", k, t, i)
