"""`python -m mjcffi.viewer [--mjcf PATH]`: the standalone viewer.

With --mjcf it opens that model (ctrl+L reloads it); without, an empty window
that a model file can be dropped on.  The environment variable
MJCFFI_VIEWER_CLOSE_AFTER (seconds) closes the window after that long, through
GLFW's own close request, and prints the frame count: for tests and scripts.
"""

import argparse
import math
import os
import time

from .._cli import load_model
from ..data import MjData
from ._managed import Simulation, file_loader

CLOSE_AFTER = "MJCFFI_VIEWER_CLOSE_AFTER"


def _close_after(simulation, seconds):
    """Wrap the simulation's frame so that the window asks to close after `seconds`."""
    deadline = time.monotonic() + seconds
    frame = simulation.frame

    def timed_frame():
        if time.monotonic() > deadline and simulation.viewer.window is not None:
            simulation.viewer.window.request_close()
        frame()
    simulation.frame = timed_frame


def _close_after_seconds(parser):
    """MJCFFI_VIEWER_CLOSE_AFTER as seconds (0 or more), None if unset; else parser.error."""
    text = os.environ.get(CLOSE_AFTER)
    if not text:
        return None
    try:
        seconds = float(text)
    except ValueError:
        seconds = math.nan
    if not (math.isfinite(seconds) and seconds >= 0):
        parser.error(f"{CLOSE_AFTER} must be a number of seconds (0 or more), got {text!r}")
    return seconds


def _first_loaded(model, loader):
    """`loader`, except that its first call returns `model`, loaded already to check it."""
    first = [model]

    def load():
        if first:
            loaded = first.pop()
            return loaded, MjData(loaded)
        return loader()
    load.path = loader.path
    return load


def main(argv=None):
    """Run the viewer app until its window closes; a bad model or setting exits 2 first."""
    parser = argparse.ArgumentParser(prog="python -m mjcffi.viewer",
                                     description="The MuJoCo viewer (mjcffi).")
    parser.add_argument("--mjcf", help="an MJCF (.xml) or binary (.mjb) model file")
    args = parser.parse_args(argv)
    close_after = _close_after_seconds(parser)
    loader = None
    if args.mjcf:
        # loaded before any window opens, so that a bad file is one line on stderr
        path = os.path.expanduser(args.mjcf)
        try:
            model = load_model(path)
        except ValueError as error:
            parser.error(f"argument --mjcf: {error}")
        loader = _first_loaded(model, file_loader(path))
    simulation = Simulation(loader=loader)
    if close_after is not None:
        _close_after(simulation, close_after)
    simulation.run()
    if close_after is not None:
        meter = simulation.viewer.meter
        print(f"mjcffi.viewer: closed after {meter.frames} frames, "
              f"model time {simulation.data.time:.3f} s, nbody {simulation.model.nbody}")


if __name__ == "__main__":
    main()
