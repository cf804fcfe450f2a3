"""mujoco-py's wheel from PyPI, cached, and its test files laid out to run against mjcffi.

The wheel is downloaded once with pip into ~/.cache/mjcffi/ (or
$XDG_CACHE_HOME/mjcffi/) and checked against the SHA-256 below.  Its
`mujoco_py/tests/*.py` and XML files are extracted into a temporary folder,
never into this repository, beside a `mujoco_py/__init__.py` that maps
mujoco-py's package to mjcffi.sim (conformance/_mujoco_py_alias.py).
"""

import ast
import hashlib
import os
import pathlib
import subprocess
import sys
import zipfile

VERSION = "2.1.2.14"
WHEEL = f"mujoco_py-{VERSION}-py3-none-any.whl"
WHEEL_SHA256 = "37c0b41bc0153a8a0eb3663103a67c60f65467753f74e4ff6e68b879f3e3a71f"
TESTS = "mujoco_py/tests/"
ALIAS = pathlib.Path(__file__).resolve().parent / "_mujoco_py_alias.py"


class WheelUnavailable(RuntimeError):
    """mujoco-py's wheel is neither cached nor downloadable."""


def cache_dir():
    """The folder that keeps the downloaded wheel."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache")
    return pathlib.Path(base) / "mjcffi"


def _sha256(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def cached_wheel():
    """The cached wheel's path when it is there and intact, else None."""
    path = cache_dir() / WHEEL
    return path if path.is_file() and _sha256(path) == WHEEL_SHA256 else None


def wheel():
    """The path of mujoco-py's wheel: the cached one, or downloaded with pip now."""
    path = cached_wheel()
    if path is not None:
        return path
    folder = cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    command = [sys.executable, "-m", "pip", "download", "--no-deps", "--disable-pip-version-check",
               "-q", "-d", str(folder), f"mujoco-py=={VERSION}"]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=300)
    except (OSError, subprocess.TimeoutExpired) as error:
        raise WheelUnavailable(f"pip download of mujoco-py=={VERSION} failed: {error}") from None
    path = folder / WHEEL
    if done.returncode != 0 or not path.is_file():
        raise WheelUnavailable(f"pip download of mujoco-py=={VERSION} failed "
                               f"(exit {done.returncode}): {(done.stdout + done.stderr).strip()}")
    if _sha256(path) != WHEEL_SHA256:
        path.unlink()
        raise WheelUnavailable(f"{WHEEL} from PyPI does not have the expected SHA-256 "
                               f"{WHEEL_SHA256}; removed it")
    return path


def listed_test_files(wheel_path):
    """The names of the wheel's test files, e.g. 'test_cymj.py'."""
    with zipfile.ZipFile(wheel_path) as archive:
        return sorted(name[len(TESTS):] for name in archive.namelist()
                      if name.startswith(TESTS) and "/" not in name[len(TESTS):]
                      and name.rsplit("/", 1)[-1].startswith("test_") and name.endswith(".py"))


def extract(wheel_path, folder):
    """Lay out `folder`/mujoco_py: the alias package and the wheel's tests (.py, .xml)."""
    folder = pathlib.Path(folder)
    tests = folder / TESTS
    tests.mkdir(parents=True)
    with zipfile.ZipFile(wheel_path) as archive:
        for name in archive.namelist():
            leaf = name[len(TESTS):]
            if name.startswith(TESTS) and "/" not in leaf and leaf.endswith((".py", ".xml")):
                (tests / leaf).write_bytes(archive.read(name))
    (folder / "mujoco_py" / "__init__.py").write_text(ALIAS.read_text())
    return tests


def source_test_ids(path):
    """The ids pytest gives the tests of file `path` ('test_x', 'Class::test_x'), from its source.

    Used when a file cannot be imported, to count and name the tests it holds.
    """
    tree = ast.parse(pathlib.Path(path).read_text())
    ids = []
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name.startswith("test"):
            ids.append(node.name)
        elif isinstance(node, ast.ClassDef) and node.name.startswith("Test"):
            ids += [f"{node.name}::{item.name}" for item in node.body
                    if isinstance(item, ast.FunctionDef) and item.name.startswith("test")]
    return ids
