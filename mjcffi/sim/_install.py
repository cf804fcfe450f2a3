"""`install_as_mujoco_py()`: make `import mujoco_py` give this face, at every module
path of mujoco-py 2.1's package.

After the call, `sys.modules["mujoco_py"]` is mjcffi.sim itself, and a finder
first on sys.meta_path answers `import mujoco_py.<name>` with the module object
`mjcffi.sim.<name>` (mjviewer, mjrenderpool, builder, generated, generated.const,
modder, cymj, const, functions, utils, version), never a second copy of it: a
class imported either way is the same class.  mujoco-py's `gl` and `pxd`
packages held C and Cython declarations only; they import as empty modules.
"""

import importlib
import importlib.abc
import importlib.util
import sys
import types

PACKAGE = "mujoco_py"
_FACE = __package__                      # mjcffi.sim

# mujoco-py's packages that held no Python: name -> what they were
_EMPTY = {"gl": "mujoco-py's C shims for EGL and OSMesa (mjcffi renders with "
                "mjcffi.rendering).",
          "pxd": "mujoco-py's Cython declarations of MuJoCo (mjcffi's bindings are "
                 "generated from MuJoCo's headers)."}


class _FaceFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Answers `import mujoco_py.<name>` with mjcffi.sim.<name>, the module itself."""

    def find_spec(self, fullname, path=None, target=None):
        rest = _submodule(fullname)
        if rest is None:
            return None
        if rest in _EMPTY or _face_has(rest):
            return importlib.util.spec_from_loader(fullname, self)
        return None                      # not mujoco-py's: the normal search goes on

    def create_module(self, spec):
        rest = _submodule(spec.name)
        if rest in _EMPTY:
            return types.ModuleType(spec.name, _EMPTY[rest])
        return None                      # a placeholder, replaced in exec_module

    def exec_module(self, module):
        rest = _submodule(module.__name__)
        if rest not in _EMPTY:
            # the import system reads the module back from sys.modules after this call
            sys.modules[module.__name__] = importlib.import_module(f"{_FACE}.{rest}")


def _submodule(fullname):
    """'mjviewer' for 'mujoco_py.mjviewer'; None for a name outside mujoco_py."""
    prefix = PACKAGE + "."
    return fullname[len(prefix):] if fullname.startswith(prefix) else None


def _face_has(rest):
    """Whether mjcffi.sim has a module `rest` (dotted: 'generated.const')."""
    try:
        return importlib.util.find_spec(f"{_FACE}.{rest}") is not None
    except ModuleNotFoundError:          # a parent that is not a package
        return False


def install_as_mujoco_py():
    """Make `import mujoco_py` (and every `mujoco_py.<module>` of mujoco-py 2.1) give
    mjcffi.sim, so that mujoco-py code runs unchanged.  Returns mjcffi.sim.

    Call it before anything imports mujoco_py, for example at the top of the program
    or in a sitecustomize.py.  RuntimeError if another mujoco_py is imported already;
    calling it again does nothing."""
    face = importlib.import_module(_FACE)
    present = sys.modules.get(PACKAGE)
    if present is not None and present is not face:
        where = getattr(present, "__file__", None) or repr(present)
        raise RuntimeError(f"mujoco_py is already imported (from {where}): call "
                           f"install_as_mujoco_py() before anything imports mujoco_py")
    if not any(isinstance(finder, _FaceFinder) for finder in sys.meta_path):
        sys.meta_path.insert(0, _FaceFinder())
    sys.modules[PACKAGE] = face
    return face
