"""The official package's pure-Python subpackages on mjcffi: mjcffi.sysid, .usd,
.msh2obj, .introspect and .mjx (mjcffi/_support/official_source.py).

Their own test files run under `python -m conformance` (CONFORMANCE.md); these check
the machinery: the official source runs on mjcffi and never on an official compiled
module, a module is in sys.modules under both names from the start of its import,
missing extras are named, and the official package keeps working beside it.
"""

import importlib
import importlib.util
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import mjcffi
from mjcffi._support import official_source

OFFICIAL = pathlib.Path(importlib.util.find_spec("mujoco").origin).parent
HAS_PXR = importlib.util.find_spec("pxr") is not None
HAS_MJX = (OFFICIAL / "mjx").is_dir() and importlib.util.find_spec("jax") is not None
HAS_SYSID = all(importlib.util.find_spec(name) is not None
                for name in ("tabulate", "plotly", "colorama", "yaml", "jinja2"))

# what the subprocess checks print: every official compiled module it has loaded
_NO_OFFICIAL_SO = f"""
import sys
official = {str(OFFICIAL)!r}
loaded = sorted(name for name, module in list(sys.modules.items())
                if (getattr(module, "__file__", None) or "").startswith(official)
                and module.__file__.endswith(".so"))
print("OFFICIAL-SO", loaded)
"""


def _run(code, timeout=300):
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=timeout)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def _official_so(out):
    line = next(line for line in out.splitlines() if line.startswith("OFFICIAL-SO"))
    return line.removeprefix("OFFICIAL-SO ")


@pytest.mark.parametrize("name, needed", [
    ("msh2obj", True), ("introspect.structs", True), ("sysid", HAS_SYSID),
    ("usd.exporter", HAS_PXR), ("mjx", HAS_MJX)])
def test_under_the_swap_no_official_compiled_module_is_imported(name, needed):
    if not needed:
        pytest.skip(f"mujoco.{name} needs packages not installed here")
    out = _run(f"""
import sys
import mjcffi
sys.modules["mujoco"] = mjcffi
import mujoco.{name} as module
top = sys.modules["mujoco.{name.split('.')[0]}"]
assert top is sys.modules["mjcffi.{name.split('.')[0]}"], top
assert module is sys.modules["mjcffi.{name}"]
assert module.__name__ == "mjcffi.{name}", module.__name__
assert module.__file__.startswith({str(OFFICIAL)!r}), module.__file__
# every module of the subpackage: under both names, one object
for key, value in list(sys.modules.items()):
    if key.startswith("mujoco.{name.split('.')[0]}"):
        assert sys.modules["mjcffi" + key[len("mujoco"):]] is value, key
{_NO_OFFICIAL_SO}""")
    assert _official_so(out) == "[]"


def test_the_official_source_gets_mjcffi_for_mujoco_without_the_swap():
    msh2obj = importlib.import_module("mjcffi.msh2obj")
    structs = importlib.import_module("mjcffi.introspect.structs")
    assert msh2obj.__file__ == str(OFFICIAL / "msh2obj.py")
    assert "mujoco.msh2obj" not in sys.modules or sys.modules["mujoco.msh2obj"] is not msh2obj
    assert structs.__spec__.submodule_search_locations is None
    assert importlib.import_module("mjcffi.introspect").__path__ == [str(OFFICIAL / "introspect")]
    if HAS_PXR:
        exporter = importlib.import_module("mjcffi.usd.exporter")
        assert exporter.mujoco is mjcffi          # `import mujoco` in the official file
        assert exporter.camera_module is sys.modules["mjcffi.usd.camera"]


def test_an_import_inside_an_official_function_gets_mjcffi_too():
    # sysid/report/defaults.py imports mujoco.sysid... inside a function; the test
    # module here does the same through the same builtins
    module = importlib.import_module("mjcffi.introspect")
    namespace = {"__builtins__": module.__builtins__, "__name__": "probe"}
    exec("def f():\n    import mujoco\n    from mujoco import msh2obj\n"
         "    return mujoco, msh2obj\n", namespace)
    got, msh2obj = namespace["f"]()
    assert got is mjcffi and msh2obj is sys.modules["mjcffi.msh2obj"]


