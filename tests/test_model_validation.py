"""The model validator (mjcffi/_support/modelcheck): every real model passes it and
round-trips through pickle; a corrupted MJB, pickle or MJB file is a ValueError
whose note names the field, for every check it runs; the fields Batch.expand
refuses are all checked; and byte flips never crash the process."""

import functools
import pathlib
import pickle
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import mjcffi
from mjcffi._support import modelcheck as _modelcheck
from mjcffi._support.modelcheck import CHECKED, INDEX_FIELDS, Model, mjb_problem

from .conftest import gymnasium_assets

GYM = gymnasium_assets()
SCENE = pathlib.Path(__file__).parent / "scenes" / "every_category.xml"
CHECKS = {check.__name__: check for check in CHECKED}

# Small scenes for what every_category.xml and the gymnasium models lack.
CLOTH = """<mujoco><worldbody>
  <flexcomp name="cloth" type="grid" count="4 3 1" spacing=".1 .1 .1" dim="2" pos="0 0 1"
            radius=".01"><elasticity young="1e3" thickness="1e-2" elastic2d="bend"/>
    <edge damping="0.1"/></flexcomp>
</worldbody></mujoco>"""
TRILINEAR = """<mujoco><worldbody>
  <flexcomp name="cube" type="grid" count="3 3 3" spacing=".1 .1 .1" dim="3" pos="0 0 1"
            radius=".01" dof="trilinear"><elasticity young="1e4" poisson="0.2"/></flexcomp>
</worldbody></mujoco>"""
SKIN = """<mujoco><worldbody>
  <body name="b" pos="0 0 1"><freejoint/><geom size=".1"/></body>
  <body name="c" pos="1 0 1"><freejoint/><geom size=".1"/></body></worldbody>
  <deformable><skin name="sk" vertex="0 0 0 1 0 0 0 1 0 0 0 1" face="0 1 2 0 2 3 0 3 1 1 3 2">
    <bone body="b" bindpos="0 0 0" bindquat="1 0 0 0" vertid="0 1 2" vertweight="1 1 1"/>
    <bone body="c" bindpos="0 0 0" bindquat="1 0 0 0" vertid="2 3" vertweight="1 1"/>
  </skin></deformable></mujoco>"""
TENDONS = """<mujoco>
  <extension><plugin plugin="mujoco.pid"><instance name="pid">
    <config key="kp" value="1"/></instance></plugin></extension>
  <worldbody><body><joint name="a"/><geom size=".1"/>
    <body pos="0 0 1"><joint name="b" type="slide"/><geom size=".1"/></body></body>
  </worldbody>
  <tendon><fixed name="t"><joint joint="a" coef="1"/><joint joint="b" coef="-1"/></fixed></tendon>
  <equality><joint joint1="a" joint2="b"/><tendon tendon1="t"/></equality>
  <actuator><motor name="m" tendon="t" nsample="3" delay="0.01"/>
    <plugin joint="a" plugin="mujoco.pid" instance="pid"/></actuator>
  <sensor><tendonpos tendon="t"/><actuatorfrc actuator="m"/></sensor>
</mujoco>"""
SCENES = {"every": SCENE, "humanoid": next(p for p in GYM if p.stem == "humanoid"),
          "cloth": CLOTH, "trilinear": TRILINEAR, "skin": SKIN, "tendons": TENDONS}


@functools.cache
def mjb_of(scene):
    source = SCENES[scene]
    if isinstance(source, str):
        return mjcffi.MjModel.from_xml_string(source).to_bytes()
    return mjcffi.MjModel.from_xml_path(str(source)).to_bytes()


def corrupt(mjb, field, index, value):
    """`mjb` with element `index` (flat) of `field` set to `value`, or to value(old, m)
    where `m` is the validator's view of the MJB."""
    m = Model(mjb)
    if field.startswith("opt."):
        dtype, old = np.dtype(np.int32), getattr(m.opt, field[4:])
    else:
        values = m.arrays[field].ravel()
        dtype, old = values.dtype, int(values[index])
    new = value(old, m) if callable(value) else value
    assert new != old, f"{field}[{index}] is {new} already"
    at = m.offset(field) + index * dtype.itemsize
    raw = bytearray(mjb)
    raw[at:at + dtype.itemsize] = np.array([new], dtype).tobytes()
    return bytes(raw)


def noted_field(error):
    """The field a validator note names: 'body_parentid[2] is 5: ...' -> body_parentid."""
    notes = getattr(error, "__notes__", [])
    assert len(notes) == 1, notes
    return notes[0].split(" ")[0].split("[")[0]


