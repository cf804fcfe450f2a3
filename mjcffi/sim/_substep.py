"""Substep callbacks written in C, compiled at run time, as mujoco-py's builder did.

`build_callback_fn(source, userdata_names)` compiles a string of C code that
defines `void fun(const mjModel* m, mjData* d)` into a small cffi module linked
against the libmujoco that mjcffi uses, loads it and returns the address of
`fun` as an int (mujoco-py's `substep_callback_ptr`).  Each name in
`userdata_names` becomes `#define name d->userdata[i]` ahead of the code.

Nothing is compiled at import.  A module is kept in a per-user cache folder
($MJCFFI_CACHE_DIR, else $XDG_CACHE_HOME/mjcffi/substep, else
~/.cache/mjcffi/substep), named by a hash of everything that went into it, so the
same code is compiled once per machine; in one process it is loaded once and
stays loaded (its address may be held by any MjSim).
"""

import contextlib
import hashlib
import importlib.machinery
import importlib.util
import io
import operator
import os
import shlex
import subprocess
import sys
import sysconfig
import tempfile
import threading

import cffi  # type: ignore[import-untyped]
import numpy as np

from .._generated.constants import mjVERSION_HEADER
from .._support.library import _mujoco_library_path, ffi


class SubstepCompileError(RuntimeError):
    """A substep callback's C code did not compile, link or load; the message is the compiler's."""


_CDEF = """
typedef struct mjModel_ mjModel;
typedef struct mjData_ mjData;
void fun(const mjModel* m, mjData* d);
"""
_PROLOGUE = "#include <mujoco/mujoco.h>\nvoid fun(const mjModel* m, mjData* d);\n"
_CFLAGS = ["-O2", "-fPIC", "-shared", "-w"]      # -w: cffi's glue warns; the user's errors stay
_loaded: dict = {}                               # key -> address of fun, this process
_lock = threading.Lock()


def defines(userdata_names):
    """The `#define name d->userdata[i]` lines for `userdata_names`."""
    lines = []
    for i, name in enumerate(userdata_names or ()):
        if not isinstance(name, str) or not name.isidentifier():
            raise ValueError(f"userdata name {name!r} is not a C identifier")
        lines.append(f"#define {name} d->userdata[{i}]\n")
    return "".join(lines)


def build_callback_fn(function_string, userdata_names=()):
    """Compile `function_string` (C code defining `fun`) and return the address of `fun`.

    SubstepCompileError, with the compiler's message, when it does not compile or
    defines no `fun`; TypeError when it is not a str."""
    if not isinstance(function_string, str):
        raise TypeError(f"the substep callback's C code must be a str, not "
                        f"{type(function_string).__name__}")
    source = _PROLOGUE + defines(userdata_names) + "#line 1 \"substep_callback\"\n" \
        + function_string + "\n#line 1 \"mjcffi_substep_glue\"\n"
    library = _mujoco_library_path()
    command = _compiler() + _CFLAGS
    key = _key(source, library, command)
    with _lock:
        address = _loaded.get(key)
        if address is None:
            address = _loaded[key] = _load(key, source, library, command)
    return address


def resolve(substep_callback, userdata_names):
    """(Python callable or None, C address or 0) for what MjSim was given."""
    if substep_callback is None:
        return None, 0
    if isinstance(substep_callback, str):
        return None, build_callback_fn(substep_callback, userdata_names)
    if isinstance(substep_callback, ffi.CData):
        kind = ffi.typeof(substep_callback)
        if kind.kind != "function" or len(kind.args) != 2 or kind.result.cname != "void":
            raise TypeError(f"substep_callback: a cffi {kind.cname} is not a C function "
                            "pointer void (*)(const mjModel*, mjData*)")
        return None, _address(int(ffi.cast("uintptr_t", substep_callback)))
    if isinstance(substep_callback, (bool, np.bool_)):
        raise TypeError("substep_callback must be C code (str), a C function's address "
                        "(int), a callable or None, not bool")
    if hasattr(substep_callback, "__index__"):
        return None, _address(operator.index(substep_callback))
    if callable(substep_callback):
        return substep_callback, 0
    raise TypeError("substep_callback must be C code (str), a C function's address (int), "
                    f"a callable or None, not {type(substep_callback).__name__}")


