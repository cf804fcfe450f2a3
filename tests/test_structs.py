"""The struct classes: zero-copy views, shapes and dtypes equal to the official ones,
lifetimes, copying and pickling."""

import copy
import gc
import pickle
import resource

import numpy as np
import pytest

import mjcffi
from mjcffi import structs

from .conftest import gymnasium_assets

ffi, lib = mjcffi.ffi, mjcffi.lib
PENDULUM = """
<mujoco>
  <worldbody>
    <body name="pole">
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -1" size=".05"/>
    </body>
  </worldbody>
</mujoco>
"""


def _step(m, d, n=1):
    for _ in range(n):
        lib.mj_step(m._ptr, d._ptr)


def _official_arrays(obj):
    for name in dir(obj):
        if name.startswith("_"):
            continue
        try:
            value = getattr(obj, name)
        except Exception:       # some official properties need a context
            continue
        if isinstance(value, np.ndarray):
            yield name, value


# Array fields whose values may differ between two runs of the same model in two
# bindings, with why.  (Every other field is compared by value too.)
DIFFERING = {
    "plugin_data": "addresses of each MjData's own plugin instances",
}
# With a dense constraint Jacobian (mj_isSparse false), MuJoCo never writes the
# sparse structure of efc_J (mj_addConstraint): these hold whatever the arena
# held before, which differs between two MjData.
DENSE_UNWRITTEN = {"efc_J_rownnz", "efc_J_rowadr", "efc_J_colind", "efc_J_rowsuper"}


def _same_controls(m, steps, seed=0):
    """A fixed control sequence within the model's control ranges."""
    rng = np.random.default_rng(seed)
    low, high = np.where(m.actuator_ctrllimited[:, None], m.actuator_ctrlrange,
                         [-1.0, 1.0]).T if m.nu else (np.zeros(0), np.zeros(0))
    return rng.uniform(low, high, size=(steps, m.nu))


@pytest.mark.parametrize("jacobian", ["auto", "sparse"])
@pytest.mark.parametrize("path", gymnasium_assets(), ids=lambda p: p.stem)
def test_item_array_fields_match_the_official_names_shapes_dtypes_and_values(mujoco, path,
                                                                           jacobian):
    """Every official array field of MjModel and MjData, after 50 steps with the same
    controls in both bindings: same name, shape, dtype and value.  The gymnasium
    models are small enough for a dense Jacobian; a sparse one is forced too."""
    m, om = mjcffi.MjModel.from_xml_path(path), mujoco.MjModel.from_xml_path(str(path))
    if jacobian == "sparse":
        m.opt.jacobian = om.opt.jacobian = mjcffi.mjtJacobian.mjJAC_SPARSE
    d, od = mjcffi.MjData(m), mujoco.MjData(om)
    for ctrl in _same_controls(m, 50):
        d.ctrl[:], od.ctrl[:] = ctrl, ctrl
        mjcffi.mj_step(m, d)
        mujoco.mj_step(om, od)
    unwritten = set() if mjcffi.mj_isSparse(m) else DENSE_UNWRITTEN
    compared = valued = 0
    for ours, theirs in ((m, om), (d, od)):
        for name, official in _official_arrays(theirs):
            mine = getattr(ours, name)
            assert isinstance(mine, np.ndarray), name
            assert (mine.shape, mine.dtype) == (official.shape, official.dtype), name
            compared += 1
            if name in DIFFERING or name in unwritten:
                continue
            assert np.array_equal(mine, official, equal_nan=mine.dtype.kind in "fc"), name
            valued += 1
    assert compared > 600 and valued >= compared - len(DIFFERING) - len(unwritten)
    assert d.time == od.time > 0 and d.ncon == od.ncon and d.nefc == od.nefc


