"""The search: candidate settings, their local error on the search set, and their cost.

First the integrator and the number of steps per control period (the timestep), costed
from one measured step cost per integrator; then, for the cheapest candidates within
the budget, one solver option at a time (a coordinate search), each change kept only
when it is measured faster, or for `objective='accurate'` more accurate at no extra cost.
"""

import dataclasses

from .._generated.enums import mjtCone, mjtDisableBit, mjtIntegrator, mjtJacobian, mjtSolver
from ..evaluation import measures
from ..evaluation.periods import period_error, setting_model
from ..evaluation.settings import INTEGRATOR_NAMES, value_name
from ..evaluation.timing import PeriodTimer, speed_ratio

INTEGRATORS = (int(mjtIntegrator.mjINT_EULER), int(mjtIntegrator.mjINT_IMPLICITFAST),
               int(mjtIntegrator.mjINT_IMPLICIT), int(mjtIntegrator.mjINT_RK4))
# solver values tried, cheapest first; a value is tried only where it is cheaper than the
# current one (fewer iterations, a looser tolerance)
_ITERATIONS = (1, 2, 3, 5, 10, 20, 50)
_TOLERANCES = (1e-3, 1e-4, 1e-6)
_LS_ITERATIONS = (2, 5, 10, 20)
_NOSLIP = (0, 1, 2, 5)
MIN_GAIN = 1.03      # a solver change is kept when measured at least this much faster


@dataclasses.dataclass
class Candidate:
    """One setting tried, with what the search and the verification found."""

    setting: object            # an mjcffi.evaluation.Setting
    nstep: int                 # steps per control period
    error: dict                # local error per joint kind on the search set
    speedup: float             # × the original's speed (estimated, then measured)
    measured: bool = False     # speedup measured interleaved, not estimated
    status: str = "searched"   # 'verified', or why it was rejected
    held_out: dict = None      # local error per joint kind on the held-out set
    stability: object = None   # a _verify.Stability
    reasons: dict = dataclasses.field(default_factory=dict)   # option -> why it changed

    def label(self, original):
        return self.setting.label(original)