def c_pointer(address):
    """The mjfGeneric at `address`, or NULL for 0."""
    return ffi.cast("mjfGeneric", address)


def _address(value):
    if not 0 <= value < 2**64:
        raise ValueError(f"substep_callback: {value} is not a C function's address")
    return value


def cache_dir():
    """The folder that holds the compiled substep callbacks of this user."""
    folder = os.environ.get("MJCFFI_CACHE_DIR")
    if not folder:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        folder = os.path.join(base, "mjcffi")
    return os.path.join(folder, "substep")


def _compiler():
    return shlex.split(sysconfig.get_config_var("CC") or "cc")


def _key(source, library, command):
    """What the compiled file depends on, hashed: a change in any of it compiles anew."""
    parts = [source, library, str(os.path.getmtime(library)), " ".join(command), cffi.__version__,
             str(mjVERSION_HEADER), sys.implementation.cache_tag or "", sys.platform]
    return hashlib.sha256("\0".join(parts).encode()).hexdigest()[:24]


def _module_name(key):
    return f"_mjcffi_substep_{key}"


def _load(key, source, library, command):
    name = _module_name(key)
    folder = cache_dir()
    path = os.path.join(folder, name + importlib.machinery.EXTENSION_SUFFIXES[0])
    if not os.path.exists(path):
        os.makedirs(folder, exist_ok=True)
        _compile(name, source, library, command, folder, path)
    spec = importlib.util.spec_from_file_location(name, path)
    try:
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    except ImportError as exc:     # e.g. `fun` declared but never defined
        os.remove(path)
        raise SubstepCompileError(f"the substep callback did not load: {exc}. Its C code "
                                  "must define void fun(const mjModel* m, mjData* d)") from None
    sys.modules.setdefault(name, module)
    return int(module.ffi.cast("uintptr_t", module.ffi.addressof(module.lib, "fun")))


def _compile(name, source, library, command, folder, path):
    """cffi's C for the module, compiled by the C compiler with its messages captured."""
    builder = cffi.FFI()
    builder.cdef(_CDEF)
    builder.set_source(name, source)
    package = os.path.dirname(library)
    with tempfile.TemporaryDirectory(dir=folder) as work:
        c_file = os.path.join(work, name + ".c")
        with contextlib.redirect_stdout(io.StringIO()):     # it says "generating ..."
            builder.emit_c_code(c_file)
        built = os.path.join(work, os.path.basename(path))
        argv = command + [
            "-I", os.path.join(package, "include"), "-I", sysconfig.get_paths()["include"],
            c_file, "-o", built, os.path.join(package, os.path.basename(library)),
            f"-Wl,-rpath,{package}"]
        try:
            result = subprocess.run(argv, capture_output=True, text=True, check=False)
        except OSError as exc:
            raise SubstepCompileError(f"no C compiler to build the substep callback "
                                      f"({argv[0]}): {exc}") from None
        if result.returncode:
            raise SubstepCompileError("the substep callback's C code did not compile:\n"
                                      + _user_lines(result.stderr or result.stdout))
        os.replace(built, path)     # atomic: another process may build the same one


def _user_lines(text):
    """The compiler's message, less the lines about cffi's glue when the user's are there."""
    lines = text.strip().splitlines()
    own = [line for line in lines if "substep_callback" in line]
    return "\n".join(lines if not own else _with_context(lines)).strip()


def _with_context(lines):
    """The lines from the first that names the user's code on."""
    for i, line in enumerate(lines):
        if "substep_callback" in line:
            return lines[i:]
    return lines
