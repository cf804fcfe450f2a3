"""MuJoCo's fatal errors (mju_error) become mjcffi.FatalError; the process lives.

The guards (lib.mjcffi_guard_*, lib.mjcffi_step) install their log handler per
call on the calling thread only and restore the previous one, so they coexist
with the official bindings, which share this process's libmujoco.
Models and data are raw cdata here: the struct classes are not needed.
"""

import ctypes
import os
import pathlib
import re
import subprocess
import sys
import threading

import pytest

import mjcffi
from mjcffi._support import library as _library
from mjcffi._support.errors import FatalError, check, raise_pending
from mjcffi._generated.funcinfo import FUNCTIONS
from mjcffi._support.loading import load_xml_path, load_xml_string

from .conftest import gymnasium_assets

ffi, lib = mjcffi.ffi, mjcffi.lib
REPO = pathlib.Path(__file__).resolve().parent.parent

PENDULUM = """
<mujoco>
  <worldbody>
    <body pos="0 0 1">
      <joint type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -.5" size=".05"/>
    </body>
  </worldbody>
</mujoco>
"""


def boxes_xml(memory="6K"):
    """Five free boxes, 1 m apart: they fly without touching.  Piled up, their
    narrowphase needs more stack than `memory` gives: a real mju_error."""
    bodies = "".join(f'<body pos="{i} 0 1"><freejoint/><geom type="box" size=".1 .1 .1"/></body>'
                     for i in range(5))
    return f'<mujoco><size memory="{memory}"/><worldbody>{bodies}</worldbody></mujoco>'


def make_data(m):
    return ffi.gc(lib.mj_makeData(m), lib.mj_deleteData)


def pile_up(d):
    for i in range(5):
        d.qpos[7 * i:7 * i + 3] = [0, 0, 0]


def state(m, d):
    """The whole integration state, as bytes: equal bytes mean bit-identical."""
    sig = mjcffi.mjtState.mjSTATE_INTEGRATION
    size = lib.mj_stateSize(m, sig)
    buffer = ffi.new("mjtNum[]", size)
    lib.mj_getState(m, d, buffer, sig)
    return bytes(ffi.buffer(buffer))


def trajectory(m, d, nstep):
    states = []
    for _ in range(nstep):
        check(lib.mjcffi_guard_mj_step(m, d))
        states.append(state(m, d))
    return states


@pytest.fixture
def in_tmp(tmp_path, monkeypatch):
    """MuJoCo's default handler writes MUJOCO_LOG.TXT into the working directory."""
    monkeypatch.chdir(tmp_path)


@pytest.fixture
def tls_log_handler():
    """libmujoco's thread-local log handler hook, reached through ctypes."""
    hook = ctypes.CDLL(_library._mujoco_library_path())._mjPRIVATE_setTlsLogHandler
    hook.restype = ctypes.c_void_p
    hook.argtypes = [ctypes.c_void_p]
    return hook


# ------------------------------------------------------------------ the guards

def test_every_function_has_a_guard():
    guards = {name[len("mjcffi_guard_"):] for name in dir(lib) if name.startswith("mjcffi_guard_")}
    assert guards == set(FUNCTIONS)


def test_generator_takes_funcinfo_as_well():
    from codegen import guards
    for relpath, text in guards.generate(FUNCTIONS).items():
        assert text == (REPO / relpath).read_text(), relpath


def test_mju_error_raises_with_mujocos_message():
    with pytest.raises(FatalError) as caught:
        check(lib.mjcffi_guard_mju_error(b"bad thing 100% (%d %s)"))
    assert str(caught.value) == "bad thing 100% (%d %s)"      # not a format string
    assert mjcffi.FatalError is FatalError


def test_process_survives_only_with_the_guard(tmp_path):
    script = ("from mjcffi import lib\nfrom mjcffi._support.errors import FatalError, check\n"
              "try:\n    check(lib.mjcffi_guard_mju_error(b'guarded'))\n"
              "except FatalError as e:\n    print('caught', e)\n"
              "lib.mju_error(b'unguarded')\nprint('not reached')\n")
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    run = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, env=env,
                         capture_output=True, text=True)
    assert run.stdout.startswith("caught guarded")
    assert "not reached" not in run.stdout
    assert run.returncode == 1 and "unguarded" in run.stdout + run.stderr   # exit(1), as documented


def test_nonvoid_guard_returns_zero_and_raise_pending_raises():
    m = load_xml_string(PENDULUM)
    assert lib.mjcffi_guard_mj_stateSize(m, 1 << 20) == 0
    with pytest.raises(FatalError, match=r"^mj_stateSize: invalid state signature 1048576"):
        raise_pending()
    assert lib.mjcffi_guard_mj_stateSize(m, 1) == lib.mj_stateSize(m, 1)
    raise_pending()                                   # nothing pending: no exception


