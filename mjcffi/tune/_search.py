"""The search: candidate settings, their error on the search set, and their cost.

Every choice the search makes is decided by errors, which come from rollouts and are the
same bits on every run, except where only a timing can tell two settings apart.  Those
few timings are CPU time of the calling thread, measured interleaved, and a change wins
only when its whole 95 % interval is above `MIN_GAIN`; anything less keeps what was
there.  So a loaded machine moves no choice unless a true gain sits right at that line.

1. Integrator and timestep: for each integrator, the fewest steps per control period
   whose error fits the budget (fewer steps cost less, so the first that fits is that
   integrator's cheapest).
2. From each of those, the solver, one option at a time:
   - options that can only make a step cheaper (fewer iterations, a looser tolerance,
     fewer line-search or noslip iterations) are taken at the cheapest value that fits,
     with no timing needed, but only when it also cuts the work it acts on by `MIN_GAIN`:
     the solver iterations (cap, tolerance) or line-search evaluations per period,
     counted, not timed.  These options save nothing else, so a smaller cut would spend
     error margin for no speed;
   - options whose cost can go either way (solver, cone, Jacobian) are taken only when
     measured faster;
   - a change that leaves every end state bit for bit as it was is a no-op for this
     model (MuJoCo's rules make many such: `ls_iterations` under PGS, `jacobian` auto
     below 60 dofs, ...) and is never made.
"""

import dataclasses
import math
import statistics

import numpy as np

from .._generated.enums import mjtCone, mjtDisableBit, mjtIntegrator, mjtJacobian, mjtSolver
from ..evaluation import measures
from ..evaluation.periods import period_estimates, setting_model
from ..evaluation.settings import INTEGRATOR_NAMES, value_name
from ..evaluation.timing import PeriodTimer, Speed, median_interval, solver_work, speed

# the model's own integrator is tried first; then the others, cheapest step first
INTEGRATORS = (int(mjtIntegrator.mjINT_EULER), int(mjtIntegrator.mjINT_IMPLICITFAST),
               int(mjtIntegrator.mjINT_IMPLICIT), int(mjtIntegrator.mjINT_RK4))
# values of the options that can only make a step cheaper, cheapest first
_ITERATIONS = (1, 2, 3, 5, 10, 20, 50)
_TOLERANCES = (1e-3, 1e-4, 1e-6)
_LS_ITERATIONS = (1, 2, 5, 10, 20)
_NOSLIP = (0, 1, 2, 5)
# a change judged by timing is made only when its whole 95 % interval is at least this
MIN_GAIN = 1.05
PAIRS = 9          # interleaved pairs per timing; 15 more when the interval straddles
# options that lower a step's cost only through the solver work it does: which count of
# solver_work (0: iterations, 1: line-search evaluations) each one cuts, and its name
_SOLVER_WORK = {"iterations": (0, "solver iterations"), "tolerance": (0, "solver iterations"),
                "ls_iterations": (1, "line-search evaluations")}
# MuJoCo's jacobian=auto: dense below this many dofs, sparse from it (mj_isSparse)
_AUTO_SPARSE_NV = 60


@dataclasses.dataclass
class Candidate:
    """One setting tried, with what the search and the verification found."""

    setting: object            # an mjcffi.evaluation.Setting
    nstep: int                 # steps per control period
    estimates: dict            # {kind: Estimate} of the error on the search set
    speed: object = None       # a timing.Speed against the original, once measured
    status: str = "searched"   # 'chosen', 'verified', or why it was not taken
    held_out: dict = None      # {kind: Estimate} on the held-out set, once verified
    stability: object = None   # a _verify.Stability, once verified
    divergence: object = None  # a _verify.Divergence (the 0.5 s check), once verified
    reasons: dict = dataclasses.field(default_factory=dict)   # option -> why it changed
    end: object = dataclasses.field(default=None, repr=False)  # search-set end states
    # the candidate this one refined (one solver option less): tried in its place if this
    # one fails the held-out check, since each refinement spends some of the budget
    previous: object = dataclasses.field(default=None, repr=False)

    @property
    def error(self):
        """{kind: error} on the search set: the quantile's point estimate."""
        return measures.values(self.estimates)

    @property
    def speedup(self):
        """× the original's speed (median of the interleaved pairs), or None before it is
        measured."""
        return None if self.speed is None else self.speed.value

    @property
    def measured(self):
        return self.speed is not None

    def label(self, original):
        return self.setting.label(original)


