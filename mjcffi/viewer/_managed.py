"""The managed viewer: `launch` blocks, stepping the physics in real time itself.

`Simulation` runs on the calling thread: each frame it handles input, advances
the physics to the wall clock (at most STEP_BUDGET of a frame's time, so the
window stays responsive when the model is slower than real time), and draws.
STEP_BUDGET is a share of the last frame's duration, not of the nominal 1/60 s.
Keys: SPACE pauses and resumes, BACKSPACE resets (mj_resetData), RIGHT steps once
while paused, ctrl+L reloads the model from its file or loader; a file dropped on
the window is loaded.  A mouse perturbation goes into the data before each step:
all of xfrc_applied is cleared, then mjv_applyPerturbPose and
mjv_applyPerturbForce apply it (paused, the pose moves the body itself).

As in MuJoCo's simulate, a `History` keeps the state after each frame that
stepped: LEFT pauses and shows the state one further back, RIGHT one forward
again (and steps once back at the newest).  Resuming from a state in the past
forgets the newer ones, so the history stays this run's past.
"""

import os
import sys
import time

import glfw

from .._functions import mj_resetData, mjv_applyPerturbForce, mjv_applyPerturbPose
from ..functions._overrides import mj_forward, mj_step
from ..data import MjData
from ..model import MjModel
from ._history import History
from ._viewer import FRAME_INTERVAL, Viewer
from ._window import report

STEP_BUDGET = 0.7            # fraction of a frame's time the physics may take
MAX_MISALIGN = 0.1           # seconds behind the wall clock before giving up catching up
_EMPTY = "<mujoco/>"         # shown until a model is dropped on the window


def file_loader(path):
    """A loader of the model at `path` (MJCF, or .mjb binary): () -> (model, data)."""
    def load():
        if path.lower().endswith(".mjb"):
            model = MjModel.from_binary_path(path)
        else:
            model = MjModel.from_xml_path(path)
        return model, MjData(model)
    load.path = path
    return load


