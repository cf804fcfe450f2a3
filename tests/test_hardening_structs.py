"""Issue 11, the struct wrappers' fields: every count that sizes a view is read-only
or bounded (the bounds derived from the struct metadata), and no scalar setter
lets an OverflowError out or writes a value the C field cannot hold.

Anything that could crash runs in a subprocess."""

import re
import subprocess
import sys
import textwrap

import pytest

import mjcffi
from codegen.structs import _EXTENTS
from mjcffi._support import views as _views
from mjcffi import structs
from mjcffi._generated.structinfo import STRUCTS

ffi, lib = mjcffi.ffi, mjcffi.lib

# Two flexes and a skin, so that a scene has something of each to bound.
FLEX = """
<mujoco>
  <worldbody>
    <flexcomp type="grid" count="3 3 1" spacing=".1 .1 .1" radius=".01" name="cloth" dim="2">
      <edge equality="true"/>
    </flexcomp>
    <flexcomp type="grid" count="2 2 1" spacing=".1 .1 .1" radius=".01" name="patch" dim="2"
              pos="0 0 .5">
      <edge equality="true"/>
    </flexcomp>
    <body name="ball" pos="0 0 1"><freejoint/><geom size=".1"/></body>
  </worldbody>
  <deformable>
    <skin name="skin" vertex="0 0 0 .1 0 0 0 .1 0" face="0 1 2">
      <bone body="ball" bindpos="0 0 0" bindquat="1 0 0 0" vertid="0 1 2" vertweight="1 1 1"/>
    </skin>
  </deformable>
</mujoco>
"""

PENDULUM = """
<mujoco>
  <worldbody>
    <body><joint type="hinge"/><geom type="capsule" fromto="0 0 0 0 0 -1" size=".05"/></body>
  </worldbody>
</mujoco>
"""


def _run(code):
    """Run `code` in a fresh interpreter: (return code, stdout + stderr)."""
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(code)],
                          capture_output=True, text=True, timeout=120)
    return done.returncode, done.stdout + done.stderr


def _classes():
    """{C struct name: class} for every struct class, MjModel and MjData included."""
    out = {getattr(structs, name)._cname: getattr(structs, name) for name in structs.MODULES}
    out["mjModel"], out["mjData"] = mjcffi.MjModel, mjcffi.MjData
    return out


def _descriptors(cls):
    """(attribute, descriptor) of every field of `cls`, the `_eager` ones included."""
    seen = {}
    for klass in reversed(cls.__mro__):
        seen.update(vars(klass))
    seen.update(cls._eager)
    return [(name, seen[name]) for name in cls._fields if name in seen]


def _writable(cls, attr):
    field = getattr(cls, attr, None)
    return isinstance(field, property) and field.fset is not None


# ----------------------------------------------------- which scalars size views

class _One(int):
    """1 as a scalar field; [1] as the ints a pointer field points to."""

    def __new__(cls):
        return super().__new__(cls, 1)

    def __getitem__(self, index):
        return [1]


class _Fields:
    """Stands for `s._ptr`: records the fields read."""

    def __init__(self, seen):
        self._seen = seen

    def __getattr__(self, name):
        self._seen.add(name)
        return _One()


class _Reads:
    """Stands for a wrapper `s` in a shape or count function: records the fields
    read on its own struct (s._ptr) and on its model (s._model._ptr)."""

    def __init__(self):
        self.own, self.model = set(), set()
        self._ptr = _Fields(self.own)
        self._model = type("Model", (), {"_ptr": _Fields(self.model)})()


def _sizing_from_views():
    """{C struct: scalars read to size its views}, found by running every view's
    shape or count function on a recorder."""
    found = {}
    for cname, cls in _classes().items():
        for _, field in _descriptors(cls):
            size = getattr(field, "shape", None) or getattr(field, "count", None)
            if not callable(size) or isinstance(field, _views.FixedRecords):
                continue
            reads = _Reads()
            size(reads)
            found.setdefault(cname, set()).update(reads.own)
            found.setdefault("mjModel", set()).update(reads.model)
    return found


