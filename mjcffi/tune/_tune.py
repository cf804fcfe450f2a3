"""tune(): the cheapest settings of a model within an error budget, verified on held-out states."""

import collections.abc
import dataclasses
import math
import numbers
import os
import time

import numpy as np

from .._support import progress as _progress
from .. import functions as mjf
from .. import rollout as _rollout
from .._generated.enums import mjtDisableBit
from ..evaluation import measures
from ..evaluation.periods import end_states, period_estimates, qpos_of, setting_model, \
    steps_per_period
from ..evaluation.reference import REF_FACTOR, reference_setting
from ..evaluation.settings import Setting
from ..evaluation.states import FULLPHYSICS, initial_states, random_controls, sample
from ..evaluation.timing import PeriodTimer, Speed, speed
from ..model import MjModel
from ..warning_errors import ignore_warnings
from . import _verify
from ._result import Change, TuneError, TuneResult
from ._search import INTEGRATORS, MIN_GAIN, Budget, Candidate, Search
from ._stages import unneeded_stages

OBJECTIVES = ("cheapest", "accurate")
DEFAULT_HORIZON = 1.0      # seconds, or 20 control periods if that is longer
# With no control period given, this one: the rate of a typical robot controller (and of
# gymnasium's locomotion envs, 4-5 steps of 2-2.5 ms).  The timestep may grow up to it.
DEFAULT_PERIOD = 0.01
# trajectories per set (search, held-out): fewer states of each one, less alike, make a
# figure that varies less between draws.  Over five draws the 95 % bound of one setting
# ranged 7.1e-4..1.34e-3 (hopper) and 9.0e-3..1.14e-2 (humanoid) with 32 trajectories of
# 400 states, 8.1e-4..1.16e-3 and 9.3e-3..1.0e-2 with 64 of 800.
NTRAJ = 64
NSAMPLE = 800              # states sampled per set
# budget='original': an error counts as equal to the original's within 1 %, the precision
# the report prints (two digits), on the same states
EQUAL = 1.01
# the timestep is searched up to this many times the original's steps per period, or
# further when the original's own settings miss the budget
MORE_STEPS = 2
MORE_STEPS_WHEN_MISSED = 8
# candidates with one more step per period, tried after held-out failures (each costs a
# search-set evaluation and a timing)
FALLBACKS = 6


def default_period(timestep):
    """The control period used when none is given: DEFAULT_PERIOD rounded to whole
    timesteps, at least one."""
    return max(1, int(DEFAULT_PERIOD / timestep + 0.5)) * timestep


class BudgetError(ValueError):
    """No setting met the budget on the held-out states.

    best: the candidate closest to the budget among those verified on the held-out states
    (its held_out and status say why it failed), or, when no setting fit the budget even on
    the search states, the closest there (status 'over the budget on the search states').
    candidates: every setting tried."""

    def __init__(self, message, best, candidates):
        super().__init__(message)
        self.best = best
        self.candidates = candidates


