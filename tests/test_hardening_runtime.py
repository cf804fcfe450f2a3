"""Issue 11, the runtime: callbacks, rollout, Batch and the mujoco-py layer.

Exceptions from callbacks reach exactly one caller, once, whichever thread ran
the callback; re-entering MuJoCo from a callback works or raises; a pool never
steps one MjData on two threads; the exceptions stay in the documented set
(TypeError, ValueError, IndexError, KeyError, FatalError); Batch.expand never
lets a simulation index out of range.  Anything that could crash runs in a
subprocess.
"""

import importlib.util
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest
from cffi import FFI

import mjcffi
from mjcffi import batch, ffi, lib, rollout
from mjcffi._support import callbacks, contract
from codegen.headers import include_dir as mujoco_include_dir
from mjcffi.sim import MjSim, MjSimPool, MjSimState, load_model_from_xml

DOCUMENTED = (TypeError, ValueError, IndexError, KeyError, mjcffi.FatalError)

PENDULUM = """
<mujoco>
  <worldbody>
    <body name="pole" pos="0 0 1">
      <joint name="hinge" type="hinge" axis="0 1 0" damping=".1"/>
      <geom name="rod" type="capsule" fromto="0 0 0 0 0 -.5" size=".05"/>
    </body>
  </worldbody>
  <actuator><motor joint="hinge"/></actuator>
</mujoco>
"""

# nq 8 != nv 7 (a free joint and a hinge), na 2 (two actuators with activation)
FREE_AND_FILTER = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 .1"/>
    <body name="ball" pos="0 0 .5"><freejoint name="free"/><geom size=".1"/></body>
    <body name="arm" pos="1 0 1">
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -.4" size=".04"/>
    </body>
  </worldbody>
  <equality><connect body1="arm" body2="ball" anchor="0 0 0"/></equality>
  <actuator>
    <general joint="hinge" dyntype="filter" dynprm=".1"/>
    <general joint="hinge" dyntype="integrator"/>
  </actuator>
</mujoco>
"""

BALL_ON_PLANE = """
<mujoco>
  <worldbody>
    <geom type="plane" size="1 1 .1"/>
    <body><freejoint/><geom size=".1"/></body>
  </worldbody>
