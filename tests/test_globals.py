"""MuJoCo's process globals and the arena: mjcffi.user_handlers (mju_user_*),
mjcffi.log_config (MjLogConfig.get/set), install_timer, and the official private
helpers _realloc_con_efc / _realloc_island (mjcffi/_support/arena.py).

The arena layouts are checked against MuJoCo's own (mj_forward's, on gymnasium
models) and against the official bindings' helpers on the same libmujoco.
"""

import ctypes
import gc
import importlib.resources
import re
import time

import numpy as np
import pytest

import mjcffi
from mjcffi import ffi, lib, scenes
from mjcffi._functions import _realloc_con_efc, _realloc_island

GLOBALS = ("mju_user_warning", "mju_user_malloc", "mju_user_free", "mjcb_time")


@pytest.fixture(autouse=True)
def restore_globals():
    """Put every global back as it was (the official bindings share them)."""
    saved = {name: getattr(lib, name) for name in GLOBALS}
    config = lib.mju_getLogConfig()
    yield
    for name, value in saved.items():
        setattr(lib, name, value)
    lib.mju_setLogConfig(config)


def gymnasium(name):
    folder = importlib.resources.files("gymnasium") / "envs" / "mujoco" / "assets"
    return mjcffi.MjModel.from_xml_string((folder / f"{name}.xml").read_text())


def arena_lists(mujoco_include):
    """mjxmacro.h's MJDATA_ARENA_POINTERS_* lists: block -> field names."""
    text = (mujoco_include / "mujoco" / "mjxmacro.h").read_text()
    lists = {}
    for block in ("CONTACT", "SOLVER", "DUAL", "ISLAND", "EFM"):
        body = text[text.index(f"#define MJDATA_ARENA_POINTERS_{block}"):]
        lists[block] = re.findall(r"X\w*\s*\(\s*\w+\s*,\s*(\w+)", body[:body.index("\n\n")])
    return lists


def offsets(d, names):
    """Each arena pointer of d as an offset into its arena (None: NULL)."""
    base = int(ffi.cast("uintptr_t", d._ptr.arena))
    out = {}
    for name in names:
        pointer = getattr(d._ptr, name)
        out[name] = None if pointer == ffi.NULL else int(ffi.cast("uintptr_t", pointer)) - base
    return out


# ------------------------------------------------------------------ the arena

ROW_COUNTS = ("ncon", "ne", "nf", "nl", "nefc", "nJ", "nY", "nA", "nisland", "nidof",
              "efm_active")

PGS_DISCRETE = """
<mujoco>
  <option solver="PGS" integrator="discrete"/>
  <worldbody>
    <geom type="plane" size="1 1 .1"/>
    <body pos="0 0 .099">
      <joint name="hinge" range="0 1" margin=".01" frictionloss="1"/>
      <geom size=".1"/>
    </body>
  </worldbody>
  <equality><joint joint1="hinge"/></equality>
</mujoco>
"""


@pytest.mark.parametrize("name", ["ant", "hopper", "walker2d", "half_cheetah"])
def test_layout_is_mujocos_own(name, mujoco_include):
    """After a step with contacts, the layout for mj_forward's counts is mj_forward's:
    every contact, constraint and island array at the same offset, the same parena."""
    lists = arena_lists(mujoco_include)
    names = lists["CONTACT"] + lists["SOLVER"] + lists["ISLAND"]
    m = gymnasium(name)
    d = mjcffi.MjData(m)
    mjcffi.mj_step(m, d, 300)
    mjcffi.mj_forward(m, d)
    assert d.ncon > 0 and d.nefc > 0 and d.nisland > 0 and not mjcffi.mj_isDual(m)
    fresh = mjcffi.MjData(m)
    _realloc_con_efc(fresh, d.ncon, d.nefc, d.nJ)
    _realloc_island(fresh, d.nisland, d.nidof)
    assert offsets(fresh, names) == offsets(d, names)
    assert fresh.parena == d.parena
    assert (fresh.ncon, fresh.nefc, fresh.nJ, fresh.nisland, fresh.nidof) == \
        (d.ncon, d.nefc, d.nJ, d.nisland, d.nidof)


def test_dual_solver_rows_come_with_the_constraints(mujoco_include):
    """The humanoid's PGS solver: contacts and rows as mj_forward lays them out, then the
    dual rows (nY, nA still 0), as the official helper does."""
    lists = arena_lists(mujoco_include)
    m = gymnasium("humanoid")
    d = mjcffi.MjData(m)
    mjcffi.mj_step(m, d, 300)
    mjcffi.mj_forward(m, d)
    assert mjcffi.mj_isDual(m) and d.ncon > 0
    fresh = mjcffi.MjData(m)
    _realloc_con_efc(fresh, d.ncon, d.nefc, d.nJ)
    names = lists["CONTACT"] + lists["SOLVER"]
    assert offsets(fresh, names) == offsets(d, names)
    assert fresh.efc_Y_rownnz.shape == (d.nefc,) and not fresh.efc_Y_rownnz.flags.owndata
    assert fresh.efc_Y.shape == (0,) and fresh.nY == fresh.nA == 0
    assert all(v is None for v in offsets(fresh, lists["ISLAND"] + lists["EFM"]).values())


