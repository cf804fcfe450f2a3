"""mjcffi.sim.functions with mujoco-py's own signatures (mjcffi/sim/generated/functions.py).

mujoco-py code calls `functions.mj_saveLastXML(path, model, "", 0)` and passes flat
arrays with their sizes (`mju_mulMatVec(res, mat, vec, nr, nc)`); each call here is
checked against mjcffi's own function (the official bindings' signature) or NumPy.
"""

import inspect
import os
import re
import zipfile

import numpy as np
import pytest

import mjcffi
from codegen import simfunctions
from mjcffi.sim import _callbacks, const, functions
from mjcffi.sim._model import SimData, SimModel, load_model_from_xml
from mjcffi.sim._vfs import PyMjVFS
from mjcffi.sim.generated import functions as generated

XML = """
<mujoco>
  <worldbody>
    <site name="anchor"/>
    <body name="arm" pos="0 0 1">
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom name="upper" type="capsule" size=".05" fromto="0 0 0 .3 0 0"/>
      <site name="tip" pos=".3 0 0"/>
      <body name="hand" pos=".3 0 0">
        <joint name="ball" type="ball"/>
        <geom name="palm" type="box" size=".05 .1 .02" pos=".05 0 0"/>
      </body>
    </body>
    <body name="ball" pos="1 0 1">
      <freejoint/>
      <geom name="sphere" size=".1"/>
    </body>
  </worldbody>
  <tendon><spatial name="cord"><site site="anchor"/><site site="tip"/></spatial></tendon>
  <actuator><muscle name="muscle" tendon="cord"/></actuator>
</mujoco>
"""

# What MuJoCo 4 changed or dropped, from mujoco-py's module (generated REMOVED).
EXPECTED_REMOVED = {"mj_fullM", "mj_makeEmptyFileVFS", "mj_deleteModel", "mj_deleteData"}


@pytest.fixture
def sim():
    model = load_model_from_xml(XML)
    data = SimData(model)
    data.qpos[1:5] = [0.9, 0.1, 0.2, 0.3]
    functions.mj_forward(model, data)
    return model, data


@pytest.fixture
def error_callback():
    seen = []
    previous = _callbacks.get_error_callback()
    _callbacks.set_error_callback(seen.append)
    yield seen
    _callbacks.set_error_callback(previous)


# ------------------------------------------------------- the brief's examples

def test_save_last_xml_takes_mujoco_py_error_buffer(tmp_path, sim):
    model, _ = sim
    path = tmp_path / "saved.xml"
    assert functions.mj_saveLastXML(str(path), model, "", 0) == 1
    saved = path.read_text()
    assert "<mujoco" in saved and 'name="arm"' in saved
    assert list(inspect.signature(functions.mj_saveLastXML).parameters) == \
        ["filename", "m", "error", "error_sz"]


def test_quat2mat_with_flat_arrays_equals_mjcffi():
    quat = np.array([0.8, 0.2, -0.4, 0.4])
    quat /= np.linalg.norm(quat)
    res9 = np.zeros(9)
    assert functions.mju_quat2Mat(res9, quat) is None
    expected = np.zeros(9)
    mjcffi.mju_quat2Mat(expected, quat)
    np.testing.assert_array_equal(res9, expected)


# ------------------------------------------------------------ model and data

def test_model_and_data_functions(sim):
    model, data = sim
    functions.mj_step(model, data)
    assert data.time == pytest.approx(model.opt.timestep)
    functions.mj_resetData(model, data)
    assert data.time == 0.0
    functions.mj_forwardSkip(model, data, const.STAGE_NONE, 0)
    assert functions.mj_name2id(model, const.OBJ_BODY, "hand") == 2
    assert functions.mj_isSparse(model) == mjcffi.mj_isSparse(model)
    assert functions.mj_getTotalmass(model) == pytest.approx(mjcffi.mj_getTotalmass(model))


