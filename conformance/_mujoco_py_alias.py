"""A `mujoco_py` package that is mjcffi.sim, for running mujoco-py's own tests.

The conformance runner copies this file, as it is, to `mujoco_py/__init__.py`
in a temporary folder, beside the `mujoco_py/tests/` it extracts from
mujoco-py's wheel.  Then `from mujoco_py import MjSim` reads mjcffi.sim,
`import mujoco_py.const` gives mjcffi.sim.const (the module object itself,
not a copy), and `mujoco_py.tests` stays the real extracted test package.

The submodules are imported on first use, as in mujoco-py, so a test file
that needs no rendering never imports the rendering modules.
"""

import importlib
import importlib.abc
import importlib.util
import sys

PACKAGE = "mujoco_py"

# mujoco-py's submodule -> the mjcffi module that plays its part.
SUBMODULES = {
    "const": "mjcffi.sim.const",
    "functions": "mjcffi.sim.functions",
    "cymj": "mjcffi.sim.cymj",
    "modder": "mjcffi.sim.modder",
    "generated": "mjcffi.sim.generated",
    "generated.const": "mjcffi.sim.generated.const",
    "mjviewer": "mjcffi.sim",
    "mjrenderpool": "mjcffi.sim",
    "builder": "mjcffi.sim",
}


class SubmoduleAlias(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Answers `import <package>.<submodule>` with the mjcffi module SUBMODULES names."""

    def __init__(self, package=PACKAGE):
        self.package = package

    def target(self, fullname):
        """The mjcffi module name for `fullname`, or None when it is not an alias."""
        prefix = self.package + "."
        if fullname.startswith(prefix):
            return SUBMODULES.get(fullname[len(prefix):])
        return None

    def find_spec(self, fullname, path=None, target=None):
        if self.target(fullname) is None:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        return None                      # a placeholder, replaced in exec_module

    def exec_module(self, module):
        # The import system takes the module back from sys.modules after this
        # call, so the alias names the mjcffi module itself, its spec untouched.
        sys.modules[module.__name__] = importlib.import_module(self.target(module.__name__))


def install(package=PACKAGE):
    """Put one SubmoduleAlias for `package` first on sys.meta_path (once)."""
    for finder in sys.meta_path:
        if isinstance(finder, SubmoduleAlias) and finder.package == package:
            return finder
    finder = SubmoduleAlias(package)
    sys.meta_path.insert(0, finder)
    return finder


if __name__ == PACKAGE:
    install()

    def __getattr__(name):
        # `mujoco_py.cymj` without an import, and every name of mjcffi.sim.
        if name in SUBMODULES:
            return importlib.import_module(f"{PACKAGE}.{name}")
        return getattr(importlib.import_module("mjcffi.sim"), name)
