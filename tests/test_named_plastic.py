"""Named access to the plastic state: `d.joint(j).plastic`, `d.tendon(t).plastic`.

mjData.plastic is shared by the joints and tendons with a springyield (and the
flexes with a yield); each element's span starts at its plasticadr (-1: none)
and runs to the next element's start.  The values are set to distinct numbers,
so that a span starting or ending one entry off reads a wrong value, and
compared with the official accessors.
"""

import numpy as np
import pytest

import mjcffi

# Elements with plastic state interleaved with ones without: a hinge (1 entry),
# a plain hinge, a ball joint (4), a slide (1), a spatial tendon (2), a plain
# tendon, a fixed tendon (2, the last span, which ends at nplastic).
JOINTS_AND_TENDONS = """
<mujoco>
  <worldbody>
    <site name="s0"/>
    <body name="b1">
      <joint name="h1" type="hinge" stiffness="1" springyield="0.5"/>
      <joint name="h2" type="hinge" axis="1 0 0"/>
      <geom size=".1" mass="1"/>
      <site name="s1" pos="0 0 1"/>
      <body name="b2" pos="0 0 1">
        <joint name="ball" type="ball" stiffness="1" springyield="0.3"/>
        <geom size=".1" mass="1"/>
        <site name="s2" pos="0 0 1"/>
      </body>
      <body name="b3" pos="1 0 0">
        <joint name="slide" type="slide" stiffness="1" springyield="0.2"/>
        <geom size=".1" mass="1"/>
      </body>
    </body>
  </worldbody>
  <tendon>
    <spatial name="t1" stiffness="1" springyield="0.1"><site site="s0"/><site site="s1"/></spatial>
    <spatial name="t2"><site site="s1"/><site site="s2"/></spatial>
    <fixed name="t3" stiffness="2" springyield="0.1"><joint joint="h2" coef="1"/></fixed>
  </tendon>
</mujoco>
"""

# A plastic flex after a joint and a tendon: its state follows theirs in mjData.plastic.
WITH_FLEX = """
<mujoco>
  <worldbody>
    <site name="s0"/>
    <body name="b1">
      <joint name="h1" type="hinge" stiffness="1" springyield="0.5"/>
      <geom size=".1"/>
      <site name="s1" pos="0 0 1"/>
    </body>
    <flexcomp name="f" type="grid" count="3 3 3" spacing=".1 .1 .1" dim="3" radius=".01">
      <elasticity young="1e4" yield="0.1"/>
    </flexcomp>
  </worldbody>
  <tendon>
    <spatial name="t1" stiffness="1" springyield="0.1"><site site="s0"/><site site="s1"/></spatial>
  </tendon>
</mujoco>
"""


def _pair(mujoco, xml):
    om, m = mujoco.MjModel.from_xml_string(xml), mjcffi.MjModel.from_xml_string(xml)
    od, d = mujoco.MjData(om), mjcffi.MjData(m)
    assert m.nplastic > 0
    od.plastic[:] = d.plastic[:] = np.arange(1, m.nplastic + 1)
    return (om, m), (od, d)


def _spans(m):
    return [("jnt", j) for j in range(m.njnt)] + [("tendon", t) for t in range(m.ntendon)]


def test_item_mutants_the_test_model_interleaves_plastic_and_elastic_elements(mujoco):
    (om, m), _ = _pair(mujoco, JOINTS_AND_TENDONS)
    assert list(m.jnt_plasticadr) == [0, -1, 1, 5]
    assert list(m.tendon_plasticadr) == [6, -1, 8]
    assert m.nplastic == 10


def test_item_mutants_named_plastic_spans_equal_the_official(mujoco):
    _, (od, d) = _pair(mujoco, JOINTS_AND_TENDONS)
    seen = []
    for category, i in _spans(d.model):
        expected, got = getattr(od, category)(i).plastic, getattr(d, category)(i).plastic
        assert got.dtype == expected.dtype and got.shape == expected.shape, (category, i)
        np.testing.assert_array_equal(got, expected, err_msg=f"{category} {i}")
        seen += list(got)
    # the spans tile mjData.plastic exactly, in order
    assert seen == list(range(1, d.model.nplastic + 1))
    assert d.joint("ball").plastic.shape == (4,)
    assert d.joint("h2").plastic.shape == (0,) and d.tendon("t2").plastic.shape == (0,)


def test_item_mutants_named_plastic_is_a_view_that_writes_through(mujoco):
    _, (od, d) = _pair(mujoco, JOINTS_AND_TENDONS)
    d.joint("ball").plastic = [-1, -2, -3, -4]
    d.tendon("t3").plastic[1] = 99
    np.testing.assert_array_equal(d.plastic, [1, -1, -2, -3, -4, 6, 7, 8, 9, 99])


def test_item_mutants_named_plastic_after_stepping_equals_the_official(mujoco):
    (om, m), (od, d) = _pair(mujoco, JOINTS_AND_TENDONS)
    od.qpos[:] = d.qpos[:] = np.linspace(0.1, 0.9, m.nq)
    mujoco.mj_step(om, od, 20)
    mjcffi.mj_step(m, d, 20)
    np.testing.assert_array_equal(d.plastic, od.plastic)
    for category, i in _spans(m):
        np.testing.assert_array_equal(getattr(d, category)(i).plastic,
                                      getattr(od, category)(i).plastic)


def test_item_mutants_a_tendon_span_stops_where_a_flex_span_starts(mujoco):
    (om, m), (od, d) = _pair(mujoco, WITH_FLEX)
    assert m.flex_plasticadr[0] > m.tendon_plasticadr[0] >= 0
    for category, i in _spans(m):
        np.testing.assert_array_equal(getattr(d, category)(i).plastic,
                                      getattr(od, category)(i).plastic)