def test_views_are_zero_copy_and_writes_reach_the_next_step():
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    d = mjcffi.MjData(m)
    qpos = d.qpos
    assert d.qpos is qpos                                   # cached
    assert qpos.ctypes.data == int(ffi.cast("uintptr_t", d._ptr.qpos))
    qpos[0] = 0.5
    assert d._ptr.qpos[0] == 0.5
    d.qvel = [2.0]                                          # assignment writes into C
    assert d._ptr.qvel[0] == 2.0 and d.qvel is not None
    _step(m, d)
    assert qpos[0] != 0.5 and d.time == m.opt.timestep      # the step saw and moved it
    m.opt.gravity[:] = 0
    m.opt.timestep = 0.01
    assert m._ptr.opt.gravity[2] == 0 and m._ptr.opt.timestep == 0.01


def test_shapes_and_dtypes_of_headline_fields():
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    d = mjcffi.MjData(m)
    assert d.xpos.shape == (m.nbody, 3) and d.xpos.dtype == np.float64
    assert m.qpos0.shape == (m.nq,)
    assert m.body_user.shape == (m.nbody, 0)
    assert m.geom_rgba.dtype == np.float32 and m.jnt_type.dtype == np.int32
    assert m.body_simple.dtype == np.uint8 and d.eq_active.dtype == np.bool_
    assert m.opt.gravity.shape == (3,)
    assert isinstance(m.names, bytes) and m.names.startswith(b"MuJoCo Model")


def test_empty_arrays_are_zero_length_views_not_none():
    d = mjcffi.MjData(mjcffi.MjModel.from_xml_string(PENDULUM))
    assert d.ctrl.shape == (0,) and d.mocap_pos.shape == (0, 3)
    assert len(d.contact) == 0 and d.contact.dist.shape == (0,)


def test_views_outlive_their_owners():
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    d = mjcffi.MjData(m)
    d.qpos[0] = 0.25
    qpos, body_pos, opt = d.qpos, m.body_pos, m.opt
    expected = body_pos.copy()
    del m, d
    gc.collect()
    assert qpos[0] == 0.25
    assert np.array_equal(body_pos, expected)
    assert opt.timestep == 0.002
    qpos[0] = 1.0                                            # still writable, still valid


def test_creating_and_freeing_data_does_not_leak():
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    for _ in range(2000):                                    # warm up allocator and caches
        mjcffi.MjData(m).qpos
    gc.collect()
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    for _ in range(100_000):
        d = mjcffi.MjData(m)
        d.qpos[0] = 1.0
    del d
    gc.collect()
    grown_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    assert grown_kib < 1024


def test_contacts_are_valid_for_ncon_entries():
    m = mjcffi.MjModel.from_xml_string(
        '<mujoco><worldbody><geom type="plane" size="1 1 .1"/>'
        '<body pos="0 0 .09"><freejoint/><geom type="box" size=".1 .1 .1"/></body>'
        '</worldbody></mujoco>')
    d = mjcffi.MjData(m)
    _step(m, d, 5)
    assert d.ncon == len(d.contact) == 4
    assert d.contact.dist.shape == (4,) and d.contact.pos.shape == (4, 3)
    assert d.contact[0].geom[1] == 1 and d.contact[-1].dist == d.contact.dist[-1]
    with pytest.raises(IndexError, match="out of range for 4"):
        d.contact[4]
    with pytest.raises(TypeError, match="integers"):
        d.contact["0"]


def test_fixed_arrays_of_structs():
    d = mjcffi.MjData(mjcffi.MjModel.from_xml_string(PENDULUM))
    assert len(d.warning) == int(mjcffi.mjtWarning.mjNWARNING)
    assert d.warning.number.shape == (len(d.warning),)
    d.warning[mjcffi.mjtWarning.mjWARN_BADQACC].number = 3
    assert d.warning.number[int(mjcffi.mjtWarning.mjWARN_BADQACC)] == 3
    assert len(d.timer) == int(mjcffi.mjtTimer.mjNTIMER)
    assert len(d.solver) == mjcffi.mjNISLAND * mjcffi.mjNSOLVER


