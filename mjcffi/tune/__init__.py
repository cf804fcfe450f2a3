"""mjcffi.tune: the cheapest settings of a model within an error budget.

    import mjcffi
    result = mjcffi.tune(model, budget=1e-3, control_period=0.008)
    result.model, result.settings, result.outcome, result.speed, print(result.report())

    python -m mjcffi.tune MODEL.xml --budget 1e-3 --control-period 0.008 --out tuned.xml

It switches off the pipeline stages the model cannot need (found from the model
alone, each with its reason), then searches the integrator, the timestep among
the divisors of the control period (10 ms by default), and the solver's options.
A setting is judged by its error over one control period from several hundred
states sampled along trajectories, against a fine reference (RK4 at timestep /
100, tight solver): per joint kind, the 90 % quantile over the states, with its
95 % upper confidence bound (a bootstrap over the trajectories) held to the budget.  The winner is verified on a
fresh held-out draw: its bound, its contact penetration against the reference,
its distance from a fine run after 0.5 s, and its long runs (divergence, energy).

Choices follow errors, which are the same bits on every run; the few that only a
timing can make use CPU time of one thread and a 95 % interval, so the same model,
budget and seed give the same settings on a loaded machine too.  The result is
never slower than the original settings when those meet the budget.

`mjcffi.tune` is this module and can be called as the function `tune`.
"""

import sys
import types

from ._result import Change, TuneError, TuneResult
from ._stages import Stage, unneeded_stages
from ._tune import OBJECTIVES, BudgetError, tune

__all__ = ["BudgetError", "Change", "OBJECTIVES", "Stage", "TuneError", "TuneResult",
           "tune", "unneeded_stages"]


class _CallableModule(types.ModuleType):
    """Lets `mjcffi.tune(model, budget)` call `tune` while `mjcffi.tune` stays the module
    that `python -m mjcffi.tune` runs."""

    def __call__(self, *args, **kwargs):
        return tune(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
