"""Frames per second of `Renderer.update_scene` + `render`, against the official Renderer.

Both bindings render gymnasium's humanoid in one process, on the same
libmujoco and the same EGL driver, interleaved round by round.  The official
Renderer makes its own EGL context where PyOpenGL is installed; where it is
not, it draws in an mjcffi EGL context (its only use of mjcffi).  MUJOCO_GL
is read when `mujoco` is imported, so the measurement runs in a child
interpreter started with MUJOCO_GL=egl.

A second section times mujoco-py's MjRenderPool (mjcffi.sim): a batch of
states of gymnasium's ant drawn by 1 and by 2 worker processes, against the
same states drawn one after another by `MjSim.render` in the calling process.

    python -m benchmarks.bench_render          # prints the tables
"""

import json
import os
import subprocess
import sys
import time

SIZES = ((320, 240), (640, 480))
MODES = ("rgb", "rgb+depth")


def _humanoid_path():
    import gymnasium
    return os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets",
                        "humanoid.xml")


def _gl_renderer():
    """OpenGL's renderer string (llvmpipe, a GPU) of the current EGL context."""
    from mjcffi.rendering import _egl
    address = _egl.lib.eglGetProcAddress(b"glGetString")
    if not address:
        return "unknown"
    get_string = _egl.ffi.cast("const char *(*)(unsigned int)", address)
    text = get_string(0x1F01)                   # GL_RENDERER
    return _egl.ffi.string(text).decode() if text else "unknown"


def _frames(renderer, data, mode, frames):
    """A callable timing `frames` frames; returns seconds per frame."""
    def run():
        start = time.perf_counter()
        for _ in range(frames):
            renderer.update_scene(data)
            renderer.render()
            if mode == "rgb+depth":
                renderer.enable_depth_rendering()
                renderer.render()
                renderer.disable_depth_rendering()
        return (time.perf_counter() - start) / frames
    return run


def measure(rounds, frames):
    """{'contexts', 'gl', 'rows': [[width, height, mode, mjcffi s, official s, same]]}."""
    import mujoco
    import numpy as np

    import mjcffi
    from benchmarks.common import interleaved
    try:
        import OpenGL  # noqa: F401
        contexts = "its own (PyOpenGL)"
    except ImportError:
        import mujoco.rendering.classic.gl_context as official_gl
        official_gl.GLContext = mjcffi.GLContext
        contexts = "mjcffi's"
    path = _humanoid_path()
    sides = {}
    for lib in (mjcffi, mujoco):
        m = lib.MjModel.from_xml_path(path)
        d = lib.MjData(m)
        d.qpos[:] = m.qpos0 + 0.05 * np.sin(np.arange(m.nq))
        lib.mj_forward(m, d)
        sides[lib.__name__] = (lib, m, d)
    rows, gl = [], None
    for width, height in SIZES:
        renderers = {name: lib.Renderer(m, height, width) for name, (lib, m, d) in sides.items()}
        try:
            frames_seen = []
            for name, renderer in renderers.items():
                renderer.update_scene(sides[name][2])
                frames_seen.append(renderer.render())
            same = bool(np.array_equal(*frames_seen))
            if gl is None:
                renderers["mjcffi"].render()         # its context current again
                gl = _gl_renderer()
            for mode in MODES:
                medians = interleaved(
                    {name: _frames(renderer, sides[name][2], mode, frames)
                     for name, renderer in renderers.items()}, rounds)
                rows.append([width, height, mode, medians["mjcffi"], medians["mujoco"], same])
        finally:
            for renderer in renderers.values():
                renderer.close()
    return {"contexts": contexts, "gl": gl, "rows": rows}


def _child(rounds, frames):
    print(json.dumps(measure(rounds, frames)))


POOL_SIZE = (160, 120)


POOL_MODEL = "inverted_pendulum.xml"


def _pool_model_path():
    return os.path.join(os.path.dirname(_humanoid_path()), POOL_MODEL)


