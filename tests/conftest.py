"""Shared fixtures: the official bindings as oracle, and real gymnasium models."""

import importlib.resources
import os
import shlex
import subprocess
import pathlib

import pytest


def gymnasium_assets():
    """Paths of the MuJoCo models shipped inside the installed gymnasium package."""
    folder = importlib.resources.files("gymnasium") / "envs" / "mujoco" / "assets"
    return sorted(pathlib.Path(str(p)) for p in folder.iterdir() if p.name.endswith(".xml"))


@pytest.fixture(scope="session")
def mujoco():
    """The official bindings, loaded in this process on the same libmujoco."""
    import mujoco
    return mujoco


@pytest.fixture(scope="session")
def mujoco_include():
    from codegen import headers
    return headers.include_dir()


_C_PRELUDE = """
#include <stddef.h>
#include <stdio.h>
#include <mujoco/mujoco.h>
#include <mujoco/mjbatch.h>
int main(void) {
"""


@pytest.fixture
def run_c_main(mujoco_include, tmp_path):
    """Compile `body` as the inside of main() against MuJoCo's headers; return stdout."""
    def run(body):
        src, exe = tmp_path / "probe.c", tmp_path / "probe"
        src.write_text(_C_PRELUDE + body + "\n  return 0;\n}\n")
        compiler = shlex.split(os.environ.get("CC", "gcc"))
        subprocess.run([*compiler, "-std=c11", "-DMJ_STATIC", f"-I{mujoco_include}", str(src),
                        "-o", str(exe)], check=True, capture_output=True)
        return subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
    return run


@pytest.fixture
def run_python():
    """Run `code` (dedented) in a new Python process; (returncode, stdout + stderr).  For
    what may crash or hang the process: a hang ends at `timeout` with returncode None."""
    import sys
    import textwrap

    def run(code, timeout=60):
        try:
            done = subprocess.run([sys.executable, "-c", textwrap.dedent(code)],
                                  capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired as expired:
            out = (expired.stdout or b"") + (expired.stderr or b"")
            return None, out.decode("utf-8", "replace") if isinstance(out, bytes) else out
        return done.returncode, done.stdout + done.stderr
    return run