def relative_spans(d, names, base):
    spans = {}
    for name in names:
        array = getattr(d, name)
        if array.size and not array.flags.owndata:
            spans[name] = array.__array_interface__["data"][0] - base
    return spans


def test_same_layout_as_the_official_helpers(mujoco, mujoco_include):
    """Same counts, same model, both bindings on one libmujoco: the same offsets."""
    lists = arena_lists(mujoco_include)
    names = lists["SOLVER"] + lists["DUAL"] + lists["ISLAND"] + lists["EFM"]
    ours_m = mjcffi.MjModel.from_xml_string(PGS_DISCRETE)
    theirs_m = mujoco.MjModel.from_xml_string(PGS_DISCRETE)
    ours, theirs = mjcffi.MjData(ours_m), mujoco.MjData(theirs_m)
    steps = [("con_efc", (3, 5)), ("con_efc", (2, 4, 9)), ("island", (2, 3)),
             ("island", (4, 1))]
    for kind, args in steps:
        getattr(mjcffi._functions, f"_realloc_{kind}")(ours, *args)
        getattr(mujoco._functions, f"_realloc_{kind}")(theirs, *args)
        base_ours = ours.contact.dist.__array_interface__["data"][0]
        base_theirs = theirs.contact.dist.__array_interface__["data"][0]
        assert relative_spans(ours, names, base_ours) == \
            relative_spans(theirs, names, base_theirs), (kind, args)
        for count in ROW_COUNTS:
            assert getattr(ours, count) == getattr(theirs, count), (kind, args, count)


def test_omitted_nJ_keeps_the_last_one():
    m = mjcffi.MjModel.from_xml_string(PGS_DISCRETE)
    d = mjcffi.MjData(m)
    _realloc_con_efc(d, 1, 2, nJ=7)
    _realloc_con_efc(d, 3, 4)
    assert (d.ncon, d.nefc, d.nJ) == (3, 4, 7) and d.efc_J.shape == (7,)
    assert len(d.contact) == 3 and d.efc_KBIP.shape == (4, 4)


def test_views_write_into_the_arena():
    m = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    d = mjcffi.MjData(m)
    _realloc_con_efc(d, 2, 3)
    d.efc_force[:] = [1, 2, 3]
    d.contact.dist[:] = [0.5, 0.25]
    assert [d._ptr.efc_force[i] for i in range(3)] == [1, 2, 3]
    assert d._ptr.contact[1].dist == 0.25


ARENA_MESSAGE = (r'Insufficient arena memory, currently allocated memory="[0-9]+[A-Z]?"\. '
                 r'Increase using <size memory="X"/>\.')


def arena_error(caught):
    """The official message as str(exc), exactly; the request in a note."""
    assert re.fullmatch(ARENA_MESSAGE, str(caught.value)), str(caught.value)
    return caught.value.__notes__[0]


def test_con_efc_overflow_clears_every_row_count():
    m = mjcffi.MjModel.from_xml_string(PGS_DISCRETE)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    assert all(getattr(d, count) > 0 for count in ROW_COUNTS)
    with pytest.raises(mjcffi.FatalError) as caught:
        _realloc_con_efc(d, 100000000, 100000000)
    assert "ncon=100000000" in arena_error(caught)
    assert all(getattr(d, count) == 0 for count in ROW_COUNTS)
    assert d.parena == 0 and len(d.contact) == 0 and d.efc_id.shape == (0,)
    mjcffi.mj_forward(m, d)                       # MuJoCo takes it from there
    assert d.nefc > 0


def test_island_overflow_keeps_the_constraints():
    m = mjcffi.MjModel.from_xml_string(PGS_DISCRETE)
    d = mjcffi.MjData(m)
    _realloc_con_efc(d, 1, 3)
    parena = d.parena
    _realloc_island(d, 2, 1)
    with pytest.raises(mjcffi.FatalError) as caught:
        _realloc_island(d, 100000000, 100000000)
    assert "nisland=100000000" in arena_error(caught)
    assert (d.nisland, d.nidof, d.ncon, d.nefc) == (0, 0, 1, 3)
    assert d.parena == parena and d.island_nv.shape == (0,)


