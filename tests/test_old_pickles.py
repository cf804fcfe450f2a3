"""Pickles written by an earlier mjcffi still load (issue 26: the tree moved, the
paths pickles name did not).

tests/pickles/ holds an MjModel, an MjData, a value struct (MjOption), a
mujoco-py MjSimState and two enum members, pickled (protocol 4, then gzip) by
mjcffi as it was on 2026-11-27, before the package was reorganised; expected.txt
holds the values they carried, written by the same code.
"""

import ast
import gzip
import pathlib
import pickle

import mjcffi

HERE = pathlib.Path(__file__).resolve().parent / "pickles"


def _load(name):
    return pickle.loads(gzip.decompress((HERE / f"{name}.pkl.gz").read_bytes()))


def test_pickles_of_the_earlier_layout_load_with_their_values():
    time, qpos, qvel, timestep, sim_time, sim_qpos = ast.literal_eval(
        (HERE / "expected.txt").read_text())
    m, d, option, state = (_load(name) for name in ("model", "data", "option", "simstate"))
    assert isinstance(m, mjcffi.MjModel) and m.nq == 1 and m.nu == 1
    assert isinstance(d, mjcffi.MjData) and d.model.nq == 1
    assert (d.time, d.qpos.tolist(), d.qvel.tolist()) == (time, qpos, qvel)
    assert isinstance(option, mjcffi.MjOption) and option.timestep == timestep
    assert (state.time, state.qpos.tolist()) == (sim_time, sim_qpos)
    assert type(state).__module__.startswith("mjcffi.sim")


def test_an_unpickled_data_steps_on():
    d = _load("data")
    before = d.time
    mjcffi.mj_step(d.model, d, 3)
    assert d.time > before


def test_enum_members_keep_their_official_module_path():
    loaded = _load("enums")
    assert loaded == {"kind": mjcffi.mjtObj.mjOBJ_GEOM, "joint": mjcffi.mjtJoint.mjJNT_HINGE}
    assert type(loaded["kind"]) is mjcffi.mjtObj
    # pickled now, they name the same path: mjcffi._enums, as mujoco._enums
    assert b"mjcffi._enums" in pickle.dumps(mjcffi.mjtObj.mjOBJ_BODY)
