"""The official `mujoco` package's public names, and its submodule imports, in mjcffi."""

import os
import pathlib
import re
import subprocess
import sys

import pytest

import mjcffi
from mjcffi._support import stringtables as _stringtables

REPO = pathlib.Path(__file__).resolve().parent.parent

# Official public names mjcffi has not yet, and who brings them.  A name leaving
# this list is fine; a name joining it (a new gap) fails test_no_new_missing_names.
NOT_YET = {
    # the official's rendering package (mjcffi's is mjcffi.rendering, not the same layout)
    "rendering",
    # spec byte vectors read as bytes (issue 13: no class of their own)
    "MjByteVec",
    # an exception class of the official's C++ layer
    "UnexpectedError",
}
# Modules and typing names that the official's __init__ imports for its own use.
INCIDENTAL = {"Any", "IO", "Sequence", "TypeAlias", "Union", "ctypes", "np", "os", "platform",
              "subprocess", "warnings", "zipfile", "mujoco"}


def test_no_new_missing_names(mujoco):
    import importlib.util
    official = {n for n in dir(mujoco) if not n.startswith("_")}
    missing = official - set(dir(mjcffi)) - INCIDENTAL
    # an official submodule is an attribute of `mujoco` once any test imported it
    # (mujoco.egl, ...): mjcffi has it when its own submodule of that name exists
    missing = {n for n in missing if importlib.util.find_spec(f"mjcffi.{n}") is None}
    assert missing <= NOT_YET, sorted(missing - NOT_YET)


def test_every_name_in_dir_resolves():
    for name in dir(mjcffi):
        getattr(mjcffi, name)


# ----------------------------------------------------------- string tables

ENUM_OF = {"mjDISABLESTRING": ("mjtDisableBit", "mjNDISABLE"),
           "mjENABLESTRING": ("mjtEnableBit", "mjNENABLE"),
           "mjTIMERSTRING": ("mjtTimer", "mjNTIMER"),
           "mjLABELSTRING": ("mjtLabel", "mjNLABEL"),
           "mjFRAMESTRING": ("mjtFrame", "mjNFRAME"),
           "mjVISSTRING": ("mjtVisFlag", "mjNVISFLAG"),
           "mjRNDSTRING": ("mjtRndFlag", "mjNRNDFLAG"),
           "mjTOPICSTRING": ("mjtLogTopic", "mjNTOPIC")}


def test_the_tables_are_every_string_array_of_the_headers():
    cdef = (REPO / "mjcffi" / "_c" / "generated" / "cdef.h").read_text()
    declared = re.findall(r"extern const char\s*\*\s*(\w+)\[", cdef)
    assert tuple(declared) == _stringtables.NAMES == tuple(ENUM_OF)


@pytest.mark.parametrize("name", list(ENUM_OF))
def test_each_table_has_one_entry_per_enum_value(name):
    enum, count = ENUM_OF[name]
    table = getattr(mjcffi, name)
    assert isinstance(table, tuple) and len(table) == getattr(getattr(mjcffi, enum), count)
    width = 3 if name in ("mjVISSTRING", "mjRNDSTRING") else None
    for entry in table:
        if width:
            assert isinstance(entry, tuple) and len(entry) == width
            assert all(isinstance(text, str) for text in entry)
        else:
            assert isinstance(entry, str)


def test_the_tables_equal_the_official_ones(mujoco):
    assert mjcffi.mjDISABLESTRING[11] == "Actuation"        # mjDSBL_ACTUATION == 1 << 11
    assert mjcffi.mjVISSTRING[mjcffi.mjtVisFlag.mjVIS_INERTIA] == ("Inertia", "0", "I")
    for name in ENUM_OF:
        if hasattr(mujoco, name):       # the official has no mjTOPICSTRING
            assert getattr(mjcffi, name) == getattr(mujoco, name), name


def test_the_mjsc_flags(mujoco):
    for name, value in (("mjSC_IN", 1), ("mjSC_OUT", 2), ("mjSC_INOUT", 3)):
        assert getattr(mjcffi, name) == getattr(mujoco, name) == value


def test_the_folders_of_mujoco_core(mujoco):
    assert os.path.isfile(os.path.join(mjcffi.HEADERS_DIR, "mujoco.h"))
    assert os.path.samefile(mjcffi.HEADERS_DIR, mujoco.HEADERS_DIR)
    assert os.path.samefile(mjcffi.PLUGINS_DIR, mujoco.PLUGINS_DIR)


def test_model_and_data_addresses():
    model = mjcffi.MjModel.from_xml_string("<mujoco/>")
    data = mjcffi.MjData(model)
    assert model._address == int(mjcffi.ffi.cast("uintptr_t", model._ptr)) != 0
    assert data._address == int(mjcffi.ffi.cast("uintptr_t", data._ptr)) != model._address


# ------------------------------------------------------- submodule imports

def _run(code):
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            cwd=REPO)
    assert result.returncode == 0, result.stderr
    return result.stdout


def test_import_loads_none_of_the_lazy_parts():
    loaded = _run("import sys, mjcffi\n"
                  "print(' '.join(sorted(m for m in ('numpy', 'mjcffi._support.plugins', 'mjcffi.vfs',"
                  " 'mjcffi._support.stringtables', 'mjcffi.model') if m in sys.modules)))")
    assert loaded.strip() == ""


def test_submodules_import_by_their_own_names():
    _run("import mjcffi.rollout, mjcffi.sim\n"
         "from mjcffi import batch, minimize, rollout\n"
         "import mjcffi\n"
         "assert mjcffi.rollout is rollout and mjcffi.batch is batch\n"
         "assert callable(minimize.least_squares) and callable(rollout.rollout)\n")


def test_submodules_import_through_a_mujoco_alias():
    out = _run(
        "import sys, mjcffi\n"
        "sys.modules['mujoco'] = mjcffi\n"
        "from mujoco import rollout\n"
        "import mujoco.rollout, mujoco.batch\n"
        "from mujoco import minimize\n"
        "from mujoco.rollout import Rollout\n"
        "import mujoco\n"
        "assert mujoco is mjcffi and mujoco.rollout is rollout is sys.modules['mjcffi.rollout']\n"
        "assert sys.modules['mujoco.rollout'] is rollout and Rollout is rollout.Rollout\n"
        "assert rollout.__spec__.name == 'mjcffi.rollout'\n"
        "assert mujoco.batch is sys.modules['mjcffi.batch'] and minimize is mjcffi.minimize\n"
        "copies = [n for n, m in sys.modules.items() if n.startswith('mujoco.')\n"
        "          and m is not sys.modules.get('mjcffi.' + n[7:])]\n"
        "assert not copies, copies\n"
        "try:\n    import mujoco.no_such_module\n"
        "except ModuleNotFoundError as exc:\n    print(exc.name)\n")
    assert out.strip() == "mujoco.no_such_module"
