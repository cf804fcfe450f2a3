"""The official bindings' private paths on mjcffi: the modules `mujoco._enums` ...
`mujoco._batch` (attributes and importable), `MjModel._sizes`, the fields in the class
dicts of MjModel and MjData, and the constraint counts MJX's get_data_into writes.
"""

import importlib
import inspect
import subprocess
import sys
import types

import numpy as np
import pytest

import mjcffi
from .conftest import gymnasium_assets

PRIVATE = ("_enums", "_constants", "_structs", "_functions", "_errors", "_callbacks",
           "_render", "_rollout", "_specs", "_batch")

# official names with no mjcffi equivalent (mjcffi/_private_paths.py says why)
NOT_IN_MJCFFI = {
    "_errors": {"UnexpectedError"},
    "_specs": {"MjByteVec"},
    "_structs": {"_recompile_spec_addr"},
}


def _run(code):
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def test_every_private_path_is_an_attribute_under_the_swap_without_an_import():
    out = _run(f"""
import sys
import mjcffi
sys.modules["mujoco"] = mjcffi
import mujoco
print("GEOM", mujoco._enums.mjtGeom.mjGEOM_BOX == 6)
for name in {PRIVATE!r}:
    assert getattr(mujoco, name) is sys.modules["mjcffi." + name], name
import mujoco._errors, mujoco._batch
from mujoco._rollout import Rollout
from mujoco._errors import FatalError
print("SAME", mujoco._errors is mjcffi._errors, Rollout is mjcffi.rollout.Rollout,
      FatalError is mjcffi.FatalError, mujoco._batch.Batch is mjcffi.batch.Batch)
""")
    assert "GEOM True" in out and "SAME True True True True" in out


@pytest.mark.parametrize("name", PRIVATE)
def test_each_private_module_holds_what_the_official_holds(mujoco, name):
    official = importlib.import_module(f"mujoco.{name}")
    ours = importlib.import_module(f"mjcffi.{name}")
    assert ours.__name__ == f"mjcffi.{name}"
    wanted = {n for n in dir(official) if not n.startswith("__")}
    missing = wanted - set(dir(ours)) - NOT_IN_MJCFFI.get(name, set())
    assert not missing, sorted(missing)
    for attr in sorted(wanted - NOT_IN_MJCFFI.get(name, set())):
        value, theirs = getattr(ours, attr), getattr(official, attr)     # each resolves
        if inspect.isclass(theirs):
            assert inspect.isclass(value) and value.__name__ == theirs.__name__, attr
        elif callable(theirs):
            assert callable(value), attr
        else:
            assert value == theirs, attr                                 # the constants
    # and nothing the official does not have may pass silently as a name
    with pytest.raises(AttributeError):
        getattr(ours, "no_such_name")


def test_the_private_struct_classes_are_the_types_of_the_objects():
    m = mjcffi.MjModel.from_xml_string(
        "<mujoco><worldbody><body><joint/><geom size='.1'/></body></worldbody></mujoco>")
    d = mjcffi.MjData(m)
    structs = mjcffi._structs
    assert type(d.contact) is structs._MjContactList
    assert type(d.solver) is structs._MjSolverStatList
    assert type(d.warning) is structs._MjWarningStatList
    assert type(d.timer) is structs._MjTimerStatList
    assert type(m.geom(0)) is structs._MjModelGeomViews
    assert type(d.joint(0)) is structs._MjDataJointViews


@pytest.mark.parametrize("path", gymnasium_assets()[:6], ids=lambda p: p.stem)
def test_sizes_are_the_officials(mujoco, path):
    ours = mjcffi.MjModel.from_xml_path(str(path))._sizes
    theirs = mujoco.MjModel.from_xml_path(str(path))._sizes
    assert ours.dtype == theirs.dtype == np.int64
    assert ours.shape == theirs.shape and (ours == theirs).all()
    assert not ours.flags.writeable and ours.flags.owndata


def test_sizes_are_a_new_array_each_time():
    m = mjcffi.MjModel.from_xml_string("<mujoco/>")
    assert m._sizes is not m._sizes and m._sizes[0] == m.nq


@pytest.mark.parametrize("name", ("MjModel", "MjData"))
def test_the_class_dict_holds_the_fields_the_official_holds(mujoco, name):
    official = set(getattr(mujoco, name).__dict__)
    ours = set(getattr(mjcffi, name).__dict__)
    # pybind11's own, and the official's private helpers mjcffi has no use for
    left_out = {n for n in official if n.startswith("__") or n == "_pybind11_conduit_v1_"}
    left_out |= {"_all_fields", "_from_model_ptr", "_size_fields", "bind_scalar"}
    left_out |= {n for n in official if n.startswith("_setconst_")}
    missing = official - left_out - ours
    assert not missing, sorted(missing)
    expected = {"qpos", "contact", "xpos"} if name == "MjData" else {"body_pos", "_sizes"}
    assert expected <= ours