def test_nested_structs_share_memory_and_assignment_copies_in_place(mujoco):
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    opt = m.opt
    assert m.opt is opt and m.vis.global_.fovy == 45.0
    fresh = mjcffi.MjOption()
    fresh.timestep = 0.005
    m.opt = fresh                                  # copies the fields into m's mjOption
    assert opt.timestep == 0.005 and m._ptr.opt.timestep == 0.005
    fresh.timestep = 0.1
    assert m.opt.timestep == 0.005                 # later changes do not propagate
    with pytest.raises(TypeError, match="MjOption"):
        m.opt = mjcffi.MjvOption()


def _flipped(struct):
    """A new struct of the same type whose every byte differs from `struct`'s."""
    return type(struct)._from_bytes(bytes(b ^ 0xA5 for b in _raw(struct)))


def _raw(struct):
    return ffi.buffer(struct._ptr, ffi.sizeof(struct._ctype))[:]


def _equal_fields(a, b, label):
    """Every field of two ValueStructs equal, NaN equal to NaN, nested ones recursively."""
    for name in a._fields:
        x, y = getattr(a, name), getattr(b, name)
        if isinstance(x, mjcffi._support.views.Struct):
            _equal_fields(x, y, f"{label}.{name}")
        elif isinstance(x, np.ndarray):
            assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), (label, name)
        else:
            assert x == y or x != x and y != y, (label, name)


def _spec_owners():
    """An MjSpec and one element of each kind that holds nested structs."""
    spec = mjcffi.mj_makeSpec()
    world = mjcffi.mjs_findBody(spec, "world")
    body = mjcffi.mjs_addBody(world, None)
    frame = structs.MjsFrame._wrap(lib.mjs_addFrame(body._ptr, ffi.NULL), spec._root)
    return {"MjSpec": spec, "MjsCompiler": spec.compiler, "MjsBody": body, "MjsFrame": frame,
            "MjsGeom": mjcffi.mjs_addGeom(body, None), "MjsSite": mjcffi.mjs_addSite(body, None),
            "MjsCamera": mjcffi.mjs_addCamera(body, None),
            "MjsMesh": mjcffi.mjs_addMesh(spec, None),
            "MjsActuator": mjcffi.mjs_addActuator(spec, None),
            "MjsSensor": mjcffi.mjs_addSensor(spec)}


def test_item_struct_assignment_copies_every_byte_of_every_nested_struct():
    """`owner.nested = other` for every nested struct of every class, from a struct
    whose every byte differs: afterwards all its bytes (and so every field) are the
    other's, and not one byte of the owner outside it changed.  A nested struct
    holding pointers (a spec's MjsCompiler) is refused, and nothing changes."""
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    owners = {"MjModel": m, "MjVisual": mjcffi.MjVisual(), "MjuiItem": structs.MjuiItem(),
              "MjuiSection": structs.MjuiSection(), "MjUI": structs.MjUI(), **_spec_owners()}
    classes = {name: getattr(structs, name) for name in structs.MODULES}
    classes["MjModel"] = mjcffi.MjModel
    assigned = refused = 0
    for name, cls in classes.items():
        nested = [attr for klass in cls.__mro__ for attr, field in vars(klass).items()
                  if isinstance(field, mjcffi._support.views.Nested)]
        if not nested:
            continue
        owner = owners[name]              # a KeyError here: a new owner, add it above
        for attr in nested:
            target = getattr(owner, attr)
            other, before = _flipped(target), _raw(owner)
            start = target._address - owner._address
            end = start + ffi.sizeof(target._ctype)
            if not target._plain:
                with pytest.raises(TypeError, match="pointers"):
                    setattr(owner, attr, other)
                setattr(owner, attr, target)                  # to itself: nothing to do
                assert _raw(owner) == before, (name, attr)
                refused += 1
                continue
            setattr(owner, attr, other)
            after = _raw(owner)
            assert after[start:end] == _raw(other), (name, attr)
            assert after[:start] == before[:start] and after[end:] == before[end:], (name, attr)
            if isinstance(target, mjcffi._support.views.ValueStruct):
                _equal_fields(target, other, f"{name}.{attr}")
            assigned += 1
    assert assigned >= 25 and refused >= 2
    # and the headline case, through the public classes: m.opt = other
    other = _flipped(m.opt)
    m.opt = other
    assert _raw(m.opt) == _raw(other) and m.opt.timestep == other.timestep