def _pool_states(sim, batch):
    """`batch` states of `sim`'s model; the sim is left in its initial state."""
    import numpy as np
    states = []
    for k in range(batch):
        sim.data.qpos[:] = sim.model.qpos0 + 0.3 * np.sin(np.arange(sim.model.nq) + k)
        states.append(sim.get_state())
    sim.reset()
    return states


def _cpu_seconds(pids):
    """CPU seconds the processes `pids` have used (Linux /proc); None elsewhere."""
    total = 0.0
    try:
        for pid in pids:
            with open(f"/proc/{pid}/stat") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
            total += int(fields[11]) + int(fields[12])      # utime + stime, in ticks
    except OSError:
        return None
    return total / os.sysconf("SC_CLK_TCK")


def _timed(body, pids):
    """A callable running `body` once; it returns the seconds taken and appends to its
    `cores` list the CPU cores the processes `pids` used meanwhile (cpu / wall)."""
    def run():
        cpu, start = _cpu_seconds(pids), time.perf_counter()
        body()
        wall = time.perf_counter() - start
        after = _cpu_seconds(pids)
        if cpu is not None and after is not None:
            run.cores.append((after - cpu) / wall)
        return wall
    run.cores = []
    return run


def measure_pool(rounds, batch, repeats):
    """{'gl', 'batch', 'seconds': {label: median seconds per batch}, 'cores': {label:
    median CPU cores used, or None}, 'same'}: each sample times `repeats` batches.

    Needs the 'spawn' start method (set by _pool_child)."""
    import statistics

    import numpy as np

    from benchmarks.common import interleaved
    from mjcffi.sim.mjrenderpool import MjRenderPool
    from mjcffi.sim import MjSim, load_model_from_path
    width, height = POOL_SIZE
    sim = MjSim(load_model_from_path(_pool_model_path()))
    sim.render(width, height)        # the render context, made in the initial state as
    states = _pool_states(sim, batch)        # each worker's is: the same free camera

    def serial():
        for state in states:
            sim.set_state(state)
            sim.forward()
            sim.render(width, height)

    pools = {n: MjRenderPool(sim.model, n_workers=n, max_batch_size=batch) for n in (1, 2)}
    try:
        serial()                                    # warm
        with sim._render_context_offscreen.opengl_context.as_current():
            gl = _gl_renderer()
        first = pools[2].render(width, height, states=states)
        mine = []
        for state in states:
            sim.set_state(state)
            sim.forward()
            mine.append(sim.render(width, height))
        same = bool(np.array_equal(first, np.stack(mine)))
        bodies = {"serial": (serial, []),
                  **{f"pool{n}": (lambda pool=pool: pool.render(width, height, states=states),
                                  [process.pid for process, _ in pool._workers])
                     for n, pool in pools.items()}}
        runs = {label: _timed(lambda body=body: [body() for _ in range(repeats)],
                              pids or [os.getpid()])
                for label, (body, pids) in bodies.items()}
        seconds = {label: value / repeats
                   for label, value in interleaved(runs, rounds).items()}
        cores = {label: statistics.median(run.cores) if run.cores else None
                 for label, run in runs.items()}
    finally:
        for pool in pools.values():
            pool.close()
    return {"gl": gl, "batch": batch, "seconds": seconds, "cores": cores, "same": same}


def _pool_child(rounds, batch, repeats):
    import multiprocessing
    multiprocessing.set_start_method("spawn")
    print(json.dumps(measure_pool(rounds, batch, repeats)))


def _in_child(code):
    """Run `code` in a child interpreter with MUJOCO_GL=egl: (its JSON, None) or
    (None, the reason it failed)."""
    env = dict(os.environ, MUJOCO_GL="egl", PYOPENGL_PLATFORM="egl",
               PYTHONDONTWRITEBYTECODE="1")
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    done = subprocess.run([sys.executable, "-c", code], cwd=root, env=env,
                          capture_output=True, text=True, timeout=3600)
    if done.returncode != 0:
        return None, (done.stderr.strip().splitlines() or ["no output"])[-1]
    return json.loads(done.stdout.strip().splitlines()[-1]), None