def _sizing_from_metadata():
    """{C struct: scalars named by the extents in _structinfo and the generator's
    own (codegen.structs._EXTENTS)}: `self.X` of the struct itself, `m.X` of
    mjModel, `d.X` of mjData."""
    owners = {"m": "mjModel", "d": "mjData"}
    found = {}
    for cname, fields in STRUCTS.items():
        for field in fields:
            for extent in field.extents + _EXTENTS.get((cname, field.name), ()):
                for owner, name in re.findall(r"\b(self|m|d)\.(\w+)", str(extent)):
                    found.setdefault(owners.get(owner, cname), set()).add(name)
    return found


def _scalars(cname):
    return {f.name for f in STRUCTS[cname] if f.kind == "scalar"}


def test_item2_views_sized_by_counts_in_other_arrays_are_bounded_by_their_allocation():
    """A view whose size is a sum over a writable array of counts (a scene's flexedge:
    2*sum(flexedgenum)) is an AllocatedArray: its size cannot pass the allocation."""
    found = 0
    for cname, cls in _classes().items():
        pointers = {f.name for f in STRUCTS[cname] if f.kind == "pointer"}
        for attr, field in _descriptors(cls):
            if not isinstance(field, _views.Array):
                continue
            reads = _Reads()
            field.shape(reads)
            if reads.own & pointers:
                assert isinstance(field, _views.AllocatedArray), (cname, attr)
                assert attr in cls._allocated_views, (cname, attr)
                found += 1
    assert found == 7                     # the scene's flex and skin vertex data


def test_item2_every_scalar_that_sizes_a_view_is_read_only_or_bounded():
    classes = _classes()
    from_views, from_metadata = _sizing_from_views(), _sizing_from_metadata()
    checked = 0
    for cname in set(from_views) | set(from_metadata):
        scalars = _scalars(cname)
        names = (from_views.get(cname, set()) | from_metadata.get(cname, set())) & scalars
        # the views read no scalar that the metadata does not name
        assert from_views.get(cname, set()) & scalars <= from_metadata.get(cname, set()), cname
        cls = classes[cname]
        for name in names:
            if getattr(getattr(cls, name).fset, "keeps_value", False):
                # MjData.ncon, nefc: writable to the value they hold only, as MJX
                # writes them (mjcffi/_support/official_class.py, efc_count)
                _assert_keeps_value(cls, cname, name)
            else:
                assert not _writable(cls, name) or name in cls._bounds, \
                    f"{cls.__name__}.{name} sizes a view but is writable without a bound"
            checked += 1
    assert checked > 100                          # mjModel's sizes, mjData's, a scene's


def _assert_keeps_value(cls, cname, name):
    assert cname == "mjData" and name in ("ncon", "nefc"), (cname, name)
    m = mjcffi.MjModel.from_xml_string("<mujoco/>")
    d = mjcffi.MjData(m)
    setattr(d, name, getattr(d, name))
    with pytest.raises(ValueError, match="sizes the arrays laid out in the arena"):
        setattr(d, name, getattr(d, name) + 1)


def test_item2_bounds_come_from_the_metadata():
    """Each bound is a field of the same struct, the length of one of its fixed
    arrays, or what MuJoCo allocated; the message label says which."""
    bounded = 0
    for cname, cls in _classes().items():
        fields = {f.name: f for f in STRUCTS[cname]}
        for name, (low, high, label) in cls._bounds.items():
            assert fields[name].kind == "scalar" and _writable(cls, name), (cname, name)
            if high is None:
                assert name in cls._capacities and "allocated by mjv_make" in label
            elif isinstance(high, str):
                assert fields[high].kind == "scalar" and label == high, (cname, name)
            else:
                array = re.search(r"(?:len\(|index into )(\w+)", label).group(1)
                assert fields[array].kind == "array", (cname, name)
                assert high == fields[array].extents[0] + min(low, 0), (cname, name)
            bounded += 1
        assert set(cls._capacities) == {n for n, b in cls._bounds.items() if b.high is None}
    assert bounded >= 14


