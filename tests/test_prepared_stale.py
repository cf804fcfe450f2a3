"""A prepared call never writes through a pointer that has gone stale.

A prepared call (mjcffi/_support/prepared.py) converts its arguments once and keeps
their C pointers.  Two kinds of memory can move under it:

- an array on an mjData's stack (mj_stackAllocNum, ...): MuJoCo releases it
  (mj_freeStack, mj_resetData, a step's reset of a bad state) and hands its bytes
  to the next allocation.  prepare refuses such an array: it would outlive the
  frame it was made in.
- a NumPy array resized with `refcheck=False`: NumPy frees its block.  prepare
  holds a weak reference to each bound array, and NumPy refuses `resize` of an
  array with one, whatever refcheck says.

And the bad-state reset inside rollout and MjSimPool.step releases the stack as
mj_step's does: the arrays it released become read-only there too.
"""

import gc
import weakref

import numpy as np
import pytest

import mjcffi
from mjcffi import rollout
from mjcffi.sim import MjSim, MjSimPool

XML = """<mujoco><worldbody><body><joint name="j"/><geom size=".1" mass="1"/></body>
         </worldbody><actuator><motor joint="j"/></actuator></mujoco>"""


@pytest.fixture
def md():
    m = mjcffi.MjModel.from_xml_string(XML)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    return m, d


# ------------------------------------------------------------- stack arrays

def test_prepare_refuses_a_stack_array_as_output(md):
    m, d = md
    mjcffi.mj_markStack(d)
    a = mjcffi.mj_stackAllocNum(d, 3)
    with pytest.raises(mjcffi.ArgumentError, match="stack") as caught:
        mjcffi.mju_fill.prepare(a, 7.0)
    assert isinstance(caught.value, (TypeError, ValueError))
    with pytest.raises(mjcffi.ArgumentError, match="stack"):
        mjcffi.mju_zero.prepare(a[1:])          # a view of one: the same memory
    mjcffi.mju_fill(a, 7.0)                      # the plain call takes it while it lives
    assert a.tolist() == [7.0] * 3
    mjcffi.mj_freeStack(d)


def test_prepare_refuses_a_stack_array_as_input(md):
    m, d = md
    mjcffi.mj_markStack(d)
    a = mjcffi.mj_stackAllocNum(d, 3)
    with pytest.raises(mjcffi.ArgumentError, match="stack"):
        mjcffi.mju_add3.prepare(np.zeros(3), a, np.ones(3))
    ints = mjcffi.mj_stackAllocInt(d, 2)
    assert ints.dtype == np.int32
    mjcffi.mj_freeStack(d)
    # released ones too (read-only now)
    with pytest.raises(mjcffi.ArgumentError, match="stack"):
        mjcffi.mju_add3.prepare(np.zeros(3), a, np.ones(3))


def test_a_prepared_call_cannot_overwrite_a_newer_stack_array(md):
    """The scenario the refusal prevents: bound to a released frame, a prepared call
    wrote into the array allocated there next."""
    m, d = md
    mjcffi.mj_markStack(d)
    a = mjcffi.mj_stackAllocNum(d, 3)
    try:
        fill = mjcffi.mju_fill.prepare(a, 7.0)
    except mjcffi.ArgumentError:
        fill = None
    mjcffi.mj_freeStack(d)
    mjcffi.mj_markStack(d)
    b = mjcffi.mj_stackAllocNum(d, 3)
    b[:] = 1.0
    if fill is not None:
        fill()
    assert b.tolist() == [1.0] * 3
    mjcffi.mj_freeStack(d)


def test_arrays_of_your_own_still_prepare(md):
    m, d = md
    mjcffi.mj_markStack(d)
    mjcffi.mj_stackAllocNum(d, 3)               # a live stack does not refuse others
    out = np.zeros(3)
    call = mjcffi.mju_add3.prepare(out, np.ones(3), np.full(3, 2.0))
    call()
    assert out.tolist() == [3.0] * 3
    mjcffi.mj_freeStack(d)


# ------------------------------------------------------ resize(refcheck=False)

def test_a_bound_array_cannot_be_resized_even_without_refcheck(md):
    m, d = md
    jacp = np.zeros((3, m.nv))
    point = np.zeros(3)
    jac = mjcffi.mj_jac.prepare(m, d, jacp, None, point, 1)
    for array in (jacp, point):
        with pytest.raises(ValueError, match="resize"):
            array.resize(10**6, refcheck=False)
    jac()
    assert jacp.shape == (3, m.nv)
    del jac
    gc.collect()
    point.resize(10**6, refcheck=False)          # free again once the call is gone
    assert point.shape == (10**6,)


