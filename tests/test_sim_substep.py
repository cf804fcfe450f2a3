"""MjSim's substep_callback: C code compiled at run time, a C address, a Python callable.

The callback runs before each mj_step of a step(), as in mujoco-py, so a controller
that reads only the state (time, qpos, qvel) gives, as a substep callback, exactly
the trajectory it gives as mjcb_control (which MuJoCo calls inside each mj_step,
before the actuation): both are checked bit for bit on gymnasium's models.
"""

import math
import os
import subprocess
import sys

import numpy as np
import pytest

import mjcffi
from mjcffi import ffi
from mjcffi.sim import MjSim, load_model_from_path, load_model_from_xml
from mjcffi.sim import _substep
from mjcffi.sim._substep import SubstepCompileError

from .conftest import gymnasium_assets

CONTROL = """
#include <math.h>
void fun(const mjModel* m, mjData* d) {
  for (int i = 0; i < m->nu; i++) {
    d->ctrl[i] = 0.3 * sin(3.0 * d->time + i) - 0.05 * d->qvel[i % m->nv];
  }
}
"""

COUNT = """
void fun(const mjModel* m, mjData* d) {
  substeps += 1;
  last_time = d->time;
}
"""

PENDULUMS = """
<mujoco>
  <size nuserdata="{nuserdata}"/>
  <worldbody>
    <body><joint name="j1" type="hinge" axis="1 0 0"/><geom type="capsule" size=".05"
          fromto="0 0 0 0 0 -.5"/></body>
  </worldbody>
  <actuator><motor joint="j1"/></actuator>
</mujoco>
"""


def _control(model, data):
    """CONTROL in Python: the same operations in the same order, libm's sin."""
    qvel, ctrl = data.qvel, data.ctrl
    for i in range(model.nu):
        ctrl[i] = 0.3 * math.sin(3.0 * data.time + i) - 0.05 * qvel[i % model.nv]


def _model(name, euler):
    model = load_model_from_path(next(p for p in gymnasium_assets() if p.name == name))
    if euler:      # RK4 calls mjcb_control at each of its stages, a substep callback once
        model.opt.integrator = mjcffi.mjtIntegrator.mjINT_EULER
    return model


def _trajectory(sim, steps):
    rows = []
    for _ in range(steps):
        sim.step()
        d = sim.data
        act = [] if d.act is None else d.act      # SimData: None when na == 0
        rows.append(np.concatenate([[d.time], d.qpos, d.qvel, act, d.ctrl]))
    return np.array(rows)


def _with_mjcb_control(model, control, nsubsteps, steps):
    sim = MjSim(model, nsubsteps=nsubsteps)
    mjcffi.set_mjcb_control(control)
    try:
        return _trajectory(sim, steps)
    finally:
        mjcffi.set_mjcb_control(None)


def _bits(array):
    return np.ascontiguousarray(array, dtype=np.float64).view(np.uint64)


@pytest.mark.parametrize("name, euler", [("half_cheetah.xml", False), ("humanoid.xml", True)])
def test_c_and_python_substeps_match_mjcb_control_bit_for_bit(name, euler):
    model = _model(name, euler)
    address = _substep.build_callback_fn(CONTROL)
    reference = _with_mjcb_control(model, ffi.cast("mjfGeneric", address), 5, 40)
    in_c = _trajectory(MjSim(model, nsubsteps=5, substep_callback=CONTROL), 40)
    in_python = _trajectory(MjSim(model, nsubsteps=5, substep_callback=_control), 40)
    python_control = _with_mjcb_control(model, _control, 5, 40)
    assert np.abs(reference[-1, 1:1 + model.nq] - reference[0, 1:1 + model.nq]).max() > 1e-3
    np.testing.assert_array_equal(_bits(in_c), _bits(reference))
    np.testing.assert_array_equal(_bits(in_python), _bits(reference))
    np.testing.assert_array_equal(_bits(python_control), _bits(reference))


