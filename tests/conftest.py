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
