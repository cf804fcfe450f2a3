"""Named access: every category, ragged fields, writes, errors, lifetimes.

The official bindings are the oracle: for every element of every category of
every gymnasium model (and of an embedded scene with one of each category),
each attribute they offer is offered here with an equal value.
"""

import gc
import pathlib

import numpy as np
import pytest

import mjcffi
from mjcffi._generated import namedinfo as _namedinfo, structinfo as _structinfo

from .conftest import gymnasium_assets

SCENE = pathlib.Path(__file__).parent / "scenes" / "every_category.xml"
MODELS = [SCENE] + gymnasium_assets()


def _public(obj):
    return {name for name in dir(obj) if not name.startswith("_")}


def _pairs(mujoco, path, steps=5):
    om, m = mujoco.MjModel.from_xml_path(str(path)), mjcffi.MjModel.from_xml_path(path)
    od, d = mujoco.MjData(om), mjcffi.MjData(m)
    mujoco.mj_step(om, od, steps)
    mjcffi.mj_step(m, d, steps)
    return (om, m), (od, d)


@pytest.mark.parametrize("path", MODELS, ids=lambda p: p.stem)
def test_every_official_attribute_is_here_with_an_equal_value(mujoco, path):
    (om, m), (od, d) = _pairs(mujoco, path)
    compared = 0
    for category in _namedinfo.CATEGORIES:
        for theirs, ours in ((om, m), (od, d)):
            method = getattr(theirs, category, None)
            if not callable(method):
                continue
            for element in range(getattr(om, "n" + category)):
                official, mine = method(element), getattr(ours, category)(element)
                assert _public(official) <= _public(mine), (category, element)
                assert (mine.id, mine.name) == (official.id, official.name)
                for attr in _public(official) - {"id", "name"}:
                    expected, got = np.asarray(getattr(official, attr)), getattr(mine, attr)
                    assert got.shape == expected.shape, (category, element, attr)
                    assert np.array_equal(got, expected, equal_nan=True), (category, attr)
                    compared += 1
    assert compared > 50


def test_the_extra_attributes_are_fields_of_their_category(mujoco):
    # Fields MuJoCo added after the official accessors' lists were written (geom
    # fluid, tendon range, ...) are offered as well; each is a real field here.
    (om, m), (od, d) = _pairs(mujoco, SCENE)
    for category, spec in _namedinfo.CATEGORIES.items():
        for theirs, ours, fields in ((om, m, spec.model), (od, d, spec.data)):
            method = getattr(theirs, category, None)
            if not callable(method) or not getattr(om, "n" + category):
                continue
            extra = _public(getattr(ours, category)(0)) - _public(method(0))
            assert extra <= {f.attr for f in fields}, category


def test_categories_come_from_the_name_address_fields():
    model_fields = {f.name for f in _structinfo.STRUCTS["mjModel"]}
    expected = {name[len("name_"):-len("adr")] for name in model_fields
                if name.startswith("name_") and name.endswith("adr")}
    assert set(_namedinfo.CATEGORIES) == expected
    m = mjcffi.MjModel.from_xml_path(SCENE)
    for category in expected - {"plugin"}:         # m.plugin is an array field
        assert callable(getattr(m, category)), category
    for category, alias in _namedinfo.ALIASES.items():
        assert getattr(mjcffi.MjModel, alias) is getattr(mjcffi.MjModel, category)


def test_ragged_fields_follow_each_element():
    m = mjcffi.MjModel.from_xml_path(SCENE)
    d = mjcffi.MjData(m)
    widths = {"free": (7, 6), "ball": (4, 3), "hinge": (1, 1), "slide": (1, 1)}
    for name, (nq, nv) in widths.items():
        assert d.joint(name).qpos.shape == (nq,) and d.joint(name).qvel.shape == (nv,)
        assert m.joint(name).qpos0.shape == (nq,) and d.jnt(name).cdof.shape == (nv, 6)
    for sensor in range(m.nsensor):
        assert d.sensor(sensor).data.shape == (m.sensor_dim[sensor],)
    assert m.numeric("num").data.tolist() == [1, 2, 3]
    assert bytes(m.text("txt").data.astype(np.uint8)) == b"hello\0"   # text_size counts the NUL
    assert m.tuple("tup").objtype.tolist() == [mjcffi.mjtObj.mjOBJ_BODY]
    assert m.hfield("hf").data.shape == (3, 3)


def test_writes_go_both_ways():
    m = mjcffi.MjModel.from_xml_path(SCENE)
    d = mjcffi.MjData(m)
    d.joint("ball").qpos = [0, 1, 0, 0]                 # assignment writes through
    adr = m.jnt_qposadr[m.joint("ball").id]
    assert d.qpos[adr:adr + 4].tolist() == [0, 1, 0, 0]
    d.qpos[adr] = 0.5                                    # and the flat array shows through
    assert d.joint("ball").qpos[0] == 0.5
    m.geom("box").rgba[:] = [1, 0, 0, 1]
    assert m.geom_rgba[m.geom("box").id].tolist() == [1, 0, 0, 1]
    d.actuator("motor").ctrl = 0.25
    mjcffi.mj_step(m, d)
    assert d.ctrl[0] == 0.25 and d.actuator("motor").force[0] == 0.25
    with pytest.raises(ValueError, match="could not broadcast") as info:
        d.joint("ball").qpos = [1, 2]
    assert info.value.__notes__ == ["jnt (joint) 'qpos' has shape (4,)"]
    with pytest.raises(AttributeError, match="object has no attribute 'bogus'"):
        d.joint("ball").bogus = 1


def test_accessors_are_cached():
    m = mjcffi.MjModel.from_xml_path(SCENE)
    d = mjcffi.MjData(m)
    assert d.joint("hinge") is d.joint("hinge") is d.jnt(m.joint("hinge").id)
    assert d.joint("hinge").qpos is d.joint("hinge").qpos


def test_errors_name_the_problem():
    # The official message is str(exc); the hints are PEP 678 notes.
    m = mjcffi.MjModel.from_xml_path(SCENE)
    with pytest.raises(KeyError, match="Invalid name 'boxx'") as info:
        m.geom("boxx")
    assert "no geom named 'boxx'; did you mean 'box'?" in info.value.__notes__
    with pytest.raises(KeyError) as info:
        m.joint("elbow")
    assert info.value.__notes__[0].startswith("no jnt (joint) named 'elbow'")
    with pytest.raises(IndexError, match="Invalid index 99") as info:
        m.geom(99)
    assert info.value.__notes__ == ["geom id 99 is out of range: the model has 5"]
    with pytest.raises(IndexError, match="Invalid index -1. Valid indices from 0 to 4"):
        m.geom(-1)
    for bad in (1.5, 1.0, True, [1], None):
        with pytest.raises(TypeError, match="name .str. or an id .int."):
            m.geom(bad)
    with pytest.raises(AttributeError, match="object has no attribute 'rbga'") as info:
        m.geom("box").rbga
    assert "rgba" in info.value.__notes__[0]
    assert m.geom(np.int64(2)).name == "box"


def test_accessors_keep_their_memory_alive():
    m = mjcffi.MjModel.from_xml_path(SCENE)
    d = mjcffi.MjData(m)
    joint, geom = d.joint("free"), m.geom("box")
    del m, d
    gc.collect()
    joint.qpos[:] = 3.0                      # built after the owners were dropped
    assert joint.qpos.tolist() == [3.0] * 7
    assert geom.size.tolist() == pytest.approx([0.1, 0.1, 0.1])
