"""python -m mjcffi.tune MODEL.xml --budget ERR|original [--out tuned.xml]: tune a model's options.

Prints the report (markdown) and, with --out, writes the model's MJCF with the
<option>/<flag> changes and nothing else changed.
"""

import argparse
import os
import sys

from ..model import MjModel
from ._tune import OBJECTIVES, BudgetError, tune


def _budget(text):
    if text == "original":
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"not a number or 'original': {text!r}") from None


def parser():
    p = argparse.ArgumentParser(prog="python -m mjcffi.tune",
                                description="The cheapest settings of a model's options "
                                            "within a local-error budget, verified on "
                                            "held-out states.")
    p.add_argument("model", help="an MJCF (.xml) or MJB file")
    p.add_argument("--budget", type=_budget, required=True,
                   help="largest local error over one control period per joint kind "
                        "(rad or m), or 'original': as accurate as the model's own settings")
    timing = p.add_mutually_exclusive_group()
    timing.add_argument("--control-period", type=float, default=None, metavar="SECONDS",
                        help="time between control updates (default: one timestep)")
    timing.add_argument("--frame-skip", type=int, default=None, metavar="N",
                        help="the control period as N timesteps (a gymnasium env's frame_skip)")
    p.add_argument("--objective", choices=OBJECTIVES, default="cheapest")
    p.add_argument("--horizon", type=float, default=None, metavar="SECONDS",
                   help="length of each trajectory and of the stability runs")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default=None, help="write the tuned MJCF here (needs an .xml model)")
    p.add_argument("--report", default=None, metavar="FILE.md",
                   help="also write the report here, with a plot beside it (FILE.png)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--ray", action="store_true",
                   help="run the error evaluations on Ray actors (mjcffi[distributed]); "
                        "timings stay local")
    return p


def main(argv=None):
    args = parser().parse_args(argv)
    if not os.path.isfile(args.model):
        parser().error(f"no such model file: {args.model}")
    if args.out is not None and not args.model.endswith(".xml"):
        parser().error("--out writes MJCF, so the model must be an .xml file")
    if args.model.endswith(".mjb"):
        m = MjModel.from_binary_path(args.model)
    else:
        m = MjModel.from_xml_path(args.model)
    period = args.control_period
    if args.frame_skip is not None:
        if args.frame_skip < 1:
            parser().error(f"--frame-skip must be at least 1, got {args.frame_skip}")
        period = args.frame_skip * m.opt.timestep
    try:
        result = tune(m, args.budget, control_period=period, horizon=args.horizon,
                      objective=args.objective, seed=args.seed, progress=not args.quiet,
                      ray=args.ray)
    except BudgetError as error:
        print(f"mjcffi.tune: {error}", file=sys.stderr)
        return 1
    plot = None if args.report is None else os.path.splitext(args.report)[0] + ".png"
    text = result.report(plot=None if plot is None else plot)
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