def test_the_official_package_keeps_working_beside_it(mujoco):
    ours = importlib.import_module("mjcffi.msh2obj")
    theirs = importlib.import_module("mujoco.msh2obj")
    assert theirs is not ours and theirs.__name__ == "mujoco.msh2obj"
    if HAS_SYSID:
        official_sysid = importlib.import_module("mujoco.sysid._src.parameter")
        our_sysid = importlib.import_module("mjcffi.sysid._src.parameter")
        assert official_sysid.mujoco is mujoco and our_sysid.mujoco is mjcffi
    m = mujoco.MjModel.from_xml_string("<mujoco/>")      # the official still loads
    assert m.nq == 0 and type(m).__module__ == "mujoco._structs"


def test_resources_are_the_official_package_data():
    introspect = importlib.resources.files("mjcffi.introspect")
    assert pathlib.Path(str(introspect)) == OFFICIAL / "introspect"
    if HAS_SYSID:
        builder = importlib.import_module("mjcffi.sysid.report.builder")
        assert pathlib.Path(builder.TEMPLATE_DIR).is_dir()


@pytest.mark.skipif(not HAS_MJX, reason="jax and mujoco-mjx are not installed")
def test_mjx_test_data_resolves_under_the_swap():
    out = _run("""
import importlib.resources, sys
import mjcffi
sys.modules["mujoco"] = mjcffi
print("DATA", importlib.resources.files("mujoco.mjx") / "test_data")
""")
    data = next(line for line in out.splitlines() if line.startswith("DATA"))[5:]
    assert pathlib.Path(data) == OFFICIAL / "mjx" / "test_data"
    assert pathlib.Path(data).is_dir()


def _tetra_msh(path):
    header = np.array([4, 0, 0, 4], dtype=np.int32)
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32)
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.int32)
    path.write_bytes(header.tobytes() + vertices.tobytes() + faces.tobytes())


