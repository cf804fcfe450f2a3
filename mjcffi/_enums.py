"""The official `mujoco._enums` path: MuJoCo's enums (generated in mjcffi/_generated/).

Real code imports `from mujoco._enums import mjtObj`, and pickled enum members
name this module.
"""

from ._generated.enums import *  # noqa: F401,F403