class Budget:
    """What "fits" means.  A numeric budget: each kind's upper bound (95 %) of the error
    quantile is within its limit.  budget='original': each kind's point estimate is within
    1 % of the original's on the same states (a paired comparison, no bound needed)."""

    def __init__(self, limits, paired):
        self.limits = dict(limits)
        self.paired = paired

    def fits(self, estimates):
        figures = measures.values(estimates) if self.paired else measures.uppers(estimates)
        return measures.within(figures, self.limits)

    def worst(self, estimates):
        """The largest (figure / limit) over the kinds: at most 1 fits."""
        figures = measures.values(estimates) if self.paired else measures.uppers(estimates)
        return measures.worst_ratio(figures, self.limits)

    def describe(self, estimates):
        """The worst kind's figure, as the reasons quote it."""
        kind = max(estimates, key=lambda k: self.worst({k: estimates[k]}), default=None)
        if kind is None:
            return "no joint to compare"
        e = estimates[kind]
        return (f"search-set {kind} error {e.value:.2e} (90 % quantile; 95 % bound "
                f"{e.upper:.2e}) against {self.limits.get(kind, float('nan')):.2e}")


def effective_jacobian(setting, nv):
    """The Jacobian MuJoCo uses: auto is dense below 60 dofs and sparse from 60."""
    if setting.jacobian == int(mjtJacobian.mjJAC_AUTO):
        return int(mjtJacobian.mjJAC_SPARSE if nv >= _AUTO_SPARSE_NV else mjtJacobian.mjJAC_DENSE)
    return int(setting.jacobian)


