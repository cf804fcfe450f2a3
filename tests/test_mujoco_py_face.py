"""mjcffi.sim as `mujoco_py`: install_as_mujoco_py() and every module path of mujoco-py
2.1's package, the private name dicts of PyMjModel, and the versions.

The module paths are read from mujoco-py's wheel (cached by the conformance runner),
so a module of the wheel that the face misses fails here without being named.
"""

import json
import os
import subprocess
import sys
import textwrap
import zipfile

import pytest

import mjcffi
import mjcffi.sim as sim
from conformance import _mujoco_py_wheel as wheel

# The wheel's .pyx files other than cymj.pyx are `include`d into cymj: not modules.
_NOT_MODULES = {"mjbatchrenderer", "mjpid", "mjrendercontext", "mjsim", "mjsimstate",
                "opengl_context"}


def _module_paths(wheel_path):
    """Every importable module path of mujoco-py's package but its tests."""
    paths = set()
    with zipfile.ZipFile(wheel_path) as archive:
        for name in archive.namelist():
            if not name.startswith("mujoco_py/") or name.startswith("mujoco_py/tests/"):
                continue
            stem, ext = os.path.splitext(name[len("mujoco_py/"):])
            if ext not in (".py", ".pyx"):
                continue
            parts = stem.split("/")
            if parts[-1] == "__init__":
                parts = parts[:-1]
            if parts and parts[-1] not in _NOT_MODULES:
                paths.add(".".join(parts))
    return sorted(paths)


@pytest.fixture(scope="module")
def module_paths():
    try:
        return _module_paths(wheel.wheel())
    except wheel.WheelUnavailable as error:
        pytest.skip(f"mujoco-py's wheel: PyPI cannot be reached and none is cached: {error}")


def _run(script):
    run = subprocess.run([sys.executable, "-c", textwrap.dedent(script)], capture_output=True,
                         text=True, timeout=120, env=dict(os.environ, MUJOCO_GL="egl"))
    assert run.returncode == 0, run.stderr[-3000:]
    return json.loads(run.stdout.splitlines()[-1])


def test_the_wheel_lists_the_modules_the_issue_names(module_paths):
    assert {"builder", "mjviewer", "mjrenderpool", "generated", "generated.const", "modder",
            "cymj", "utils", "version", "gl", "pxd"} <= set(module_paths)


def test_every_module_path_of_mujoco_py_gives_mjcffi_s_module_itself(module_paths):
    found = _run("""
        import importlib, json, sys
        import mjcffi.sim
        assert mjcffi.sim.install_as_mujoco_py() is mjcffi.sim
        import mujoco_py
        report = {"package": mujoco_py is mjcffi.sim}
        for name in %r + ["const", "functions"]:
            module = importlib.import_module("mujoco_py." + name)
            face = sys.modules.get("mjcffi.sim." + name)
            # a module of the face is that module object; gl and pxd are empty placeholders
            report[name] = module is face if face is not None else module.__doc__
        print(json.dumps(report))
    """ % module_paths)
    assert found.pop("package") is True
    placeholders = {name: found.pop(name) for name in ("gl", "pxd")}
    assert all("mujoco-py's" in doc for doc in placeholders.values())
    assert found == {name: True for name in found}
    assert set(found) == set(module_paths) - {"gl", "pxd"} | {"const", "functions"}


def test_mujoco_py_s_own_import_lines_work_after_the_call():
    found = _run("""
        import json
        import mjcffi.sim
        mjcffi.sim.install_as_mujoco_py()
        mjcffi.sim.install_as_mujoco_py()                 # twice: nothing more happens
        from mujoco_py.mjviewer import MjViewer, MjViewerBasic
        from mujoco_py.builder import cymj, functions, MujocoException, ignore_mujoco_warnings
        from mujoco_py.generated import const
        from mujoco_py.mjrenderpool import MjRenderPool
        from mujoco_py.version import __version__, get_version
        from mujoco_py.utils import rec_copy, rec_assign, remove_empty_lines, discover_mujoco
        from mujoco_py import MjSim, load_model_from_xml
        import mujoco_py, sys
        print(json.dumps({"viewer": MjViewer is mjcffi.sim.MjViewer,
                          "cymj": cymj is mjcffi.sim.cymj,
                          "exception": MujocoException is mjcffi.sim.MujocoException,
                          "const": const.GEOM_BOX == mjcffi.mjtGeom.mjGEOM_BOX,
                          "version": [__version__, get_version()],
                          "finders": sum(type(f).__name__ == "_FaceFinder"
                                         for f in sys.meta_path),
                          "lines": remove_empty_lines("a\\n\\n b\\n")}))
    """)
    assert found == {"viewer": True, "cymj": True, "exception": True, "const": True,
                     "version": ["2.1.2.14", "2.1.2.14"], "finders": 1, "lines": "a\n b"}


