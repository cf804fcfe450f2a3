"""mujoco-py's `mujoco_py.builder`, the module that compiled and loaded its Cython
extension: here the names code imports from it, taken from mjcffi.sim.

Nothing is compiled: `cymj` is mjcffi.sim.cymj, `functions` mjcffi.sim.functions.
`build_callback_fn` compiles a substep callback as mujoco-py's did (C code and a
compiler, on first use).  `mujoco_path` is the folder of the MuJoCo library that
mjcffi runs on (mujoco-py's was ~/.mujoco/mujoco210).
"""

from . import cymj, functions
from ._substep import build_callback_fn
from ._warnings import MujocoException, ignore_mujoco_warnings
from .utils import discover_mujoco

__all__ = ["cymj", "functions", "MujocoException", "ignore_mujoco_warnings",
           "build_callback_fn", "discover_mujoco", "mujoco_path"]

mujoco_path = discover_mujoco()

