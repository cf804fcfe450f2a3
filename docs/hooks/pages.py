"""MkDocs hook: the pages generated at build time, so that nothing generated is committed.

- `api/*.md`: the API reference. Every name of `mjcffi.__all__` and `mjcffi.sim.__all__`
  is on one page: functions and classes as mkdocstrings directives (their docstrings and
  signatures), values (constants, string tables, `ffi`, `lib`) in tables.
- `results.md`, `accuracy-report.md` (with its plot) and `conformance-report.md`: the
  reports the repository keeps beside the code, shown in the site as they are.

`api_pages()` is what tests/test_docs.py checks: every public name is on a page.
"""

import inspect
import pathlib

# Function pages, by prefix: (page, title, what the functions do).
FUNCTION_PAGES = (
    ("mj_", "functions-mj", "Simulation (mj_*)", "Loading, stepping, computing and querying."),
    ("mju_", "functions-mju", "Utilities (mju_*)", "Vector, matrix, quaternion and misc math."),
    ("mjd_", "functions-mjd", "Derivatives (mjd_*)", "Finite-difference and analytic derivatives."),
    ("mjv_", "functions-mjv", "Visualization (mjv_*)", "Scenes, cameras, perturbations."),
    ("mjr_", "functions-mjr", "Rendering (mjr_*)", "OpenGL rendering with an MjrContext."),
    ("mjui_", "functions-mjui", "UI (mjui_*)", "MuJoCo's user interface framework."),
    ("mjs_", "functions-mjs", "Model editing (mjs_*)", "The raw spec API (MjSpec wraps it)."),
    ("mj", "functions-other", "Plugins, caches and the rest", "mjp_*, mjc_*, mjb_* and others."),
)

# Submodules with a page of their own: (module, title).
MODULES = (
    ("mjcffi.rollout", "mjcffi.rollout"), ("mjcffi.batch", "mjcffi.batch"),
    ("mjcffi.minimize", "mjcffi.minimize"), ("mjcffi.distributed", "mjcffi.distributed"),
    ("mjcffi.tune", "mjcffi.tune"), ("mjcffi.viewer", "mjcffi.viewer"),
    ("mjcffi.egl", "mjcffi.egl"), ("mjcffi.osmesa", "mjcffi.osmesa"),
    ("mjcffi.glfw", "mjcffi.glfw"),
)

REPORTS = {"results.md": "benchmarks/RESULTS.md", "accuracy-report.md": "benchmarks/ACCURACY.md",
           "conformance-report.md": "CONFORMANCE.md"}
ASSETS = {"accuracy.png": "benchmarks/accuracy.png"}


def _directive(obj, name):
    """`::: module.qualname` for a function or class, or None for a value."""
    if not (inspect.isclass(obj) or inspect.isfunction(obj)):
        return None
    module = getattr(obj, "__module__", "") or ""
    if not module.startswith("mjcffi"):
        return None
    return f"::: {module}.{obj.__qualname__}\n"


def _value_table(rows):
    lines = ["| name | type | value |", "| --- | --- | --- |"]
    for name, obj in rows:
        text = repr(obj)
        text = text if len(text) <= 60 else text[:57] + "..."
        text = text.replace("|", "\\|").replace("`", "'")
        lines.append(f"| `{name}` | `{type(obj).__name__}` | `{text}` |")
    return "\n".join(lines) + "\n"


def _section(names, module):
    """Directives for the functions and classes of `names`, a table for the rest."""
    parts, values = [], []
    for name in names:
        obj = getattr(module, name)
        directive = _directive(obj, name)
        if directive is None:
            values.append((name, obj))
        else:
            parts.append(directive)
    if values:
        parts.append("## Values\n\n" + _value_table(values))
    return "\n".join(parts)


def api_pages():
    """{path under docs/: Markdown} of the API reference."""
    import enum
    import mjcffi
    import mjcffi.sim
    from mjcffi import functions

    names = list(mjcffi.__all__)
    function_names = set(functions.NAMES)
    pages, index = {}, ["# API reference\n",
                        "Generated from the docstrings and signatures at build time "
                        "(docs/hooks/pages.py). mjcffi's names follow the official bindings'; "
                        "the MuJoCo C API reference explains each function in depth.\n"]
    left = [n for n in names if n not in function_names]
    for prefix, page, title, about in FUNCTION_PAGES:
        mine = [n for n in names if n in function_names and n.startswith(prefix)]
        function_names -= set(mine)
        pages[f"api/{page}.md"] = f"# {title}\n\n{about}\n\n" + _section(mine, mjcffi)
        index.append(f"- [{title}]({page.split('/')[-1]}.md): {len(mine)} functions")
    enums = [n for n in left if inspect.isclass(getattr(mjcffi, n))
             and issubclass(getattr(mjcffi, n), enum.Enum)]
    classes = [n for n in left if n not in enums and inspect.isclass(getattr(mjcffi, n))]
    rest = [n for n in left if n not in enums and n not in classes]
    constants = [n for n in rest if isinstance(getattr(mjcffi, n), (int, float))]
    helpers = [n for n in rest if n not in constants]
    pages["api/classes.md"] = "# Classes\n\nStructs, `MjModel`, `MjData`, `MjSpec` and its " \
                              "elements, contexts and errors.\n\n" + _section(classes, mjcffi)
    pages["api/enums.md"] = "# Enums\n\nMuJoCo's enums, as `enum.IntEnum`s.\n\n" + \
                            _section(enums, mjcffi)
    pages["api/constants.md"] = "# Constants\n\nMuJoCo's `#define` constants and sizes.\n\n" + \
                                _value_table([(n, getattr(mjcffi, n)) for n in constants])
    pages["api/helpers.md"] = "# Helpers and values\n\nCallbacks, handlers, string tables, " \
                              "the raw C API.\n\n" + _section(helpers, mjcffi)
    index += ["- [Classes](classes.md)", "- [Enums](enums.md)", "- [Constants](constants.md)",
              "- [Helpers and values](helpers.md)"]
    for module, title in MODULES:
        slug = module.replace(".", "-")
        pages[f"api/{slug}.md"] = f"# {title}\n\n::: {module}\n"
        index.append(f"- [{title}]({slug}.md)")
    pages["api/mjcffi-sim.md"] = "# mjcffi.sim (mujoco-py)\n\n::: mjcffi.sim\n    options:\n" \
                                 "      members: false\n\n" + _section(mjcffi.sim.__all__, mjcffi.sim)
    index.append("- [mjcffi.sim (mujoco-py)](mjcffi-sim.md)")
    pages["api/index.md"] = "\n".join(index) + "\n"
    return pages


def on_files(files, config):
    from mkdocs.structure.files import File
    root = pathlib.Path(config.config_file_path).resolve().parent     # the repository
    for path, text in api_pages().items():
        files.append(File.generated(config, path, content=text))
    for path, source in REPORTS.items():
        files.append(File.generated(config, path, content=(root / source).read_text()))
    for path, source in ASSETS.items():
        files.append(File.generated(config, path, content=(root / source).read_bytes()))
    return files
