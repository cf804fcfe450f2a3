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
    """Held-out figures of the tuned and the original settings."""

    local: dict                # local error per joint kind, held-out states
    original_local: dict
    budget: dict               # the limit per joint kind the held-out error was held to
    stability: object          # _verify.Stability of the tuned settings
    original_stability: object


def _fmt(x):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    if x == math.inf:
        return "diverged"
    return "0" if x == 0 else f"{x:.2e}"


class TuneResult:
    """The outcome of `mjcffi.tune`.

    model: the tuned copy of the model.  settings: {name: Change}, only what changed.
    speedup: × real time against the original, measured interleaved.  error: a TuneError
    (held-out local error and stability).  candidates: every setting tried, with its
    errors, speed and status.  report(): a markdown table (and a plot, given a path).
    """

    def __init__(self, *, model, original, setting, original_setting, settings, speedup, error,
                 candidates, budget_name, objective, control_period, wall_time, evaluations,
                 disable_set=0):
        self.model = model
        self.original = original
        self.setting = setting
        self.original_setting = original_setting
        self.settings = settings
        self.speedup = speedup
        self.error = error
        self.candidates = candidates
        self.budget_name = budget_name
        self.objective = objective
        self.control_period = control_period
        self.wall_time = wall_time
        self.evaluations = evaluations
        self.disable_set = disable_set      # mjtDisableBit bits the tuning switched off

    def __repr__(self):
        changed = ", ".join(f"{c.name}={_show(c.name, c.after)}" for c in self.settings.values())
        return (f"<TuneResult {self.speedup:.2f}× real time of the original; "
                f"{changed or 'no change'}>")

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
        return [f"# Tuned settings (budget: {self.budget_name}, objective: {self.objective})",
                "",
                f"Control period {self.control_period:g} s. Speed-up **{self.speedup:.2f}×** "
                f"real time against the original settings (measured interleaved, median). "
                f"Tuning took {self.wall_time:.1f} s and {self.evaluations} evaluations.", ""]

    def _changes(self):
        if not self.settings:
            return ["No setting changed: nothing cheaper met the budget.", ""]
        out = ["| setting | original | tuned | why |", "|---|---|---|---|"]
        for c in self.settings.values():
            out.append(f"| {c.name} | {_show(c.name, c.before)} | {_show(c.name, c.after)} "
                       f"| {c.reason} |")
        return out + [""]

    def _errors(self):
        e = self.error
        out = ["Held-out local error over one control period (root mean square over the "
               "held-out states of each joint kind's largest error):", "",
               "| joint kind | unit | original | tuned | budget |", "|---|---|---:|---:|---:|"]
        for kind, unit in JOINT_KINDS.items():
            if kind in e.local:
                out.append(f"| {kind} | {unit} | {_fmt(e.original_local.get(kind))} | "
                           f"{_fmt(e.local[kind])} | {_fmt(e.budget.get(kind))} |")
        s, o = e.stability, e.original_stability
        out += ["", "Long horizon, held-out trajectories: "
                f"diverged {s.diverged} (original {o.diverged}); deepest penetration "
                f"{_fmt(s.penetration)} m (original {_fmt(o.penetration)} m); energy drift "
                f"{_fmt(s.energy_drift)} J (original {_fmt(o.energy_drift)} J).", ""]
        return out

    def _candidates(self):
        kinds = [k for k in JOINT_KINDS if k in self.error.local]
        out = ["Candidates (search-set error; speed-ups marked ~ are estimates):", "",
               "| setting | × speed | " + " | ".join(kinds) + " | status |",
               "|---|---:|" + "---:|" * len(kinds) + "---|"]
        for c in sorted(self.candidates, key=lambda c: -c.speedup):
            speed = f"{c.speedup:.2f}" if c.measured else f"~{c.speedup:.2f}"
            errs = " | ".join(_fmt(c.error.get(k)) for k in kinds)
            out.append(f"| {c.label(self.original_setting)} | {speed} | {errs} | {c.status} |")
        return out + [""]


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
    for status, colour in (("verified", "tab:green"), ("searched", "tab:gray")):
        pts = [c for c in result.candidates if (c.status == "verified") == (status == "verified")
               and math.isfinite(worst_ratio(c.error, budget))]
        ax.scatter([c.speedup for c in pts], [max(worst_ratio(c.error, budget), 1e-6)
                                              for c in pts], c=colour, s=18, label=status)
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
    ax.set_ylabel("worst local error / budget")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig
