"""The official package's pure-Python subpackages, run on top of mjcffi.

`mjcffi.sysid`, `mjcffi.usd`, `mjcffi.msh2obj`, `mjcffi.introspect` and `mjcffi.mjx`
(from the mujoco-mjx distribution) are the official `mujoco` package's own Python
source, read from where pip installed it and executed as modules named
`mjcffi.<name>...`.  Nothing of theirs is copied into this repository, and they keep
in step with the installed official release by construction.

How: a meta path finder answers `mjcffi.<name>[...]` with the official file of the
same path.  Its loader executes that file with a `__builtins__` whose `__import__`
reads `mujoco` as `mjcffi`, so the official code's `import mujoco`, `from mujoco
import ...` and `import mujoco.x.y` (at module level or inside functions) all get
mjcffi, whether or not the official package is imported as `mujoco` in the same
process (it keeps working unchanged: its own `mujoco.sysid` is a separate copy).

- The official compiled modules (`mujoco._structs`, ...) are never imported on the
  way; a compiled file under one of these folders (mujoco-usd's writer, say) is
  refused with an error that says why.
- Under the swap (`sys.modules['mujoco'] is mjcffi`) each module is entered in
  sys.modules under both names, `mjcffi.x` and `mujoco.x`, before its code runs, so
  that a package importing its own submodules during its import (MJX does) finds
  one module under either name.
- A module's `__file__` and `__path__` are the official ones, so its resources
  (`epath.resource_path('mujoco.mjx') / 'test_data'`, `os.path.dirname(__file__)`)
  are the official package's data.
- A dependency that is missing raises ModuleNotFoundError naming the pip extra that
  installs it (`pip install 'mjcffi[usd]'`); it stays a ModuleNotFoundError, which
  the official code's own optional-import guards catch.
- `python -m mjcffi.msh2obj` runs the official script with the same `mujoco`.

Names added to `builtins` after the first such import are not seen by these modules
(their builtins are a copy, made then, with `__import__` replaced).

Support module: imports only the standard library.
"""

import builtins
import importlib.machinery
import importlib.util
import os
import sys

PACKAGE = __name__.partition(".")[0]        # mjcffi
OFFICIAL = "mujoco"

# subpackage -> (the pip extra of mjcffi that installs what it needs, or None;
#                the top-level modules that extra brings)
SUBPACKAGES = {
    "sysid": ("sysid", frozenset({"absl", "colorama", "imageio", "jinja2", "matplotlib",
                                  "plotly", "yaml", "scipy", "tabulate",
                                  "typing_extensions"})),
    "usd": ("usd", frozenset({"pxr", "PIL"})),
    "msh2obj": (None, frozenset()),
    "introspect": (None, frozenset()),
    "mjx": ("mjx", frozenset({"jax", "jaxlib", "ml_dtypes", "opt_einsum", "scipy",
                              "trimesh", "etils", "absl"})),
}
# what installs a subpackage that the official wheel may lack
_DISTRIBUTION = {"mjx": "mujoco-mjx"}

_EXTENSION_SUFFIXES = tuple(importlib.machinery.EXTENSION_SUFFIXES)


def official_roots():
    """The folders of the official `mujoco` package: the installed package's own, then
    any other `mujoco` folder on sys.path (where another distribution such as mujoco-mjx
    may have put its part), in sys.path order, as the official package's
    pkgutil.extend_path joins them.  Nothing is imported."""
    roots = []
    for entry in sys.path:
        folder = os.path.join(entry or os.curdir, OFFICIAL)
        if os.path.isdir(folder):
            folder = os.path.realpath(folder)
            if folder not in roots:
                roots.append(folder)
    own = [r for r in roots if os.path.isfile(os.path.join(r, "__init__.py"))]
    return own[:1] + [r for r in roots if r not in own[:1]]


def official_name(name):
    """`mjcffi.x.y` -> `mujoco.x.y`."""
    return OFFICIAL + name[len(PACKAGE):]


def _swapped():
    package = sys.modules.get(PACKAGE)
    return package is not None and sys.modules.get(OFFICIAL) is package


# ------------------------------------------------------------------ imports

def _import(name, globals=None, locals=None, fromlist=(), level=0):
    """`__import__` for the official source: `mujoco[.x]` is `mjcffi[.x]`."""
    if level == 0 and (name == OFFICIAL or name.startswith(OFFICIAL + ".")):
        name = PACKAGE + name[len(OFFICIAL):]
    return builtins.__import__(name, globals, locals, fromlist, level)


_builtins = None


def redirecting_builtins():
    """The `__builtins__` of every module loaded here: builtins, with _import."""
    global _builtins
    if _builtins is None:
        _builtins = dict(vars(builtins), __import__=_import)
    return _builtins


# ------------------------------------------------------------------ errors

def _needs_extra(fullname, error):
    """The ModuleNotFoundError to raise when `error` (a ModuleNotFoundError) escapes
    the official module `fullname`: one that names mjcffi's pip extra when the missing
    module is one the extra installs; `error` itself otherwise."""
    if getattr(error, "_mjcffi_extra", False):
        return error                       # a submodule's, already explained
    sub = fullname.split(".")[1]
    extra, provides = SUBPACKAGES[sub]
    missing = (error.name or "").partition(".")[0]
    if extra is None or missing not in provides:
        return error
    new = ModuleNotFoundError(
        f"{PACKAGE}.{sub} needs the module {missing!r}, which is not installed: "
        f"pip install '{PACKAGE}[{extra}]' ({error})", name=error.name)
    new._mjcffi_extra = True
    return new


