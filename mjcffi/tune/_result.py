"""What `tune` returns: the tuned model, what changed and why, and the figures behind it."""

import dataclasses
import math

from ..evaluation.measures import JOINT_KINDS
from ..evaluation.settings import value_name


@dataclasses.dataclass(frozen=True)
class Change:
    """One option or stage the tuning changed."""

    name: str          # an MjOption field ('timestep', 'integrator', ...) or a stage ('contact')
    before: object
    after: object
    reason: str

    def __str__(self):
        # enum values by name, as the report shows them (integrator: Euler → RK4)
        return (f"{self.name}: {_show(self.name, self.before)} → "
                f"{_show(self.name, self.after)} ({self.reason})")


@dataclasses.dataclass
class TuneError:
    """Held-out figures of the tuned and the original settings.

    The error of a joint kind is the 90 % quantile over the held-out states of that
    kind's largest joint error after one control period; `*_bound` is its 95 % upper
    confidence bound.  With a numeric budget the bound is what must be within `budget`;
    with budget='original' the point estimate, against the original's on the same
    states."""

    local: dict                # {kind: error} of the tuned settings, held-out states
    original_local: dict
    budget: dict               # the limit per joint kind the held-out error was held to
    stability: object          # _verify.Stability of the tuned settings
    original_stability: object
    local_bound: dict = None   # {kind: 95 % upper bound}
    original_bound: dict = None
    bounded: bool = True       # the bound (True) or the estimate (False) was held to budget
    reference_penetration: float = math.nan   # the fine reference's, same states (m)
    divergence: object = None  # _verify.Divergence: the 0.5 s check against a fine run

    @classmethod
    def of(cls, tuned, original, budget, stability, original_stability, reference_penetration,
           divergence):
        """From {kind: Estimate} of both and the held-out Budget."""
        return cls({k: e.value for k, e in tuned.items()},
                   {k: e.value for k, e in original.items()}, dict(budget.limits), stability,
                   original_stability, {k: e.upper for k, e in tuned.items()},
                   {k: e.upper for k, e in original.items()}, not budget.paired,
                   reference_penetration, divergence)


def _fmt(x):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    if x == math.inf:
        return "diverged"
    return "0" if x == 0 else f"{x:.2e}"


OUTCOMES = ("faster", "original", "slower")


