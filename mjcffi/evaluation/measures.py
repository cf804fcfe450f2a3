"""How far a state is from the reference, per joint type, and the stability figures.

Positions are compared joint by joint, in each joint's own units: a hinge by its
angle (rad), a slide by its displacement (m), a ball joint by the rotation angle
between orientations (rad), a free joint by the distance between positions (m)
and, separately, the rotation angle (rad).  Velocities are not compared: an
error in velocity shows up in position one control period later.
"""

import dataclasses
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


# The error statistic: a high quantile of the per-state errors, not a mean.  One control
# period's error is heavy-tailed (a contact made or missed moves a state far more than
# smooth motion does), so a root mean square is carried by a handful of states and varies
# many times over from one draw of states to the next; a quantile moves little.
QUANTILE = 0.9
CONFIDENCE = 0.95


@dataclasses.dataclass(frozen=True)
class Estimate:
    """A quantile of per-state errors: the point estimate and its one-sided upper
    confidence bound (distribution-free, from the order statistics)."""

    value: float
    upper: float
    n: int


BOOTSTRAP = 400            # resamples of the trajectories for the bound
_BOOTSTRAP_SEED = 20261128  # fixed: the bound is a function of the data alone


def quantile_estimate(errors, groups=None, q=QUANTILE, confidence=CONFIDENCE):
    """The `q` quantile of `errors` (one per state) with an upper bound that holds with
    probability about `confidence` for states drawn as these were.

    States sampled along one trajectory are alike, so they are not independent draws:
    with `groups` (the trajectory of each state) the bound is a bootstrap over the
    trajectories (whole trajectories resampled with replacement, the quantile of each
    resample, and the `confidence` quantile of those), with a fixed seed, so that it is
    the same for the same errors.  Without, it is the order statistic X(k) with the
    smallest k such that P(Binomial(n, q) < k) >= confidence, for independent draws.
    Any error that is not finite makes both infinite."""
    e = np.asarray(errors, dtype=np.float64)
    n = len(e)
    if n == 0:
        return Estimate(0.0, 0.0, 0)
    if not np.all(np.isfinite(e)):
        return Estimate(math.inf, math.inf, n)
    order = np.argsort(e, kind="stable")
    sorted_e = e[order]
    value = float(np.quantile(sorted_e, q, method="inverted_cdf"))
    if groups is None or len(np.unique(groups)) < 2:
        k = _upper_rank(n, q, confidence)
        upper = float(sorted_e[min(k, n) - 1])
    else:
        upper = _bootstrap_upper(sorted_e, np.asarray(groups)[order], q, confidence)
    return Estimate(value, max(upper, value), n)


def _bootstrap_upper(sorted_e, groups, q, confidence):
    """The `confidence` quantile, over resamples of whole groups, of the weighted `q`
    quantile of the errors (sorted ascending, with their groups)."""
    labels, index = np.unique(groups, return_inverse=True)
    rng = np.random.default_rng(_BOOTSTRAP_SEED)
    counts = rng.multinomial(len(labels), np.full(len(labels), 1.0 / len(labels)),
                             size=BOOTSTRAP)                 # (B, ngroups)
    weights = counts[:, index].astype(np.float64)            # (B, n): each state's copies
    cumulative = np.cumsum(weights, axis=1)
    # the first sorted error at which the resample's weight reaches q of its total
    first = np.argmax(cumulative >= q * cumulative[:, -1:], axis=1)
    quantiles = np.sort(sorted_e[first])
    return float(quantiles[min(BOOTSTRAP - 1, int(math.ceil(confidence * BOOTSTRAP)) - 1)])


def _upper_rank(n, q, confidence):
    """The smallest k (1-based) with P(Binomial(n, q) <= k - 1) >= confidence."""
    # the binomial's CDF summed in log space: n is a few hundred to a few thousand
    logs = [math.lgamma(n + 1) - math.lgamma(i + 1) - math.lgamma(n - i + 1)
            + i * math.log(q) + (n - i) * math.log1p(-q) for i in range(n + 1)]
    total = 0.0
    for i, lp in enumerate(logs):
        total += math.exp(lp)
        if total >= confidence:
            return i + 1
    return n + 1


def error_estimates(m, qpos, ref, groups=None):
    """{kind: Estimate} of each kind's largest error per state (`groups`: the trajectory
    of each state, for the bound); a state that is not finite counts as an infinite
    error."""
    return {k: quantile_estimate(e, groups) for k, e in joint_errors(m, qpos, ref).items()}


def values(estimates):
    """{kind: point estimate} of {kind: Estimate}."""
    return {k: e.value for k, e in estimates.items()}


def uppers(estimates):
    """{kind: upper bound} of {kind: Estimate}."""
    return {k: e.upper for k, e in estimates.items()}


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