# ------------------------------------------------------------ real models

def test_the_gymnasium_models_are_all_found():
    assert len(GYM) >= 14, GYM


@pytest.mark.parametrize("path", GYM, ids=[p.stem for p in GYM])
def test_every_gymnasium_model_passes_and_round_trips(path):
    model = mjcffi.MjModel.from_xml_path(str(path))
    mjb = model.to_bytes()
    assert mjb_problem(mjb) is None
    assert pickle.loads(pickle.dumps(model)).to_bytes() == mjb


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_every_scene_passes(scene):
    assert mjb_problem(mjb_of(scene)) is None


def test_an_interpolated_flex_and_a_flex_on_welded_bodies_pass():
    # an interpolated flex's vertices have no body (-1), and an edge is rigid when its
    # vertices' bodies share a weld, not only a body: both once refused, wrongly
    welded = """<mujoco><worldbody><body name="p"><freejoint/><geom size=".1"/>
      <body name="a" pos="1 0 0"/><body name="b" pos="0 1 0"/>
      <body name="c" pos="1 1 0"><joint type="slide"/><geom size=".1"/></body></body>
      </worldbody><deformable><flex name="f" dim="2" body="p a b c" element="0 1 2 1 2 3"
      vertex="0 0 0 0 0 0 0 0 0 0 0 0"><edge damping="1"/></flex></deformable></mujoco>"""
    model = mjcffi.MjModel.from_xml_string(welded)
    assert model.flexedge_rigid[0] and model.flex_vertbodyid[1] != model.flex_vertbodyid[2]
    assert mjb_problem(model.to_bytes()) is None
    cube = mjcffi.MjModel.from_bytes(mjb_of("trilinear"))
    assert cube.flex_interp[0] == 1 and (cube.flex_vertbodyid == -1).all()


# ------------------------------------------------------------ one corruption per check

def _dof_not_in_first_tendon_row(old, m):
    row = m.flat("ten_J_colind")[:m.flat("ten_J_rownnz")[0]]
    return next(d for d in range(m.nv) if d not in row)


# (check, scene, field, flat index, new value or value(old, m), the field the note names)
CORRUPTIONS = [
    ("check_options", "every", "opt.integrator", 0, 99, "opt.integrator"),
    ("check_enums", "every", "geom_type", 0, 99, "geom_type"),
    ("check_enums", "every", "jnt_type", 1, 9, "jnt_type"),
    ("check_condims", "every", "geom_condim", 0, 2, "geom_condim"),
    ("check_ids", "every", "geom_matid", 0, 99, "geom_matid"),
    ("check_ids", "humanoid", "jnt_bodyid", 1, 99, "jnt_bodyid"),
    ("check_spans", "every", "name_bodyadr", 1, 10**6, "name_bodyadr"),
    ("check_spans", "humanoid", "body_dofnum", 1, 1000, "body_dofadr"),
    ("check_colind", "humanoid", "M_colind", 0, lambda old, m: m.nv + 5, "M_colind"),
    ("check_bodies", "humanoid", "body_parentid", 2, 5, "body_parentid"),
    ("check_bodies", "humanoid", "body_weldid", 3, 1, "body_weldid"),
    ("check_joints", "humanoid", "jnt_qposadr", 1, lambda old, m: old + 1, "jnt_qposadr"),
    ("check_joints", "humanoid", "dof_jntid", 7, 0, "dof_jntid"),
    ("check_dofs", "humanoid", "dof_parentid", 7, 0, "dof_parentid"),
    ("check_dofs", "humanoid", "dof_simplenum", 0, 1000, "dof_simplenum"),
    ("check_trees", "every", "dof_treeid", 0, 1, "dof_treeid"),
    ("check_inertia", "humanoid", "D_diag", 5, 0, "D_diag"),
    ("check_inertia", "humanoid", "mapM2D", 3, lambda old, m: old + 1, "mapM2D"),
    ("check_body_dofs", "humanoid", "B_colind", 0, 1, "B_colind"),
    ("check_geoms", "every", "geom_dataid", 1, 3, "geom_dataid"),
    ("check_geoms", "every", "pair_signature", 0, 0x7fffffff, "pair_signature"),
    ("check_meshes", "every", "mesh_graph", 0, 10**6, "mesh_graph"),
    ("check_faces", "every", "mesh_face", 0, 99, "mesh_face"),
    ("check_faces", "every", "mesh_polyvert", 0, 99, "mesh_polyvert"),
    ("check_faces", "skin", "skin_face", 0, 99, "skin_face"),
    ("check_faces", "skin", "skin_bonevertid", 3, 4, "skin_bonevertid"),
    ("check_tendons", "every", "tendon_type", 0, 0, "tendon_type"),
    ("check_tendons", "every", "wrap_objid", 0, 99, "wrap_objid"),
    ("check_tendon_jacobian", "humanoid", "ten_J_colind", 0, _dof_not_in_first_tendon_row,
     "ten_J_colind"),
    ("check_sensors", "every", "sensor_adr", 1, 0, "sensor_adr"),
    ("check_sensors", "every", "sensor_objid", 1, 99, "sensor_objid"),
    ("check_actuators", "every", "actuator_trnid", 0, 99, "actuator_trnid"),
    ("check_actuators", "every", "actuator_ctrladr", 1, 0, "actuator_ctrladr"),
    ("check_history", "tendons", "actuator_historyadr", 0, 1, "actuator_historyadr"),
    ("check_history", "tendons", "actuator_history", 0, 2, "nhistory"),
    ("check_history", "every", "actuator_history", 0, -1, "actuator_history"),
    ("check_equalities", "every", "eq_obj1id", 0, 99, "eq_obj1id"),
    ("check_equalities", "tendons", "eq_obj2id", 0, 99, "eq_obj2id"),
    ("check_tuples", "every", "tuple_objid", 0, 99, "tuple_objid"),
    ("check_hierarchies", "every", "bvh_child", 0, 0, "bvh_child"),
    ("check_flexes", "cloth", "flex_elem", 0, 99, "flex_elem"),
    ("check_flexes", "cloth", "flex_edgeflap", 1, 99, "flex_edgeflap"),
    ("check_flexes", "cloth", "flexedge_rigid", 0, 1, "flexedge_rigid"),
    ("check_flexes", "cloth", "flex_vertbodyid", 0, -1, "flex_vertbodyid"),
    ("check_flexes", "cloth", "flex_bendingadr", 0, 1, "flex_bendingadr"),
    ("check_flexes", "trilinear", "flex_vertcell", 0, 99, "flex_vertcell"),
    ("check_strings", "every", "names_map", 0, 99, "names_map"),
    ("check_plugins", "every", "body_simple", 1, 7, "body_simple"),
    ("check_plugins", "tendons", "plugin", 0, 999, "plugin"),
]


