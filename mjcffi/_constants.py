"""The official `mujoco._constants` path: MuJoCo's #define constants (generated in
mjcffi/_generated/)."""

from ._generated.constants import *  # noqa: F401,F403
