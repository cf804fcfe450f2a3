"""The interactive viewer, as the official `mujoco.viewer`: a GLFW window drawing a model.

- `launch(model=None, data=None)`: the managed viewer; blocks, and steps the
  physics in real time itself (SPACE pause, BACKSPACE reset, RIGHT step).
- `launch_from_path(path)`: the same for a model file; ctrl+L reloads it.
- `launch_passive(model, data)`: returns a `Handle` at once; the window runs on its
  own thread and shows the caller's physics at each `handle.sync()`.
- `python -m mjcffi.viewer [--mjcf PATH]`: the standalone app (files can be
  dropped on the window).

It needs the `glfw` package (pip install 'mjcffi[glfw]') and a display (under
Xvfb where there is none).  Modules: `_window` (the GLFW window and its
callbacks), `_input` (the mjuiState of the mouse and keys), `_interaction`
(camera, selection, perturbation), `_viewer` (the render loop), `_overlay`
(info and help text), `_user_overlays` (the passive handle's figures, texts and
images), `_history` (the bounded history of states), `_panels` (the optional UI
panels of `_ui`), `_passive` and `_managed` (the two ways to run it).
"""

from ._managed import launch, launch_from_path
from ._passive import Handle, launch_passive

__all__ = ["Handle", "launch", "launch_from_path", "launch_passive"]