def test_jacobians_fill_flat_arrays(sim):
    model, data = sim
    nv = model.nv
    jacp, jacr = np.zeros(3 * nv), np.zeros(3 * nv)
    functions.mj_jacBody(model, data, jacp, jacr, 2)
    expected_p, expected_r = np.zeros((3, nv)), np.zeros((3, nv))
    mjcffi.mj_jacBody(model, data, expected_p, expected_r, 2)
    np.testing.assert_array_equal(jacp, expected_p.ravel())
    np.testing.assert_array_equal(jacr, expected_r.ravel())
    assert np.any(jacp)
    point = np.array([0.2, 0.1, 1.0])
    jacp[:] = 0
    functions.mj_jac(model, data, jacp, jacr, point, 2)
    mjcffi.mj_jac(model, data, expected_p, expected_r, point, 2)
    np.testing.assert_array_equal(jacp, expected_p.ravel())
    # the (3, nv) arrays of mjcffi are taken as they are
    functions.mj_jacSite(model, data, expected_p, expected_r, 1)
    site_p = np.zeros(3 * nv)
    functions.mj_jacSite(model, data, site_p, None, 1)
    np.testing.assert_array_equal(site_p, expected_p.ravel())


def test_a_longer_flat_array_is_filled_from_its_start(sim):
    model, data = sim
    nv = model.nv
    jacp = np.full(3 * nv + 5, 7.0)
    functions.mj_jacBody(model, data, jacp, np.zeros(3 * nv), 2)
    expected = np.zeros((3, nv))
    mjcffi.mj_jacBody(model, data, expected, None, 2)
    np.testing.assert_array_equal(jacp[:3 * nv], expected.ravel())
    np.testing.assert_array_equal(jacp[3 * nv:], 7.0)


def test_a_short_array_raises(sim):
    model, data = sim
    with pytest.raises(ValueError, match="jacp"):
        functions.mj_jacBody(model, data, np.zeros(3 * model.nv - 1), np.zeros(3 * model.nv), 2)
    with pytest.raises(ValueError, match="res"):
        functions.mju_quat2Mat(np.zeros(8), np.array([1.0, 0, 0, 0]))


def test_solve_m_with_n_rows(sim):
    model, data = sim
    nv = model.nv
    dense = np.zeros((nv, nv))
    mjcffi.mj_fullM(model, data, dense)
    y = np.arange(2 * nv, dtype=float) + 1
    x = np.zeros(2 * nv)
    functions.mj_solveM(model, data, x, y, 2)
    np.testing.assert_allclose(x.reshape(2, nv), np.linalg.solve(dense, y.reshape(2, nv).T).T)
    x[:] = 0
    functions.mj_solveM(model, data, x, y, 1)               # n cuts the arrays
    np.testing.assert_allclose(x[:nv], np.linalg.solve(dense, y[:nv]))
    assert not np.any(x[nv:])


def test_solve_m2_is_half_a_solve(sim):
    model, data = sim
    nv = model.nv
    dense = np.zeros((nv, nv))
    mjcffi.mj_fullM(model, data, dense)
    y = np.linspace(1, 2, nv)
    x = np.zeros(nv)
    functions.mj_solveM2(model, data, x, y, 1)
    # x = sqrt(inv(D)) inv(L') y, so x.x = y' inv(M) y
    assert x @ x == pytest.approx(y @ np.linalg.solve(dense, y))


def test_mul_m_and_rne(sim):
    model, data = sim
    vec = np.linspace(-1, 1, model.nv)
    res, expected = np.zeros(model.nv), np.zeros(model.nv)
    functions.mj_mulM(model, data, res, vec)
    mjcffi.mj_mulM(model, data, expected, vec)
    np.testing.assert_array_equal(res, expected)
    functions.mj_rne(model, data, 0, res)
    mjcffi.mj_rne(model, data, 0, expected)
    np.testing.assert_array_equal(res, expected)


