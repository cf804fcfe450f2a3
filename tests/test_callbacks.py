"""The mjcb_* callbacks (mjcffi._support.callbacks): Python callables, C pointers, errors.

The globals live in the one libmujoco of the process, shared with the official
bindings (whose import puts a timer in mjcb_time): the autouse fixture saves
every raw pointer before each test and puts it back after.  Stepping is raw
(lib.mjcffi_guard_mj_step + _errors.check), then an explicit
raise_pending_callback_error(), as the function layer will do.
"""

import ctypes
import gc
import importlib.util
import sys
import threading
import traceback
import weakref

import numpy as np
import pytest
from cffi import FFI

import mjcffi
from mjcffi._support import callbacks, contract
from mjcffi import ffi, lib
from codegen.headers import include_dir as mujoco_include_dir
from mjcffi._support.errors import check
from mjcffi._support.callbacks import raise_pending_callback_error

NAMES = ("passive", "control", "contactfilter", "sensor", "time", "act_dyn", "act_gain",
         "act_bias")

PENDULUM = """
<mujoco>
  <worldbody>
    <body pos="0 0 1">
      <joint name="hinge" type="hinge" axis="0 1 0" damping=".1"/>
      <geom type="capsule" fromto="0 0 0 0 0 -.5" size=".05"/>
    </body>
  </worldbody>
  <actuator><motor joint="hinge"/></actuator>
</mujoco>
"""

USER_ACTUATORS = """
<mujoco>
  <worldbody>
    <body>
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom size=".1"/>
    </body>
  </worldbody>
  <actuator>
    <general joint="hinge" gaintype="user" biastype="user"/>
    <general joint="hinge" dyntype="user" gainprm="1"/>
  </actuator>
</mujoco>
"""

USER_SENSOR = """
<mujoco>
  <worldbody>
    <body><joint type="hinge"/><geom size=".1"/></body>
  </worldbody>
  <sensor><user dim="2" needstage="pos" datatype="real"/></sensor>
</mujoco>
"""

BALL_ON_FLOOR = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 .1"/>
    <body pos="0 0 .2"><freejoint/><geom name="ball" size=".1"/></body>
  </worldbody>
</mujoco>
"""

# A native callback in a cffi module of its own, with its own cdef of the
# MuJoCo structs (cffi spells them `mjModel *`, mjcffi `struct mjModel_ *`).
NATIVE_CDEF = """
typedef struct mjModel_ mjModel;
typedef struct mjData_ mjData;
void half_control(const mjModel* m, mjData* d);
long long half_control_calls(void);
void nothing(const mjModel* m, mjData* d);
void call_on_new_thread(void* generic, void* m, void* d);
"""

NATIVE_SOURCE = """
#include <pthread.h>
#include <mujoco/mujoco.h>
static long long calls = 0;
void half_control(const mjModel* m, mjData* d) {
  calls++;
  for (int i = 0; i < m->nu; i++) d->ctrl[i] = 0.5;
}
long long half_control_calls(void) { return calls; }
void nothing(const mjModel* m, mjData* d) { (void)m; (void)d; }

/* Call an mjfGeneric on a thread Python never saw, as MuJoCo's pool threads do. */
typedef struct { mjfGeneric f; const mjModel* m; mjData* d; } job;
static void* run(void* arg) { job* j = arg; j->f(j->m, j->d); return NULL; }
void call_on_new_thread(void* generic, void* m, void* d) {
  job j = {(mjfGeneric)generic, m, d};
  pthread_t thread;
  if (pthread_create(&thread, NULL, run, &j) == 0) pthread_join(thread, NULL);
}
"""


def load(xml):
    return mjcffi.MjModel.from_xml_string(xml)


def step(m, d, n=1):
    for _ in range(n):
        check(lib.mjcffi_guard_mj_step(m._ptr, d._ptr))
        raise_pending_callback_error()


def forward(m, d):
    check(lib.mjcffi_guard_mj_forward(m._ptr, d._ptr))
    raise_pending_callback_error()


def state(m, d):
    """The integration state as bytes: equal bytes mean bit-identical."""
    sig = mjcffi.mjtState.mjSTATE_INTEGRATION
    buffer = ffi.new("mjtNum[]", lib.mj_stateSize(m._ptr, sig))
    lib.mj_getState(m._ptr, d._ptr, buffer, sig)
    return bytes(ffi.buffer(buffer))


def setter(name):
    return getattr(mjcffi, f"set_mjcb_{name}")


def getter(name):
    return getattr(mjcffi, f"get_mjcb_{name}")


def address(pointer):
    return int(ffi.cast("uintptr_t", pointer))


@pytest.fixture(autouse=True)
def restore_globals():
    """Save the raw mjcb_* pointers; after the test clear mjcffi's, restore them all."""
    saved = {name: getattr(lib, f"mjcb_{name}") for name in NAMES}
    yield
    for name in NAMES:
        setter(name)(None)
        setattr(lib, f"mjcb_{name}", saved[name])
    leftover = contract._take()
    assert leftover is None, f"a test left a callback error pending: {leftover!r}"


