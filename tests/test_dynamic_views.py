"""Views of moving memory (issue 35): `d.contact` and its fields, the efc_*, island_*,
iefc_* arrays and the others sized by ncon, nefc, nisland, nJ, ..., a scene's geoms
and its flex and skin arrays.  They are cached with the words that define them
(pointer and count) and checked on every read: right after every step, reset,
copy and scene remake, never a view of the old size, and each keeps its memory
alive.  The official bindings, stepped in the same process, are the oracle."""

import copy
import gc
import weakref

import numpy as np
import pytest

import mjcffi
from mjcffi._support import views
from mjcffi._support.library import ffi

from .conftest import gymnasium_assets

ANT = next(p for p in gymnasium_assets() if p.name == "ant.xml")
HUMANOID = next(p for p in gymnasium_assets() if p.name == "humanoid.xml")

# Boxes dropped in a pile on a plane: contacts come and go, and their number changes.
STACK = """
<mujoco>
  <option timestep="0.005"/>
  <worldbody>
    <geom type="plane" size="2 2 .1"/>
    %s
  </worldbody>
</mujoco>
""" % "\n    ".join(
    f'<body pos="{0.03 * (i % 3)} {0.02 * (i % 2)} {0.15 + 0.22 * i}" euler="0 {7 * i} {11 * i}">'
    f'<freejoint/><geom type="box" size=".1 .08 .06"/></body>' for i in range(6))

# With a dense constraint Jacobian MuJoCo never writes the sparse structure of efc_J:
# it holds whatever the arena held, which differs between two MjData (test_structs).
DENSE_UNWRITTEN = {"efc_J_rownnz", "efc_J_rowadr", "efc_J_colind", "efc_J_rowsuper"}
DIFFERING = {"plugin_data"}


def _moving(cls):
    """The array fields of `cls` whose size or address moves (DynamicArray)."""
    return [name for name in cls._fields
            if isinstance(getattr(cls, name, None), views.DynamicArray)]


def _contact_fields():
    return list(mjcffi.MjContact._fields)


def _address(array):
    return array.__array_interface__["data"][0]


def _twins(mujoco, xml=None, path=None):
    if path is not None:
        m, om = mjcffi.MjModel.from_xml_path(path), mujoco.MjModel.from_xml_path(str(path))
    else:
        m, om = mjcffi.MjModel.from_xml_string(xml), mujoco.MjModel.from_xml_string(xml)
    return m, mjcffi.MjData(m), om, mujoco.MjData(om)


def _assert_same(mine, theirs, label):
    assert isinstance(mine, np.ndarray), label
    assert (mine.shape, mine.dtype) == (theirs.shape, theirs.dtype), label
    assert np.array_equal(mine, theirs, equal_nan=mine.dtype.kind == "f"), label


def _compare_all(m, d, od, held):
    """Every moving field and every contact field of `d` against the official `od`,
    read fresh and through the contact list `held` taken before the steps."""
    unwritten = set() if mjcffi.mj_isSparse(m) else DENSE_UNWRITTEN
    assert (d.ncon, d.nefc, d.nJ, d.nisland) == (od.ncon, od.nefc, od.nJ, od.nisland)
    for name in _moving(type(d)):
        if name in unwritten or name in DIFFERING:
            assert getattr(d, name).shape == getattr(od, name).shape, name
            continue
        _assert_same(getattr(d, name), getattr(od, name), name)
    assert len(d.contact) == len(held) == len(od.contact) == d.ncon
    for name in _contact_fields():
        official = getattr(od.contact, name)
        _assert_same(getattr(d.contact, name), official, f"contact.{name}")
        _assert_same(getattr(held, name), official, f"held contact.{name}")
    for i in range(d.ncon):
        assert d.contact[i].dist == od.contact[i].dist
        _assert_same(d.contact[i].pos, od.contact[i].pos, f"contact[{i}].pos")
        _assert_same(d.contact[-1 - i].frame, od.contact[d.ncon - 1 - i].frame, f"contact[-{i}]")