class TuneResult:
    """The outcome of `mjcffi.tune`.

    model: the tuned copy of the model.  settings: {name: Change}, only what changed.
    outcome: 'faster' (measurably cheaper than the original within the budget),
    'original' (nothing was measurably cheaper: the original settings, with only the
    unneeded stages off), or 'slower' (the original settings miss the budget, and the
    cheapest setting that meets it is slower).  original_meets: whether the original
    settings meet the budget on the held-out states.  speedup: × the original's speed
    (CPU time, interleaved, median of 15 pairs; 1.0 for 'original'), and speed the same
    with its 95 % interval.  error: a TuneError (held-out error and stability).
    candidates: every setting tried, with its errors, speed and status.  report(): a
    markdown table (and a plot, given a path).
    """

    def __init__(self, *, model, original, setting, original_setting, settings, speedup, error,
                 candidates, budget_name, objective, control_period, wall_time, evaluations,
                 disable_set=0, speed=None, period_source="", outcome="faster",
                 original_meets=True, timings=0):
        self.model = model
        self.original = original
        self.setting = setting
        self.original_setting = original_setting
        self.settings = settings
        self.speedup = speedup
        self.speed = speed
        self.error = error
        self.candidates = candidates
        self.budget_name = budget_name
        self.objective = objective
        self.control_period = control_period
        self.period_source = period_source
        self.outcome = outcome
        self.original_meets = original_meets
        self.wall_time = wall_time
        self.evaluations = evaluations
        self.timings = timings
        self.disable_set = disable_set      # mjtDisableBit bits the tuning switched off

    def __repr__(self):
        changed = ", ".join(f"{c.name}={_show(c.name, c.after)}" for c in self.settings.values())
        return (f"<TuneResult {self.outcome}: {self._speed_words()}; "
                f"{changed or 'no change'}>")

    def _speed_words(self):
        """The speed as the report says it: a speed-up only above 1."""
        if self.outcome == "original":
            return "the original settings (nothing measurably cheaper)"
        s = self.speed
        interval = "" if s is None or not s.ratios else \
            f" (95 % interval {s.low:.2f}–{s.high:.2f})"
        if self.speedup < 1.0:
            return f"{self.speedup:.2f}× the original's speed, slower{interval}"
        return f"{self.speedup:.2f}× the original's speed{interval}"

    def options(self):
        """{MjOption field: new value} for the option fields that changed."""
        return {n: c.after for n, c in self.settings.items() if not _is_stage(c)}

    def write_xml(self, source, out_path):
        """Write the MJCF file `source` with this result's option and flag changes, and
        nothing else changed, to `out_path`; returns (path, route): the route is 'text' (the
        <option> element edited in the source text, every other byte kept) or 'spec' (MjSpec
        wrote it), the first that reproduces `self.model` bit for bit (see
        mjcffi.tune._mjcf)."""
        from ._mjcf import tuned_mjcf
        tuned = tuned_mjcf(source, self.options(), disable_set=self.disable_set,
                           out_path=out_path)
        with open(out_path, "w", encoding="utf-8") as f:
            f.write(tuned.text)
        return out_path, tuned.route

    def report(self, plot=None):
        """Markdown: what changed and why, the held-out figures, and the candidates.

        plot: a .png path; draws the candidates' search-set error against their speed-up
        there (needs matplotlib) and links it from the markdown."""
        lines = self._head() + self._changes() + self._errors() + self._candidates()
        if plot is not None:
            problem = draw(self, plot)
            lines += ([f"(No plot: {problem}.)", ""] if problem
                      else [f"![local error against speed]({plot})", ""])
        return "\n".join(lines)

    def _repr_markdown_(self):
        """Jupyter's display where markdown is wanted: the report, without the plot."""
        try:
            return self.report()
        except Exception:
            return None            # IPython then shows the next representation

    def _repr_html_(self):
        """Jupyter's display: the report as HTML, with the plot (inline PNG, when
        matplotlib is installed) before the candidates' table."""
        from .._support import display

        def build():
            html = display.markdown_html("\n".join(self._head() + self._changes() +
                                                   self._errors()))
            png = png_bytes(self)
            if png is not None:
                html += "\n" + display.png_img(png, "local error against speed")
            return html + "\n" + display.markdown_html("\n".join(self._candidates()))
        return display.safe(self, build)

    def _head(self):
        out = [f"# Tuned settings (budget: {self.budget_name}, objective: {self.objective})",
               ""]
        if not self.original_meets:
            out += ["**The original settings miss the budget** on the held-out states "
                    f"({self._original_problem()}).", ""]
        if self.outcome == "original":
            out += ["**Result: the original settings.** No candidate within the budget was "
                    "measurably cheaper than the model's own settings (a 95 % interval "
                    "above a 5 % gain), so none is offered." +
                    (" Only stages the model cannot need are switched off." if self.settings
                     else ""), ""]
        elif self.outcome == "slower":
            out += [f"**Result: slower, {self.speedup:.2f}× the original's speed** "
                    f"(95 % interval {self.speed.low:.2f}–{self.speed.high:.2f}): the "
                    "cheapest setting that meets the budget costs more than the original "
                    "settings, which do not meet it.", ""]
        else:
            out += [f"**Result: {self.speedup:.2f}× the original's speed** (95 % interval "
                    f"{self.speed.low:.2f}–{self.speed.high:.2f}; CPU time of one thread, "
                    "interleaved with the original, median of 15 pairs on the held-out "
                    "states).", ""]
        out += [f"Control period: {self.period_source or f'{self.control_period:g} s'}. "
                f"Tuning took {self.wall_time:.1f} s, {self.evaluations} error evaluations "
                f"and {self.timings} timings.", ""]
        return out

    def _original_problem(self):
        own = next((c for c in self.candidates if c.setting == self.original_setting), None)
        status = "" if own is None else own.status
        return status.replace("the original: ", "") or "see the table"

    def _changes(self):
        if not self.settings:
            return ["No setting changed.", ""]
        out = ["| setting | original | tuned | why |", "|---|---|---|---|"]
        for c in self.settings.values():
            out.append(f"| {c.name} | {_show(c.name, c.before)} | {_show(c.name, c.after)} "
                       f"| {c.reason} |")
        return out + [""]

    def _errors(self):
        e = self.error
        held = ("the bound must be within the budget" if e.bounded else
                "budget='original': the estimate must be within 1 % of the original's on "
                "the same states")
        out = ["Held-out error over one control period: per joint kind, the 90 % quantile "
               "over the held-out states of the kind's largest joint error, with its 95 % "
               f"upper confidence bound in brackets ({held}):", "",
               "| joint kind | unit | original | tuned | budget |", "|---|---|---:|---:|---:|"]
        for kind, unit in JOINT_KINDS.items():
            if kind in e.local:
                out.append(f"| {kind} | {unit} | {_pair(e.original_local, e.original_bound, kind)}"
                           f" | {_pair(e.local, e.local_bound, kind)} | "
                           f"{_fmt(e.budget.get(kind))} |")
        s, o = e.stability, e.original_stability
        out += ["", "Held-out trajectories over the whole horizon: "
                f"diverged {s.diverged} (original {o.diverged}); energy drift "
                f"{_fmt(s.energy_drift)} J (original {_fmt(o.energy_drift)} J). Contact "
                f"penetration at the held-out period ends, 90 % quantile: {_fmt(s.penetration)} m "
                f"(original {_fmt(o.penetration)} m, fine reference "
                f"{_fmt(e.reference_penetration)} m).", ""]
        d = e.divergence
        if d is not None:
            out += [f"Over {d.horizon:g} s ({d.nperiod} control periods) from "
                    f"{next(iter(d.tuned.values())).n if d.tuned else 0} held-out states, "
                    "distance from a fine run (the original settings at timestep / 8), 90 % "
                    "quantile [95 % bound]; allowed: the original's plus the budget over those "
                    "periods:", "",
                    "| joint kind | original | tuned | allowed |", "|---|---:|---:|---:|"]
            for kind in JOINT_KINDS:
                if kind in d.tuned:
                    t = d.tuned[kind]
                    allowed = d.allowed.get(kind)
                    shown = "not checked (chaotic: the original strays further than the " \
                        "accumulated budget)" if allowed == math.inf else _fmt(allowed)
                    out.append(f"| {kind} | {_fmt(d.original[kind].value)} | {_fmt(t.value)} "
                               f"[{_fmt(t.upper)}] | {shown} |")
            out.append("")
        return out

    def _candidates(self):
        kinds = [k for k in JOINT_KINDS if k in self.error.local]
        out = ["Candidates (search-set error, 90 % quantile [95 % bound]; × speed with its "
               "95 % interval, where timed):", "",
               "| setting | × speed | " + " | ".join(kinds) + " | status |",
               "|---|---:|" + "---:|" * len(kinds) + "---|"]

        def order(c):
            return (c.status != "chosen", -(c.speedup or 0.0))
        for c in sorted(self.candidates, key=order):
            if c.speed is None:
                speed = "–"
            elif not c.speed.ratios:
                speed = "1 (itself)"
            else:
                speed = f"{c.speed.value:.2f} ({c.speed.low:.2f}–{c.speed.high:.2f})"
            errs = " | ".join(_estimate(c.estimates.get(k)) for k in kinds)
            out.append(f"| {c.label(self.original_setting)} | {speed} | {errs} | {c.status} |")
        return out + [""]