@pytest.fixture(scope="session")
def native(tmp_path_factory):
    """A cffi extension compiled now, holding C callbacks (its .so path, ffi, lib)."""
    builder = FFI()
    builder.cdef(NATIVE_CDEF)
    builder.set_source("mjcffi_test_native", NATIVE_SOURCE,
                       include_dirs=[str(mujoco_include_dir())],
                       libraries=["pthread"])
    path = builder.compile(tmpdir=str(tmp_path_factory.mktemp("native")))
    spec = importlib.util.spec_from_file_location("mjcffi_test_native", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return path, module.ffi, module.lib


# ----------------------------------------------------------- Python callables

def test_python_control_equals_ctrl_written_before_each_step():
    m = load(PENDULUM)
    law = lambda d: -2.0 * d.qpos[0] - 0.3 * d.qvel[0] + np.sin(7 * d.time)  # noqa: E731
    by_hand, by_callback, free = mjcffi.MjData(m), mjcffi.MjData(m), mjcffi.MjData(m)
    for d in (by_hand, by_callback, free):
        d.qpos[0] = 0.7
    hand, callback, uncontrolled = [], [], []
    for _ in range(300):
        by_hand.ctrl[0] = law(by_hand)
        step(m, by_hand)
        hand.append(state(m, by_hand))
        step(m, free)
        uncontrolled.append(state(m, free))

    def control(model, data):
        data.ctrl[0] = law(data)
    mjcffi.set_mjcb_control(control)
    for _ in range(300):
        step(m, by_callback)
        callback.append(state(m, by_callback))
    assert callback == hand                     # bit-identical, every step
    assert callback[-1] != uncontrolled[-1]     # and the control did something


def test_callback_receives_the_users_objects():
    m = load(PENDULUM)
    d = mjcffi.MjData(m)
    assert d._root in callbacks._DATAS and m._root in callbacks._MODELS   # _track's hook
    seen = []
    mjcffi.set_mjcb_control(lambda model, data: seen.append((model, data)))
    step(m, d)
    assert seen and all(model is m and data is d for model, data in seen)


def test_tracked_wrappers_arrive_as_themselves():
    m = load(PENDULUM)
    d = mjcffi.MjData(m)
    callbacks._track(m)
    callbacks._track(d)
    other = mjcffi.MjData(m)           # a second data: each finds its own wrapper
    callbacks._track(other)
    seen = []
    mjcffi.set_mjcb_passive(lambda model, data: seen.append((model, data)))
    step(m, d)
    step(m, other)
    assert [(a is m, b) for a, b in seen] == [(True, d), (True, other)]
    assert seen[0][1] is d and seen[1][1] is other


def test_registry_forgets_dead_wrappers():
    m = load(PENDULUM)
    d = mjcffi.MjData(m)
    callbacks._track(d)
    key = d._root
    assert key in callbacks._DATAS
    del d
    gc.collect()
    assert key not in callbacks._DATAS


def test_foreign_data_arrives_as_a_borrowed_wrapper():
    m = load(PENDULUM)
    callbacks._track(m)
    raw = ffi.gc(lib.mj_makeData(m._ptr), lib.mj_deleteData)   # no mjcffi wrapper owns it
    raw.qpos[0] = 0.25
    seen = []

    def control(model, data):
        seen.append((model, type(data), data.model, data.qpos.copy(), data._ptr == raw))
    mjcffi.set_mjcb_control(control)
    check(lib.mjcffi_guard_mj_step(m._ptr, raw))
    model, kind, its_model, qpos, same = seen[0]
    assert model is m and kind is mjcffi.MjData and its_model is m and same
    assert qpos.tolist() == [0.25]


def test_passive_adds_force():
    m = load(PENDULUM)
    d, free = mjcffi.MjData(m), mjcffi.MjData(m)

    def push(model, data):
        data.qfrc_passive[0] += 5.0
    mjcffi.set_mjcb_passive(push)
    forward(m, d)
    mjcffi.set_mjcb_passive(None)
    forward(m, free)
    assert d.qfrc_passive[0] == free.qfrc_passive[0] + 5.0
    assert d.qacc[0] > free.qacc[0]


def test_sensor_fills_user_sensor():
    m = load(USER_SENSOR)
    d = mjcffi.MjData(m)
    stages = []

    def sensor(model, data, stage):
        stages.append(stage)
        if stage == mjcffi.mjtStage.mjSTAGE_POS:
            data.sensordata[:2] = [42.0, model.nq]
    mjcffi.set_mjcb_sensor(sensor)
    forward(m, d)
    assert d.sensordata.tolist() == [42.0, 1.0]
    assert stages == [mjcffi.mjtStage.mjSTAGE_POS]     # only the stages a user sensor needs


def test_act_gain_and_bias_set_the_force():
    m = load(USER_ACTUATORS)
    d = mjcffi.MjData(m)
    d.ctrl[:] = [2.0, 0.0]
    asked = []

    def gain(model, data, actuator):
        asked.append(actuator)
        return 3.0
    mjcffi.set_mjcb_act_gain(gain)
    mjcffi.set_mjcb_act_bias(lambda model, data, actuator: 0.25)
    forward(m, d)
    assert asked == [0]                                 # only the user-gain actuator
    assert d.actuator_force[0] == 3.0 * 2.0 + 0.25


def test_act_dyn_sets_the_activation_rate():
    m = load(USER_ACTUATORS)
    d = mjcffi.MjData(m)
    mjcffi.set_mjcb_act_dyn(lambda model, data, actuator: -1.5 * (actuator + 1))
    forward(m, d)
    assert d.act_dot.tolist() == [-3.0]                 # actuator 1, the only stateful one


def test_contactfilter_discards_pairs():
    m = load(BALL_ON_FLOOR)
    kept, dropped = mjcffi.MjData(m), mjcffi.MjData(m)
    pairs = []

    def reject(model, data, geom1, geom2):
        pairs.append((geom1, geom2))
        return True                                      # any int-like: nonzero discards
    step(m, kept, 300)
    mjcffi.set_mjcb_contactfilter(reject)
    step(m, dropped, 300)
    assert kept.ncon > 0 and kept.qpos[2] > 0.09        # rests on the floor
    assert dropped.ncon == 0 and dropped.qpos[2] < 0.0  # falls through it
    assert set(pairs) == {(0, 1)}


def test_time_callback_drives_the_timers():
    m = load(PENDULUM)
    d = mjcffi.MjData(m)
    clock = iter(range(1, 10**6))
    mjcffi.set_mjcb_time(lambda: next(clock))
    step(m, d)
    mjcffi.set_mjcb_time(None)
    assert next(clock) > 2                                # called during the step
    assert d.timer[mjcffi.mjtTimer.mjTIMER_STEP].duration > 0


# ------------------------------------------------------------------ exceptions

def test_exception_is_reraised_after_the_call_and_the_process_lives():
    m = load(PENDULUM)
    d, reference = mjcffi.MjData(m), mjcffi.MjData(m)
    d.ctrl[0] = reference.ctrl[0] = 1.0
    calls = []

    def broken(model, data):
        calls.append(data.time)
        raise ValueError("broken controller")
    mjcffi.set_mjcb_control(broken)
    check(lib.mjcffi_step(m._ptr, d._ptr, 3))           # no Python error crosses MuJoCo
    assert contract.pending
    with pytest.raises(ValueError, match="broken controller") as caught:
        raise_pending_callback_error()
    assert len(calls) == 3                               # the call ran to its end
    assert any(frame.name == "broken" for frame in traceback.extract_tb(caught.value.__traceback__))
    if sys.version_info >= (3, 11):
        assert "mjcb_control" in caught.value.__notes__[0]
    raise_pending_callback_error()                       # taken once: nothing left
    assert not contract.pending
    mjcffi.set_mjcb_control(None)
    step(m, d)                                           # the data steps on as usual
    step(m, reference, 4)
    assert state(m, d) == state(m, reference)           # the failed callback changed nothing


def test_first_exception_wins():
    m = load(PENDULUM)
    d = mjcffi.MjData(m)
    count = iter(range(100))

    def failing(model, data):
        raise RuntimeError(f"failure {next(count)}")
    mjcffi.set_mjcb_control(failing)
    check(lib.mjcffi_step(m._ptr, d._ptr, 5))
    with pytest.raises(RuntimeError, match="failure 0"):
        raise_pending_callback_error()
    raise_pending_callback_error()


@pytest.mark.parametrize("name, result", [("act_gain", "three"), ("act_bias", None)])
def test_bad_return_value_is_a_typeerror_and_mujoco_gets_zero(name, result):
    m = load(USER_ACTUATORS)
    d = mjcffi.MjData(m)
    d.ctrl[0] = 1.0
    mjcffi.set_mjcb_act_gain(lambda model, data, actuator: 0.0)
    mjcffi.set_mjcb_act_bias(lambda model, data, actuator: 0.0)
    setter(name)(lambda model, data, actuator: result)
    check(lib.mjcffi_guard_mj_forward(m._ptr, d._ptr))
    assert d.actuator_force[0] == 0.0
    with pytest.raises(TypeError) as caught:
        raise_pending_callback_error()
    assert str(caught.value) == f"mjcb_{name} callback did not return a number"  # official
    assert f"it returned {type(result).__name__}" in caught.value.__notes__


def test_contactfilter_bad_return_keeps_the_pair():
    m = load(BALL_ON_FLOOR)
    d = mjcffi.MjData(m)
    mjcffi.set_mjcb_contactfilter(lambda model, data, g1, g2: "no")
    check(lib.mjcffi_step(m._ptr, d._ptr, 300))
    with pytest.raises(TypeError) as caught:
        raise_pending_callback_error()
    assert str(caught.value) == "mjcb_contactfilter callback did not return an integer"
    assert "it returned str" in caught.value.__notes__[0]
    assert d.ncon > 0 and d.qpos[2] > 0.09             # neutral 0: the pair was kept


def test_keyboard_interrupt_is_stashed_too():
    m = load(PENDULUM)
    d = mjcffi.MjData(m)

    def interrupted(model, data):
        raise KeyboardInterrupt
    mjcffi.set_mjcb_control(interrupted)
    check(lib.mjcffi_guard_mj_step(m._ptr, d._ptr))
    with pytest.raises(KeyboardInterrupt):
        raise_pending_callback_error()


def test_exceptions_stay_on_their_thread():
    m = load(PENDULUM)
    mjcffi.set_mjcb_control(lambda model, data: 1 / 0)
    stepped, checked, outcome = threading.Event(), threading.Event(), []

    def worker():
        check(lib.mjcffi_guard_mj_step(m._ptr, mjcffi.MjData(m)._ptr))
        stepped.set()
        checked.wait()
        try:
            raise_pending_callback_error()
        except ZeroDivisionError:
            outcome.append("raised on the worker")
    thread = threading.Thread(target=worker)
    thread.start()
    stepped.wait()
    assert contract.pending
    raise_pending_callback_error()                       # the worker's: not raised here
    checked.set()
    thread.join()
    assert outcome == ["raised on the worker"]


def test_errors_of_ended_threads_are_dropped():
    m = load(PENDULUM)
    mjcffi.set_mjcb_control(lambda model, data: 1 / 0)
    thread = threading.Thread(
        target=lambda: check(lib.mjcffi_guard_mj_step(m._ptr, mjcffi.MjData(m)._ptr)))
    thread.start()
    thread.join()
    assert contract.pending                             # the worker never asked
    raise_pending_callback_error()                        # not ours: nothing raised
    assert not contract.pending                         # and the fast path is back


def test_callback_on_a_thread_python_never_saw(native):
    # as on the pool threads of an mjThreadPool: cffi takes the GIL there too
    _, _, native_lib = native
    m = load(PENDULUM)
    d = mjcffi.MjData(m)
    seen = []

    def control(model, data):
        seen.append((threading.current_thread() is threading.main_thread(), data.ctrl.shape))
        data.ctrl[0] = 0.25
    mjcffi.set_mjcb_control(control)
    native_lib.call_on_new_thread(lib.mjcb_control, m._ptr, d._ptr)
    assert seen == [(False, (1,))] and d.ctrl[0] == 0.25


def test_error_on_a_thread_python_never_saw_goes_to_the_next_check(native):
    _, _, native_lib = native
    m = load(PENDULUM)
    d = mjcffi.MjData(m)
    mjcffi.set_mjcb_control(lambda model, data: 1 / 0)
    native_lib.call_on_new_thread(lib.mjcb_control, m._ptr, d._ptr)
    with pytest.raises(ZeroDivisionError):
        raise_pending_callback_error()


# ---------------------------------------------------------- C function pointers

def test_cffi_c_pointer_is_installed_directly(native):
    _, native_ffi, native_lib = native
    pointer = native_ffi.addressof(native_lib, "half_control")
    m = load(PENDULUM)
    d = mjcffi.MjData(m)
    before = native_lib.half_control_calls()
    mjcffi.set_mjcb_control(pointer)
    # MuJoCo holds the C function's own address: no trampoline in between
    assert address(lib.mjcb_control) == int(native_ffi.cast("uintptr_t", pointer))
    assert mjcffi.get_mjcb_control() is pointer
    python_calls = []

    def profile(frame, event, arg):
        if event == "call":
            python_calls.append(frame.f_code.co_name)
    sys.setprofile(profile)
    try:
        status = lib.mjcffi_step(m._ptr, d._ptr, 10)
    finally:
        sys.setprofile(None)
    check(status)
    assert native_lib.half_control_calls() - before == 10
    assert d.ctrl.tolist() == [0.5]
    assert python_calls == []                            # no Python ran during the steps


def test_python_callable_does_run_python(native):
    m = load(PENDULUM)
    d = mjcffi.MjData(m)
    mjcffi.set_mjcb_control(lambda model, data: None)
    assert address(lib.mjcb_control) == address(lib.mjcffi_py_mjcb_control)
    python_calls = []
    sys.setprofile(lambda frame, event, arg: python_calls.append(event))
    try:
        check(lib.mjcffi_step(m._ptr, d._ptr, 10))
    finally:
        sys.setprofile(None)
    assert python_calls.count("call") >= 10              # the contrast with the test above


def test_mjcffi_own_function_pointer(native):
    # a function of libmujoco with mjfGeneric's signature, taken through mjcffi.ffi
    m = load(PENDULUM)
    d = mjcffi.MjData(m)
    energy = ffi.addressof(lib, "mj_energyPos")
    mjcffi.set_mjcb_control(energy)
    assert mjcffi.get_mjcb_control() is energy and lib.mjcb_control == energy
    forward(m, d)
    assert d.energy[0] != 0.0                            # energy is not enabled: only the callback


def test_ctypes_function_from_a_library(native):
    path, _, native_lib = native
    function = ctypes.CDLL(path).half_control          # the symbol itself (cffi's addressof
    m = load(PENDULUM)                                 # gives a direct-call stub beside it)
    d = mjcffi.MjData(m)
    before = native_lib.half_control_calls()
    mjcffi.set_mjcb_control(function)
    assert address(lib.mjcb_control) == ctypes.cast(function, ctypes.c_void_p).value
    assert mjcffi.get_mjcb_control() is function
    step(m, d)
    assert d.ctrl.tolist() == [0.5] and native_lib.half_control_calls() == before + 1


def test_ctypes_cfunctype_of_a_python_function():
    # installed directly too, but ctypes' own thunk takes the GIL on each call;
    # its function gets raw addresses, not wrappers
    seen = []
    prototype = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int)
    thunk = prototype(lambda model, data, actuator: seen.append(actuator) or 4.0)
    m = load(USER_ACTUATORS)
    d = mjcffi.MjData(m)
    d.ctrl[0] = 1.0
    mjcffi.set_mjcb_act_gain(thunk)
    assert address(lib.mjcb_act_gain) == ctypes.cast(thunk, ctypes.c_void_p).value
    forward(m, d)
    assert seen == [0] and d.actuator_force[0] == 4.0


