"""Issue 11, item 3: unpickling an MjData trusts nothing in the pickle.

A pickled MjData is (model, header, buffer, arena, layout), none holding an address: the
header is mjData's scalars and counts (with the thread pool and stack zeroed), the layout the
signature and each arena array as an offset.  Unpickling takes every
buffer pointer from a fresh MjData of the model, every arena pointer from an offset checked to
lie inside the arena bytes with room for its count, checks every count against the model and
the arena, and raises ValueError("Invalid serialized mjData"), the detail in a note, on anything
else (mjcffi/_c/guard.c, mjcffi_restore_data).

Anything that might crash runs in a subprocess.  The byte-flip fuzz runs in subprocess batches:
a crash ends a batch with a signal, is recorded with its case, and the next batch goes on after
it.  MJCFFI_PICKLE_FUZZ sets the number of single-byte flips, shared by the models (default
1500; a fifth as many multi-byte changes, truncations and cuts come with them).  A long run
for a report: `python -m tests.test_hardening_pickle fuzz-report [flips per model]`.
"""

import collections
import concurrent.futures
import copy
import json
import os
import pathlib
import pickle
import subprocess
import sys
import traceback

import numpy as np
import pytest

import mjcffi
from mjcffi import ffi, lib, scenes
from mjcffi._support.arena import _realloc_con_efc, _realloc_island

REPO = pathlib.Path(__file__).resolve().parent.parent
INVALID = "Invalid serialized mjData"

# Sleep (with a sleeping island and one asleep from the start), delay buffers, a spatial tendon
# around a pulley, contacts, every kind of constraint row and the dual solver's arrays (PGS).
KITCHEN = """
<mujoco model="pickle kitchen">
  <option timestep="0.005" solver="PGS"><flag sleep="enable"/></option>
  <size memory="1M"/>
  <worldbody>
    <geom type="plane" size="2 2 .1"/>
    <site name="anchor" pos="0 0 1"/>
    <geom name="pulley" type="cylinder" pos=".15 0 1.1" size=".03 .02" zaxis="0 1 0"/>
    <body name="arm" pos="0 0 1">
      <joint name="hinge" type="hinge" axis="0 1 0" damping="0.1" range="-30 30"
             frictionloss=".01"/>
      <geom type="capsule" fromto="0 0 0 .3 0 0" size=".03"/>
      <site name="tip" pos=".3 0 0"/>
    </body>
    <body name="sled" pos="-.6 0 .05">
      <joint name="slide" type="slide" axis="1 0 0" frictionloss=".05"/>
      <joint name="lift" type="slide" axis="0 0 1"/>
      <geom type="box" size=".05 .05 .05"/>
    </body>
    <body pos=".5 0 .05"><freejoint/><geom type="box" size=".05 .05 .05"/></body>
    <body pos=".7 0 .05"><freejoint/><geom type="box" size=".05 .05 .05"/></body>
    <body pos="-.2 .5 .05" sleep="init"><freejoint/><geom type="box" size=".05 .05 .05"/></body>
  </worldbody>
  <tendon>
    <spatial name="rope" limited="true" range="0 .5">
      <site site="anchor"/><geom geom="pulley"/><site site="tip"/>
    </spatial>
    <fixed name="fixed"><joint joint="hinge" coef="1"/></fixed>
  </tendon>
  <equality><joint joint1="lift" polycoef="0 0 0 0 0"/></equality>
  <actuator>
    <motor joint="hinge" delay="0.01" nsample="4"/>
    <position joint="slide" kp="20" ctrlrange="-.5 .5"/>
    <motor tendon="rope"/>
  </actuator>
  <sensor>
    <jointpos joint="hinge" delay="0.01" nsample="3"/>
    <tendonpos tendon="rope"/>
    <framepos objtype="body" objname="sled"/>
  </sensor>
</mujoco>
"""

