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
from ..evaluation.periods import (end_states, period_error, qpos_of, setting_model,
                                  steps_per_period)
from ..evaluation.reference import REF_FACTOR, reference_setting
from ..evaluation.settings import Setting
from ..evaluation.states import FULLPHYSICS, initial_states, random_controls, sample
from ..evaluation.timing import PeriodTimer, speed_ratio
from ..model import MjModel
from ..warning_errors import ignore_warnings
from . import _verify
from ._result import Change, TuneError, TuneResult
from ._search import MIN_GAIN, Candidate, Search
from ._stages import unneeded_stages

OBJECTIVES = ("cheapest", "accurate")
DEFAULT_HORIZON = 1.0      # seconds, or 20 control periods if that is longer
NTRAJ = 8                  # trajectories per set (search, held-out)
NSAMPLE = 256              # states sampled per set (the error is heavy-tailed: contact events)
TOP = 3                    # structural candidates the solver search starts from
VERIFY = 8                 # candidates verified at most, best first
# With a numeric budget the search aims below it, so that what it picks stays within the
# budget on states it never saw: the local error is heavy-tailed (contact events), and its
# root mean square over a few hundred states varies by some 10 % from one set to another.
SEARCH_MARGIN = 0.8
# budget='original': an error counts as equal to the original's within 1 %, the precision
# the report prints (two digits); a change of the solver's options alone perturbs the
# error by far less than the set-to-set spread, up or down at random
EQUAL = 1.01


class BudgetError(ValueError):
    """No setting met the budget on the held-out states; `best` is the closest found."""

    def __init__(self, message, best, candidates):
        super().__init__(message)
        self.best = best
        self.candidates = candidates


def tune(model, budget, *, control_period=None, control=None, horizon=None, states=None,
         objective="cheapest", nthread=None, seed=0, progress=True, ray=False):
    """The cheapest settings of `model` whose local error stays within `budget`.

    Args:
      model: an MjModel (not changed; the result holds a tuned copy).
      budget: the largest local error over one control period, per joint kind: a number
        (rad for hinges, ball joints and free-joint rotation; m for slides and free-joint
        position), a dict {kind: limit} over 'free_pos', 'free_rot', 'ball', 'slide',
        'hinge', or 'original': as accurate as the model's own settings on every kind
        (equal within 1 %, or better).  With a number the search aims at 80 % of it, and
        the held-out states must stay within it.
      control_period: seconds between control updates (a whole number of the model's
        timesteps; default one timestep).  Timesteps are searched among its divisors.
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
    budget, naming the best found; ValueError or TypeError on bad input, or when the model
    diverges at its own settings.
    """
    started = time.perf_counter()
    m = _check_model(model)
    if objective not in OBJECTIVES:
        raise ValueError(f"objective must be one of {OBJECTIVES}, got {objective!r}")
    dt0 = float(m.opt.timestep)
    period = dt0 if control_period is None else _positive(control_period, "control_period")
    nstep0 = steps_per_period(period, dt0)
    control = _check_control(m, control)
    horizon = _horizon(horizon, period, dt0, control)
    nperiod = max(1, round(horizon / period))
    limits = _check_budget(budget)
    nthread = (os.cpu_count() or 1) if nthread is None else _positive_int(nthread, "nthread")
    rng = np.random.default_rng(seed)
    initial = _split_states(m, states, rng)
    controls = _split_controls(m, control, [len(s) for s in initial], nperiod, rng)

    run = _Run(m=m, budget=budget, limits=limits, objective=objective, period=period,
               nstep0=nstep0, nthread=nthread, progress=progress, started=started, ray=ray)
    # candidates may diverge: that is measured, not raised, even with warnings as errors
    with ignore_warnings():
        return _tune(run, initial, controls)


@dataclasses.dataclass
class _Run:
    """What one tuning run goes by, checked by `tune`: the model, the budget and its
    per-kind limits, the objective, the control period (seconds, and timesteps of the
    model's own), the threads, the progress bar's switch, the start time, Ray or not."""
    m: object
    budget: object
    limits: dict
    objective: str
    period: float
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