def test_cffi_callback_object():
    @ffi.callback("mjfAct")
    def gain(m, d, actuator):
        return 2.5
    m = load(USER_ACTUATORS)
    d = mjcffi.MjData(m)
    d.ctrl[0] = 2.0
    mjcffi.set_mjcb_act_gain(gain)
    assert lib.mjcb_act_gain == gain
    forward(m, d)
    assert d.actuator_force[0] == 5.0


# ------------------------------------------------------------- set, get, clear

@pytest.mark.parametrize("name", NAMES)
def test_round_trip(name):
    callback = lambda *args: 0  # noqa: E731
    setter(name)(callback)
    assert getter(name)() is callback
    assert address(getattr(lib, f"mjcb_{name}")) == address(getattr(lib, f"mjcffi_py_mjcb_{name}"))
    other = lambda *args: 0  # noqa: E731
    setter(name)(other)
    assert getter(name)() is other
    native = ffi.cast(ffi.typeof(getattr(lib, f"mjcb_{name}")), 0x1234)   # never called
    setter(name)(native)
    assert getter(name)() is native and address(getattr(lib, f"mjcb_{name}")) == 0x1234
    setter(name)(None)
    assert getter(name)() is None and getattr(lib, f"mjcb_{name}") == ffi.NULL


def test_names_are_public_and_lazy():
    for name in NAMES:
        assert getattr(mjcffi, f"set_mjcb_{name}") is getattr(callbacks, f"set_mjcb_{name}")
        assert f"get_mjcb_{name}" in dir(mjcffi) and f"get_mjcb_{name}" in callbacks.__all__


