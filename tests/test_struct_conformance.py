"""The struct classes behave as the official ones where code can tell: class-level
dir(), equality and hashing, repr, `_address`, constructors, which scalars can be
written, and arrays of structs such as d.contact that follow the simulation.
Each test checks against the official bindings in the same process."""

import copy
import gc
import types
import weakref

import numpy as np
import pytest

import mjcffi
from mjcffi import scenes

# A box resting on a plane (four contacts once it has fallen), and a tendon that
# is not always in the constraints: its efc address is then unallocated.
BOX = """
<mujoco>
  <option timestep="0.001953125"/>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 .1"/>
    <site name="anchor" pos="0 0 2"/>
    <body name="box" pos="0 0 .3">
      <freejoint/>
      <geom type="box" size=".1 .1 .1" mass="1"/>
      <site name="corner" pos=".1 .1 .1"/>
    </body>
    <body name="arm" pos="1 0 1">
      <joint name="swing" axis="0 1 0" range="-.5 .5"/>
      <geom type="capsule" fromto="0 0 0 0 0 -.4" size=".02"/>
    </body>
  </worldbody>
  <tendon><spatial range="0 3"><site site="anchor"/><site site="corner"/></spatial></tendon>
  <actuator><motor joint="swing"/></actuator>
</mujoco>
"""

FLEX = """
<mujoco>
  <worldbody>
    <flexcomp type="grid" count="3 3 1" spacing=".1 .1 .1" radius=".01" name="cloth" dim="2">
      <edge equality="true"/>
    </flexcomp>
    <body name="ball" pos="0 0 1"><freejoint/><geom size=".1"/></body>
  </worldbody>
  <deformable>
    <skin name="patch" vertex="0 0 0 .1 0 0 0 .1 0" face="0 1 2">
      <bone body="ball" bindpos="0 0 0" bindquat="1 0 0 0" vertid="0 1 2" vertweight="1 1 1"/>
    </skin>
  </deformable>
</mujoco>
"""

# Public names of the official classes that mjcffi does not offer (yet): spec
# binding (MjSpec) and an OpenGL context method belong to other parts.
KNOWN_GAPS = {"MjData": {"bind", "bind_scalar"}, "MjModel": {"bind", "bind_scalar"},
              "MjrContext": {"free"}}


def _pair(mujoco, xml=BOX):
    """(model, data) in both bindings, forwarded."""
    out = []
    for module in (mjcffi, mujoco):
        m = module.MjModel.from_xml_string(xml)
        d = module.MjData(m)
        module.mj_forward(m, d)
        out.append((m, d))
    return out


def _official_struct_classes(mujoco):
    """name -> official class, for every official struct class mjcffi also has."""
    out = {}
    for name in dir(mujoco):
        cls = getattr(mujoco, name)
        if name.startswith("Mj") and isinstance(cls, type) and \
                cls.__module__ in ("mujoco._structs", "mujoco._render") and hasattr(mjcffi, name):
            out[name] = cls
    for inner in ("Global", "Quality", "Headlight", "Map", "Scale", "Rgba"):
        out["MjVisual." + inner] = getattr(mujoco.MjVisual, inner)
    return out


def _ours(name):
    outer, _, inner = name.partition(".")
    cls = getattr(mjcffi, outer)
    return getattr(cls, inner) if inner else cls


def _public(names):
    return {n for n in names if not n.startswith("_")}


# ------------------------------------------------------------- introspection

def test_class_dir_lists_every_public_name_of_the_official_class(mujoco):
    compared = 0
    for name, official in _official_struct_classes(mujoco).items():
        missing = _public(dir(official)) - _public(dir(_ours(name)))
        assert missing <= KNOWN_GAPS.get(name, set()), (name, sorted(missing))
        compared += 1
    assert compared >= 28