def _tune(run, initial, controls):
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
    search_set, held_set = sets

    bar = _progress.bar(None, "tune", "eval", run.progress, leave=False)
    try:
        with _pool(run.nthread, run.ray) as pool:
            return _run(run, stages, base_disable, search_set, held_set, pool, bar)
    finally:
        bar.close()


def _run(run, stages, base_disable, search_set, held_set, pool, bar):
    m, nstep0, nthread, budget = run.m, run.nstep0, run.nthread, run.budget
    original = Setting.of(m)
    tight = not base_disable & mjtDisableBit.mjDSBL_CONSTRAINT
    ref = setting_model(m, reference_setting(m, tight), base_disable)
    references = []
    for samples in (search_set, held_set):
        end, ok = end_states(pool, ref, samples, nstep0 * REF_FACTOR, nthread)
        if not ok.all():
            raise ValueError("the fine reference (RK4 at timestep / 100) diverged from "
                             f"{int((~ok).sum())} sampled states: the model is not stable "
                             "enough to be tuned")
        references.append(qpos_of(m, end))
    search = Search(m, original, base_disable, search_set, references[0], None, pool,
                    nthread, nstep0, run.period, bar)
    own_error = search.error(original, nstep0)
    own_held = period_error(pool, m, original, base_disable, held_set, references[1], nstep0,
                            nthread)
    if budget == "original":
        search.budget = {k: v * EQUAL for k, v in own_error.items()}
        held_limits = {k: v * EQUAL for k, v in own_held.items()}
    else:
        held_limits = _limits_for(run.limits, own_error)
        search.budget = {k: v * SEARCH_MARGIN for k, v in held_limits.items()}

    own = Candidate(original, nstep0, own_error, 1.0, measured=True)
    candidates = _search(search, own, run.objective, budget)
    check = _Verification(m, base_disable, held_set, references[1], held_limits, own_held,
                          nstep0, strict=budget == "original")
    chosen = _first_verified(search, check, _ranked(candidates, own, run.objective,
                                                    search.budget), own, run.objective)
    if chosen is None:
        raise _no_setting(candidates, search.budget, held_limits, original)

    tuned = setting_model(m, chosen.setting, base_disable)
    speedup = _final_speedup(m, tuned, held_set, nstep0, chosen.nstep)
    chosen.speedup, chosen.measured = speedup, True
    error = TuneError(chosen.held_out, own_held, held_limits, chosen.stability,
                      check.own_stability)
    return TuneResult(
        model=tuned, original=m, setting=chosen.setting, original_setting=original,
        settings=_changes(chosen, original, stages), speedup=speedup, error=error,
        candidates=candidates, budget_name=str(budget), objective=run.objective,
        control_period=run.period, wall_time=time.perf_counter() - run.started,
        evaluations=search.evaluations,
        disable_set=base_disable & ~int(m.opt.disableflags))


class _Verification:
    """What the held-out check compares with: the original's held-out error and stability."""

    def __init__(self, m, base_disable, held_set, reference_qpos, limits, own_held, nstep0,
                 strict):
        self.m = m
        self.base_disable = base_disable
        self.held_set = held_set
        self.reference_qpos = reference_qpos
        self.limits = limits
        self.own_held = own_held
        self.strict = strict
        self.conservative = _verify.conserves_energy(m, base_disable)
        self.own_stability = self.stability(Setting.of(m), nstep0)
        # contacts may sink deeper than the original's by the position budget
        self.position = min((v for k, v in limits.items() if k in ("free_pos", "slide")),
                            default=0.25 * self.own_stability.penetration)

    def stability(self, setting, nstep):
        return _verify.stability(self.m, setting, self.base_disable, self.held_set, nstep,
                                 self.conservative)

    def problem(self, search, c, own, objective):
        """Why candidate `c` fails on the held-out set, or None (its held_out and stability
        are filled in on the way)."""
        c.held_out = self.own_held if c is own else period_error(
            search.pool, self.m, c.setting, self.base_disable, self.held_set,
            self.reference_qpos, c.nstep, search.nthread)
        search.progress.update()
        if not measures.within(c.held_out, self.limits):
            return "held-out error over budget"
        if objective == "accurate" and c is not own and \
                measures.worst_ratio(c.held_out, self.own_held) >= 1.0:
            return "no more accurate than the original on held-out states"
        c.stability = self.own_stability if c is own else self.stability(c.setting, c.nstep)
        return _verify.stability_problem(c.stability, self.own_stability, self.position,
                                         self.strict)


