"""mujoco-py's PID actuators: `set_pid_control(model, data)` (mujoco-py's `cymj.set_pid_control`).

An actuator with `gaintype="user" biastype="user"` becomes a controller whose
setpoint is its control.  Its `user[0]` picks which:

- anything but 1: a PID on the actuator length.  gainprm = Kp, Ti (integral
  time constant, 0 for none), integral clamp, Td (derivative time constant),
  derivative smoothing (EMA weight of the new sample), error deadband.
- 1: a cascaded controller.  The control is smoothed by an EMA (starting from
  the control itself at time 0); a PID on position (Kp 0: the control is the
  velocity setpoint itself) gives a desired velocity, clamped to the velocity
  limit, that a PI on the actuator velocity follows; the bias force of the
  joint's dof (gravity compensation) is added.  gainprm = Kp, Ti, integral
  clamp, Td, derivative smoothing (position loop), Kp, Ti, integral clamp
  (velocity loop), EMA factor, velocity limit.  With Ti and the clamp 0 the
  position loop is a PD (a PD-PI controller).

Both clamp their force to forcerange unless it is (0, 0).  Actuator `i` keeps
its state in `data.userdata[5*i : 5*i + 5]` (mujoco-py's layout), so the model
needs `<size nuserdata>` of at least 5 per actuator up to the last user-bias
one, and `<size nuser_actuator>` of at least 1.  The state advances one
timestep per evaluation of the actuator forces, as in mujoco-py: four times per
step under RK4, and once more on each `forward()`.

This is a C-callback implementation (mjcffi/_c/sim_pid.c, installed as MuJoCo's
mjcb_act_gain and mjcb_act_bias), not MuJoCo 4's `mujoco.pid` actuator plugin:
that plugin (kp, ki, kd, imax, slewmax) keeps its integral in the actuator's
activation and has none of mujoco-py's cascaded controller, derivative
smoothing, deadband, setpoint EMA, gravity compensation or userdata layout.

The callbacks are process-global, as in mujoco-py: once set, they compute the
force of every user-gain or user-bias actuator of every model in the process
(also those of the official `mujoco` bindings, which share the library), until
another `mjcb_act_gain` / `mjcb_act_bias` replaces them (`mjcffi._support.callbacks`).
Actuators of other gain and bias types never reach them.  (With biastype user
but another gaintype, the force is that gain times ctrl plus the controller's,
as in mujoco-py.)  A model this function
did not check is still safe: an actuator whose state does not fit in its
userdata gets force 0.

Deviations from mujoco-py, all where mujoco-py misbehaved:
- the gravity term is `qfrc_bias` of the actuator's joint dof; mujoco-py read
  `qfrc_bias[actuator id]`, the same value when actuator i drives dof i.  A
  cascaded actuator must therefore drive a hinge or slide joint.
- the checks ask for state room up to the last user-bias actuator (mujoco-py:
  5 * nu) and for nuser_actuator >= 1 (mujoco-py: >= nu); only these state slots
  are zeroed (mujoco-py zeroed all of userdata).
"""

import numpy as np

from .._support import callbacks
from .._generated.enums import mjtBias, mjtJoint, mjtTrn
from .._support.library import ffi, lib
from .._support.marshal import model_data

__all__ = ["set_pid_control"]

NSTATE = lib.MJCFFI_PID_NSTATE       # userdata numbers per actuator
CASCADE = lib.MJCFFI_PID_CASCADE     # user[0] of a cascaded actuator


def set_pid_control(model, data):
    """Make the user-bias actuators of `model` PID or cascaded controllers.

    Checks the model (ValueError naming what is missing), zeroes the
    controllers' state in `data.userdata` and installs the C callbacks, which
    are process-global (see the module docstring).
    """
    model_data(model, data, "model", "data")     # TypeError / ValueError if they do not match
    controlled = _controlled(model)
    if controlled.size:
        _check(model, controlled)
        data.userdata[:NSTATE * (int(controlled[-1]) + 1)] = 0.0
    callbacks.set_mjcb_act_gain(ffi.addressof(lib, "mjcffi_pid_gain"))
    callbacks.set_mjcb_act_bias(ffi.addressof(lib, "mjcffi_pid_bias"))


def _controlled(model):
    """Ids of the actuators whose bias the controllers compute, ascending."""
    return np.flatnonzero(np.asarray(model.actuator_biastype) == mjtBias.mjBIAS_USER)


def _check(model, controlled):
    last = int(controlled[-1])
    need = NSTATE * (last + 1)
    if model.nuserdata < need:
        raise ValueError(
            f"nuserdata is {model.nuserdata}, too small for the PID state: actuator {last} "
            f"keeps its {NSTATE} numbers in userdata[{NSTATE * last}:{need}]; "
            f'set <size nuserdata="{need}"/> or more')
    if model.nuser_actuator < 1:
        raise ValueError(
            f"nuser_actuator is {model.nuser_actuator}: the PID controllers read their type "
            f'from the actuator\'s user[0] (1: cascaded); set <size nuser_actuator="1"/>')
    user = np.asarray(model.actuator_user).reshape(model.nu, -1)[:, 0]
    for i in controlled:
        cascaded = CASCADE <= user[i] < CASCADE + 1      # int(user[0]) == 1, as the C side
        if cascaded and not _drives_hinge_or_slide(model, i):
            raise ValueError(
                f"actuator {i} is cascaded (user[0] = 1) but does not drive a hinge or slide "
                f"joint: its gravity compensation needs the bias force of one dof")


def _drives_hinge_or_slide(model, i):
    if int(model.actuator_trntype[i]) != mjtTrn.mjTRN_JOINT:
        return False
    joint = int(np.asarray(model.actuator_trnid)[i, 0])
    return int(model.jnt_type[joint]) in (mjtJoint.mjJNT_HINGE, mjtJoint.mjJNT_SLIDE)