@pytest.mark.parametrize("check, scene, field, index, value, named", CORRUPTIONS,
                         ids=[f"{c[0]}-{c[2]}" for c in CORRUPTIONS])
def test_a_corrupted_field_is_a_value_error_naming_it(check, scene, field, index, value,
                                                      named):
    bad = corrupt(mjb_of(scene), field, index, value)
    with pytest.raises(ValueError) as caught:
        mjcffi.MjModel.from_bytes(bad)
    assert noted_field(caught.value) == named


def test_every_check_runs_and_has_a_corruption_above():
    assert set(CHECKED) == set(_modelcheck._CHECKS)
    assert set(CHECKS) == {case[0] for case in CORRUPTIONS}


def test_each_corruption_is_of_a_field_its_check_covers():
    for check, _, field, _, _, _ in CORRUPTIONS:
        if not field.startswith("opt."):
            assert field in CHECKED[CHECKS[check]], (check, field)


# ------------------------------------------------------------ coverage of the index fields

# Index fields no check covers, and why none needs to: none is used as an index.
EXEMPT = {
    # input bits: MuJoCo reads at most four controls from the actuator's ctrladr,
    # inside mjData's buffer (ctrl is never its last array)
    "actuator_ctrlspec",
    "cam_output",               # bits the renderer tests
    "flex_activelayers",        # compared with flex_elemlayer, never an index
    "flex_elemlayer",           # compared with flex_activelayers and the scene's layer
    "flex_edgeequality",        # compared with 1 and 3 (edges, strain)
    "flex_plasticmode",         # bits; MuJoCo's loader refuses values it does not know
}


def test_every_index_field_is_covered_by_a_check_or_exempt():
    covered = set().union(*CHECKED.values())
    assert INDEX_FIELDS - covered == EXEMPT
    assert len(INDEX_FIELDS) > 240


def test_batch_refuses_exactly_the_expandable_index_fields():
    from mjcffi.batch import _batch
    expected = (_batch._EXPANDABLE & INDEX_FIELDS) - set(_batch.CHECKED_FIELDS)
    assert _batch.INDEX_FIELDS == expected
    assert {"body_parentid", "jnt_qposadr", "geom_type", "M_colind"} <= _batch.INDEX_FIELDS


