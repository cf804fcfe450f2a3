"""OpenGL contexts for MuJoCo's renderer, without a window on screen.

MuJoCo's mjr_* functions draw with whatever OpenGL context is current on the
calling thread; this package makes one.  Three backends, one module each:

- `_egl`: EGL, headless, on a GPU or on Mesa's software renderer (llvmpipe);
- `_osmesa`: Mesa's off-screen software renderer;
- `_glfw`: an invisible GLFW window (needs an X or Wayland display).

`context` picks one from the environment variable MUJOCO_GL, as the official
bindings do; `mjcffi.GLContext`, `mjcffi.gl_context.GLContext` and
`mjcffi.egl.GLContext` (`.osmesa`, `.glfw`) are the public names.  Every
backend binds its C library on import, never at `import mjcffi`, and compiles
nothing: EGL and OSMesa through cffi's ABI mode, GLFW through the `glfw`
package.  `_base` holds the contract they share (sizes, free, as_current),
`_current` the rule that a context is current on one thread at a time, and
`_egl_devices` the choice of GPU for MUJOCO_EGL_DEVICE_ID.

On top of the contexts: `renderer` (mjcffi.Renderer, the official API, with
`_readout` turning the framebuffer into images) and `recording`
(render_trajectory, frames for notebooks).  mujoco-py's render contexts, built
on these, are the mujoco-py face's own (mjcffi/sim/).
"""