def test_hot_fields_are_listed_by_the_class_and_are_slots():
    names = dir(mjcffi.MjData)
    for hot in ("qpos", "qvel", "ctrl", "act", "xpos", "xquat", "sensordata", "qfrc_applied"):
        assert hot in names
        # a slot, in the class dict as the official's fields are (MJX reads
        # MjData.__dict__): it reads as fast as the instance attribute it replaced,
        # where any other class attribute of that name would slow every d.qpos
        assert isinstance(vars(mjcffi.MjData)[hot], types.MemberDescriptorType), hot
    assert names.count("qpos") == 1 and names == sorted(names)
    d = mjcffi.MjData(mjcffi.MjModel.from_xml_string(scenes.PENDULUM))
    assert "qpos" not in vars(d) and "qpos" in dir(d) and d.qpos is d.qpos


def test_nested_structs_have_their_official_names():
    assert mjcffi.MjVisual.Global is mjcffi.MjVisualGlobal
    assert mjcffi.MjVisual.Rgba is mjcffi.MjVisualRgba
    m = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    assert isinstance(m.vis.global_, mjcffi.MjVisual.Global)


# ------------------------------------------------------ equality and hashing

def test_value_equality_and_hashing_are_those_of_the_official_classes(mujoco):
    for name, official in _official_struct_classes(mujoco).items():
        ours = _ours(name)
        assert (ours.__hash__ is None) == (official.__hash__ is None), name
    m = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    d = mjcffi.MjData(m)
    assert {m: 1, d: 2, mjcffi.MjvScene(): 3, mjcffi.MjvFigure(): 4}   # hashable: by identity
    for value in (m.opt, d.warning, d.contact, mjcffi.MjvCamera()):
        with pytest.raises(TypeError):
            hash(value)


def test_structs_compare_field_by_field():
    a, b = mjcffi.MjOption(), mjcffi.MjOption()
    assert a == b and not a != b
    a.gravity[2] = -1
    assert a != b
    b.gravity[:] = a.gravity
    assert a == b
    a.timestep = b.timestep = float("nan")          # field equality: NaN is unequal
    assert a != b
    a.timestep, b.timestep = 0.0, -0.0
    assert a == b
    assert a != mjcffi.MjvOption() and a != 3 and a is not None
    contact1, contact2 = mjcffi.MjContact(), mjcffi.MjContact()
    contact1.H[35] = 1                               # the last element of a long array
    assert contact1 != contact2


def test_nested_and_subclassed_structs_compare_by_value():
    m = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    vis = copy.copy(m.vis)
    assert vis == m.vis
    vis.headlight.ambient[0] += 0.25                 # a change two levels down
    assert vis != m.vis
    m.vis = vis
    assert m.vis == vis

    class Sub(mjcffi.MjWarningStat):
        pass
    assert Sub() == mjcffi.MjWarningStat()


def test_struct_lists_compare_entry_by_entry(mujoco):
    (m, d), _ = _pair(mujoco)
    other = mjcffi.MjData(m)
    for data in (d, other):
        data.qpos[2] = 0.09                           # the box resting on the floor
        mjcffi.mj_forward(m, data)
    assert d.ncon == 4 and d.contact == other.contact
    other.qpos[2] = 0.3
    mjcffi.mj_forward(m, other)
    assert other.ncon == 0 and d.contact != other.contact
    assert d.contact[:2] != d.contact and d.contact[:2] == d.contact[0:2]
    assert d.contact != d.warning and d.contact != 5
    assert d.warning == other.warning


# ---------------------------------------------------------------------- repr

@pytest.mark.parametrize("name, field", [
    ("MjOption", "tolerance"), ("MjContact", "dist"), ("MjvCamera", "fixedcamid"),
    ("MjvGeom", "objid"), ("MjStatistic", "extent"), ("MjvPerturb", "select"),
    ("MjrRendererInfo", None), ("MjLogMessage", "line"), ("MjvOption", "label"),
])
def test_repr_is_the_official_text(mujoco, name, field):
    ours, theirs = getattr(mjcffi, name)(), getattr(mujoco, name)()
    if field:
        setattr(ours, field, 1)
        setattr(theirs, field, 1)
    assert repr(ours) == repr(theirs) == str(ours)


def test_repr_of_nested_structs_indents_them(mujoco):
    ours = repr(mjcffi.MjModel.from_xml_string(scenes.PENDULUM).vis)
    theirs = repr(mujoco.MjModel.from_xml_string(scenes.PENDULUM).vis)
    # the nested classes are named MjVisualGlobal, ... here, Global, ... there
    for inner in ("Global", "Quality", "Headlight", "Map", "Scale", "Rgba"):
        ours = ours.replace(f"<MjVisual{inner}\n", f"<{inner}\n")
    # the official 4.0.0 shows rgba.bv and rgba.bvactive as empty arrays; they have 4 floats
    kept = [line for line in theirs.splitlines() if " bv" not in line]
    assert [line for line in ours.splitlines() if " bv" not in line] == kept
    assert "\n  global_: <Global\n    azimuth: " in ours and ours.endswith("\n  >\n>")


def test_repr_of_a_subclass_names_it_and_lists_only_the_fields():
    class Stat(mjcffi.MjWarningStat):
        @property
        def ptr(self):
            return self

    assert repr(Stat()) == "<Stat\n  lastinfo: 0\n  number: 0\n>"


def test_repr_of_struct_lists_is_the_official_text(mujoco):
    (m, d), (om, od) = _pair(mujoco)
    for data, module, model in ((d, mjcffi, m), (od, mujoco, om)):
        data.qpos[2] = 0.09
        module.mj_step(model, data, 3)
    assert repr(d.contact) == repr(od.contact) and repr(d.contact).startswith("<_MjContactList")
    assert repr(d.warning) == repr(od.warning)


# ------------------------------------------------------------------ address

def test_address_is_the_c_address_of_every_wrapper(mujoco):
    m = mjcffi.MjModel.from_xml_string(BOX)
    d = mjcffi.MjData(m)
    assert m._address == int(mjcffi.ffi.cast("uintptr_t", m._ptr)) > 0
    assert m.opt._address == m._address + mjcffi.ffi.offsetof("mjModel", "opt")
    assert d.warning[1]._address - d.warning[0]._address == mjcffi.ffi.sizeof("mjWarningStat")
    assert len({m._address, d._address, mjcffi.MjData(m)._address, m.vis._address}) == 4
    with pytest.raises(AttributeError):
        m._address = 0


# ------------------------------------------------------------- constructors

def test_constructors_take_the_official_arguments(mujoco):
    for module in (mjcffi, mujoco):
        rect = module.MjrRect(1, 2, width=3, height=4)
        assert (rect.left, rect.bottom, rect.width, rect.height) == (1, 2, 3, 4)
        with pytest.raises(TypeError):
            module.MjrRect(1, 2, 3)
        attribute = module.MjrVertexAttribute(type=2)
        assert (attribute.usage, attribute.type) == (0, 2)
        with pytest.raises(TypeError):
            module.MjvScene(module.MjModel.from_xml_string(scenes.PENDULUM))
        with pytest.raises(TypeError):
            module.MjvCamera(1)
    assert repr(mjcffi.MjrRect(1, 2, 3, 4)) == repr(mujoco.MjrRect(1, 2, 3, 4))


@pytest.mark.parametrize("name", ["MjvScene", "MjvGeom", "MjvCamera", "MjvOption", "MjvPerturb",
                                  "MjOption", "MjStatistic", "MjvFigure", "MjvLight"])
def test_default_construction_matches_the_official(mujoco, name):
    ours, theirs = getattr(mjcffi, name)(), getattr(mujoco, name)()
    compared = 0
    for field in _public(dir(theirs)):
        value = getattr(theirs, field)
        if isinstance(value, np.ndarray):
            mine = getattr(ours, field)
            assert mine.shape == value.shape and mine.dtype == value.dtype, field
            assert np.array_equal(mine, value), field
        elif isinstance(value, (int, float, str)):
            assert getattr(ours, field) == value, field
        else:
            continue
        compared += 1
    assert compared >= 3


def test_scene_arrays_have_the_official_extents(mujoco):
    (m, _), (om, _) = _pair(mujoco, FLEX)
    ours, theirs = mjcffi.MjvScene(m, maxgeom=20), mujoco.MjvScene(om, maxgeom=20)
    assert len(ours.geoms) == len(theirs.geoms) == 20 and ours.ngeom == 0
    assert isinstance(ours.geoms[19], mjcffi.MjvGeom)
    for field in ("geomorder", "flexedge", "flexvert", "flexface", "flexnormal",
                  "flextexcoord", "skinvert", "skinnormal", "flexedgenum", "skinvertnum"):
        mine, official = getattr(ours, field), getattr(theirs, field)
        assert (mine.shape, mine.dtype) == (official.shape, official.dtype), field
        assert mine.size > 0, field
    assert len(ours.lights) == len(theirs.lights) and len(ours.camera) == len(theirs.camera)


# --------------------------------------------------------------- writability

def _scalar_fields(obj):
    for name in _public(dir(type(obj))):
        value = getattr(obj, name)
        if isinstance(value, (bool, int, float)) and not callable(value):
            yield name, value


def _writable(obj, name, value):
    try:
        setattr(obj, name, value)
    except AttributeError:
        return False
    return True


# Stricter than the official on purpose: these size arrays or hold addresses, and
# a wrong value would let views or MuJoCo reach outside the allocated memory.  No
# bound keeps them safe: nJ, nY, ... size arrays laid out one after another in
# the arena, and MuJoCo follows the addresses they hold.  (A scene's maxgeom,
# nflex and nskin are writable as in the official, within what mjv_makeScene
# allocated; MjData's ncon and nefc to the value they hold, and ne, nf and nl within
# the arena, as MJX's get_data_into writes them: mjcffi/_support/official_class.py.)
# pbase holds the address of the last mj_markStack record.
STRICTER = {
    "MjData": {"narena", "nbuffer", "nplugin", "parena", "pbase", "threadpool",
               "nJ", "efm_active", "nefmK", "nefmcon", "nefmT", "nefmA", "nefmdof",
               "nefmL", "nY", "nA", "nisland", "nidof", "ntree_awake", "nbody_awake",
               "nparent_awake", "nv_awake"},
}


def test_writable_scalars_are_the_official_ones_but_for_memory_sizes(mujoco):
    (m, d), (om, od) = _pair(mujoco, FLEX)
    objects = {
        "MjModel": (m, om), "MjData": (d, od), "MjOption": (m.opt, om.opt),
        "MjStatistic": (m.stat, om.stat), "MjLROpt": (mjcffi.MjLROpt(), mujoco.MjLROpt()),
        "MjvScene": (mjcffi.MjvScene(m, 10), mujoco.MjvScene(om, 10)),
        "MjvCamera": (mjcffi.MjvCamera(), mujoco.MjvCamera()),
        "MjvGeom": (mjcffi.MjvGeom(), mujoco.MjvGeom()),
        "MjrContext": (mjcffi.MjrContext(), mujoco.MjrContext()),
        "MjvFigure": (mjcffi.MjvFigure(), mujoco.MjvFigure()),
    }
    for label, (ours, theirs) in objects.items():
        official = {n for n, v in _scalar_fields(theirs) if _writable(theirs, n, v)}
        mine = {n for n, v in _scalar_fields(ours) if _writable(ours, n, v)}
        assert mine <= official, (label, sorted(mine - official))
        assert official - mine == STRICTER.get(label, set()), (label, sorted(official - mine))


def test_flags_of_the_model_can_be_set_and_gravcomp_keeps_its_count():
    m = mjcffi.MjModel.from_xml_string(BOX)
    assert not m.flg_gravcomp and m.ngravcomp == 0
    m.flg_gravcomp = True
    assert m.flg_gravcomp and m.ngravcomp == 1          # as the official: the flag, as a count
    m.flg_surfacevel = 1
    assert m.flg_surfacevel is True
    m.flg_gravcomp = False
    assert m.ngravcomp == 0
    with pytest.raises(TypeError):
        m.flg_adhesion = "yes"
    with pytest.raises(AttributeError):
        m.ngravcomp = 3