def test_plain_steps_are_unchanged_without_a_callback():
    model = _model("half_cheetah.xml", False)
    with_none = MjSim(model, nsubsteps=3, substep_callback=None)
    plain = MjSim(model, nsubsteps=3)
    for sim in (with_none, plain):
        sim.data.ctrl[:] = 0.2
    np.testing.assert_array_equal(_trajectory(with_none, 10), _trajectory(plain, 10))
    assert with_none.substep_callback_ptr == 0


def test_the_c_callback_runs_once_per_substep_before_mj_step():
    model = load_model_from_xml(PENDULUMS.format(nuserdata=2))
    sim = MjSim(model, nsubsteps=7, substep_callback=COUNT,
                userdata_names=["substeps", "last_time"])
    assert model.userdata_names == ["substeps", "last_time"]
    assert sim.data.userdata.tolist() == [0, 0]
    sim.step()
    step = model.opt.timestep
    assert sim.data.userdata[0] == 7
    assert sim.data.userdata[1] == pytest.approx(6 * step)     # the last substep's start
    assert sim.data.time == pytest.approx(7 * step)
    sim.step()
    assert sim.data.userdata[0] == 14
    sim.substep_callback()                        # once, and no step
    assert sim.data.userdata[0] == 15 and sim.data.time == pytest.approx(14 * step)


def test_the_python_callback_runs_in_the_same_order():
    model = load_model_from_xml(PENDULUMS.format(nuserdata=0))
    seen = []
    sim = MjSim(model, nsubsteps=3,
                substep_callback=lambda m, d: seen.append((m is model, float(d.time))))
    sim.step()
    step = model.opt.timestep
    assert [s[0] for s in seen] == [True] * 3
    assert [s[1] for s in seen] == pytest.approx([0, step, 2 * step])
    sim.substep_callback()
    assert len(seen) == 4 and sim.data.time == pytest.approx(3 * step)
    assert sim.substep_callback_ptr == 0


def test_a_python_callback_error_stops_the_step():
    model = load_model_from_xml(PENDULUMS.format(nuserdata=0))
    calls = []

    def failing(m, d):
        calls.append(d.time)
        if len(calls) == 2:
            raise KeyError("from the callback")

    sim = MjSim(model, nsubsteps=5, substep_callback=failing)
    with pytest.raises(KeyError, match="from the callback"):
        sim.step()
    assert len(calls) == 2 and sim.data.time == pytest.approx(model.opt.timestep)


def test_the_address_is_reusable_by_another_sim():
    model = load_model_from_xml(PENDULUMS.format(nuserdata=2))
    sim = MjSim(model, substep_callback=COUNT, userdata_names=["substeps", "last_time"])
    other = MjSim(model, nsubsteps=4, substep_callback=sim.substep_callback_ptr)
    assert other.substep_callback_ptr == sim.substep_callback_ptr > 0
    other.step()
    assert other.data.userdata[0] == 4 and sim.data.userdata[0] == 0
    pointer = MjSim(model, substep_callback=ffi.cast("mjfGeneric", sim.substep_callback_ptr))
    pointer.step()
    assert pointer.data.userdata[0] == 1
    other.set_substep_callback(None)
    other.step()
    assert other.data.userdata[0] == 4 and other.substep_callback_ptr == 0