class Simulation:
    """A Viewer plus the physics it owns, stepped in real time."""

    def __init__(self, model=None, data=None, loader=None):
        if model is None and data is not None:
            raise ValueError("data was given without its model")
        if model is not None and loader is not None:
            raise ValueError("give a model or a loader, not both")
        if model is not None and not isinstance(model, MjModel):
            raise TypeError(f"model must be an mjcffi.MjModel, got {type(model).__name__}")
        if data is not None and not isinstance(data, MjData):
            raise TypeError(f"data must be an mjcffi.MjData, got {type(data).__name__}")
        self.loader = loader
        if model is None:
            model = MjModel.from_xml_string(_EMPTY)
        self.model = model
        self.data = data if data is not None else MjData(model)
        self.viewer = Viewer(self.model, self.data, managed=True)
        self.viewer.key_handler = self._on_key
        self.viewer.drop_handler = self._on_drop
        self.viewer.action_handler = self._on_action
        self.viewer.paused = False
        self._pending = loader            # a loader to run at the next frame
        self._sync_wall = self._sync_sim = None
        self._frame_time = FRAME_INTERVAL   # seconds the last frame took
        self._new_history()

    @property
    def paused(self):
        return self.viewer.paused

    # ------------------------------------------------------------ keys and files

    def _on_key(self, key, mods):
        if key == glfw.KEY_L and mods & glfw.MOD_CONTROL:
            self._pending = self.loader
        elif mods & glfw.MOD_CONTROL:
            return
        elif key == glfw.KEY_SPACE:
            self._pause(not self.viewer.paused)
        elif key == glfw.KEY_BACKSPACE:
            self._reset()
        elif key == glfw.KEY_RIGHT and self.viewer.paused:
            self._step_forward()
        elif key == glfw.KEY_LEFT:
            self._scrub(-1)

    def _on_action(self, action):
        """What the user did in the UI panels (their Pause box shares SPACE)."""
        panels = self.viewer.panels
        if action == "pause":
            self._pause(bool(panels.get("paused", not self.viewer.paused)))
        elif action == "step" and self.viewer.paused:
            self._step_forward()
        elif action == "reset":
            self._reset()
        elif action == "speed":
            self._sync_wall = None

    def _pause(self, paused):
        if not paused and self.viewer.scrub < 0:
            # the run goes on from the state shown: the newer ones are no longer its past
            self.history.drop_newest(-self.viewer.scrub)
            self.viewer.scrub = 0
        self.viewer.paused = paused
        if self.viewer.panels is not None:
            self.viewer.panels.set("paused", paused)
        self._sync_wall = None

    def _reset(self):
        with self.viewer.lock:
            mj_resetData(self.model, self.data)
            mj_forward(self.model, self.data)
        self.viewer.scrub = 0
        self._sync_wall = None

    def _speed(self):
        """The panels' speed slider: simulated seconds per real second."""
        panels = self.viewer.panels
        speed = panels.get("speed", 1.0) if panels is not None else 1.0
        return speed if speed > 0 else 1.0

    def _on_drop(self, paths):
        self.loader = self._pending = file_loader(paths[0])

    def _load(self):
        """Run the pending loader; a failure is shown in the window and printed."""
        loader, self._pending = self._pending, None
        if loader is None:
            return
        try:
            model, data = loader()
        except Exception as error:        # noqa: BLE001  (the viewer stays up)
            self._load_failed(loader, error)
            return
        self.model, self.data = model, data
        mj_forward(model, data)
        self.viewer.set_model(model, data)
        self._new_history()
        self.viewer.message = ""
        path = getattr(loader, "path", None)
        self.viewer.window.set_title(f"{os.path.basename(path)} - MuJoCo (mjcffi)" if path
                                     else self.viewer.title)
        self._sync_wall = None

    def _load_failed(self, loader, error):
        """Show why the model did not load, in the window and on stderr: one line when
        MuJoCo rejected a file (the user's error), with the traceback otherwise (a bug)."""
        text = "; ".join(line.strip() for line in str(error).splitlines() if line.strip())
        path = getattr(loader, "path", None)
        if isinstance(error, ValueError) and path:
            print(f"mjcffi.viewer: cannot load {path}: {text}", file=sys.stderr, flush=True)
        else:
            report("loading the model")
        self.viewer.message = f"load failed: {text}"[:200]

    # ------------------------------------------------------------ history

    def _new_history(self):
        """A History of the model now, holding its state now."""
        self.history = History(self.model)
        self.history.record(self.model, self.data)
        self.viewer.scrub = 0

    def _scrub(self, delta):
        """Pause and show the state `delta` steps forward (+1) or back (-1) in the
        history, within what it holds; 0 is the newest."""
        if not self.viewer.paused:
            self._pause(True)
        scrub = min(0, max(self.viewer.scrub + delta, 1 - len(self.history)))
        with self.viewer.lock:
            self.history.restore(self.model, self.data, scrub - 1)
            mj_forward(self.model, self.data)
        self.viewer.scrub = scrub

    def _step_forward(self):
        """RIGHT while paused: forward in the history, or, at its newest, one step."""
        if self.viewer.scrub < 0:
            self._scrub(+1)
            return
        with self.viewer.lock:
            self._step()
            self.history.record(self.model, self.data)

    # ------------------------------------------------------------ physics

    def _step(self):
        """One mj_step with the mouse perturbation applied."""
        pert = self.viewer.pert
        self.data.xfrc_applied[:] = 0
        if pert.active and pert.select > 0:
            mjv_applyPerturbPose(self.model, self.data, pert, 0)
            mjv_applyPerturbForce(self.model, self.data, pert)
        mj_step(self.model, self.data)

    def advance(self):
        """Step until the simulation catches up with the wall clock (or the budget ends)."""
        with self.viewer.lock:
            if self.viewer.paused:
                pert = self.viewer.pert
                if pert.active and pert.select > 0:
                    mjv_applyPerturbPose(self.model, self.data, pert, 1)
                mj_forward(self.model, self.data)
                return
            start = time.monotonic()
            speed = self._speed()
            behind = (None if self._sync_wall is None else
                      (start - self._sync_wall) * speed - (self.data.time - self._sync_sim))
            slack = MAX_MISALIGN + 2 * self._frame_time      # a frame's worth is expected
            if behind is None or behind > slack or behind < -slack:
                self._sync_wall, self._sync_sim = start, self.data.time
                self._step()
                self.history.record(self.model, self.data)
                return
            # a share of the last frame's time: slow drawing (software OpenGL) must
            # not starve the physics
            budget = STEP_BUDGET * max(FRAME_INTERVAL, min(self._frame_time, 0.5))
            before = self.data.time
            stepped = False
            while (self.data.time - self._sync_sim < (time.monotonic() - self._sync_wall) * speed
                   and time.monotonic() - start < budget):
                self._step()
                stepped = True
                if self.data.time < before:      # the model reset itself
                    self._sync_wall = None
                    break
            if stepped:                          # one state a frame, as MuJoCo's simulate
                self.history.record(self.model, self.data)

    # ------------------------------------------------------------ the loop

    def open(self):
        self.viewer.open()

    def frame(self):
        start = time.monotonic()
        self._frame()
        self._frame_time = time.monotonic() - start

    def _frame(self):
        self._load()
        viewer = self.viewer
        if viewer.panels is not None:
            viewer.panels.sync_to(self.model, self.data, viewer.opt)
        self.advance()
        if viewer.panels is not None:
            viewer.panels.sync_from(self.model, self.data, viewer.opt)
        viewer.frame()

    def run(self):
        """Open the window and run until it is closed."""
        self.open()
        try:
            while self.viewer.running:
                self.frame()
        finally:
            self.viewer.destroy()


def launch(model=None, data=None, *, loader=None, show_left_ui=True, show_right_ui=True):
    """Open the viewer and simulate `model` (or what `loader` returns) until the window
    closes; with neither, show an empty window that a model file can be dropped on."""
    simulation = Simulation(model, data, loader)
    simulation.viewer.show_ui = [show_left_ui, show_right_ui]
    simulation.run()


def launch_from_path(path):
    """Open the viewer on the model file at `path` (reloaded by ctrl+L)."""
    launch(loader=file_loader(os.fspath(path)))
