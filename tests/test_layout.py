"""cffi lays out every MuJoCo struct exactly as the C compiler does."""

import pytest

import mjcffi
from mjcffi import _structinfo

ffi = mjcffi.ffi


def _c_name(name):
    """How C spells a struct of _structinfo: its typedef, or `struct tag`."""
    try:
        ffi.typeof(name)
        return name
    except ffi.error:
        return f"struct {name}"


def _layout_queries():
    """(label, cffi value, C expression) for every struct size and field offset."""
    queries = []
    for name, fields in _structinfo.STRUCTS.items():
        outer, *path = name.split(".")
        c_name = _c_name(outer)
        if not path:
            queries.append((f"sizeof {name}", ffi.sizeof(c_name), f"sizeof({c_name})"))
        for field in fields:
            members = [*path, field.name]
            queries.append((f"offsetof {name}.{field.name}",
                            ffi.offsetof(c_name, *members),
                            f"offsetof({c_name}, {'.'.join(members)})"))
    return queries


def test_sizes_and_offsets_match_the_c_compiler(run_c_main):
    queries = _layout_queries()
    assert sum(label.startswith("sizeof") for label, _, _ in queries) > 70
    assert len(queries) > 1900
    body = "\n".join(f'  printf("%zu\\n", (size_t)({expr}));' for _, _, expr in queries)
    c_values = [int(v) for v in run_c_main(body).split()]
    mismatches = [(label, ours, theirs) for (label, ours, _), theirs in zip(queries, c_values)
                  if ours != theirs]
    assert len(c_values) == len(queries)
    assert mismatches == []


@pytest.mark.parametrize("name, size", [("mjtNum", 8), ("mjtSize", 8), ("mjtBool", 1),
                                        ("mjtByte", 1)])
def test_basic_types_have_the_abi_sizes(name, size):
    assert ffi.sizeof(name) == size