</mujoco>
"""


@pytest.fixture(autouse=True)
def clean_callbacks():
    """No callback installed before or after a test, and nothing left pending."""
    saved = {name: getattr(lib, f"mjcb_{name}") for name in ("control", "passive", "time")}
    yield
    for name in saved:
        getattr(mjcffi, f"set_mjcb_{name}")(None)
        setattr(lib, f"mjcb_{name}", saved[name])
    mjcffi.set_mju_user_warning(None)
    leftover = contract._take()
    assert leftover is None and not contract._errors, f"left pending: {leftover!r}"


def run_python(code, timeout=120):
    """Run `code` in a fresh interpreter; (returncode, stdout + stderr)."""
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=timeout)
    return done.returncode, done.stdout + done.stderr


def rollout_inputs(m, nbatch, nstep):
    d = mjcffi.MjData(m)
    state = np.empty(mjcffi.mj_stateSize(m, mjcffi.mjtState.mjSTATE_FULLPHYSICS))
    mjcffi.mj_getState(m, d, state, mjcffi.mjtState.mjSTATE_FULLPHYSICS)
    return np.tile(state, (nbatch, 1)), np.zeros((nbatch, nstep, m.nu))


# ------------------------------------------- item 4: one caller, once, any thread

@pytest.mark.parametrize("persistent", [False, True])
def test_item4_no_stale_callback_exception_after_a_threaded_rollout(persistent):
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    datas = [mjcffi.MjData(m), mjcffi.MjData(m)]
    state, control = rollout_inputs(m, 16, 5)
    threads = set()

    def broken(model, data):
        threads.add(threading.current_thread().__class__.__name__)
        time.sleep(0.001)                      # let the other thread take the GIL too
        raise ValueError("broken controller")
    mjcffi.set_mjcb_control(broken)
    for _ in range(3):
        with pytest.raises(ValueError, match="broken controller"):
            rollout.rollout(m, datas, state, control, chunk_size=1,
                            persistent_pool=persistent)
    assert "_DummyThread" in threads and "_MainThread" in threads   # both threads raised
    mjcffi.set_mjcb_control(None)
    assert not contract.pending and not contract._errors
    d = mjcffi.MjData(m)
    mjcffi.mj_step(m, d)             # the old exception is not raised here
    mjcffi.mj_step(m, d, 10)
    if persistent:
        rollout.shutdown_persistent_pool()


def test_item4_exception_only_on_a_pool_thread_reaches_the_rollout():
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    datas = [mjcffi.MjData(m), mjcffi.MjData(m)]
    state, control = rollout_inputs(m, 16, 5)

    def broken_on_workers(model, data):
        time.sleep(0.001)                      # let the other thread take the GIL too
        if not isinstance(threading.current_thread(), threading._MainThread):
            raise KeyError("pool thread")
    mjcffi.set_mjcb_control(broken_on_workers)
    with rollout.Rollout(nthread=2) as pool:
        with pytest.raises(KeyError, match="pool thread") as caught:
            pool.rollout(m, datas, state, control, chunk_size=1)
        assert "mjcb_control" in caught.value.__notes__[0]
        mjcffi.set_mjcb_control(None)
        pool.rollout(m, datas, state, control, chunk_size=1)      # nothing left over
    mjcffi.mj_step(m, datas[0])
    assert not contract.pending


def test_item4_a_concurrent_call_on_another_thread_does_not_take_it():
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    datas = [mjcffi.MjData(m), mjcffi.MjData(m)]
    mine = mjcffi.MjData(m)
    state, control = rollout_inputs(m, 64, 20)

    def broken_for_the_rollout(model, data):
        if data is datas[0]:                   # the calling thread's: let the pool's run
            time.sleep(0.0005)
        elif data is datas[1]:                 # the pool thread's
            raise ZeroDivisionError("rollout only")
    mjcffi.set_mjcb_control(broken_for_the_rollout)
    stop, outcome = threading.Event(), []

    def other_thread():
        try:
            while not stop.is_set():
                mjcffi.mj_step(m, mine, 5)
            outcome.append("clean")
        except BaseException as exc:        # noqa: BLE001  (the test reports it)
            outcome.append(exc)
    worker = threading.Thread(target=other_thread)
    worker.start()
    try:
        for _ in range(5):
            with pytest.raises(ZeroDivisionError, match="rollout only"):
                rollout.rollout(m, datas, state, control, chunk_size=1)
    finally:
        stop.set()
        worker.join()
    assert outcome == ["clean"]


@pytest.fixture(scope="module")
def native(tmp_path_factory):
    """A C mjcb_passive that runs the installed mjcb_control and mjcb_time on a thread
    of its own (Python never saw it), as an mjThreadPool's workers do."""
    builder = FFI()
    builder.cdef("void passive_on_a_thread(const void* m, void* d);"
                 "void set_targets(void* control, void* time);")
    builder.set_source("mjcffi_test_pool_thread", """
        #include <pthread.h>
        #include <mujoco/mujoco.h>
        static mjfGeneric control;
        static mjfTime timer;
        void set_targets(void* c, void* t) { control = (mjfGeneric)c; timer = (mjfTime)t; }
        typedef struct { const mjModel* m; mjData* d; } job;
        static void* run(void* arg) {
          job* j = arg;
          if (control) control(j->m, j->d);
          if (timer) timer();
          return NULL;
        }
        void passive_on_a_thread(const void* m, void* d) {
          job j = {(const mjModel*)m, (mjData*)d};
          pthread_t thread;
          if (pthread_create(&thread, NULL, run, &j) == 0) pthread_join(thread, NULL);
        }
    """, include_dirs=[str(mujoco_include_dir())], libraries=["pthread"])
    path = builder.compile(tmpdir=str(tmp_path_factory.mktemp("pool_thread")))
    spec = importlib.util.spec_from_file_location("mjcffi_test_pool_thread", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    # the trampolines of mjcffi's Python mjcb_control and mjcb_time
    module.lib.set_targets(ffi.cast("void *", lib.mjcffi_py_mjcb_control),
                           ffi.cast("void *", lib.mjcffi_py_mjcb_time))
    return module


def test_item4_exception_on_a_thread_pool_of_the_data_reaches_that_call(native):
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    d, other = mjcffi.MjData(m), mjcffi.MjData(m)
    mjcffi.mju_threadpool(d, 2)            # d has a pool: its callbacks may run there
    mjcffi.set_mjcb_passive(ffi.cast("mjfGeneric",
                                     native.ffi.addressof(native.lib, "passive_on_a_thread")))
    calls = []

    def broken_off_thread(model, data):
        calls.append(threading.current_thread().__class__.__name__)
        if calls[-1] == "_DummyThread":
            raise ValueError(f"on the pool of {data._address}")
    mjcffi.set_mjcb_control(broken_off_thread)
    with pytest.raises(ValueError, match=f"on the pool of {d._address}"):
        mjcffi.mj_step(m, d)
    assert "_DummyThread" in calls and "_MainThread" in calls
    assert not contract.pending
    mjcffi.set_mjcb_control(None)
    mjcffi.mj_step(m, other)                  # another data's call: nothing for it
    mjcffi.mj_step(m, d)

    # mjcb_time has no mjData: it goes to the call of the only data with a pool
    mjcffi.set_mjcb_time(lambda: "not a number")
    with pytest.raises(TypeError, match="mjcb_time callback did not return a number"):
        mjcffi.mj_forward(m, d)
    mjcffi.set_mjcb_time(None)
    assert not contract.pending


def test_item4_both_threads_raise_in_one_call_the_first_wins_and_nothing_is_left(native):
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    d = mjcffi.MjData(m)
    mjcffi.mju_threadpool(d, 2)
    mjcffi.set_mjcb_passive(ffi.cast("mjfGeneric",
                                     native.ffi.addressof(native.lib, "passive_on_a_thread")))
    order = iter(range(100))

    def broken(model, data):
        raise RuntimeError(f"failure {next(order)}")
    mjcffi.set_mjcb_control(broken)
    with pytest.raises(RuntimeError, match="failure 0"):   # the caller's own ran first
        mjcffi.mj_step(m, d)
    assert not contract.pending and not contract._errors
    mjcffi.set_mjcb_control(None)
    mjcffi.mj_step(m, d)


def test_item4_batch_takes_the_warning_handlers_exception_from_its_threads():
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    b = batch.Batch(m, 32, 2)
    seen = []

    def handler(message):
        seen.append(threading.current_thread().__class__.__name__)
        time.sleep(0.001)                      # let the batch's other thread run too
        raise ValueError(message)
    mjcffi.set_mju_user_warning(handler)
    b.ctrl = np.nan                            # a bad control: MuJoCo warns in every one
    with pytest.raises(ValueError, match="CTRL"):
        b.step()
    assert "_DummyThread" in seen              # raised on the batch's own threads too
    assert not contract.pending
    mjcffi.set_mju_user_warning(None)
    mjcffi.mj_step(m, mjcffi.MjData(m))        # a later call gets nothing
    b.ctrl = 0.0
    b.step()


def test_item4_simpool_steps_every_sim_then_raises_the_first_error():
    model = load_model_from_xml(PENDULUM)
    sims = [MjSim(model) for _ in range(4)]
    bad = {sims[1].data._address, sims[2].data._address}

    def broken(m, d):
        if d._address in bad:
            raise ValueError(f"sim {d._address}")
    mjcffi.set_mjcb_control(broken)
    pool = MjSimPool(sims, nsubsteps=3, nthreads=2)
    with pytest.raises(ValueError, match=f"sim {sims[1].data._address}"):
        pool.step()
    assert [s.data.time for s in sims] == [3 * model.opt.timestep] * 4   # all stepped
    assert not contract.pending
    pool.close()


# -------------------------------------------------- item 5: re-entry raises

def test_item5_reentrant_step_raises_recursion_error_at_any_depth():
    code = """
        import sys, mjcffi
        from mjcffi._support import callbacks, contract
        m = mjcffi.MjModel.from_xml_string(%r)
        d = mjcffi.MjData(m)
        def control(model, data):
            mjcffi.mj_step(model, data)
        def call_from(depth):              # start the re-entry from varied depths
            if depth:
                return call_from(depth - 1)
            mjcffi.mj_step(m, d)
        mjcffi.set_mjcb_control(control)
        for depth in range(12):
            try:
                call_from(depth)
            except RecursionError as exc:   # at the first re-entry, not the recursion limit
                assert "mj_step: this mjData is in a MuJoCo call on this thread" in str(exc)
            else:
                raise SystemExit(f"no exception from depth {depth}")
            assert not contract.pending and contract.local.lost is None, depth
        mjcffi.set_mjcb_control(None)
        mjcffi.mj_resetData(m, d)
        mjcffi.mj_step(m, d, 10)
        print("ok")
    """ % PENDULUM
    returncode, output = run_python(code)
    assert returncode == 0 and output.strip().endswith("ok"), output


def test_item5_bounded_reentry_works():
    """Re-entry with other mjData works, 20 deep; with the same one, calls that do not
    restart its computation work too."""
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    chain = [mjcffi.MjData(m) for _ in range(21)]
    index = {data._address: k for k, data in enumerate(chain)}
    depth, jacs = [], []

    def control(model, data):
        k = index[data._address]
        depth.append(k)
        mjcffi.mj_kinematics(model, data)          # the same data: no restart, allowed
        jac = np.zeros((3, model.nv))
        mjcffi.mj_jacBody(model, data, None, jac, 1)    # rotational: the hinge axis
        jacs.append(jac)
        if k < 20:                                 # a callback stepping another data
            mjcffi.mj_step(model, chain[k + 1])
    mjcffi.set_mjcb_control(control)
    try:
        mjcffi.mj_step(m, chain[0])
    finally:
        mjcffi.set_mjcb_control(None)
    assert depth == list(range(21))
    assert all(data.time == pytest.approx(m.opt.timestep) for data in chain)
    assert np.abs(jacs[0]).sum() > 0


def test_item5_contactfilter_stepping_its_data_raises_recursion_error():
    m = mjcffi.MjModel.from_xml_string(BALL_ON_PLANE)
    d = mjcffi.MjData(m)
    d.qpos[2] = 0.05                               # touching: the filter runs

    def contactfilter(model, data, geom1, geom2):
        mjcffi.mj_step(model, data)                # would reset the contacts being made
        return 0
    mjcffi.set_mjcb_contactfilter(contactfilter)
    try:
        with pytest.raises(RecursionError, match="mj_step: this mjData is in a MuJoCo call"):
            mjcffi.mj_step(m, d)
    finally:
        mjcffi.set_mjcb_contactfilter(None)
    mjcffi.mj_resetData(m, d)
    mjcffi.mj_step(m, d, 10)
    assert d.time == pytest.approx(10 * m.opt.timestep)


def test_item5_one_data_in_two_threads_raises_value_error():
    m = mjcffi.MjModel.from_xml_string(BALL_ON_PLANE)
    d = mjcffi.MjData(m)
    errors, barrier = [], threading.Barrier(4)

    def run():
        barrier.wait()
        try:
            for _ in range(3000):
                mjcffi.mj_step(m, d, 3)
                mjcffi.mj_forward(m, d)
        except ValueError as exc:
            errors.append(exc)
    threads = [threading.Thread(target=run) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert errors, "four threads stepping one data never met"
    assert all("in a MuJoCo call on another thread" in str(e) for e in errors)
    assert np.isfinite(d.qpos).all()
    mjcffi.mj_step(m, d)                           # free again once the others stopped


# --------------------------------------------- item 6: one MjData, one thread

def test_item6_simpool_refuses_one_sim_or_one_data_twice():
    code = """
        import mjcffi
        from mjcffi.sim import MjSim, MjSimPool, load_model_from_xml
        model = load_model_from_xml(%r)
        sim = MjSim(model)
        for sims, what in (([sim, sim], "is sims[0]"),
                           ([sim, MjSim(model, data=sim.data)], "shares its MjData")):
            try:
                MjSimPool(sims, nsubsteps=50).step()
            except ValueError as exc:
                assert what in str(exc), exc
            else:
                raise SystemExit("accepted")
        pool = MjSimPool([sim, MjSim(model)], nsubsteps=50)
        pool.sims.append(sim)                  # the list is public: checked at each call
        try:
            pool.step()
        except ValueError as exc:
            assert "sims[2] is sims[0]" in str(exc)
        else:
            raise SystemExit("accepted after append")
        pool.close()
        print("ok")
    """ % PENDULUM
    returncode, output = run_python(code)
    assert returncode == 0 and output.strip().endswith("ok"), output


def test_item6_rollout_and_simpool_refuse_a_shared_data_alike():
    m = mjcffi.MjModel.from_xml_string(PENDULUM)
    d = mjcffi.MjData(m)
    state, control = rollout_inputs(m, 4, 2)
    with pytest.raises(ValueError, match="each thread needs its own MjData"):
        rollout.rollout(m, [d, d], state, control)
    model = load_model_from_xml(PENDULUM)
    with pytest.raises(ValueError, match="MjData of its own"):
        MjSimPool([MjSim(model), MjSim(model)] * 2)


# ------------------------------------------- exception types: the documented set

def test_item_types_rollout_thread_counts_are_value_errors():
    for nthread in (2**31, 10**9, rollout._MAX_THREADS + 1):
        with pytest.raises(ValueError, match=f"nthread must be at most {rollout._MAX_THREADS}"):
            rollout.Rollout(nthread=nthread)
    with pytest.raises(TypeError):
        rollout.Rollout(nthread=2.0)
    with pytest.raises(ValueError, match="non-negative"):
        rollout.Rollout(nthread=-1)


def test_item_types_batch_counts_past_a_c_int_are_value_errors():
    b = batch.Batch(mjcffi.MjModel.from_xml_string(PENDULUM), 2, 1)
    for kwargs in ({"nstep": 2**31}, {"stage": 2**31}, {"nstep": -2**31 - 1}):
        with pytest.raises(ValueError, match="must fit a C int"):
            b.step(**kwargs)
    with pytest.raises(TypeError, match="nstep must be an int"):
        b.step(nstep=1.5)
    for call in (b.forward, b.reset):
        with pytest.raises(ValueError, match="stage must fit a C int"):
            call(stage=2**31)
    with pytest.raises(ValueError, match="geomgroup must be in"):
        b.ray([0, 0, 2], [0, 0, -1], geomgroup=[2**31] + [1] * 5)
    b.step()
    assert b.time.tolist() == [m * 1 for m in [b.model.opt.timestep] * 2]


def test_item_types_closed_simpool_is_a_value_error():
    model = load_model_from_xml(PENDULUM)
    pool = MjSimPool([MjSim(model), MjSim(model)], nthreads=2)
    pool.step()
    pool.close()
    for call in (pool.step, pool.forward, pool.reset):
        with pytest.raises(ValueError, match="MjSimPool is closed"):
            call()
    pool.close()                              # twice is fine


def test_item_types_sim_arguments():
    model = load_model_from_xml(PENDULUM)
    sim = MjSim(model)
    with pytest.raises(TypeError, match="sim must be an MjSim"):
        MjSimState.from_flattened(sim.get_state().flatten(), 5)
    with pytest.raises(TypeError, match="file must be a file opened for writing"):
        sim.save(5)
    for bad, error in ((2**31, ValueError), (0, ValueError), (1.5, TypeError), (None, TypeError)):
        with pytest.raises(error, match="nsubsteps"):
            MjSim(model, nsubsteps=bad)
        with pytest.raises(error, match="nsubsteps"):
            MjSimPool([sim], nsubsteps=bad)
    with pytest.raises(ValueError, match="nsims must be at most"):
        MjSimPool([sim]).step(nsims=2)
    with pytest.raises(ValueError, match="nsims must be from 0"):
        MjSimPool([sim]).step(nsims=-1)         # not sims[:-1]


_BAD = [2**31, 2**64 + 5, -1, -2**31 - 1, 1.5, float("nan"), None, "x", object(), [],
        np.zeros((2, 2)), True]


def _sweep(label, function, names, base):
    """Call `function(**base)` with each of `names` replaced by each bad value; return
    what raised outside the documented set."""
    leaks = []
    for name in names:
        for bad in _BAD:
            try:
                function(**{**base, name: bad})
            except DOCUMENTED:
                pass
            except batch.SimulationError:
                pass                           # the official's type for a failed simulation
            except RuntimeError as exc:
                if "thread pool shutdown" not in str(exc):
                    leaks.append((label, name, repr(bad)[:20], type(exc).__name__))
            except BaseException as exc:       # noqa: BLE001  (what the test looks for)
                leaks.append((label, name, repr(bad)[:20], type(exc).__name__))
    return leaks


def test_item_types_sweep_of_the_public_entry_points():
    m = mjcffi.MjModel.from_xml_string(FREE_AND_FILTER)
    d, d2 = mjcffi.MjData(m), mjcffi.MjData(m)
    state, control = rollout_inputs(m, 2, 3)
    leaks = _sweep("rollout", rollout.rollout,
                   ["model", "data", "initial_state", "control", "control_spec", "nstep",
                    "initial_warmstart", "state", "sensordata", "chunk_size"],
                   dict(model=m, data=[d, d2], initial_state=state, control=control))

    def pool(nthread, **kwargs):
        with rollout.Rollout(nthread=nthread) as r:
            return r.rollout(**kwargs)
    leaks += _sweep("Rollout", pool, ["nthread"], dict(nthread=2, model=m, data=[d, d2],
                                                       initial_state=state, control=control))
    b = batch.Batch(m, 3, 2)
    leaks += _sweep("Batch", batch.Batch, ["model", "nsim", "nthread"],
                    dict(model=m, nsim=2, nthread=1))
    leaks += _sweep("Batch.step", b.step, ["ids", "nstep", "stage"], {})
    leaks += _sweep("Batch.forward", b.forward, ["ids", "stage"], {})
    leaks += _sweep("Batch.reset", b.reset, ["ids", "keyframe", "stage"], {})
    leaks += _sweep("Batch.rollout", b.rollout, ["nstep", "control", "control_spec", "record",
                                                 "ids", "out"], dict(nstep=2))
    leaks += _sweep("Batch.jac", b.jac, ["body", "point", "ids"], dict(body=1, point=[0, 0, 0]))
    leaks += _sweep("Batch.ray", b.ray, ["pnt", "vec", "geomgroup", "bodyexclude", "ids"],
                    dict(pnt=[0, 0, 2], vec=[0, 0, -1]))
    leaks += _sweep("Batch.expand", b.expand, ["name"], {})
    leaks += _sweep("Batch.get_data", b.get_data, ["sim", "data"], dict(sim=0))
    leaks += _sweep("Batch.set_models", b.set_models, ["models"], {})
    sim_model = load_model_from_xml(FREE_AND_FILTER)
    sim = MjSim(sim_model)
    leaks += _sweep("MjSim", MjSim, ["model", "data", "nsubsteps"], dict(model=sim_model))
    leaks += _sweep("MjSim.set_state", sim.set_state, ["value"], {})
    leaks += _sweep("from_flattened", MjSimState.from_flattened, ["array", "sim"],
                    dict(array=sim.get_state().flatten(), sim=sim))
    leaks += _sweep("MjSimPool", MjSimPool, ["sims", "nsubsteps", "nthreads"],
                    dict(sims=[MjSim(sim_model), MjSim(sim_model)]))
    leaks += _sweep("MjSimPool.step", MjSimPool([sim]).step, ["nsims"], {})
    leaks += _sweep("get_joint_qpos", sim.data.get_joint_qpos, ["name"], {})
    leaks += _sweep("set_joint_qpos", sim.data.set_joint_qpos, ["value"], dict(name="free"))
    assert leaks == []


# --------------------------------------------------- Batch.expand and index fields

@pytest.mark.parametrize("name", ["body_parentid", "geom_bodyid", "jnt_qposadr", "jnt_dofadr",
                                  "jnt_type", "geom_type", "sensor_adr", "sensor_dim",
                                  "actuator_trnid", "actuator_actadr", "eq_obj1id", "M_colind",
                                  "body_mocapid", "pair_geom1", "tendon_adr", "wrap_objid"])
def test_item_expand_refuses_index_fields(name):
    assert name in batch.INDEX_FIELDS and name not in batch.MODEL_FIELDS
    b = batch.Batch(mjcffi.MjModel.from_xml_string(FREE_AND_FILTER), 2, 1)
    with pytest.raises(ValueError, match="ids, addresses, counts or types") as caught:
        b.expand(name)
    assert "index out of range" in caught.value.__notes__[0]
    with pytest.raises(ValueError, match="cannot differ between simulations"):
        b._b.expand(name)                      # the lower layer refuses too
    assert b.expanded(name) is None


def test_item_expand_index_fields_come_from_the_metadata():
    from mjcffi._generated.structinfo import STRUCTS
    docs = {field.name: field.doc for field in STRUCTS["mjModel"]}
    m = mjcffi.MjModel.from_xml_string(FREE_AND_FILTER)
    for name in batch.MODEL_FIELDS:
        value = getattr(m, name, None)
        if name.startswith("opt.") or value is None or value.dtype.kind not in "iub":
            continue
        # what stays expandable is a flag, a group, a bitmask or a priority, or is checked
        doc = docs[name]
        assert name in batch._batch.CHECKED_FIELDS or not any(
            word in doc for word in (" id", "address", "number of", "index", "(mjt")), name
    # and every integer field that names an id or an address of another array is refused
    for name, doc in docs.items():
        value = getattr(m, name, None)
        if isinstance(value, np.ndarray) and value.dtype.kind in "iu" and \
                (" id" in doc or "address" in doc) and name in batch._batch._EXPANDABLE:
            assert name in batch.INDEX_FIELDS, name


def test_item_expand_named_views_read_index_fields_and_refuse_writes():
    m = mjcffi.MjModel.from_xml_string(FREE_AND_FILTER)
    b = batch.Batch(m, 3, 1)
    assert b.joint("hinge").qposadr.tolist() == [[m.joint("hinge").qposadr[0]]] * 3
    with pytest.raises(ValueError, match="cannot differ between simulations"):
        b.joint("hinge").qposadr = 0
    with pytest.raises(ValueError, match="cannot differ between simulations"):
        b.body("arm").parentid = 0


def test_item_expand_checked_fields_are_checked_before_each_call():
    m = mjcffi.MjModel.from_xml_string(FREE_AND_FILTER)
    b = batch.Batch(m, 3, 2)
    condim = b.expand("geom_condim")
    condim[1, 0] = 1                               # frictionless floor in simulation 1
    b.step()
    condim[2, 0] = 5
    for call in (b.step, b.forward, b.reset, lambda: b.rollout(2), lambda: b.get_model(0),
                 lambda: b.jac(1, [0, 0, 0]), b.set_const):
        with pytest.raises(ValueError, match=r"geom_condim\[0\] of simulation 2 is 5"):
            call()
    condim[2, 0] = 3
    eq_type = b.expand("eq_type")
    eq_type[1] = mjcffi.mjtEq.mjEQ_WELD              # a connect may become a weld
    b.step()
    eq_type[2] = mjcffi.mjtEq.mjEQ_JOINT             # but its bodies are not joints
    with pytest.raises(ValueError, match=r"eq_type\[0\] of simulation 2 is 2"):
        b.step()
    eq_type[2] = 99                                # an unknown type MuJoCo refuses itself
    with pytest.raises(batch.SimulationError, match="1 of 3 simulations"):
        b.step()
    eq_type[2] = mjcffi.mjtEq.mjEQ_CONNECT
    b.step()
    assert not b.status.any()


# ----------------------------------------------------------------- item: layering

def test_item_imports_callbacks_load_the_wrapper_classes_without_importing_them():
    # a Python callback installed before any mjcffi model exists, then called on the
    # official binding's structs: it receives (borrowed) mjcffi wrappers
    code = """
        import sys, mujoco, mjcffi
        assert "mjcffi.model" not in sys.modules and "mjcffi.data" not in sys.modules
        seen = []
        mjcffi.set_mjcb_control(lambda m, d: seen.append((type(m).__name__, type(d).__name__)))
        m = mujoco.MjModel.from_xml_string(%r)
        mujoco.mj_step(m, mujoco.MjData(m))
        mjcffi.set_mjcb_control(None)
        assert seen and set(seen) == {("MjModel", "MjData")}, seen
        from mjcffi import model, data
        from mjcffi._support import callbacks, contract
        assert callbacks._CLASSES == {"mjModel": model.MjModel, "mjData": data.MjData}
        print("ok")
    """ % PENDULUM
    returncode, output = run_python(code)
    assert returncode == 0 and output.strip().endswith("ok"), output


# ------------------------------- mjr_makeContext without OpenGL, more than once

def test_mjr_context_without_opengl_raises_every_time():
    code = """
        import mjcffi
        m = mjcffi.MjModel.from_xml_string("<mujoco/>")
        for attempt in range(3):        # the second used to abort in the C++ runtime
            try:
                mjcffi.MjrContext(m, 100)
            except mjcffi.FatalError as exc:
                assert "OpenGL platform library has not been loaded" in str(exc), exc
            else:
                raise SystemExit("no FatalError")
        print("ok")
    """
    returncode, output = run_python(code)
    assert returncode == 0 and output.strip().endswith("ok"), output