class _Refused:
    """A loader that refuses to make its module, with the reason."""

    def __init__(self, message, name):
        self.message = message
        self.name = name

    def create_module(self, spec):
        error = ModuleNotFoundError(self.message, name=self.name)
        error._mjcffi_extra = True
        raise error

    def exec_module(self, module):      # never reached: create_module raises
        raise AssertionError(self.message)


# ------------------------------------------------------------------ loading

class OfficialSourceLoader(importlib.machinery.SourceFileLoader):
    """Executes an official source file as an mjcffi module (see the module docstring).
    `path` is None for a folder without `__init__.py` (a namespace package), which has
    no code."""

    def __init__(self, fullname, path, package):
        super().__init__(fullname, path)
        self._package = package

    def exec_module(self, module):
        name = module.__name__
        module.__dict__["__builtins__"] = redirecting_builtins()
        alias = official_name(name)
        aliased = _swapped() and sys.modules.setdefault(alias, module) is module
        try:
            if self.path is not None:
                exec(super().get_code(name), module.__dict__)
        except BaseException as error:
            if aliased and sys.modules.get(alias) is module:
                del sys.modules[alias]
            if isinstance(error, ModuleNotFoundError):
                new = _needs_extra(name, error)
                if new is not error:
                    raise new from error
            raise

    def get_code(self, fullname):
        """For `python -m mjcffi.x` (runpy runs this code as `__main__`): code that runs
        the official script under the same `mujoco` as an import of it gets."""
        return compile(f"import {__name__} as _official_source\n"
                       f"_official_source.run_as_main(globals())\n",
                       f"<{fullname} as __main__>", "exec")

    def get_source(self, fullname):
        return None if self.path is None else super().get_source(fullname)

    def is_package(self, fullname):
        return self._package


def run_as_main(main_globals):
    """Run the official file of `main_globals['__spec__']` in `main_globals`, with the
    builtins its modules have (runpy's `__main__` has the plain ones)."""
    loader = main_globals["__spec__"].loader
    code = importlib.machinery.SourceFileLoader.get_code(loader, loader.name)
    main_globals["__builtins__"] = redirecting_builtins()
    exec(code, main_globals)


def _spec(fullname):
    """The spec of official module `fullname` (mjcffi.<subpackage>...), a refusing one
    for a compiled file, or None where there is no such module."""
    parts = fullname.split(".")[1:]
    roots = official_roots()
    if not roots:
        return importlib.util.spec_from_loader(fullname, _Refused(
            f"{fullname} runs the official `{OFFICIAL}` package's source, and that "
            f"package is not installed: pip install mujoco-core", fullname))
    for root in roots:
        base = os.path.join(root, *parts)
        init = os.path.join(base, "__init__.py")
        if os.path.isfile(init):
            return importlib.util.spec_from_file_location(
                fullname, init, loader=OfficialSourceLoader(fullname, init, True),
                submodule_search_locations=[base])
        if os.path.isfile(base + ".py"):
            return importlib.util.spec_from_file_location(
                fullname, base + ".py", loader=OfficialSourceLoader(fullname, base + ".py",
                                                                    False))
        if any(os.path.isfile(base + suffix) for suffix in _EXTENSION_SUFFIXES):
            return importlib.util.spec_from_loader(fullname, _Refused(
                f"{official_name(fullname)} is compiled against the official bindings' "
                f"own classes; mjcffi runs only the official package's Python source",
                fullname))
    for root in roots:              # a folder of Python files without __init__.py
        base = os.path.join(root, *parts)
        if os.path.isdir(base):
            spec = importlib.machinery.ModuleSpec(
                fullname, OfficialSourceLoader(fullname, None, True), is_package=True)
            spec.submodule_search_locations = [base]
            return spec
    sub = parts[0]
    if len(parts) == 1 and sub in _DISTRIBUTION:
        extra = SUBPACKAGES[sub][0]
        return importlib.util.spec_from_loader(fullname, _Refused(
            f"{fullname} is the official {_DISTRIBUTION[sub]} package's `{OFFICIAL}.{sub}`, "
            f"run on mjcffi, and {_DISTRIBUTION[sub]} is not installed: "
            f"pip install '{PACKAGE}[{extra}]'", fullname))
    return None


class OfficialSourceFinder:
    """A meta path finder for `mjcffi.<subpackage>...` (SUBPACKAGES)."""

    @staticmethod
    def find_spec(fullname, path=None, target=None):
        package, dot, rest = fullname.partition(".")
        if package != PACKAGE or rest.partition(".")[0] not in SUBPACKAGES:
            return None
        return _spec(fullname)


def install():
    """Put the finder first on sys.meta_path (once), ahead of the path finder."""
    if OfficialSourceFinder not in sys.meta_path:
        sys.meta_path.insert(0, OfficialSourceFinder)