def test_item_whole_struct_copies_keep_every_byte():
    """copy, deepcopy and pickle of every plain struct that Python can make, from an
    instance whose every byte differs from a fresh one: all bytes kept."""
    copied = 0
    for name in structs.MODULES:
        cls = getattr(structs, name)
        if not cls._plain:
            continue
        try:
            fresh = cls()
        except TypeError:
            continue                       # MuJoCo makes it, or it takes arguments
        source = _flipped(fresh)
        for copied_struct in (copy.copy(source), copy.deepcopy(source),
                              pickle.loads(pickle.dumps(source))):
            assert _raw(copied_struct) == _raw(source), name
        copied += 1
    assert copied >= 20


def test_bad_assignments_name_the_field():
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    d = mjcffi.MjData(m)
    with pytest.raises(AttributeError, match="no field 'qpso'"):
        d.qpso = [0]
    with pytest.raises(AttributeError):
        m.nq = 5
    with pytest.raises(ValueError, match="qpos"):
        d.qpos = [1.0, 2.0, 3.0]
    with pytest.raises(TypeError, match="timestep"):
        m.opt.timestep = "fast"
    with pytest.raises(ValueError, match="ngeom"):
        mjcffi.MjvScene(m, 10).ngeom = 11


def _compare_fields(ours, theirs, label):
    """Compare every field of two structs, recursing into nested ones; count them."""
    compared = 0
    for field, _ in ours._ctype.fields:
        attr = field + "_" if field == "global" else field
        value, official = getattr(ours, attr), getattr(theirs, attr)
        if isinstance(value, mjcffi._support.views.Struct):
            compared += _compare_fields(value, official, f"{label}.{attr}")
        elif isinstance(value, np.ndarray):
            assert np.array_equal(value, official), (label, field)
            compared += 1
        else:
            assert value == official, (label, field)
            compared += 1
    return compared


def test_default_initialized_structs_equal_the_official_ones(mujoco):
    for name in ("MjOption", "MjvOption", "MjvCamera", "MjvPerturb", "MjStatistic"):
        ours, theirs = getattr(mjcffi, name)(), getattr(mujoco, name)()
        assert _compare_fields(ours, theirs, name) >= 4, name


def test_lropt_is_default_initialized_as_documented():
    # python.rst: a struct with an mj_defaultFoo initializer gets it.  (The official
    # MjLROpt() of 4.0.0 is all zeros; we follow the documented behaviour.)
    ours, reference = mjcffi.MjLROpt(), ffi.new("mjLROpt *")
    lib.mj_defaultLROpt(reference)
    assert ours._bytes() == ffi.buffer(reference)[:]
    assert ours.mode == 1


def test_constructors():
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    with pytest.raises(TypeError, match="no constructor"):
        mjcffi.MjModel()
    with pytest.raises(TypeError, match="model must be MjModel"):
        mjcffi.MjData(mjcffi.MjOption())
    scene = mjcffi.MjvScene(m, maxgeom=50)
    assert scene.maxgeom == 50 and len(scene.geoms) == 50 and scene.ngeom == 0
    assert mjcffi.MjvScene().maxgeom == 0


