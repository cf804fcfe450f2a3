"""python -m mjcffi.tune MODEL.xml --budget ERR|original [--out tuned.xml]: tune a model's options.

Prints the report (markdown) and, with --out, writes the model's MJCF with the
<option>/<flag> changes and nothing else changed.
"""

import argparse
import os
import sys

from .._cli import (check_ray, check_writable, load_model, non_negative_int, one_line,
                        positive, positive_int)
from ..evaluation.periods import steps_per_period
from ._tune import OBJECTIVES, BudgetError, _horizon, default_period, tune

PROG = "python -m mjcffi.tune"


def _budget(text):
    """argparse type: 'original', or a positive, finite error (tune's own range)."""
    if text == "original":
        return text
    try:
        float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"not a number or 'original': {text!r}") from None
    return positive(text)


def parser():
    """The command line's parser."""
    p = argparse.ArgumentParser(prog=PROG,
                                description="The cheapest settings of a model's options "
                                            "within a local-error budget, verified on "
                                            "held-out states; the same settings on "
                                            "every run.")
    p.add_argument("model", help="an MJCF (.xml) or MJB file")
    p.add_argument("--budget", type=_budget, required=True,
                   help="largest local error over one control period per joint kind "
                        "(rad or m, positive), or 'original': as accurate as the model's "
                        "own settings")
    timing = p.add_mutually_exclusive_group()
    timing.add_argument("--control-period", type=positive, default=None, metavar="SECONDS",
                        help="time between control updates, a whole number of timesteps "
                             "(default: 10 ms in whole timesteps, at least one)")
    timing.add_argument("--frame-skip", type=positive_int, default=None, metavar="N",
                        help="the control period as N timesteps (a gymnasium env's frame_skip)")
    p.add_argument("--objective", choices=OBJECTIVES, default="cheapest")
    p.add_argument("--horizon", type=positive, default=None, metavar="SECONDS",
                   help="length of each trajectory and of the stability runs (at least one "
                        "control period)")
    p.add_argument("--seed", type=non_negative_int, default=0)
    p.add_argument("--out", default=None, help="write the tuned MJCF here (needs an .xml model)")
    p.add_argument("--report", default=None, metavar="FILE.md",
                   help="also write the report here, with a plot beside it (FILE.png)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--ray", action="store_true",
                   help="run the error evaluations on Ray actors (mjcffi[distributed]); "
                        "timings stay local")
    return p


def _plot_path(report):
    return None if report is None else os.path.splitext(report)[0] + ".png"


def _checked(p, args):
    """(model, control period): everything the run needs, checked before it starts;
    parser.error on the first problem."""
    if args.out is not None and not args.model.endswith(".xml"):
        p.error("--out writes MJCF, so the model must be an .xml file")
    try:
        m = load_model(args.model)
    except ValueError as error:
        p.error(str(error))
    dt = m.opt.timestep
    period = args.control_period
    if args.frame_skip is not None:
        period = args.frame_skip * dt
    if period is None:
        period = default_period(dt)
    # the model-dependent checks tune() makes, made here before any work
    try:
        steps_per_period(period, dt)
    except ValueError as error:
        p.error(f"argument --control-period: {error}")
    try:
        _horizon(args.horizon, period, dt, None)
    except ValueError as error:
        p.error(f"argument --horizon: {error}")
    for option, path in (("--report", args.report), ("--report", _plot_path(args.report)),
                         ("--out", args.out)):
        check_writable(p, option, path)
    if args.ray:
        check_ray(p)
    return m, period


def main(argv=None):
    """Run the command line; 0 on success, 1 if no setting met the budget, 2 on bad input."""
    p = parser()
    args = p.parse_args(argv)
    m, period = _checked(p, args)
    try:
        result = tune(m, args.budget, control_period=period, horizon=args.horizon,
                      objective=args.objective, seed=args.seed, progress=not args.quiet,
                      ray=args.ray)
    except BudgetError as error:
        print(f"mjcffi.tune: {error}", file=sys.stderr)
        return 1
    except ValueError as error:     # tune's word for a model it cannot tune (it diverges)
        print(f"{PROG}: error: {one_line(error)}", file=sys.stderr)
        return 2
    plot = _plot_path(args.report)
    text = result.report(plot=plot)
    print(text)
    if args.report is not None:
        with open(args.report, "w", encoding="utf-8") as f:
            f.write(text)
    if args.out is not None:
        path, route = result.write_xml(args.model, args.out)
        print(f"wrote {path} ({route} route)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