def tune(model, budget, *, control_period=None, control=None, horizon=None, states=None,
         objective="cheapest", nthread=None, seed=0, progress=True, ray=False):
    """The cheapest settings of `model` whose error stays within `budget`.

    The same model, budget and seed give the same settings on every run: the choices
    follow errors, which are the same bits every run, and the few timings that decide
    anything are CPU time of this thread with a 95 % interval that must clear a 5 % gain.
    The result is never slower than the model's own settings when those meet the budget:
    if nothing is measurably cheaper, the original settings come back, and the report
    says so.  When the original settings miss the budget, the report says that first,
    and the cheapest setting that meets it comes back, labelled as slower if it is.

    Args:
      model: an MjModel (not changed; the result holds a tuned copy).
      budget: the largest error over one control period, per joint kind, as the 90 %
        quantile over sampled states of each kind's largest joint error (its 95 % upper
        confidence bound must be within the budget): a number (rad for hinges, ball
        joints and free-joint rotation; m for slides and free-joint position), a dict
        {kind: limit} over 'free_pos', 'free_rot', 'ball', 'slide', 'hinge', or
        'original': as accurate as the model's own settings on every kind (equal within
        1 % on the same states, or better).
      control_period: seconds between control updates (a whole number of the model's
        timesteps).  Default: 10 ms rounded to whole timesteps (at least one); the report
        says which was used.  Timesteps are searched among its divisors, so the timestep
        can grow up to the period.
      control: controls, (nperiod x nu) or (ntraj x nperiod x nu), one row per period;
        default uniform random within ctrlrange.  With ntraj >= 2 the first half drives the
        search trajectories and the second half the held-out ones.
      horizon: seconds each trajectory runs (the long-horizon stability check); default
        max(1 s, 20 control periods), or the length of `control`.
      states: initial states (n x nstate, mjSTATE_FULLPHYSICS), n >= 2, split in half
        between search and held-out; default the first keyframe (or qpos0) perturbed.
      objective: 'cheapest' (the fastest within the budget) or 'accurate' (the most
        accurate at no more than the original cost).
      nthread: threads of the rollout pool (default: all cores).
      seed: seeds the random initial states and controls.
      progress: show a tqdm progress bar when tqdm is installed.
      ray: run the error evaluations on Ray actors (mjcffi.distributed; needs
        `pip install 'mjcffi[distributed]'` and, for a cluster, ray.init first); the
        timings stay on this machine, so that speed-ups compare like with like.

    Returns a TuneResult.  Raises BudgetError (a ValueError) when no setting meets the
    budget on the held-out states, naming the closest verified one; ValueError or
    TypeError on bad input, or when the model diverges at its own settings.
    """
    started = time.perf_counter()
    m = _check_model(model)
    if objective not in OBJECTIVES:
        raise ValueError(f"objective must be one of {OBJECTIVES}, got {objective!r}")
    dt0 = float(m.opt.timestep)
    if control_period is None:
        period = default_period(dt0)
        nstep0 = steps_per_period(period, dt0)
        period_source = (f"{period * 1e3:g} ms, the default (no control_period was given): "
                         f"{DEFAULT_PERIOD * 1e3:g} ms rounded to whole timesteps of "
                         f"{dt0 * 1e3:g} ms, at least one")
    else:
        period = _positive(control_period, "control_period")
        nstep0 = steps_per_period(period, dt0)
        period_source = f"{period * 1e3:g} ms, as given"
    control = _check_control(m, control)
    horizon = _horizon(horizon, period, dt0, control)
    nperiod = max(1, round(horizon / period))
    limits = _check_budget(budget)
    nthread = (os.cpu_count() or 1) if nthread is None else _positive_int(nthread, "nthread")
    rng = np.random.default_rng(seed)
    initial = _split_states(m, states, rng)
    controls = _split_controls(m, control, [len(s) for s in initial], nperiod, rng)
    horizon_controls = random_controls(
        m, rng, (_verify.DIVERGENCE_STATES,
                 max(1, round(_verify.DIVERGENCE_HORIZON / period))))

    run = _Run(m=m, budget=budget, limits=limits, objective=objective, period=period,
               period_source=period_source, nstep0=nstep0, nthread=nthread,
               progress=progress, started=started, ray=ray)
    # candidates may diverge: that is measured, not raised, even with warnings as errors
    with ignore_warnings():
        return _tune(run, initial, controls, horizon_controls)


@dataclasses.dataclass
class _Run:
    """What one tuning run goes by, checked by `tune`: the model, the budget and its
    per-kind limits, the objective, the control period (seconds, how it was chosen, and
    timesteps of the model's own), the threads, the progress bar's switch, the start time,
    Ray or not."""
    m: object
    budget: object
    limits: dict
    objective: str
    period: float
    period_source: str
    nstep0: int
    nthread: int
    progress: bool
    started: float
    ray: bool


def _pool(nthread, ray):
    """Where the error evaluations run: the local C rollout pool, or Ray actors."""
    if ray:
        from ..distributed import RolloutCluster
        return RolloutCluster()
    return _rollout.Rollout(nthread=nthread if nthread > 1 else 0)


def _tune(run, initial, controls, horizon_controls):
    m = run.m
    stages = unneeded_stages(m)
    base_disable = int(m.opt.disableflags)
    for s in stages:
        base_disable |= s.flag
    sets = []
    for init, u in zip(initial, controls):
        samples, diverged = sample(m, init, u, run.nstep0, NSAMPLE)
        if diverged:
            raise ValueError(f"the model diverges at its own settings: MuJoCo warned of a bad "
                             f"qpos, qvel or qacc in {len(diverged)} of {len(init)} "
                             f"trajectories; fix the model (or its controls) before tuning")
        sets.append(samples)

    bar = _progress.bar(None, "tune", "eval", run.progress, leave=False)
    try:
        with _pool(run.nthread, run.ray) as pool:
            return _run(run, stages, base_disable, sets[0], sets[1], horizon_controls, pool,
                        bar)
    finally:
        bar.close()


