"""Mouse interaction with the 3D scene: the camera, selection and perturbation.

- left drag rotates the camera (shift: about the horizontal), right drag pans it
  (shift: horizontally), middle drag and the scroll wheel zoom (mjv_moveCamera);
- double-click left selects the body under the cursor (mjv_select), or clears the
  selection on empty space; double-click right centres the camera on the point
  under the cursor, ctrl+double-click right makes the camera track that body;
- with a body selected, ctrl+left drag rotates it and ctrl+right drag pushes it
  (mjv_initPerturb, mjv_movePerturb): the perturbation's reference moves here, and
  is applied to the physics by whoever owns it (sync(), or the managed loop).

Mouse motion is relative to the window height, as in MuJoCo's samples.
"""

import numpy as np

from .._generated.enums import mjtCamera, mjtMouse, mjtPertBit
from .._functions import mjv_initPerturb, mjv_moveCamera, mjv_movePerturb, mjv_select

SCROLL_ZOOM = -0.05          # mjv_moveCamera's zoom per scroll notch, as MuJoCo's samples


def drag_action(state):
    """The mjtMouse action of the buttons held in the mjuiState `state`."""
    if state.right:
        return mjtMouse.mjMOUSE_MOVE_H if state.shift else mjtMouse.mjMOUSE_MOVE_V
    if state.left:
        return mjtMouse.mjMOUSE_ROTATE_H if state.shift else mjtMouse.mjMOUSE_ROTATE_V
    if state.middle:
        return mjtMouse.mjMOUSE_ZOOM
    return mjtMouse.mjMOUSE_NONE


def drag(view, state, dx, dy, height):
    """Move the perturbation (when active) or the camera by a cursor move of dx, dy."""
    action = drag_action(state)
    if action == mjtMouse.mjMOUSE_NONE:
        return
    reldx, reldy = dx / height, dy / height
    if view.pert.active:
        mjv_movePerturb(view.model, view.data, action, reldx, reldy, view.scene, view.pert)
    else:
        mjv_moveCamera(view.model, action, reldx, reldy, view.cam)


def zoom(view, sy):
    mjv_moveCamera(view.model, mjtMouse.mjMOUSE_ZOOM, 0.0, SCROLL_ZOOM * sy, view.cam)


def start_perturbation(view, state):
    """At a press with ctrl held and a body selected: rotate (left) or push (right) it."""
    if not state.control or view.pert.select <= 0:
        return False
    if state.left:
        kind = mjtPertBit.mjPERT_ROTATE
    elif state.right:
        kind = mjtPertBit.mjPERT_TRANSLATE
    else:
        return False
    if not view.pert.active:
        mjv_initPerturb(view.model, view.data, view.scene, view.pert)
    view.pert.active = int(kind)
    return True


def stop_perturbation(view):
    view.pert.active = 0


def pick(view, relx, rely, aspect):
    """(body id, point, flex id, skin id) under the relative window point (relx, rely)."""
    view.update_scene()          # select in the scene as the camera is now
    point = np.zeros(3)
    geom, flex, skin = (np.full(1, -1, dtype=np.int32) for _ in range(3))
    body = mjv_select(view.model, view.data, view.opt, aspect, relx, rely, view.scene,
                      point, geom, flex, skin)
    return int(body), point, int(flex[0]), int(skin[0])


def select(view, relx, rely, aspect):
    """Double-click left: select the body under the point, or clear the selection."""
    body, point, flex, skin = pick(view, relx, rely, aspect)
    pert = view.pert
    if body > 0:
        pert.select, pert.flexselect, pert.skinselect = body, flex, skin
        # the grabbed point in the body's frame: perturbation forces pull there
        xmat = view.data.xmat[body].reshape(3, 3)
        pert.localpos[:] = xmat.T @ (point - view.data.xpos[body])
    else:
        pert.select, pert.flexselect, pert.skinselect = 0, -1, -1
    pert.active = 0
    return body


def centre(view, relx, rely, aspect, track):
    """Double-click right: look at the point under the cursor (track: follow its body)."""
    body, point, _, _ = pick(view, relx, rely, aspect)
    if body < 0:
        return
    view.cam.lookat[:] = point
    if track and body > 0:
        view.cam.type = mjtCamera.mjCAMERA_TRACKING
        view.cam.trackbodyid = body
        view.cam.fixedcamid = -1


def cycle_camera(view, step):
    """Step through the free camera (index -1) and the model's cameras."""
    count = view.model.ncam
    current = view.cam.fixedcamid if view.cam.type == mjtCamera.mjCAMERA_FIXED else -1
    index = (current + 1 + step) % (count + 1) - 1
    set_camera(view, index)
    return index


def set_camera(view, index):
    """The free camera for index -1, otherwise the model's camera `index`."""
    if index < 0:
        view.cam.type = mjtCamera.mjCAMERA_FREE
        view.cam.fixedcamid = -1
    else:
        view.cam.type = mjtCamera.mjCAMERA_FIXED
        view.cam.fixedcamid = index
