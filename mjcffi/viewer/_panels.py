"""The hook for UI panels: `mjcffi.viewer._ui.Panels`, used when it imports and works.

The viewer runs without panels.  When `_ui` is importable, its `Panels(model,
data, left=..., right=...)` is made once the window has an MjrContext, and
called with: `resize(con, width, height)` after every size change,
`event(window_state) -> bool` for every input event (the viewer's mjuiState,
see `_input`; True: the panels consumed it, the 3D scene does not see it),
`render(con)` after the scene is drawn (the window's framebuffer is bound),
and, at each sync, `sync_to(model, data, opt)` (GUI edits into the physics) then
`sync_from(model, data, opt)`; after an event they consumed, their `actions`
(a list: 'pause', 'step', 'reset', ...) are taken, and their rect[3] of the
state, when laid out, is the 3D view.  The first exception of any call is printed with its
traceback and the panels are switched off; the viewer carries on without them.
"""

from ._window import report


def load(model, data, left, right):
    """A `Guarded` Panels, or None when there is no _ui module, or it fails."""
    if not (left or right):
        return None
    try:
        from ._ui import Panels
    except ImportError:
        return None
    except Exception:             # noqa: BLE001  (a broken _ui must not stop the viewer)
        report("importing mjcffi.viewer._ui")
        return None
    try:
        return Guarded(Panels(model, data, left=left, right=right))
    except Exception:             # noqa: BLE001
        report("mjcffi.viewer._ui.Panels()")
        return None


class Guarded:
    """Forwards to a Panels object until one of its calls raises."""

    def __init__(self, panels):
        self._panels = panels

    @property
    def alive(self):
        return self._panels is not None

    def _call(self, name, *args, default=None):
        if self._panels is None:
            return default
        try:
            return getattr(self._panels, name)(*args)
        except Exception:         # noqa: BLE001
            report(f"the UI panels' {name}(); the panels are now off")
            self._panels = None
            return default

    def resize(self, con, width, height):
        self._call("resize", con, width, height)

    def event(self, window_state):
        return bool(self._call("event", window_state, default=False))

    def render(self, con):
        self._call("render", con)

    def sync_from(self, model, data, opt):
        self._call("sync_from", model, data, opt)

    def sync_to(self, model, data, opt):
        self._call("sync_to", model, data, opt)

    def take_actions(self):
        """What the user did in the panels since the last call ('pause', 'step', ...)."""
        actions = getattr(self._panels, "actions", None)
        if not actions:
            return []
        taken = list(actions)
        actions.clear()
        return taken

    def get(self, name, default=None):
        """An attribute of the panels (paused, speed), or `default`."""
        return default if self._panels is None else getattr(self._panels, name, default)

    def set(self, name, value):
        if self._panels is not None:
            try:
                setattr(self._panels, name, value)
            except Exception:     # noqa: BLE001
                report(f"setting the UI panels' {name}")

    def view_rect(self, state):
        """The 3D view's rect in `state` as the panels laid it out, or None."""
        if self._panels is None or state.nrect < 4 or state.rect[3].width <= 0:
            return None
        return state.rect[3]
