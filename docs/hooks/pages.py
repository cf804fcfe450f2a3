"""MkDocs hook: the pages generated at build time, so that nothing generated is committed.

- `api/**.md`: the API reference, every name of `mjcffi.__all__` and `mjcffi.sim.__all__`.
  Functions, structs and enums are Markdown tables written from codegen's tables
  (docs/hooks/reference.py); the hand-written classes and functions of the package
  are written here from their signatures and docstrings, under their public names
  (`mjcffi.FatalError`); the submodules (`mjcffi.rollout`, `mjcffi.tune`, ...) go
  through mkdocstrings. The reference's part of the navigation is generated too
  (`on_config`).
- `results.md`, `accuracy-report.md` (with its plot) and `conformance-report.md`: the
  reports the repository keeps beside the code, shown in the site as they are.
- After the build, the search index ranks a public name's own entry first when the name
  is searched for (`rank_exact_names`), and docs/hooks/rendering.py checks that every page
  rendered as written (highlighted code blocks, nested lists, no literal list markers): a
  failure fails the build.

`api_pages()` and `api_nav()` are what tests/test_docs.py checks.
"""

import importlib.util
import inspect
import json
import math
import pathlib
import re
import sys

try:
    from mkdocs.plugins import event_priority
except ImportError:             # tests/test_docs.py reads api_pages() without MkDocs
    def event_priority(priority):
        return lambda function: function

HOOKS = pathlib.Path(__file__).resolve().parent