# ------------------------------------------------------------ writing past bounds

def _bounded_instances():
    m = mjcffi.MjModel.from_xml_string(FLEX)
    return {
        "MjvScene": mjcffi.MjvScene(m, 10),
        "MjData": mjcffi.MjData(m),
        "MjvFigure": mjcffi.MjvFigure(),
        "MjUI": structs.MjUI(),
        "MjuiSection": structs.MjuiSection(),
        "MjuiState": structs.MjuiState(),
        "MjuiItemMulti": structs.MjuiItemMulti(),
        "MjuiItemEdit": structs.MjuiItemEdit(),
        "MjrContext": mjcffi.MjrContext(),
    }


def test_item2_writing_past_a_bound_raises_value_error_naming_the_field_and_the_bound():
    instances = _bounded_instances()
    for cls in _classes().values():
        if cls._bounds:
            assert cls.__name__ in instances, f"add an instance of {cls.__name__} to test"
    checked = 0
    for label, obj in instances.items():
        for name, bound in type(obj)._bounds.items():
            kept = getattr(obj, name)
            high = bound.high
            if high is None:
                high = obj._capacity[name][0]
            elif isinstance(high, str):
                high = getattr(obj, high)
            for bad in (high + 1, bound.low - 1, 10**12, -10**12, 2**70):
                with pytest.raises(ValueError) as caught:
                    setattr(obj, name, bad)
                text = str(caught.value)
                assert f"{label}.{name}" in text and f"{bound.low}..{high}" in text, text
                assert bound.label in text, text
                assert getattr(obj, name) == kept                # nothing written
            with pytest.raises(TypeError, match=f"{label}.{name}"):
                setattr(obj, name, 1.5)
            if name != "pstack":                             # both ends are accepted
                for good in (bound.low, high):
                    setattr(obj, name, good)
                    assert getattr(obj, name) == good
            setattr(obj, name, kept)
            checked += 1
    assert checked >= 14


def test_item2_scene_counts_are_writable_as_official_within_their_allocation():
    m = mjcffi.MjModel.from_xml_string(FLEX)
    scene = mjcffi.MjvScene(m, maxgeom=10)
    assert (scene.nflex, scene.nskin, scene.maxgeom) == (m.nflex, m.nskin, 10) == (2, 1, 10)
    vertadr, edges = scene.flexvertadr.copy(), scene.flexedge.copy()
    scene.nflex, scene.nskin, scene.maxgeom = 0, 0, 4
    assert scene.flexvertadr.shape == scene.flexedge.shape == scene.skinvert.shape == (0,)
    assert len(scene.geoms) == 4 and scene.geomorder.shape == (4,)
    with pytest.raises(ValueError, match=r"ngeom must be within 0\.\.4 \(maxgeom\)"):
        scene.ngeom = 5
    scene.nflex, scene.nskin, scene.maxgeom = 2, 1, 10
    assert (scene.flexvertadr == vertadr).all() and (scene.flexedge == edges).all()
    with pytest.raises(ValueError, match=r"MjvScene\.nflex must be within 0\.\.2 "
                                         r"\(the nflex allocated by mjv_makeScene\)"):
        scene.nflex = 3
    with pytest.raises(ValueError, match=r"nskin must be within 0\.\.1"):
        scene.nskin = 2
    with pytest.raises(ValueError, match=r"maxgeom must be within 0\.\.10"):
        scene.maxgeom = 11
    empty = mjcffi.MjvScene()                      # no model: nothing allocated
    with pytest.raises(ValueError, match=r"within 0\.\.0"):
        empty.nflex = 1


