"""Build script: compiles mjcffi._mjcffi and mjcffi._descriptors; everything else lives
in pyproject.toml.

cffi_modules has no pyproject.toml spelling, and two wheel properties need code:

- both modules are built against CPython's limited API (hence `_mjcffi.abi3.so`,
  `_descriptors.abi3.so`), so one wheel serves every CPython from 3.11 on: tag it
  cp311-abi3.  A free-threaded CPython has no limited API; both build per-Python
  there, and so does the wheel.
- a Python built with `-Wl,-rpath,<its prefix>/lib` in LDSHARED (pyenv's are)
  passes that path on to every extension; in a wheel it names a folder of the
  build machine, so it is dropped.  The module's own rpath into the mujoco-core
  wheel ($ORIGIN/../mujoco, from mjcffi/_c/build.py) is relative and stays.

One compile per checkout: every `pip install -e '.[extra]'` runs this build again, in a
fresh build folder.  The module in the source tree (mjcffi/_mjcffi.abi3.so) has a stamp
beside it (`.inputs`): a digest of everything its compile read (the C that cffi
generates, the C files and headers of mjcffi/_c/, MuJoCo's headers and library, the
compiler's command lines, this Python's version) and one of the module itself.  When a
new build's digest and the module's match the stamp, the module is copied instead of
compiled again; `build_ext --force` compiles anyway.
"""

import filecmp
import hashlib
import os
import pathlib
import shutil
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

OLDEST_PYTHON = "cp311"   # pyproject.toml's requires-python, as mujoco-core 4.0.0
# the limited API of that Python (0x030B0000), the one the abi3 tag promises
LIMITED_API = f"0x03{int(OLDEST_PYTHON[3:]):02X}0000"
FREE_THREADED = bool(sysconfig.get_config_var("Py_GIL_DISABLED"))   # no limited API there


def is_absolute_rpath(argument):
    """True for a linker argument `-Wl,-rpath,/some/path` (or -R/-rpath= spellings)."""
    if not argument.startswith("-Wl,"):
        return False
    parts = argument[len("-Wl,"):].split(",")
    paths = [p.split("=", 1)[1] for p in parts if p.startswith(("-rpath=", "--rpath="))]
    paths += [b for a, b in zip(parts, parts[1:]) if a in ("-rpath", "--rpath", "-R")]
    return any(os.path.isabs(p) for p in paths)


ROOT = pathlib.Path(__file__).resolve().parent


def inputs_digest(ext, compiler):
    """sha256 of what compiling and linking `ext` reads: file contents (never their
    paths, which name pip's temporary build folder), flags, and this Python."""
    digest = hashlib.sha256()

    def add(label, data):
        data = data if isinstance(data, bytes) else repr(data).encode()
        digest.update(f"{label} {len(data)}\n".encode() + data)

    for source in ext.sources:            # cffi's generated C first, then mjcffi/_c/*.c
        add("source " + os.path.basename(source), pathlib.Path(source).read_bytes())
    for folder in ext.include_dirs:       # mjcffi/_c/, its generated/, MuJoCo's include/
        for header in sorted(pathlib.Path(folder).rglob("*.h")):
            add("header " + header.relative_to(folder).as_posix(), header.read_bytes())
    for folder in ext.library_dirs:       # libmujoco.so.<version> of mujoco-core
        for library in ext.libraries:
            path = pathlib.Path(folder) / library.lstrip(":")
            if library.startswith(":") and path.is_file():
                add("library " + path.name, path.read_bytes())
    for name in ("compiler_so", "linker_so"):
        add(name, getattr(compiler, name, None))
    add("ext", (ext.name, ext.define_macros, ext.undef_macros, ext.libraries,
                ext.extra_compile_args, ext.extra_link_args, getattr(ext, "py_limited_api", None)))
    add("python", (sys.version, sysconfig.get_config_var("EXT_SUFFIX")))
    return digest.hexdigest()


def file_digest(path):
    """sha256 of a file: the stamp names the very module it was written for."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


class BuildExtension(build_ext):
    """build_ext whose link line carries no absolute rpath from Python's own LDSHARED,
    and which copies the source tree's module instead of compiling the same inputs again."""

    def run(self):
        self._compiled = []
        super().run()
        # an editable install has copied what it compiled into the tree: stamp that copy
        for digest, built, tree in self._compiled:
            if tree.is_file() and filecmp.cmp(built, tree, shallow=False):
                tree.with_name(tree.name + ".inputs").write_text(f"{digest} {file_digest(tree)}\n")

    def build_extensions(self):
        for name in ("linker_so", "linker_so_cxx"):
            command = getattr(self.compiler, name, None)
            if command:
                setattr(self.compiler, name, [a for a in command if not is_absolute_rpath(a)])
        super().build_extensions()

    def build_extension(self, ext):
        digest = inputs_digest(ext, self.compiler)
        built = pathlib.Path(self.get_ext_fullpath(ext.name)).resolve()
        tree = ROOT / self.get_ext_filename(ext.name)
        stamp = tree.with_name(tree.name + ".inputs")
        if (not self.force and tree.is_file() and stamp.is_file()
                and stamp.read_text().split() == [digest, file_digest(tree)]):
            if tree.resolve() != built:
                built.parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(tree, built)
            print(f"mjcffi: {tree.relative_to(ROOT)} was compiled from these same inputs "
                  f"(digest {digest[:12]}); reusing it instead of compiling again")
            return
        # compile even where the sources are older than the module: the digest says an
        # input changed (flags, headers, the library), which setuptools' mtime check misses
        force, self.force = self.force, True
        try:
            super().build_extension(ext)
        finally:
            self.force = force
        self._compiled.append((digest, built, tree))


def wheel_options():
    if FREE_THREADED:
        return {}
    return {"bdist_wheel": {"py_limited_api": OLDEST_PYTHON}}


def descriptors_extension():
    """mjcffi._descriptors, the C field descriptors (mjcffi/_c/descriptors.c): a plain
    CPython extension beside the cffi module, on the limited API where there is one."""
    limited = not FREE_THREADED
    # libc named outright: the compiler inlines all the module uses of it, and a module
    # that needs no libc is one auditwheel cannot place ("couldn't detect libc")
    return Extension("mjcffi._descriptors", ["mjcffi/_c/descriptors.c"],
                     define_macros=[("Py_LIMITED_API", LIMITED_API)] if limited else [],
                     extra_link_args=["-Wl,--no-as-needed", "-lc"],
                     py_limited_api=limited)


setup(cffi_modules=["mjcffi/_c/build.py:ffibuilder"],
      ext_modules=[descriptors_extension()],
      cmdclass={"build_ext": BuildExtension},
      options=wheel_options())