class Search:
    """The state of one search: the model, its samples, the reference and the pool."""

    def __init__(self, m, original, base_disable, samples, reference_qpos, budget, pool,
                 nthread, nstep0, period, progress):
        self.m = m
        self.original = original
        self.base_disable = base_disable
        self.samples = samples
        self.reference_qpos = reference_qpos
        self.budget = budget
        self.pool = pool
        self.nthread = nthread
        self.nstep0 = nstep0
        self.period = period
        self.progress = progress
        self.evaluations = 0
        self._base_timer = PeriodTimer(setting_model(m, original), samples, nstep0)

    # ------------------------------------------------------------ measures

    def error(self, setting, nstep):
        """Local error per joint kind over one period from the search states."""
        self.evaluations += 1
        self.progress.update()
        return period_error(self.pool, self.m, setting, self.base_disable, self.samples,
                            self.reference_qpos, nstep, self.nthread)

    def timer(self, setting, nstep):
        return PeriodTimer(setting_model(self.m, setting, self.base_disable), self.samples, nstep)

    def speedup(self, setting, nstep, pairs=5):
        """Measured: × the original's speed over one control period."""
        return speed_ratio(self._base_timer, self.timer(setting, nstep), pairs)[0]

    def fits(self, error):
        return measures.within(error, self.budget)

    # ------------------------------------------------- integrator and timestep

    def step_costs(self):
        """{integrator: cost of one step relative to the original's}, measured at the
        original's steps per period."""
        costs = {}
        for integrator in INTEGRATORS:
            if integrator == self.original.integrator:
                costs[integrator] = 1.0
                continue
            s = self.original.replace(integrator=integrator)
            costs[integrator] = 1.0 / self.speedup(s, self.nstep0, pairs=3)
        return costs

    def structural(self, max_cost):
        """Candidates over integrator × steps per period whose estimated cost is at most
        `max_cost` (× the original's), each with its search-set error."""
        costs = self.step_costs()
        out = []
        for integrator in INTEGRATORS:
            for nstep in range(1, 2 * self.nstep0 + 1):
                cost = costs[integrator] * nstep / self.nstep0
                if cost > max_cost:
                    continue
                s = self.original.replace(integrator=integrator, timestep=self.period / nstep)
                c = Candidate(s, nstep, self.error(s, nstep), 1.0 / cost)
                c.reasons.update(self._structural_reasons(c))
                out.append(c)
        return out

    def _structural_reasons(self, c):
        before = f"{self.nstep0} {INTEGRATOR_NAMES[self.original.integrator]} steps"
        after = f"{c.nstep} {INTEGRATOR_NAMES[c.setting.integrator]} steps"
        kind = max(c.error, key=lambda k: c.error[k], default=None)
        worst = "" if kind is None else f", search-set {kind} error {c.error[kind]:.2e}"
        why = (f"{after} per control period instead of {before} (about {c.speedup:.2f}× the "
               f"original's speed, estimated{worst})")
        return {f: why for f in c.setting.changes(self.original)}

    # ------------------------------------------------------------ solver

    def solver_options(self, setting):
        """(field, values) to try from `setting`, cheapest value first."""
        s = setting
        opts = [("solver", [v for v in (int(mjtSolver.mjSOL_NEWTON), int(mjtSolver.mjSOL_PGS),
                                        int(mjtSolver.mjSOL_CG)) if v != s.solver]),
                ("iterations", [v for v in _ITERATIONS if v < s.iterations]),
                ("tolerance", [v for v in _TOLERANCES if v > s.tolerance]),
                ("ls_iterations", [v for v in _LS_ITERATIONS if v < s.ls_iterations]),
                ("noslip_iterations", [v for v in _NOSLIP if v < s.noslip_iterations]),
                ("cone", [v for v in (int(mjtCone.mjCONE_PYRAMIDAL),
                                      int(mjtCone.mjCONE_ELLIPTIC)) if v != s.cone]),
                ("jacobian", [v for v in (int(mjtJacobian.mjJAC_DENSE),
                                          int(mjtJacobian.mjJAC_SPARSE)) if v != s.jacobian])]
        return [(f, vals) for f, vals in opts if vals]

    def needs_solver(self):
        return not (self.base_disable & mjtDisableBit.mjDSBL_CONSTRAINT)

    def coordinate(self, start, accurate=False):
        """From candidate `start`, change one solver option at a time; keep a change that is
        measured at least MIN_GAIN× faster within the budget (or, `accurate`, one that lowers
        the error at no measured cost).  Returns the candidates tried, the last kept first."""
        if not self.needs_solver():
            return [start]
        best = start
        tried = []
        best_timer = self.timer(best.setting, best.nstep)
        for field, values in self.solver_options(start.setting):
            for value in values:
                s = best.setting.replace(**{field: value})
                err = self.error(s, best.nstep)
                if not self.fits(err) and not accurate:
                    continue
                if accurate and measures.worst_ratio(err, self.budget) >= \
                        measures.worst_ratio(best.error, self.budget):
                    continue
                timer = self.timer(s, best.nstep)
                gain = speed_ratio(best_timer, timer, 3)[0]
                c = Candidate(s, best.nstep, err, best.speedup * gain, reasons=dict(best.reasons))
                c.reasons[field] = (
                    f"{value_name(field, getattr(best.setting, field))} → "
                    f"{value_name(field, value)} measured {gain:.2f}× the speed of the "
                    f"setting without it, " + ("with a lower local error" if accurate
                                                else "local error still within the budget"))
                tried.append(c)
                if gain >= (0.98 if accurate else MIN_GAIN):
                    best, best_timer = c, timer
                    break
        return [best] + [c for c in tried if c is not best]
