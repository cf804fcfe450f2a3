"""`Panels`: MuJoCo's own UI (mjui_*) beside the 3D view, as in MuJoCo's simulate.

The left panel holds the simulation's controls (pause, step, reset, speed), the
physics options (integrator, timestep, disable flags) and the visualization flags
of an MjvOption; the right panel a slider per hinge and slide joint (its qpos) and
per actuator (its ctrl, within ctrlrange).

The UI edits only its own buffers (NumPy arrays kept by the MjUI, see
mjcffi/functions/_mjui.py), never the model's or data's memory: `sync_from` copies the
model's and data's values into them, `sync_to` copies back what the user changed
through the UI since the last sync_to, and nothing else (the simulation keeps
moving the joints and a controller may set ctrl; only an edit overrides them).

Coordinates are MuJoCo's: framebuffer pixels, y up from the bottom; the state's
rect[0] is the whole window.  Panels lays out rect[1] (left panel), rect[2]
(right panel) and rect[3] (the rest, the 3D view) in the states it is given, and
works out `mouserect` and `dragrect` itself, so a caller fills only the mouse,
button, key and modifier fields.  Every call needs the OpenGL context the
MjrContext was made in to be current.
"""

import numpy as np

from ..functions import _mjui
from .._generated.constants import mjMAXUIITEM, mjMAXUINAME
from .._generated.enums import mjtButton, mjtEvent, mjtIntegrator, mjtItem, mjtJoint, mjtObj
from .._support.library import ffi
from .. import mjDISABLESTRING, mjVISSTRING
from .._functions import (mj_id2name, mjr_addAux, mjr_restoreBuffer, mjui_themeColor,
                          mjui_themeSpacing)
from ..structs import MjUI, MjuiState

__all__ = ["Panels"]

_I = mjtItem
_LEFT, _RIGHT, _VIEW = 1, 2, 3          # rect indices of the layout
_INTEGRATORS = [kind.name[len("mjINT_"):] for kind in mjtIntegrator]


def _label(text, limit=mjMAXUINAME - 2):
    """`text` as an item name MuJoCo can draw: ASCII, short enough."""
    return text.encode("ascii", "replace").decode()[:limit]


def _range(low, high, fallback):
    return (low, high) if high > low else fallback


