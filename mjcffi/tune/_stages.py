"""Pipeline stages a model cannot need, found from the compiled model alone.

Each rule below mirrors where MuJoCo 4.0's pipeline reads the model before
doing work in a stage (mj_collision, mj_makeConstraint, mj_passive,
mj_fwdActuation, mj_sensor*). A stage is reported only when every source of
work in it is absent, so switching it off leaves every trajectory bit as it
was. When a rule is unsure, the stage counts as needed.

User callbacks (mjcb_contactfilter, mjcb_passive, mjcb_control, mjcb_sensor)
live outside the model and are not seen here.
"""

import dataclasses

import numpy as np

from .._generated.enums import mjtDisableBit

# mjMINVAL: mj_fluid skips bodies lighter than this.
_MINVAL = 1e-15
# Rows of unique geom classes compared at once, to bound memory.
_BLOCK = 512

_CONTACT = int(mjtDisableBit.mjDSBL_CONTACT)
_CONSTRAINT = int(mjtDisableBit.mjDSBL_CONSTRAINT)
_PASSIVE = int(mjtDisableBit.mjDSBL_SPRING) | int(mjtDisableBit.mjDSBL_DAMPER)
_ACTUATION = int(mjtDisableBit.mjDSBL_ACTUATION)
_SENSOR = int(mjtDisableBit.mjDSBL_SENSOR)


@dataclasses.dataclass(frozen=True)
class Stage:
    """A stage of the pipeline the model cannot need.

    flag: the mjtDisableBit bits that switch the stage off (passive is
    mjDSBL_SPRING | mjDSBL_DAMPER: mj_passive skips everything only when both
    are set). name: 'contact', 'constraint', 'passive', 'actuation' or
    'sensor'. reason: one sentence saying why the model cannot need it.
    """

    flag: int
    name: str
    reason: str


def unneeded_stages(m):
    """Stages the model cannot need, found from the model alone (no simulation).

    A stage already switched off in m.opt.disableflags is not listed.
    """
    disabled = int(m.opt.disableflags)
    stages = []
    contact_reason = _contact_unneeded(m, disabled)
    contact_off = bool(disabled & _CONTACT) or contact_reason is not None
    candidates = (
        (_CONTACT, "contact", contact_reason),
        (_CONSTRAINT, "constraint", _constraint_unneeded(m, disabled, contact_off)),
        (_PASSIVE, "passive", _passive_unneeded(m, disabled, contact_off)),
        (_ACTUATION, "actuation", _actuation_unneeded(m)),
        (_SENSOR, "sensor", _sensor_unneeded(m)),
    )
    for flag, name, reason in candidates:
        if (disabled & flag) == flag or reason is None:
            continue
        stages.append(Stage(flag, name, reason))
    return stages


# ---------------------------------------------------------------- contact


def _contact_unneeded(m, disabled):
    """Why no contact can ever be made, or None when one can."""
    if m.npair > 0:
        return None
    if m.nflex > 0:
        return None
    if _any_geom_pair_collides(m, disabled):
        return None
    return ("no geom pair can collide: every pair fails the contype/conaffinity test "
            "or is filtered as same-weld, parent-child, dof-free or excluded, "
            "and there are no <pair> or flex entries")


def _geom_classes(m):
    """Unique (body, contype, conaffinity) of geoms that can collide at all.

    Geoms sharing all three behave alike under every filter, and two geoms of
    one body never collide, so comparing classes is enough.
    """
    contype = np.asarray(m.geom_contype, dtype=np.int64)
    conaffinity = np.asarray(m.geom_conaffinity, dtype=np.int64)
    body = np.asarray(m.geom_bodyid, dtype=np.int64)
    keep = (contype != 0) | (conaffinity != 0)
    keys = np.stack([body[keep], contype[keep], conaffinity[keep]], axis=1)
    if keys.size == 0:
        return keys.reshape(0, 3)
    return np.unique(keys, axis=0)