def run(rounds=15, frames=3, pool_rounds=15, pool_batch=16, pool_repeats=10):
    """The RESULTS.md sections: measured in child interpreters with MUJOCO_GL=egl."""
    return _renderer_section(rounds, frames) + [""] + \
        _pool_section(pool_rounds, pool_batch, pool_repeats)


def _pool_section(rounds, batch, repeats):
    lines = ["## mujoco-py's render pool (`MjRenderPool`)", ""]
    found, failed = _in_child(f"from benchmarks.bench_render import _pool_child; "
                              f"_pool_child({rounds}, {batch}, {repeats})")
    if failed:
        return lines + [f"Not measured: the EGL child process failed ({failed}).", ""]
    width, height = POOL_SIZE
    seconds = found["seconds"]
    lines += [
        f"Frames per second rendering a batch of {batch} states of gymnasium's {POOL_MODEL[:-4]} at "
        f"{width}×{height} (free camera, rgb): `MjRenderPool.render(states=...)` with 1 and "
        f"2 worker processes (spawned, an EGL context each), against `MjSim.render` of the "
        f"same states one after another in the calling process (set_state + forward + "
        f"render). Median of {rounds} interleaved rounds of {repeats} batches, on OpenGL renderer "
        f"`{found['gl']}` and {os.cpu_count()} CPU cores. Speed-up is against 1 worker. "
        f"Target: 2 workers ≥ 1.6× 1 worker. Pooled images equal serial ones bit for bit: "
        f"{'yes' if found['same'] else 'NO'}. *CPU cores used*: CPU time of the rendering "
        f"processes (the workers, or the caller for serial) per wall-clock second, median: "
        f"what the machine gave them; the speed-up of more workers follows it.", "",
        "| renderer | frames/s | speed-up vs 1 worker | vs serial | CPU cores used |",
        "|---|---:|---:|---:|---:|"]
    names = (("serial", "`MjSim.render`, serial"), ("pool1", "`MjRenderPool`, 1 worker"),
             ("pool2", "`MjRenderPool`, 2 workers"))
    for key, name in names:
        cores = found["cores"][key]
        lines.append(f"| {name} | {batch / seconds[key]:.1f} | "
                     f"{seconds['pool1'] / seconds[key]:.2f}× | "
                     f"{seconds['serial'] / seconds[key]:.2f}× | "
                     f"{'n/a' if cores is None else f'{cores:.2f}'} |")
    return lines


def _renderer_section(rounds, frames):
    lines = ["## Offscreen rendering (`Renderer`)", ""]
    found, failed = _in_child(f"from benchmarks.bench_render import _child; "
                              f"_child({rounds}, {frames})")
    if failed:
        return lines + [f"Not measured: the EGL child process failed ({failed}).", ""]
    lines += [
        f"Frames per second of `renderer.update_scene(data)` + `renderer.render()` on "
        f"gymnasium's humanoid (free camera), median of {rounds} interleaved rounds of "
        f"{frames} frames; `rgb+depth` renders each frame twice, colour then depth. Both "
        f"bindings in one process with MUJOCO_GL=egl, on OpenGL renderer "
        f"`{found['gl']}`; the official Renderer used {found['contexts']} EGL contexts. "
        f"The ratio is time per frame, mjcffi / official. Target: ratio ≤ 1.0.", "",
        "| size | images | mjcffi frames/s | official frames/s | ratio | same pixels |",
        "|---|---|---:|---:|---:|---|"]
    for width, height, mode, ours, theirs, same in found["rows"]:
        lines.append(f"| {width}×{height} | {mode} | {1 / ours:.1f} | {1 / theirs:.1f} | "
                     f"{ours / theirs:.2f} | {'yes' if same else 'NO'} |")
    return lines


if __name__ == "__main__":
    print("\n".join(run()))
