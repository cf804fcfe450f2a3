"""How far a state is from the reference, per joint type, and the stability figures.

Positions are compared joint by joint, in each joint's own units: a hinge by its
angle (rad), a slide by its displacement (m), a ball joint by the rotation angle
between orientations (rad), a free joint by the distance between positions (m)
and, separately, the rotation angle (rad).  Velocities are not compared: an
error in velocity shows up in position one control period later.
"""

import math

import numpy as np

from .._generated.enums import mjtJoint

# joint kinds, in report order, with their units
JOINT_KINDS = {"free_pos": "m", "free_rot": "rad", "ball": "rad", "slide": "m", "hinge": "rad"}


def quat_angle(q1, q2):
    """Rotation angle between two orientation quaternions, radians, in [0, pi]."""
    return float(quat_angles(np.asarray(q1)[None], np.asarray(q2)[None])[0])


def quat_angles(a, b):
    """Rotation angles between rows of two (n x 4) quaternion arrays, radians.

    The angle of the relative rotation conj(a)*b = (w, v) is 2*atan2(|v|, |w|):
    acos of w alone would round every angle below about 1e-8 rad to 0.
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    b = b / np.linalg.norm(b, axis=-1, keepdims=True)
    w = a[:, 0] * b[:, 0] + np.einsum("ij,ij->i", a[:, 1:], b[:, 1:])
    v = a[:, :1] * b[:, 1:] - b[:, :1] * a[:, 1:] - np.cross(a[:, 1:], b[:, 1:])
    return 2.0 * np.arctan2(np.linalg.norm(v, axis=1), np.abs(w))


def joint_errors(m, qpos, ref):
    """{kind: (n,) array}: for each of n states, the largest error among the joints of a kind.

    qpos, ref: (n x nq) positions.  Kinds the model has no joint of are left out."""
    qpos = np.atleast_2d(qpos)
    ref = np.atleast_2d(ref)
    per_kind = {}
    for j in range(m.njnt):
        a = int(m.jnt_qposadr[j])
        t = int(m.jnt_type[j])
        if t == mjtJoint.mjJNT_FREE:
            per_kind.setdefault("free_pos", []).append(
                np.linalg.norm(qpos[:, a:a + 3] - ref[:, a:a + 3], axis=1))
            per_kind.setdefault("free_rot", []).append(
                quat_angles(qpos[:, a + 3:a + 7], ref[:, a + 3:a + 7]))
        elif t == mjtJoint.mjJNT_BALL:
            per_kind.setdefault("ball", []).append(quat_angles(qpos[:, a:a + 4], ref[:, a:a + 4]))
        else:
            kind = "slide" if t == mjtJoint.mjJNT_SLIDE else "hinge"
            per_kind.setdefault(kind, []).append(np.abs(qpos[:, a] - ref[:, a]))
    return {k: np.max(per_kind[k], axis=0) for k in JOINT_KINDS if k in per_kind}


def local_error(m, qpos, ref):
    """{kind: float}: the root mean square, over the states, of each kind's largest error.

    A state that is not finite counts as an infinite error."""
    errs = joint_errors(m, qpos, ref)
    out = {}
    for kind, e in errs.items():
        out[kind] = math.inf if not np.all(np.isfinite(e)) else float(np.sqrt(np.mean(e ** 2)))
    return out


def position_error(m, qpos, ref):
    """One number for one state: the Euclidean norm of every joint's error (free joints:
    distance plus rotation angle), as the accuracy report tabulates it."""
    errs = []
    for j in range(m.njnt):
        a = int(m.jnt_qposadr[j])
        t = m.jnt_type[j]
        if t == mjtJoint.mjJNT_FREE:
            errs.append(float(np.linalg.norm(qpos[a:a + 3] - ref[a:a + 3]))
                        + quat_angle(qpos[a + 3:a + 7], ref[a + 3:a + 7]))
        elif t == mjtJoint.mjJNT_BALL:
            errs.append(quat_angle(qpos[a:a + 4], ref[a:a + 4]))
        else:
            errs.append(abs(float(qpos[a] - ref[a])))
    return float(np.linalg.norm(errs)) if errs else 0.0


def within(errors, budget):
    """Whether every kind's error is within its budget ({kind: limit}); kinds without a
    limit are not checked."""
    return all(errors.get(k, 0.0) <= limit for k, limit in budget.items())


def worst_ratio(errors, budget):
    """The largest error / budget over the kinds (inf for an infinite error)."""
    ratios = [errors[k] / limit if limit > 0 else (0.0 if errors[k] == 0 else math.inf)
              for k, limit in budget.items() if k in errors]
    return max(ratios, default=0.0)
