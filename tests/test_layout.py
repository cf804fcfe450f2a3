"""cffi lays out every MuJoCo struct exactly as the C compiler does; and the
package's modules import one another in the layers docs/architecture.md describes."""

import ast
from pathlib import Path

import pytest

import mjcffi
from mjcffi._generated import structinfo as _structinfo

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
# docs/architecture.md, "Layout": the tree shows the tiers, and imports run down them.  A module's
# tier is read from where it lies:
#   tables     mjcffi/_generated/          generated data; imports nothing of the package
#   compiled   mjcffi._mjcffi, mjcffi._descriptors   built from mjcffi/_c/
#   support    mjcffi/_support/            imports the compiled module, tables and itself
#   generated  mjcffi/structs/, mjcffi/_functions/   (the kept paths) use those three
#   top        everything else: the public modules and subpackages, the mujoco-py face
# Every import statement counts, one inside a function too ("imported on use" is still
# an import of that module), and no module may reach itself through its imports.

PACKAGE = Path(mjcffi.__file__).parent
COMPILED = ("_mjcffi", "_descriptors")     # the extension modules, built by pip install
ORDER = ("tables", "compiled", "support", "generated", "top")
ALLOWED = {"tables": set(), "compiled": set(),
           "support": {"compiled", "tables", "support"},
           "generated": {"compiled", "tables", "support", "generated"},
           "top": set(ORDER)}


def tier(dotted):
    """The tier of an mjcffi module, from its place in the tree (see above)."""
    parts = dotted.split(".")[1:]
    if not parts:
        return "top"
    first = parts[0]
    if first == "_generated":
        return "tables"
    if first in COMPILED:
        return "compiled"
    if first == "_support":
        return "support"
    if first in ("structs", "_functions"):
        return "generated"
    return "top"


def _modules():
    """Every Python module of the package: (dotted name, path)."""
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        yield ".".join(("mjcffi", *parts)), path


def _exists(dotted):
    relative = Path(*dotted.split(".")[1:])
    return (PACKAGE / relative).with_suffix(".py").exists() or \
        (PACKAGE / relative / "__init__.py").exists() or dotted.split(".")[1:] in \
        [[name] for name in COMPILED]


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


def _graph():
    """{module: set of the modules it imports}, over the whole package.  Importing
    `mjcffi.spec.bind` runs `mjcffi/spec/__init__.py` first: a package of the target that
    is not one of the importer's own (already running) packages counts as imported too."""
    graph = {}
    for dotted, path in _modules():
        targets = set()
        for target in _imports(dotted, path):
            targets.add(target)
            parts = target.split(".")
            for n in range(2, len(parts)):
                parent = ".".join(parts[:n])
                if not dotted.startswith(parent + "."):
                    targets.add(parent)
        targets.discard(dotted)
        graph[dotted] = targets
    return graph


def _violations(graph):
    return [f"{module} ({tier(module)}) imports {target} ({tier(target)})"
            for module, targets in graph.items() for target in sorted(targets)
            if tier(target) not in ALLOWED[tier(module)]]


def _circles(graph):
    """The import circles: each strongly connected group of two or more modules (Tarjan)."""
    index, low, stack, on_stack, groups = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                groups.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return groups


def test_imports_run_down_the_tiers():
    assert _violations(_graph()) == []


def test_no_module_reaches_itself_through_its_imports():
    assert _circles(_graph()) == []


def test_item_imports_the_check_sees_lazy_relative_and_absolute_imports(tmp_path):
    # as callbacks.py and _simsupport.py once did: upward, inside a function too
    path = tmp_path / "callbacks.py"
    path.write_text("from .errors import with_note\n"
                    "from .._functions import mj_objectVelocity\n"
                    "def f():\n    from ..model import MjModel\n    from .. import data\n"
                    "import mjcffi.sim\n")
    found = sorted(_imports("mjcffi._support.callbacks", path))
    assert found == ["mjcffi._functions", "mjcffi._support.errors", "mjcffi.data",
                     "mjcffi.model", "mjcffi.sim"]
    graph = {"mjcffi._support.callbacks": set(found)}
    assert len(_violations(graph)) == 4


