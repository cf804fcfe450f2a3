"""The text the viewer draws over the scene: the info block and the help block.

`Meter` measures frames per second and the ratio of simulated to real time over
the last second or so, from (wall time, simulation time) samples, one a frame.
"""

import collections
import time

HELP = (("Left drag", "rotate camera (shift: horizontal)"),
        ("Right drag", "pan camera (shift: horizontal)"),
        ("Scroll, middle drag", "zoom"),
        ("Double-click left", "select body"),
        ("Double-click right", "centre camera (ctrl: track body)"),
        ("Ctrl left / right drag", "rotate / push selected body"),
        ("[ ]", "previous / next camera"),
        ("Esc", "free camera"),
        ("Tab, shift+Tab", "left / right panel"),
        ("F1", "this help"),
        ("F2", "info"))
MANAGED_HELP = (("Space", "pause / run"),
                ("Backspace", "reset"),
                ("Right arrow", "step (paused; forward in history)"),
                ("Left arrow", "step back in history"),
                ("Ctrl+L", "reload model"))


def help_text(managed):
    rows = HELP + (MANAGED_HELP if managed else ())
    return "\n".join(k for k, _ in rows), "\n".join(v for _, v in rows)


class Meter:
    """Frames per second and simulated/real time over a sliding window of samples."""

    WINDOW = 1.0                  # seconds of samples kept

    def __init__(self):
        self._samples = collections.deque()
        self.frames = 0

    def tick(self, sim_time):
        now = time.monotonic()
        self.frames += 1
        self._samples.append((now, sim_time))
        while len(self._samples) > 2 and now - self._samples[0][0] > self.WINDOW:
            self._samples.popleft()

    def _span(self):
        if len(self._samples) < 2:
            return None
        (t0, s0), (t1, s1) = self._samples[0], self._samples[-1]
        return (t1 - t0, s1 - s0, len(self._samples) - 1) if t1 > t0 else None

    @property
    def fps(self):
        span = self._span()
        return span[2] / span[0] if span else 0.0

    @property
    def realtime(self):
        """Simulated seconds per real second (0 before two samples, or after a reset)."""
        span = self._span()
        return max(0.0, span[1] / span[0]) if span else 0.0


def info_text(sim_time, meter, paused=None, scrub=0):
    """The two columns of the info block; `scrub` < 0: that many states back in history."""
    names, values = ["Time", "FPS", "Sim/real"], [f"{sim_time:.3f}", f"{meter.fps:.0f}",
                                                 f"{meter.realtime:.2f}"]
    if paused is not None:
        names.append("State")
        values.append(("paused" if paused else "running") + (f" ({scrub})" if scrub else ""))
    return "\n".join(names), "\n".join(values)