def test_item2_a_huge_scene_count_is_refused_and_every_view_stays_readable():
    """The issue's crash: scn.nflex = 10**9, then scn.flexvertadr.sum()."""
    code = f"""
        import mjcffi
        m = mjcffi.MjModel.from_xml_string({FLEX!r})
        scn = mjcffi.MjvScene(m, 10)
        for name in ("nflex", "nskin", "maxgeom", "ngeom", "nlight"):
            try:
                setattr(scn, name, 10**9)
            except ValueError as exc:
                print("refused", name)
        print(scn.flexvertadr.sum(), scn.flexvert.sum(), scn.skinvert.size, len(scn.geoms))
        for name in scn._fields:
            getattr(scn, name)
        print("done")
    """
    code_, out = _run(code)
    assert code_ == 0, out
    assert out.count("refused") == 5 and out.strip().endswith("done"), out


def test_item2_a_remade_scene_is_bounded_by_its_new_allocation():
    """After MuJoCo reallocates a scene in place, the bounds follow the new sizes:
    `_remade()` records them, and a count that MuJoCo changed is taken as the new
    allocation even without that call."""
    flex = mjcffi.MjModel.from_xml_string(FLEX)
    plain = mjcffi.MjModel.from_xml_string(PENDULUM)
    scene = mjcffi.MjvScene(flex, 10)
    lib.mjv_makeScene(plain._ptr, scene._ptr, 3)
    scene._remade()
    assert {name: cap[0] for name, cap in scene._capacity.items()} == \
        {"maxgeom": 3, "nflex": 0, "nskin": 0}
    with pytest.raises(ValueError, match=r"within 0\.\.0"):
        scene.nflex = 2
    with pytest.raises(ValueError, match=r"within 0\.\.3"):
        scene.maxgeom = 10
    assert scene.flexvertadr.shape == (0,) and len(scene.geoms) == 3

    # no _remade(): the counts MuJoCo rewrote are the new allocation
    for make in (lambda: lib.mjv_makeScene(plain._ptr, scene._ptr, 2),
                 lambda: lib.mjv_freeScene(scene._ptr)):
        scene = mjcffi.MjvScene(flex, 10)
        scene.maxgeom = 9                            # written from Python: still bounded
        make()
        with pytest.raises(ValueError, match=r"maxgeom must be within 0\.\.[02] "):
            scene.maxgeom = 9
        with pytest.raises(ValueError, match=r"nflex must be within 0\.\.0 "):
            scene.nflex = 2
    scene = mjcffi.MjvScene(plain, 5)
    lib.mjv_makeScene(flex._ptr, scene._ptr, 20)      # grown: the new sizes are allowed
    assert scene.flexedge.shape == (2 * flex.nflexedge,)
    scene.maxgeom, scene.nflex, scene.nskin = 20, 2, 1
    assert scene.flexvertadr.shape == (2,) and len(scene.geoms) == 20


def test_item2_counts_written_into_scene_arrays_cannot_size_a_view_past_its_allocation():
    code = f"""
        import mjcffi
        m = mjcffi.MjModel.from_xml_string({FLEX!r})
        scn = mjcffi.MjvScene(m, 10)
        edges = scn.flexedge.copy()
        kept = scn.flexedgenum.copy()
        scn.flexedgenum[0] = 10**8
        for name in ("flexedge",):
            try:
                getattr(scn, name).sum()
            except ValueError as exc:
                print("refused", exc)
        try:
            scn.flexedge = 0
        except ValueError:
            print("refused assignment")
        scn.flexfacenum[:] = 10**6
        for name in ("flexface", "flexnormal", "flextexcoord"):
            try:
                getattr(scn, name)
            except ValueError:
                print("refused", name)
        scn.skinvertnum[0] = -10**6             # a negative size
        try:
            scn.skinvert
        except ValueError:
            print("refused skinvert")
        scn.flexedgenum[:] = kept
        scn.flexedgenum[0] -= 1                   # smaller than allocated: fine
        print("smaller", scn.flexedge.size == edges.size - 2)
        print("done")
    """
    returncode, out = _run(code)
    assert returncode == 0, out
    assert "refused MjvScene.flexedge would show 200000010 entries, not within the 0..42 " \
           "allocated" in out
    assert out.count("refused") == 6 and "smaller True" in out, out
    assert out.rstrip().endswith("done"), out