def _first_verified(search, check, ranked, own, objective):
    """The first of `ranked` (at most VERIFY of them) that passes the held-out check."""
    own_fits = measures.within(own.error, search.budget)
    for c in ranked[:VERIFY]:
        if not c.measured:
            c.speedup, c.measured = search.speedup(c.setting, c.nstep), True
            if objective == "cheapest" and c.speedup < MIN_GAIN and own_fits:
                c.status = "not measurably faster than the original"
                continue
        problem = check.problem(search, c, own, objective)
        if problem:
            c.status = problem
            continue
        c.status = "verified"
        return c
    return None


def _search(search, own, objective, budget):
    """Every candidate tried: the structural ones, then the solver search from the best."""
    max_cost = 1.0 if (objective == "accurate" or budget == "original") else math.inf
    structural = search.structural(max_cost)
    out = [own] + [c for c in structural if c.setting != own.setting]
    if objective == "cheapest":
        starts = sorted((c for c in out if search.fits(c.error)), key=lambda c: -c.speedup)
    else:
        starts = sorted(out, key=lambda c: measures.worst_ratio(c.error, search.budget))
    for start in starts[:TOP]:
        for c in search.coordinate(start, accurate=objective == "accurate"):
            if c is not start and all(c.setting != o.setting for o in out):
                out.append(c)
    _measure_speed(search, out, objective)
    return out


def _measure_speed(search, candidates, objective):
    """Measure the speed-up of the candidates that may be picked (estimates rank them)."""
    if objective == "cheapest":
        pool = sorted((c for c in candidates if search.fits(c.error)), key=lambda c: -c.speedup)
    else:
        pool = sorted(candidates, key=lambda c: measures.worst_ratio(c.error, search.budget))
    for c in pool[:2 * TOP]:
        if not c.measured:
            c.speedup = search.speedup(c.setting, c.nstep)
            c.measured = True
            search.progress.update()


def _ranked(candidates, own, objective, budget):
    """Candidates in the order to verify them: measured speed-ups first, then estimates.

    The original's own setting ranks as if MIN_GAIN× faster than itself: another setting
    must be measurably faster to be preferred to it."""
    def speed(c):
        return MIN_GAIN if c is own else c.speedup

    if objective == "cheapest":
        pool = [c for c in candidates if measures.within(c.error, budget)]
        return sorted(pool, key=lambda c: (not c.measured, -speed(c)))
    others = [c for c in candidates if c is not own and c.measured
              and c.speedup >= 1.0 / MIN_GAIN and measures.worst_ratio(c.error, budget) < 1.0]
    others.sort(key=lambda c: measures.worst_ratio(c.error, budget))
    return others + [own]


def _final_speedup(m, tuned, samples, nstep0, nstep):
    base = PeriodTimer(m, samples, nstep0, min_time=0.05)
    return speed_ratio(base, PeriodTimer(tuned, samples, nstep, min_time=0.05), pairs=9)[0]


def _changes(chosen, original, stages):
    out = {}
    for s in stages:
        out[s.name] = Change(s.name, "on", "off", s.reason)
    for field, (before, after) in chosen.setting.changes(original).items():
        out[field] = Change(field, before, after,
                            chosen.reasons.get(field, "part of the verified setting"))
    return out


def _no_setting(candidates, limits, held_limits, original):
    best = min(candidates, key=lambda c: measures.worst_ratio(
        c.held_out if c.held_out is not None else c.error, limits))
    errors = best.held_out if best.held_out is not None else best.error
    if best.status == "searched":
        best.status = "over the budget on the search states"
    shown = ", ".join(f"{k} {v:.2e}" for k, v in errors.items())
    limit = ", ".join(f"{k} {v:.2e}" for k, v in held_limits.items())
    return BudgetError(f"no setting met the budget ({limit}); the best found was "
                       f"{best.label(original)} with local error {shown} "
                       f"({best.status})", best, candidates)


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


def _limits_for(limits, own_error):
    """The budget for the kinds the model has."""
    return {k: v for k, v in limits.items() if k in own_error}


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
