"""Verification on held-out states: local error, and stability over the long horizon.

The held-out set comes from other initial states and other controls than the search
set.  A candidate passes when its held-out local error is within the budget and its
long runs (each held-out trajectory, over the whole horizon) do not diverge, do not
sink contacts deeper than the original does by more than the position budget, and,
where energy is conserved, do not drift in energy more than the original does or 1 %
of the energy's scale, whichever is larger (with budget='original': no more than
the original does).
"""

import dataclasses
import math

import numpy as np

from .. import functions as mjf
from .._generated.enums import mjtDisableBit, mjtEnableBit
from ..data import MjData
from ..evaluation.periods import setting_model
from ..evaluation.states import DIVERGED, FULLPHYSICS

@dataclasses.dataclass
class Stability:
    """Long-horizon figures over the held-out trajectories."""

    diverged: int = 0                  # trajectories in which MuJoCo warned of divergence
    penetration: float = math.nan      # deepest contact seen at a period boundary, m (>= 0)
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


def stability(m, setting, base_disable, samples, nstep, conservative):
    """Run each held-out trajectory over its controls with `setting`, checking at every
    control period."""
    mm = setting_model(m, setting, base_disable)
    if conservative:
        mm.opt.enableflags |= mjtEnableBit.mjENBL_ENERGY
    d = MjData(mm)
    out = Stability(penetration=0.0)
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
            if d.ncon:
                out.penetration = max(out.penetration, -float(d.contact.dist.min()))
            if conservative:
                e = _energy(mm, d)
                out.energy_drift = max(out.energy_drift, abs(e - e0))
                out.energy_scale = max(out.energy_scale, abs(e), abs(e0))
    return out


def _energy(m, d):
    mjf.mj_forward(m, d)
    return float(d.energy[0] + d.energy[1])


def stability_problem(candidate, original, position_budget, strict):
    """Why `candidate`'s Stability fails against the original's, or None."""
    if candidate.diverged:
        return f"diverged in {candidate.diverged} held-out trajectories"
    allowed = original.penetration + position_budget
    if candidate.penetration > allowed:
        return (f"contacts sink {candidate.penetration:.2e} m deep, more than the original's "
                f"{original.penetration:.2e} m plus the position budget")
    if not math.isnan(candidate.energy_drift):
        limit = original.energy_drift if strict else max(original.energy_drift,
                                                         0.01 * original.energy_scale)
        if candidate.energy_drift > limit:
            return (f"energy drifts by {candidate.energy_drift:.2e} J, more than "
                    f"{limit:.2e} J")
    return None