def test_item_struct_constructors_take_only_what_c_can_hold():
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    for make in (lambda: mjcffi.MjvScene(m, 2**40), lambda: mjcffi.MjrContext(m, -2**31 - 1)):
        with pytest.raises(ValueError, match=r"out of range for a C int") as caught:
            make()
        assert isinstance(caught.value, TypeError)            # the official type, too
    with pytest.raises(TypeError, match="not the class MjModel"):
        mjcffi.MjvScene(mjcffi.MjModel, 10)
    with pytest.raises(TypeError, match="maxgeom must be an int"):
        mjcffi.MjvScene(m, 1.5)
    with pytest.raises(mjcffi.FatalError, match="allocate"):
        mjcffi.MjvScene(m, 2**31 - 1)                        # too big for memory, no crash


# -------------------------------------------------------------- scalar setters

def _spec_elements():
    spec = mjcffi.mj_makeSpec()
    world = mjcffi.mjs_findBody(spec, "world")
    body = mjcffi.mjs_addBody(world, None)
    return [spec, spec.compiler, spec.compiler.LRopt, spec.option, spec.authored, body,
            body.alt, mjcffi.mjs_addJoint(body, None), mjcffi.mjs_addGeom(body, None),
            mjcffi.mjs_addSite(body, None), mjcffi.mjs_addCamera(body, None),
            mjcffi.mjs_addLight(body, None), mjcffi.mjs_addMesh(spec, None),
            mjcffi.mjs_addTexture(spec), mjcffi.mjs_addActuator(spec, None),
            mjcffi.mjs_addSensor(spec), mjcffi.mjs_addTendon(spec, None)]


def _instances():
    """One instance of as many struct classes as Python can reach."""
    m = mjcffi.MjModel.from_xml_string(FLEX)
    d = mjcffi.MjData(m)
    out = [m, m.opt, m.stat, m.vis, d, d.warning[0], d.timer[0], d.solver[0],
           mjcffi.MjvScene(m, 10), structs.MjUI().sect[0].item[0]]
    out += [getattr(m.vis, name) for name in m.vis._fields]
    for name in structs.MODULES:
        try:
            out.append(getattr(structs, name)())
        except TypeError:
            pass                       # made by MuJoCo, or takes arguments
    return out + _spec_elements()


def _too_big(ctype):
    """Values the C type cannot hold."""
    span = _views._range(ctype)
    if span is None:
        return [10**400, -10**400]
    return [span[1] + 1, span[0] - 1, 2**200]


def test_item_no_scalar_setter_lets_an_overflow_error_out():
    """Every writable scalar of every reachable struct: a value beyond its C type's
    range raises ValueError naming the field and the range (it is also the
    official TypeError), a non-number a TypeError naming the field, and the
    field keeps its value."""
    kinds, checked = set(), 0
    for obj in _instances():
        cls = type(obj)
        struct_type = ffi.typeof(obj._ptr).item
        for attr, field in _descriptors(cls):
            if not _writable(cls, attr):
                continue
            found = _views._field_at(struct_type, _views._cname_of(attr))
            ctype = found and found[0]
            if ctype is None or ctype.kind not in ("primitive", "enum"):
                continue                               # function pointers, char arrays
            kept = getattr(obj, attr)
            label = f"{cls.__name__}.{_views._cname_of(attr)}"
            with pytest.raises(TypeError, match=re.escape(label)):
                setattr(obj, attr, "seven")
            if ctype.kind == "primitive" and ctype.cname == "_Bool":
                setattr(obj, attr, 2**70)              # any int, as a truth value
                assert getattr(obj, attr) is True
                setattr(obj, attr, kept)
            else:
                for bad in _too_big(ctype):
                    with pytest.raises(ValueError, match=re.escape(label)) as caught:
                        setattr(obj, attr, bad)
                    assert not isinstance(caught.value, OverflowError)
                    span = _views._range(ctype)
                    if span is not None and attr not in cls._bounds:
                        assert f"{span[0]}..{span[1]}" in str(caught.value)
            after = getattr(obj, attr)
            assert after == kept or after != after and kept != kept, label   # NaN stays NaN
            kinds.add(ctype.kind if ctype.kind == "enum" else ctype.cname)
            checked += 1
    assert checked > 500
    assert {"int", "unsigned int", "int64_t", "uint64_t", "size_t", "unsigned char", "_Bool",
            "float", "double", "enum"} <= kinds, kinds


