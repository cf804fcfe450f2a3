"""Batch's lower layer `b._b` (mjcffi/batch/_batch.py) against the official `_b`, and the
official messages of mjcffi.batch with mjcffi's detail in PEP 678 notes.

The lower layer takes ids and arrays in their final dtypes and shapes and
converts nothing: whatever it is given is the memory MuJoCo reads or writes.
"""

import numpy as np
import pytest

import mjcffi
from mjcffi.batch import _batch
from mjcffi import batch

from .test_batch import CARTPOLE

NSIM = 6
NUM = np.float64
CTRL = int(mjcffi.mjtState.mjSTATE_CTRL)

MIMO = """
<mujoco>
  <worldbody>
    <body>
      <joint name="slide" type="slide"/>
      <geom size=".1"/>
      <body>
        <joint name="ball" type="ball"/>
        <geom size=".1" pos=".2 0 0"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="before" joint="slide" gear="2"/>
    <orientation name="orient" joint="ball" kp="1" input="quat"/>
    <motor name="after" joint="slide" gear="3"/>
  </actuator>
</mujoco>
"""


@pytest.fixture
def pair(mujoco):
    """The same batch in both bindings, with the same state and controls."""
    from mujoco import batch as official_batch
    ours = batch.Batch(mjcffi.MjModel.from_xml_string(CARTPOLE), NSIM, 2)
    theirs = official_batch.Batch(mujoco.MjModel.from_xml_string(CARTPOLE), NSIM, 2)
    rng = np.random.default_rng(0)
    qpos, ctrl = rng.uniform(-.3, .3, (NSIM, 2)), rng.uniform(-1, 1, (NSIM, 2))
    for b in (ours, theirs):
        b.qpos, b.ctrl = qpos, ctrl
    return ours, theirs


def test_the_lower_layer_is_a_private_batch_object():
    b = batch.Batch(mjcffi.MjModel.from_xml_string(CARTPOLE), NSIM, 2)
    assert isinstance(b._b, _batch.Batch)
    assert (b._b.nsim, b._b.nthread, b._b.nstate, b._b.persistent) == \
        (b.nsim, b.nthread, b.nstate, b.persistent)
    assert b._b.state_component(mjcffi.mjtState.mjSTATE_QPOS) == (1, 2)   # after time
    assert b._b.output("qpos") is None                  # a state field, in the rows
    xpos = b._b.output("xpos")
    assert xpos.dtype == np.uint8 and xpos.shape == (NSIM, b.model.nbody * 3 * 8)
    assert not b._b.status().flags.writeable
    b.close()
    with pytest.raises(ValueError, match="closed"):
        b._b


def test_rollout_and_jac_match_the_officials_lower_layer(pair):
    ours, theirs = pair
    m = ours.model
    results = []
    for b in (ours, theirs):
        ids = np.array([1, 3, 4], np.int32)
        control = np.linspace(-1, 1, 3 * 4 * m.nu).reshape(3, 4, m.nu)
        qpos, state = np.empty((3, 4, m.nq), NUM), np.empty((3, 4, b.nstate), NUM)
        spec = int(mjcffi.mjtState.mjSTATE_INTEGRATION)
        assert b._b.rollout(ids, 4, control, CTRL, [("qpos", 0, qpos), (None, spec, state)]) == 0
        jacp = np.zeros((NSIM, 3, m.nv), NUM)
        body = np.full(NSIM, m.body("pole").id, np.int32)
        assert b._b.jac(None, body, np.ones((NSIM, 3), NUM), jacp, None) == 0
        results.append((qpos, state, jacp, b.state.copy()))
    for mine, official in zip(*results):
        np.testing.assert_array_equal(mine, official)


def test_ray_matches_the_officials_lower_layer(pair):
    ours, theirs = pair
    results = []
    for b in (ours, theirs):
        pnt = np.tile([[0., 0, 1], [.1, 0, 1]], (NSIM, 1, 1))
        vec = np.tile([0., 0, -1], (NSIM, 2, 1))
        dist, geomid = np.zeros((NSIM, 2), NUM), np.zeros((NSIM, 2), np.int32)
        normal = np.zeros((NSIM, 2, 3), NUM)
        exclude = np.full((NSIM, 2), -1, np.int32)
        assert b._b.ray(None, pnt, vec, None, True, exclude, dist, geomid, normal) == 0
        results.append((dist, geomid, normal))
    for mine, official in zip(*results):
        np.testing.assert_array_equal(mine, official)
    assert (results[0][1] >= 0).all()


