"""Frames per second of `Renderer.update_scene` + `render`, against the official Renderer.

Both bindings render gymnasium's humanoid in one process, on the same
libmujoco and the same EGL driver, interleaved round by round.  The official
Renderer makes its own EGL context where PyOpenGL is installed; where it is
not, it draws in an mjcffi EGL context (its only use of mjcffi).  MUJOCO_GL
is read when `mujoco` is imported, so the measurement runs in a child
interpreter started with MUJOCO_GL=egl.

    python -m benchmarks.bench_render          # prints the table
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


def run(rounds=15, frames=3):
    """The RESULTS.md section: measured in a child interpreter with MUJOCO_GL=egl."""
    env = dict(os.environ, MUJOCO_GL="egl", PYOPENGL_PLATFORM="egl",
               PYTHONDONTWRITEBYTECODE="1")
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    code = f"from benchmarks.bench_render import _child; _child({rounds}, {frames})"
    done = subprocess.run([sys.executable, "-c", code], cwd=root, env=env,
                          capture_output=True, text=True, timeout=3600)
    lines = ["## Offscreen rendering (`Renderer`)", ""]
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["no output"])[-1]
        return lines + [f"Not measured: the EGL child process failed ({last}).", ""]
    found = json.loads(done.stdout.strip().splitlines()[-1])
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
