"""Build script: compiles mjcffi._mjcffi; everything else lives in pyproject.toml.

cffi_modules has no pyproject.toml spelling, and two wheel properties need code:

- cffi builds the module against CPython's limited API (hence `_mjcffi.abi3.so`),
  so one wheel serves every CPython from 3.11 on: tag it cp311-abi3.  A
  free-threaded CPython has no limited API; cffi builds per-Python there, and so
  does the wheel.
- a Python built with `-Wl,-rpath,<its prefix>/lib` in LDSHARED (pyenv's are)
  passes that path on to every extension; in a wheel it names a folder of the
  build machine, so it is dropped.  The module's own rpath into the mujoco-core
  wheel ($ORIGIN/../mujoco, from mjcffi/_c/build.py) is relative and stays.
"""

import os
import sysconfig

from setuptools import setup
from setuptools.command.build_ext import build_ext

OLDEST_PYTHON = "cp311"   # pyproject.toml's requires-python, as mujoco-core 4.0.0


def is_absolute_rpath(argument):
    """True for a linker argument `-Wl,-rpath,/some/path` (or -R/-rpath= spellings)."""
    if not argument.startswith("-Wl,"):
        return False
    parts = argument[len("-Wl,"):].split(",")
    paths = [p.split("=", 1)[1] for p in parts if p.startswith(("-rpath=", "--rpath="))]
    paths += [b for a, b in zip(parts, parts[1:]) if a in ("-rpath", "--rpath", "-R")]
    return any(os.path.isabs(p) for p in paths)


class BuildExtension(build_ext):
    """build_ext whose link line carries no absolute rpath from Python's own LDSHARED."""

    def build_extensions(self):
        for name in ("linker_so", "linker_so_cxx"):
            command = getattr(self.compiler, name, None)
            if command:
                setattr(self.compiler, name, [a for a in command if not is_absolute_rpath(a)])
        super().build_extensions()


def wheel_options():
    if sysconfig.get_config_var("Py_GIL_DISABLED"):
        return {}
    return {"bdist_wheel": {"py_limited_api": OLDEST_PYTHON}}


setup(cffi_modules=["mjcffi/_c/build.py:ffibuilder"],
      cmdclass={"build_ext": BuildExtension},
      options=wheel_options())