def test_python_m_msh2obj_keeps_its_command_line(tmp_path):
    _tetra_msh(tmp_path / "t.msh")
    done = subprocess.run([sys.executable, "-m", "mjcffi.msh2obj", "-i", str(tmp_path / "t.msh"),
                           "-o", str(tmp_path / "t.obj")], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    obj = (tmp_path / "t.obj").read_text()
    assert obj.count("\nv ") + obj.startswith("v ") == 4 and "f 1 3 2" in obj
    model = mjcffi.MjModel.from_xml_string(
        '<mujoco><asset><mesh name="t" file="t.obj"/></asset></mujoco>',
        {"t.obj": obj.encode()})
    assert model.mesh_vertnum[0] == 4
    helped = subprocess.run([sys.executable, "-m", "mjcffi.msh2obj", "--help"],
                            capture_output=True, text=True, timeout=120)
    assert helped.returncode == 0 and "--input" in helped.stdout


def test_python_m_runs_the_script_on_mjcffi(tmp_path):
    # a script of the official package run with -m gets mjcffi for `import mujoco`
    root = tmp_path / "mujoco"
    (root / "introspect").mkdir(parents=True)
    (root / "__init__.py").write_text("raise ImportError('the official package ran')\n")
    (root / "introspect" / "__init__.py").write_text("")
    (root / "introspect" / "probe.py").write_text(
        "import mujoco\nif __name__ == '__main__':\n    print('MUJOCO', mujoco.__name__)\n")
    out = _run(f"""
import runpy, sys
import mjcffi      # first: it finds its libmujoco in the real package
sys.path.insert(0, {str(tmp_path)!r})
runpy.run_module("mjcffi.introspect.probe", run_name="__main__", alter_sys=True)
""")
    assert "MUJOCO mjcffi" in out


def test_a_module_is_in_sys_modules_under_both_names_while_it_runs(tmp_path):
    # what MJX does: its package imports its own submodules during its import, by the
    # `mujoco.` name; they must find the package already there under that name
    root = tmp_path / "mujoco"
    (root / "introspect").mkdir(parents=True)
    (root / "__init__.py").write_text("")
    (root / "introspect" / "__init__.py").write_text(
        "import sys\n"
        "SEEN = sys.modules.get('mujoco.introspect') is sys.modules.get('mjcffi.introspect')\n"
        "from mujoco.introspect import sub\n")
    (root / "introspect" / "sub.py").write_text(
        "import sys\n"
        "SEEN = sys.modules.get('mujoco.introspect.sub') is sys.modules['mjcffi.introspect.sub']\n"
        "PARENT = sys.modules['mujoco.introspect'] is sys.modules['mjcffi.introspect']\n")
    out = _run(f"""
import sys
import mjcffi      # first: it finds its libmujoco in the real package
sys.path.insert(0, {str(tmp_path)!r})
sys.modules["mujoco"] = mjcffi
import mujoco.introspect as package
assert package.__file__.startswith({str(tmp_path)!r}), package.__file__
print("SEEN", package.SEEN, package.sub.SEEN, package.sub.PARENT)
""")
    assert "SEEN True True True" in out


def test_a_failed_import_leaves_neither_name_behind(tmp_path):
    root = tmp_path / "mujoco"
    (root / "introspect").mkdir(parents=True)
    (root / "__init__.py").write_text("")
    (root / "introspect" / "__init__.py").write_text("raise RuntimeError('broken')\n")
    out = _run(f"""
import sys
import mjcffi      # first: it finds its libmujoco in the real package
sys.path.insert(0, {str(tmp_path)!r})
sys.modules["mujoco"] = mjcffi
try:
    import mujoco.introspect
except RuntimeError as error:
    print("RAISED", error)
print("LEFT", [n for n in sys.modules if n.endswith(".introspect")])
""")
    assert "RAISED broken" in out and "LEFT []" in out


def _blocked(module, code):
    """Run `code` with the import of `module` failing as if it were not installed."""
    return subprocess.run([sys.executable, "-c", f"""
import sys
class Block:
    @staticmethod
    def find_spec(name, path=None, target=None):
        if name.partition(".")[0] == {module!r}:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
sys.meta_path.insert(0, Block)
{code}
"""], capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("module, subpackage, extra", [
    ("pxr", "usd.exporter", "usd"), ("jax", "mjx", "mjx"), ("tabulate", "sysid._src.parameter",
                                                             "sysid")])
def test_a_missing_dependency_names_the_extra(module, subpackage, extra):
    done = _blocked(module, f"""
try:
    import mjcffi.{subpackage}
except ModuleNotFoundError as error:
    print("ERROR", error.name, "|", error)
""")
    assert done.returncode == 0, done.stderr
    if subpackage == "mjx" and not (OFFICIAL / "mjx").is_dir():
        assert f"pip install 'mjcffi[{extra}]'" in done.stdout and "mujoco-mjx" in done.stdout
        return
    line = next(line for line in done.stdout.splitlines() if line.startswith("ERROR"))
    assert line.startswith(f"ERROR {module}") and f"pip install 'mjcffi[{extra}]'" in line


def test_the_official_guard_of_an_optional_import_still_catches_it():
    # usd/exporter_test.py: `except ModuleNotFoundError: exporter_module = None`
    done = _blocked("pxr", """
import mjcffi
sys.modules["mujoco"] = mjcffi
try:
    from mujoco.usd import exporter
except ModuleNotFoundError:
    exporter = None
print("EXPORTER", exporter)
""")
    assert "EXPORTER None" in done.stdout, done.stderr


def test_an_absent_distribution_is_named_with_its_extra(tmp_path, monkeypatch):
    root = tmp_path / "mujoco"
    root.mkdir()
    (root / "__init__.py").write_text("")
    monkeypatch.setattr(official_source, "official_roots", lambda: [str(root)])
    monkeypatch.delitem(sys.modules, "mjcffi.mjx", raising=False)
    with pytest.raises(ModuleNotFoundError, match=r"mujoco-mjx is not installed: "
                                                  r"pip install 'mjcffi\[mjx\]'"):
        importlib.import_module("mjcffi.mjx")
    assert "mjcffi.mjx" not in sys.modules


def test_a_compiled_official_module_is_refused(tmp_path):
    # mujoco-usd puts compiled modules into mujoco/usd/: they are the official
    # bindings' own, and must not load as mjcffi.usd.<name>
    root = tmp_path / "mujoco"
    (root / "usd").mkdir(parents=True)
    (root / "__init__.py").write_text("")
    (root / "usd" / "__init__.py").write_text("")
    suffix = importlib.machinery.EXTENSION_SUFFIXES[0]
    (root / "usd" / f"writer{suffix}").write_bytes(b"")
    out = _run(f"""
import sys
import mjcffi      # first: it finds its libmujoco in the real package
sys.path.insert(0, {str(tmp_path)!r})
try:
    import mjcffi.usd.writer
except ModuleNotFoundError as error:
    print("REFUSED", error)
""")
    assert "REFUSED mujoco.usd.writer is compiled against the official" in out


def test_other_names_pass_by():
    assert official_source.OfficialSourceFinder.find_spec("mjcffi.rollout") is None
    assert official_source.OfficialSourceFinder.find_spec("mujoco.sysid") is None
    assert official_source.OfficialSourceFinder.find_spec("mjcffi") is None
    assert official_source.OfficialSourceFinder.find_spec("mjcffi.sysid.no_such") is None