def test_replacing_drops_the_reference():
    class Controller:
        def __call__(self, model, data):
            pass
    controller = Controller()
    alive = weakref.ref(controller)
    mjcffi.set_mjcb_control(controller)
    del controller
    gc.collect()
    assert alive() is not None                           # kept while installed
    mjcffi.set_mjcb_control(lambda model, data: None)
    gc.collect()
    assert alive() is None


def test_getter_knows_only_what_mjcffi_installed(mujoco):
    mine = lambda model, data: None  # noqa: E731
    mjcffi.set_mjcb_control(mine)
    theirs = lambda model, data: None  # noqa: E731
    mujoco.set_mjcb_control(theirs)                     # the same global, through them
    try:
        assert mjcffi.get_mjcb_control() is None
        assert lib.mjcb_control != ffi.NULL
    finally:
        mujoco.set_mjcb_control(None)
    mjcffi.set_mjcb_time(None)
    assert mujoco.get_mjcb_time() is None and mjcffi.get_mjcb_time() is None


def test_official_binding_steps_with_a_callback_set_here(mujoco):
    m = mujoco.MjModel.from_xml_string(PENDULUM)
    d = mujoco.MjData(m)
    seen = []

    def control(model, data):
        seen.append(type(data))
        data.ctrl[0] = 0.5
    mjcffi.set_mjcb_control(control)
    mujoco.mj_step(m, d)
    assert d.ctrl[0] == 0.5 and seen == [mjcffi.MjData]  # a borrowed mjcffi wrapper


