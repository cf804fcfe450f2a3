"""Named access as the official bindings present it: class names, dir(), reprs,
private attributes, error types and messages, and multi-input actuators.

tests/test_named.py checks that every official attribute is here with an
equal value; this file checks the rest of what a user of the official
bindings sees, with the official bindings as the oracle.
"""

import gc
import pathlib
import weakref

import numpy as np
import pytest

import mjcffi
from mjcffi._generated import namedinfo as _namedinfo
from mjcffi._support import named

from .conftest import gymnasium_assets
from .test_named_plastic import JOINTS_AND_TENDONS

SCENE = pathlib.Path(__file__).parent / "scenes" / "every_category.xml"

# An arm whose actuators take several controls and give several force outputs
# (MuJoCo 4.0): a quaternion servo (4 controls, 3 outputs), an exponential-map
# one (3, 3), and single-input ones between them.
MIMO = """
<mujoco>
  <worldbody>
    <body name="arm">
      <joint name="shoulder" type="ball"/>
      <geom size=".1" pos=".3 0 0"/>
      <body pos=".6 0 0">
        <joint name="elbow" type="hinge"/>
        <geom size=".05" pos=".2 0 0"/>
        <body pos=".4 0 0">
          <joint name="wrist" type="ball"/>
          <geom size=".05"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <orientation name="shoulder_q" joint="shoulder" kp="2" input="quat"/>
    <motor name="elbow_m" joint="elbow" gear="5" ctrlrange="-1 1"/>
    <orientation name="wrist_e" joint="wrist" kp="3"/>
    <general name="elbow_g" joint="elbow" dyntype="integrator" gainprm="2"/>
  </actuator>
</mujoco>
"""

# DC motors without controls (input="none") and with three (setpoints and feedforward).
DC_MOTORS = """
<mujoco>
  <worldbody><body><joint name="axle"/><geom size=".1"/></body></worldbody>
  <actuator>
    <dcmotor name="passive" joint="axle" resistance="2" motorconst="0.05" input="none"/>
    <motor name="plain" joint="axle"/>
    <dcmotor name="servo" joint="axle" resistance="1" motorconst="0.1" input="pos vel ff"/>
  </actuator>
</mujoco>
"""

# One skin (every_category.xml has none), and tendons and joints with plastic state.
SKIN_AND_PLASTIC = """
<mujoco>
  <worldbody>
    <body name="base">
      <joint name="slider" type="slide" stiffness="4" springref="0.1" springyield="0.3"/>
      <geom size=".1"/>
    </body>
  </worldbody>
  <tendon>
    <fixed name="cable" stiffness="3" springlength="0.2 0.4" springyield="0.1">
      <joint joint="slider" coef="2"/>
    </fixed>
  </tendon>
  <deformable>
    <skin name="membrane" vertex="0 0 0  1 0 0  0 1 0" face="0 1 2">
      <bone body="base" bindpos="0 0 0" bindquat="1 0 0 0" vertid="0 1 2" vertweight="1 1 1"/>
    </skin>
  </deformable>
</mujoco>
"""

MODELS = [("every_category", SCENE), ("mimo", MIMO), ("dc_motors", DC_MOTORS),
          ("skin_and_plastic", SKIN_AND_PLASTIC), ("plastic_spans", JOINTS_AND_TENDONS)]
MODELS += [(path.stem, path) for path in gymnasium_assets()]


# Official attributes with a stale width: the official `_lengthspring` of a tendon
# has 1 value where tendon_lengthspring has 2 per tendon, so tendon i > 0 reads
# its neighbour's value.  Ours is the tendon's own row (test below).
OFFICIAL_BUGS = {("_MjModelTendonViews", "_lengthspring")}


def _load(module, source):
    if isinstance(source, pathlib.Path):
        return module.MjModel.from_xml_path(str(source))
    return module.MjModel.from_xml_string(source)


def _pairs(mujoco, source, steps=3):
    """(official, ours) models and datas, stepped alike with nonzero controls."""
    om, m = _load(mujoco, source), _load(mjcffi, source)
    od, d = mujoco.MjData(om), mjcffi.MjData(m)
    od.ctrl[:] = d.ctrl[:] = np.linspace(-0.5, 0.5, m.nu)
    mujoco.mj_step(om, od, steps)
    mjcffi.mj_step(m, d, steps)
    return (om, m), (od, d)


def _accessors(mujoco, source):
    """Every (official, ours) accessor pair of every element the official offers."""
    (om, m), (od, d) = _pairs(mujoco, source)
    for category in _namedinfo.CATEGORIES:
        for theirs, ours in ((om, m), (od, d)):
            method = getattr(theirs, category, None)
            if callable(method):
                for element in range(getattr(om, "n" + category)):
                    yield method(element), getattr(ours, category)(element)


def _attributes(obj):
    """dir() without the dunders and pybind11's own."""
    return {name for name in dir(obj)
            if not name.startswith("__") and name != "_pybind11_conduit_v1_"}


