"""Import time: `import mjcffi` against `import mujoco`, each in a fresh interpreter; and
first use, from `import mjcffi` to the first `mj_step`, with and without .pyc files.

    python -m benchmarks.bench_import            # print the section
    python -m benchmarks.bench_import --write    # also replace it in RESULTS.md
"""

import argparse
import os
import subprocess
import sys
import tempfile

from .common import interleaved, write_section

HEADING = "## Import time"
_PROBE = ("import time; t = time.perf_counter(); import {module}; "
          "print(time.perf_counter() - t)")
# import, load an empty model, make its data, step once: everything a first step needs
_FIRST_STEP = ("import time; t = time.perf_counter(); import {module} as mj; "
               "m = mj.MjModel.from_xml_string('<mujoco/>'); d = mj.MjData(m); "
               "mj.mj_step(m, d); print(time.perf_counter() - t)")


def _seconds(probe, module, env=None):
    def run():
        out = subprocess.run([sys.executable, "-c", probe.format(module=module)],
                             capture_output=True, text=True, check=True, env=env)
        return float(out.stdout)
    return run


def _no_pyc_env(empty):
    """Python reads no .pyc and writes none: its cache lives in an empty folder
    (PYTHONPYCACHEPREFIX), and PYTHONDONTWRITEBYTECODE keeps it empty, so every module,
    ours and the official's and numpy's, is compiled from source in every process."""
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1", PYTHONPYCACHEPREFIX=empty)
    return env


def run(rounds=15):
    medians = interleaved({"mjcffi": _seconds(_PROBE, "mjcffi"),
                           "official": _seconds(_PROBE, "mujoco")}, rounds)
    ours, theirs = medians["mjcffi"], medians["official"]
    with tempfile.TemporaryDirectory() as empty:
        env = _no_pyc_env(empty)
        first = interleaved({
            "mjcffi step": _seconds(_FIRST_STEP, "mjcffi", env),
            "official import": _seconds(_PROBE, "mujoco", env),
            "official step": _seconds(_FIRST_STEP, "mujoco", env)}, rounds)
        assert not os.listdir(empty), "a .pyc was written"
    warm = interleaved({"mjcffi step": _seconds(_FIRST_STEP, "mjcffi"),
                        "official step": _seconds(_FIRST_STEP, "mujoco")}, rounds)
    base = first["official import"]
    return [
        HEADING,
        "",
        f"`import X` timed inside a fresh interpreter (interpreter start-up excluded); "
        f"median of {rounds} interleaved runs each. Target: mjcffi at most 30 ms.",
        "",
        "| import | median ms | ratio to official |",
        "|---|---:|---:|",
        f"| `import mjcffi` | {ours * 1e3:.1f} | {ours / theirs:.2f} |",
        f"| `import mujoco` (official) | {theirs * 1e3:.1f} | 1.00 |",
        "",
        "First use: from the import to the end of the first `mj_step` on an empty model "
        "(load it, make its data, step), in a fresh interpreter, median of "
        f"{rounds} interleaved runs. Without .pyc files, as with `PYTHONDONTWRITEBYTECODE=1` "
        "or a read-only tree that was never compiled: the interpreter's cache points at an "
        "empty folder and nothing is written to it, so every module (ours, the "
        "official's, numpy's) is compiled from source in every process. mjcffi's function "
        "layer is one module per section of mujoco.h, compiled on first use of one of its "
        "names. Target: mjcffi's first step without .pyc at most the official's "
        "`import mujoco` in the same conditions.",
        "",
        "| first use | without .pyc, ms | ratio to official `import mujoco` | with .pyc, ms |",
        "|---|---:|---:|---:|",
        f"| mjcffi: import → first `mj_step` | {first['mjcffi step'] * 1e3:.0f} | "
        f"{first['mjcffi step'] / base:.2f} | {warm['mjcffi step'] * 1e3:.0f} |",
        f"| official: `import mujoco` | {base * 1e3:.0f} | 1.00 | {theirs * 1e3:.0f} |",
        f"| official: import → first `mj_step` | {first['official step'] * 1e3:.0f} | "
        f"{first['official step'] / base:.2f} | {warm['official step'] * 1e3:.0f} |",
    ]


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m benchmarks.bench_import",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help="write the section into "
                        "RESULTS.md")
    lines = run()
    print("\n".join(lines))
    if parser.parse_args(argv).write:
        print(f"wrote the section into {write_section(HEADING, lines)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
