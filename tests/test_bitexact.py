"""Raw `lib` calls step real models bit-identically to the official binding.

Both bindings run on the same libmujoco in this process, so any difference in
a trajectory is a bug in mjcffi.
"""

import numpy as np
import pytest

import mjcffi

from .conftest import gymnasium_assets

ffi, lib = mjcffi.ffi, mjcffi.lib


def _load_raw(path):
    error = ffi.new("char[]", 1000)
    model = lib.mj_loadXML(str(path).encode(), ffi.NULL, error, 1000)
    assert model != ffi.NULL, ffi.string(error).decode()
    return ffi.gc(model, lib.mj_deleteModel)


def _view(pointer, n):
    return np.frombuffer(ffi.buffer(pointer, 8 * n), dtype=np.float64)


def _perturbation(nq, nv, nu, nstep, seed):
    rng = np.random.default_rng(seed)
    return (rng.normal(0, 0.05, nq), rng.normal(0, 0.5, nv), rng.uniform(-1, 1, (nstep, nu)))


def _trajectories(mujoco, path, nstep, seed=0):
    """(ours, theirs): stacked [qpos, qvel, sensordata] after every step."""
    m = _load_raw(path)
    d = ffi.gc(lib.mj_makeData(m), lib.mj_deleteData)
    om = mujoco.MjModel.from_xml_path(str(path))
    od = mujoco.MjData(om)
    dq, dv, controls = _perturbation(m.nq, m.nv, m.nu, nstep, seed)

    qpos, qvel, ctrl = _view(d.qpos, m.nq), _view(d.qvel, m.nv), _view(d.ctrl, m.nu)
    sensordata = _view(d.sensordata, m.nsensordata)
    qpos += dq
    qvel += dv
    od.qpos += dq
    od.qvel += dv

    ours, theirs = [], []
    for row in controls:
        ctrl[:] = row
        lib.mj_step(m, d)
        od.ctrl[:] = row
        mujoco.mj_step(om, od)
        ours.append(np.concatenate([qpos, qvel, sensordata]))
        theirs.append(np.concatenate([od.qpos, od.qvel, od.sensordata]))
    return np.array(ours), np.array(theirs)


def _asset(name):
    return next(p for p in gymnasium_assets() if p.name == name)


def test_humanoid_1000_steps_from_a_perturbed_state_is_bit_identical(mujoco):
    ours, theirs = _trajectories(mujoco, _asset("humanoid.xml"), 1000)
    assert ours.shape == theirs.shape == (1000, ours.shape[1])
    # the perturbed humanoid really moves: a frozen trajectory would prove nothing
    assert np.ptp(ours[:, 2]) > 0.05
    assert ours.tobytes() == theirs.tobytes()


def test_a_different_perturbation_gives_a_different_trajectory(mujoco):
    # guards the test above: the comparison can tell two trajectories apart
    a, _ = _trajectories(mujoco, _asset("hopper.xml"), 50, seed=1)
    b, _ = _trajectories(mujoco, _asset("hopper.xml"), 50, seed=2)
    assert a.tobytes() != b.tobytes()


@pytest.mark.parametrize("path", gymnasium_assets(), ids=lambda p: p.stem)
def test_every_gymnasium_asset_is_bit_identical(mujoco, path):
    ours, theirs = _trajectories(mujoco, path, 200)
    assert ours.tobytes() == theirs.tobytes()


def _python_layer_trajectory(module, path, nstep, seed=0):
    """[qpos, qvel, sensordata] after each step, through `module`'s Python API only."""
    m = module.MjModel.from_xml_path(str(path))
    d = module.MjData(m)
    controls = np.random.default_rng(seed).uniform(-1, 1, (nstep, m.nu))
    rows = []
    for row in controls:
        d.ctrl[:] = row
        module.mj_step(m, d)
        rows.append(np.concatenate([d.qpos, d.qvel, d.sensordata]))
    return np.array(rows)


@pytest.mark.parametrize("path", gymnasium_assets(), ids=lambda p: p.stem)
def test_python_layer_1000_random_control_steps_are_bit_identical(mujoco, path):
    # `import mjcffi as mujoco` code: MjModel, MjData, mj_step, views
    ours = _python_layer_trajectory(mjcffi, path, 1000)
    theirs = _python_layer_trajectory(mujoco, path, 1000)
    assert ours.shape == theirs.shape == (1000, ours.shape[1])
    assert np.ptp(ours, axis=0).max() > 1e-3          # the controls really moved it
    assert ours.tobytes() == theirs.tobytes()
