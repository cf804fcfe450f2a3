"""One control period from each sampled state under a setting, on the C rollout pool."""

import copy
import math

import numpy as np

from .. import rollout as _rollout
from ..data import MjData
from .measures import error_estimates, local_error
from .states import FULLPHYSICS

# rollouts record every step: keep one call's output under this many float64s
_MAX_OUTPUT = 1 << 22


def setting_model(m, setting, base_disable=None):
    """A copy of `m` with `setting` applied."""
    mm = copy.copy(m)
    setting.apply(mm, base_disable)
    return mm


def steps_per_period(period, timestep):
    """Steps of `timestep` in a control period (a whole number, else ValueError)."""
    k = round(period / timestep)
    if k < 1 or abs(k * timestep - period) > 1e-9 * period:
        raise ValueError(f"the control period {period:g} s is not a whole number of "
                         f"timesteps of {timestep:g} s")
    return k


def end_states(pool, m, samples, nstep, nthread):
    """(n x nstate) states one period (`nstep` steps of model `m`) after each sample, and a
    mask of those that ran it through: finite, with time advanced by the whole period."""
    n = len(samples)
    nstate = samples.states.shape[1]
    out = np.empty((n, nstate))
    datas = [MjData(m) for _ in range(max(1, nthread))]
    chunk = max(1, _MAX_OUTPUT // (nstep * nstate))
    for a in range(0, n, chunk):
        b = min(n, a + chunk)
        control = np.repeat(samples.next_controls[a:b, None, :], nstep, axis=1)
        state, _ = pool.rollout(m, datas, samples.states[a:b], control, nstep=nstep,
                                initial_warmstart=samples.warmstarts[a:b])
        out[a:b] = state[:, -1]
    period = nstep * m.opt.timestep
    advanced = np.abs(out[:, 0] - samples.states[:, 0] - period) <= 1e-6 * period + 1e-12
    ok = advanced & np.all(np.isfinite(out), axis=1)
    return out, ok


def period_error(pool, m, setting, base_disable, samples, reference_qpos, nstep, nthread):
    """{kind: local error} of `setting` (on top of `base_disable`) over one period of `nstep`
    steps from each sample, against the reference's qpos; every kind infinite if a run
    diverged."""
    end, ok = end_states(pool, setting_model(m, setting, base_disable), samples, nstep, nthread)
    if not ok.all():
        return {k: math.inf for k in local_error(m, reference_qpos[:1], reference_qpos[:1])}
    return local_error(m, qpos_of(m, end), reference_qpos)


def run_periods(pool, m, states, warmstarts, controls, nstep, nthread):
    """(n x nstate) states after len(controls[i]) control periods of `nstep` steps from each
    of `states` (with its warm start), control row p held over period p; rows that did
    not run through (diverged) are not finite."""
    n, nperiod = controls.shape[:2]
    nstate = states.shape[1]
    total = nstep * nperiod
    out = np.empty((n, nstate))
    datas = [MjData(m) for _ in range(max(1, nthread))]
    chunk = max(1, _MAX_OUTPUT // (total * nstate))
    for a in range(0, n, chunk):
        b = min(n, a + chunk)
        control = np.repeat(controls[a:b], nstep, axis=1)
        state, _ = pool.rollout(m, datas, states[a:b], control, nstep=total,
                                initial_warmstart=warmstarts[a:b])
        out[a:b] = state[:, -1]
    horizon = total * m.opt.timestep
    advanced = np.abs(out[:, 0] - states[:, 0] - horizon) <= 1e-6 * horizon + 1e-12
    out[~(advanced & np.all(np.isfinite(out), axis=1))] = np.nan
    return out


def period_estimates(pool, m, setting, base_disable, samples, reference_qpos, nstep, nthread):
    """({kind: Estimate}, end states): the quantile estimates of `setting`'s one-period
    error (on top of `base_disable`) from each sample against the reference's qpos, and the
    (n x nstate) end states (a run that diverged has rows that are not finite, and makes
    every kind's estimate infinite)."""
    end, ok = end_states(pool, setting_model(m, setting, base_disable), samples, nstep, nthread)
    qpos = qpos_of(m, end).copy()
    qpos[~ok] = np.nan
    return error_estimates(m, qpos, reference_qpos, samples.trajectory), end


def qpos_of(m, states):
    """The qpos columns of (n x nstate) mjSTATE_FULLPHYSICS states (time comes first)."""
    return states[:, 1:1 + m.nq]


def new_pool(nthread):
    """A rollout pool of `nthread` threads (the C pool; the GIL is released)."""
    return _rollout.Rollout(nthread=nthread)


__all__ = ["FULLPHYSICS", "end_states", "new_pool", "period_error", "period_estimates",
           "qpos_of", "run_periods", "setting_model", "steps_per_period"]