def _sibling(name):
    """docs/hooks/<name>.py, loaded once (MkDocs loads hooks by path, not as a package)."""
    key = f"_mjcffi_docs_{name}"
    if key not in sys.modules:
        spec = importlib.util.spec_from_file_location(key, HOOKS / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules[key] = module
        spec.loader.exec_module(module)
    return sys.modules[key]


reference = _sibling("reference")

# Submodules with a page of their own, rendered by mkdocstrings: (module, title).
MODULES = (
    ("mjcffi.rollout", "mjcffi.rollout"), ("mjcffi.batch", "mjcffi.batch"),
    ("mjcffi.minimize", "mjcffi.minimize"), ("mjcffi.distributed", "mjcffi.distributed"),
    ("mjcffi.tune", "mjcffi.tune"), ("mjcffi.viewer", "mjcffi.viewer"),
    ("mjcffi.egl", "mjcffi.egl"), ("mjcffi.osmesa", "mjcffi.osmesa"),
    ("mjcffi.glfw", "mjcffi.glfw"),
)

# Struct pages are grouped in the navigation by the header that declares the struct.
HEADER_GROUPS = (("mjmodel", "mjModel and its parts"), ("mjdata", "mjData and its parts"),
                 ("mjspec", "mjSpec elements"), ("mjvisualize", "Visualization"),
                 ("mjrender", "Rendering"), ("mjui", "UI"), ("mjplugin", "Plugins"),
                 ("mjtype", "Logging"), ("mjbatch", "Batch"))
ERRORS = ("ArgumentError", "IdError", "FatalError", "MjWarningError")

# Values whose repr differs from one machine or process to the next: what they are instead.
DESCRIBED = {
    "HEADERS_DIR": "The folder of MuJoCo's C headers in the installed mujoco-core package "
                   "(a path on this machine).",
    "PLUGINS_DIR": "The folder of MuJoCo's first-party plugin libraries in the installed "
                   "mujoco-core package (a path on this machine).",
    "PLUGIN_HANDLES": "The handles of the plugin libraries loaded so far (filled when the "
                      "first model loads).",
    "ffi": "The `cffi.FFI` of the compiled module: C types, `ffi.new`, `ffi.cast`, "
           "`ffi.from_buffer`.",
    "lib": "The compiled module's C functions, globals and constants: every MuJoCo "
           "function (`lib.mj_step`) and its guarded twin (`lib.mjcffi_guard_mj_step`).",
    "MjStruct": "A typing alias: any of mjcffi's struct classes.",
    "MJTNUM_DTYPE": "`numpy.float64`, the NumPy type of `mjtNum`.",
}

REPORTS = {"results.md": "benchmarks/RESULTS.md", "accuracy-report.md": "benchmarks/ACCURACY.md",
           "conformance-report.md": "CONFORMANCE.md"}
ASSETS = {"accuracy.png": "benchmarks/accuracy.png"}


# ------------------------------------------------------------------ hand-written objects

_SECTION = re.compile(r"^(Args|Arguments|Parameters|Returns|Yields|Raises|Examples?|Notes?|"
                      r"Attributes):\s*$")


def docstring_markdown(doc, linker, here):
    """A hand-written docstring as Markdown: prose paragraphs escaped and linked, Google-style
    sections as lists, indented or doctest blocks as code blocks."""
    out = []
    for paragraph in re.split(r"\n\s*\n", inspect.cleandoc(doc or "")):
        lines = paragraph.splitlines()
        if not lines:
            continue
        head = _SECTION.match(lines[0].strip())
        if head:
            out += [f"**{head.group(1)}**", ""]
            entries = []
            for line in lines[1:]:
                if re.match(r"^\s{0,4}\S", line) and (not entries or
                                                     len(line) - len(line.lstrip()) <= 2):
                    entries.append(line.strip())
                elif entries:
                    entries[-1] += " " + line.strip()
            for entry in entries:
                name, sep, text = entry.partition(": ")
                if sep and re.fullmatch(r"[\w*.\[\], ]+", name):
                    out.append(f"- `{name}`: {linker.text(text, here)}")
                else:
                    out.append(f"- {linker.text(entry, here)}")
            out.append("")
        elif lines[0].lstrip().startswith(">>>") or any(
                line[:1].isspace() for line in lines[1:]) and lines[0][:1].isspace():
            language = "python" if lines[0].lstrip().startswith(">>>") else "text"
            out += [f"```{language}", *inspect.cleandoc(paragraph).splitlines(), "```", ""]
        else:
            out += [linker.text(" ".join(line.strip() for line in lines), here), ""]
    return out


def _signature(name, obj):
    try:
        text = str(inspect.signature(obj))
    except (TypeError, ValueError):
        return None
    text = re.sub(r" at 0x[0-9a-f]+", "", text)      # no object addresses in the site
    return f"{name}{text}"


def object_markdown(name, obj, linker, here, level=2, public=None):
    """A hand-written class or function under its public name `public` (mjcffi.<name>)."""
    public = public or f"mjcffi.{name}"
    lines = [f"{'#' * level} {name} {{ #{public} }}", ""]
    if inspect.isclass(obj):
        bases = [b.__name__ for b in obj.__bases__ if b is not object]
        signature = _signature(name, obj) if "__init__" in vars(obj) else None
        if signature:
            lines += ["```python", f"class {signature}", "```", ""]
        if bases:
            lines += ["Bases: " + ", ".join(f"`{b}`" for b in bases) + ".", ""]
    else:
        signature = _signature(name, obj)
        if signature:
            lines += ["```python", signature, "```", ""]
    lines += docstring_markdown(inspect.getdoc(obj), linker, here)
    if inspect.isclass(obj):
        for member, value in _own_members(obj):
            lines += _member_markdown(name, member, value, linker, here, level + 1, public)
    return "\n".join(lines) + "\n"


def _own_members(cls):
    """Public members written by hand in `cls` or its hand-written bases: not the struct's
    fields (the table has them), nor the named-access accessors (generated)."""
    from mjcffi._generated import structinfo
    seen = {f.name for f in structinfo.STRUCTS.get(getattr(cls, "_cname", ""), ())}
    for klass in cls.__mro__:
        if (klass.__module__ or "").startswith(("mjcffi._generated", "mjcffi._support.views")):
            seen |= set(vars(klass))
    out = []
    for klass in cls.__mro__:
        module = klass.__module__ or ""
        if klass is object or module.startswith(("mjcffi.structs", "mjcffi._generated",
                                                 "builtins")) or not module.startswith("mjcffi"):
            continue
        for member, value in vars(klass).items():
            if member.startswith("_") or member in seen:
                continue
            seen.add(member)
            out.append((member, value))
    return out


def _member_markdown(owner, member, value, linker, here, level, public):
    anchor = f"{public}.{member}"
    kind = "property" if isinstance(value, property) else \
        "classmethod" if isinstance(value, classmethod) else \
        "staticmethod" if isinstance(value, staticmethod) else ""
    function = value.__func__ if isinstance(value, (classmethod, staticmethod)) else value
    lines = [f"{'#' * level} {owner}.{member} {{ #{anchor} }}", ""]
    if not callable(function) and not isinstance(value, property):
        shown = repr(value)                       # a class attribute: its value
        if len(shown) <= 70 and not re.search(r" at 0x|['\"]/", shown):
            lines += ["```python", f"{member} = {shown}", "```", ""]
        return lines
    signature = _signature(member, function) if callable(function) and not kind == "property" \
        else None
    if signature and kind != "classmethod" and signature.startswith(f"{member}(self"):
        signature = signature.replace("(self, ", "(", 1).replace("(self)", "()", 1)
    if kind == "classmethod" and signature:
        signature = re.sub(r"^(\w+)\(cls,? ?", r"\1(", signature)
    if signature:
        lines += ["```python", (f"@{kind}\n" if kind else "") + signature, "```", ""]
    elif kind:
        lines += [f"*{kind}*", ""]
    doc = inspect.getdoc(value.fget if isinstance(value, property) else function)
    lines += docstring_markdown(doc, linker, here) if doc else []
    return lines


# ------------------------------------------------------------------ the pages

def _value_rows(names, module):
    lines = ["| name | type | value |", "| --- | --- | --- |"]
    for name in names:
        obj = getattr(module, name)
        if name in DESCRIBED:
            text = DESCRIBED[name]
        elif inspect.ismodule(obj):
            summary = (inspect.getdoc(obj) or "").split("\n\n")[0].replace("\n", " ")
            text = f"The module `{obj.__name__}`" + (f": {summary}" if summary else ".")
        elif re.search(r" at 0x[0-9a-fA-F]+|['\"]/[^'\"]*/", repr(obj)):  # an address, a path
            text = f"A `{type(obj).__name__}`."
        else:
            text = repr(obj)
            text = text if len(text) <= 70 else text[:67] + "..."
            text = "`" + text.replace("`", "'") + "`"
        lines.append(f"| <span id=\"{module.__name__}.{name}\"></span>`{name}` | "
                     f"`{type(obj).__name__}` | {reference.cell(text)} |")
    return "\n".join(lines) + "\n"


def _classify():
    """The public names of mjcffi, sorted into the reference's pages."""
    import mjcffi
    from mjcffi import functions
    names = list(mjcffi.__all__)
    function_names = set(functions.NAMES)
    structs = reference.struct_classes()
    enums = [n for n in names if reference.is_enum(getattr(mjcffi, n))]
    rest = [n for n in names if n not in function_names and n not in structs and n not in enums]
    constants = [n for n in rest if isinstance(getattr(mjcffi, n), (int, float))
                 and not isinstance(getattr(mjcffi, n), bool)]
    errors = [n for n in ERRORS if n in rest]
    classes = [n for n in rest if n not in constants and n not in errors
               and n not in DESCRIBED and inspect.isclass(getattr(mjcffi, n))]
    helpers = [n for n in rest if n not in constants and n not in errors and n not in classes]
    return dict(functions=[n for n in names if n in function_names], structs=structs,
                enums=enums, constants=constants, errors=errors, classes=classes,
                helpers=helpers)


def _struct_group(class_name):
    """The header that declares the struct: the module of its generated class."""
    import mjcffi
    for klass in getattr(mjcffi, class_name).__mro__:
        if klass.__module__.startswith("mjcffi.structs."):
            return klass.__module__.rsplit(".", 1)[1]
    return "mjmodel"


def api_pages():
    """{path under docs/: Markdown} of the API reference."""
    import mjcffi
    import mjcffi.sim

    groups = _classify()
    linker = reference.Linker()
    sections = reference.function_sections()
    enum_comments, member_comments, struct_comments = reference.header_comments()
    labels = reference.xml_labels()

    # every target first, so that any page can link to any other
    for slug, title, names in sections:
        for name in names:
            linker.add(name, f"api/functions/{slug}.md", f"mjcffi.{name}")
    for class_name, cname in groups["structs"].items():
        linker.add(class_name, f"api/structs/{class_name}.md", f"mjcffi.{class_name}")
        linker.c_structs.setdefault(cname, class_name)
        linker.add(cname, f"api/structs/{class_name}.md", f"mjcffi.{class_name}")
    for name in groups["enums"]:
        linker.add(name, "api/enums.md", f"mjcffi.{name}")
    for name in groups["errors"]:
        linker.add(name, "api/errors.md", f"mjcffi.{name}")
    for name in groups["classes"]:
        linker.add(name, "api/classes.md", f"mjcffi.{name}")

    pages = {}
    for slug, title, names in sections:
        here = f"api/functions/{slug}.md"
        header = "mjbatch.h" if slug == "batch" else "mujoco.h"
        parts = [f"# {title}\n",
                 f"The functions of {header}'s section *{title}*, in the header's order "
                 f"({len(names)}). How to read a function's entry: "
                 f"[API reference](../index.md#reading-a-function).\n"]
        parts += [reference.function_markdown(name, linker, here) for name in names]
        pages[here] = "\n".join(parts)

    for class_name, cname in groups["structs"].items():
        here = f"api/structs/{class_name}.md"
        text = reference.struct_markdown(class_name, cname, linker, here, struct_comments,
                                         labels)
        cls = getattr(mjcffi, class_name)
        own = _own_members(cls)
        if own or not cls.__module__.startswith("mjcffi.structs"):
            doc = inspect.getdoc(cls) if cls.__doc__ and "__doc__" in vars(cls) else ""
            text += "\n## Python\n\n" + "\n".join(docstring_markdown(doc, linker, here)) + "\n"
            for member, value in own:
                text += "\n".join(_member_markdown(class_name, member, value, linker, here, 3,
                                                   f"mjcffi.{class_name}")) + "\n"
        named = [n for n in ("body", "joint", "geom", "site", "actuator", "sensor")
                 if n in dir(cls)]
        if named and class_name in ("MjModel", "MjData"):
            text += ("\n## Named access\n\n" + ", ".join(f"`{n}(name or id)`" for n in named)
                     + " and the others of the official bindings: see "
                     "[Named access](../../named-access.md).\n")
        pages[here] = "---\nhide:\n  - toc\n---\n\n" + text if len(own) < 3 else text

    pages["api/enums.md"] = "\n".join(
        ["# Enums\n", f"MuJoCo's {len(groups['enums'])} enums, each an `enum.IntEnum` "
         "whose values equal C's, with every member and its header comment.\n"]
        + [reference.enum_markdown(n, getattr(mjcffi, n), linker, "api/enums.md",
                                   enum_comments, member_comments) for n in groups["enums"]])
    pages["api/constants.md"] = "# Constants\n\nMuJoCo's `#define` constants and sizes.\n\n" \
        + _value_rows(groups["constants"], mjcffi)
    pages["api/errors.md"] = "# Errors\n\nWhat mjcffi raises, besides Python's own " \
        "exceptions.\n\n" + "\n".join(object_markdown(n, getattr(mjcffi, n), linker,
                                                       "api/errors.md") for n in groups["errors"])
    pages["api/classes.md"] = "# Other classes\n\nThe classes that are not a MuJoCo struct: " \
        "the renderer, the OpenGL context, the spec's vector fields.\n\n" + "\n".join(
            object_markdown(n, getattr(mjcffi, n), linker, "api/classes.md")
            for n in groups["classes"])
    callables = [n for n in groups["helpers"] if callable(getattr(mjcffi, n))
                 and n not in DESCRIBED]
    values = [n for n in groups["helpers"] if n not in callables]
    pages["api/helpers.md"] = "# Callbacks, handlers and values\n\nMuJoCo's callbacks and " \
        "handlers, warnings as errors, the string tables and the raw C API.\n\n" + "\n".join(
            object_markdown(n, getattr(mjcffi, n), linker, "api/helpers.md")
            for n in callables) + "\n## Values\n\n" + _value_rows(values, mjcffi)

    for module, title in MODULES:
        slug = module.replace(".", "-")
        pages[f"api/{slug}.md"] = f"# {title}\n\n::: {module}\n"
    sim_names = list(mjcffi.sim.__all__)
    pages["api/mjcffi-sim.md"] = "# mjcffi.sim (mujoco-py)\n\n::: mjcffi.sim\n    options:\n" \
        "      members: false\n\n" + "\n".join(_sim_section(sim_names, mjcffi.sim))

    pages["api/official-subpackages.md"] = _OFFICIAL_SUBPACKAGES
    pages["api/index.md"] = _index(groups, sections)
    return pages


# The official pure-Python subpackages, run from the installed official source on mjcffi
# (mjcffi/_support/official_source.py): their API is the official one, so the page says
# what each is and what it needs, and links to the official documentation.
_OFFICIAL_SUBPACKAGES = """# The official subpackages

These run the official bindings' own pure-Python code, read from the installed `mujoco`
package, on mjcffi's objects: `import mjcffi.sysid`, or `from mujoco import sysid` under
`sys.modules['mujoco'] = mjcffi`. Nothing of them is copied into mjcffi, and no official
compiled module is imported on the way; their API is the official one
([MuJoCo's Python documentation](https://mujoco.readthedocs.io/en/stable/python.html),
[MJX](https://mujoco.readthedocs.io/en/stable/mjx.html)). How it works, and what differs:
[the drop-in guide](../drop-in.md).

| module | what it is | install |
|---|---|---|
| `mjcffi.sysid` | system identification: fit a model's parameters to recorded trajectories | `pip install 'mjcffi[sysid]'` |
| `mjcffi.usd` | export a simulation to USD (Universal Scene Description) | `pip install 'mjcffi[usd]'` |
| `mjcffi.msh2obj` | convert MuJoCo's legacy `.msh` meshes to `.obj`; `python -m mjcffi.msh2obj` | nothing more |
| `mjcffi.introspect` | MuJoCo's headers as Python data: structs, functions, enums | nothing more |
| `mjcffi.mjx` | MJX, MuJoCo in JAX: `mjx.put_model(m)` and `mjx.put_data(m, d)` take mjcffi's objects, `mjx.get_data_into(d, m, dx)` fills an mjcffi MjData | `pip install 'mjcffi[mjx]'` |

A missing dependency is a `ModuleNotFoundError` that names the extra to install.
`python -m conformance` runs their official tests on mjcffi, and compares MJX's steps from
mjcffi's objects with those from the official's, bit for bit
([conformance report](../conformance-report.md)).
"""


def _sim_section(names, module):
    parts, values = [], []
    for name in names:
        obj = getattr(module, name)
        home = getattr(obj, "__module__", "") or ""
        if (inspect.isclass(obj) or inspect.isfunction(obj)) and home.startswith("mjcffi") \
                and not any(p.startswith("_") for p in home.split(".")):
            parts.append(f"::: {home}.{obj.__qualname__}\n")
        elif inspect.isclass(obj) or inspect.isfunction(obj):
            linker = reference.Linker()
            parts.append(object_markdown(name, obj, linker, "api/mjcffi-sim.md",
                                         public=f"mjcffi.sim.{name}"))
        else:
            values.append(name)
    if values:
        parts.append("## Values\n\n" + _value_rows(values, module))
    return parts


def _index(groups, sections):
    lines = ["# API reference", "",
             "Every public name of `mjcffi` and `mjcffi.sim`, generated at build time from "
             "the tables that codegen writes from MuJoCo's headers (docs/hooks/). Names follow "
             "the official bindings'; each function, struct and enum links to its entry in "
             "[MuJoCo's C reference](https://mujoco.readthedocs.io/en/stable/APIreference/"
             "index.html), and the fields of the option, visual and spec structs to the "
             "[XML reference](https://mujoco.readthedocs.io/en/stable/XMLreference.html).", "",
             "## Reading a function", "",
             "Each function has its Python signature, MuJoCo's doc comment and a table of "
             "parameters:", "",
             "- **type**: what Python takes, in the official bindings' types (`ndarray[float64]` "
             "is a NumPy array of that dtype);",
             "- **shape**: in MuJoCo's size names: `(3, nv)` means 3 rows and `m.nv` columns, "
             "`(n,)` a vector whose `n` is deduced from the arrays and left out of the Python "
             "signature, as the official bindings do;",
             "- **in/out**: *in* is read only (`const` in C); *out* and *in/out* are written "
             "in place, so pass a writable C-contiguous array of the exact dtype;",
             "- **None allowed**: `None` stands for C's `NULL` where MuJoCo's header says the "
             "argument is nullable;",
             "- **C declaration**: the argument as `mujoco.h` declares it.", "",
             "Then what it returns, what it raises, the notes on its Python form, and the link "
             "to the C reference. Every function also has `F.prepare(...)`, which checks the "
             "arguments once and returns a call that skips the checks "
             "([Structs and functions](../structs-and-functions.md)).", "",
             "## Functions, by section of mujoco.h", ""]
    for slug, title, names in sections:
        lines.append(f"- [{title}](functions/{slug}.md): " + ", ".join(
            f"`{n}`" for n in names[:4]) + (", ..." if len(names) > 4 else "")
            + f" ({len(names)})")
    lines += ["", "## Structs", "",
              "Each page lists every field: shape in MuJoCo's sizes, dtype, C declaration and "
              "header comment.", ""]
    by_group = _struct_groups(groups["structs"])
    for header, title in HEADER_GROUPS:
        if by_group.get(header):
            lines.append(f"- {title} ({header}.h): " + ", ".join(
                f"[`{n}`](structs/{n}.md)" for n in by_group[header]))
    lines += ["", "## Everything else", "",
              f"- [Enums](enums.md): {len(groups['enums'])} enums, every member with its value "
              "and header comment",
              "- [Constants](constants.md), [Errors](errors.md), "
              "[Other classes](classes.md), [Callbacks, handlers and values](helpers.md)"]
    lines += ["- Submodules: " + ", ".join(
        f"[{title}]({module.replace('.', '-')}.md)" for module, title in MODULES)
        + ", [mjcffi.sim (mujoco-py)](mjcffi-sim.md)",
        "- [The official subpackages](official-subpackages.md): sysid, usd, msh2obj, "
        "introspect and mjx, the official code on mjcffi", ""]
    return "\n".join(lines)


def _struct_groups(structs):
    by_group = {}
    for class_name in structs:
        by_group.setdefault(_struct_group(class_name), []).append(class_name)
    for names in by_group.values():
        names.sort(key=lambda n: (n not in ("MjModel", "MjData", "MjSpec", "MjOption"), n))
    return by_group


def api_nav():
    """The API reference's part of the navigation (MkDocs' nav format)."""
    groups = _classify()
    sections = reference.function_sections()
    by_group = _struct_groups(groups["structs"])
    return [
        "api/index.md",
        {"Functions": [{title: f"api/functions/{slug}.md"} for slug, title, _ in sections]},
        {"Structs": [{title: [{n: f"api/structs/{n}.md"} for n in by_group[header]]}
                     for header, title in HEADER_GROUPS if by_group.get(header)]},
        {"Enums": "api/enums.md"}, {"Constants": "api/constants.md"},
        {"Errors": "api/errors.md"}, {"Other classes": "api/classes.md"},
        {"Callbacks, handlers and values": "api/helpers.md"},
        {"Submodules": [{title: f"api/{module.replace('.', '-')}.md"}
                        for module, title in MODULES]
         + [{"mjcffi.sim (mujoco-py)": "api/mjcffi-sim.md"},
            {"The official subpackages": "api/official-subpackages.md"}]},
    ]


# ------------------------------------------------------------------ MkDocs events

def repository_url(root):
    """The repository's address from pyproject.toml's [project.urls] (Repository, Source
    or Homepage), or None: the site links no address the project does not state."""
    import tomllib
    urls = tomllib.loads((root / "pyproject.toml").read_text()).get("project", {}).get(
        "urls", {})
    for key in ("Repository", "Source", "Source Code", "Homepage"):
        if urls.get(key):
            return urls[key]
    return None


def on_config(config):
    """Put the generated reference pages into the navigation, in place of the
    `API reference` entry of mkdocs.yml, and the repository link into the header."""
    for i, entry in enumerate(config.nav or []):
        if isinstance(entry, dict) and "API reference" in entry:
            config.nav[i] = {"API reference": api_nav()}
    root = pathlib.Path(config.config_file_path).resolve().parent
    if not config.repo_url and repository_url(root):
        config.repo_url = repository_url(root)
    return config


def on_files(files, config):
    from mkdocs.structure.files import File
    root = pathlib.Path(config.config_file_path).resolve().parent     # the repository
    for path, text in api_pages().items():
        files.append(File.generated(config, path, content=text))
    for path, source in REPORTS.items():    # written by scripts in GitHub's Markdown
        text = _sibling("rendering").reindent_lists((root / source).read_text())
        files.append(File.generated(config, path, content=text))
    for path, source in ASSETS.items():
        files.append(File.generated(config, path, content=(root / source).read_bytes()))
    return files


def rank_exact_names(index):
    """Boost the search entries of the reference's names so that a name's own entry comes
    first when it is searched for: `mj_step` above `mj_step2`, `mj_jac` above
    `mj_jacSubtreeCom`.

    Material's search matches each query word as a prefix (`mj_step*`), and lunr scores a
    match by how rare the matched word is, so a name mentioned on many pages (`mj_step`)
    loses to a rarer name that extends it (`mj_step2`). Each entry whose title is a
    public name gets a boost that makes up for its name's frequency (every name then
    scores as a word found once), times 1 + 2/len(name), so that of two names that match
    a prefix, the shorter (the exact one) comes first."""
    docs = index["docs"]
    separator = re.compile(index["config"]["separator"])
    counts = {}
    for doc in docs:
        text = re.sub(r"<[^>]+>", " ", doc["title"] + " " + doc["text"]).lower()
        for word in set(separator.split(text)):
            counts[word] = counts.get(word, 0) + 1
    total = len(docs)

    def idf(n):                                   # lunr's
        return math.log(1 + abs((total - n + 0.5) / (n + 0.5)))

    boosted = 0
    for doc in docs:
        location, title = doc["location"], re.sub(r"<[^>]+>", "", doc["title"])
        public = "#mjcffi." in location or (location.startswith("api/structs/")
                                            and "#" not in location)
        if not public or not re.fullmatch(r"\w+", title):
            continue
        doc["boost"] = round(idf(1) / idf(counts.get(title.lower(), 1)) * (1 + 2 / len(title)),
                             4)
        boosted += 1
    return boosted


@event_priority(-100)          # after the search plugin has written its index
def on_post_build(config):
    """Rank exact names first in the search index; fail the build when a page did not
    render as written (docs/hooks/rendering.py)."""
    from mkdocs.exceptions import PluginError
    site = pathlib.Path(config.site_dir)
    path = site / "search" / "search_index.json"
    if path.is_file():
        index = json.loads(path.read_text())
        rank_exact_names(index)
        path.write_text(json.dumps(index, ensure_ascii=False, separators=(",", ":")))
    problems = _sibling("rendering").check_site(pathlib.Path(config.docs_dir), site)
    if problems:
        raise PluginError("pages that did not render as written:\n  " + "\n  ".join(problems))
