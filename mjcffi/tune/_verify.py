"""Verification on held-out states: error, penetration, and stability over the long horizon.

The held-out set comes from other initial states and other controls than the search
set.  A candidate passes when
- its held-out error fits the budget (the 95 % upper bound of each kind's error quantile
  within its limit; with budget='original', within 1 % of the original's on these states);
- its contacts sink no deeper than the fine reference's from the same states, plus the
  position budget: the 90 % quantile of penetration over every contact at the end of
  each held-out period, not the single deepest one;
- over 0.5 s from held-out states, it strays from a fine run (the original settings at
  timestep / 8) no further than the original settings do, plus the budget accumulated
  over the control periods of those 0.5 s (per joint kind, the 95 % bound of the 90 %
  quantile over 256 states against the original's estimate): the budget is a local error,
  and this holds it to what a local error may add up to.  A kind whose original run
  already strays further than that accumulated budget is chaotic over 0.5 s (runs
  separate whatever the setting) and is not checked;
- its long runs (each held-out trajectory over the whole horizon) do not diverge and,
  where energy is conserved, do not drift in energy more than the original does or 1 % of
  the energy's scale, whichever is larger (with budget='original': no more than the
  original does).
"""

import dataclasses
import math

import numpy as np

from .. import functions as mjf
from .._generated.enums import mjtDisableBit, mjtEnableBit
from ..data import MjData
from ..evaluation import measures
from ..evaluation.periods import qpos_of, run_periods, setting_model
from ..evaluation.settings import Setting
from ..evaluation.states import DIVERGED, FULLPHYSICS

PENETRATION_QUANTILE = 0.9
DIVERGENCE_HORIZON = 0.5     # seconds, in whole control periods (at least one)
# spread over the held-out states; on hopper over three draws the bound of one setting
# ranged 0.26-0.36 rad with 64 states, 0.23-0.25 with 256
DIVERGENCE_STATES = 256
FINE = 8                     # the fine run's timestep is the original's / FINE


@dataclasses.dataclass
class Divergence:
    """How far runs of DIVERGENCE_HORIZON stray from the fine run, per joint kind."""

    horizon: float             # seconds
    nperiod: int               # control periods in it
    tuned: dict                # {kind: Estimate} of the candidate
    original: dict             # {kind: Estimate} of the original settings
    allowed: dict              # {kind: limit} for the candidate's bound


class HorizonCheck:
    """The fine run from a spread subset of the held-out states, and the original's
    divergence from it."""

    def __init__(self, pool, m, base_disable, samples, controls, nstep0, nthread, limits):
        self.pool, self.m, self.base_disable, self.nthread = pool, m, base_disable, nthread
        pick = np.unique(np.linspace(0, len(samples) - 1,
                                     min(DIVERGENCE_STATES, len(samples))).round().astype(int))
        self.states = samples.states[pick]
        self.warmstarts = samples.warmstarts[pick]
        self.trajectory = None if samples.trajectory is None else samples.trajectory[pick]
        self.controls = controls[:len(pick)]
        self.nperiod = self.controls.shape[1]
        period = nstep0 * m.opt.timestep
        self.horizon = self.nperiod * period
        original = Setting.of(m)
        fine = original.replace(timestep=original.timestep / FINE)
        self.fine_qpos = self._run(fine, nstep0 * FINE)
        self.original = self.divergence(original, nstep0)
        # where the original's own run strays further than the whole accumulated budget,
        # the model is chaotic over this horizon: runs separate whatever the setting, and
        # the distance says nothing of the setting's accuracy (the kind is not checked)
        self.allowed = {k: (self.original[k].value + self.nperiod * limit
                            if self.original[k].value <= self.nperiod * limit else math.inf)
                        for k, limit in limits.items() if k in self.original}

    def _run(self, setting, nstep):
        mm = setting_model(self.m, setting, self.base_disable)
        return qpos_of(self.m, run_periods(self.pool, mm, self.states, self.warmstarts,
                                           self.controls, nstep, self.nthread))

    def divergence(self, setting, nstep):
        return measures.error_estimates(self.m, self._run(setting, nstep), self.fine_qpos,
                                        self.trajectory)

    def of(self, setting, nstep):
        """A Divergence of `setting`."""
        return Divergence(self.horizon, self.nperiod, self.divergence(setting, nstep),
                          self.original, self.allowed)


