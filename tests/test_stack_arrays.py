"""Issue 27, finding 2: no raw, unbounded pointer from a public function.

mj_stackAllocNum, mj_stackAllocInt and mj_stackAllocByte return NumPy arrays of
exactly the size asked for, in the MjData's arena, keeping the MjData alive; the
calls that release them make them read-only (mjcffi/_support/stack.py).  A scan of
every function returning a pointer checks what each gives Python.
"""

import gc
import inspect
import re

import numpy as np
import pytest

import mjcffi
from mjcffi import _functions
from mjcffi._generated.funcinfo import FUNCTIONS

XML = """
<mujoco>
  <worldbody>
    <body><joint name="hinge"/><geom size=".1" mass="1"/></body>
  </worldbody>
  <keyframe><key qpos=".3"/></keyframe>
</mujoco>
"""

POINTER_RESULTS = sorted(name for name, f in FUNCTIONS.items() if f.restype.endswith("*"))

# what a function returning a pointer may give Python: a copy, a wrapper that bounds it,
# an opaque void pointer (cffi cannot index one), or nothing
SAFE = ("_m.string(ret)", "_m.copy_array(", "_m.fill(", "_m.wrap(", "_m.wrap_const(",
        "_m.own(", "_m.stack_array(", "_h.result(")


@pytest.fixture
def md():
    m = mjcffi.MjModel.from_xml_string(XML)
    return m, mjcffi.MjData(m)


def _returns(name):
    function = getattr(_functions, "_" + name, None)
    if function is None:
        return None               # hand-written (an MjModel, MjData, ...) or unsupported
    return re.findall(r"^    return (.*)$", inspect.getsource(function), re.M)[-1]


@pytest.mark.parametrize("name", POINTER_RESULTS)
def test_no_function_returns_a_typed_raw_pointer(name):
    expression = _returns(name)
    if expression is None:
        source = inspect.getsource(getattr(mjcffi, name))
        assert "NotImplementedError" in source or "_model(" in source or \
            "MjData(" in source or FUNCTIONS[name].restype == "void *" or \
            "_m.copy_array(" in source or name in ("mj_copyModel", "mjui_event"), name
        return
    if expression.startswith(SAFE) or expression == "None":
        return
    assert expression == "None if ret == _m.NULL else ret", (name, expression)
    assert FUNCTIONS[name].restype in ("void *", "const void *"), name


@pytest.mark.parametrize("alloc, dtype, size", [
    (lambda d: mjcffi.mj_stackAllocNum(d, 7), np.float64, 7),
    (lambda d: mjcffi.mj_stackAllocInt(d, 5), np.int32, 5),
    (lambda d: mjcffi.mj_stackAllocByte(d, 13, 8), np.uint8, 13),
])
def test_a_stack_allocation_is_an_array_of_exactly_its_size(md, alloc, dtype, size):
    _, d = md
    a = alloc(d)
    assert isinstance(a, np.ndarray) and a.dtype == dtype and a.shape == (size,)
    a[:] = 3
    with pytest.raises(IndexError):
        a[size] = 1
    with pytest.raises(IndexError):
        a[10**9] = 1
    address = a.__array_interface__["data"][0]
    arena = int(mjcffi.ffi.cast("uintptr_t", d._ptr.arena))
    assert arena <= address and address + a.nbytes <= arena + d._ptr.narena


def test_an_empty_allocation_is_an_empty_array_and_a_huge_one_a_fatal_error(md):
    _, d = md
    assert mjcffi.mj_stackAllocNum(d, 0).shape == (0,)
    with pytest.raises(mjcffi.FatalError):
        mjcffi.mj_stackAllocNum(d, 2**62)
    with pytest.raises(mjcffi.FatalError):
        mjcffi.mj_stackAllocInt(d, d._ptr.narena)          # more than the arena
    assert d._ptr.pstack == 0