def test_hoisting_puts_in_the_dict_what_lookups_found_in_the_bases():
    # a subclass that defines nothing: every name hoisted into its dict is the object
    # the first of its bases holds, so no lookup changes
    for base in (mjcffi.MjModel, mjcffi.MjData):
        probe = type("Probe", (base,), {})
        hoisted = {n for n in vars(probe) if not n.startswith("__")}
        assert {"qpos", "bind", "_address"} <= hoisted if base is mjcffi.MjData else \
               {"body_pos", "_sizes", "from_xml_path"} <= hoisted
        for name in hoisted:
            owner = next(k for k in probe.__mro__[1:] if name in vars(k))
            assert vars(probe)[name] is vars(owner)[name], (base.__name__, name)


def test_the_hot_fields_are_slots_that_read_and_assign_as_before():
    m = mjcffi.MjModel.from_xml_path(str(gymnasium_assets()[0]))
    d = mjcffi.MjData(m)
    descriptor = type(d).__dict__["qpos"]
    assert isinstance(descriptor, types.MemberDescriptorType)
    assert "qpos" not in d.__dict__
    view = d.qpos
    assert view is d.qpos                   # the one view built when wrapped
    d.qpos = np.arange(m.nq, dtype=float)   # assigning writes into it
    assert view is d.qpos and (view == np.arange(m.nq)).all()
    copy = d.__copy__()
    assert copy.qpos is not d.qpos and (copy.qpos == d.qpos).all()


def _stepped(xml):
    m = mjcffi.MjModel.from_xml_string(xml)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    return m, d


_LIMITED = """<mujoco><worldbody><body><joint name='j' range='0 0.1' limited='true'/>
<geom size='.1' mass='1'/></body></worldbody><keyframe><key qpos='0.5'/></keyframe></mujoco>"""


def test_the_constraint_counts_take_what_mjx_writes():
    m, d = _stepped(_LIMITED)
    mjcffi.mj_resetDataKeyframe(m, d, 0)
    mjcffi.mj_forward(m, d)
    assert (d.nl, d.nefc) == (1, 1)
    mjcffi._functions._realloc_con_efc(d, ncon=0, nefc=1, nJ=1)
    d.ncon, d.nefc = 0, np.int64(1)          # the values they hold: accepted
    d.ne, d.nf, d.nl = 0, 0, 1
    d.nl = 3           # MJX counts inactive limit rows too: more than nefc, in the arena
    assert d.nl == 3
    mjcffi.mj_forward(m, d)                   # a step recounts them
    assert (d.ne, d.nf, d.nl, d.nefc) == (0, 0, 1, 1)


def test_the_constraint_counts_refuse_what_would_read_past_the_arena():
    m, d = _stepped(_LIMITED)
    with pytest.raises(ValueError, match="sizes the arrays laid out in the arena"):
        d.nefc = d.nefc + 1
    with pytest.raises(ValueError, match="sizes the arrays"):
        d.ncon = 5
    with pytest.raises(ValueError, match="must be >= 0"):
        d.ne = -1
    with pytest.raises(ValueError, match="inside the arena"):
        d.nl = d.narena                       # rows far past the end of the arena
    with pytest.raises(TypeError, match="MjData.nf takes a number"):
        d.nf = "1"
    with pytest.raises(ValueError, match="out of range for a C int"):
        d.nf = 2**31
    assert (d.ne, d.nf) == (0, 0)
    with pytest.raises(AttributeError):       # the other counts stay read-only
        d.nJ = 0


def test_official_pickles_of_model_and_data_load_under_the_swap(mujoco, tmp_path):
    # tests/test_official_objects.py checks the values; this, that the swap's
    # mujoco._structs is what they name, for a real model after steps
    path = gymnasium_assets()[0]
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mujoco.mj_step(m, d, 20)
    import pickle
    (tmp_path / "blob").write_bytes(pickle.dumps((m, d)))
    out = _run(f"""
import pickle, sys
import mjcffi
sys.modules["mujoco"] = mjcffi
m, d = pickle.loads(open({str(tmp_path / "blob")!r}, "rb").read())
print("TYPES", type(m) is mjcffi.MjModel, type(d) is mjcffi.MjData, d.time, list(d.qpos))
""")
    line = next(line for line in out.splitlines() if line.startswith("TYPES"))
    assert line == f"TYPES True True {d.time} {list(d.qpos)}"
