"""Load the compiled module mjcffi._mjcffi and check it against libmujoco.

The compiled module links `libmujoco.so.4.0.0` with an rpath to the installed
`mujoco` package (site-packages/mujoco).  An editable install keeps the module
in the source tree, where that rpath does not reach, so on a failed first try
libmujoco is preloaded by its full path: the dynamic loader then matches the
module's dependency by soname.
"""

import importlib.util
import os

from .._generated.constants import mjVERSION_HEADER

MUJOCO_LIBRARY = "libmujoco.so.4.0.0"
_VERSION_TEXT = f"{mjVERSION_HEADER // 1000000}.{mjVERSION_HEADER // 1000 % 1000}.{mjVERSION_HEADER % 1000}"
_FIX = f"pip install 'mujoco-core=={_VERSION_TEXT}'"


def _mujoco_library_path():
    spec = importlib.util.find_spec("mujoco")
    if spec is None or not spec.submodule_search_locations:
        raise ImportError(
            f"mjcffi needs MuJoCo {_VERSION_TEXT} from the mujoco-core wheel, which is not "
            f"installed. Fix: {_FIX}")
    for folder in spec.submodule_search_locations:
        path = os.path.join(folder, MUJOCO_LIBRARY)
        if os.path.exists(path):
            return path
    raise ImportError(
        f"mjcffi needs {MUJOCO_LIBRARY} (MuJoCo {_VERSION_TEXT}), but the installed mujoco "
        f"package has no such file: it is another version. Fix: {_FIX}")


def _import_compiled():
    try:
        from .. import _mjcffi
        return _mjcffi
    except ModuleNotFoundError as exc:
        if exc.name != f"{__package__}._mjcffi":
            raise
        raise ImportError(
            "mjcffi's compiled module is missing: this is a source tree that was not built. "
            "Install it with: pip install -e .") from None
    except ImportError:
        pass            # libmujoco was not found through the rpath: preload it
    import ctypes
    ctypes.CDLL(_mujoco_library_path())
    from .. import _mjcffi
    return _mjcffi


def load():
    """Return (ffi, lib) after checking that headers and library agree."""
    compiled = _import_compiled()
    lib = compiled.lib
    versions = {"generated headers": mjVERSION_HEADER,
                "compiled headers": lib.mjcffi_header_version(),
                "libmujoco": lib.mj_version()}
    if len(set(versions.values())) != 1:
        found = ", ".join(f"{k} {v}" for k, v in versions.items())
        raise ImportError(f"mjcffi was generated for MuJoCo {_VERSION_TEXT} but found {found}. "
                          f"Fix: {_FIX}, then reinstall mjcffi")
    return compiled.ffi, lib


ffi, lib = load()
