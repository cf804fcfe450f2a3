"""The official `mujoco.osmesa` import path: `GLContext`, an OSMesa software context.

Importing it binds libOSMesa (ImportError naming the Debian package when missing).
See mjcffi.rendering._osmesa.
"""

from ..rendering._osmesa import GLContext

__all__ = ["GLContext"]