@pytest.mark.parametrize("scene", ["stack", "ant"])
def test_every_moving_field_equals_the_official_after_every_step(mujoco, scene):
    """300 steps of a contact-rich scene: after each, every efc_*, island_*, iefc_* (all
    DynamicArray) field and every d.contact.<field>, d.contact[i] equals the
    official's on a twin MjData; ncon and nefc change along the way."""
    if scene == "ant":
        m, d, om, od = _twins(mujoco, path=ANT)
    else:
        m, d, om, od = _twins(mujoco, xml=STACK)
    rng = np.random.default_rng(35)
    held = d.contact                 # taken before the steps, it shows each step's contacts
    counts = set()
    for _ in range(300):
        if m.nu:
            d.ctrl[:] = od.ctrl[:] = rng.uniform(-1, 1, m.nu)
        mjcffi.mj_step(m, d)
        mujoco.mj_step(om, od)
        _compare_all(m, d, od, held)
        counts.add((d.ncon, d.nefc))
    assert len({n for n, _ in counts}) > 2 and len({n for _, n in counts}) > 2, counts
    assert max(n for n, _ in counts) > 0


def test_a_view_is_never_handed_out_after_its_size_or_address_changed(mujoco):
    """Every view handed out has the size and the address of the moment it is read:
    one taken when nefc was 8 is not handed out when nefc is 12, and reads between
    two changes give the same object (cached)."""
    m = mjcffi.MjModel.from_xml_string(STACK)
    d = mjcffi.MjData(m)
    seen_nefc, renewed = set(), 0
    previous = {}
    for _ in range(400):
        mjcffi.mj_step(m, d)
        current = {}
        for name in ("efc_force", "efc_J", "efc_KBIP", "island_nefc", "map_efc2iefc"):
            array = getattr(d, name)
            assert array is getattr(d, name), name                 # cached
            pointer = getattr(d._ptr, name)
            size = getattr(type(d), name).shape(d)
            assert array.shape == size, (name, array.shape, size)
            if array.size:
                assert _address(array) == int(ffi.cast("uintptr_t", pointer)), name
            current[name] = (array, array.shape, _address(array) if array.size else 0)
        for name in ("dist", "pos", "geom", "frame"):
            array = getattr(d.contact, name)
            assert array.shape[0] == d.ncon and array is getattr(d.contact, name), name
            if d.ncon:
                assert _address(array) == int(ffi.cast("uintptr_t", d._ptr.contact)) + \
                    ffi.offsetof("mjContact", name), name
            current["contact." + name] = (array, array.shape,
                                          _address(array) if array.size else 0)
        if d.ncon:
            entry = d.contact[d.ncon - 1]
            assert entry is d.contact[d.ncon - 1]
            assert entry._ptr == d._ptr.contact + (d.ncon - 1)
        for name, (array, shape, address) in current.items():
            if name in previous:
                old, old_shape, old_address = previous[name]
                if (shape, address) != (old_shape, old_address):
                    assert array is not old, name                   # a new view
                    renewed += 1
        previous = current
        seen_nefc.add(d.nefc)
    assert len(seen_nefc) > 3 and renewed > 10


def test_one_view_taken_at_nefc_8_is_not_given_at_nefc_12():
    """The case in the issue, made on purpose: a view taken at one nefc stays that
    size (it shows the memory of then), and the next read gives a new, right-sized one."""
    m = mjcffi.MjModel.from_xml_string(STACK)
    d = mjcffi.MjData(m)
    first = None
    for _ in range(400):
        mjcffi.mj_step(m, d)
        if first is None and d.nefc:
            first, nefc = d.efc_force, d.nefc
            contacts, ncon = d.contact.dist, d.ncon
        elif first is not None and d.nefc != nefc and d.ncon != ncon:
            break
    else:
        pytest.fail("nefc and ncon never changed")
    now = d.efc_force
    assert now is not first and first.shape == (nefc,) and now.shape == (d.nefc,)
    assert d.contact.dist is not contacts and d.contact.dist.shape == (d.ncon,)
    assert contacts.shape == (ncon,)


