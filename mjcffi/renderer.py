"""`mjcffi.renderer.Renderer`, as the official `mujoco.renderer` module offers it.

The class lives in `mjcffi.rendering.renderer`; `mjcffi.Renderer` is the same.
"""

from .rendering.renderer import Renderer  # noqa: F401

__all__ = ["Renderer"]