def test_add_m_adds_the_whole_matrix_as_mujoco_2(sim):
    model, data = sim
    nv = model.nv
    dense = np.zeros((nv, nv))
    mjcffi.mj_fullM(model, data, dense)
    assert np.any(np.triu(dense, 1))           # MuJoCo 4's own mj_addM leaves this out
    dst = np.ones(nv * nv)
    functions.mj_addM(model, data, dst, 0, 0, 0)
    np.testing.assert_allclose(dst, 1 + dense.ravel())
    rownnz = np.zeros(nv, np.int32)
    with pytest.raises(NotImplementedError, match="mj_addM"):
        functions.mj_addM(model, data, dst, rownnz.ctypes.data, 0, 0)


def test_positions_and_velocities(sim):
    model, data = sim
    qpos2 = data.qpos.copy()
    qvel = np.linspace(0.1, 0.5, model.nv)
    functions.mj_integratePos(model, qpos2, qvel, 0.01)
    expected = data.qpos.copy()
    mjcffi.mj_integratePos(model, expected, qvel, 0.01)
    np.testing.assert_array_equal(qpos2, expected)
    back = np.zeros(model.nv + 3)                          # longer than nv
    functions.mj_differentiatePos(model, back, 0.01, data.qpos, qpos2)
    np.testing.assert_allclose(back[:model.nv], qvel)
    res = np.zeros(6)
    functions.mj_objectVelocity(model, data, const.OBJ_BODY, 2, res, 0)


# ------------------------------------------------------- arrays with sizes

def test_vector_functions_use_n():
    a, b = np.arange(6.0), np.ones(6)
    res = np.full(6, -1.0)
    functions.mju_add(res, a, b, 4)
    np.testing.assert_array_equal(res, [1, 2, 3, 4, -1, -1])
    functions.mju_scl(res, a, 2.0, 6)
    np.testing.assert_array_equal(res, 2 * a)
    assert functions.mju_dot(a, b, 3) == 3.0
    assert functions.mju_sum(a, 6) == 15.0
    functions.mju_zero(res, 2)
    np.testing.assert_array_equal(res[:2], 0)
    assert res[2] == 4.0
    functions.mju_copy(res, a, 6)                           # mjcffi's vec is mujoco-py's data
    np.testing.assert_array_equal(res, a)
    assert functions.mju_isZero(np.zeros(3), 3) == 1


def test_sizes_are_checked():
    with pytest.raises(ValueError, match="res"):
        functions.mju_zero(np.zeros(3), 4)
    with pytest.raises(ValueError, match="n must be >= 0"):
        functions.mju_zero(np.zeros(3), -1)
    with pytest.raises(TypeError):
        functions.mju_zero(np.zeros(3), 1.5)


def test_matrix_functions_take_flat_matrices():
    rng = np.random.default_rng(0)
    mat = rng.standard_normal(6)                            # 2 x 3
    vec3, vec2 = rng.standard_normal(3), rng.standard_normal(2)
    res = np.zeros(3)
    functions.mju_mulMatVec(res, mat, vec3, 2, 3)
    np.testing.assert_allclose(res[:2], mat.reshape(2, 3) @ vec3)
    functions.mju_mulMatTVec(res, mat, vec2, 2, 3)
    np.testing.assert_allclose(res, mat.reshape(2, 3).T @ vec2)
    trans = np.zeros(6)
    functions.mju_transpose(trans, mat, 2, 3)
    np.testing.assert_array_equal(trans.reshape(3, 2), mat.reshape(2, 3).T)
    other = rng.standard_normal(12)                         # 3 x 4
    prod = np.zeros(8)
    functions.mju_mulMatMat(prod, mat, other, 2, 3, 4)
    np.testing.assert_allclose(prod.reshape(2, 4), mat.reshape(2, 3) @ other.reshape(3, 4))
    prod = np.zeros(4)
    functions.mju_mulMatMatT(prod, mat, mat, 2, 3, 2)
    np.testing.assert_allclose(prod.reshape(2, 2), mat.reshape(2, 3) @ mat.reshape(2, 3).T)
    square = np.zeros(9)
    functions.mju_sqrMatTD(square, mat, np.array([2.0, 3.0]), 2, 3)
    np.testing.assert_allclose(square.reshape(3, 3),
                               mat.reshape(2, 3).T @ np.diag([2.0, 3.0]) @ mat.reshape(2, 3))


