"""cffi lays out every MuJoCo struct exactly as the C compiler does; and the
package's modules import one another in the layers the README describes."""

import ast
from pathlib import Path

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


# ------------------------------------------------------------ import layering
#
# README, "Layout": imports run one way.  The compiled module and the support
# modules sit at the bottom; the generated modules use only those; the
# hand-written layer on top uses both.  The generated tables (enums, constants,
# struct, function and name metadata) hold data only and import nothing of the
# package: any module may read them.  Every import statement counts, also one
# inside a function ("imported on use" is still an import of that layer).

PACKAGE = Path(mjcffi.__file__).parent

TABLES = {"_enums", "_constants", "_structinfo", "_funcinfo", "_namedinfo",
          "sim.generated"}     # mujoco-py's names for the constants (issue 15)
SUPPORT = {"_library", "_errors", "_views", "_marshal", "_arena", "_loading", "plugins",
           "_stringtables", "callbacks", "named", "_simsupport", "_modelcheck",
           # not named in the README's list, and importing nothing of the package
           "_aliases", "scenes", "_machine", "_build", "_progress",
           # prepared calls (issue 25): imports only the standard library
           "_prepared",
           # what the mjr_* functions check of their OpenGL context (issue 12)
           "_mjr", "structs._checks", "structs._handles",
           "structs._elements", "structs._element_fields", "structs._element_vectors",
           "structs._element_adders"}
GENERATED = {"_functions", "_simgetters", "structs"}
# Units of their own inside a package: the hand-written modules beside the generated
# struct classes, used by them and by the support layer (the mjr_* checks), in the
# support layer; and mjcffi.sim's generated constants, a table.
OWN_UNITS = {"sim.generated", "structs._checks", "structs._handles", "structs._elements",
             "structs._element_fields", "structs._element_vectors", "structs._element_adders"}
TOP = {"model", "data", "vfs", "log_config", "functions", "_overrides", "warning_errors",
       "user_handlers", "rollout", "_batch", "batch", "minimize", "sim", "accuracy",
       "__init__", "__main__",
       # rendering (issue 12): the package holds the OpenGL contexts (cffi and glfw only)
       # and the Renderer, which draws with the mjr_* functions; the official import paths
       "rendering", "gl_context", "egl", "osmesa", "glfw", "renderer",
       # model editing (issue 13): the hand-written MjSpec over the generated struct
       "spec",
       # the interactive viewer (issue 14): GLFW windows drawing with mjv_*/mjr_*; the
       # mjui_* functions it builds its panels with (hand-written: their mjuiDef arrays)
       "viewer", "_mjui",
       # speed against error (issue 16): the evaluation core shared by accuracy and tune
       "evaluation", "tune",
       # rollouts on Ray (issue 17): actors running the C rollout pool
       "distributed"}
TIER = {**{n: "table" for n in TABLES}, **{n: "support" for n in SUPPORT},
        **{n: "generated" for n in GENERATED}, **{n: "top" for n in TOP}, "_mjcffi": "compiled"}
ALLOWED = {"table": set(), "compiled": set(),
           "support": {"compiled", "table", "support"},
           "generated": {"compiled", "table", "support", "generated"},
           "top": {"compiled", "table", "support", "generated", "top"}}


def _unit_of(parts):
    """The unit of a module from its path in the package: its top-level name, or one of
    OWN_UNITS."""
    inner = ".".join(parts[:2])
    return inner if inner in OWN_UNITS else parts[0]


def _modules():
    """Every Python module of the package: (unit, dotted name, path)."""
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE).with_suffix("").parts
        yield _unit_of(parts), ".".join(("mjcffi", *parts)), path


def _unit(dotted):
    """The unit ('callbacks', 'structs', 'structs._checks', '__init__') of an mjcffi module
    name."""
    parts = dotted.split(".")[1:]
    return "__init__" if not parts else _unit_of(parts)


def _exists(dotted):
    relative = Path(*dotted.split(".")[1:])
    return (PACKAGE / relative).with_suffix(".py").exists() or (PACKAGE / relative).is_dir() \
        or dotted == "mjcffi._mjcffi"


def _imports(dotted, path):
    """The mjcffi modules that the module `dotted` at `path` imports, anywhere in it."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = dotted if path.name == "__init__.py" else dotted.rpartition(".")[0]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [alias.name for alias in node.names if alias.name.split(".")[0] == "mjcffi"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - (node.level - 1)]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            if module.split(".")[0] != "mjcffi":
                continue
            for alias in node.names:     # `from . import x`: the submodule x, if there is one
                sub = f"{module}.{alias.name}"
                found.append(sub if _exists(sub) else module)
    return found


def test_every_module_has_a_layer():
    units = {unit for unit, _, _ in _modules()}
    assert units - set(TIER) == set(), "classify new modules in TIER"
    assert set(TIER) - units - {"_mjcffi"} == set(), "TIER names modules that are gone"


def test_generated_modules_are_those_headed_so():
    headed = {unit for unit, _, path in _modules()
              if "generated by codegen; do not edit" in path.read_text(encoding="utf-8")[:200]}
    assert headed == TABLES | GENERATED


def _violations(unit, dotted, path):
    return [f"{dotted} ({TIER[unit]}) imports {target} ({TIER[_unit(target)]})"
            for target in _imports(dotted, path)
            if _unit(target) != unit and TIER[_unit(target)] not in ALLOWED[TIER[unit]]]


def test_imports_run_one_way():
    assert [v for module in _modules() for v in _violations(*module)] == []


def test_item_imports_the_check_sees_lazy_relative_and_absolute_imports(tmp_path):
    # as callbacks.py and _simsupport.py once did: upward, inside a function too
    path = tmp_path / "callbacks.py"
    path.write_text("from ._errors import with_note\n"
                    "from ._functions import mj_objectVelocity\n"
                    "def f():\n    from .model import MjModel\n    from . import data\n"
                    "import mjcffi.sim\n")
    assert sorted(_imports("mjcffi.callbacks", path)) == [
        "mjcffi._errors", "mjcffi._functions", "mjcffi.data", "mjcffi.model", "mjcffi.sim"]
    assert len(_violations("callbacks", "mjcffi.callbacks", path)) == 4


def test_codegen_is_never_imported_at_run_time():
    for _, dotted, path in _modules():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level
                     else [])
            assert not any(n.split(".")[0] == "codegen" for n in names), dotted


def test_every_subpackage_is_in_the_wheel():
    # pyproject lists packages by hand: one left out installs in editable mode
    # (as here) and is missing from a built wheel
    import tomllib
    pyproject = tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text(encoding="utf-8"))
    listed = set(pyproject["tool"]["setuptools"]["packages"])
    found = {"mjcffi." + ".".join(p.parent.relative_to(PACKAGE).parts)
             for p in PACKAGE.rglob("__init__.py")} | {"mjcffi"}
    found = {name.rstrip(".") for name in found}
    assert found == listed