def _references(run, base_disable, pool, sets):
    """For each set: the fine reference's end states one period after each sample."""
    m = run.m
    tight = not base_disable & mjtDisableBit.mjDSBL_CONSTRAINT
    ref = setting_model(m, reference_setting(m, tight), base_disable)
    out = []
    for samples in sets:
        end, ok = end_states(pool, ref, samples, run.nstep0 * REF_FACTOR, run.nthread)
        if not ok.all():
            raise ValueError("the fine reference (RK4 at timestep / 100) diverged from "
                             f"{int((~ok).sum())} sampled states: the model is not stable "
                             "enough to be tuned")
        out.append(end)
    return ref, out


def _run(run, stages, base_disable, search_set, held_set, horizon_controls, pool, bar):
    m, nstep0 = run.m, run.nstep0
    original = Setting.of(m)
    ref, (ref_search, ref_held) = _references(run, base_disable, pool, (search_set, held_set))
    own_search, own_end = period_estimates(pool, m, original, base_disable, search_set,
                                           qpos_of(m, ref_search), nstep0, run.nthread)
    if run.budget == "original":
        search_budget = Budget({k: e.value * EQUAL for k, e in own_search.items()}, paired=True)
    else:
        search_budget = Budget(_limits_for(run.limits, own_search), paired=False)
    search = Search(m, original, base_disable, search_set, qpos_of(m, ref_search),
                    search_budget, pool, run.nthread, nstep0, bar)
    search._cache[(original, nstep0)] = (own_search, own_end)
    own = search.evaluate(original, nstep0)
    own.speed = Speed(1.0, 1.0, 1.0, ())

    check = _Verification(run, base_disable, held_set, ref, ref_held, pool, own,
                          horizon_controls)
    own_problem = check.problem(own)
    own_ok = own_problem is None
    own.status = "the original: meets the budget" if own_ok else f"the original: {own_problem}"

    if run.objective == "cheapest":
        candidates, ranked = _cheapest_candidates(search, own, own_ok)
    else:
        candidates, ranked = _accurate_candidates(search, own)
    chosen, added = _first_verified(search, check, ranked, own, own_ok, run.objective)
    candidates = _unique(candidates + added)
    if chosen is None:
        if not own_ok:
            raise _no_setting([own] + candidates, check)
        chosen = own
    chosen.status = "chosen"
    outcome, speed_final = _outcome(search, chosen, own, own_ok, held_set, m, base_disable)
    tuned = setting_model(m, chosen.setting, base_disable)
    error = TuneError.of(chosen.held_out, own.held_out, check.budget, chosen.stability,
                         own.stability, check.reference_penetration, chosen.divergence)
    return TuneResult(
        model=tuned, original=m, setting=chosen.setting, original_setting=original,
        settings=_changes(chosen, own, original, stages, speed_final), speedup=speed_final.value,
        speed=speed_final, error=error, candidates=[own] + candidates,
        budget_name=str(run.budget), objective=run.objective, control_period=run.period,
        period_source=run.period_source, outcome=outcome, original_meets=own_ok,
        wall_time=time.perf_counter() - run.started, evaluations=search.evaluations,
        timings=search.timings, disable_set=base_disable & ~int(m.opt.disableflags))


def _cheapest_candidates(search, own, own_ok):
    """(every candidate tried, the finals in the order to verify them)."""
    structural, misses = search.structural(_max_nstep(search, own_ok))
    starts = ([own] if search.fits(own.estimates) else []) + structural
    tried, finals = [], []
    for start in starts:
        final, steps = search.refine(start)
        tried += [c for c in steps if c is not own]
        if final is not own and all(final.setting != f.setting for f in finals):
            finals.append(final)
    for c in finals:
        c.speed = search.speed((own.setting, own.nstep), (c.setting, c.nstep))
    everything = _unique(structural + misses + tried + finals)
    return everything, _ranked(finals, search.budget)


def _max_nstep(search, own_ok):
    """The most steps per control period a 'cheapest' candidate may take."""
    return search.nstep0 * (MORE_STEPS if own_ok else MORE_STEPS_WHEN_MISSED)


