"""A `mujoco_py/__init__.py` for running mujoco-py's own tests against mjcffi.sim.

The conformance runner copies this file, as it is, to `mujoco_py/__init__.py`
in a temporary folder, beside the `mujoco_py/tests/` it extracts from
mujoco-py's wheel.  It maps no module itself: it calls the public
`mjcffi.sim.install_as_mujoco_py()`, as a user would, after which
`sys.modules["mujoco_py"]` is mjcffi.sim and every mujoco-py module path
resolves to mjcffi's module.  What stays here is the runner's own business:
the extracted `mujoco_py.tests` package, which is not part of the face, is
registered under its name so that pytest and the tests can import it.
"""

import importlib.util
import os
import sys

import mjcffi.sim


def _register_tests():
    folder = os.path.join(os.path.dirname(os.path.abspath(__file__)), "tests")
    spec = importlib.util.spec_from_file_location(
        "mujoco_py.tests", os.path.join(folder, "__init__.py"),
        submodule_search_locations=[folder])
    module = importlib.util.module_from_spec(spec)
    sys.modules["mujoco_py.tests"] = module
    spec.loader.exec_module(module)
    mjcffi.sim.tests = module            # as the import system binds a submodule


if __name__ == "mujoco_py":
    # this module is being imported as mujoco_py: hand the name to mjcffi.sim
    del sys.modules["mujoco_py"]
    mjcffi.sim.install_as_mujoco_py()
    _register_tests()