def test_install_refuses_when_another_mujoco_py_is_imported():
    found = _run("""
        import json, sys, types
        sys.modules["mujoco_py"] = types.ModuleType("mujoco_py")
        import mjcffi.sim
        try:
            mjcffi.sim.install_as_mujoco_py()
        except RuntimeError as error:
            print(json.dumps(str(error)))
    """)
    assert "mujoco_py is already imported" in found


def test_a_name_that_is_not_mujoco_py_s_is_not_found():
    found = _run("""
        import json
        import mjcffi.sim
        mjcffi.sim.install_as_mujoco_py()
        try:
            import mujoco_py.no_such_module
        except ModuleNotFoundError as error:
            print(json.dumps(error.name))
    """)
    assert found == "mujoco_py.no_such_module"


# ------------------------------------------------------------ name dicts

_XML = """<mujoco><worldbody>
  <body name="torso"><joint name="hinge"/><geom name="ball" size=".1"/><geom size=".1"/>
    <site name="tip"/><camera name="track"/></body>
  <camera name="fixed" pos="0 0 1"/>
</worldbody>
<actuator><motor joint="hinge"/><motor name="m1" joint="hinge"/></actuator></mujoco>"""

# mujoco-py's PyMjModel had these kinds (generated/wrappers.pxi, _extract_mj_names)
_KINDS = ("body", "joint", "geom", "site", "light", "camera", "actuator", "sensor",
          "tendon", "mesh")


def test_pymjmodel_s_name_dicts_are_there_for_every_kind():
    model = sim.load_model_from_xml(_XML)
    for kind in _KINDS:
        name2id, id2name = getattr(model, f"_{kind}_name2id"), getattr(model, f"_{kind}_id2name")
        count = len(id2name)
        names = getattr(model, f"{kind}_names")
        assert name2id == {name: getattr(model, f"{kind}_name2id")(name) for name in names}
        assert all(id2name[i] == getattr(model, f"{kind}_id2name")(i) for i in range(count))
    assert model._camera_name2id == {"fixed": 0, "track": 1}   # the world's first
    assert model._geom_id2name == {0: "ball", 1: None}
    assert model._actuator_name2id == {"m1": 1}
    assert model._body_id2name == {0: "world", 1: "torso"}
    assert model._body_name2id is model._body_name2id       # one dict, as mujoco-py kept


def test_an_environment_picks_its_render_camera_by_name2id():
    # the pattern real environment code uses: camera id from the private dict
    simulation = sim.MjSim(sim.load_model_from_xml(_XML))
    camera_id = simulation.model._camera_name2id["fixed"]
    assert simulation.model.camera_id2name(camera_id) == "fixed"


def test_the_name_dicts_follow_mj_copymodel():
    model = sim.load_model_from_xml(_XML)
    assert model._site_name2id == {"tip": 0}
    other = sim.load_model_from_xml(_XML.replace('name="tip"', 'name="end"'))
    mjcffi.mj_copyModel(model, other)
    assert model._site_name2id == {"end": 0} and model.site_names == ("end",)


# ------------------------------------------------------------ versions

def test_version_is_mujoco_s_and_mjcffi_s_own_is_in_the_metadata():
    from importlib import metadata
    assert mjcffi.__version__ == mjcffi.mj_versionString() == "4.0.0"
    assert mjcffi.__mjcffi_version__ == metadata.version("mjcffi")
    assert sim.__version__ == sim.get_version() == "2.1.2.14"


def test_version_gated_code_takes_its_mujoco_4_path():
    # the comparisons real packages make on mujoco.__version__
    from packaging.version import Version
    assert Version(mjcffi.__version__) >= Version("3.0.0")
    assert Version(mjcffi.__version__) >= Version("2.3.6")
    assert tuple(int(part) for part in mjcffi.__version__.split(".")) >= (2, 3, 6)


def test_the_utils_copy_and_assign_a_struct_recursively():
    from mjcffi.sim import utils
    option = mjcffi.MjvOption()
    option.geomgroup[:] = 1
    saved = utils.rec_copy(option)
    option.geomgroup[:] = 0
    option.frame = 3
    utils.rec_assign(option, saved)
    assert list(option.geomgroup) == [1] * len(option.geomgroup) and option.frame == 0
    assert os.path.exists(os.path.join(utils.discover_mujoco(), "libmujoco.so.4.0.0"))