def test_jac_outputs_may_be_none(pair):
    b = pair[0]
    m = b.model
    body = np.full(NSIM, m.body("pole").id, np.int32)
    point = np.ones((NSIM, 3), NUM)
    jacp, jacr = np.zeros((NSIM, 3, m.nv), NUM), np.zeros((NSIM, 3, m.nv), NUM)
    b._b.jac(None, body, point, jacp, jacr)
    alone = np.zeros_like(jacr)
    assert b._b.jac(None, body, point, None, alone) == 0
    np.testing.assert_array_equal(alone, jacr)
    assert b._b.jac(None, body, point, None, None) == 0
    assert jacp.any() and jacr.any()


def test_an_empty_selection_runs_nothing():
    # a NULL id list with count 0 means "every simulation" to MuJoCo: never pass one
    b = batch.Batch(mjcffi.MjModel.from_xml_string(CARTPOLE), NSIM)
    none = np.zeros(0, np.int32)
    m = b.model
    assert b._b.step(none) == 0
    assert b._b.forward(none) == 0
    assert b._b.reset(none, None) == 0
    assert b._b.set_const(none) == 0
    assert b._b.rollout(none, 2, None, CTRL, [("qpos", 0, np.empty((0, 2, m.nq)))]) == 0
    assert b._b.jac(none, np.zeros(0, np.int32), np.zeros((0, 3)), None, None) == 0
    np.testing.assert_array_equal(b.time, 0)
    b._b.step()
    assert (b.time > 0).all()


def test_nothing_is_converted():
    b = batch.Batch(mjcffi.MjModel.from_xml_string(CARTPOLE), NSIM)
    m = b.model
    body = np.full(NSIM, 1, np.int32)
    point = np.zeros((NSIM, 3), NUM)
    jac = np.zeros((NSIM, 3, m.nv), NUM)
    read_only = jac.copy()
    read_only.flags.writeable = False
    bad_jac = (
        ([0, 1], body[:2], point[:2], jac[:2], None),                     # a list of ids
        (np.arange(NSIM), body, point, jac, None),                          # int64 ids
        (np.arange(2 * NSIM, dtype=np.int32)[::2], body, point, jac, None),  # strided ids
        (None, body.astype(np.int64), point, jac, None),
        (None, body, point.tolist(), jac, None),
        (None, body, point.astype(np.float32), jac, None),
        (None, body, point, jac.astype(np.float32), None),
        (None, body, point, np.zeros((NSIM, m.nv, 3)).transpose(0, 2, 1), None),
        (None, body, point, None, read_only),
    )
    for args in bad_jac:
        with pytest.raises(TypeError, match="converts nothing"):
            b._b.jac(*args)
    for ids in ([0, 1], np.array([0, 1])):
        with pytest.raises(TypeError, match="ids must be a C-contiguous int32 array"):
            b._b.step(ids)
    with pytest.raises(TypeError, match="control"):
        b._b.rollout(None, 2, np.zeros((NSIM, 2, m.nu), np.float32), CTRL, [])
    with pytest.raises(TypeError, match="geomid"):
        b._b.ray(None, np.zeros((NSIM, 1, 3)), np.ones((NSIM, 1, 3)), None, True,
                 np.full((NSIM, 1), -1, np.int32), np.zeros((NSIM, 1)),
                 np.zeros((NSIM, 1), np.int64), None)
    with pytest.raises(TypeError, match="a record must be a"):
        b._b.rollout(None, 2, None, CTRL, [["qpos", 0, np.empty((NSIM, 2, m.nq))]])


