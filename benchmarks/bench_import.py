"""Import time: `import mjcffi` against `import mujoco`, each in a fresh interpreter."""

import subprocess
import sys

from .common import interleaved

_PROBE = ("import time; t = time.perf_counter(); import {module}; "
          "print(time.perf_counter() - t)")


def _import_seconds(module):
    def run():
        out = subprocess.run([sys.executable, "-c", _PROBE.format(module=module)],
                             capture_output=True, text=True, check=True)
        return float(out.stdout)
    return run


def run(rounds=15):
    medians = interleaved({"mjcffi": _import_seconds("mjcffi"),
                           "official": _import_seconds("mujoco")}, rounds)
    ours, theirs = medians["mjcffi"], medians["official"]
    return [
        "## Import time",
        "",
        f"`import X` timed inside a fresh interpreter (interpreter start-up excluded); "
        f"median of {rounds} interleaved runs each. Target: mjcffi at most 30 ms.",
        "",
        "| import | median ms | ratio to official |",
        "|---|---:|---:|",
        f"| `import mjcffi` | {ours * 1e3:.1f} | {ours / theirs:.2f} |",
        f"| `import mujoco` (official) | {theirs * 1e3:.1f} | 1.00 |",
    ]