def test_kept_bounds_stop_writes_past_the_allocations():
    m = mjcffi.MjModel.from_xml_string(BOX)
    d = mjcffi.MjData(m)
    d.pstack = d.narena                                  # allowed: MuJoCo reports the overflow
    with pytest.raises(mjcffi.FatalError, match="stack overflow"):
        mjcffi.mj_forward(m, d)
    with pytest.raises(ValueError, match="narena"):
        d.pstack = d.narena + 1
    scene = mjcffi.MjvScene(m, 5)
    scene.ngeom = 5
    with pytest.raises(ValueError, match="maxgeom"):
        scene.ngeom = 6
    with pytest.raises(ValueError, match="100"):
        scene.nlight = 101
    with pytest.raises(ValueError, match="maxgeom allocated by mjv_makeScene"):
        scene.maxgeom = 50                               # writable as official, within 0..5


# ------------------------------------------------------- arrays of structs

def test_a_contact_list_taken_early_sees_later_contacts():
    m = mjcffi.MjModel.from_xml_string(BOX)
    d = mjcffi.MjData(m)
    contact = d.contact
    assert len(contact) == 0 and contact.dist.shape == (0,)
    while d.ncon == 0:
        mjcffi.mj_step(m, d)
    assert len(contact) == d.ncon == 4 and contact == d.contact
    assert sorted(c.geom[1] for c in contact) == [1] * 4
    first = contact[0]
    mjcffi.mj_resetData(m, d)
    assert len(contact) == 0 and isinstance(first.dist, float)


def test_struct_lists_slice_and_protect_their_fields():
    m = mjcffi.MjModel.from_xml_string(BOX)
    d = mjcffi.MjData(m)
    d.qpos[2] = 0.09
    mjcffi.mj_forward(m, d)
    contact = d.contact
    part = contact[1:4:2]
    assert len(part) == 2 and part[1]._address == contact[3]._address
    np.testing.assert_array_equal(part.dist, contact.dist[1:4:2])
    np.testing.assert_array_equal(contact[::-1].pos, contact.pos[::-1])
    contact.dist[:] = 7                                  # field views write through
    assert contact[2].dist == 7
    with pytest.raises(AttributeError, match="has no setter") as info:
        contact.dist = 1
    assert str(info.value) == "property of '_MjContactList' object has no setter"
    with pytest.raises(AttributeError):
        contact.nope = 1
    with pytest.raises(AttributeError):
        d.contact = contact
    assert "dist" in dir(contact) and "number" in dir(d.warning)


# --------------------------------------------------------- fields and views

def test_unallocated_index_arrays_read_as_minus_one():
    m = mjcffi.MjModel.from_xml_string(BOX)
    d = mjcffi.MjData(m)
    assert d.tendon_efcadr.flags.owndata and list(d.tendon_efcadr) == [-1]
    assert (d.dof_island == -1).all() and d.efc_type.shape == (0,)
    d.qpos[2] = 0.09
    mjcffi.mj_forward(m, d)
    assert not d.efc_type.flags.owndata and d.nefc > 0


def test_names_are_read_once(mujoco):
    m = mjcffi.MjModel.from_xml_string(BOX)
    assert m.names is m.names and m.names == mujoco.MjModel.from_xml_string(BOX).names
    with pytest.raises(AttributeError):
        m.names = b""


def test_rows_of_text_are_bytes_strings_as_official(mujoco):
    ours, theirs = mjcffi.MjvFigure(), mujoco.MjvFigure()
    assert (ours.linename.dtype, ours.linename.shape) == (theirs.linename.dtype,
                                                          theirs.linename.shape)
    ours.linename[1] = b"speed"
    assert ours.linename[1] == b"speed" and not ours.linename.flags.owndata
    assert mjcffi.ffi.string(ours._ptr.linename[1]) == b"speed"


def test_views_keep_only_the_memory_alive_not_the_wrapper():
    # The official test_array_keeps_struct_alive counts references to one shared
    # capsule; here each view keeps the owning cdata alive by itself.  What that
    # test is for holds: the memory lives as long as a view, and no longer.
    m = mjcffi.MjModel.from_xml_string(BOX)
    qpos0, spring = m.qpos0, m.qpos_spring
    qpos0[:] = 1
    root, wrapper = weakref.ref(m._root), weakref.ref(m)
    del m
    gc.collect()
    assert wrapper() is None and root() is not None and qpos0[0] == 1
    del qpos0
    gc.collect()
    assert root() is not None
    del spring
    gc.collect()
    assert root() is None