def test_the_same_code_is_compiled_once(tmp_path, monkeypatch):
    monkeypatch.setenv("MJCFFI_CACHE_DIR", str(tmp_path))
    code = COUNT.replace("+= 1", "+= 3")        # code no other test compiled
    first = _substep.build_callback_fn(code, ["substeps", "last_time"])
    built = list((tmp_path / "substep").iterdir())
    assert len(built) == 1 and built[0].name.startswith("_mjcffi_substep_")
    stamp = built[0].stat().st_mtime_ns
    _substep._loaded.clear()                     # as a new process: only the file is left

    def no_compiler(*args, **kwargs):
        raise AssertionError("compiled again")

    monkeypatch.setattr(_substep.subprocess, "run", no_compiler)
    assert _substep.build_callback_fn(code, ["substeps", "last_time"]) == first
    sim = MjSim(load_model_from_xml(PENDULUMS.format(nuserdata=2)), nsubsteps=2,
                substep_callback=code, userdata_names=["substeps", "last_time"])
    sim.step()
    assert sim.data.userdata[0] == 6
    assert built[0].stat().st_mtime_ns == stamp
    with pytest.raises(AssertionError, match="compiled again"):     # other code would
        _substep.build_callback_fn(code + "\n// changed\n", ["substeps", "last_time"])


def test_a_new_process_reuses_the_cached_module(tmp_path):
    code = ("from mjcffi.sim import _substep\nimport sys\n"
            "print(_substep.build_callback_fn(sys.argv[1]) > 0)\n")
    env = dict(os.environ, MJCFFI_CACHE_DIR=str(tmp_path))
    source = CONTROL.replace("0.3 *", "0.25 *")
    for _ in range(2):
        run = subprocess.run([sys.executable, "-c", code, source], env=env,
                             capture_output=True, text=True, timeout=300)
        assert run.returncode == 0 and run.stdout.strip() == "True", run.stderr[-2000:]
    assert len(list((tmp_path / "substep").iterdir())) == 1


def test_a_compile_error_shows_the_compilers_message():
    model = load_model_from_xml(PENDULUMS.format(nuserdata=1))
    bad = "void fun(const mjModel* m, mjData* d) {\n  d->no_such_field = 1;\n}\n"
    with pytest.raises(SubstepCompileError) as info:
        MjSim(model, substep_callback=bad)
    message = str(info.value)
    assert message.startswith("the substep callback's C code did not compile")
    assert "substep_callback:2:" in message and "no_such_field" in message
    assert isinstance(info.value, RuntimeError)
    with pytest.raises(SubstepCompileError, match="void fun"):
        MjSim(model, substep_callback="void other(const mjModel* m, mjData* d) {}")
    with pytest.raises(SubstepCompileError, match="did not compile"):
        MjSim(model, substep_callback="this is not C")


def test_mju_error_in_the_c_callback_is_a_fatal_error():
    model = load_model_from_xml(PENDULUMS.format(nuserdata=0))
    sim = MjSim(model, nsubsteps=3, substep_callback="""
        void fun(const mjModel* m, mjData* d) { if (d->time > 0) mju_error("boom at %g", 1.5); }
    """)
    with pytest.raises(mjcffi.FatalError, match="boom at 1.5"):
        sim.step()
    assert sim.data.time == pytest.approx(model.opt.timestep)
    sim.reset()
    sim.set_substep_callback(None)
    sim.step()
    assert sim.data.time == pytest.approx(3 * model.opt.timestep)


def test_bad_input_names_the_problem():
    model = load_model_from_xml(PENDULUMS.format(nuserdata=1))
    for value in (3.5, b"void fun() {}", [CONTROL]):
        with pytest.raises(TypeError, match="substep_callback must be"):
            MjSim(model, substep_callback=value)
    with pytest.raises(TypeError, match="not bool"):
        MjSim(model, substep_callback=True)
    with pytest.raises(ValueError, match="not a C function's address"):
        MjSim(model, substep_callback=-1)
    with pytest.raises(TypeError, match="not a C function pointer"):
        MjSim(model, substep_callback=ffi.new("int*"))
    with pytest.raises(AssertionError):             # more names than nuserdata
        MjSim(model, substep_callback=COUNT, userdata_names=["substeps", "last_time"])
    with pytest.raises(ValueError, match="not a C identifier"):
        _substep.build_callback_fn(COUNT, ["substeps", "last-time"])
    with pytest.raises(TypeError, match="must be a str"):
        _substep.build_callback_fn(42)