def test_item_a_circle_is_found_through_a_function_level_import():
    graph = {"mjcffi.a": {"mjcffi.b"}, "mjcffi.b": {"mjcffi.c"}, "mjcffi.c": {"mjcffi.a"},
             "mjcffi.d": {"mjcffi.a"}}
    assert _circles(graph) == [["mjcffi.a", "mjcffi.b", "mjcffi.c"]]


def test_generated_files_lie_in_the_generated_places_and_nothing_else_does():
    # the generated folders, and the two generated modules kept at paths users and pickles
    # name (mjcffi._functions, mjcffi.structs)
    places = ("mjcffi/_generated/", "mjcffi/_c/generated/", "mjcffi/sim/generated/",
              "mjcffi/structs/", "mjcffi/_functions/")
    for path in sorted(PACKAGE.rglob("*")):
        if not path.is_file() or path.suffix not in (".py", ".pyi", ".c", ".h", ".md"):
            continue
        rel = str(path.relative_to(PACKAGE.parent))
        with open(path, encoding="utf-8") as f:
            generated = "generated by codegen; do not edit" in f.read(300)
        inside = rel.startswith(places) and not rel.endswith("sim/generated/__init__.py")
        assert generated == inside, (rel, "generated" if generated else "hand-written")


def test_the_package_root_holds_at_most_forty_entries():
    entries = [p.name for p in PACKAGE.iterdir()
               if p.name != "__pycache__" and p.name.split(".")[0] not in COMPILED]
    assert len(entries) <= 40, sorted(entries)


def test_codegen_is_never_imported_at_run_time():
    for dotted, path in _modules():
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


# The public import paths: the official ones (also those real code names, such as
# mujoco._enums), mjcffi's own subsystems, and mujoco-py's under mjcffi.sim.  A
# reorganisation of the tree keeps every one of them.
PUBLIC_PATHS = (
    "mjcffi", "mjcffi.model", "mjcffi.data", "mjcffi.functions", "mjcffi.vfs",
    "mjcffi.log_config", "mjcffi.user_handlers", "mjcffi.warning_errors", "mjcffi.rollout",
    "mjcffi.batch", "mjcffi.scenes", "mjcffi.renderer", "mjcffi.gl_context", "mjcffi.accuracy",
    "mjcffi.minimize", "mjcffi.spec", "mjcffi.rendering", "mjcffi.viewer", "mjcffi.tune",
    "mjcffi.evaluation", "mjcffi.distributed", "mjcffi._functions", "mjcffi._enums",
    "mjcffi._constants", "mjcffi.structs", "mjcffi.structs.mjmodel", "mjcffi.structs.mjdata",
    "mjcffi.structs.mjspec", "mjcffi.structs.mjvisualize", "mjcffi.structs.mjrender",
    "mjcffi.structs.mjui", "mjcffi.structs.mjplugin", "mjcffi.structs.mjtype",
    "mjcffi.structs.mjbatch", "mjcffi.sim", "mjcffi.sim.const", "mjcffi.sim.functions",
    "mjcffi.sim.cymj", "mjcffi.sim.modder", "mjcffi.sim.generated",
    "mjcffi.sim.generated.const", "mjcffi.sim.mjviewer", "mjcffi.sim.mjrenderpool")


@pytest.mark.parametrize("path", PUBLIC_PATHS)
def test_every_public_path_imports(path):
    import importlib
    assert importlib.import_module(path).__name__ == path


@pytest.mark.parametrize("path", ("mjcffi.egl", "mjcffi.osmesa", "mjcffi.glfw"))
def test_the_gl_backend_paths_import_where_their_library_is(path):
    import importlib
    try:
        module = importlib.import_module(path)
    except ImportError as error:          # a backend's system library (or glfw) is absent
        pytest.skip(f"{path}: {error}")
    assert hasattr(module, "GLContext")