def test_reset_data_empties_every_moving_view(mujoco):
    m, d, om, od = _twins(mujoco, xml=STACK)
    held = d.contact
    for _ in range(120):
        mjcffi.mj_step(m, d)
        mujoco.mj_step(om, od)
    assert d.ncon and d.nefc
    views_before = d.efc_force, d.contact.dist, d.contact[0]
    mjcffi.mj_resetData(m, d)
    mujoco.mj_resetData(om, od)
    assert d.ncon == d.nefc == 0 and len(held) == 0
    assert d.efc_force.shape == (0,) and d.contact.dist.shape == (0,)
    assert held.pos.shape == (0, 3) and d.contact.geom.shape == (0, 2)
    with pytest.raises(IndexError):
        d.contact[0]
    for name in _moving(type(d)):
        if name not in DENSE_UNWRITTEN | DIFFERING:
            _assert_same(getattr(d, name), getattr(od, name), name)
    assert d.efc_force is not views_before[0] and d.contact.dist is not views_before[1]
    for _ in range(120):
        mjcffi.mj_step(m, d)
        mujoco.mj_step(om, od)
        _compare_all(m, d, od, held)


def test_copy_data_into_another_data_updates_its_views(mujoco):
    """mj_copyData into an existing MjData whose ncon and nefc differ: its cached views
    show the copied contacts and constraints, not the ones it had."""
    m = mjcffi.MjModel.from_xml_string(STACK)
    src, dest = mjcffi.MjData(m), mjcffi.MjData(m)
    for _ in range(150):
        mjcffi.mj_step(m, src)
    for _ in range(20):
        mjcffi.mj_step(m, dest)
    assert (src.ncon, src.nefc) != (dest.ncon, dest.nefc)
    held, old_force = dest.contact, dest.efc_force
    old_dist = held.dist
    mjcffi.mj_copyData(dest, m, src)
    assert (dest.ncon, dest.nefc) == (src.ncon, src.nefc)
    for name in _moving(type(dest)):
        if name not in DENSE_UNWRITTEN | DIFFERING:
            assert np.array_equal(getattr(dest, name), getattr(src, name)), name
    for name in _contact_fields():
        assert np.array_equal(getattr(held, name), getattr(src.contact, name)), name
    assert held.dist is not old_dist and dest.efc_force is not old_force
    copied = copy.copy(src)
    assert np.array_equal(copied.contact.dist, src.contact.dist)
    assert np.array_equal(copied.efc_force, src.efc_force)
    assert _address(copied.efc_force) != _address(src.efc_force)


def test_writes_through_cached_views_reach_the_c_memory():
    m = mjcffi.MjModel.from_xml_string(STACK)
    d = mjcffi.MjData(m)
    for _ in range(150):
        mjcffi.mj_step(m, d)
    assert d.ncon > 1 and d.nefc > 1
    d.contact.dist[1] = 0.25
    assert d._ptr.contact[1].dist == 0.25 and d.contact[1].dist == 0.25
    d.contact.pos[0] = [1, 2, 3]
    assert list(d._ptr.contact[0].pos) == [1, 2, 3]
    d.efc_force[-1] = 7.5
    assert d._ptr.efc_force[d.nefc - 1] == 7.5
    d.efc_force = np.arange(d.nefc)                    # assignment writes into C
    assert [d._ptr.efc_force[i] for i in range(d.nefc)] == list(range(d.nefc))
    with pytest.raises(AttributeError, match="cannot be assigned"):
        d.contact = None
    with pytest.raises(AttributeError, match="no setter"):
        d.contact.dist = 0


def test_unallocated_memory_reads_as_a_new_array_each_time(mujoco):
    """A NULL pointer (an inactive effective metric) reads as a new array of its fill,
    as in the official bindings: a write into one is not seen by the next read."""
    m, d, om, od = _twins(mujoco, path=HUMANOID)
    for _ in range(50):
        mjcffi.mj_step(m, d)
        mujoco.mj_step(om, od)
    nulls = [name for name in _moving(type(d))
             if getattr(d._ptr, name) == ffi.NULL and getattr(d, name).size]
    assert nulls
    for name in nulls:
        first = getattr(d, name)
        first[...] = 5
        again = getattr(d, name)
        assert again is not first and not (again == 5).any(), name
        _assert_same(again, getattr(od, name), name)


