"""Every MJAPI function of mujoco.h and mjbatch.h reaches Python through mjcffi.lib.

The list of functions comes from a scan of the header text written here,
independent of codegen's pycparser-based list.
"""

import re

import pytest

import mjcffi
from mjcffi._generated import funcinfo as _funcinfo


def _scan_mjapi_functions(text):
    """Names of the functions declared `MJAPI ...(...);`, found without a C parser."""
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    names = []
    for statement in text.split(";"):
        statement = " ".join(statement.split())
        start = statement.find("MJAPI ")
        if start < 0:
            continue
        statement = statement[start + len("MJAPI "):]
        if statement.startswith("extern ") or "(" not in statement:
            continue
        names.append(statement[:statement.index("(")].split()[-1].lstrip("*"))
    return names


@pytest.fixture(scope="module")
def declared(mujoco_include):
    names = []
    for header in ("mujoco.h", "mjbatch.h"):
        names += _scan_mjapi_functions((mujoco_include / "mujoco" / header).read_text())
    return names


def test_scan_finds_the_whole_api(declared):
    # mujoco.h declares well over 500 functions; a broken scan finds few.
    assert len(declared) > 500
    assert len(set(declared)) == len(declared)
    for name in ("mj_step", "mj_loadXML", "mju_error", "mjv_updateScene", "mjb_makeBatch",
                 "mjb_rollout"):
        assert name in declared


def test_every_declared_function_is_in_lib(declared):
    missing = [name for name in declared if not hasattr(mjcffi.lib, name)]
    assert missing == []


def test_function_metadata_covers_exactly_the_declared_functions(declared):
    assert sorted(_funcinfo.FUNCTIONS) == sorted(declared)


def test_function_metadata_of_known_signatures():
    load = _funcinfo.FUNCTIONS["mj_loadXML"]
    assert [a.name for a in load.args] == ["filename", "vfs", "error", "error_sz"]
    assert [a.nullable for a in load.args] == [False, True, True, False]
    assert load.args[0].const and load.args[0].elem == "char"
    assert load.restype == "mjModel *"
    assert "Parse XML file" in load.doc and "Nullable" not in load.doc

    add3 = _funcinfo.FUNCTIONS["mju_add3"]
    assert [(a.name, a.extents, a.const) for a in add3.args] == [
        ("res", (3,), False), ("vec1", (3,), True), ("vec2", (3,), True)]

    step = _funcinfo.FUNCTIONS["mj_step"]
    assert [(a.elem, a.pointer, a.const) for a in step.args] == [
        ("mjModel", 1, True), ("mjData", 1, False)]


def test_every_function_has_its_header_doc():
    undocumented = [name for name, f in _funcinfo.FUNCTIONS.items() if not f.doc.strip()]
    assert undocumented == []


def test_extern_globals_are_reachable():
    lib = mjcffi.lib
    for name in ("mjcb_control", "mjcb_passive", "mju_user_error", "mju_user_warning",
                 "mju_user_malloc"):
        assert hasattr(lib, name), name
    assert mjcffi.ffi.string(lib.mjDISABLESTRING[0]) == b"Constraint"