def test_the_array_keeps_its_mjdata_alive(md):
    m, d = md
    a = mjcffi.mj_stackAllocNum(d, 4)
    a[:] = [1, 2, 3, 4]
    del d
    gc.collect()
    mjcffi.MjData(m)                                      # memory that could reuse d's
    assert a.tolist() == [1, 2, 3, 4]


@pytest.mark.parametrize("release", [
    lambda m, d: mjcffi.mj_freeStack(d),
    lambda m, d: mjcffi.mj_resetData(m, d),
    lambda m, d: mjcffi.mj_resetDataKeyframe(m, d, 0),
    lambda m, d: mjcffi.mj_resetDataDebug(m, d, 7),
    lambda m, d: mjcffi.mj_copyData(d, m, mjcffi.MjData(m)),
])
def test_a_released_allocation_becomes_read_only(md, release):
    m, d = md
    mjcffi.mj_markStack(d)
    a = mjcffi.mj_stackAllocNum(d, 3)
    assert a.flags.writeable
    release(m, d)
    assert not a.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        a[0] = 1.0


def test_a_raw_mjdata_pointer_gets_arrays_and_releases_them_too(md):
    # the functions take a raw `mjData *` as well (found by python -m tests.fuzz)
    m, d = md
    raw_m, raw_d = m._ptr, d._ptr
    mjcffi.mj_markStack(raw_d)
    a = mjcffi.mj_stackAllocByte(raw_d, 5, 1)
    b = mjcffi.mj_stackAllocNum(d, 2)                  # the same data, through its wrapper
    assert (a.shape, a.dtype, a.flags.writeable) == ((5,), np.uint8, True)
    mjcffi.mj_resetData(raw_m, raw_d)
    assert not a.flags.writeable and not b.flags.writeable


def test_a_frame_pop_releases_only_what_the_frame_holds(md):
    m, d = md
    outer = mjcffi.mj_stackAllocInt(d, 2)
    mjcffi.mj_markStack(d)
    inner = mjcffi.mj_stackAllocInt(d, 2)
    mjcffi.mj_freeStack(d)
    assert outer.flags.writeable and not inner.flags.writeable
    mjcffi.mj_step(m, d)                      # MuJoCo's own frames come and go above
    assert outer.flags.writeable
    outer[:] = 5
    mjcffi.mj_step(m, d, 3)
    assert outer.tolist() == [5, 5]


@pytest.mark.parametrize("step", [lambda m, d: mjcffi.mj_step(m, d),
                                  lambda m, d: mjcffi.mj_step(m, d, 2),
                                  lambda m, d: mjcffi.mj_step1(m, d),
                                  lambda m, d: mjcffi.mj_checkPos(m, d)])
def test_the_reset_of_a_bad_state_releases_the_stack(md, step):
    m, d = md
    a = mjcffi.mj_stackAllocNum(d, 3)
    d.qpos[0] = np.nan
    step(m, d)
    assert d._ptr.pstack == 0 and not a.flags.writeable


def test_a_prepared_allocation_gives_arrays_too(md):
    _, d = md
    call = mjcffi.mj_stackAllocNum.prepare(d, 2)
    first, second = call(), call()
    assert first.shape == second.shape == (2,)
    assert first.__array_interface__["data"][0] != second.__array_interface__["data"][0]


def test_reproducer_indexing_far_past_a_stack_allocation_cannot_crash(run_python):
    """Finding 2: `p[10**9] = 1.0` on mj_stackAllocNum's raw pointer segfaulted."""
    code, out = run_python(f"""
        import mjcffi
        m = mjcffi.MjModel.from_xml_string({XML!r})
        d = mjcffi.MjData(m)
        mjcffi.mj_markStack(d)
        p = mjcffi.mj_stackAllocNum(d, 10)
        try:
            p[10**9] = 1.0
        except IndexError:
            print("refused")
        mjcffi.mj_freeStack(d)
        del d
        try:
            p[0] = 1.0
        except (IndexError, ValueError):
            print("refused after free")
        print("alive")
        """)
    assert code == 0, out
    assert "refused" in out and "refused after free" in out and "alive" in out