def test_cholesky_in_place_on_a_flat_matrix():
    spd = np.array([[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]])
    factor = spd.ravel().copy()
    assert functions.mju_cholFactor(factor, 3, 0.0) == 3
    rhs = np.array([1.0, 2.0, 3.0])
    res = np.zeros(3)
    functions.mju_cholSolve(res, factor, rhs, 3)
    np.testing.assert_allclose(res, np.linalg.solve(spd, rhs))


def test_print_mat_prints_nr_by_nc(capfd):
    functions.mju_printMat(np.arange(8.0), 2, 3)
    out = capfd.readouterr().out.split("\n")
    rows = [line.split() for line in out if line.strip()]
    assert [[float(v) for v in row] for row in rows] == [[0, 1, 2], [3, 4, 5]]


def test_print_mat_sparse_takes_addresses_or_arrays(capfd):
    mat = np.array([1.0, 2.0, 3.0])
    rownnz = np.array([2, 1], np.int32)
    rowadr = np.array([0, 2], np.int32)
    colind = np.array([0, 2, 1], np.int32)
    functions.mju_printMatSparse(mat, 2, rownnz, rowadr, colind)
    from_arrays = capfd.readouterr().out
    functions.mju_printMatSparse(mat, 2, rownnz.ctypes.data, rowadr.ctypes.data,
                                 colind.ctypes.data)
    assert capfd.readouterr().out == from_arrays
    mjcffi.mju_printMatSparse(mat, rownnz, rowadr, colind)
    assert capfd.readouterr().out == from_arrays


def test_insertion_sort_int_at_an_address():
    values = np.array([5, 3, 9, 1, 7], np.int32)
    functions.mju_insertionSortInt(values.ctypes.data, 4)
    np.testing.assert_array_equal(values, [1, 3, 5, 9, 7])
    values = np.array([5, 3, 9, 1, 7], np.int32)
    functions.mju_insertionSortInt(values, 5)
    np.testing.assert_array_equal(values, [1, 3, 5, 7, 9])


def test_ray_writes_geomid_at_an_address(sim):
    model, data = sim
    pnt, vec = np.array([1.0, -1.0, 1.0]), np.array([0.0, 1.0, 0.0])
    geomid = np.array([-5], np.int32)
    distance = functions.mj_ray(model, data, pnt, vec, np.ones(6, np.uint8), 1, -1,
                                geomid.ctypes.data)
    assert distance == pytest.approx(0.9)
    assert geomid[0] == functions.mj_name2id(model, const.OBJ_GEOM, "sphere")
    geomid[0] = -5
    assert functions.mj_ray(model, data, pnt, vec, None, 1, -1, geomid) == pytest.approx(0.9)
    assert geomid[0] == functions.mj_name2id(model, const.OBJ_GEOM, "sphere")