def test_every_struct_class_builds_reprs_and_copies():
    built = 0
    for name in structs.MODULES:
        cls = getattr(structs, name)          # the generated classes themselves
        try:
            obj = cls(0, 0, 0, 0) if name == "MjrRect" else cls()
        except TypeError as exc:
            assert "no constructor" in str(exc) or "." in cls._cname, name
            continue
        assert repr(obj).startswith(f"<{name}"), name
        if obj._plain:
            clone = copy.copy(obj)
            assert ffi.buffer(clone._ptr, ffi.sizeof(cls._ctype))[:] == \
                ffi.buffer(obj._ptr, ffi.sizeof(cls._ctype))[:]
            assert pickle.loads(pickle.dumps(obj))._bytes() == obj._bytes()
        else:
            with pytest.raises(TypeError, match="pointers"):
                copy.copy(obj)
        built += 1
    assert built > 30


def _full_state(m, d):
    size = lib.mj_stateSize(m._ptr, mjcffi.mjtState.mjSTATE_INTEGRATION)
    state = np.empty(size)
    lib.mj_getState(m._ptr, d._ptr, ffi.cast("mjtNum *", state.ctypes.data),
                    mjcffi.mjtState.mjSTATE_INTEGRATION)
    return state


@pytest.mark.parametrize("how", ["copy", "deepcopy", "pickle"])
def test_data_copies_are_bit_exact_and_step_identically(how):
    path = next(p for p in gymnasium_assets() if p.name == "ant.xml")
    m = mjcffi.MjModel.from_xml_path(path)
    d = mjcffi.MjData(m)
    d.ctrl[:] = 0.3
    _step(m, d, 50)
    other = {"copy": copy.copy, "deepcopy": copy.deepcopy,
             "pickle": lambda x: pickle.loads(pickle.dumps(x))}[how](d)
    assert other is not d and other._ptr != d._ptr
    for field in ("qpos", "qvel", "qacc_warmstart", "xpos", "cacc", "efc_force", "sensordata"):
        assert getattr(other, field).tobytes() == getattr(d, field).tobytes(), field
    assert (other.ncon, other.nefc, other.time) == (d.ncon, d.nefc, d.time)
    assert other.contact.dist.tobytes() == d.contact.dist.tobytes()
    om = other.model
    _step(m, d, 100)
    _step(om, other, 100)
    assert _full_state(om, other).tobytes() == _full_state(m, d).tobytes()


@pytest.mark.parametrize("how", ["copy", "deepcopy", "pickle"])
def test_model_copies_are_bit_exact(how):
    path = next(p for p in gymnasium_assets() if p.name == "humanoid.xml")
    m = mjcffi.MjModel.from_xml_path(path)
    other = {"copy": copy.copy, "deepcopy": copy.deepcopy,
             "pickle": lambda x: pickle.loads(pickle.dumps(x))}[how](m)
    assert other._ptr != m._ptr
    for name in ("body_pos", "geom_size", "actuator_gear", "qpos0", "names_map"):
        assert getattr(other, name).tobytes() == getattr(m, name).tobytes()
    assert other.names == m.names and other.opt.timestep == m.opt.timestep


def test_binary_round_trip(tmp_path):
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    path = tmp_path / "pendulum.mjb"
    path.write_bytes(m.to_bytes())
    again = mjcffi.MjModel.from_binary_path(path)
    assert again.body_pos.tobytes() == m.body_pos.tobytes()
    with pytest.raises(ValueError, match="MJB"):
        mjcffi.MjModel.from_binary_path(tmp_path / "missing.mjb")


def test_unpickling_onto_a_model_of_other_sizes_is_refused():
    small = mjcffi.MjModel.from_xml_string(PENDULUM)
    path = next(p for p in gymnasium_assets() if p.name == "ant.xml")
    big = mjcffi.MjModel.from_xml_path(path)
    _, (model, *rest) = mjcffi.MjData(big).__reduce__()
    with pytest.raises(ValueError, match="does not fit its model"):
        mjcffi.data._unpickle(small, *rest)
    with pytest.raises(ValueError, match="does not fit its model"):
        mjcffi.data._unpickle(big, rest[0][:-8], *rest[1:])
