"""python -m mjcffi: simulate a scene with mjcffi and with the official bindings.

Steps the same model through both bindings in one process, on the same
libmujoco, and prints steps per second for each (medians of interleaved
rounds) and whether the two trajectories are bit-identical.  Exits 1 if they
are not: any difference is a bug in mjcffi.
"""

import argparse
import statistics
import sys
import time

import numpy as np

from . import _loading, scenes
from ._library import ffi, lib


def _view(pointer, n):
    """A float64 NumPy view of n mjtNum at `pointer` (no copy)."""
    return np.frombuffer(ffi.buffer(pointer, 8 * n), dtype=np.float64)


def _controls(nu, nstep, seed=0):
    return np.random.default_rng(seed).uniform(-1.0, 1.0, size=(nstep, nu))


def _run_mjcffi(m, d, controls):
    ctrl, trajectory = _view(d.ctrl, m.nu), []
    lib.mj_resetData(m, d)
    for row in controls:
        ctrl[:] = row
        lib.mj_step(m, d)
        trajectory.append(np.concatenate([_view(d.qpos, m.nq), _view(d.qvel, m.nv)]))
    return np.array(trajectory)


def _run_official(mujoco, m, d, controls):
    trajectory = []
    mujoco.mj_resetData(m, d)
    for row in controls:
        d.ctrl[:] = row
        mujoco.mj_step(m, d)
        trajectory.append(np.concatenate([d.qpos, d.qvel]))
    return np.array(trajectory)


def _steps_per_second(step, nstep):
    start = time.perf_counter()
    for _ in range(nstep):
        step()
    return nstep / (time.perf_counter() - start)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m mjcffi", description=__doc__.splitlines()[0])
    parser.add_argument("--xml", help="MJCF file to simulate (default: the embedded scene)")
    parser.add_argument("--steps", type=int, default=2000, help="steps per timing round")
    parser.add_argument("--rounds", type=int, default=7, help="interleaved timing rounds")
    args = parser.parse_args(argv)
    if args.steps < 1 or args.rounds < 1:
        parser.error("--steps and --rounds must be positive")

    import mujoco   # the official bindings, from the same mujoco-core wheel

    if args.xml:
        try:
            ours = _loading.load_xml_path(args.xml)
        except ValueError as exc:
            parser.exit(2, f"python -m mjcffi: cannot load {args.xml}: {exc}\n")
        theirs, name = mujoco.MjModel.from_xml_path(args.xml), args.xml
    else:
        ours = _loading.load_xml_string(scenes.DEFAULT)
        theirs = mujoco.MjModel.from_xml_string(scenes.DEFAULT)
        name = "embedded default scene"
    our_data = ffi.gc(lib.mj_makeData(ours), lib.mj_deleteData)
    their_data = mujoco.MjData(theirs)

    print(f"mjcffi on MuJoCo {ffi.string(lib.mj_versionString()).decode()}: {name} "
          f"(nq={ours.nq}, nv={ours.nv}, nu={ours.nu})")

    controls = _controls(ours.nu, args.steps)
    a = _run_mjcffi(ours, our_data, controls)
    b = _run_official(mujoco, theirs, their_data, controls)
    identical = a.shape == b.shape and a.tobytes() == b.tobytes()

    mine, official = [], []
    for _ in range(args.rounds):
        mine.append(_steps_per_second(lambda: lib.mj_step(ours, our_data), args.steps))
        official.append(_steps_per_second(lambda: mujoco.mj_step(theirs, their_data), args.steps))
    mine, official = statistics.median(mine), statistics.median(official)

    print(f"steps/s, median of {args.rounds} interleaved rounds of {args.steps} steps:")
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
