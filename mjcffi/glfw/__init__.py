"""The official `mujoco.glfw` import path: `GLContext`, the context of an invisible GLFW window.

Importing it imports the `glfw` package (ImportError when missing: pip install
'mjcffi[glfw]').  See mjcffi.rendering._glfw.
"""

from ..rendering._glfw import GLContext

__all__ = ["GLContext"]
