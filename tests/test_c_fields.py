"""The fields read in C (mjcffi._descriptors, issue 35): a struct's scalars are read at
their offset, and the cached views of its moving memory returned while the words that
define them are unchanged.  Each C read must give what cffi's own read of the field
gives (the same value, of the same Python type), for every scalar of every struct
class; and the C side must refuse what would read out of bounds, and hold nothing
that outlives its wrapper."""

import gc
import importlib
import math
import operator
import pkgutil
import random
import weakref

import pytest

import mjcffi
import mjcffi.structs
import mjcffi.structs.mjspec
from mjcffi._descriptors import MOVING, Field, Holder
from mjcffi._support import views
from mjcffi._support.library import ffi

from .conftest import gymnasium_assets

HUMANOID = next(p for p in gymnasium_assets() if p.name == "humanoid.xml")


def _struct_classes():
    """Every generated struct class (one per C struct type, with its Scalar fields)."""
    found = {}
    for info in pkgutil.iter_modules(mjcffi.structs.__path__, "mjcffi.structs."):
        module = importlib.import_module(info.name)
        for cls in vars(module).values():
            if isinstance(cls, type) and issubclass(cls, views.Struct) and cls._ctype is not None:
                found.setdefault(cls._cname, cls)
    return sorted(found.values(), key=lambda cls: cls._cname)


CLASSES = _struct_classes()


def _scalars(cls):
    return [(name, value) for klass in cls.__mro__ for name, value in vars(klass).items()
            if type(value) is views.Scalar]


def _same(a, b):
    return type(a) is type(b) and (a == b or (isinstance(a, float) and math.isnan(a)
                                              and math.isnan(b)))


def test_there_are_struct_classes_with_scalars_to_check():
    assert len(CLASSES) > 60
    assert sum(len(_scalars(cls)) for cls in CLASSES) > 600


@pytest.mark.parametrize("cls", CLASSES, ids=lambda cls: cls._cname)
def test_every_scalar_reads_in_c_what_cffi_reads_over_random_bytes(cls):
    """Over random bytes, every Scalar of the class reads (in C) the value and type
    that cffi reads from the same memory: offsets, widths, signedness and floats."""
    size = ffi.sizeof(cls._ctype)
    rng = random.Random(size)
    for _ in range(3):
        memory = ffi.new("unsigned char[]", bytes(rng.getrandbits(8) for _ in range(size)))
        obj = cls.__new__(cls)           # no eager fields: nothing points anywhere
        obj.__dict__.update(_ptr=ffi.cast(ffi.getctype(cls._ctype, "*"), memory),
                            _root=memory)
        for name, field in _scalars(cls):
            mine = field.__get__(obj, cls)
            try:
                theirs = getattr(obj._ptr, field.field)
            except ValueError:           # cffi refuses a _Bool byte other than 0 or 1
                assert views._field_at(cls._ctype, field.field)[0].cname == "_Bool"
                theirs = True            # C reads it as C does: nonzero is true
            assert _same(mine, theirs), (cls._cname, name, mine, theirs)


@pytest.mark.parametrize("cls", CLASSES, ids=lambda cls: cls._cname)
def test_every_scalar_is_read_in_c_unless_cffi_reads_it_as_bytes_or_a_pointer(cls):
    for name, field in _scalars(cls):
        ftype, _ = views._field_at(cls._ctype, field.field)
        if field._kind == 0:
            assert ftype.kind in ("pointer", "function") or ftype.cname == "char", \
                (cls._cname, name, ftype.cname)
        else:
            assert 1 <= field._kind < MOVING, (cls._cname, name, field._kind)


def test_the_c_fields_are_properties_as_the_official_ones_are(mujoco):
    """Code that looks fields up in a class's __dict__ and asks for a property (as the
    official classes hold) finds one for every field read in C."""
    checked = 0
    for ours, theirs in [(mjcffi.MjModel, mujoco.MjModel), (mjcffi.MjData, mujoco.MjData),
                         (mjcffi.MjOption, mujoco.MjOption), (mjcffi.MjvScene, mujoco.MjvScene)]:
        for name, value in vars(theirs).items():
            mine = vars(ours).get(name)
            if isinstance(value, property) and isinstance(mine, Field):
                assert isinstance(mine, property) and callable(mine.fget), (ours.__name__, name)
                checked += 1
    assert checked > 250
    assert isinstance(mjcffi.MjModel.nq, property) and isinstance(mjcffi.MjData.efc_force, property)
    assert mjcffi.MjModel.nq.__doc__ == "number of generalized coordinates = dim(qpos)"


def test_real_structs_read_the_same_in_c_and_through_cffi_after_steps(mujoco):
    m = mjcffi.MjModel.from_xml_path(str(HUMANOID))
    d = mjcffi.MjData(m)
    om = mujoco.MjModel.from_xml_path(str(HUMANOID))
    od = mujoco.MjData(om)
    for step in range(120):
        mjcffi.mj_step(m, d)
        mujoco.mj_step(om, od)
        if step % 40 == 39:
            for obj, theirs in [(m, om), (d, od), (m.opt, om.opt), (m.vis.global_, om.vis.global_),
                                (m.stat, om.stat)]:
                for name, field in _scalars(type(obj)):
                    mine = getattr(obj, name)
                    assert _same(mine, getattr(obj._ptr, field.field)), name
                    if hasattr(theirs, name):
                        assert mine == getattr(theirs, name), name
    assert d.ncon > 0 and d.nefc > 0
    d.time = 12.5
    m.opt.timestep = 0.004
    assert (d.time, m.opt.timestep, d._ptr.time, m._ptr.opt.timestep) == (12.5, 0.004, 12.5, 0.004)


def test_a_remade_scene_reads_its_new_memory_in_c():
    m = mjcffi.MjModel.from_xml_path(str(HUMANOID))
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    scn = mjcffi.MjvScene(m, 50)
    assert scn.maxgeom == len(scn.geoms) == 50
    mjcffi.mjv_updateScene(m, d, mjcffi.MjvOption(), None, mjcffi.MjvCamera(),
                           mjcffi.mjtCatBit.mjCAT_ALL, scn)
    flexvert = scn.flexvert
    assert scn.ngeom > 0
    mjcffi.mjv_makeScene(m, scn, 400)
    assert (scn.maxgeom, scn.ngeom) == (400, 0) == (scn._ptr.maxgeom, scn._ptr.ngeom)
    assert len(scn.geoms) == 400
    assert scn.flexvert.shape == flexvert.shape
    other = mjcffi.MjData(m)
    other.time = 3.0
    assert (d.time, other.time) == (d._ptr.time, 3.0)


def test_a_forgotten_address_is_found_again():
    m = mjcffi.MjModel.from_xml_path(str(HUMANOID))
    d = mjcffi.MjData(m)
    for _ in range(50):
        mjcffi.mj_step(m, d)
    force, nefc = d.efc_force, d.nefc
    assert d._dyn is not None
    d._forget_memory()
    assert d._dyn is None
    assert d.nefc == nefc and (d.efc_force == force).all()
    assert d.efc_force is d.efc_force


def test_a_struct_without_memory_reads_through_python_and_says_why():
    obj = mjcffi.MjOption.__new__(mjcffi.MjOption)        # never given a _ptr
    with pytest.raises(AttributeError, match="_ptr"):
        obj.timestep
    with pytest.raises(AttributeError, match="_ptr"):
        obj.timestep


def test_the_c_cache_makes_no_cycle_that_gc_cannot_collect():
    m = mjcffi.MjModel.from_xml_path(str(HUMANOID))
    d = mjcffi.MjData(m)
    mjcffi.mj_step(m, d)
    d.efc_force
    d._dyn.append((None, d, False, None))      # a cycle through the C slot
    wrapper = weakref.ref(d)
    del d
    gc.collect()
    assert wrapper() is None