def test_views_keep_their_memory_alive_and_make_no_cycle():
    """Views and contact lists hold the MjData's memory, not the MjData: the wrapper
    goes at once when deleted (no reference cycle), the memory when the last view goes."""
    m = mjcffi.MjModel.from_xml_string(STACK)
    d = mjcffi.MjData(m)
    for _ in range(150):
        mjcffi.mj_step(m, d)
    force, contacts, dist, first = d.efc_force, d.contact, d.contact.dist, d.contact[0]
    island = d.island_nefc
    expected = (force.copy(), dist.copy(), first.pos.copy(), island.copy(), len(contacts))
    wrapper, root = weakref.ref(d), weakref.ref(d._root)
    del d
    assert wrapper() is None                              # freed by its reference count
    gc.collect()
    garbage = [bytearray(1 << 20) for _ in range(20)]     # reuse of freed memory
    assert root() is not None
    assert np.array_equal(force, expected[0]) and np.array_equal(dist, expected[1])
    assert np.array_equal(first.pos, expected[2]) and np.array_equal(island, expected[3])
    assert len(contacts) == expected[4] and np.array_equal(contacts.dist, expected[1])
    assert np.array_equal(contacts[0].pos, expected[2])
    del force, contacts, dist, first, island, garbage
    gc.collect()
    assert root() is None


def test_entries_follow_the_count_when_nothing_else_is_read():
    """d.contact[i] alone, step after step: an entry past the new ncon is an IndexError,
    never a wrapper cached when there were more; the others point at the contact now."""
    m = mjcffi.MjModel.from_xml_string(STACK)
    d = mjcffi.MjData(m)
    contacts, most, shrank = d.contact, 0, 0
    for _ in range(400):
        mjcffi.mj_step(m, d)
        for i in range(most):
            if i < d.ncon:
                assert contacts[i]._ptr == d._ptr.contact + i
                assert contacts[i] is contacts[i]
            else:
                with pytest.raises(IndexError):
                    contacts[i]
                shrank += 1
        most = max(most, d.ncon)
    assert shrank > 0


# ------------------------------------------------------------------- scenes

GEOMS = """
<mujoco>
  <worldbody>
    <geom type="plane" size="1 1 .1"/>
    <body pos="0 0 .2"><freejoint/><geom type="box" size=".1 .1 .1"/></body>
    <body pos=".3 0 .2"><freejoint/><geom type="sphere" size=".1"/></body>
  </worldbody>
</mujoco>
"""


def _update(lib, m, d, scn):
    lib.mjv_updateScene(m, d, lib.MjvOption(), lib.MjvPerturb(), lib.MjvCamera(),
                        lib.mjtCatBit.mjCAT_ALL, scn)


def test_scene_geoms_follow_updates_and_remakes(mujoco):
    m, d, om, od = _twins(mujoco, xml=GEOMS)
    scn, oscn = mjcffi.MjvScene(m, 30), mujoco.MjvScene(om, 30)
    held, order = scn.geoms, scn.geomorder
    for _ in range(3):
        mjcffi.mj_step(m, d)
        mujoco.mj_step(om, od)
        _update(mjcffi, m, d, scn)
        _update(mujoco, om, od, oscn)
        assert scn.ngeom == oscn.ngeom > 0 and len(held) == 30
        for name in ("pos", "size", "mat", "rgba", "type", "objid"):
            ours = getattr(scn.geoms, name)[:scn.ngeom]
            official = np.array([np.reshape(getattr(g, name), getattr(ours, "shape")[1:])
                                 for g in oscn.geoms[:oscn.ngeom]])
            assert np.array_equal(ours, official.astype(ours.dtype)), name
            assert getattr(held, name) is getattr(scn.geoms, name), name     # cached
        assert scn.geoms[1].pos.tolist() == list(oscn.geoms[1].pos)
    old_pos, old_root = held.pos, weakref.ref(scn._root)
    mjcffi.mjv_makeScene(m, scn, 50)                     # a new scene in new memory
    assert len(held) == 50 and held.pos.shape == (50, 3) and held.pos is not old_pos
    assert scn.geomorder.shape == (50,) and order.shape == (30,)
    assert scn.geoms is held
    del old_pos, order, ours
    gc.collect()
    assert old_root() is None                            # no cache held the old scene
    _update(mjcffi, m, d, scn)
    assert scn.ngeom == oscn.ngeom and held[0].pos.tolist() == list(oscn.geoms[0].pos)
    mjcffi.mjv_freeScene(scn)
    assert len(held) == 0 and held.pos.shape == (0, 3) and scn.geomorder.shape == (0,)