def _ranked(finals, budget):
    """The finals, fastest first; where the fastest's interval overlaps others', the most
    accurate of those goes first (a tie that a timing cannot break is broken by error), and
    at equal error the fewest steps, then the cheaper integrator, then the setting itself:
    never the timing, which load moves (Euler and implicitfast give the same bits on a model
    with no damping, and their order flipped under load)."""
    order = sorted(finals, key=lambda c: -c.speed.value)
    out = []
    while order:
        top = order[0]
        tied = [c for c in order if c.speed.high >= top.speed.low]
        pick = min(tied, key=lambda c: (budget.worst(c.estimates), c.nstep,
                                        INTEGRATORS.index(c.setting.integrator),
                                        repr(c.setting)))
        out.append(pick)
        order.remove(pick)
    return out


def _accurate_candidates(search, own):
    """'accurate': every integrator × steps per period up to twice the original's that is
    more accurate than the original on the search set, most accurate first, timed against
    the original; those measurably slower (interval below 1) are left out."""
    budget = Budget(own.error, paired=True)
    out = []
    order = (search.original.integrator,) + tuple(
        i for i in (0, 1, 2, 3) if i != search.original.integrator)
    for integrator in order:
        for nstep in range(1, MORE_STEPS * search.nstep0 + 1):
            s = search.original.replace(integrator=integrator,
                                        timestep=search.original.timestep * search.nstep0 / nstep)
            if s.integrator == own.setting.integrator and nstep == own.nstep:
                continue
            c = search.evaluate(s, nstep)
            if search.fits(c.estimates) and budget.worst(c.estimates) < 1.0:
                c.reasons.update(search.structural_reasons(c, "more accurate than the "
                                                              "original's"))
                out.append(c)
    out.sort(key=lambda c: (budget.worst(c.estimates), c.nstep))
    ranked = []
    for c in out:
        c.speed = search.speed((own.setting, own.nstep), (c.setting, c.nstep))
        if c.speed.high < 1.0:
            c.status = f"measurably slower than the original ({c.speed})"
            continue
        ranked.append(c)
        if len(ranked) >= 3:
            break
    return out, ranked


def _first_verified(search, check, ranked, own, own_ok, objective):
    """The first of `ranked` that passes the held-out check; every one is tried in turn.
    When a candidate fails, two that spend less of the budget join the queue, timed and
    ranked like the others: the one it refined (one solver option less) and, for
    'cheapest', the same setting with one more step per period (at most FALLBACKS of
    those in all)."""
    queue = list(ranked)
    max_nstep = _max_nstep(search, own_ok)
    added, seen = [], {(c.setting, c.nstep) for c in queue}
    while queue:
        c = queue.pop(0)
        if objective == "cheapest" and own_ok and c.speed.low < MIN_GAIN:
            c.status = (f"not measurably faster than the original ({c.speed}; needs the "
                        f"whole interval above {MIN_GAIN:g})")
            continue
        problem = check.problem(c)
        if problem is None and objective == "accurate" and \
                Budget(measures.values(own.held_out), paired=True).worst(c.held_out) >= 1.0:
            problem = "no more accurate than the original on held-out states"
        if problem is None:
            return c, added
        c.status = problem
        more = []
        before = c.previous
        if before is not None and before is not own and before.held_out is None:
            more.append(before)
        if objective == "cheapest" and len(added) < FALLBACKS:
            step = search.one_more_step(c, max_nstep)
            if step is not None and (step.setting, step.nstep) not in seen:
                added.append(step)
                more.append(step)
        for extra in more:
            seen.add((extra.setting, extra.nstep))
            if extra.speed is None:
                extra.speed = search.speed((own.setting, own.nstep),
                                           (extra.setting, extra.nstep))
        if more:
            queue = _ranked(queue + more, search.budget)
    return None, added


def _outcome(search, chosen, own, own_ok, held_set, m, base_disable):
    """('faster' | 'original' | 'slower', its Speed measured on the held-out states)."""
    if chosen is own:
        return "original", own.speed
    base = PeriodTimer(setting_model(m, own.setting, base_disable), held_set, own.nstep,
                       min_time=0.05)
    tuned = PeriodTimer(setting_model(m, chosen.setting, base_disable), held_set,
                        chosen.nstep, min_time=0.05)
    final = speed(base, tuned, pairs=15)
    search.timings += 1
    return ("faster" if own_ok else ("slower" if final.value < 1.0 else "faster")), final


