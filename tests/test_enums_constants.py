"""Enums and #define constants equal the official binding's and the C compiler's."""

import enum

import pytest

import mjcffi
from mjcffi._generated import constants as _constants, enums as _enums

CONSTANTS = [name for name in vars(_constants) if name.startswith("mj")]


def test_enums_are_intenums_reachable_from_the_package():
    assert len(_enums.__all__) > 70
    for name in _enums.__all__:
        cls = getattr(mjcffi, name)
        assert issubclass(cls, enum.IntEnum), name
    assert mjcffi.mjtObj.mjOBJ_BODY == 1
    assert mjcffi.mjtObj(1) is mjcffi.mjtObj.mjOBJ_BODY


def test_enums_equal_the_official_binding(mujoco):
    compared = 0
    for name in _enums.__all__:
        ours = getattr(_enums, name)
        theirs = getattr(mujoco, name)
        their_members = {k: int(v) for k, v in theirs.__members__.items()}
        our_members = {k: int(v) for k, v in ours.__members__.items()}
        assert our_members == their_members, name
        compared += len(our_members)
    assert compared > 500


def test_constants_equal_the_official_binding(mujoco):
    shared = [name for name in CONSTANTS if hasattr(mujoco, name)]
    assert len(shared) >= 25   # mjPI, mjMINVAL, mjNREF, ... are all official
    for name in shared:
        ours, theirs = getattr(_constants, name), getattr(mujoco, name)
        assert ours == theirs and type(ours) is type(theirs), name
    for name in ("mjPI", "mjMINVAL", "mjMAXVAL", "mjMINMU", "mjNREF", "mjNIMP", "mjVERSION_HEADER"):
        assert name in shared


def test_every_constant_equals_the_c_compilers(run_c_main):
    lines = []
    for name in CONSTANTS:
        if isinstance(getattr(_constants, name), float):
            lines.append(f'  printf("{name} %a\\n", (double)({name}));')
        else:
            lines.append(f'  printf("{name} %lld\\n", (long long)({name}));')
    out = run_c_main("\n".join(lines))
    values = dict(line.split(" ", 1) for line in out.splitlines())
    assert sorted(values) == sorted(CONSTANTS)
    for name in CONSTANTS:
        ours = getattr(_constants, name)
        expected = float.fromhex(values[name]) if isinstance(ours, float) else int(values[name])
        assert ours == expected, name


@pytest.mark.parametrize("name", ["mjtDisableBit", "mjtGeom", "mjtState", "mjtWarning"])
def test_enum_values_equal_the_c_compilers(name, run_c_main):
    members = list(getattr(_enums, name).__members__.items())
    body = "".join(f'  printf("%lld\\n", (long long){m});\n' for m, _ in members)
    out = run_c_main(body)
    assert [int(v) for v in out.split()] == [int(v) for _, v in members]
