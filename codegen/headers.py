"""Find MuJoCo's installed headers and run them through the C preprocessor."""

import importlib.util
import os
import pathlib
import re
import shlex
import subprocess

# The two public entry headers: mujoco.h does not include mjbatch.h.
ENTRY_HEADERS = ("mujoco.h", "mjbatch.h")

# Headers whose text (comments, #defines) codegen reads.  mjrfilament.h and
# mjspecmacro.h are not reached from the entry headers, so they are left out.
_LINE_MARKER = re.compile(r'^# \d+ "([^"]*)"')
_PRINTF_ATTR = re.compile(r"\s*__attribute__\(\(format\(printf, \d+, \d+\)\)\)")


def mujoco_package_dir():
    """Return the directory of the installed `mujoco` package (mujoco-core)."""
    spec = importlib.util.find_spec("mujoco")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit("codegen needs mujoco-core: pip install 'mujoco-core==4.0.0'")
    return pathlib.Path(list(spec.submodule_search_locations)[0])


def include_dir():
    """Return the `include` directory that holds `mujoco/*.h`."""
    return mujoco_package_dir() / "include"


def header_dir():
    return include_dir() / "mujoco"


def _compiler():
    return shlex.split(os.environ.get("CC", "gcc"))


def _entry_source():
    return "".join(f"#include <mujoco/{h}>\n" for h in ENTRY_HEADERS)


def _preprocess(source, *flags):
    cmd = [*_compiler(), "-E", "-std=c11", "-DMJ_STATIC", *flags,
           f"-I{include_dir()}", "-x", "c", "-"]
    out = subprocess.run(cmd, input=source, capture_output=True, text=True, check=True)
    return out.stdout


def mujoco_declarations():
    """Preprocessed declarations that come from MuJoCo's own headers, as text.

    `-DMJ_STATIC` blanks MJAPI.  Line markers tell which header each line came
    from; lines of the C library's headers are dropped.  The printf attributes
    and _Static_assert lines are removed because cffi's parser rejects them.
    """
    kept = []
    ours = False
    for line in _preprocess(_entry_source()).splitlines():
        marker = _LINE_MARKER.match(line)
        if marker:
            ours = "/include/mujoco/" in marker.group(1).replace(os.sep, "/")
            continue
        if not ours or not line.strip() or line.lstrip().startswith("_Static_assert"):
            continue
        kept.append(_PRINTF_ATTR.sub("", line.rstrip()))
    return "\n".join(kept) + "\n"


def macro_values():
    """Every object-like macro defined after including the entry headers."""
    values = {}
    for line in _preprocess(_entry_source(), "-dM").splitlines():
        match = re.match(r"#define (\w+) (.*)$", line)
        if match:
            values[match.group(1)] = match.group(2).strip()
    return values


def expand(source):
    """Run `source` (C text) through the preprocessor with MuJoCo's includes."""
    return _preprocess(source, "-P")


def header_texts():
    """Name -> raw text of each MuJoCo header, for comments and #defines."""
    return {p.name: p.read_text() for p in sorted(header_dir().glob("*.h"))}