class _Verification:
    """The held-out check: the budget there, the reference's penetration, the original's
    stability."""

    def __init__(self, run, base_disable, held_set, ref, ref_end, pool, own, horizon_controls):
        m = run.m
        self.m = m
        self.run = run
        self.base_disable = base_disable
        self.held_set = held_set
        self.reference_qpos = qpos_of(m, ref_end)
        self.pool = pool
        self.conservative = _verify.conserves_energy(m, base_disable)
        self.reference_penetration, _ = _verify.penetration(ref, ref_end)
        own.held_out, self.own_end = period_estimates(
            pool, m, own.setting, base_disable, held_set, self.reference_qpos, own.nstep,
            run.nthread)
        if run.budget == "original":
            self.budget = Budget({k: e.value * EQUAL for k, e in own.held_out.items()},
                                 paired=True)
        else:
            self.budget = Budget(_limits_for(run.limits, own.held_out), paired=False)
        self.own = own
        own.stability = self.stability(own.setting, own.nstep, self.own_end)
        self.horizon = _verify.HorizonCheck(pool, m, base_disable, held_set, horizon_controls,
                                            own.nstep, run.nthread, self.budget.limits)
        own.divergence = _verify.Divergence(self.horizon.horizon, self.horizon.nperiod,
                                            self.horizon.original, self.horizon.original,
                                            self.horizon.allowed)
        if run.budget == "original":
            # no deeper than the original or the reference, whichever is deeper
            self.position = max(0.0, own.stability.penetration - self.reference_penetration) \
                if not math.isnan(own.stability.penetration) and \
                not math.isnan(self.reference_penetration) else 0.0
        else:
            self.position = _position_budget(self.budget.limits, run.limits)

    def stability(self, setting, nstep, end):
        return _verify.stability(self.m, setting, self.base_disable, self.held_set, nstep,
                                 self.conservative, end)

    def problem(self, c):
        """Why candidate `c` fails on the held-out set, or None (its held_out and stability
        are filled in on the way)."""
        if c.held_out is None or c is not self.own:
            c.held_out, end = period_estimates(
                self.pool, self.m, c.setting, self.base_disable, self.held_set,
                self.reference_qpos, c.nstep, self.run.nthread)
        else:
            end = self.own_end
        if not self.budget.fits(c.held_out):
            return "held-out error over the budget"
        if c is not self.own:
            c.divergence = self.horizon.of(c.setting, c.nstep)
            problem = _verify.divergence_problem(c.divergence)
            if problem:
                return problem
        if c.stability is None:
            c.stability = self.stability(c.setting, c.nstep, end)
        return _verify.stability_problem(c.stability, self.own.stability,
                                         self.reference_penetration, self.position,
                                         self.run.budget == "original")


def _position_budget(limits, given):
    """Metres a contact may sink past the reference: the position kinds' budget, else the
    smallest budget given (a number is in m for every kind)."""
    position = [v for k, v in limits.items() if k in ("free_pos", "slide")]
    if position:
        return min(position)
    return min(given.values()) if given else 0.0


def _unique(candidates):
    out, seen = [], set()
    for c in candidates:
        key = (c.setting, c.nstep)
        if key not in seen:
            seen.add(key)
            out.append(c)
    return out


def _changes(chosen, own, original, stages, final_speed):
    out = {}
    for s in stages:
        out[s.name] = Change(s.name, "on", "off", s.reason)
    if chosen is own:
        return out
    for field, (before, after) in chosen.setting.changes(original).items():
        out[field] = Change(field, before, after,
                            chosen.reasons.get(field, "part of the verified setting"))
    return out


def _no_setting(candidates, check):
    """The BudgetError: only what was verified is named as such."""
    # the original is the baseline, said first; the others as far as they got
    verified = [c for c in candidates if c.held_out is not None and c is not check.own]
    limit = ", ".join(f"{k} {v:.2e}" for k, v in check.budget.limits.items())
    if verified:
        best = min(verified, key=lambda c: check.budget.worst(c.held_out))
        shown = ", ".join(f"{k} {e.upper:.2e}" for k, e in best.held_out.items())
        where = (f"of the {len(verified)} settings verified on the held-out states, the "
                 f"closest was {best.label(check.own.setting) or 'the original'} with "
                 f"held-out error bounds {shown} ({best.status})")
    else:
        best = min((c for c in candidates if c is not check.own),
                   key=lambda c: check.budget.worst(c.estimates), default=check.own)
        shown = ", ".join(f"{k} {e.upper:.2e}" for k, e in best.estimates.items())
        best.status = "over the budget on the search states"
        where = (f"no setting fit it even on the search states; the closest there was "
                 f"{best.label(check.own.setting)} with error bounds {shown}")
    return BudgetError(f"no setting met the budget ({limit}); the original settings miss "
                       f"it, and {where}", best, candidates)