# ------------------------------------------------------------------- bad input

@pytest.mark.parametrize("bad", [42, "callback", object(), b"\x00"])
def test_not_a_callback(bad):
    with pytest.raises(TypeError) as caught:
        mjcffi.set_mjcb_control(bad)
    assert str(caught.value) == "callback is not an Optional[Callable]"   # the official text
    assert caught.value.__notes__[0].startswith("mjcb_control takes a Python callable, a C "
                                                "function pointer")


def test_wrong_cffi_function_type_and_state_kept():
    kept = lambda model, data: None  # noqa: E731
    mjcffi.set_mjcb_control(kept)
    for wrong in (lib.mjcffi_py_mjcb_sensor, ffi.addressof(lib, "mj_version"),
                  ffi.new("int *"), ffi.NULL):
        with pytest.raises(TypeError, match=r"mjcb_control needs a C function pointer of type "
                                            r"void\(\*\)\(struct mjModel_ \*, struct mjData_ \*\)"):
            mjcffi.set_mjcb_control(wrong)
    assert mjcffi.get_mjcb_control() is kept            # a refused callback changes nothing
    with pytest.raises(TypeError, match="mjcb_time needs"):
        mjcffi.set_mjcb_time(ffi.addressof(lib, "mj_step"))
    with pytest.raises(TypeError, match="mjcb_act_gain needs"):   # mjfSensor is not mjfAct
        mjcffi.set_mjcb_act_gain(lib.mjcffi_py_mjcb_sensor)


def test_wrong_ctypes_arity():
    prototype = ctypes.CFUNCTYPE(None, ctypes.c_void_p)
    thunk = prototype(lambda model: None)
    with pytest.raises(TypeError, match="mjcb_control needs a C function of 2 arguments"):
        mjcffi.set_mjcb_control(thunk)
    assert lib.mjcb_control == ffi.NULL


def test_cffi_pointer_of_another_module_with_another_signature(native):
    _, native_ffi, native_lib = native
    with pytest.raises(TypeError, match="mjcb_sensor needs"):
        mjcffi.set_mjcb_sensor(native_ffi.addressof(native_lib, "half_control"))
    mjcffi.set_mjcb_passive(native_ffi.addressof(native_lib, "nothing"))
    assert lib.mjcb_passive != ffi.NULL