def test_select_writes_its_ids_at_addresses(sim):
    model, data = sim
    scene, option, camera = mjcffi.MjvScene(model, 100), mjcffi.MjvOption(), mjcffi.MjvCamera()
    mjcffi.mjv_defaultFreeCamera(model, camera)
    functions.mjv_updateScene(model, data, option, mjcffi.MjvPerturb(), camera, const.CAT_ALL,
                              scene)
    selpnt = np.zeros(3)
    geomid, skinid = np.array([77], np.int32), np.array([77], np.int32)
    body = functions.mjv_select(model, data, option, 1.0, 0.5, 0.5, scene, selpnt,
                                geomid.ctypes.data, skinid.ctypes.data)
    expected_geom, expected_flex, expected_skin = (np.array([77], np.int32) for _ in range(3))
    expected = mjcffi.mjv_select(model, data, option, 1.0, 0.5, 0.5, scene, np.zeros(3),
                                 expected_geom, expected_flex, expected_skin)
    assert body == expected
    assert geomid[0] == expected_geom[0] != 77 and skinid[0] == expected_skin[0] == -1


def test_rot_vec_mat_is_mul_mat_vec3():
    mat = np.arange(9.0)
    vec = np.array([1.0, -2.0, 0.5])
    res = np.zeros(3)
    functions.mju_rotVecMat(res, vec, mat)
    np.testing.assert_allclose(res, mat.reshape(3, 3) @ vec)
    functions.mju_rotVecMatT(res, vec, mat)
    np.testing.assert_allclose(res, mat.reshape(3, 3).T @ vec)


def test_muscle_dynamics_takes_mujoco_2s_two_parameters(sim):
    model, _ = sim
    two = np.array([0.01, 0.04])
    expected = mjcffi.mju_muscleDynamics(0.5, 0.1, np.array([0.01, 0.04, 0.0]))
    assert functions.mju_muscleDynamics(0.5, 0.1, two) == expected
    # a model's dynprm row (longer) gives its first two, without smoothing
    prm = model.actuator_dynprm[0]
    assert functions.mju_muscleDynamics(0.5, 0.1, prm) == \
        mjcffi.mju_muscleDynamics(0.5, 0.1, np.array([prm[0], prm[1], 0.0]))


# ---------------------------------------------------------------- strings

def test_string_arguments(sim):
    model, _ = sim
    assert functions.mju_str2Type("body") == const.OBJ_BODY
    assert functions.mj_name2id(model, const.OBJ_SITE, "tip") == 1


def test_print_schema_writes_the_file_and_returns_its_length(tmp_path):
    path = tmp_path / "schema.txt"
    length = functions.mj_printSchema(str(path), "", 0, 0, 0)
    assert length == len(mjcffi.mj_printSchema(0, 0)) == len(path.read_text())
    assert functions.mj_printSchema("", "", 0, 1, 1) == len(mjcffi.mj_printSchema(1, 1))
    assert list(tmp_path.iterdir()) == [path]


def test_error_and_warning_formats_are_filled(error_callback):
    functions.mju_error_i("bad index %d", 7)
    functions.mju_error_s("no %s here", "body")
    functions.mju_error_i("nowhere to put it", 3)
    functions.mju_error("plain")
    assert error_callback == [b"bad index 7", b"no body here", b"nowhere to put it", b"plain"]


# ------------------------------------------------------------ error buffers

def test_load_xml_ignores_the_error_buffer_and_gives_a_sim_model(tmp_path):
    path = tmp_path / "model.xml"
    path.write_text(XML)
    model = functions.mj_loadXML(str(path), PyMjVFS(), "", 0)
    assert isinstance(model, SimModel) and model.nbody == 4
    assert model.body_name2id("hand") == 2            # mujoco-py's getters
    with pytest.raises(ValueError, match="missing.xml"):
        functions.mj_loadXML(str(tmp_path / "missing.xml"), PyMjVFS(), "", 1000)


def test_load_model_reads_mjb(tmp_path, sim):
    model, _ = sim
    path = tmp_path / "model.mjb"
    path.write_bytes(model.get_mjb())
    loaded = functions.mj_loadModel(str(path), PyMjVFS())
    assert isinstance(loaded, SimModel) and loaded.nv == model.nv


