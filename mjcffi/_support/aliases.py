"""Submodules of mjcffi imported under another name for the package.

Code that runs `sys.modules['mujoco'] = mjcffi` and then `import mujoco.rollout`
would otherwise get a second copy of mjcffi/rollout.py named 'mujoco.rollout',
with its own module state and classes, and a second copy of every module it
imports.  The finder here answers such an import with the module itself:
`mujoco.rollout` is `mjcffi.rollout`.  It acts only while the first part of
the name is bound to mjcffi in sys.modules; every other import passes by.
"""

import importlib
import importlib.util
import sys

_PACKAGE = __name__.partition(".")[0]      # mjcffi


class _SameModule:
    """A loader that hands back the already-imported canonical module."""

    def __init__(self, canonical):
        self.canonical = canonical

    def create_module(self, spec):
        module = importlib.import_module(self.canonical)
        self.own_spec = module.__spec__
        return module

    def exec_module(self, module):
        # the import system has just set module.__spec__ to the alias's: undo that
        module.__spec__ = self.own_spec


class AliasFinder:
    """A meta path finder: `<alias>.x` is `mjcffi.x` when sys.modules[alias] is mjcffi."""

    @staticmethod
    def find_spec(fullname, path=None, target=None):
        alias, dot, rest = fullname.partition(".")
        if not dot or alias == _PACKAGE:
            return None
        package = sys.modules.get(_PACKAGE)
        if package is None or sys.modules.get(alias) is not package:
            return None
        canonical = f"{_PACKAGE}.{rest}"
        if canonical not in sys.modules and importlib.util.find_spec(canonical) is None:
            return None
        return importlib.util.spec_from_loader(fullname, _SameModule(canonical))


def install():
    """Put the finder first on sys.meta_path (once), ahead of the path finder."""
    if AliasFinder not in sys.meta_path:
        sys.meta_path.insert(0, AliasFinder)