# ---------------------------------------------------------------- input checks

def _check_model(model):
    if not isinstance(model, MjModel):
        raise TypeError(f"model must be an mjcffi.MjModel, got {type(model).__name__}")
    return model


def _positive(value, name):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a number of seconds, got {type(value).__name__}")
    if not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be positive and finite, got {value}")
    return float(value)


def _positive_int(value, name):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an int, got {type(value).__name__}")
    if value < 1:
        raise ValueError(f"{name} must be at least 1, got {value}")
    return int(value)


def _check_budget(budget):
    """{kind: limit}, or None for 'original'."""
    if isinstance(budget, str):
        if budget != "original":
            raise ValueError(f"budget must be a number, a dict per joint kind or 'original', "
                             f"got {budget!r}")
        return None
    if isinstance(budget, collections.abc.Mapping):
        unknown = set(budget) - set(measures.JOINT_KINDS)
        if unknown:
            raise ValueError(f"unknown joint kinds in budget: {sorted(unknown)}; "
                             f"choose from {list(measures.JOINT_KINDS)}")
        return {k: _limit(v, f"budget[{k!r}]") for k, v in budget.items()}
    limit = _limit(budget, "budget")
    return {k: limit for k in measures.JOINT_KINDS}


def _limit(value, name):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a number (rad or m), got {type(value).__name__}")
    if not value > 0 or not math.isfinite(value):
        raise ValueError(f"{name} must be a positive, finite error (rad or m), got {value}")
    return float(value)


def _limits_for(limits, own_estimates):
    """The budget for the kinds the model has."""
    return {k: v for k, v in limits.items() if k in own_estimates}


def _horizon(horizon, period, dt0, control):
    if horizon is None:
        if control is not None:
            return control.shape[-2] * period
        return max(DEFAULT_HORIZON, 20 * period)
    horizon = _positive(horizon, "horizon")
    if horizon < dt0:
        raise ValueError(f"horizon {horizon:g} s is shorter than one step ({dt0:g} s)")
    if horizon < period * (1 - 1e-9):
        raise ValueError(f"horizon {horizon:g} s is shorter than one control period "
                         f"({period:g} s)")
    return horizon


def _check_control(m, control):
    if control is None:
        return None
    u = np.asarray(control, dtype=np.float64)
    if u.ndim not in (2, 3) or u.shape[-1] != m.nu:
        raise ValueError(f"control must have shape (nperiod, {m.nu}) or "
                         f"(ntraj, nperiod, {m.nu}), got {u.shape}")
    if not np.all(np.isfinite(u)):
        raise ValueError("control holds values that are not finite")
    return u


def _split_states(m, states, rng):
    """(search, held-out) initial states."""
    if states is None:
        return initial_states(m, NTRAJ, rng), initial_states(m, NTRAJ, rng)
    s = np.asarray(states, dtype=np.float64)
    nstate = mjf.mj_stateSize(m, FULLPHYSICS)
    if s.ndim != 2 or s.shape[1] != nstate or len(s) < 2:
        raise ValueError(f"states must have shape (n, {nstate}) with n >= 2 "
                         f"(mjSTATE_FULLPHYSICS), got {s.shape}")
    if not np.all(np.isfinite(s)):
        raise ValueError("states holds values that are not finite")
    half = len(s) // 2
    return s[:half], s[half:]


def _split_controls(m, control, sizes, nperiod, rng):
    """(search, held-out) controls, (ntraj x nperiod x nu) each."""
    if control is None:
        return [random_controls(m, rng, (n, nperiod)) for n in sizes]
    if control.ndim == 2:
        return [np.broadcast_to(control, (n,) + control.shape).copy() for n in sizes]
    if len(control) >= 2:
        half = len(control) // 2
        parts = [control[:half], control[half:]]
    else:
        parts = [control, control]
    return [np.resize(p, (n,) + p.shape[1:]) for p, n in zip(parts, sizes)]
