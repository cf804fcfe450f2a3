"""python -m mjcffi: simulate a scene with mjcffi and with the official bindings.

Steps the same model through both bindings in one process, on the same
libmujoco, with the same random controls, and prints steps per second for
each (medians of interleaved rounds) and whether the two trajectories are
bit-identical.  Exits 1 if they are not: any difference is a bug in mjcffi.
"""

import argparse
import statistics
import sys
import time

import numpy as np

import mjcffi
from mjcffi import scenes
from mjcffi._cli import load_model, positive_int

def _controls(nu, nstep, seed=0):
    return np.random.default_rng(seed).uniform(-1.0, 1.0, size=(nstep, nu))


def _trajectory(module, m, d, controls):
    """[qpos, qvel] after each step, through `module`'s public API alone."""
    module.mj_resetData(m, d)
    rows = []
    for row in controls:
        d.ctrl[:] = row
        module.mj_step(m, d)
        rows.append(np.concatenate([d.qpos, d.qvel]))
    return np.array(rows)


def _steps_per_second(module, m, d, nstep):
    step = module.mj_step
    start = time.perf_counter()
    for _ in range(nstep):
        step(m, d)
    return nstep / (time.perf_counter() - start)


def _load(module, path):
    """`module`'s MjModel of the file at `path` (as load_model reads it), or of the default."""
    if not path:
        return module.MjModel.from_xml_string(scenes.DEFAULT)
    if path.lower().endswith(".mjb"):
        return module.MjModel.from_binary_path(path)
    return module.MjModel.from_xml_path(path)


def main(argv=None):
    """Run the comparison; 0 if the trajectories are bit-identical, else 1 (2: bad input)."""
    parser = argparse.ArgumentParser(prog="python -m mjcffi", description=__doc__.splitlines()[0])
    parser.add_argument("--xml",
                        help="MJCF (or .mjb) file to simulate (default: the embedded scene)")
    parser.add_argument("--steps", type=positive_int, default=2000,
                        help="steps per timing round")
    parser.add_argument("--rounds", type=positive_int, default=7,
                        help="interleaved timing rounds")
    args = parser.parse_args(argv)
    try:
        ours = load_model(args.xml) if args.xml else _load(mjcffi, None)
    except ValueError as error:
        parser.error(f"argument --xml: {error}")

    import mujoco  # type: ignore[import-untyped]  # the official bindings (mujoco-core)

    theirs = _load(mujoco, args.xml)
    our_data, their_data = mjcffi.MjData(ours), mujoco.MjData(theirs)
    name = args.xml or "embedded default scene"
    print(f"mjcffi {mjcffi.__mjcffi_version__} on MuJoCo {mjcffi.__version__}: {name} "
          f"(nq={ours.nq}, nv={ours.nv}, nu={ours.nu})")

    controls = _controls(ours.nu, args.steps)
    a = _trajectory(mjcffi, ours, our_data, controls)
    b = _trajectory(mujoco, theirs, their_data, controls)
    identical = a.shape == b.shape and a.tobytes() == b.tobytes()

    mine, official = [], []
    for _ in range(args.rounds):
        mine.append(_steps_per_second(mjcffi, ours, our_data, args.steps))
        official.append(_steps_per_second(mujoco, theirs, their_data, args.steps))
    mine, official = statistics.median(mine), statistics.median(official)

    print(f"mj_step from a Python loop, steps/s, median of {args.rounds} interleaved rounds "
          f"of {args.steps}:")
    print(f"  mjcffi    {mine:12,.0f}")
    print(f"  official  {official:12,.0f}")
    print(f"  ratio     {mine / official:12.2f}x  (mjcffi / official)")
    if identical:
        print(f"trajectories: bit-identical over {args.steps} steps (qpos, qvel)")
        return 0
    diff = np.max(np.abs(a - b)) if a.shape == b.shape else float("nan")
    print(f"trajectories: DIFFER (max |difference| {diff:.3g}): this is a bug in mjcffi")
    return 1


if __name__ == "__main__":
    sys.exit(main())