def test_message_is_taken_once_and_never_blamed_on_a_later_call():
    m = load_xml_string(PENDULUM)
    assert lib.mjcffi_guard_mju_error(b"first") == 1
    assert ffi.string(lib.mjcffi_take_error()) == b"first"
    assert lib.mjcffi_take_error() == ffi.NULL
    assert lib.mjcffi_guard_mju_error(b"left untaken") == 1
    assert lib.mjcffi_guard_mj_stateSize(m, 1) > 0   # a later call succeeds: nothing pending
    assert lib.mjcffi_take_error() == ffi.NULL


def test_warnings_pass_through(in_tmp):
    assert lib.mjcffi_guard_mju_warning(b"only a warning") == 0
    assert lib.mjcffi_take_error() == ffi.NULL
    assert "only a warning" in pathlib.Path("MUJOCO_LOG.TXT").read_text()


def test_legacy_warning_handler_still_served():
    seen = []

    @ffi.callback("void(*)(const char *)")
    def warning(message):
        seen.append(ffi.string(message))

    lib.mju_user_warning = warning
    try:
        assert lib.mjcffi_guard_mju_warning(b"to the legacy handler") == 0
    finally:
        lib.mju_user_warning = ffi.NULL
    assert seen == [b"to the legacy handler"]


def test_previous_thread_local_handler_restored_and_sees_warnings(tls_log_handler):
    seen = []

    @ffi.callback("mjfLogHandler")
    def foreign(message):
        seen.append((message.level, ffi.string(message.subject)))

    address = int(ffi.cast("uintptr_t", foreign))
    assert tls_log_handler(address) is None            # no handler is left installed
    try:
        assert lib.mjcffi_guard_mju_warning(b"forwarded") == 0
        with pytest.raises(FatalError, match="caught by mjcffi"):
            check(lib.mjcffi_guard_mju_error(b"caught by mjcffi"))
    finally:
        assert tls_log_handler(None) == address        # restored after each call
    assert seen == [(lib.mjLOG_WARNING, b"forwarded")]  # the error went to the guard only


# --------------------------------------------------- a real error in the engine

def test_stack_overflow_in_mj_step_raises():
    m = load_xml_string(boxes_xml())
    d = make_data(m)
    pile_up(d)
    with pytest.raises(FatalError, match=r"^mj_stackAlloc: out of memory, stack overflow"):
        check(lib.mjcffi_guard_mj_step(m, d))
    with pytest.raises(FatalError, match=r"^mj_stackAlloc: out of memory"):
        check(lib.mjcffi_step(m, d, 10))


def test_recovery_by_mj_resetData():
    m = load_xml_string(boxes_xml())
    d = make_data(m)
    pile_up(d)
    with pytest.raises(FatalError):
        check(lib.mjcffi_guard_mj_step(m, d))
    # Why a reset is needed: the longjmp skipped mj_step's release of its stack
    # frames, so part of the stack stays taken.
    assert d.pstack > 0
    lib.mj_resetData(m, d)
    assert d.pstack == 0
    fresh = make_data(m)
    assert trajectory(m, d, 50) == trajectory(m, fresh, 50)


def test_repeated_errors_leave_the_handler_working():
    m = load_xml_string(boxes_xml())
    d = make_data(m)
    for _ in range(100):
        lib.mj_resetData(m, d)
        pile_up(d)
        assert lib.mjcffi_step(m, d, 1) == 1
        assert lib.mjcffi_take_error() != ffi.NULL


# ---------------------------------------------------------------------- nstep

@pytest.mark.parametrize("name", ["hopper.xml", "ant.xml"])
def test_mjcffi_step_equals_single_steps(name):
    path = next(p for p in gymnasium_assets() if p.name == name)
    m = load_xml_path(path)
    one, many = make_data(m), make_data(m)
    for d in (one, many):
        d.qvel[0] = 0.3                               # start moving, into contact
    for _ in range(300):
        check(lib.mjcffi_guard_mj_step(m, one))
    check(lib.mjcffi_step(m, many, 300))
    assert state(m, many) == state(m, one)
    assert many.time == one.time > 0


def test_mjcffi_step_zero_steps_is_a_no_op():
    m = load_xml_string(PENDULUM)
    d = make_data(m)
    before = state(m, d)
    assert lib.mjcffi_step(m, d, 0) == 0
    assert state(m, d) == before


# -------------------------------------------------------------------- threads