class Search:
    """The state of one search: the model, its samples, the reference, the pool."""

    def __init__(self, m, original, base_disable, samples, reference_qpos, budget, pool,
                 nthread, nstep0, progress):
        self.m = m
        self.original = original
        self.base_disable = base_disable
        self.samples = samples
        self.reference_qpos = reference_qpos
        self.budget = budget
        self.pool = pool
        self.nthread = nthread
        self.nstep0 = nstep0
        self.progress = progress
        self.evaluations = 0
        self.timings = 0
        self._cache = {}
        self._timers = {}
        self._work = {}

    # ------------------------------------------------------------ measures

    def evaluate(self, setting, nstep):
        """A Candidate of `setting` with its search-set error (each setting run once)."""
        key = (setting, nstep)
        if key not in self._cache:
            self.evaluations += 1
            self.progress.update()
            estimates, end = period_estimates(self.pool, self.m, setting, self.base_disable,
                                              self.samples, self.reference_qpos, nstep,
                                              self.nthread)
            self._cache[key] = (estimates, end)
        estimates, end = self._cache[key]
        return Candidate(setting, nstep, estimates, end=end)

    def timer(self, setting, nstep):
        key = (setting, nstep)
        if key not in self._timers:
            self._timers[key] = PeriodTimer(setting_model(self.m, setting, self.base_disable),
                                            self.samples, nstep)
        return self._timers[key]

    def speed(self, base, candidate):
        """timing.Speed of `candidate` against `base` ((setting, nstep) each); when the
        interval straddles MIN_GAIN, 15 more pairs narrow it."""
        self.timings += 1
        self.progress.update()
        a, b = self.timer(*base), self.timer(*candidate)
        s = speed(a, b, PAIRS)
        if s.low < MIN_GAIN <= s.high:
            more = speed(a, b, 15)
            s = _merge(s, more)
        return s

    def fits(self, estimates):
        return self.budget.fits(estimates)

    def solver_work(self, c):
        """(iterations, line-search evaluations) per control period of candidate `c`, the
        means over the samples (cached): the work a cap or a tolerance can lower, counted,
        so no timing is needed."""
        key = (c.setting, c.nstep)
        if key not in self._work:
            self._work[key] = solver_work(self.timer(*key).m, self.samples, c.nstep)
        return self._work[key]

    # ------------------------------------------------- integrator and timestep

    def structural(self, max_nstep):
        """(fits, misses): for each integrator, the candidate with the fewest steps per
        period (at most `max_nstep`) whose error fits, the model's own setting left out (it
        is the baseline); and every step count tried on the way that did not fit."""
        out, misses = [], []
        order = (self.original.integrator,) + tuple(
            i for i in INTEGRATORS if i != self.original.integrator)
        for integrator in order:
            for nstep in range(1, max_nstep + 1):
                s = self.original.replace(integrator=integrator,
                                          timestep=self._period() / nstep)
                if integrator == self.original.integrator and nstep == self.nstep0:
                    s = self.original      # exactly the model's own timestep
                c = self.evaluate(s, nstep)
                if self.fits(c.estimates):
                    if s != self.original:
                        c.reasons.update(self.structural_reasons(c))
                        out.append(c)
                    break
                c.status = ("diverged" if any(math.isinf(e.value) for e in c.estimates.values())
                            else "error over the budget")
                misses.append(c)
        return out, misses

    def _period(self):
        return self.original.timestep * self.nstep0

    def one_more_step(self, c, max_nstep):
        """`c` with one more step per control period and its solver options kept, as a
        Candidate when its error fits the search set (else None): what to try when `c`
        failed the held-out check, since a step more spends less of the budget than any
        solver option does.  None past `max_nstep` steps, or when it is the original."""
        nstep = c.nstep + 1
        if nstep > max_nstep:
            return None
        timestep = (self.original.timestep if nstep == self.nstep0
                    else self._period() / nstep)
        s = c.setting.replace(timestep=timestep)
        if s == self.original:
            return None
        more = self.evaluate(s, nstep)
        if not self.fits(more.estimates):
            more.status = "one step more after a held-out failure: error over the budget"
            return None
        more.reasons = dict(c.reasons)
        more.reasons.update(self.structural_reasons(
            more, f"one more than {c.nstep}, which failed the held-out check"))
        return more

    def structural_reasons(self, c, why="the fewest of this integrator whose error fits "
                                        "the budget"):
        """{field: reason} for `c`'s integrator and timestep changes: its steps per period
        against the original's, `why`, and its search-set error."""
        before = _steps(self.nstep0, self.original.integrator)
        after = _steps(c.nstep, c.setting.integrator)
        reason = (f"{after} per control period instead of {before}: {why} "
                  f"({self.budget.describe(c.estimates)})")
        return {f: reason for f in c.setting.changes(self.original) if f in ("integrator",
                                                                               "timestep")}

    # ------------------------------------------------------------ solver

    def needs_solver(self):
        return not (self.base_disable & mjtDisableBit.mjDSBL_CONSTRAINT)

    def refine(self, start):
        """From `start`, the solver's options one at a time (see the module's docstring).
        Returns (final candidate, every candidate tried on the way)."""
        if not self.needs_solver():
            return start, []
        best, tried = start, []
        for field in ("solver", "iterations", "tolerance", "ls_iterations",
                      "noslip_iterations", "cone", "jacobian"):
            best = self._option(best, field, tried)
        return best, tried

    def _values(self, s, field):
        """Values to try for `field` from setting `s`, in the order they are tried, and
        whether the option can only make a step cheaper (then the first that fits is
        taken without timing)."""
        nv = self.m.nv
        if field == "solver":
            return [v for v in (int(mjtSolver.mjSOL_NEWTON), int(mjtSolver.mjSOL_CG),
                                int(mjtSolver.mjSOL_PGS)) if v != s.solver], False
        if field == "iterations":
            return [v for v in _ITERATIONS if v < s.iterations], True
        if field == "tolerance":
            return [v for v in _TOLERANCES if v > s.tolerance], True
        if field == "ls_iterations":
            if s.solver == int(mjtSolver.mjSOL_PGS):
                return [], True        # PGS has no line search
            return [v for v in _LS_ITERATIONS if v < s.ls_iterations], True
        if field == "noslip_iterations":
            return [v for v in _NOSLIP if v < s.noslip_iterations], True
        if field == "cone":
            return [v for v in (int(mjtCone.mjCONE_PYRAMIDAL), int(mjtCone.mjCONE_ELLIPTIC))
                    if v != s.cone], False
        if field == "jacobian":
            now = effective_jacobian(s, nv)
            return [v for v in (int(mjtJacobian.mjJAC_DENSE), int(mjtJacobian.mjJAC_SPARSE))
                    if v != now], False
        raise ValueError(field)

    def _option(self, best, field, tried):
        values, cheaper_only = self._values(best.setting, field)
        for value in values:
            s = best.setting.replace(**{field: value})
            c = self.evaluate(s, best.nstep)
            c.reasons = dict(best.reasons)
            if not self.fits(c.estimates):
                c.status = f"{field} {value_name(field, value)}: error over the budget"
                tried.append(c)
                continue
            if _same_bits(c.end, best.end):
                # a no-op for this model: nothing else of this option to learn
                c.status = f"{field} {value_name(field, value)}: no-op (same bits)"
                tried.append(c)
                if cheaper_only:
                    return best
                continue
            change = (f"{value_name(field, getattr(best.setting, field))} → "
                      f"{value_name(field, value)}")
            saved = None
            if field in _SOLVER_WORK:
                which, what = _SOLVER_WORK[field]
                before, after = self.solver_work(best)[which], self.solver_work(c)[which]
                counts = f"{what} per period {before:.3g} → {after:.3g}"
                if not before or after * MIN_GAIN > before:
                    # such a cut saves only the work it skips; when that is less than a
                    # timed change must gain, it spends error margin for no speed
                    c.status = (f"{field} {value_name(field, value)}: {counts}, fewer by "
                                f"less than the {MIN_GAIN:g}× a change must gain")
                    tried.append(c)
                    return best
                saved = f"{counts}, {before / after:.2f}× fewer" if after else counts
            if cheaper_only:
                # no timing: this option only ever lowers the work of a step
                c.reasons[field] = (f"{change}: the cheapest value whose error fits "
                                    f"({self.budget.describe(c.estimates)}), and it changes "
                                    f"the result (a no-op is never made)"
                                    + (f"; {saved}" if saved else ""))
                c.previous = best
                tried.append(best)
                return c
            gain = self.speed((best.setting, best.nstep), (s, best.nstep))
            if gain.low >= MIN_GAIN:
                c.reasons[field] = (f"{change}: measured {gain} the speed without it, "
                                    f"error within the budget "
                                    f"({self.budget.describe(c.estimates)})")
                c.previous = best
                tried.append(best)
                best = c
            else:
                c.status = (f"{field} {value_name(field, value)}: not measurably faster "
                            f"({gain})")
                tried.append(c)
        return best


def _steps(n, integrator):
    return f"{n} {INTEGRATOR_NAMES[integrator]} step{'' if n == 1 else 's'}"


def _same_bits(a, b):
    return a is not None and b is not None and a.shape == b.shape and \
        np.array_equal(a, b, equal_nan=True)


def _merge(a, b):
    """One Speed from the pairs of two."""
    ratios = a.ratios + b.ratios
    low, high = median_interval(ratios)
    return Speed(statistics.median(ratios), low, high, ratios)
