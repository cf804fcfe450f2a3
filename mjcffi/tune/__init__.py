"""mjcffi.tune: the cheapest settings of a model within an error budget.

    import mjcffi
    result = mjcffi.tune(model, budget=1e-3, control_period=0.008)
    result.model, result.settings, result.speedup, print(result.report())

    python -m mjcffi.tune MODEL.xml --budget 1e-3 --control-period 0.008 --out tuned.xml

It switches off the pipeline stages the model cannot need (found from the model
alone, each with its reason), then searches the integrator, the timestep among
the divisors of the control period, and the solver's options.  A setting is
judged by its local error: from many states sampled along trajectories, one
control period under the setting against a fine reference (RK4 at timestep /
100, tight solver), per joint kind.  The winner is verified on held-out states
and controls it never saw, with long runs checked for divergence, penetration
and, where energy is conserved, energy drift.  Evaluations run on the C rollout
pool, all threads, with the GIL released.

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