PID = """
<mujoco>
  <extension><plugin plugin="mujoco.pid"/></extension>
  <worldbody>
    <geom type="plane" size="1 1 .1"/>
    <body pos="0 0 .2"><joint name="j" type="slide" axis="0 0 1"/><geom size=".1"/></body>
  </worldbody>
  <actuator>
    <plugin plugin="mujoco.pid" joint="j" actdim="2">
      <config key="kp" value="10"/><config key="ki" value="2"/>
      <config key="kd" value="1"/><config key="slewmax" value="1"/>
    </plugin>
  </actuator>
</mujoco>
"""

MODELS = {"kitchen": KITCHEN, "pid": PID, "default": scenes.DEFAULT}


def stepped(name, steps=300):
    """An MjData of MODELS[name] after `steps` steps of fixed pseudo-random controls."""
    m = mjcffi.MjModel.from_xml_string(MODELS[name])
    d = mjcffi.MjData(m)
    rng = np.random.default_rng(0)
    for _ in range(steps):
        d.ctrl[:] = rng.uniform(-1, 1, m.nu)
        mjcffi.mj_step(m, d)
    return d


def parts(d):
    """The pickled parts of d (header, buffer, arena, layout), its plugin instances'
    addresses blanked: each MjData has its own."""
    _, (_, header, buffer, arena, layout) = d.__reduce__()
    p = d._ptr
    if p.nplugin:
        buffer = bytearray(buffer)
        at = int(ffi.cast("uintptr_t", p.plugin_data)) - int(ffi.cast("uintptr_t", p.buffer))
        buffer[at:at + ffi.sizeof("uintptr_t") * p.nplugin] = bytes(8 * p.nplugin)
        buffer = bytes(buffer)
    return header, buffer, arena, layout


_ARRAYS = []


def pointers_inside(d):
    """None if every array view of d lies in d's own struct, buffer or arena; else the first
    that does not (a view of unallocated memory is a new array and lies nowhere)."""
    if not _ARRAYS:
        fresh = mjcffi.MjData(mjcffi.MjModel.from_xml_string(scenes.PENDULUM))
        _ARRAYS.extend(n for n in type(d)._fields if isinstance(getattr(fresh, n), np.ndarray))
    p = d._ptr
    spans = [(p, ffi.sizeof("mjData")), (p.buffer, p.nbuffer), (p.arena, p.narena)]
    spans = [(int(ffi.cast("uintptr_t", start)), size) for start, size in spans]
    views = [(name, getattr(d, name)) for name in _ARRAYS]
    if d.ncon:
        views.append(("contact", d.contact.dist))
    for name, view in views:
        if view.size and view.base is not None:
            start = view.__array_interface__["data"][0]
            nbytes = d.ncon * ffi.sizeof("mjContact") if name == "contact" else view.nbytes
            if not any(s <= start and start + nbytes <= s + size for s, size in spans):
                return name
    return None


def _prelude(name, steps=100):
    """Code that makes `d`, an MjData of MODELS[name] after `steps` steps, in a subprocess
    that need not import this module (and pytest)."""
    return ("import pickle, numpy as np, mjcffi\n"
            "from mjcffi import data, ffi\n"
            f"m = mjcffi.MjModel.from_xml_string({MODELS[name]!r})\n"
            "d = mjcffi.MjData(m)\n"
            "rng = np.random.default_rng(0)\n"
            f"for _ in range({steps}):\n"
            "    d.ctrl[:] = rng.uniform(-1, 1, m.nu)\n"
            "    mjcffi.mj_step(m, d)\n")


def _run(code, env=None):
    """Run `code` in a fresh interpreter from the repository root: (returncode, output)."""
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            cwd=REPO, env=env, timeout=300)
    return result.returncode, result.stdout + result.stderr


# ------------------------------------------------------------------ the three triggers