def test_the_owner_of_a_bound_view_cannot_be_resized(md):
    m, d = md
    owner = np.zeros(8)
    view = owner[2:5]
    call = mjcffi.mju_fill.prepare(view, 3.0)
    with pytest.raises(ValueError, match="resize"):
        owner.resize(10**6, refcheck=False)
    call()
    assert owner.tolist() == [0, 0, 3, 3, 3, 0, 0, 0]


def test_a_resize_cannot_make_a_prepared_call_write_into_freed_memory(run_python):
    """The scenario: after resize(refcheck=False) freed its block, the prepared call
    wrote into whatever lives there now (an unrelated array, or malloc's own
    bookkeeping: an abort).  In a process of its own: it may crash."""
    code, out = run_python("""
        import numpy as np
        import mjcffi
        out = np.zeros(3)
        fill = mjcffi.mju_fill.prepare(out, 5.0)
        try:
            out.resize(3000, refcheck=False)
            print("resized")
        except ValueError:
            print("refused")
        victims = [np.full(3, -1.0) for _ in range(50)]     # what takes the freed block
        fill()
        print("victims intact", all(v.tolist() == [-1.0] * 3 for v in victims))
        print("written", out[:3].tolist())
        """)
    assert code == 0, out
    assert "refused" in out and "victims intact True" in out, out
    assert "written [5.0, 5.0, 5.0]" in out, out


def test_rechecked_prepared_calls_lock_too(md):
    m, d = md
    vec = np.ones(m.nv)
    res = np.zeros(m.nv)
    call = mjcffi.mj_mulM.prepare(m, d, res, vec)
    with pytest.raises(ValueError, match="resize"):
        res.resize(100, refcheck=False)
    call()


# --------------------------------------------- bad-state resets free the stack

def _bad_state(m):
    """A full-physics state whose qvel MuJoCo rejects (mj_checkVel resets the data)."""
    n = mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
    d = mjcffi.MjData(m)
    d.qvel[:] = 1e12
    state = np.empty(n)
    mjcffi.mj_getState(m, d, state, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
    return state


@pytest.mark.parametrize("nthread", [0, 2])
def test_a_bad_state_reset_in_rollout_freezes_the_stack_arrays(md, nthread):
    m, _ = md
    datas = [mjcffi.MjData(m) for _ in range(max(1, nthread))]
    arrays = [mjcffi.mj_stackAllocNum(d, 4) for d in datas]
    assert all(d.pstack > 0 for d in datas)
    with rollout.Rollout(nthread=nthread) as pool:
        pool.rollout(m, datas if nthread else datas[0], _bad_state(m)[None].repeat(4, 0),
                     nstep=3)
    # the reset emptied the stack of each data that rolled a state out (with two
    # threads, one may have taken every rollout)
    assert any(d.pstack == 0 for d in datas)
    for d, a in zip(datas, arrays):
        assert a.flags.writeable == (d.pstack > 0)
        if d.pstack == 0:
            with pytest.raises(ValueError):
                a[0] = 1.0


@pytest.mark.parametrize("python", [False, True])
def test_a_bad_state_reset_in_mjsimpool_freezes_the_stack_arrays(md, python):
    m, _ = md
    sims = [MjSim(m) for _ in range(2)]
    if python:
        for sim in sims:
            sim.set_substep_callback(lambda model, data: None)
    for sim in sims:
        sim.data.qvel[:] = 1e12
    arrays = [mjcffi.mj_stackAllocNum(sim.data, 4) for sim in sims]
    pool = MjSimPool(sims, nthreads=2)
    try:
        pool.step()
    finally:
        pool.close()
    assert all(sim.data.pstack == 0 for sim in sims)      # each sim steps once
    for a in arrays:
        assert not a.flags.writeable


def test_a_plain_stack_array_survives_a_good_rollout(md):
    m, d = md
    a = mjcffi.mj_stackAllocNum(d, 4)
    n = mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
    rollout.rollout(m, d, np.zeros((2, n)), nstep=3)
    assert d.pstack > 0 and a.flags.writeable
    ref = weakref.ref(a)
    assert ref() is a