def test_island_block_is_reused_only_when_last(mujoco_include):
    lists = arena_lists(mujoco_include)
    m = mjcffi.MjModel.from_xml_string(PGS_DISCRETE)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    later = lists["DUAL"] + lists["EFM"]
    before = offsets(d, later)
    end = d.parena
    _realloc_island(d, d.nisland + 1, d.nidof)
    assert offsets(d, later) == before
    assert offsets(d, ["tree_island"])["tree_island"] == end     # appended after everything
    grown = d.parena
    _realloc_island(d, d.nisland + 1, d.nidof)                   # now last: reused
    assert offsets(d, ["tree_island"])["tree_island"] == end and d.parena > grown


@pytest.mark.parametrize("call, args, note", [
    (_realloc_con_efc, (-1, 2), "negative"), (_realloc_con_efc, (1, 2, -2), "negative"),
    (_realloc_island, (1, -1), "negative")])
def test_negative_counts(call, args, note):
    m = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    d = mjcffi.MjData(m)
    with pytest.raises(mjcffi.FatalError) as caught:
        call(d, *args)
    assert note in arena_error(caught)


def test_bad_arguments():
    m = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    with pytest.raises(TypeError, match="d must be MjData, not MjModel"):
        _realloc_con_efc(m, 1, 1)
    d = mjcffi.MjData(m)
    with pytest.raises(TypeError, match="ncon must be an int"):
        _realloc_con_efc(d, 1.5, 1)
    with pytest.raises(TypeError, match="nidof must fit in a C int"):
        _realloc_island(d, 1, 2**40)


def test_found_where_the_official_has_them():
    import mjcffi as mujoco
    assert mujoco._functions._realloc_con_efc is _realloc_con_efc
    assert mujoco._functions._realloc_island is _realloc_island


# ------------------------------------------------------------- user handlers

def bad_qpos():
    m = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    d = mjcffi.MjData(m)
    d.qpos[0] = np.nan
    return m, d


def test_warning_handler_receives_the_text():
    seen = []
    mjcffi.set_mju_user_warning(seen.append)
    assert mjcffi.get_mju_user_warning() == seen.append
    mjcffi.mj_checkPos(*bad_qpos())
    assert len(seen) == 1 and seen[0].startswith("Nan, Inf or huge value in QPOS at DOF 0")
    mjcffi.set_mju_user_warning(None)
    assert mjcffi.get_mju_user_warning() is None and lib.mju_user_warning == ffi.NULL


def test_warning_handler_exception_is_raised_after_the_call():
    def broken(message):
        raise KeyError(message)
    mjcffi.set_mju_user_warning(broken)
    m, d = bad_qpos()
    with pytest.raises(KeyError, match="QPOS") as caught:
        mjcffi.mj_checkPos(m, d)
    assert any("mju_user_warning" in note for note in caught.value.__notes__)
    assert np.isfinite(d.qpos).all()               # the call itself went to its end


def test_c_warning_handler_is_installed_directly():
    seen = []
    handler = ctypes.CFUNCTYPE(None, ctypes.c_char_p)(seen.append)
    mjcffi.set_mju_user_warning(handler)
    assert mjcffi.get_mju_user_warning() is handler
    assert int(ffi.cast("uintptr_t", lib.mju_user_warning)) == \
        ctypes.cast(handler, ctypes.c_void_p).value
    mjcffi.mj_checkPos(*bad_qpos())
    assert seen and b"QPOS" in seen[0]


def test_clear_handlers_forgets_them():
    mjcffi.set_mju_user_warning(print)
    mjcffi.mju_clearHandlers()
    assert mjcffi.get_mju_user_warning() is None


class CountingAllocator:
    """malloc/free as cffi callbacks (C function pointers), 64-byte aligned."""

    def __init__(self):
        self.live, self.mallocs, self.frees = {}, 0, 0
        self.malloc = ffi.callback("void *(size_t)", self._malloc)
        self.free = ffi.callback("void (void *)", self._free)

    def _malloc(self, size):
        self.mallocs += 1
        block = ffi.new("char[]", size + 64)
        address = (int(ffi.cast("uintptr_t", block)) + 63) & ~63
        self.live[address] = block
        return ffi.cast("void *", address)

    def _free(self, pointer):
        self.frees += 1
        del self.live[int(ffi.cast("uintptr_t", pointer))]


def test_malloc_and_free_pointers():
    gc.collect()                          # nothing older is freed through ours
    allocator = CountingAllocator()
    m = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    mjcffi.set_mju_user_malloc(allocator.malloc)
    mjcffi.set_mju_user_free(allocator.free)
    try:
        assert mjcffi.get_mju_user_malloc() is allocator.malloc
        d = mjcffi.MjData(m)
        mjcffi.mj_step(m, d, 10)
        assert allocator.mallocs > 0 and allocator.live
        del d
        gc.collect()
        assert allocator.frees == allocator.mallocs and not allocator.live
    finally:
        mjcffi.set_mju_user_malloc(None)
        mjcffi.set_mju_user_free(None)
    assert mjcffi.get_mju_user_malloc() is None and mjcffi.get_mju_user_free() is None
    assert lib.mju_user_malloc == ffi.NULL and lib.mju_user_free == ffi.NULL