def _any_geom_pair_collides(m, disabled):
    """Whether mj_collision's filters let any geom pair through.

    Mirrors filterBitmask and filterBodyPair (weld bodies, dof-free pairs,
    weld parents unless mjDSBL_FILTERPARENT) and the exclude signatures;
    bounding-volume tests depend on the state and are not applied.
    """
    classes = _geom_classes(m)
    if len(classes) < 2:
        return False
    weldid = np.asarray(m.body_weldid, dtype=np.int64)
    parentid = np.asarray(m.body_parentid, dtype=np.int64)
    dofnum = np.asarray(m.body_dofnum, dtype=np.int64)
    body, contype, conaffinity = classes.T
    weld = weldid[body]
    weldparent = weldid[parentid[weld]]
    dofless = dofnum[weld] == 0
    exclude = np.asarray(m.exclude_signature, dtype=np.int64)
    filterparent = not disabled & int(mjtDisableBit.mjDSBL_FILTERPARENT)
    for start in range(0, len(classes), _BLOCK):
        rows = slice(start, start + _BLOCK)
        ok = ((contype[rows, None] & conaffinity[None, :]) != 0) | (
            (contype[None, :] & conaffinity[rows, None]) != 0)
        ok &= weld[rows, None] != weld[None, :]
        ok &= ~(dofless[rows, None] & dofless[None, :])
        if filterparent:
            both_moving = (weld[rows, None] != 0) & (weld[None, :] != 0)
            related = ((weld[rows, None] == weldparent[None, :])
                       | (weld[None, :] == weldparent[rows, None]))
            ok &= ~(both_moving & related)
        if exclude.size and ok.any():
            low = np.minimum(body[rows, None], body[None, :])
            high = np.maximum(body[rows, None], body[None, :])
            ok &= ~np.isin((low << 16) + high, exclude)
        if ok.any():
            return True
    return False


# ------------------------------------------------------------- constraint


def _constraint_unneeded(m, disabled, contact_off):
    """Why mj_makeConstraint can never make a row, or None when it can."""
    if not contact_off:
        return None
    if m.nflex > 0:
        return None  # flex edges can be equality constraints
    if not disabled & int(mjtDisableBit.mjDSBL_EQUALITY) and m.neq > 0:
        return None
    if not disabled & int(mjtDisableBit.mjDSBL_LIMIT) and (
            np.any(m.jnt_limited) or np.any(m.tendon_limited)):
        return None
    if not disabled & int(mjtDisableBit.mjDSBL_FRICTIONLOSS) and (
            np.any(m.dof_frictionloss != 0) or np.any(m.tendon_frictionloss != 0)):
        return None
    return ("no constraint row can exist: no equality, no limited joint or tendon, "
            "no dof or tendon frictionloss (a constraint in MuJoCo) and no contact")


# ---------------------------------------------------------------- passive


def _passive_unneeded(m, disabled, contact_off):
    """Why mj_passive can never add a force, or None when it can."""
    if m.nflex > 0 or m.nplugin > 0:
        return None  # flex elasticity; plugins may compute passive forces
    if _has_springs(m) or _has_dampers(m):
        return None
    if _has_gravcomp(m, disabled):
        return None
    if _has_fluid(m):
        return None
    if not contact_off and m.flg_adhesion:
        return None
    return ("no passive force can act: no joint or tendon stiffness or damping, "
            "no actuator damping, no gravity compensation, no fluid, flex or plugin")


def _nonzero(*arrays):
    return any(np.any(np.asarray(a) != 0) for a in arrays)


def _has_springs(m):
    return _nonzero(m.jnt_stiffness, m.jnt_stiffnesspoly,
                    m.tendon_stiffness, m.tendon_stiffnesspoly)


def _has_dampers(m):
    """Dof, tendon or actuator damping (mj_actuatorDamping adds the last).

    Any joint an actuator damps (jnt_actuatorid) counts even at zero damping:
    the Euler step then takes its implicit-damping branch unless mjDSBL_DAMPER
    is set, and that branch need not round like the explicit one.
    """
    return _nonzero(m.dof_damping, m.dof_dampingpoly, m.tendon_damping,
                    m.tendon_dampingpoly, m.actuator_damping, m.actuator_dampingpoly) or (
        np.any(m.jnt_actuatorid != -1) or np.any(m.tendon_actuatorid != -1))


def _has_gravcomp(m, disabled):
    """Body gravity compensation, also when routed through actuators."""
    if disabled & int(mjtDisableBit.mjDSBL_GRAVITY) or not np.any(m.opt.gravity):
        return False
    return _nonzero(m.body_gravcomp)


def _has_fluid(m):
    """mj_fluid acts on every body with mass once density or viscosity is set."""
    if m.opt.density == 0 and m.opt.viscosity == 0:
        return False
    return bool(np.any(np.asarray(m.body_mass)[1:] >= _MINVAL))


# ------------------------------------------------------ actuation, sensor


def _actuation_unneeded(m):
    if m.nu > 0 or m.nactuator > 0:
        return None
    return "the model has no actuator (nu == 0)"


def _sensor_unneeded(m):
    if m.nsensor > 0:
        return None
    return "the model has no sensor (nsensor == 0)"