def test_the_private_c_entry_points_refuse_what_would_read_out_of_bounds():
    d = mjcffi.MjData(mjcffi.MjModel.from_xml_path(str(HUMANOID)))
    with pytest.raises(TypeError, match="_dyn must be a list"):
        d._dyn = (1, 2)
    field = views.Scalar("x", lambda obj: 0, None, "")
    owner = mjcffi.MjOption
    with pytest.raises(ValueError, match="no scalar of kind 10 at offset 100"):
        field._bind_scalar(owner, 100, 10, 104)
    with pytest.raises(ValueError, match="no scalar of kind 12"):
        field._bind_scalar(owner, 0, 12, 104)
    with pytest.raises(ValueError, match="outside a 16-byte struct"):
        field._bind_moving(owner, 0, (16,), 16)
    with pytest.raises(ValueError, match="1 to 8 key words"):
        field._bind_moving(owner, 0, (), 16)
    for not_a_struct_class in (int, mjcffi.MjOption(), None):
        with pytest.raises(TypeError, match="binds to a struct class"):
            field._bind_scalar(not_a_struct_class, 0, 10, 104)
    assert field._kind == 0


def test_a_field_reads_in_c_only_instances_of_its_own_struct_class():
    """Another struct's memory has another layout: a field of MjModel given an MjOption
    (or an MjData given to MjvScene's moving array) reads through cffi, which says the
    struct has no such field, as before the C reads."""
    m = mjcffi.MjModel.from_xml_path(str(HUMANOID))
    d = mjcffi.MjData(m)
    with pytest.raises(AttributeError, match="signature"):
        vars(mjcffi.MjModel)["signature"].__get__(m.opt)
    with pytest.raises(AttributeError, match="MjvScene has no field 'efc_force'"):
        vars(mjcffi.MjData)["efc_force"].__get__(mjcffi.MjvScene(m, 10))
    assert vars(mjcffi.MjModel)["nq"].__get__(m) == m._ptr.nq
    mjcffi.mj_step(m, d)
    assert vars(mjcffi.MjData)["efc_force"].__get__(d) is d.efc_force


def test_a_class_and_its_fields_are_collected_together():
    """A field holds its struct class (for the C check above); the GC sees that edge, so a
    class made at run time goes with its fields."""
    field = views.Scalar("timestep", operator.attrgetter("_ptr.timestep"), None, "")
    cls = views.StructType("Made", (views.ValueStruct,),
                           {"_cname": "mjOption", "_ctype": mjcffi.MjOption._ctype,
                            "timestep": field})
    assert field._kind and cls().timestep == 0.0
    gone = weakref.ref(cls), weakref.ref(field)
    del cls, field
    gc.collect()
    assert [ref() for ref in gone] == [None, None]


def test_malformed_cache_entries_are_made_again_not_trusted():
    m = mjcffi.MjModel.from_xml_path(str(HUMANOID))
    d = mjcffi.MjData(m)
    for _ in range(50):
        mjcffi.mj_step(m, d)
    expected = d.efc_force.copy()
    d._dyn = [("junk",), 3, (b"short", None, True, None)] * 300
    assert (d.efc_force == expected).all() and d.efc_force.shape == (d.nefc,)


def test_struct_instances_are_holders():
    assert issubclass(views.Struct, Holder)
    assert isinstance(mjcffi.MjOption(), Holder)


def test_a_deleted_spec_element_is_never_read_in_c():
    """After spec.delete, even the class's own descriptor, called directly, does not
    read the freed element: the C side forgot its address."""
    spec = mjcffi.MjSpec()
    body = spec.worldbody.add_body()
    body.gravcomp = 0.25
    field = vars(mjcffi.structs.mjspec.MjsBody)["gravcomp"]      # the generated class
    assert type(field) is views.Scalar and field._kind and field.__get__(body) == 0.25
    spec.delete(body)
    with pytest.raises(ValueError, match="deleted"):
        field.__get__(body)
