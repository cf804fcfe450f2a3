"""MuJoCo warnings as mujoco-py raised them: MujocoException, ignore_mujoco_warnings()."""

import contextlib
import threading

from .. import warning_errors as _warnings
from .._generated.enums import mjtWarning


class MujocoException(_warnings.MjWarningError):
    """A MuJoCo warning raised during MjSim.step() or MjSim.forward().

    As MjWarningError: `warning` (the mjtWarning), `info` and `count`; the
    message adds what usually causes it.
    """

    def __init__(self, warning, info, count):
        super().__init__(warning, info, count)
        hint = _HINTS.get(warning)
        if hint:
            self.args = (f"{self.args[0]}. {hint}",)


_UNSTABLE = ("The simulation is unstable: try a smaller timestep (<option timestep>), the "
             "implicitfast or implicit integrator, and check the model (masses, inertias, "
             "stiffness, damping, actuator gains, controls)")
_HINTS = {
    mjtWarning.mjWARN_INERTIA: "A body has a mass or inertia too small or non-positive: "
                               "check <inertial> or the geoms' density, or <compiler "
                               "boundmass/boundinertia>",
    mjtWarning.mjWARN_CONTACTFULL: "Too many contacts for the arena: increase <size memory> "
                                   "(or nconmax in older models)",
    mjtWarning.mjWARN_CNSTRFULL: "Too many constraints for the arena: increase <size memory> "
                                 "(or njmax in older models)",
    mjtWarning.mjWARN_BADQPOS: "NaN, Inf or huge value in qpos. " + _UNSTABLE,
    mjtWarning.mjWARN_BADQVEL: "NaN, Inf or huge value in qvel. " + _UNSTABLE,
    mjtWarning.mjWARN_BADQACC: "NaN, Inf or huge value in qacc. " + _UNSTABLE,
    mjtWarning.mjWARN_BADCTRL: "NaN, Inf or huge value in ctrl: check the controls you set",
}
_local = threading.local()      # .ignoring: depth of ignore_mujoco_warnings() on this thread


@contextlib.contextmanager
def ignore_mujoco_warnings():
    """Within this block, on this thread, MjSim counts warnings but raises no MujocoException."""
    _local.ignoring = getattr(_local, "ignoring", 0) + 1
    try:
        yield
    finally:
        _local.ignoring -= 1

