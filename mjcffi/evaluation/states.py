"""Where settings are judged: states sampled along trajectories at each control period.

A trajectory starts from an initial state and is driven, under the model's own
settings, by controls held for one control period each.  At every period
boundary it records the full physics state, the solver's warm start and the
control of the next period: a candidate setting started there, with that
warm start and control, sees exactly what the model's own settings saw.
"""

import dataclasses

import numpy as np

from .. import functions as mjf
from .._generated.enums import mjtState, mjtWarning
from ..data import MjData

FULLPHYSICS = int(mjtState.mjSTATE_FULLPHYSICS)
# MuJoCo's divergence warnings; after one it resets the data (unless mjDSBL_AUTORESET)
DIVERGED = (int(mjtWarning.mjWARN_BADQPOS), int(mjtWarning.mjWARN_BADQVEL),
            int(mjtWarning.mjWARN_BADQACC))


@dataclasses.dataclass
class Samples:
    """States sampled along trajectories, with what a period started from each needs."""

    initial: np.ndarray      # (ntraj x nstate) the trajectories' initial states
    controls: np.ndarray     # (ntraj x nperiod x nu) the controls that drove them
    states: np.ndarray       # (n x nstate) sampled states (mjSTATE_FULLPHYSICS)
    warmstarts: np.ndarray   # (n x nv) qacc_warmstart at each sampled state
    next_controls: np.ndarray  # (n x nu) the control held over the period that follows
    trajectory: np.ndarray | None = None   # (n,) the trajectory each state was sampled from

    def __len__(self):
        return len(self.states)


def initial_states(m, n, rng, noise=0.01):
    """n states around the model's first keyframe (or qpos0 at rest): qpos and qvel
    perturbed uniformly by ±noise, quaternions normalised again."""
    d = MjData(m)
    out = np.empty((n, mjf.mj_stateSize(m, FULLPHYSICS)))
    for i in range(n):
        reset(m, d)
        d.qpos[:] += rng.uniform(-noise, noise, m.nq)
        d.qvel[:] += rng.uniform(-noise, noise, m.nv)
        mjf.mj_normalizeQuat(m, d.qpos)
        mjf.mj_getState(m, d, out[i], FULLPHYSICS)
    return out


def random_controls(m, rng, shape):
    """Controls of shape `shape` + (nu,): uniform in each actuator's ctrlrange where it is
    limited, standard normal where it is not."""
    u = rng.standard_normal(tuple(shape) + (m.nu,))
    lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
    limited = _ctrl_limited(m)
    u[..., limited] = rng.uniform(lo[limited], hi[limited], tuple(shape) + (int(limited.sum()),))
    return u


def _ctrl_limited(m):
    limited = np.asarray(m.actuator_ctrllimited, dtype=bool).copy()
    return limited & (m.actuator_ctrlrange[:, 0] < m.actuator_ctrlrange[:, 1])


def reset(m, d):
    """Reset to the model's first keyframe, or to qpos0 at rest where it has none."""
    if m.nkey:
        mjf.mj_resetDataKeyframe(m, d, 0)
    else:
        mjf.mj_resetData(m, d)


def sample(m, initial, controls, nstep, nsample):
    """Drive each trajectory with its controls, `nstep` steps a period, and keep `nsample`
    of the period boundaries, evenly spread over all the trajectories.

    Returns (Samples, diverged): diverged lists the trajectories in which MuJoCo warned of
    a bad qpos, qvel or qacc."""
    d = MjData(m)
    nstate = mjf.mj_stateSize(m, FULLPHYSICS)
    states, warm, nxt, traj, diverged = [], [], [], [], []
    for i, (s0, u) in enumerate(zip(initial, controls)):
        mjf.mj_resetData(m, d)
        mjf.mj_setState(m, d, s0, FULLPHYSICS)
        for period in u:
            s = np.empty(nstate)
            mjf.mj_getState(m, d, s, FULLPHYSICS)
            states.append(s)
            warm.append(d.qacc_warmstart.copy())
            nxt.append(period)
            traj.append(i)
            d.ctrl[:] = period
            mjf.mj_step(m, d, nstep=nstep)
            if any(d.warning[w].number for w in DIVERGED):
                diverged.append(i)
                break
    pick = np.unique(np.linspace(0, len(states) - 1, min(nsample, len(states))).round()
                     .astype(int))
    return Samples(np.asarray(initial), np.asarray(controls), np.asarray(states)[pick],
                   np.asarray(warm)[pick], np.asarray(nxt)[pick],
                   np.asarray(traj)[pick]), diverged