MUSCLE_XML = """
<mujoco>
  <worldbody>
    <site name="anchor"/>
    <body pos="0 0 1">
      <joint type="hinge" axis="0 1 0"/>
      <geom type="capsule" size=".05" fromto="0 0 0 .3 0 0"/>
      <site name="tip" pos=".3 0 0"/>
    </body>
  </worldbody>
  <tendon><spatial name="cord"><site site="anchor"/><site site="tip"/></spatial></tendon>
  <actuator><muscle tendon="cord"/></actuator>
</mujoco>
"""


def test_set_length_range_returns_1_or_raises_mujocos_message():
    model = load_model_from_xml(MUSCLE_XML)
    data = SimData(model)
    computed = model.actuator_lengthrange.copy()       # by the compiler
    assert functions.mj_setLengthRange(model, data, 0, mjcffi.MjLROpt(), "", 0) == 1
    np.testing.assert_array_equal(model.actuator_lengthrange, computed)
    again = mjcffi.MjLROpt()
    again.useexisting = 0                              # this arm does not converge
    with pytest.raises(mjcffi.FatalError, match="did not converge"):
        functions.mj_setLengthRange(model, data, 0, again, "", 0)


def test_save_last_xml_failure_goes_to_the_error_callback(tmp_path, sim, error_callback):
    model, _ = sim
    directory = tmp_path / "no_such_dir" / "saved.xml"
    functions.mj_saveLastXML(str(directory), model, "", 0)
    assert len(error_callback) == 1


# ------------------------------------------------------ the other changes

def test_activate_and_deactivate_are_harmless():
    assert functions.mj_activate("mjkey.txt") == 1
    assert functions.mj_deactivate() is None


def test_move_camera_ignores_the_scene(sim):
    model, _ = sim
    cam, expected = mjcffi.MjvCamera(), mjcffi.MjvCamera()
    functions.mjv_moveCamera(model, const.MOUSE_ROTATE_V, 0.1, 0.2, mjcffi.MjvScene(), cam)
    mjcffi.mjv_moveCamera(model, const.MOUSE_ROTATE_V, 0.1, 0.2, expected)
    assert cam.elevation == expected.elevation and cam.azimuth == expected.azimuth
    assert cam.elevation != mjcffi.MjvCamera().elevation


def test_make_connector_is_mjv_connector():
    geom, expected = mjcffi.MjvGeom(), mjcffi.MjvGeom()
    functions.mjv_makeConnector(geom, const.GEOM_CAPSULE, 0.1, 0, 0, 0, 1, 0, 1)
    mjcffi.mjv_connector(expected, const.GEOM_CAPSULE, 0.1, np.zeros(3), np.array([1.0, 0, 1]))
    np.testing.assert_array_equal(geom.pos, expected.pos)
    np.testing.assert_array_equal(geom.size, expected.size)
    np.testing.assert_array_equal(geom.mat, expected.mat)


def test_ui_add_takes_one_definition():
    ui = mjcffi.MjUI()
    section = mjcffi.MjuiDef()
    section.type, section.name = mjcffi.mjtItem.mjITEM_SECTION, "Section"
    functions.mjui_add(ui, section)
    separator = mjcffi.MjuiDef()
    separator.type, separator.name = mjcffi.mjtItem.mjITEM_SEPARATOR, "separator"
    functions.mjui_addToSection(ui, 0, separator)
    assert ui.nsect == 1 and ui.sect[0].nitem == 1


# ------------------------------------------------------------- the module

def _wrappers_text():
    reason = simfunctions.missing_wheel()
    if reason:
        pytest.skip(reason)
    from conformance import _mujoco_py_wheel
    with zipfile.ZipFile(_mujoco_py_wheel.cached_wheel()) as archive:
        return archive.read("mujoco_py/generated/wrappers.pxi").decode()