def test_shapes_ranges_and_record_buffers_are_checked():
    b = batch.Batch(mjcffi.MjModel.from_xml_string(CARTPOLE), NSIM)
    m = b.model
    pole = np.array([m.body("pole").id], np.int32)
    one = (np.zeros((1, 3)), np.zeros((1, 3, m.nv)), None)
    for bad in (-1, NSIM):
        with pytest.raises(ValueError, match=rf"simulation ids must be in \[0, {NSIM}\), "
                                             rf"got {bad}"):
            b._b.jac(np.array([bad], np.int32), pole, *one)
    with pytest.raises(ValueError, match=rf"body must be in \[0, {m.nbody}\), got 99"):
        b._b.jac(None, np.full(NSIM, 99, np.int32), np.zeros((NSIM, 3)), None, None)
    with pytest.raises(ValueError, match=r"point must have shape \(6, 3\), got \(6, 2\)"):
        b._b.jac(None, np.zeros(NSIM, np.int32), np.zeros((NSIM, 2)), None, None)
    good = np.empty((NSIM, 3, m.nq))
    cases = (
        (("qpos", 0, np.empty((NSIM, 1, m.nq))), r"'qpos' must hold 6 x 3 x 2 float64"),
        (("qpos", 0, good.astype(np.float32)), "float32"),
        (("qpos", 0, good.astype(">f8")), ">f8"),
        (("solver_niter", 0, np.empty((NSIM, 3, mjcffi.mjNISLAND), np.float32)), "int32"),
        ((None, int(mjcffi.mjtState.mjSTATE_QVEL), np.empty((NSIM, 3, m.nv + 1))),
         "state spec 4"),
        ((None, -1, good), "invalid state spec -1"),
        (("nope", 0, good), "unknown field nope"),
        (("efc_force", 0, good), "unknown field efc_force"),
        (("qpos", 0, good.tolist()), "must be arrays"),
        (("qpos", 0, np.empty((NSIM, 3, 2 * m.nq))[:, :, ::2]), "C-contiguous"),
        (("qpos", good), r"a record is \(field, spec, buffer\)"),
    )
    for record, message in cases:
        with pytest.raises(ValueError, match=message):
            b._b.rollout(None, 3, None, CTRL, [record])
    with pytest.raises(ValueError, match=r"control must have shape \(6, 3, 2\), got \(6, 2, 2\)"):
        b._b.rollout(None, 3, np.zeros((NSIM, 2, m.nu)), CTRL, [])
    with pytest.raises(ValueError, match="nstep must be positive"):
        b._b.rollout(None, 0, None, CTRL, [])
    with pytest.raises(ValueError, match=r"keyframe must have shape \(6,\), got \(3,\)"):
        b._b.reset(None, np.zeros(3, np.int32))
    with pytest.raises(mjcffi.FatalError, match="sorted"):     # MuJoCo's own check
        b._b.step(np.array([2, 1], np.int32))
    np.testing.assert_array_equal(b.time, 0)                    # nothing ran


def test_public_errors_carry_the_official_message_and_a_note():
    b = batch.Batch(mjcffi.MjModel.from_xml_string(CARTPOLE), NSIM)
    cases = (
        (lambda: b.bind("pstack"), "pstack is not one of the MjData scalars bind() accepts: "
                                   "nA, nJ, ncon, ne, nefc, nf, nidof, nisland, nl", None),
        (lambda: b.rollout(0), "nstep must be positive", "got 0"),
        (lambda: b.rollout(1, record=("efc_force",)), "unknown field efc_force",
         "efc_force is in the arena, whose size changes from step to step, and cannot be "
         "recorded"),
        (lambda: b.rollout(1, record=("pstack",)), "unknown field pstack",
         "the MjData scalars rollout() records: nA, nJ, ncon, ne, nefc, nf, nidof, nisland, nl"),
        (lambda: b.step([[0]]), "ids must be one-dimensional", "got shape (1, 1)"),
        (lambda: b.step(np.ones(NSIM + 1, bool)), f"a boolean mask must have shape ({NSIM},)",
         f"the mask of simulations has shape ({NSIM + 1},)"),
        (lambda: b.jac(1, np.zeros(2)), None,
         f"point must have shape ({NSIM}, 3) (or broadcast to it), got (2,)"),
        (lambda: b.set_models([b.model] * 2), f"set_models needs a model per simulation, "
                                              f"got 2 for {NSIM}", None),
    )
    for call, message, note in cases:
        with pytest.raises(ValueError) as caught:
            call()
        if message is not None:
            assert str(caught.value) == message
        if note is not None:
            assert caught.value.__notes__ == [note]
    with pytest.raises(TypeError) as caught:
        b.bind(3)
    assert str(caught.value) == "attribute name must be string, not 'int'"


def test_named_views_span_every_control_of_a_multi_input_actuator():
    m = mjcffi.MjModel.from_xml_string(MIMO)
    d = mjcffi.MjData(m)
    b = batch.Batch(m, NSIM)
    ctrl = b.bind("ctrl")
    ctrl[:] = np.arange(NSIM * m.nu).reshape(NSIM, m.nu)
    b.forward()
    for name in ("before", "orient", "after"):
        a = m.actuator(name)
        adr, num = int(a.ctrladr[0]), int(a.ctrlnum[0])
        np.testing.assert_array_equal(b.actuator(name).ctrl, ctrl[:, adr:adr + num])
        assert b.actuator(name).ctrl.shape[1:] == d.actuator(name).ctrl.shape
    b.actuator("orient").ctrl = [1, 0, 0, 0]            # writes the four controls only
    np.testing.assert_array_equal(ctrl[:, 1:5], np.tile([1, 0, 0, 0], (NSIM, 1)))
    np.testing.assert_array_equal(ctrl[:, 0], 6 * np.arange(NSIM))
    np.testing.assert_array_equal(ctrl[:, 5], 6 * np.arange(NSIM) + 5)
