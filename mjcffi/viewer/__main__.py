"""`python -m mjcffi.viewer [--mjcf PATH]`: the standalone viewer.

With --mjcf it opens that model (ctrl+L reloads it); without, an empty window
that a model file can be dropped on.  The environment variable
MJCFFI_VIEWER_CLOSE_AFTER (seconds) closes the window after that long, through
GLFW's own close request, and prints the frame count: for tests and scripts.
MJCFFI_VIEWER_MIN_FRAMES (frames) holds that close until so many frames were drawn,
so that a test can count on frames however loaded the machine is.
"""

import argparse
import math
import os
import time

from .._cli import load_model
from ..data import MjData
from ._managed import Simulation, file_loader

CLOSE_AFTER = "MJCFFI_VIEWER_CLOSE_AFTER"
MIN_FRAMES = "MJCFFI_VIEWER_MIN_FRAMES"


def _close_after(simulation, seconds, min_frames=0):
    """Wrap the simulation's frame so that the window asks to close after `seconds`, and
    not before `min_frames` frames."""
    deadline = time.monotonic() + seconds
    frame = simulation.frame
    drawn = [0]

    def timed_frame():
        if time.monotonic() > deadline and drawn[0] >= min_frames and \
                simulation.viewer.window is not None:
            simulation.viewer.window.request_close()
        frame()
        drawn[0] += 1
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


def _min_frames(parser):
    """MJCFFI_VIEWER_MIN_FRAMES as a count (0 when unset); else parser.error."""
    text = os.environ.get(MIN_FRAMES) or "0"
    if not text.isdigit():
        parser.error(f"{MIN_FRAMES} must be a whole number of frames, got {text!r}")
    return int(text)


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
        _close_after(simulation, close_after, _min_frames(parser))
    simulation.run()
    if close_after is not None:
        meter = simulation.viewer.meter
        print(f"mjcffi.viewer: closed after {meter.frames} frames, "
              f"model time {simulation.data.time:.3f} s, nbody {simulation.model.nbody}")


if __name__ == "__main__":
    main()