FLEX = """
<mujoco>
  <worldbody>
    <flexcomp type="grid" count="3 3 1" spacing=".1 .1 .1" radius=".01" name="cloth" dim="2">
      <edge equality="true"/>
    </flexcomp>
    <body name="ball" pos="0 0 1"><freejoint/><geom size=".1"/></body>
  </worldbody>
</mujoco>
"""


def _assert_scene_same(scn, oscn, name):
    if name == "flextexcoord":          # a flex with no texture: memory never written
        assert getattr(scn, name).shape == getattr(oscn, name).shape
    else:
        _assert_same(getattr(scn, name), getattr(oscn, name), name)


def test_scene_flex_arrays_follow_their_counts_and_remakes(mujoco):
    """The scene's flex arrays (AllocatedArray: sized by counts in other arrays) and
    the arrays sized by nflex follow a write of nflex, an update and a remake."""
    m, d, om, od = _twins(mujoco, xml=FLEX)
    scn, oscn = mjcffi.MjvScene(m, 100), mujoco.MjvScene(om, 100)
    mjcffi.mj_forward(m, d)
    mujoco.mj_forward(om, od)
    _update(mjcffi, m, d, scn)
    _update(mujoco, om, od, oscn)
    names = ("flexedgeadr", "flexedgenum", "flexvertadr", "flexvertnum", "flexfaceadr",
             "flexfacenum", "flexfaceused", "flexedge", "flexvert", "flexface", "flexnormal",
             "flextexcoord")
    for name in names:
        _assert_scene_same(scn, oscn, name)
        assert getattr(scn, name) is getattr(scn, name) or getattr(scn, name).size == 0, name
    vert = scn.flexvert
    assert scn.nflex == 1 and vert.size
    scn.nflex = 0                                       # within what was allocated
    assert scn.flexvert.shape == (0,) and scn.flexedgeadr.shape == (0,)
    scn.nflex = 1
    assert scn.flexvert.shape == vert.shape and np.array_equal(scn.flexvert, vert)
    scn.flexvertnum[0] -= 1                            # a count held in another array
    assert scn.flexvert.shape == (vert.size - 3,)
    scn.flexvertnum[0] += 1
    assert scn.flexvert.shape == vert.shape
    scn.flexvertnum[0] += 1                            # past what was allocated
    with pytest.raises(ValueError, match="allocated"):
        scn.flexvert
    scn.flexvertnum[0] -= 1
    mjcffi.mjv_makeScene(m, scn, 10)
    _update(mjcffi, m, d, scn)
    for name in names:
        _assert_scene_same(scn, oscn, name)
    assert scn.flexvert is not vert


def test_static_struct_arrays_read_their_fields_across_entries():
    """A StructArray of fixed entries (d.warning, a slice of d.contact) gives the same
    field views as its entries, made once."""
    m = mjcffi.MjModel.from_xml_string(STACK)
    d = mjcffi.MjData(m)
    for _ in range(150):
        mjcffi.mj_step(m, d)
    assert d.timer.number is d.timer.number
    assert d.timer.number.tolist() == [t.number for t in d.timer]
    part = d.contact[1::2]
    assert part.dist.tolist() == [c.dist for c in part]
    assert part.dist.tolist() == d.contact.dist[1::2].tolist()
    backwards = d.contact[::-1]
    assert backwards.pos.tolist() == d.contact.pos[::-1].tolist()
    records = d.contact.records()
    for name in _contact_fields():
        assert np.array_equal(records[name], getattr(d.contact, name)), name
    with pytest.raises(AttributeError, match="has no attribute 'nope'"):
        d.contact.nope
    with pytest.raises(AttributeError, match="has no attribute 'nope'"):
        d.warning.nope