@pytest.mark.parametrize("obj, field, value, message", [
    ("d.warning[0]", "number", 2**40, "MjWarningStat.number: 1099511627776 is out of range "
                                     "for a C int (-2147483648..2147483647)"),
    ("m.opt", "timestep", 10**400, "MjOption.timestep: 1000000000000000...00000000 (401 "
                                   "characters) is out of range for a C double"),
    ("m.vis.quality", "shadowsize", -2**31 - 1, "out of range for a C int"),
    ("d", "maxuse_stack", 2**63, "MjData.maxuse_stack: 9223372036854775808 is out of range "
                                 "for a C int64_t"),
    ("geom", "type", -1, "MjsGeom.type: -1 is out of range for a C enum mjtGeom "
                         "(0..4294967295)"),
    ("body", "simple", 256, "MjsBody.simple: 256 is out of range for a C unsigned char (0..255)"),
    ("context", "offFBO", -1, "MjrContext.offFBO: -1 is out of range for a C unsigned int"),
], ids=["int", "double", "int-low", "int64", "enum", "byte", "unsigned"])
def test_item_scalar_setter_errors_name_the_field_and_the_c_range(obj, field, value, message):
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    spec = mjcffi.mj_makeSpec()
    body = mjcffi.mjs_addBody(mjcffi.mjs_findBody(spec, "world"), None)
    space = {"m": m, "d": mjcffi.MjData(m), "body": body, "geom": mjcffi.mjs_addGeom(body, None),
             "context": mjcffi.MjrContext()}
    target = eval(obj, {}, space)
    with pytest.raises(ValueError) as caught:
        setattr(target, field, value)
    assert isinstance(caught.value, TypeError)     # the official type, too
    assert message in str(caught.value)


def test_item_array_fields_refuse_values_their_dtype_cannot_hold():
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    with pytest.raises(ValueError, match="gravity"):
        m.opt.gravity = [10**400, 0, 0]
    with pytest.raises(ValueError, match="geom_type"):
        m.geom_type = 2**40
    with pytest.raises(ValueError, match="geomgroup"):
        mjcffi.MjvOption().geomgroup = [256] * 6
    assert (m.opt.gravity == [0, 0, -9.81]).all()


# ---------------------------------------------------------- MjData.pbase

def test_item_pbase_is_an_address_and_read_only():
    """pbase is the address of the last mj_markStack's record (0 when none), not an
    offset into the arena as pstack is: no value written from Python can be valid, and
    under the old bound 0..narena `d.pbase = 8; mj_freeStack(d)` segfaulted."""
    m = mjcffi.MjModel.from_xml_string(FLEX)
    d = mjcffi.MjData(m)
    assert d.pbase == 0 and d.pstack == 0
    mjcffi.lib.mj_markStack(d._ptr)
    arena = int(mjcffi.ffi.cast("uintptr_t", d._ptr.arena))
    assert arena <= d.pbase < arena + d.narena          # an address inside the arena
    assert 0 < d.pstack < d.narena                      # an offset
    mjcffi.lib.mj_freeStack(d._ptr)
    for value in (0, 8, d.narena):
        with pytest.raises(AttributeError):
            d.pbase = value
    assert d.pbase == 0 and "pbase" not in type(d)._bounds
    d.pstack = 8                                        # pstack stays writable, bounded
    assert d.pstack == 8
    d.pstack = 0