def divergence_problem(d):
    """Why a Divergence fails, or None."""
    for kind, limit in d.allowed.items():
        e = d.tuned.get(kind)
        if e is not None and math.isfinite(limit) and not e.upper <= limit:
            return (f"over {d.horizon:g} s it strays from the fine run by {e.upper:.2e} "
                    f"({kind}, 95 % bound of the 90 % quantile), more than the original's "
                    f"{d.original[kind].value:.2e} plus {d.nperiod} periods of budget")
    return None



@dataclasses.dataclass
class Stability:
    """Long-horizon figures over the held-out trajectories, and the contact penetration at
    the held-out period ends."""

    diverged: int = 0                  # trajectories in which MuJoCo warned of divergence
    penetration: float = math.nan      # 90 % quantile of contact penetration, m (>= 0)
    contacts: int = 0                  # contacts that quantile is over
    energy_drift: float = math.nan     # largest |E(t) - E(0)|, J, where energy is conserved
    energy_scale: float = math.nan     # largest |E(t)| seen, J


def conserves_energy(m, disable):
    """Whether nothing in the model adds or removes energy: the constraint stage is off (no
    contact, limit or equality acts), no actuator acts, and there is no damping or fluid."""
    if not disable & mjtDisableBit.mjDSBL_CONSTRAINT:
        return False
    if m.nu and not disable & mjtDisableBit.mjDSBL_ACTUATION:
        return False
    return not (np.any(m.dof_damping) or np.any(m.tendon_damping)
                or m.opt.density or m.opt.viscosity)


def penetration(m, states):
    """(quantile, contacts): the PENETRATION_QUANTILE quantile of penetration depth (m, 0
    for a contact inside its margin but not touching) over every contact of the given
    (n x nstate) states, found by collision detection at each; (nan, 0) without contacts."""
    d = MjData(m)
    depths = []
    for s in states:
        if not np.all(np.isfinite(s)):
            continue
        mjf.mj_setState(m, d, s, FULLPHYSICS)
        mjf.mj_fwdPosition(m, d)
        if d.ncon:
            depths.append(np.maximum(-d.contact.dist, 0.0))
    if not depths:
        return math.nan, 0
    depths = np.concatenate(depths)
    return float(np.quantile(depths, PENETRATION_QUANTILE, method="inverted_cdf")), len(depths)


def stability(m, setting, base_disable, samples, nstep, conservative, end_states):
    """Run each held-out trajectory over its controls with `setting`, checking at every
    control period; penetration from `end_states` (this setting's held-out period ends)."""
    mm = setting_model(m, setting, base_disable)
    if conservative:
        mm.opt.enableflags |= mjtEnableBit.mjENBL_ENERGY
    d = MjData(mm)
    out = Stability()
    out.penetration, out.contacts = penetration(mm, end_states)
    if conservative:
        out.energy_drift = 0.0
        out.energy_scale = 0.0
    for s0, controls in zip(samples.initial, samples.controls):
        mjf.mj_resetData(mm, d)
        mjf.mj_setState(mm, d, s0, FULLPHYSICS)
        e0 = _energy(mm, d) if conservative else 0.0
        for u in controls:
            d.ctrl[:] = u
            mjf.mj_step(mm, d, nstep=nstep)
            if any(d.warning[w].number for w in DIVERGED) or not np.all(np.isfinite(d.qpos)):
                out.diverged += 1
                break
            if conservative:
                e = _energy(mm, d)
                out.energy_drift = max(out.energy_drift, abs(e - e0))
                out.energy_scale = max(out.energy_scale, abs(e), abs(e0))
    return out


def _energy(m, d):
    mjf.mj_forward(m, d)
    return float(d.energy[0] + d.energy[1])


def stability_problem(candidate, original, reference_penetration, position_budget, strict):
    """Why `candidate`'s Stability fails, or None.  Penetration is held to the reference's
    from the same states plus the position budget; energy drift to the original's."""
    if candidate.diverged:
        return f"diverged in {candidate.diverged} held-out trajectories"
    if not math.isnan(candidate.penetration):
        allowed = (0.0 if math.isnan(reference_penetration) else reference_penetration) \
            + position_budget
        if candidate.penetration > allowed:
            return (f"contacts sink {candidate.penetration:.2e} m deep (90 % quantile over "
                    f"{candidate.contacts} contacts), more than the reference's "
                    f"{reference_penetration:.2e} m plus the position budget "
                    f"{position_budget:.2e} m")
    if not math.isnan(candidate.energy_drift):
        limit = original.energy_drift if strict else max(original.energy_drift,
                                                         0.01 * original.energy_scale)
        if candidate.energy_drift > limit:
            return (f"energy drifts by {candidate.energy_drift:.2e} J, more than "
                    f"{limit:.2e} J")
    return None