@pytest.mark.parametrize("bad", [len, lambda size: 0, 1, "malloc"])
def test_malloc_takes_c_pointers_only(bad):
    with pytest.raises(TypeError) as caught:
        mjcffi.set_mju_user_malloc(bad)
    assert str(caught.value) == "mju_user_malloc must be a C function pointer"
    assert "ctypes CFUNCTYPE" in caught.value.__notes__[0]
    assert lib.mju_user_malloc == ffi.NULL


def test_malloc_of_the_wrong_type():
    with pytest.raises(TypeError, match="mju_user_free needs a C function pointer of type"):
        mjcffi.set_mju_user_free(ffi.addressof(lib, "mjcffi_timer"))


@pytest.mark.parametrize("setter", ["set_mjcb_time", "set_mjcb_control", "set_mjcb_sensor",
                                    "set_mjcb_contactfilter", "set_mjcb_act_bias",
                                    "set_mju_user_warning"])
def test_not_callable_is_the_official_message(setter):
    with pytest.raises(TypeError) as caught:
        getattr(mjcffi, setter)(1)
    assert str(caught.value) == "callback is not an Optional[Callable]"
    assert caught.value.__notes__[0].endswith("not int")


@pytest.mark.parametrize("result", ["1.5", b"1", None, [1.0]])
def test_time_must_return_a_number(result):
    m = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    d = mjcffi.MjData(m)
    mjcffi.set_mjcb_time(lambda: result)
    with pytest.raises(TypeError) as caught:
        mjcffi.mj_forward(m, d)
    assert str(caught.value) == "mjcb_time callback did not return a number"
    assert caught.value.__notes__[0] == f"it returned {type(result).__name__}"


def test_time_numbers():
    m = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    d = mjcffi.MjData(m)
    for result in (1, np.float32(2.5), np.int64(3), True):
        mjcffi.set_mjcb_time(lambda: result)
        mjcffi.mj_forward(m, d)


# -------------------------------------------------------------------- timer

def test_install_timer():
    m = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    d = mjcffi.MjData(m)
    mjcffi.set_mjcb_time(None)
    mjcffi.mj_step(m, d, 3)
    step = mjcffi.mjtTimer.mjTIMER_STEP
    assert d.timer[step].number == 3 and d.timer[step].duration == 0.0
    mjcffi.install_timer()
    assert lib.mjcb_time == ffi.addressof(lib, "mjcffi_timer")
    assert mjcffi.get_mjcb_time() is not None
    mjcffi.mj_step(m, d, 3)
    assert d.timer[step].number == 6 and 0 < d.timer[step].duration < 1
    mjcffi.set_mjcb_time(None)
    assert lib.mjcb_time == ffi.NULL and mjcffi.get_mjcb_time() is None


def test_timer_is_monotonic_seconds():
    first = lib.mjcffi_timer()
    assert abs(first - time.monotonic()) < 0.1         # both CLOCK_MONOTONIC on Linux
    assert lib.mjcffi_timer() >= first


# --------------------------------------------------------------- log config

def test_log_config_get_and_set(tmp_path):
    original = mjcffi.MjLogConfig.get()
    assert isinstance(original, mjcffi.MjLogConfig)
    path = tmp_path / "mujoco.log"
    config = mjcffi.MjLogConfig.get()
    config.logto_console = False
    config.logto_file = True
    config.logfile = str(path)
    config.topics |= 1 << (mjcffi.mjtLogTopic.mjTOPIC_TIME_CMP - 1)
    assert mjcffi.MjLogConfig.get().logfile == original.logfile     # a copy until set()
    config.set()
    current = mjcffi.MjLogConfig.get()
    assert (current.logfile, current.topics, current.logto_console) == \
        (str(path), config.topics, False)
    mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    assert "compile time" in path.read_text()
    original.set()
    assert mjcffi.MjLogConfig.get().logfile == original.logfile


def test_log_config_default_is_zero(mujoco):
    ours, theirs = mjcffi.MjLogConfig(), mujoco.MjLogConfig()
    for field in ("logto_console", "logto_file", "logfile", "topics"):
        assert getattr(ours, field) == getattr(theirs, field)


def test_log_config_is_shared_with_the_official(mujoco):
    config = mjcffi.MjLogConfig.get()
    config.topics = 5
    config.set()
    assert mujoco.MjLogConfig.get().topics == 5