# ------------------------------------------------------------ pickles, files, assets

def test_a_corrupted_model_inside_an_mjdata_pickle_is_a_value_error():
    model = mjcffi.MjModel.from_xml_path(str(SCENES["humanoid"]))
    mjb = model.to_bytes()
    stream = pickle.dumps(mjcffi.MjData(model))
    at = stream.index(mjb)
    bad = stream[:at] + corrupt(mjb, "body_parentid", 2, 5) + stream[at + len(mjb):]
    with pytest.raises(ValueError) as caught:
        pickle.loads(bad)
    assert noted_field(caught.value) == "body_parentid"


def test_a_corrupted_mjb_file_is_a_value_error(tmp_path):
    path = tmp_path / "bad.mjb"
    path.write_bytes(corrupt(mjb_of("every"), "geom_type", 0, 99))
    with pytest.raises(ValueError) as caught:
        mjcffi.MjModel.from_binary_path(str(path))
    assert noted_field(caught.value) == "geom_type"
    path.write_bytes(mjb_of("every"))
    assert mjcffi.MjModel.from_binary_path(str(path)).to_bytes() == mjb_of("every")


def test_assets_that_are_not_a_dict_are_a_type_error(tmp_path):
    path = tmp_path / "good.mjb"
    path.write_bytes(mjb_of("every"))
    with pytest.raises(TypeError, match="assets must be a dict"):
        mjcffi.MjModel.from_binary_path(str(path), assets=[("a.png", b"")])


def test_a_sound_mjb_is_checked_once_and_a_corrupted_one_every_time(monkeypatch):
    from mjcffi._support import loading as _loading
    calls = []
    monkeypatch.setattr(_loading._modelcheck, "mjb_problem",
                        lambda mjb: calls.append(len(mjb)) or mjb_problem(mjb))
    _loading.SOUND.clear()
    good, bad = mjb_of("every"), corrupt(mjb_of("every"), "geom_type", 0, 99)
    for _ in range(3):
        mjcffi.MjModel.from_bytes(good)
        with pytest.raises(ValueError):
            mjcffi.MjModel.from_bytes(bad)
    assert calls == [len(good), len(bad), len(bad), len(bad)]


def test_the_sound_cache_keeps_the_latest_digests_only():
    from mjcffi._support.loading import _Sound
    sound = _Sound(2)
    for digest in (b"a", b"b", b"c"):
        sound.add(digest)
    assert b"a" not in sound
    assert b"b" in sound                # b is now the latest used: c is the oldest
    sound.add(b"d")
    assert b"c" not in sound
    assert b"b" in sound and b"d" in sound


# ------------------------------------------------------------ byte flips, in a subprocess

FLIPS = 300

SWEEP = textwrap.dedent("""
    import random, sys
    import mjcffi
    from mjcffi._support.modelcheck import Model, mjb
    raw_model = open(sys.argv[1], "rb").read()
    m = Model(raw_model)
    ints = [(m.offset(f.name), m.arrays[f.name].nbytes) for f in mjb.POINTERS
            if f.elem == "int" and m.arrays[f.name].nbytes]
    rng = random.Random(20240611)
    loaded = refused = failed = 0
    for n in range(int(sys.argv[2])):
        if n % 2:                       # anywhere
            at = rng.randrange(len(raw_model))
        else:                           # in an int array: an id, address, count or type
            start, size = rng.choice(ints)
            at = start + rng.randrange(size)
        raw = bytearray(raw_model)
        raw[at] ^= 1 << rng.randrange(8)
        try:
            model = mjcffi.MjModel.from_bytes(bytes(raw))
        except ValueError:
            refused += 1
            continue
        try:                            # MuJoCo's own errors (mju_error) are exceptions
            data = mjcffi.MjData(model)
            for _ in range(10):
                mjcffi.mj_step(model, data)
        except (mjcffi.FatalError, MemoryError):
            failed += 1
        loaded += 1
    print("done", loaded + refused, "loaded", loaded, "refused", refused, "failed", failed)
""")


def test_byte_flips_load_and_step_or_are_python_errors(tmp_path):
    path = tmp_path / "scene.mjb"
    path.write_bytes(mjb_of("every"))
    run = subprocess.run([sys.executable, "-c", SWEEP, str(path), str(FLIPS)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]      # a crash is a signal here
    words = run.stdout.split()
    counts = dict(zip(words[::2], map(int, words[1::2])))
    assert counts["done"] == FLIPS
    assert counts["loaded"] > 0 and counts["refused"] > 0, counts