def test_item3_corrupted_pickle_header_ncon_raises():
    code = _prelude("default") + (
        "_, (model, header, buffer, arena, layout) = d.__reduce__()\n"
        "at = ffi.offsetof('mjData', 'ncon')\n"
        "header = header[:at] + (10**7).to_bytes(4, 'little') + header[at + 4:]\n"
        "try:\n"
        "    d2 = data._unpickle(model, header, buffer, arena, layout)\n"
        "    print(d2.contact.dist.shape)\n"
        "except ValueError as e:\n"
        "    print(type(e).__name__, '|', e, '|', *e.__notes__)\n")
    returncode, output = _run(code)
    assert returncode == 0, output
    assert f"ValueError | {INVALID} | ncon = 10000000 exceeds" in output, output


@pytest.mark.parametrize("byte", [0, 5], ids=["low byte", "high byte"])
def test_item3_flipped_qvel_pointer_byte_is_refused(byte):
    # the old pickle (the whole mjData struct as its header) held qvel's address; flipping a
    # byte of it crashed the next mj_step (high byte) or gave a view and a MuJoCo of
    # different memory (low byte)
    code = _prelude("default") + (
        "p = d._ptr\n"
        "model, header = m, ffi.buffer(p, ffi.sizeof('mjData'))[:]\n"
        "buffer, arena = ffi.buffer(p.buffer, p.nbuffer)[:], ffi.buffer(p.arena, p.parena)[:]\n"
        f"at = ffi.offsetof('mjData', 'qvel') + {byte}\n"
        "header = header[:at] + bytes([header[at] ^ 0x40]) + header[at + 1:]\n"
        "try:\n"
        "    d2 = data._unpickle(model, header, buffer, arena)\n"
        "    mjcffi.mj_step(model, d2)\n"
        "    print('loaded', d2.qvel.ctypes.data - int(ffi.cast('uintptr_t', d2._ptr.qvel)))\n"
        "except ValueError as e:\n"
        "    print(type(e).__name__, '|', e, '|', *e.__notes__)\n")
    returncode, output = _run(code)
    assert returncode == 0, output
    assert f"ValueError | {INVALID} | no layout: pickled by an mjcffi older" in output, output


def test_item3_the_pickle_holds_no_address():
    d = stepped("kitchen")
    blob = pickle.dumps(d)
    p = d._ptr
    addresses = [p.buffer, p.arena, p.qvel, p.contact, p.efc_J, p.plugin_data, d.model._ptr]
    for address in addresses:
        assert address != ffi.NULL
        assert int(ffi.cast("uintptr_t", address)).to_bytes(8, "little") not in blob
    # the unpickled data's pointers are its own, every view inside its own memory
    e = pickle.loads(blob)
    q = e._ptr
    for name in ("qpos", "qvel", "history", "tree_asleep"):
        offset = int(ffi.cast("uintptr_t", getattr(q, name))) - int(ffi.cast("uintptr_t", q.buffer))
        assert offset == int(ffi.cast("uintptr_t", getattr(p, name))) - \
            int(ffi.cast("uintptr_t", p.buffer)), name
    assert pointers_inside(e) is None and e.ncon > 0
    assert e.contact.dist.ctypes.data == int(ffi.cast("uintptr_t", q.contact))


# ------------------------------------------------------------------ each check, one at a time

def _with(header, field, value, size=4, signed=True):
    at = ffi.offsetof("mjData", field)
    return header[:at] + int(value).to_bytes(size, "little", signed=signed) + header[at + size:]


