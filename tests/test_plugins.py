"""MuJoCo's first-party plugins: registered on first use, and stepped bit-identically."""

import copy
import ctypes
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import mjcffi
from mjcffi._support import plugins

REPO = pathlib.Path(__file__).resolve().parent.parent

PID_XML = """<mujoco>
  <extension><plugin plugin="mujoco.pid"/></extension>
  <worldbody>
    <body pos="0 0 1">
      <joint name="j" type="slide" axis="0 0 1"/>
      <geom size=".1"/>
    </body>
  </worldbody>
  <actuator>
    <plugin plugin="mujoco.pid" joint="j" actdim="2">
      <config key="kp" value="10"/><config key="ki" value="2"/>
      <config key="kd" value="1"/><config key="slewmax" value="1"/>
    </plugin>
  </actuator>
</mujoco>"""


def _run(code):
    """Run `code` in a fresh interpreter; its stdout, after checking it exited cleanly."""
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            cwd=REPO)
    assert result.returncode == 0, result.stderr
    return result.stdout.split()


def test_import_registers_nothing_and_the_first_model_registers_the_plugins():
    before, after = _run(
        "import mjcffi\n"
        "print(mjcffi.lib.mjp_pluginCount())\n"
        f"mjcffi.MjModel.from_xml_string({PID_XML!r})\n"
        "print(mjcffi.lib.mjp_pluginCount())\n")
    assert before == "0" and int(after) >= 1


def test_a_function_looked_up_registers_them_too(tmp_path):
    path = tmp_path / "pid.xml"
    path.write_text(PID_XML)
    (nplugin,) = _run(f"import mjcffi\nprint(mjcffi.mj_loadXML({str(path)!r}).nplugin)")
    assert nplugin == "1"


def test_the_handles_are_the_libraries_of_the_plugin_folder():
    names = sorted(os.path.basename(h._name) for h in mjcffi.PLUGIN_HANDLES)
    assert names and names == sorted(f for f in os.listdir(mjcffi.PLUGINS_DIR)
                                     if f.endswith(".so"))
    assert all(isinstance(h, ctypes.CDLL) for h in mjcffi.PLUGIN_HANDLES)
    slot = mjcffi.ffi.new("int *")
    assert mjcffi.lib.mjp_getPlugin(b"mujoco.pid", slot) != mjcffi.ffi.NULL


def test_both_bindings_in_one_process_share_the_registrations():
    counts = _run("import mjcffi\n"
                  f"mjcffi.MjModel.from_xml_string({PID_XML!r})\n"
                  "n = mjcffi.lib.mjp_pluginCount()\n"
                  "import mujoco\n"
                  f"mujoco.MjModel.from_xml_string({PID_XML!r})\n"
                  "print(n, mjcffi.lib.mjp_pluginCount())\n")
    assert counts[0] == counts[1]


def test_a_broken_library_warns_and_the_others_load(tmp_path, monkeypatch):
    good = sorted(p for p in os.listdir(mjcffi.PLUGINS_DIR) if p.endswith(".so"))[0]
    (tmp_path / "libbroken.so").write_bytes(b"not a shared library")
    (tmp_path / "README.txt").write_text("not a library either")
    (tmp_path / "sub").mkdir()
    os.symlink(os.path.join(mjcffi.PLUGINS_DIR, good), tmp_path / "sub" / good)
    monkeypatch.setattr(plugins, "PLUGINS_DIR", str(tmp_path))
    monkeypatch.setattr(plugins, "_loaded", False)
    monkeypatch.setattr(plugins, "_handles", [])
    with pytest.warns(RuntimeWarning, match="libbroken.so"), \
            pytest.warns(ImportWarning, match="README.txt"):
        plugins.load_bundled()
    assert [os.path.basename(h._name) for h in plugins.PLUGIN_HANDLES] == [good]


def _pid_pair(mujoco):
    ours = mjcffi.MjModel.from_xml_string(PID_XML)
    official = mujoco.MjModel.from_xml_string(PID_XML)
    return (ours, mjcffi.MjData(ours)), (official, mujoco.MjData(official))


def test_a_pid_model_steps_bit_identically_to_the_official(mujoco):
    (m, d), (om, od) = _pid_pair(mujoco)
    assert m.nplugin == om.nplugin == 1 and m.na == 2
    for i in range(500):
        d.ctrl[:] = od.ctrl[:] = np.sin(i / 25)
        mjcffi.mj_step(m, d)
        mujoco.mj_step(om, od)
    for field in ("qpos", "qvel", "act", "plugin_state"):
        assert np.array_equal(getattr(d, field), getattr(od, field)), field
    assert np.any(d.act != 0)


def test_copies_of_plugin_data_step_alike_with_their_own_instances(mujoco):
    (m, d), _ = _pid_pair(mujoco)
    d.ctrl[:] = 0.3
    mjcffi.mj_step(m, d, 20)
    copies = [copy.copy(d), copy.deepcopy(d)]
    assert copies[0].model is m and copies[1].model is not m
    assert copies[1].model._address != m._address
    for other in copies:
        assert other.plugin_data[0] != d.plugin_data[0]
    for data in [d, *copies]:
        mjcffi.mj_step(data.model, data, 20)
    for other in copies:
        assert np.array_equal(other.qpos, d.qpos) and np.array_equal(other.act, d.act)


def test_pickled_plugin_data_gets_its_own_plugin_instance():
    # in a subprocess: two datas sharing one plugin instance end in a double free
    same, distinct = _run(
        "import pickle, numpy as np, mjcffi\n"
        f"m = mjcffi.MjModel.from_xml_string({PID_XML!r}); d = mjcffi.MjData(m)\n"
        "d.ctrl[:] = 0.5; mjcffi.mj_step(m, d, 30)\n"
        "e = pickle.loads(pickle.dumps(d))\n"
        "mjcffi.mj_step(m, d, 30); mjcffi.mj_step(e.model, e, 30)\n"
        "print(np.array_equal(d.qpos, e.qpos) and np.array_equal(d.act, e.act))\n"
        "print(e.plugin_data[0] != d.plugin_data[0])\n"
        "del d, e\n")
    assert same == distinct == "True"
