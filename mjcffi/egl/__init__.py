"""The official `mujoco.egl` import path: `GLContext`, an EGL context for headless rendering.

Importing it binds libEGL (ImportError naming the Debian package when missing).
See mjcffi.rendering._egl.
"""

from ..rendering._egl import GLContext

__all__ = ["GLContext"]