def _mujoco_py_signatures():
    """{name: [parameter]} of every `def _mj...` of wrappers.pxi, read here on its own."""
    found = {}
    for name, params in re.findall(r"^def _(mj\w*)\((.*)\):", _wrappers_text(), re.M):
        params = re.sub(r"\[[^\]]*\]", "", params)       # np.ndarray[...] holds commas
        found[name] = [p.split()[-1] for p in params.split(",") if p.strip()]
    return found


def test_every_function_of_mujoco_py_has_its_signature_or_is_removed():
    signatures = _mujoco_py_signatures()
    assert len(signatures) > 200
    assert list(generated.NAMES) == list(signatures)
    assert functions.__all__ == list(signatures)
    for name, params in signatures.items():
        function = getattr(functions, name)
        if name in functions.REMOVED:
            assert functions.REMOVED[name].strip(), name
        assert list(inspect.signature(function).parameters) == params, name


def test_removed_functions_raise_not_implemented_error_naming_themselves():
    assert set(functions.REMOVED) == EXPECTED_REMOVED
    for name, reason in functions.REMOVED.items():
        count = len(inspect.signature(getattr(functions, name)).parameters)
        with pytest.raises(NotImplementedError, match=rf"^{name}: ") as raised:
            getattr(functions, name)(*[None] * count)
        assert reason in str(raised.value)


def test_full_m_points_to_mjcffis(sim):
    model, data = sim
    with pytest.raises(NotImplementedError, match=r"mjcffi\.functions\.mj_fullM\(m, d, dst\)"):
        functions.mj_fullM(model, np.zeros(model.nv ** 2), np.zeros(model.nM))


def test_changed_and_removed_tables():
    assert set(functions.CHANGED) <= set(functions.__all__)
    assert not set(functions.CHANGED) & set(functions.REMOVED)
    for name in ("mj_saveLastXML", "mj_loadXML", "mju_mulMatVec", "mj_addM", "mjv_moveCamera",
                 "mju_rotVecMat", "mju_error_i"):
        assert name in functions.CHANGED, name
    assert "error_sz" in functions.CHANGED["mj_saveLastXML"]
    for name in ("mj_step", "mju_quat2Mat", "mj_jac"):
        assert name not in functions.CHANGED, name       # same arguments (arrays viewed)


def test_mjcffi_only_functions_keep_the_official_signature():
    assert "mj_jacDot" not in functions.__all__
    assert list(inspect.signature(functions.mj_jacDot).parameters) == \
        list(inspect.signature(mjcffi.functions.mj_jacDot).parameters)
    assert functions.mj_jacDot.__wrapped__ is mjcffi.functions.mj_jacDot
    # where both have it, mujoco-py's signature is the one here
    assert list(inspect.signature(functions.mj_step).parameters) == ["m", "d"]
    assert "nstep" in inspect.signature(mjcffi.functions.mj_step).parameters


def test_star_import_gives_mujoco_py_names():
    namespace = {}
    exec("from mjcffi.sim.functions import *", namespace)
    assert {"mj_step", "mju_rotVecMat", "mj_findFileVFS", "mj_activate"} <= set(namespace)
    assert "mj_jacDot" not in namespace


def test_the_generated_module_says_it_is_generated_and_from_what():
    with open(generated.__file__) as f:
        assert "generated by codegen" in f.readline()
    assert "wrappers.pxi" in generated.__doc__ and "mujoco_py-2.1.2.14" in generated.__doc__
    assert set(generated.HAND_WRITTEN) <= {"mj_defaultVFS", "mj_deleteVFS", "mj_addFileVFS",
                                           "mj_deleteFileVFS", "mj_findFileVFS"}
    for name in generated.HAND_WRITTEN:
        assert getattr(functions, name).__module__ == functions.__name__
    assert os.path.basename(generated.__file__) == "functions.py"


def test_a_fatal_error_in_a_mapped_function_goes_to_the_callback(sim, error_callback):
    model, data = sim
    functions.mju_error_i("stop %d", 1)
    assert error_callback == [b"stop 1"]
