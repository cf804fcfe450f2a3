"""mjcffi.tune on gymnasium's MuJoCo models: the speed-up it finds at equal or better held-out
local error (budget='original'), and what a looser budget buys, with the tuning's wall time.

    python -m benchmarks.bench_tune            # prints the table

Each model is tuned with random controls (uniform in ctrlrange) held for its env's control
period: frame_skip × timestep, frame_skip read from the v5 env's constructor default.
"""

import importlib
import inspect
import os

from mjcffi import MjModel, tune
from mjcffi.evaluation.measures import JOINT_KINDS

# model file -> (env module, env class) of gymnasium's v5 envs
ENVS = {"hopper": ("hopper_v5", "HopperEnv"), "walker2d": ("walker2d_v5", "Walker2dEnv"),
        "half_cheetah": ("half_cheetah_v5", "HalfCheetahEnv"), "ant": ("ant_v5", "AntEnv"),
        "humanoid": ("humanoid_v5", "HumanoidEnv")}
BUDGETS = ("original", 1e-2)
TARGET_SPEEDUP = 1.3       # on at least 3 of the 5 models, budget='original'
TARGET_WALL = 120.0        # seconds of tuning per model


def frame_skip(name):
    module, cls = ENVS[name]
    env = getattr(importlib.import_module(f"gymnasium.envs.mujoco.{module}"), cls)
    return inspect.signature(env.__init__).parameters["frame_skip"].default


def model_path(name):
    import gymnasium
    return os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets",
                        f"{name}.xml")


def _row(name, budget):
    m = MjModel.from_xml_path(model_path(name))
    skip = frame_skip(name)
    try:
        r = tune(m, budget, control_period=skip * m.opt.timestep, progress=False)
    except tune.BudgetError as error:
        return f"| {name}.xml | {budget} | {skip} × {m.opt.timestep:g} s | none met the budget: " \
               f"{error} | | | | |", None, None
    changes = ", ".join(f"{c.name} {_show(c)}" for c in r.settings.values()
                        if c.before not in ("on", "off")) or "none"
    stages = ", ".join(c.name for c in r.settings.values() if c.before == "on") or "none"
    kinds = [k for k in JOINT_KINDS if k in r.error.local]
    errors = "; ".join(f"{k} {r.error.original_local[k]:.1e} → {r.error.local[k]:.1e}"
                       for k in kinds)
    line = (f"| {name}.xml | {budget} | {skip} × {m.opt.timestep:g} s | {changes} (stages off: "
            f"{stages}) | **{r.speedup:.2f}×** | {errors} | {_nearest_miss(r)} | "
            f"{r.wall_time:.0f} s |")
    return line, r.speedup, r.wall_time


def _nearest_miss(r):
    """The candidate at least TARGET_SPEEDUP× faster (estimated or measured) whose search-set
    error comes closest to the original's: what the target would have cost in error."""
    own = next(c for c in r.candidates if c.setting == r.original_setting)
    fast = [c for c in r.candidates if c.speedup >= TARGET_SPEEDUP and c is not own]
    if not fast:
        return "–"

    def ratio(c):
        return max(c.error[k] / own.error[k] for k in own.error if own.error[k] > 0)
    best = min(fast, key=ratio)
    return (f"{best.label(r.original_setting)}: ~{best.speedup:.2f}× at "
            f"{ratio(best):.2f}× the original's error")


def _show(change):
    from mjcffi.evaluation.settings import value_name
    return f"{value_name(change.name, change.before)} → {value_name(change.name, change.after)}"


def run(budgets=BUDGETS, names=tuple(ENVS)):
    lines = ["## `mjcffi.tune` on gymnasium's models", "",
             "`tune(model, budget, control_period=frame_skip × timestep)` with random controls; "
             "speed-up is × real time against the model's own settings, measured interleaved "
             "on held-out states (median of 9 pairs); errors are held-out local errors over one "
             "control period (root mean square over 256 states of each joint kind's largest "
             "error; rad or m), original → tuned. `budget='original'` asks for equal (within 1 %) "
             "or better error on every joint kind. The nearest candidate column shows the "
             "search-set error, relative to the original's worst joint kind, of the candidate at "
             f"least {TARGET_SPEEDUP}× as fast that came closest.", "",
             "| model | budget | control period | changed | speed-up | held-out error "
             f"(original → tuned) | nearest ≥ {TARGET_SPEEDUP}× candidate | tuning time |",
             "|---|---|---|---|---:|---|---|---:|"]
    speedups, walls = [], []
    for budget in budgets:
        for name in names:
            line, speedup, wall = _row(name, budget)
            lines.append(line)
            if budget == "original" and speedup is not None:
                speedups.append(speedup)
            if wall is not None:
                walls.append(wall)
    met = sum(s >= TARGET_SPEEDUP for s in speedups)
    lines += ["", f"Targets: speed-up ≥ {TARGET_SPEEDUP}× with budget='original' on at least 3 "
              f"of 5 models: **{'met' if met >= 3 else 'not met'}** ({met} of {len(speedups)}); "
              f"tuning under {TARGET_WALL:.0f} s per model: "
              f"**{'met' if walls and max(walls) < TARGET_WALL else 'not met'}** "
              f"(longest {max(walls, default=float('nan')):.0f} s)."]
    return lines


if __name__ == "__main__":
    print("\n".join(run()))