class Panels:
    """The left and right UI panels of a viewer for `model` and `data`."""

    def __init__(self, model, data, left=True, right=True):
        self.actions = []                 # what the user did: 'pause', 'step', 'reset', ...
        self.enabled = {_LEFT: bool(left), _RIGHT: bool(right)}
        self._items = {}                  # (rectid, section, item) -> (action, index)
        self._changed = {}                # action -> indices edited since sync_to
        self._con, self._size, self._aux = None, (0, 0), {}
        self._dirty = True
        self._state = MjuiState()
        # the UI's own buffers
        self._pause = np.zeros(1, np.int32)
        self._speed = np.ones(1)
        self._integrator = np.zeros(1, np.int32)
        self._timestep = np.zeros(1)
        self._disable = np.zeros(len(mjDISABLESTRING), np.int32)
        self.vis_flags = np.array([int(row[1]) for row in mjVISSTRING], np.uint8)
        self._joints = [(j, int(model.jnt_qposadr[j])) for j in range(model.njnt)
                        if model.jnt_type[j] in (mjtJoint.mjJNT_HINGE, mjtJoint.mjJNT_SLIDE)]
        self._joints = self._joints[:mjMAXUIITEM]
        self._qpos = np.zeros(len(self._joints))
        self._ctrl = np.zeros(min(model.nu, mjMAXUIITEM))
        self.uis = {_LEFT: self._new_ui(_LEFT, 0), _RIGHT: self._new_ui(_RIGHT, 1)}
        self._build_left(model)
        self._build_right(model)
        self.sync_from(model, data)

    # ------------------------------------------------------------ building

    @staticmethod
    def _new_ui(rectid, auxid):
        ui = MjUI()
        ui.spacing, ui.color = mjui_themeSpacing(0), mjui_themeColor(0)
        ui.rectid, ui.auxid = rectid, auxid
        return ui

    def _add(self, rectid, defs, actions):
        """mjui_add `defs` to a panel; `actions[k]` names what definition k does."""
        ui = self.uis[rectid]
        section = ui.nsect - 1
        item = ui.sect[section].nitem if section >= 0 else 0
        found = {}
        for row, action in zip(defs, actions):
            if row[0] == _I.mjITEM_SECTION:
                section, item = section + 1, 0
                continue
            if action is not None:
                found[(rectid, section, item)] = action
            item += 1
        _mjui.mjui_add(ui, defs)
        self._items.update(found)

    def _build_left(self, model):
        S = _I.mjITEM_SECTION
        defs = [(S, "Simulation", 1, None, "AS"),
                (_I.mjITEM_CHECKINT, "Pause", 2, self._pause, " #32"),
                (_I.mjITEM_BUTTON, "Step", 2),
                (_I.mjITEM_BUTTON, "Reset", 2),
                (_I.mjITEM_SLIDERNUM, "Speed", 2, self._speed, "0.05 2")]
        self._add(_LEFT, defs, [None, ("pause", 0), ("step", 0), ("reset", 0), ("speed", 0)])
        names = "\n".join(_INTEGRATORS)
        defs = [(S, "Physics", 1, None, "AP"),
                (_I.mjITEM_SELECT, "Integrator", 2, self._integrator, names),
                (_I.mjITEM_EDITNUM, "Timestep", 2, self._timestep, "1 0 1"),
                (_I.mjITEM_SEPARATOR, "Disable Flags", 1)]
        defs += [(_I.mjITEM_CHECKINT, _label(name), 2, self._disable[i:i + 1])
                 for i, name in enumerate(mjDISABLESTRING)]
        self._add(_LEFT, defs, [None, ("integrator", 0), ("timestep", 0), None]
                  + [("disable", i) for i in range(len(mjDISABLESTRING))])
        defs = [(S, "Visualization", 0, None, "AV")]
        defs += [(_I.mjITEM_CHECKBYTE, _label(row[0]), 2, self.vis_flags[i:i + 1])
                 for i, row in enumerate(mjVISSTRING)]
        self._add(_LEFT, defs, [None] + [("visual", i) for i in range(len(mjVISSTRING))])

    def _build_right(self, model):
        S, slider = _I.mjITEM_SECTION, _I.mjITEM_SLIDERNUM
        if self._joints:
            defs, actions = [(S, "Joint", 1, None, "AJ")], [None]
            for k, (j, _) in enumerate(self._joints):
                hinge = model.jnt_type[j] == mjtJoint.mjJNT_HINGE
                fallback = (-np.pi, np.pi) if hinge else (-1.0, 1.0)
                low, high = (_range(*model.jnt_range[j], fallback) if model.jnt_limited[j]
                             else fallback)
                name = mj_id2name(model, mjtObj.mjOBJ_JOINT, j) or f"joint {j}"
                defs.append((slider, _label(name), 2, self._qpos[k:k + 1],
                             f"{low:.6g} {high:.6g}"))
                actions.append(("joint", k))
            self._add(_RIGHT, defs, actions)
        if len(self._ctrl):
            defs, actions = [(S, "Control", 1, None, "AC")], [None]
            for i in range(len(self._ctrl)):
                low, high = (_range(*model.actuator_ctrlrange[i], (-1.0, 1.0))
                             if model.actuator_ctrllimited[i] else (-1.0, 1.0))
                name = mj_id2name(model, mjtObj.mjOBJ_ACTUATOR, i) or f"actuator {i}"
                defs.append((slider, _label(name), 2, self._ctrl[i:i + 1],
                             f"{low:.6g} {high:.6g}"))
                actions.append(("ctrl", i))
            self._add(_RIGHT, defs, actions)

    # ------------------------------------------------------------ values

    @property
    def paused(self):
        return bool(self._pause[0])

    @paused.setter
    def paused(self, value):
        self._pause[0] = 1 if value else 0
        self._dirty = True

    @property
    def speed(self):
        return float(self._speed[0])

    def sync_from(self, model, data, opt=None):
        """Copy the model's options, the joints' qpos and ctrl (and `opt`'s flags, an
        MjvOption) into the UI."""
        self._integrator[0] = min(int(model.opt.integrator), len(_INTEGRATORS) - 1)
        self._timestep[0] = model.opt.timestep
        flags = int(model.opt.disableflags)
        self._disable[:] = [(flags >> i) & 1 for i in range(len(self._disable))]
        qpos = np.asarray(data.qpos)
        for k, (_, adr) in enumerate(self._joints):
            self._qpos[k] = qpos[adr]
        self._ctrl[:] = np.asarray(data.ctrl)[:len(self._ctrl)]
        if opt is not None:
            self.vis_flags[:] = np.asarray(opt.flags)
        self._dirty = True

    def sync_to(self, model, data, opt=None):
        """Copy into the model and data (and `opt`) what the UI edited since the last
        sync_to; nothing else."""
        changed, self._changed = self._changed, {}
        if "integrator" in changed:
            model.opt.integrator = int(self._integrator[0])
        if "timestep" in changed and self._timestep[0] > 0:
            model.opt.timestep = float(self._timestep[0])
        if "disable" in changed:
            flags = int(model.opt.disableflags)
            for i in changed["disable"]:
                flags = (flags | (1 << i)) if self._disable[i] else (flags & ~(1 << i))
            model.opt.disableflags = flags
        if "joint" in changed:
            qpos = data.qpos
            for k in changed["joint"]:
                qpos[self._joints[k][1]] = self._qpos[k]
        if "ctrl" in changed:
            ctrl = data.ctrl
            for i in changed["ctrl"]:
                ctrl[i] = self._ctrl[i]
        if "visual" in changed and opt is not None:
            opt.flags[:] = self.vis_flags

    # ------------------------------------------------------------ layout and drawing

    def _layout(self, state):
        """Lay out rect[1..3] of `state` for a window of rect[0] (or the last resize)."""
        rect = state.rect
        width, height = rect[0].width, rect[0].height
        if width <= 0 or height <= 0:
            width, height = self._size
            rect[0].left, rect[0].bottom, rect[0].width, rect[0].height = 0, 0, width, height
        left = self.uis[_LEFT].width if self.enabled[_LEFT] else 0
        right = self.uis[_RIGHT].width if self.enabled[_RIGHT] else 0
        for index, (x, w) in ((_LEFT, (0, left)), (_RIGHT, (max(0, width - right), right)),
                              (_VIEW, (left, max(0, width - left - right)))):
            r = rect[index]
            r.left, r.bottom, r.width, r.height = x, 0, w, height
        state.nrect = max(state.nrect, 4)

    def _active(self):
        return [(rectid, ui) for rectid, ui in self.uis.items()
                if self.enabled[rectid] and ui.nsect]

    def resize(self, con, width, height):
        """Lay the panels out for a window of width x height pixels, drawing with con."""
        self._con, self._size = con, (int(width), int(height))
        r = self._state.rect[0]
        r.left, r.bottom, r.width, r.height = 0, 0, int(width), int(height)
        for _, ui in self._active():
            _mjui.mjui_resize(ui, con)
            aux = (id(con), ui.width, ui.maxheight, ui.spacing.samples)
            if self._aux.get(ui.auxid) != aux:
                mjr_addAux(ui.auxid, ui.width, ui.maxheight, ui.spacing.samples, con)
                self._aux[ui.auxid] = aux
        self._layout(self._state)
        self._dirty = True

    def _update(self, con):
        for _, ui in self._active():
            _mjui.mjui_update(-1, -1, ui, self._state, con)
        mjr_restoreBuffer(con)
        self._dirty = False

    def render(self, con, width=None, height=None):
        """Draw the panels into the current buffer of con."""
        size = (int(width), int(height)) if width is not None else self._size
        if con is not self._con or size != self._size:
            self.resize(con, *size)
        if self._dirty:
            self._update(con)
        for _, ui in self._active():
            _mjui.mjui_render(ui, self._state, con)

    # ------------------------------------------------------------ events

    def _which(self, state):
        """The rect the mouse is in (the last that holds it; 0: none of 1..3)."""
        for index in (_VIEW, _RIGHT, _LEFT):
            r = state.rect[index]
            if r.left <= state.x < r.left + r.width and r.bottom <= state.y < r.bottom + r.height:
                return index
        return 0

    def event(self, state):
        """Handle one input event of `state` (an MjuiState, or an object whose .state is
        one); True when a panel took it.  What the user did goes to `actions`."""
        state = getattr(state, "state", state)
        if self._con is None:
            return False
        self._layout(state)
        kind = state.type
        state.mouserect = self._which(state)
        if kind == mjtEvent.mjEVENT_PRESS:
            state.dragrect, state.dragbutton = state.mouserect, state.button
        if kind == mjtEvent.mjEVENT_KEY:
            targets = [ui for _, ui in self._active()]
        else:
            dragging = kind == mjtEvent.mjEVENT_RELEASE or (
                kind == mjtEvent.mjEVENT_MOVE and (state.left or state.right or state.middle))
            rectid = state.dragrect if dragging else state.mouserect
            targets = [ui for r, ui in self._active() if r == rectid]
            if kind not in (mjtEvent.mjEVENT_PRESS, mjtEvent.mjEVENT_RELEASE,
                            mjtEvent.mjEVENT_MOVE, mjtEvent.mjEVENT_SCROLL):
                targets = []
        taken = False
        for ui in targets:
            editing = ui.editsect > 0
            item = _mjui.mjui_event(ui, state, self._con)
            if item is not None:
                self._record(ui.rectid, item.sectionid, item.itemid)
            taken = taken or kind != mjtEvent.mjEVENT_KEY or editing or item is not None
            if kind == mjtEvent.mjEVENT_KEY and (item is not None or editing):
                break
        if kind == mjtEvent.mjEVENT_RELEASE:
            state.dragrect, state.dragbutton = 0, mjtButton.mjBUTTON_NONE
        if taken:
            mjr_restoreBuffer(self._con)
        ffi.memmove(self._state._ptr, state._ptr, ffi.sizeof("mjuiState"))
        return taken

    def _record(self, rectid, section, item):
        found = self._items.get((rectid, section, item))
        if found is None:
            return
        action, index = found
        self.actions.append(action)
        self._changed.setdefault(action, set()).add(index)

