"""Speed against error: how fast each integrator, timestep and solver setting steps a scene,
and how far its trajectory strays from a fine reference.

    python -m mjcffi.accuracy [SCENE ...] [--budget ERR] [--out DIR] [--quick] [--ray]

Scenes are the hard cases of mjcffi.scenes (read at run time) and gymnasium's humanoid
(loaded from the installed gymnasium package).  For each scene the report sweeps the
integrator (Euler, implicit, implicitfast, RK4) over five timesteps around the scene's own; for
the contact scenes also the solver's iterations and tolerance; and, where the scene does not
need them, it times the pipeline stages (contact, constraint) switched off against on.

Every setting is compared with a reference run: RK4 at a timestep 100 times smaller than the
scene's own (and, for the contact scenes, Newton converged to 1e-12), at a fixed horizon.  The
setting, the reference, the error measure and the timing loop are mjcffi.evaluation's, the
core shared with mjcffi.tune (which measures local error per control period instead).

Writes ACCURACY.md (a table per scene, the cheapest setting within the error budget) and
accuracy.png (error against steps/s, Pareto front marked; needs matplotlib, the `plot` extra)
into --out (default: the current directory; made if missing).
With --ray the trajectory runs go to Ray tasks (mjcffi.distributed); the timing stays local.
"""

import argparse
import dataclasses
import math
import os
import sys
import time

import numpy as np

import mjcffi as mujoco
from mjcffi import scenes
from mjcffi._cli import check_ray, check_writable, positive
from mjcffi._support.machine import environment
from mjcffi.evaluation import REF_FACTOR, Setting, position_error, reference_setting
from mjcffi.evaluation import steps_per_second as _steps_per_second
from mjcffi.evaluation.periods import setting_model
from mjcffi.evaluation.settings import INTEGRATOR_NAMES, flag_names
from mjcffi.evaluation.states import DIVERGED, reset

INT = mujoco.mjtIntegrator
DSBL = mujoco.mjtDisableBit
# the integrators swept, in the order they are tried
INTEGRATORS = (INT.mjINT_EULER, INT.mjINT_IMPLICIT, INT.mjINT_IMPLICITFAST, INT.mjINT_RK4)
DEFAULT_BUDGET = 1e-2     # position error: 1 cm or 10 mrad


# ------------------------------------------------------------------ scenes

@dataclasses.dataclass
class Scene:
    name: str
    xml: str = None                 # an MJCF string, or
    path: str = None                # a file path
    horizon: float = 2.0            # seconds simulated
    why: str = ""                   # why this horizon
    conservative: bool = False      # report energy drift
    contact: bool = False           # report penetration; sweep the solver
    drift: bool = False             # report horizontal drift (a stack should stay put)
    unneeded: int = 0               # disable bits the scene can do without (checked exact)

    def model(self):
        if self.xml is not None:
            return mujoco.MjModel.from_xml_string(self.xml)
        return mujoco.MjModel.from_xml_path(self.path)


def humanoid_path():
    import importlib.resources
    path = importlib.resources.files("gymnasium") / "envs" / "mujoco" / "assets" / "humanoid.xml"
    if not path.is_file():
        raise FileNotFoundError(path)
    return str(path)


NOT_NEEDED = DSBL.mjDSBL_CONTACT | DSBL.mjDSBL_CONSTRAINT


def all_scenes():
    """The scenes by name; the hard cases' XML is read from mjcffi.scenes now."""
    hard = scenes.HARD_CASES
    out = {
        "double_pendulum": Scene(
            "double_pendulum", hard["double_pendulum"], horizon=2.0, conservative=True,
            unneeded=NOT_NEEDED,
            why="2 s is a few swings: long enough for the chaos to amplify step errors, "
                "short enough that the fine reference itself is still trustworthy"),
        "dzhanibekov": Scene(
            "dzhanibekov", hard["dzhanibekov"], horizon=2.0, conservative=True,
            unneeded=NOT_NEEDED,
            why="2 s covers the first flip of the intermediate axis, where orientation "
                "errors show up most"),
        "box_stack": Scene(
            "box_stack", hard["box_stack"], horizon=2.0, contact=True, drift=True,
            why="2 s of resting contact: enough for penetration to settle and for "
                "solver-driven sliding to accumulate"),
        "mass_ratio_chain": Scene(
            "mass_ratio_chain", hard["mass_ratio_chain"], horizon=1.0,
            unneeded=NOT_NEEDED,
            why="1 s: the chain falls from horizontal through its first swing; the light "
                "links' fast modes dominate the error early"),
    }
    try:
        out["humanoid"] = Scene(
            "humanoid", path=humanoid_path(), horizon=1.0, contact=True,
            why="1 s: the humanoid falls and lands (about 0.5 s); after the landing "
                "the motion is chaotic, so a longer horizon only measures chaos")
    except (ImportError, FileNotFoundError):
        pass
    return out