def _repr_blocks(text):
    """A multi-line accessor repr: (first line, last line, {attribute: its text})."""
    lines = text.split("\n")
    blocks, attr = {}, None
    for line in lines[1:-1]:
        if line.startswith("  ") and not line.startswith("   "):
            attr, _, value = line[2:].partition(": ")
            blocks[attr] = value
        else:                                       # a continuation of a multi-line array
            blocks[attr] += "\n" + line
    return lines[0], lines[-1], blocks


@pytest.mark.parametrize("source", [s for _, s in MODELS], ids=[n for n, _ in MODELS])
def test_accessors_look_like_the_official_ones(mujoco, source):
    compared = 0
    for official, mine in _accessors(mujoco, source):
        assert type(mine).__name__ == type(official).__name__
        assert _attributes(official) <= _attributes(mine), type(official).__name__
        for attr in _attributes(official) - {"id", "name"}:   # the private ones too
            if (type(mine).__name__, attr) in OFFICIAL_BUGS:
                continue
            expected, got = getattr(official, attr), getattr(mine, attr)
            assert got.dtype == expected.dtype, (type(mine).__name__, attr)
            assert got.shape == expected.shape, (type(mine).__name__, attr)
            assert np.array_equal(got, expected, equal_nan=True), (type(mine).__name__, attr)
            assert got.flags.writeable == expected.flags.writeable, attr
        first, last, theirs = _repr_blocks(repr(official))
        my_first, my_last, ours = _repr_blocks(repr(mine))
        assert (my_first, my_last) == (first, last)
        assert {a: ours.get(a) for a in theirs} == theirs
        assert list(ours) == sorted(ours)
        compared += 1
    assert compared


def test_the_extra_repr_lines_are_the_public_fields():
    m = mjcffi.MjModel.from_xml_path(SCENE)
    geom = m.geom("box")
    _, _, blocks = _repr_blocks(repr(geom))
    assert set(blocks) == {a for a in dir(geom) if a[0] != "_"} - {"id", "name"} | {"id", "name"}
    assert blocks["id"] == repr(geom.id) and blocks["name"] == "'box'"
    assert blocks["fluid"] == repr(geom.fluid)      # a field the official accessor lacks


def test_private_attributes_are_views_of_the_same_memory():
    m = mjcffi.MjModel.from_xml_path(SCENE)
    tendon = m.tendon(0)
    assert tendon._limited.dtype == bool
    tendon._limited[:] = True
    assert m.tendon_limited[0] and tendon.limited[0]
    tendon._range = [-2, 3]
    assert m.tendon_range[0].tolist() == [-2, 3]
    assert "_limited" in dir(tendon) and "_limited" not in repr(tendon)


def test_a_tendon_lengthspring_is_its_own_row(mujoco):
    xml = """
    <mujoco>
      <worldbody><body><joint name="j"/><geom size=".1"/></body></worldbody>
      <tendon>
        <fixed name="short" springlength="0.1 0.2"><joint joint="j" coef="1"/></fixed>
        <fixed name="long" springlength="0.5 0.7"><joint joint="j" coef="2"/></fixed>
      </tendon>
    </mujoco>"""
    m = mjcffi.MjModel.from_xml_string(xml)
    assert m.tendon("long")._lengthspring.tolist() == [0.5, 0.7] == m.tendon_lengthspring[1].tolist()
    official = mujoco.MjModel.from_xml_string(xml).tendon("long")._lengthspring
    assert official.tolist() == [0.2]       # the official reads the short tendon's second value


def test_the_classes_are_made_once_and_list_their_fields():
    m = mjcffi.MjModel.from_xml_path(SCENE)
    d = mjcffi.MjData(m)
    cls = type(d.joint("hinge"))
    assert cls is named.accessor_class("data", "jnt") is type(d.jnt("ball"))
    assert cls.__name__ == "_MjDataJointViews" and issubclass(cls, named.Accessor)
    assert {"qpos", "qvel", "cdof"} <= set(dir(cls))        # as class-level introspection
    assert type(m.tendon(0)).__name__ == "_MjModelTendonViews"
    assert type(m.key(0)).__name__ == "_MjModelKeyframeViews"


def test_mimo_actuators_span_their_controls_and_outputs():
    m = mjcffi.MjModel.from_xml_string(MIMO)
    d = mjcffi.MjData(m)
    assert m.actuator_ctrlnum.tolist() == [4, 1, 3, 1] and m.actuator_outnum.tolist() == [3, 1, 3, 1]
    d.ctrl[:] = np.arange(m.nu)
    mjcffi.mj_forward(m, d)
    for i in range(m.nactuator):
        controls = slice(m.actuator_ctrladr[i], m.actuator_ctrladr[i] + m.actuator_ctrlnum[i])
        outputs = slice(m.actuator_outadr[i], m.actuator_outadr[i] + m.actuator_outnum[i])
        assert d.actuator(i).ctrl.tolist() == d.ctrl[controls].tolist()
        for attr in ("force", "length", "velocity"):
            assert getattr(d.actuator(i), attr).tolist() == \
                getattr(d, "actuator_" + attr)[outputs].tolist()
        assert np.shares_memory(d.actuator(i).ctrl, d.ctrl)
    assert m.actuator("shoulder_q").ctrlrange.shape == (4, 2)
    assert m.actuator("shoulder_q").gear.shape == (3, 6)
    assert m.actuator("wrist_e").ctrllimited.shape == (3,)
    assert m.actuator("elbow_m").gear.shape == (6,)               # one output: one row
    assert m.actuator("elbow_m").ctrlrange.tolist() == [-1, 1]
    d.actuator("wrist_e").ctrl = [7, 8, 9]
    assert d.ctrl[m.actuator_ctrladr[2]:][:3].tolist() == [7, 8, 9]


