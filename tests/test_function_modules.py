"""The function layer is one module per section of mujoco.h, each imported on first use of
one of its names, so that a process without .pyc files compiles only what it calls
(issue 35).  `mjcffi._functions` stays the path of every generated name."""

import json
import os
import subprocess
import sys

import pytest

import mjcffi
import mjcffi.functions
from mjcffi import _functions
from mjcffi._generated import funcinfo


def _run(code, **env):
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env=dict(os.environ, **env))
    return json.loads(out.stdout.splitlines()[-1])


_LOADED = ("import json, sys\n"
           "def loaded():\n"
           "    return sorted(k[len('mjcffi._functions.'):] for k in sys.modules\n"
           "                  if k.startswith('mjcffi._functions.'))\n")


def test_a_first_step_compiles_no_section_of_the_function_layer(tmp_path):
    # no .pyc read or written: every module imported here is compiled from source
    code = _LOADED + (
        "import mjcffi as mj\n"
        "m = mj.MjModel.from_xml_string('<mujoco><worldbody><geom size=\".1\"/>"
        "</worldbody></mujoco>')\n"
        "d = mj.MjData(m); mj.mj_step(m, d); mj.mj_forward(m, d)\n"
        "after_step = loaded()\n"
        "mj.mju_zero(d.qacc)\n"
        "print(json.dumps([after_step, loaded()]))\n")
    after_step, after_mju = _run(code, PYTHONDONTWRITEBYTECODE="1",
                                 PYTHONPYCACHEPREFIX=str(tmp_path))
    assert after_step == []          # mj_step and mj_forward are hand-written
    assert after_mju == ["_common", "vector_math"]
    assert list(tmp_path.iterdir()) == []


def test_each_name_resolves_to_the_module_that_defines_it():
    for name, module in _functions._MODULE_OF.items():
        value = getattr(_functions, name)
        assert value is getattr(sys.modules[f"mjcffi._functions.{module}"], name)
        # named after the package, as the official functions are after mujoco._functions
        assert value.__module__ == "mjcffi._functions", name


def test_names_are_every_function_of_the_headers_in_order():
    assert _functions.NAMES == tuple(funcinfo.FUNCTIONS) == mjcffi.functions.NAMES
    generated = {n for n in _functions._MODULE_OF if not n.startswith("_")}
    hand_written = set(_functions.NAMES) - generated
    assert hand_written == set(_functions.HAND_WRITTEN_DOCS)
    assert {"mj_step", "mj_forward", "mj_name2id"} <= hand_written
    for name in _functions.NAMES:
        # every public function, generated or hand-written, resolves through mjcffi
        assert callable(getattr(mjcffi, name)), name
        assert funcinfo.FUNCTIONS[name].doc in (getattr(mjcffi, name).__doc__ or ""), name


def test_the_official_paths_still_resolve():
    from mjcffi._functions import _realloc_con_efc, _realloc_island, mj_jac, _mj_jac
    assert callable(_realloc_con_efc) and callable(_realloc_island)
    assert mj_jac is mjcffi.mj_jac and callable(_mj_jac)
    assert mjcffi._functions is _functions
    assert {"mj_jac", "_mj_jac", "_bind_mj_jac", "_realloc_island"} <= set(dir(_functions))


@pytest.mark.parametrize("where", [_functions, mjcffi.functions])
def test_an_unknown_name_is_an_attribute_error(where):
    with pytest.raises(AttributeError, match="mj_nosuchfunction"):
        where.mj_nosuchfunction
    assert not hasattr(where, "_mj_nosuchfunction")


def test_the_sections_hold_what_mujoco_h_declares_under_them():
    assert _functions._MODULE_OF["mj_jac"] == "support"
    assert _functions._MODULE_OF["mju_add3"] == "vector_math"
    assert _functions._MODULE_OF["mjv_updateScene"] == "visualization"
    assert _functions._MODULE_OF["mjr_render"] == "opengl_rendering"
    assert _functions._MODULE_OF["mjs_addBody"] == "tree_elements"
    batch = {n for n, m in _functions._MODULE_OF.items() if m == "batch"}
    assert batch and all(n.lstrip("_").removeprefix("bind_").startswith("mjb") for n in batch)


def test_the_hand_written_functions_are_on_the_official_private_path_too():
    # the official mujoco._functions holds mj_step; mjcffi's is hand-written, a tier up
    for name in _functions.HAND_WRITTEN_DOCS:
        assert getattr(_functions, name) is getattr(mjcffi, name), name
    assert set(_functions.HAND_WRITTEN_DOCS) <= set(dir(_functions))
    out = _run("import json, sys, mjcffi\n"
               "sys.modules['mujoco'] = mjcffi\n"
               "import mujoco._functions\n"
               "from mujoco._functions import mj_forward\n"
               "print(json.dumps([mujoco._functions.mj_step is mjcffi.mj_step,\n"
               "                  mj_forward is mjcffi.mj_forward]))\n")
    assert out == [True, True]