def test_error_in_one_thread_leaves_another_untouched():
    m = load_xml_string(boxes_xml())
    failing_started, done = threading.Event(), threading.Event()
    counts = {"during": 0}

    def failing():
        d = make_data(m)
        while not done.is_set():
            lib.mj_resetData(m, d)
            pile_up(d)
            try:
                check(lib.mjcffi_guard_mj_step(m, d))
            except FatalError:
                counts["during"] += not done.is_set()
                failing_started.set()

    def stepping():
        # Steps in chunks until the other thread has failed a few times meanwhile:
        # on two loaded cores a fixed length could end before it is scheduled again.
        d, states = make_data(m), []
        failing_started.wait(10)
        try:
            while counts["during"] < 3 and len(states) < 50_000:
                states += trajectory(m, d, 500)
        finally:
            counts["states"] = states
            done.set()

    threads = [threading.Thread(target=failing), threading.Thread(target=stepping)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert counts["during"] >= 3                      # errors kept coming while the other stepped
    assert counts["states"] == trajectory(m, make_data(m), len(counts["states"]))


def test_error_and_message_are_per_thread():
    assert lib.mjcffi_guard_mju_error(b"on the main thread") == 1
    seen = []
    worker = threading.Thread(target=lambda: seen.append(lib.mjcffi_take_error() == ffi.NULL))
    worker.start()
    worker.join()
    assert seen == [True]
    assert ffi.string(lib.mjcffi_take_error()) == b"on the main thread"


# ---------------------------------------------- nesting, and the official bindings

@pytest.fixture
def control_callback():
    """Install a cffi mjcb_control for the test; always cleared after."""
    keep = []

    def install(function):
        callback = ffi.callback("mjfGeneric", function)
        keep.append(callback)
        lib.mjcb_control = callback

    yield install
    lib.mjcb_control = ffi.NULL


def test_nested_guard_inside_a_guarded_step(control_callback):
    inner = []

    def control(m, d):
        try:
            check(lib.mjcffi_guard_mju_error(b"inside the callback"))
        except FatalError as error:
            inner.append(str(error))

    m = load_xml_string(PENDULUM)                    # compiling runs mjcb_control too
    d = make_data(m)
    control_callback(control)
    assert lib.mjcffi_step(m, d, 3) == 0              # the outer guard goes on
    assert inner == ["inside the callback"] * 3
    assert lib.mjcffi_take_error() == ffi.NULL


def _official_error(mujoco, model):
    with pytest.raises(mujoco.FatalError, match="invalid state signature"):
        mujoco.mj_stateSize(model, 1 << 20)


def test_official_bindings_unaffected_in_turn(mujoco):
    om = mujoco.MjModel.from_xml_string(PENDULUM)
    _official_error(mujoco, om)
    with pytest.raises(FatalError, match="mjcffi first"):
        check(lib.mjcffi_guard_mju_error(b"mjcffi first"))
    _official_error(mujoco, om)
    with pytest.raises(FatalError, match="mjcffi again"):
        check(lib.mjcffi_guard_mju_error(b"mjcffi again"))


def test_official_error_inside_a_mjcffi_guarded_step(mujoco, control_callback):
    om = mujoco.MjModel.from_xml_string(PENDULUM)
    inner = []

    def control(m, d):
        try:
            mujoco.mj_stateSize(om, 1 << 20)
        except mujoco.FatalError as error:
            inner.append(str(error))

    m = load_xml_string(PENDULUM)
    d = make_data(m)
    control_callback(control)
    assert lib.mjcffi_step(m, d, 2) == 0
    assert len(inner) == 2 and inner[0].startswith("mj_stateSize: invalid state signature")
    with pytest.raises(FatalError, match="still ours"):  # ours was put back after theirs
        check(lib.mjcffi_guard_mju_error(b"still ours"))


def test_mjcffi_error_inside_an_official_step(mujoco):
    om = mujoco.MjModel.from_xml_string(PENDULUM)
    od = mujoco.MjData(om)
    inner = []

    def control(m, d):
        try:
            check(lib.mjcffi_guard_mju_error(b"from mjcffi inside mujoco"))
        except FatalError as error:
            inner.append(str(error))

    mujoco.set_mjcb_control(control)
    try:
        mujoco.mj_step(om, od, 2)
    finally:
        mujoco.set_mjcb_control(None)
    assert inner == ["from mjcffi inside mujoco"] * 2
    _official_error(mujoco, om)                        # theirs was put back after ours


def test_message_format_matches_official(mujoco):
    om = mujoco.MjModel.from_xml_string(PENDULUM)
    with pytest.raises(mujoco.FatalError) as theirs:
        mujoco.mj_stateSize(om, 1 << 20)
    assert lib.mjcffi_guard_mj_stateSize(load_xml_string(PENDULUM), 1 << 20) == 0
    with pytest.raises(FatalError) as ours:
        raise_pending()
    assert str(ours.value) == str(theirs.value)


def test_errors_module_imports_only_the_library_and_stdlib():
    source = (REPO / "mjcffi" / "_support" / "errors.py").read_text()
    imports = re.findall(r"^(?:from|import) (\S+)", source, re.M)
    assert set(imports) <= {".library"}