def _slot(d, name):
    """Where the arena offset of arena array `name` lies in d's pickled layout."""
    p = d._ptr
    layout = d.__reduce__()[1][4]
    offset = int(ffi.cast("uintptr_t", getattr(p, name))) - int(ffi.cast("uintptr_t", p.arena))
    start = 16                                  # after the tag and the signature
    slots = [start + 8 * i for i in range((len(layout) - start) // 8)
             if int.from_bytes(layout[start + 8 * i:start + 8 * i + 8], "little",
                               signed=True) == offset]
    assert len(slots) >= 1
    return slots[0]


def _refused(model, header, buffer, arena, layout):
    with pytest.raises(ValueError) as caught:
        mjcffi.data._unpickle(model, header, buffer, arena, layout)
    assert str(caught.value) == INVALID
    return " ".join(caught.value.__notes__)


@pytest.fixture(scope="module")
def kitchen():
    d = stepped("kitchen")
    assert d.ncon and d.nefc and d.ne and d.nf and d.nl and d.nY and d.nisland
    assert 0 < d.ntree_awake < d.model.ntree and d.model.nhistory
    return d


COUNT_CASES = [
    ("ncon", -1, "ncon = -1 is negative"),
    ("ncon", 10**7, "ncon = 10000000 exceeds"),            # more than the arena could hold
    ("ncon", 200, "contact: 200 entries of"),               # more than the arena bytes hold
    ("nefc", 2**30, "nefc = 1073741824 exceeds"),
    ("ne", 1000, "ne + nf + nl = 1003 exceeds 20"),
    ("nJ", 2**29, "nJ = 536870912 exceeds"),
    ("nJ", 10**5, "efc_J_colind: 100000 entries of 4 bytes"),
    ("nY", 10**5, "efc_Y: 100000 entries of 8 bytes"),
    ("nisland", 99, "nisland = 99 exceeds 5"),
    ("nidof", 99, "nidof = 99 exceeds 21"),
    ("nv_awake", 99, "nv_awake = 99 exceeds 21"),
    ("nbody_awake", -3, "nbody_awake = -3 is negative"),
    ("nefmT", 50, "nefmT = 50 exceeds 2"),
    ("efm_active", 3, "efm_active = 3 exceeds 2"),
    ("nefmK", 10**8, "nefmK = 100000000 exceeds"),         # its arrays absent: the arena bound
]


@pytest.mark.parametrize("field, value, note", COUNT_CASES,
                         ids=[f"{field}={value}" for field, value, _ in COUNT_CASES])
def test_item3_counts_are_checked_against_model_and_arena(kitchen, field, value, note):
    model, header, buffer, arena, layout = kitchen.__reduce__()[1]
    assert note in _refused(model, _with(header, field, value), buffer, arena, layout)


@pytest.mark.parametrize("field, size, value, note", [
    ("pstack", 8, 64, "a pickle holds no stack"),
    ("pbase", 8, 1 << 40, "a pickle holds no stack"),
    ("threadpool", 8, 0x1000, "no thread pool"),
    ("threadlock", 1, 1, "threadlock = 1"),
    ("flg_energypos", 1, 7, "flg_energypos = 7"),
    ("parena", 8, 1 << 60, "parena = 1152921504606846976"),
    ("narena", 8, 1 << 21, "does not fit its model: narena"),
    ("nplugin", 4, 3, "does not fit its model"),
    ("solver_niter", 4, 100000, "solver_niter[0] = 100000"),
])
def test_item3_sizes_stack_and_flags_are_checked(kitchen, field, size, value, note):
    model, header, buffer, arena, layout = kitchen.__reduce__()[1]
    assert note in _refused(model, _with(header, field, value, size), buffer, arena, layout)


def test_item3_arena_offsets_must_fit_the_arena(kitchen):
    model, header, buffer, arena, layout = kitchen.__reduce__()[1]
    for name, offset, note in [
            ("efc_force", len(arena) - 8, "efc_force: 20 entries of 8 bytes"),
            ("efc_force", len(arena) + 8, "efc_force: arena offset"),
            ("efc_force", 3, "efc_force: arena offset 3 is not an offset"),
            ("contact", -5, "contact: arena offset -5"),
            ("contact", len(arena) - 104, "contact: 4 entries")]:
        at = _slot(kitchen, name)
        bad = layout[:at] + offset.to_bytes(8, "little", signed=True) + layout[at + 8:]
        assert note in _refused(model, header, buffer, arena, bad), name
    # parena is the arena's length
    assert "parena = " in _refused(model, header, buffer, arena[:-8], layout)


def test_item3_buffer_indices_a_step_follows_are_checked(kitchen):
    model, header, buffer, arena, layout = kitchen.__reduce__()[1]
    p = kitchen._ptr

    def poke(field, index, value, fmt="i"):
        at = int(ffi.cast("uintptr_t", getattr(p, field))) - int(ffi.cast("uintptr_t", p.buffer))
        item = np.array([value], dtype=fmt).tobytes()
        at += index * len(item)
        return buffer[:at] + item + buffer[at + len(item):]

    cursor = model.actuator_historyadr[0] + 1
    for bad, note in [
            (poke("dof_awake_ind", 0, 10**6), "dof_awake_ind[0] = 1000000 is outside"),
            (poke("body_awake_ind", 0, -1), "body_awake_ind[0] = -1 is outside"),
            (poke("tree_asleep", 2, 77), "tree_asleep[2] = 77 is outside"),
            (poke("ten_wrapadr", 0, 10**6), "ten_wrapadr[0] = 1000000"),
            (poke("wrap_obj", 1, 10**6), "wrap_obj[1] = 1000000 is outside"),
            (poke("history", cursor, np.nan, "f8"), "the cursor of actuator 0 is nan"),
            (poke("history", cursor, 1.5, "f8"), "the cursor of actuator 0 is 1.5"),
            (poke("history", cursor, 4.0, "f8"), "the cursor of actuator 0 is 4")]:
        assert note in _refused(model, header, bad, arena, layout)
    assert "does not fit its model: the buffer" in _refused(model, header, buffer[:-1], arena,
                                                            layout)


def test_item3_what_is_not_an_mjdata_pickle_is_refused(kitchen):
    model, header, buffer, arena, layout = kitchen.__reduce__()[1]
    assert "is not one that this mjcffi writes" in _refused(model, header, buffer, arena,
                                                            b"X" + layout[1:])
    assert "is not one that this mjcffi writes" in _refused(model, header, buffer, arena,
                                                            layout + b"\0")
    assert "header has" in _refused(model, header + b"\0", buffer, arena, layout)
    assert "the buffer is a str" in _refused(model, header, "text", arena, layout)
    assert "the header is a int" in _refused(model, 7, buffer, arena, layout)
    assert "not an MjModel" in _refused(kitchen, header, buffer, arena, layout)
    assert "no layout" in _refused(model, header, buffer, arena, None)    # an older pickle
    other = mjcffi.MjModel.from_xml_string(scenes.PENDULUM)
    assert "does not fit its model" in _refused(other, header, buffer, arena, layout)


def test_item3_a_refused_pickle_leaves_plugin_instances_alone():
    # the fresh data is dropped whole; its own instances are freed once, the original's never
    code = _prelude("pid") + (
        "model, header, buffer, arena, layout = d.__reduce__()[1]\n"
        "for cut in (header[:-1], header):\n"
        "    try:\n"
        "        data._unpickle(model, cut, buffer, arena[:-1] if cut is header else arena,\n"
        "                       layout)\n"
        "    except ValueError as e:\n"
        "        print('refused')\n"
        "e = pickle.loads(pickle.dumps(d))\n"
        "print(e.plugin_data[0] != d.plugin_data[0], e.plugin[0] == d.plugin[0])\n"
        "mjcffi.mj_step(e.model, e, 10)\n"
        "del d, e\n"
        "print('done')\n")
    returncode, output = _run(code)
    assert returncode == 0, output
    assert output.split() == ["refused", "refused", "True", "True", "done"], output


def test_item3_a_corrupted_mjb_size_is_refused_before_mujoco_allocates():
    m = mjcffi.MjModel.from_xml_string(KITCHEN)
    mjb = bytearray(m.to_bytes())
    at = 5 * 4                             # the sizes follow five header ints; nq is first
    mjb[at:at + 8] = (2**30).to_bytes(8, "little")
    with pytest.raises(ValueError) as caught:
        mjcffi.MjModel.from_bytes(bytes(mjb))
    assert "but its sizes describe" in caught.value.__notes__[0]


# ------------------------------------------------------------------ exactness

def _full_state(d):
    spec = mjcffi.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(lib.mj_stateSize(d.model._ptr, spec))
    lib.mj_getState(d.model._ptr, d._ptr, ffi.cast("mjtNum *", state.ctypes.data), spec)
    return state


def _state(name):
    """An MjData in one of the states that a pickle must reproduce."""
    if name == "fresh":
        return mjcffi.MjData(mjcffi.MjModel.from_xml_string(KITCHEN))
    if name in MODELS:
        return stepped(name)
    if name == "CG, forward":
        d = stepped("default")
        d.model.opt.solver = mjcffi.mjtSolver.mjSOL_CG
        mjcffi.mj_forward(d.model, d)
    elif name == "kinematics after a step":
        d = stepped("kitchen")
        mjcffi.mj_kinematics(d.model, d)
    elif name == "private realloc":
        d = mjcffi.MjData(mjcffi.MjModel.from_xml_string(scenes.DEFAULT))
        _realloc_con_efc(d, ncon=3, nefc=7, nJ=20)
        _realloc_island(d, nisland=2, nidof=5)
    else:
        assert name == "reset"
        d = stepped("default")
        mjcffi.mj_resetData(d.model, d)
    return d


@pytest.mark.parametrize("name", ["fresh", *MODELS, "CG, forward", "kinematics after a step",
                                  "private realloc", "reset"])
def test_item3_round_trip_is_bit_exact_and_steps_identically(name):
    d = _state(name)
    e = pickle.loads(pickle.dumps(d))
    assert e is not d and e._ptr != d._ptr and pointers_inside(e) is None
    assert parts(e) == parts(d)                     # every byte of header, buffer and arena
    for field in ("qpos", "qvel", "act", "history", "tree_asleep", "efc_force", "qacc_warmstart"):
        assert getattr(e, field).tobytes() == getattr(d, field).tobytes(), field
    assert (e.ncon, e.nefc, e.nisland, e.time) == (d.ncon, d.nefc, d.nisland, d.time)
    assert e.contact.dist.tobytes() == d.contact.dist.tobytes()
    for x in (d, e):
        mjcffi.mj_step(x.model, x, 50)
    assert _full_state(e).tobytes() == _full_state(d).tobytes()
    # header and buffer again; not the timers (mjcb_time may be set: `import mujoco` sets it),
    # nor unused arena bytes (MuJoCo's scratch, which may differ)
    timers = slice(ffi.offsetof("mjData", "timer"), ffi.offsetof("mjData", "ncon"))
    (dh, db, _, dl), (eh, eb, _, el) = parts(d), parts(e)
    assert eb == db and el == dl
    assert eh[:timers.start] + eh[timers.stop:] == dh[:timers.start] + dh[timers.stop:]


def test_item3_a_data_with_its_stack_in_use_pickles_with_an_empty_stack():
    xml = scenes.DEFAULT.replace('<option timestep="0.002"/>',
                                 '<option timestep="0.002"/><size memory="16K"/>')
    m = mjcffi.MjModel.from_xml_string(xml)
    d = mjcffi.MjData(m)
    with pytest.raises(mjcffi.FatalError):
        mjcffi.mj_step(m, d, 500)                 # the arena overflows mid-step
    assert d.pstack and d.pbase                   # left in use (pbase is an address)
    e = pickle.loads(pickle.dumps(d))
    assert (e.pstack, e.pbase) == (0, 0) and e.ncon == d.ncon and e.time == d.time
    assert e.qpos.tobytes() == d.qpos.tobytes()
    copy.copy(e)                                  # MuJoCo copies only a data at rest


# ------------------------------------------------------------------ the fuzz

FUZZ_CASES = int(os.environ.get("MJCFFI_PICKLE_FUZZ", "1500"))


def _regions(blob, d):
    """Byte ranges of the pickle `blob` of d to aim at: each part, the header's counts and
    its arena offsets, and everything but the model's MJB bytes.

    The MJB is left out: MuJoCo's loader checks its sizes (and mjcffi, before it allocates)
    and its object references, but not every index and enum in it, so a corrupted model
    can crash inside MuJoCo whether or not an MjData comes with it."""
    model, header, buffer, arena, layout = d.__reduce__()[1]
    mjb = model.to_bytes()
    found = {}
    for name, part in (("header", header), ("buffer", buffer), ("arena", arena),
                       ("layout", layout), ("mjb", mjb)):
        at = blob.find(part)
        assert at >= 0 and part, name
        found[name] = (at, at + len(part))
    start = found["header"][0]
    found["counts"] = (start, start + ffi.offsetof("mjData", "solver"))
    found["pickle"] = None                                 # anywhere but the MJB
    return found


def _position(found, name, blob_size, rng):
    if name != "pickle":
        return int(rng.integers(*found[name]))
    lo, hi = found["mjb"]
    at = int(rng.integers(0, blob_size - (hi - lo)))
    return at if at < lo else at + (hi - lo)


AIMS = ("pickle", "pickle", "counts", "layout", "header", "buffer", "arena")


def _mutate(blob, found, case, seed, flips, aims=AIMS):
    """Case `case`: one byte flipped (cases < flips), else several bytes, a truncation or a
    slice cut out; aimed at a region chosen at random among `aims`.  Reproducible from
    (seed, case)."""
    rng = np.random.default_rng([seed, case])
    name = aims[int(rng.integers(len(aims)))]
    out = bytearray(blob)
    if case < flips:
        at = _position(found, name, len(blob), rng)
        out[at] ^= int(rng.integers(1, 256))
        return bytes(out), f"flip {name} {at}"
    kind = int(rng.integers(3))
    if kind == 0:
        count = int(rng.integers(2, 17))
        for _ in range(count):
            out[_position(found, name, len(blob), rng)] = int(rng.integers(256))
        return bytes(out), f"{count} bytes {name}"
    if kind == 1:
        at = int(rng.integers(len(blob)))
        return bytes(out[:at]), f"truncated at {at}"
    at, length = _position(found, name, len(blob), rng), int(rng.integers(1, 65))
    return bytes(out[:at] + out[at + length:]), f"cut {length} at {at} {name}"


def _ours(error):
    """Whether `error` came out of mjcffi (else out of the pickle machinery itself)."""
    return any(os.sep + "mjcffi" + os.sep in frame.filename
               for frame in traceback.extract_tb(error.__traceback__))


def _fuzz_batch(model, seed, start, stop, flips, aims=AIMS):
    """Run cases [start, stop) in this process: for each, a line of JSON naming it, then one
    with its outcome and any violation of the promise."""
    d = stepped(model)
    blob = pickle.dumps(d)
    found = _regions(blob, d)
    for case in range(start, stop):
        mutated, what = _mutate(blob, found, case, seed, flips, aims)
        print(json.dumps({"case": case, "what": what}), flush=True)
        violation = None
        try:
            e = pickle.loads(mutated)
        except Exception as error:      # noqa: BLE001  (classified below)
            if _ours(error):
                outcome = "refused: " + type(error).__name__
                # a corrupted model size can ask MuJoCo for more memory than there is
                memory = isinstance(error, mjcffi.FatalError) and "allocate" in str(error)
                if not isinstance(error, (ValueError, TypeError)) and not memory:
                    violation = f"{what}: {type(error).__name__}: {error}"
            else:
                outcome = "pickle machinery: " + type(error).__name__
            print(json.dumps({"outcome": outcome, "violation": violation}), flush=True)
            continue
        if not isinstance(e, mjcffi.MjData):
            print(json.dumps({"outcome": "not an MjData: " + type(e).__name__}), flush=True)
            continue
        try:
            e.ctrl[:] = 0.1
            mjcffi.mj_step(e.model, e, 20)
            outcome = "unpickled and stepped"
        except mjcffi.FatalError:
            outcome = "unpickled, FatalError in a step"
        outside = pointers_inside(e)
        if outside:
            violation = f"{what}: {outside} lies outside the data's memory"
        print(json.dumps({"outcome": outcome, "violation": violation}), flush=True)


def fuzz(model, seed, flips, others, perturb=None, batch=1000, aims=AIMS):
    """The fuzz for `model`: `flips` single-byte flips, then `others` multi-byte changes,
    truncations and cuts, in subprocess batches (a crash ends its batch; the next starts
    after it).  MALLOC_PERTURB_=`perturb` fills what malloc returns and free releases."""
    env = dict(os.environ)
    if perturb:
        env["MALLOC_PERTURB_"] = str(perturb)
    total = flips + others
    report = {"outcomes": collections.Counter(), "violations": [], "crashes": []}
    start = 0
    while start < total:
        stop = min(total, start + batch)
        code = ("from tests.test_hardening_pickle import _fuzz_batch\n"
                f"_fuzz_batch({model!r}, {seed}, {start}, {stop}, {flips}, {aims!r})\n")
        try:
            result = subprocess.run([sys.executable, "-c", code], capture_output=True,
                                    text=True, cwd=REPO, env=env, timeout=300)
            lines, returncode = result.stdout.splitlines(), result.returncode
            error = result.stderr
        except subprocess.TimeoutExpired as expired:
            lines = (expired.stdout or b"").decode().splitlines()
            returncode, error = "timeout", ""
        records = [json.loads(line) for line in lines if line.startswith("{")]
        for record in records:
            if "outcome" in record:
                report["outcomes"][record["outcome"]] += 1
                if record.get("violation"):
                    report["violations"].append(record["violation"])
        if returncode == 0:
            start = stop
            continue
        cases = [r for r in records if "case" in r]
        if not cases:
            raise AssertionError(f"fuzz batch failed before its first case:\n{error}")
        report["crashes"].append(f"{cases[-1]['what']} (case {cases[-1]['case']}, seed {seed}): "
                                 f"{returncode} {error.strip().splitlines()[-1:]}")
        start = cases[-1]["case"] + 1
    return report


def test_item3_random_byte_flips_never_crash():
    # the third trigger (random flips gave some 7 segfaults in 1,500): each model's
    # share of the flips, and the kitchen again under MALLOC_PERTURB_, in parallel
    share = FUZZ_CASES // len(MODELS)
    runs = {name: dict(model=name, seed=11, flips=share, others=share // 5)
            for name in sorted(MODELS)}
    runs["kitchen, MALLOC_PERTURB_"] = dict(model="kitchen", seed=12, flips=share // 2,
                                           others=share // 10, perturb=165)
    with concurrent.futures.ThreadPoolExecutor(len(runs)) as pool:
        reports = dict(zip(runs, pool.map(lambda kw: fuzz(**kw), runs.values())))
    for name, report in reports.items():
        assert report["crashes"] == [], (name, report)
        assert report["violations"] == [], (name, report)
        outcomes = report["outcomes"]
        # both ways out were exercised: refusals by the checks, and data that steps
        assert outcomes["refused: ValueError"] > 30, (name, outcomes)
        assert outcomes["unpickled and stepped"] > 30, (name, outcomes)


if __name__ == "__main__" and sys.argv[1:2] == ["fuzz-report"]:
    # python -m tests.test_hardening_pickle fuzz-report [flips per model]: the fuzz at
    # length, plain and under MALLOC_PERTURB_, then the flips aimed at the model's MJB alone
    flips = int(sys.argv[2]) if len(sys.argv) > 2 else 20000
    for name in sorted(MODELS):
        for seed, perturb, aims in ((101, None, AIMS), (102, 90, AIMS), (103, None, ("mjb",))):
            result = fuzz(name, seed, flips, flips // 5, perturb=perturb, aims=aims)
            result["outcomes"] = dict(result["outcomes"])
            print(json.dumps({"model": name, "seed": seed, "perturb": perturb, "aims": aims,
                              **result}), flush=True)
