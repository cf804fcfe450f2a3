"""`python -m mjcffi.viewer [--mjcf PATH]`: the standalone viewer.

With --mjcf it opens that model (ctrl+L reloads it); without, an empty window
that a model file can be dropped on.  The environment variable
MJCFFI_VIEWER_CLOSE_AFTER (seconds) closes the window after that long, through
GLFW's own close request, and prints the frame count: for tests and scripts.
"""

import argparse
import os
import time

from ._managed import Simulation, file_loader


def _close_after(simulation, seconds):
    """Wrap the simulation's frame so that the window asks to close after `seconds`."""
    deadline = time.monotonic() + seconds
    frame = simulation.frame

    def timed_frame():
        if time.monotonic() > deadline and simulation.viewer.window is not None:
            simulation.viewer.window.request_close()
        frame()
    simulation.frame = timed_frame


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m mjcffi.viewer",
                                     description="The MuJoCo viewer (mjcffi).")
    parser.add_argument("--mjcf", help="an MJCF (.xml) or binary (.mjb) model file")
    args = parser.parse_args(argv)
    loader = file_loader(os.path.expanduser(args.mjcf)) if args.mjcf else None
    simulation = Simulation(loader=loader)
    close_after = os.environ.get("MJCFFI_VIEWER_CLOSE_AFTER")
    if close_after:
        _close_after(simulation, float(close_after))
    simulation.run()
    if close_after:
        meter = simulation.viewer.meter
        print(f"mjcffi.viewer: closed after {meter.frames} frames, "
              f"model time {simulation.data.time:.3f} s, nbody {simulation.model.nbody}")


if __name__ == "__main__":
    main()