def test_an_actuator_without_controls_has_empty_ones():
    m = mjcffi.MjModel.from_xml_string(DC_MOTORS)
    d = mjcffi.MjData(m)
    assert m.actuator_ctrlnum.tolist() == [0, 1, 3]
    assert d.actuator("passive").ctrl.shape == (0,)
    assert m.actuator("passive").ctrlrange.shape == (0, 2)
    assert d.actuator("servo").ctrl.shape == (3,) and d.actuator("plain").ctrl.shape == (1,)


def test_the_moment_is_a_read_only_dense_copy_per_output():
    m = mjcffi.MjModel.from_xml_string(MIMO)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    dense = np.zeros((m.nout, m.nv))
    mjcffi.mju_sparse2dense(dense, d.actuator_moment, d.moment_rownnz, d.moment_rowadr,
                            d.moment_colind)
    shoulder, elbow = d.actuator("shoulder_q").moment, d.actuator("elbow_m").moment
    assert shoulder.shape == (3, m.nv) and elbow.shape == (m.nv,)
    assert shoulder.tolist() == dense[0:3].tolist() and elbow.tolist() == dense[3].tolist()
    assert not shoulder.flags.writeable
    with pytest.raises(AttributeError, match="object has no setter"):
        d.actuator("elbow_m").moment = 0


def _error(call):
    try:
        call()
    except Exception as exc:        # noqa: BLE001: the oracle's exception, whatever it is
        return type(exc), str(exc)
    return None


@pytest.mark.parametrize("call", [
    lambda m: m.geom("nope"), lambda m: m.geom(), lambda m: m.joint(""),
    lambda m: m.geom(99), lambda m: m.geom(-1), lambda m: m.skin(0), lambda m: m.skin("x"),
    lambda m: m.actuator(np.int32(7)), lambda m: m.body(b"nope"),
], ids=["unknown", "no-argument", "empty", "too-large", "negative", "none-at-all",
        "no-names", "numpy-int", "bytes"])
def test_lookup_errors_are_the_official_ones(mujoco, call):
    om, m = mujoco.MjModel.from_xml_path(str(SCENE)), mjcffi.MjModel.from_xml_path(SCENE)
    od, d = mujoco.MjData(om), mjcffi.MjData(m)
    expected = _error(lambda: call(om))
    assert expected is not None and _error(lambda: call(m)) == expected
    if callable(getattr(od, call.__code__.co_names[0], None)):
        assert _error(lambda: call(d)) == _error(lambda: call(od))


def test_the_hints_are_notes():
    m = mjcffi.MjModel.from_xml_path(SCENE)
    d = mjcffi.MjData(m)
    with pytest.raises(KeyError) as info:
        d.body("lowr")
    assert str(info.value) == repr("Invalid name 'lowr'. Valid names: ['arm', 'free', 'lower', 'world']")
    assert info.value.__notes__ == ["no body named 'lowr'; did you mean 'lower'?"]
    with pytest.raises(IndexError) as info:
        m.tendon(5)
    assert info.value.__notes__ == ["tendon (ten) id 5 is out of range: the model has 1"]


def test_bytes_and_keyword_names_find_the_element():
    m = mjcffi.MjModel.from_xml_path(SCENE)
    assert m.geom(b"box") is m.geom("box") is m.geom(name="box")


def test_writes_and_deletes_fail_as_the_official_ones(mujoco):
    om, m = mujoco.MjModel.from_xml_path(str(SCENE)), mjcffi.MjModel.from_xml_path(SCENE)
    for action in (lambda g: setattr(g, "id", 3), lambda g: setattr(g, "name", "x"),
                   lambda g: setattr(g, "nonsense", 1), lambda g: delattr(g, "size"),
                   lambda g: g.nonsense, lambda g: setattr(g, "size", [1, 2])):
        official = _error(lambda: action(om.geom("box")))
        assert official is not None
        kind, message = _error(lambda: action(m.geom("box")))
        assert kind is official[0]
        assert message == official[1].replace("mujoco._structs.", "")
    assert m.geom("box").id == 2 and m.geom("box").size.shape == (3,)


def test_accessors_make_no_reference_cycle():
    m = mjcffi.MjModel.from_xml_path(SCENE)
    d = mjcffi.MjData(m)
    d.joint("free").qpos, m.tendon(0)._limited, repr(d.actuator(0))
    refs = weakref.ref(m), weakref.ref(d)
    gc.disable()
    try:
        del m, d
        assert refs[0]() is None and refs[1]() is None      # freed by reference counts alone
    finally:
        gc.enable()