# ---------------------------------------------------------------- sweep

def sweep(scene, m, quick=False):
    """The settings to try on `scene` (m: its model as loaded)."""
    dt0 = m.opt.timestep
    factors = (2, 1, 0.5) if quick else (8, 4, 2, 1, 0.5, 0.25)
    integrators = list(INTEGRATORS)
    if quick:
        integrators = [INT.mjINT_EULER, INT.mjINT_RK4]
    out = [Setting(i, dt0 * f) for i in integrators for f in factors]
    if scene.contact and not quick:
        for i in (INT.mjINT_IMPLICITFAST, m.opt.integrator):
            for it in (1, 3, 10, 30):
                out.append(Setting(i, dt0, iterations=it))
            out.append(Setting(i, dt0, iterations=100, tolerance=1e-3))
            out.append(Setting(i, dt0, iterations=100, tolerance=1e-12))
    if scene.unneeded:
        # the same settings at the scene's own timestep, with the stages switched back on
        for i in integrators:
            out.append(Setting(i, dt0, enable_stages=scene.unneeded))
    unique = []
    for s in out:
        if s not in unique:
            unique.append(s)
    return unique


def scene_reference(scene, m):
    """The reference setting for `scene`: the shared core's, with the solver run to a tight
    tolerance where the scene has contacts (elsewhere there is no constraint to solve)."""
    return reference_setting(m, tight_solver=scene.contact)


# ------------------------------------------------------------------- runs

@dataclasses.dataclass
class Trajectory:
    qpos: np.ndarray                # at the horizon
    energy_drift: float = math.nan  # max |E(t) - E(0)| over samples, J
    energy0: float = math.nan
    penetration: float = math.nan   # most negative contact distance, m
    drift: float = math.nan         # largest horizontal displacement of a free body, m
    unstable: bool = False


# MuJoCo's divergence warnings (after one it resets the data and goes on), as an index array
_DIVERGED = list(DIVERGED)


def nsteps(scene, setting):
    return max(1, round(scene.horizon / setting.timestep))


def free_bodies(m):
    """qpos addresses of the free joints."""
    return [int(m.jnt_qposadr[j]) for j in range(m.njnt)
            if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE]


def simulate(scene, base_model, setting, samples=200):
    """One instrumented run to the horizon (energy, contacts sampled along the way)."""
    m = setting_model(base_model, setting, base_model.opt.disableflags | scene.unneeded)
    if scene.conservative:
        m.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    d = mujoco.MjData(m)
    reset(m, d)
    n = nsteps(scene, setting)
    free = free_bodies(m)
    start_xy = [d.qpos[a:a + 2].copy() for a in free]
    traj = Trajectory(qpos=None)

    def energy():
        mujoco.mj_forward(m, d)
        return float(d.energy[0] + d.energy[1])

    if scene.conservative:
        traj.energy0 = energy()
        traj.energy_drift = 0.0
    if scene.contact:
        traj.penetration = math.inf
        traj.drift = 0.0
    # contact scenes: look at every step (penetration peaks are brief); else ~`samples` chunks
    chunk = 1 if scene.contact else max(1, n // samples)
    done = 0
    while done < n:
        k = min(chunk, n - done)
        mujoco.mj_step(m, d, nstep=k)
        done += k
        if d.warning.number[_DIVERGED].any() or not np.all(np.isfinite(d.qpos)):
            traj.unstable = True
            break
        if scene.conservative:
            traj.energy_drift = max(traj.energy_drift, abs(energy() - traj.energy0))
        if scene.contact:
            if d.ncon:
                traj.penetration = min(traj.penetration, float(d.contact.dist.min()))
    if scene.contact:
        if traj.penetration == math.inf:
            traj.penetration = 0.0
        traj.penetration = min(traj.penetration, 0.0)
    if scene.drift:
        traj.drift = max((float(np.linalg.norm(d.qpos[a:a + 2] - xy))
                          for a, xy in zip(free, start_xy)), default=0.0)
    traj.qpos = d.qpos.copy()
    return traj


def steps_per_second(scene, base_model, setting, repeats=3, min_time=0.05):
    """Steps/s of `setting` on `scene`: the shared core's timing of mj_step(m, d, nstep=N) from
    the initial state, N covering the horizon."""
    m = setting_model(base_model, setting, base_model.opt.disableflags | scene.unneeded)
    return _steps_per_second(m, reset, nsteps(scene, setting), repeats, min_time)


# ------------------------------------------------------------------ report

@dataclasses.dataclass
class Row:
    setting: Setting
    label: str
    steps_per_s: float
    pos_err: float
    energy_drift: float
    penetration: float
    drift: float
    unstable: bool
    qpos: np.ndarray = None         # at the horizon
    pareto: bool = False

    @property
    def realtime(self):
        """Simulated seconds per wall-clock second: what a setting costs for a fixed horizon."""
        return self.steps_per_s * self.setting.timestep


def errors_against(m, traj, ref):
    if traj.unstable:
        return math.inf
    return position_error(m, traj.qpos, ref.qpos)


def pareto(rows):
    """Mark the rows no other row beats on both speed and error."""
    for r in rows:
        r.pareto = not r.unstable and not any(
            o is not r and not o.unstable and o.realtime >= r.realtime
            and o.pos_err <= r.pos_err
            and (o.realtime > r.realtime or o.pos_err < r.pos_err)
            for o in rows)


def cheapest_within(rows, budget):
    ok = [r for r in rows if not r.unstable and r.pos_err <= budget]
    return max(ok, key=lambda r: r.realtime) if ok else None


def simulate_on_ray(scene, base_model, settings):
    """[simulate(scene, base_model, s) for s in settings], each run a Ray task
    (mjcffi.distributed; the scene and model go to the object store once)."""
    from mjcffi import accuracy                # by module name: workers import it
    from mjcffi.distributed import map_calls
    return map_calls(accuracy.simulate, [(s,) for s in settings], shared=(scene, base_model))


def run_scene(scene, quick=False, log=print, use_ray=False):
    m = scene.model()
    ref_setting = scene_reference(scene, m)
    settings = sweep(scene, m, quick)
    t0 = time.perf_counter()
    if use_ray:
        # the trajectories on Ray; the timing below stays on this machine, one at a time
        ref, *trajectories = simulate_on_ray(scene, m, [ref_setting] + settings)
        log(f"  reference and {len(settings)} settings simulated on Ray: "
            f"{time.perf_counter() - t0:.1f} s")
    else:
        ref = simulate(scene, m, ref_setting)
        log(f"  reference {ref_setting.label()}: {time.perf_counter() - t0:.1f} s")
        trajectories = None
    rows = []
    for i, s in enumerate(settings):
        traj = trajectories[i] if use_ray else simulate(scene, m, s)
        # a diverged run is not timed: its speed means nothing, and MuJoCo would warn each time
        rate = math.nan if traj.unstable else steps_per_second(
            scene, m, s, repeats=2 if quick else 5, min_time=0.02 if quick else 0.1)
        rows.append(Row(s, s.label(), rate, errors_against(m, traj, ref),
                        traj.energy_drift, traj.penetration, traj.drift, traj.unstable,
                        traj.qpos))
    pareto(rows)
    return m, ref_setting, ref, rows


def fmt(x, unit=""):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    if x == math.inf:
        return "unstable"
    if x == 0:
        return "0"
    return f"{x:.2e}{unit}"


def stage_lines(scene, rows, dt0):
    """Steps/s with the unneeded stages off against on, same integrator and timestep."""
    if not scene.unneeded:
        return []
    names = "+".join(flag_names(scene.unneeded))
    lines = [f"Stages this scene does not need ({names}), off (as the sweep runs) against "
             f"switched back on, at dt={dt0:g}:", "",
             "| integrator | steps/s off | steps/s on | speed-up | same trajectory |",
             "|---|---:|---:|---:|:---:|"]
    by = {r.setting: r for r in rows}
    for r in rows:
        if not r.setting.enable_stages:
            continue
        off = by.get(r.setting.replace(enable_stages=0))
        if off is None or off.unstable or r.unstable:
            continue
        same = ("yes, bit for bit" if np.array_equal(off.qpos, r.qpos)
                else f"no (differs by {fmt(float(np.abs(off.qpos - r.qpos).max()))})")
        lines.append(f"| {INTEGRATOR_NAMES[int(r.setting.integrator)]} | {off.steps_per_s:,.0f} "
                     f"| {r.steps_per_s:,.0f} | {off.steps_per_s / r.steps_per_s:.2f}× "
                     f"| {same} |")
    return lines + [""]


def budget_winners(rows, budgets):
    out = []
    for b in budgets:
        best = cheapest_within([r for r in rows if not r.setting.enable_stages], b)
        out.append((b, best))
    return out


def scene_section(scene, m, ref_setting, rows, budget):
    dt0 = m.opt.timestep
    lines = [f"## {scene.name}", "",
             f"nq={m.nq}, nv={m.nv}; own timestep {dt0:g} s, own integrator "
             f"{INTEGRATOR_NAMES[int(m.opt.integrator)]}; horizon {scene.horizon:g} s — "
             f"{scene.why}.", "",
             f"Reference: {ref_setting.label()}.", ""]
    cols = ["setting", "steps/s", "× real time", "pos err"]
    if scene.conservative:
        cols.append("energy drift (J)")
    if scene.contact:
        cols.append("penetration (m)")
    if scene.drift:
        cols.append("horiz. drift (m)")
    lines.append("| " + " | ".join(cols) + " | Pareto |")
    lines.append("|" + "---|" + "---:|" * (len(cols) - 1) + ":---:|")
    for r in sorted(rows, key=lambda r: (r.unstable, -r.realtime)):
        speed = ["–", "–"] if r.unstable else [f"{r.steps_per_s:,.0f}", f"{r.realtime:,.1f}"]
        cells = [r.label] + speed + [fmt(r.pos_err)]
        if scene.conservative:
            cells.append(fmt(r.energy_drift))
        if scene.contact:
            cells.append(fmt(r.penetration))
        if scene.drift:
            cells.append(fmt(r.drift))
        lines.append("| " + " | ".join(cells) + f" | {'★' if r.pareto else ''} |")
    lines.append("")
    lines += stage_lines(scene, rows, dt0)
    best = cheapest_within([r for r in rows if not r.setting.enable_stages], budget)
    if best:
        lines.append(f"**Cheapest within the budget {budget:g}: {best.label}** — "
                     f"{best.steps_per_s:,.0f} steps/s, {best.realtime:,.1f}× real time, "
                     f"position error {fmt(best.pos_err)}.")
    else:
        lines.append(f"**No setting is within the budget {budget:g}.**")
    lines.append("")
    lines.append("Cheapest setting for other budgets: " + "; ".join(
        f"{b:g}: {w.label if w else 'none'}" for b, w in budget_winners(rows, (1e-1, 1e-3, 1e-4)))
        + ".")
    lines.append("")
    return lines


def plot(results, path):
    """One panel per scene: error against steps/s, Pareto front joined. Returns a message."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return ("matplotlib is not installed, so no plot was drawn "
                "(pip install 'mjcffi[plot]' or pip install matplotlib)")
    n = len(results)
    cols = min(n, 3)
    nrows = math.ceil(n / cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(4.2 * cols, 3.4 * nrows), squeeze=False)
    colours = {"Euler": "tab:red", "implicit": "tab:green", "implicitfast": "tab:blue",
               "RK4": "tab:purple"}
    for ax, (scene, m, ref_setting, rows) in zip(axes.flat, results):
        finite = [r for r in rows if not r.unstable]
        floor = min([r.pos_err for r in finite if r.pos_err > 0], default=1e-12) / 3
        for name, c in colours.items():
            pts = [r for r in finite if INTEGRATOR_NAMES[int(r.setting.integrator)] == name]
            plain = [r for r in pts if r.setting.iterations is None and r.setting.tolerance is None
                     and not r.setting.enable_stages]
            solver = [r for r in pts if r not in plain and not r.setting.enable_stages]
            staged = [r for r in pts if r.setting.enable_stages]
            for group, marker in ((plain, "o"), (solver, "s"), (staged, "^")):
                if group:
                    ax.scatter([r.realtime for r in group],
                               [max(r.pos_err, floor) for r in group], c=c, marker=marker,
                               s=22, alpha=0.8, label=name if marker == "o" else None)
        front = sorted((r for r in finite if r.pareto), key=lambda r: r.realtime)
        ax.plot([r.realtime for r in front], [max(r.pos_err, floor) for r in front],
                "k--", lw=1, label="Pareto front")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(scene.name, fontsize=10)
        ax.set_xlabel("simulated s per wall s (steps/s × dt)", fontsize=8)
        ax.set_ylabel("position error", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="major", lw=0.3)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    from matplotlib.lines import Line2D
    handles += [Line2D([], [], ls="", marker="s", c="gray"),
                Line2D([], [], ls="", marker="^", c="gray")]
    labels += ["solver iterations/tolerance", "unneeded stages on"]
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.07 if nrows > 1 else 0.12, 1, 1))
    fig.savefig(path, dpi=72)
    plt.close(fig)
    return None


REPORT_FILES = ("ACCURACY.md", "accuracy.png")


def unwritable_folder(path):
    """Why the report cannot be written into folder `path` (made if missing), or None.
    Creates nothing."""
    existing = os.path.abspath(path)
    while not os.path.exists(existing):
        existing = os.path.dirname(existing)
    if not os.path.isdir(existing):
        return f"{existing} is not a folder"
    if not os.access(existing, os.W_OK | os.X_OK):
        return "permission denied"
    return None


def _checked_out(p, out):
    """parser.error unless the report can be written into `out`; then make the folder."""
    reason = unwritable_folder(out)
    if reason:
        p.error(f"argument --out: cannot write into {out}: {reason}")
    if os.path.isdir(out):          # the files there, if any, must be overwritable
        for name in REPORT_FILES:
            check_writable(p, "--out", os.path.join(out, name))
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as error:
        p.error(f"argument --out: cannot make {out}: {error.strerror}")


def main(argv=None):
    """Run the sweep on the chosen scenes and write the report; 0 on success, 2 on bad input."""
    names = list(all_scenes())
    p = argparse.ArgumentParser(prog="python -m mjcffi.accuracy",
                                description=__doc__.split("\n")[0])
    p.add_argument("scenes", nargs="*", metavar="SCENE",
                   help=f"scenes to run (default: all): {', '.join(names)}")
    p.add_argument("--budget", type=positive, default=DEFAULT_BUDGET,
                   help="position error budget in the scene's units "
                        "(m and rad, positive; default %(default)g)")
    p.add_argument("--out", default=os.curdir,
                   help="folder for ACCURACY.md and accuracy.png (default: the current one)")
    p.add_argument("--quick", action="store_true",
                   help="a small sweep (Euler and RK4, three timesteps, no solver sweep)")
    p.add_argument("--ray", action="store_true",
                   help="simulate the trajectories (reference and settings) as Ray tasks "
                        "(mjcffi.distributed; connects with ray.init(), needs pip install "
                        "'mjcffi[distributed]'); the timing (steps/s) still runs here, one "
                        "setting at a time, so its figures are this machine's")
    args = p.parse_args(argv)
    catalogue = all_scenes()
    chosen = args.scenes or list(catalogue)
    for name in chosen:
        if name not in catalogue:
            p.error(f"unknown scene {name!r}; choose from {', '.join(catalogue)}"
                    + ("" if "humanoid" in catalogue else " (humanoid needs gymnasium)"))
    if args.ray:
        check_ray(p)
    out = args.out or os.curdir
    _checked_out(p, out)

    started = time.perf_counter()
    results = []
    for name in chosen:
        print(f"{name} ...", flush=True)
        t = time.perf_counter()
        scene = catalogue[name]
        m, ref_setting, _ref, rows = run_scene(scene, args.quick, use_ray=args.ray)
        results.append((scene, m, ref_setting, rows))
        print(f"  {len(rows)} settings, {time.perf_counter() - t:.1f} s", flush=True)
    report = write_report(results, args.budget, out, time.perf_counter() - started, args.quick)
    print(f"wrote {report}")
    return 0


def write_report(results, budget, out, elapsed, quick=False):
    png = os.path.join(out, "accuracy.png")
    problem = plot(results, png)
    if problem:
        print(problem, file=sys.stderr)
    lines = ["# Speed against error", "",
             "Written by `python -m mjcffi.accuracy" + (" --quick" if quick else "")
             + f" --budget {budget:g}`"
             + f" in {elapsed:.0f} s.", ""]
    lines += environment(("mjcffi", "mujoco-core", "numpy", "gymnasium"))
    lines += ["",
              "How to read it:", "",
              "- The reference, the error measure and the timing loop come from "
              "`mjcffi.evaluation`, the core this report shares with `mjcffi.tune` "
              "(`python -m mjcffi.tune MODEL --budget ...` searches one model's options for "
              "the cheapest within a local-error budget per control period; this report "
              "shows fixed-horizon error on its own scenes).",
              f"- **Reference**: each scene is run with RK4 at its own timestep / {REF_FACTOR} "
              "to a fixed horizon (contact scenes: Newton, 100+ iterations, tolerance 1e-12 — "
              "the constraint problem is convex with one solution, so this is the physics "
              "any solver converges to); every setting is compared with it at that horizon.",
              "- **pos err** (`position_error`): Euclidean norm of per-joint errors at the "
              "horizon; a hinge "
              "contributes |Δq| (rad), a free joint the distance between positions (m) plus "
              "the rotation angle between orientations (rad).",
              "- **energy drift**: largest |E(t) − E(0)| along the run (J, mjENBL_ENERGY), for "
              "the scenes that conserve energy.",
              "- **penetration**: the most negative contact distance seen at any step (m); "
              "**horiz. drift**: the largest horizontal distance a free body ends from where it "
              "started (m).",
              "- **steps/s** (`steps_per_second`): median of a few runs of "
              "`mj_step(m, d, nstep=N)` (the loop in C) "
              "over the horizon from the initial state. The machine is shared and noisy: take "
              "differences under ~10 % as noise.",
              "- **× real time**: steps/s × timestep, simulated seconds per wall-clock "
              "second. A step costs about the same at any timestep, so steps/s alone cannot "
              "rank timesteps: the Pareto front, the plot and the budget pick all use this "
              "(for a fixed horizon, the highest × real time is the cheapest setting).",
              "- **Pareto** ★: no other setting is both faster and more accurate. "
              "`unstable`: the run diverged (MuJoCo's bad qpos/qvel/qacc warning, after "
              "which it resets the state, or a non-finite state); "
              "it is not timed.",
              "- Stages a scene does not need (contact, constraint) are off in its sweep; rows "
              "marked `+contact+constraint` switch them back on to show what they cost.",
              ""]
    if not problem:
        lines += [f"![error against steps/s]({os.path.basename(png)})", ""]
    else:
        lines += [f"(No plot: {problem}.)", ""]
    lines += ["## Cheapest setting within the budget", "",
              f"Budget: position error ≤ {budget:g} (m and rad).", "",
              "| scene | setting | steps/s | × real time | pos err |", "|---|---|---:|---:|---:|"]
    for scene, m, ref_setting, rows in results:
        best = cheapest_within([r for r in rows if not r.setting.enable_stages], budget)
        if best:
            lines.append(f"| {scene.name} | {best.label} | {best.steps_per_s:,.0f} | "
                         f"{best.realtime:,.1f} | "
                         f"{fmt(best.pos_err)} |")
        else:
            lines.append(f"| {scene.name} | none within budget | | |")
    lines.append("")
    for scene, m, ref_setting, rows in results:
        lines += scene_section(scene, m, ref_setting, rows, budget)
    path = os.path.join(out, "ACCURACY.md")
    with open(path, "w") as f:
        f.write("\n".join(lines))
    return path


if __name__ == "__main__":
    sys.exit(main())