def _pair(values, bounds, kind):
    value = _fmt(values.get(kind))
    if bounds is None or kind not in bounds:
        return value
    return f"{value} [{_fmt(bounds[kind])}]"


def _estimate(e):
    return "–" if e is None else f"{_fmt(e.value)} [{_fmt(e.upper)}]"


def _is_stage(change):
    return change.before in ("on", "off")


def _show(name, value):
    if value in ("on", "off"):
        return value
    return value_name(name, value)


def draw(result, path):
    """Search-set error (worst joint kind / its budget) against speed-up, saved as a PNG
    at `path`; None, or the reason there is no plot."""
    fig = _figure(result)
    if fig is None:
        return ("matplotlib is not installed (pip install 'mjcffi[plot]')")
    fig.savefig(path, dpi=72)
    return None


def png_bytes(result, dpi=80):
    """The plot of `draw` as PNG bytes, or None without matplotlib."""
    fig = _figure(result)
    if fig is None:
        return None
    import io
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()


def _figure(result):
    """The plot as a matplotlib Figure, or None without matplotlib.  It is made without
    pyplot: no backend is chosen or changed (a notebook's stays as it is), and no
    figure is left open for pyplot to show."""
    try:
        from matplotlib import ticker
        from matplotlib.figure import Figure
    except ImportError:
        return None
    from ..evaluation.measures import worst_ratio
    budget = result.error.budget
    fig = Figure(figsize=(5.5, 3.8))
    ax = fig.subplots()
    timed = [c for c in result.candidates if c.speed is not None
             and math.isfinite(worst_ratio(c.error, budget))]
    # the chosen setting last and on top (zorder), so no other point hides it
    for label, pts, style in (
            ("timed", [c for c in timed if c.status != "chosen"],
             dict(c="tab:gray", s=18, zorder=2)),
            ("chosen", [c for c in timed if c.status == "chosen"],
             dict(c="tab:green", s=70, marker="*", edgecolors="k", linewidths=0.6,
                  zorder=5))):
        ax.scatter([c.speedup for c in pts], [max(worst_ratio(c.error, budget), 1e-6)
                                              for c in pts], label=label, **style)
    ax.axhline(1.0, color="k", lw=0.8, ls="--", label="budget")
    ax.axvline(1.0, color="tab:red", lw=0.8, ls=":", label="original speed")
    ax.set_xscale("log")
    ax.set_yscale("log")
    # speed-ups often span less than a decade: label 1, 2 and 5 of each decade as plain
    # numbers, not every minor tick in powers of ten (their labels ran into each other)
    ax.xaxis.set_major_locator(ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(ticker.FuncFormatter(lambda value, _: f"{value:g}"))
    ax.xaxis.set_minor_formatter(ticker.NullFormatter())
    ax.set_xlabel("× the original's speed")
    ax.set_ylabel("worst error (90 % quantile) / budget")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig
