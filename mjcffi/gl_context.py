"""The official `mujoco.gl_context` import path: `GLContext` of the backend MUJOCO_GL names.

With MUJOCO_GL=disable this module has no GLContext, as official.  See
mjcffi.rendering.context for the choice.
"""

from .rendering import context as _context

if hasattr(_context, "GLContext"):
    GLContext = _context.GLContext
    __all__ = ["GLContext"]
else:
    __all__ = []
