"""MjRenderPool (mujoco-py's render pool): batches drawn by worker processes.

Each scenario runs in a fresh interpreter per backend (one GL backend per
process) that sets multiprocessing's 'spawn' start method, as the pool needs,
and prints one JSON line of what it saw; the assertions are here.  The
reference for every pooled image is `MjSim.render` of the same state in the
scenario's own process, on the same backend: the pool must match it bit for
bit.  The model is gymnasium's ant (a textured floor, a skybox and a camera).
"""

import functools
import os

import pytest
from tests import _gl
from tests._gl import outcome as _outcome, skip_reason as _skip_reason

BACKENDS = ("egl", "osmesa")
W, H = 160, 120
TIMEOUT = 600


def _ant():
    import gymnasium
    return os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets",
                        "ant.xml")


@functools.lru_cache(maxsize=None)
def _cached(backend, scenario):
    return _gl.run("tests.test_render_pool", backend, scenario, timeout=TIMEOUT)


@pytest.fixture(params=BACKENDS)
def backend(request):
    reason = _skip_reason(request.param)
    if reason:
        pytest.skip(reason)
    return request.param


# ------------------------------------------------------------ helpers of the scenarios

def _spawn():
    import multiprocessing
    multiprocessing.set_start_method("spawn")


def _sim_and_states(n):
    """A sim on the ant with its render context made in the initial state (as each
    worker's is), and n distinct states of it."""
    import numpy as np
    from mjcffi.sim import MjRenderContextOffscreen, MjSim, load_model_from_path
    sim = MjSim(load_model_from_path(_ant()))
    MjRenderContextOffscreen(sim)
    states = []
    for k in range(n):
        sim.data.qpos[:] = sim.model.qpos0 + 0.15 * (k + 1) * np.sin(np.arange(sim.model.nq) + k)
        sim.data.qvel[:] = 0.01 * k
        states.append(sim.get_state())
    sim.reset()
    return sim, states


def _single(sim, states, width=W, height=H, **kwargs):
    """sim.render of each state in turn, in this process."""
    images = []
    for state in states:
        sim.set_state(state)
        sim.forward()
        images.append(sim.render(width, height, **kwargs))
    return images


def _print(result):
    import json
    print(json.dumps(result))


def _equal(a, b):
    import numpy as np
    return bool(np.array_equal(a, b))


class FailingModder:
    """A modder whose randomize raises: an error inside a worker."""

    def __init__(self, sim, random_state=None):
        self.sim = sim

    def whiten_materials(self):
        pass

    def randomize(self):
        raise KeyError("randomize failed on purpose")


class SlowModder(FailingModder):
    """A modder whose randomize outlasts the pool's timeout: a hung worker."""

    def randomize(self):
        import time
        time.sleep(30)


class NapModder(FailingModder):
    """A modder whose randomize takes a few seconds: a batch to interrupt."""

    def randomize(self):
        import time
        time.sleep(3)


class BrokenModder(FailingModder):
    """A modder that cannot be made: a worker that fails to start."""

    def __init__(self, sim, random_state=None):
        raise ArithmeticError("no modder here")


# ------------------------------------------------------------ scenarios

def images_scenario():
    """Pooled images against single renders: states, order, depth, camera, views."""
    import numpy as np
    from mjcffi.sim.mjrenderpool import MjRenderPool
    _spawn()
    sim, states = _sim_and_states(5)
    out = {}
    with MjRenderPool(sim.model, n_workers=2, max_batch_size=5) as pool:
        rgbs, depths = pool.render(W, H, states=states, depth=True)
        reference = _single(sim, states, depth=True)
        out["shapes"] = [list(rgbs.shape), str(rgbs.dtype), list(depths.shape),
                         str(depths.dtype)]
        out["rgb_equal"] = [_equal(rgbs[i], reference[i][0]) for i in range(5)]
        out["depth_equal"] = [_equal(depths[i], reference[i][1]) for i in range(5)]
        out["distinct"] = len({rgbs[i].tobytes() for i in range(5)})
        out["std"] = float(rgbs.std())
        out["depth_range"] = [float(depths.min()), float(depths.max())]

        backwards = pool.render(W, H, states=states[::-1])
        out["reversed_equal"] = [_equal(backwards[i], reference[4 - i][0]) for i in range(5)]

        two = pool.render(W, H, states=states[1:3])
        out["two"] = [list(two.shape), _equal(two[0], reference[1][0]),
                      _equal(two[1], reference[2][0])]

        # no states: each worker draws its sim as it stands (worker 0: slots 0, 2, 4)
        stand = pool.render(W, H)
        out["stand"] = [list(stand.shape), _equal(stand[0], stand[2]),
                        _equal(stand[0], stand[4])]

        small = pool.render(37, 23, states=states[:3])
        ref_small = _single(sim, states[:3], 37, 23)
        out["odd_size"] = [list(small.shape)] + [_equal(small[i], ref_small[i])
                                                 for i in range(3)]

        view1 = pool.render(W, H, states=states[:2], copy=False)
        kept = view1.copy()
        view2 = pool.render(W, H, states=states[2:4], copy=False)
        out["views"] = [bool(np.shares_memory(view1, view2)), _equal(view1, view2),
                        _equal(kept, view2)]

        # a named camera last: it stays the render context's camera afterwards
        tracked = pool.render(W, H, states=states, camera_name="track")
        ref_tracked = _single(sim, states, camera_name="track")
        out["camera_equal"] = [_equal(tracked[i], ref_tracked[i]) for i in range(5)]
        out["camera_differs"] = not _equal(tracked[0], rgbs[0])

        # wider than the model's offscreen buffer (640): the workers grow theirs
        wide = pool.render(700, 50, states=states[:1])
        sim._render_context_offscreen.update_offscreen_size(700, 480)
        out["wide"] = [list(wide.shape), _equal(wide[0], _single(sim, states[:1], 700, 50,
                                                                 camera_name="track")[0])]
    _print(out)


def modder_scenario():
    """randomize=True: each worker's TextureModder (random_state = its index)."""
    from mjcffi.sim.mjrenderpool import MjRenderPool
    from mjcffi.sim import TextureModder
    _spawn()
    sim, states = _sim_and_states(2)
    out = {}
    with MjRenderPool(sim.model, n_workers=2, modder=TextureModder) as pool:
        first = pool.render(W, H, states=states, randomize=True)
        again = pool.render(W, H, states=states, randomize=False)
        second = pool.render(W, H, states=states, randomize=True)
    out["kept"] = [_equal(first[i], again[i]) for i in range(2)]
    out["changed"] = [not _equal(first[i], second[i]) for i in range(2)]
    plain = _single(sim, states)
    out["differs_from_plain"] = [not _equal(first[i], plain[i]) for i in range(2)]
    # the same modder in this process, as worker 0 made and used it
    modder = TextureModder(sim, random_state=0)
    modder.whiten_materials()
    sim.set_state(states[0])
    modder.randomize()
    sim.forward()
    out["as_worker_0"] = _equal(first[0], sim.render(W, H))
    _print(out)


def lifetime_scenario():
    """Create, close, delete, context manager; dead and hung workers; worker errors."""
    import gc
    import multiprocessing
    import os
    import signal
    from mjcffi.sim.mjrenderpool import MjRenderPool
    _spawn()
    sim, states = _sim_and_states(2)
    model = sim.model
    out = {}

    pool = MjRenderPool(model, n_workers=2)
    pids = [process.pid for process, _ in pool._workers]
    out["workers"] = len(pids)
    del pool
    gc.collect()
    out["deleted_gone"] = not multiprocessing.active_children()

    pool = MjRenderPool(model, n_workers=2)
    pool.close()
    pool.close()
    out["closed_gone"] = not multiprocessing.active_children()
    out["closed_render"] = _outcome(lambda: pool.render(W, H))
    del pool

    with MjRenderPool(model) as pool:
        out["with_shape"] = list(pool.render(W, H).shape)
    out["with_closed"] = pool.closed and not multiprocessing.active_children()

    # an exception inside a worker comes back as itself; the pool goes on
    pool = MjRenderPool(model, n_workers=2, modder=FailingModder)
    out["worker_error"] = _outcome(lambda: pool.render(W, H, states=states, randomize=True))
    try:
        pool.render(W, H, randomize=True)
    except KeyError as error:
        out["worker_traceback"] = "randomize failed on purpose" in str(error.__cause__)
    out["after_error"] = _equal(pool.render(W, H, states=states[:1])[0],
                                _single(sim, states[:1])[0])
    pool.close()

    # a worker killed: a RuntimeError, not a hang, and the pool closes
    pool = MjRenderPool(model, n_workers=2)
    os.kill(pool._workers[1][0].pid, signal.SIGKILL)
    out["killed"] = _outcome(lambda: pool.render(W, H, states=states))
    out["killed_closed"] = pool.closed and not multiprocessing.active_children()

    # a worker that does not answer in time
    pool = MjRenderPool(model, n_workers=1, modder=SlowModder)
    pool.timeout = 2
    out["hung"] = _outcome(lambda: pool.render(W, H, randomize=True))
    out["hung_closed"] = pool.closed and not multiprocessing.active_children()

    # Ctrl-C in the caller mid-batch: the answers still owed would be taken for the next
    # batch's, so the pool closes; a SIGINT to the workers themselves is ignored
    pool = MjRenderPool(model, n_workers=2, modder=NapModder)
    for process, _ in pool._workers:
        os.kill(process.pid, signal.SIGINT)
    out["sigint_ignored"] = _equal(pool.render(W, H, states=states[:1])[0],
                                   _single(sim, states[:1])[0])

    def interrupt(*_):
        raise KeyboardInterrupt

    signal.signal(signal.SIGALRM, interrupt)
    signal.setitimer(signal.ITIMER_REAL, 1.0)
    out["interrupted"] = "ok"
    try:
        pool.render(W, H, randomize=True)
    except KeyboardInterrupt:
        out["interrupted"] = "KeyboardInterrupt"
    out["interrupted_closed"] = pool.closed and not multiprocessing.active_children()

    # a worker that cannot start
    out["start_error"] = _outcome(lambda: MjRenderPool(model, modder=BrokenModder))
    out["start_error_gone"] = not multiprocessing.active_children()
    out["bad_device"] = _outcome(lambda: MjRenderPool(model, device_ids=[0, 99]))
    out["bad_device_gone"] = not multiprocessing.active_children()

    # a script that never closes its pool still exits, quietly
    import subprocess
    import sys
    code = ("import multiprocessing\n"
            "if __name__ == '__main__':\n"
            "    multiprocessing.set_start_method('spawn')\n"
            "    from tests.test_render_pool import _sim_and_states\n"
            "    from mjcffi.sim.mjrenderpool import MjRenderPool\n"
            "    sim, states = _sim_and_states(2)\n"
            "    pool = MjRenderPool(sim.model, n_workers=2)\n"
            "    print(pool.render(16, 12, states=states).shape)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    out["unclosed_exit"] = [done.returncode, done.stdout.strip(), done.stderr.strip()]
    _print(out)


def bad_input_scenario():
    """Every refusal of the constructor and of render, by its message."""
    import numpy as np
    from mjcffi.sim.mjrenderpool import MjRenderPool
    from mjcffi.sim import MjSim, MjSimState, TextureModder, load_model_from_xml
    _spawn()
    sim, states = _sim_and_states(1)
    model = sim.model
    out = {}
    for name, kwargs in {
            "model": dict(model="ant"),
            "device_zero": dict(device_ids=0), "device_empty": dict(device_ids=[]),
            "device_str": dict(device_ids=["0"]), "device_negative": dict(device_ids=[-1]),
            "device_float": dict(device_ids=1.0),
            "workers_zero": dict(n_workers=0), "workers_float": dict(n_workers=1.5),
            "batch_zero": dict(max_batch_size=0), "image_zero": dict(max_image_size=0),
            "modder_instance": dict(modder=TextureModder(sim)),
            "modder_local": dict(modder=type("Local", (TextureModder,), {})),
            "timeout": dict(timeout=0), "timeout_str": dict(timeout="5")}.items():
        kwargs.setdefault("model", model)
        out[name] = _outcome(lambda: MjRenderPool(**kwargs))

    other = MjSim(load_model_from_xml(
        "<mujoco><worldbody><body><freejoint/><geom size='.1'/></body></worldbody></mujoco>"))
    with MjRenderPool(model, n_workers=1, max_batch_size=2, max_image_size=W * H) as pool:
        for name, call in {
                "width_zero": lambda: pool.render(0, H),
                "width_str": lambda: pool.render("160", H),
                "too_big": lambda: pool.render(W + 1, H),
                "too_many": lambda: pool.render(W, H, states=states * 3),
                "states_int": lambda: pool.render(W, H, states=3),
                "states_items": lambda: pool.render(W, H, states=[1]),
                "states_other_model": lambda: pool.render(W, H, states=[other.get_state()]),
                "state_short": lambda: pool.render(W, H, states=[MjSimState(
                    0.0, np.zeros(2), np.zeros(2), None, {})]),
                "camera_unknown": lambda: pool.render(W, H, camera_name="nope"),
                "camera_int": lambda: pool.render(W, H, camera_name=0),
                "udd_unpicklable": lambda: pool.render(W, H, states=[states[0]._replace(
                    udd_state={"f": lambda: 0})])}.items():
            out[name] = _outcome(call)
        # refusals leave the pool working
        out["still_works"] = _equal(pool.render(W, H, states=states)[0],
                                    _single(sim, states)[0])
    _print(out)


def spawn_scenario():
    """Start methods other than 'spawn' are refused, and asking fixes no method."""
    import multiprocessing
    from mjcffi.sim.mjrenderpool import MjRenderPool
    from mjcffi.sim import load_model_from_path
    model = load_model_from_path(_ant())
    out = {"default": _outcome(lambda: MjRenderPool(model)),
           "still_unset": multiprocessing.get_start_method(allow_none=True) is None}
    for method in ("fork", "forkserver"):
        multiprocessing.set_start_method(method, force=True)
        out[method] = _outcome(lambda: MjRenderPool(model, n_workers=2))
    out["children"] = len(multiprocessing.active_children())
    _print(out)


# ------------------------------------------------------------ the tests

def test_images_equal_single_renders(backend):
    out = _cached(backend, "images_scenario")
    assert out["shapes"] == [[5, H, W, 3], "uint8", [5, H, W], "float32"]
    assert out["rgb_equal"] == [True] * 5
    assert out["distinct"] == 5          # the states look different: order is visible
    assert out["std"] > 5                # a picture, not a blank
    assert out["two"] == [[2, H, W, 3], True, True]
    assert out["odd_size"] == [[3, 23, 37, 3], True, True, True]


def test_states_order(backend):
    out = _cached(backend, "images_scenario")
    assert out["reversed_equal"] == [True] * 5
    assert out["stand"] == [[5, H, W, 3], True, True]


def test_depth(backend):
    out = _cached(backend, "images_scenario")
    assert out["depth_equal"] == [True] * 5
    low, high = out["depth_range"]
    assert 0 <= low < high <= 1


def test_camera_name(backend):
    out = _cached(backend, "images_scenario")
    assert out["camera_equal"] == [True] * 5
    assert out["camera_differs"]


def test_larger_than_offscreen_buffer(backend):
    out = _cached(backend, "images_scenario")
    assert out["wide"] == [[1, 50, 700, 3], True]


def test_copy_false_gives_views_of_shared_memory(backend):
    out = _cached(backend, "images_scenario")
    shared, same_after, kept_is_second = out["views"]
    assert shared and same_after and not kept_is_second


def test_modder_randomize(backend):
    out = _cached(backend, "modder_scenario")
    assert out["kept"] == [True, True]
    assert out["changed"] == [True, True]
    assert out["differs_from_plain"] == [True, True]
    assert out["as_worker_0"]


def test_create_close_delete():
    out = _cached("egl", "lifetime_scenario")
    assert out["workers"] == 2
    assert out["deleted_gone"] and out["closed_gone"] and out["with_closed"]
    assert out["closed_render"] == "RuntimeError: this MjRenderPool is closed"
    assert out["with_shape"] == [1, H, W, 3]
    assert out["unclosed_exit"] == [0, "(2, 12, 16, 3)", ""]


def test_worker_errors():
    out = _cached("egl", "lifetime_scenario")
    assert out["worker_error"] == "KeyError: 'randomize failed on purpose'"
    assert out["worker_traceback"] and out["after_error"]
    assert out["killed"].startswith("RuntimeError: render pool worker 1 died")
    assert out["killed_closed"]
    assert out["hung"].startswith("RuntimeError: render pool workers [0] did not render")
    assert "timeout" in out["hung"] and out["hung_closed"]
    assert out["start_error"] == "ArithmeticError: no modder here"
    assert out["start_error_gone"]
    assert out["bad_device"].startswith("ValueError: device_ids: worker 1 cannot draw on "
                                        "EGL device 99")
    assert out["bad_device_gone"]
    assert out["sigint_ignored"]
    assert out["interrupted"] == "KeyboardInterrupt" and out["interrupted_closed"]


def test_spawn_required():
    out = _cached("egl", "spawn_scenario")
    for method in ("default", "fork", "forkserver"):
        assert out[method].startswith("RuntimeError: the multiprocessing start method is")
        assert "set_start_method('spawn')" in out[method]
    assert out["still_unset"]
    assert out["children"] == 0


BAD = {
    "model": "TypeError: model must be a SimModel",
    "device_zero": "ValueError: device_ids must be at least 1",
    "device_empty": "ValueError: device_ids must name at least one device",
    "device_str": "TypeError: device_ids must hold ints",
    "device_negative": "ValueError: device ids must not be negative",
    "device_float": "TypeError: device_ids must be an int or a list of ints",
    "workers_zero": "ValueError: n_workers must be at least 1",
    "workers_float": "TypeError: n_workers must be an int",
    "batch_zero": "ValueError: max_batch_size must be at least 1",
    "image_zero": "ValueError: max_image_size must be at least 1",
    "modder_instance": "ValueError: modder must be a class",
    "modder_local": "ValueError: modder Local cannot be sent to worker processes",
    "timeout": "ValueError: timeout must be a positive number",
    "timeout_str": "ValueError: timeout must be a positive number",
    "width_zero": "ValueError: width must be a positive number of pixels",
    "width_str": "TypeError: width must be an int",
    "too_big": "ValueError: an image of 161x120 is more than max_image_size",
    "too_many": "ValueError: 3 states are more than max_batch_size=2",
    "states_int": "TypeError: states must be a sequence of MjSimState",
    "states_items": "TypeError: states[0] must be an MjSimState",
    "states_other_model": "ValueError: states[0]: its qpos/qvel sizes do not match",
    "state_short": "ValueError: states[0]: its qpos/qvel sizes do not match",
    "camera_unknown": "ValueError: unknown camera name 'nope'",
    "camera_int": "TypeError: camera_name must be a str or None",
    "udd_unpicklable": "TypeError: the states cannot be sent to the worker processes",
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_input(name):
    out = _cached("egl", "bad_input_scenario")
    assert out[name].startswith(BAD[name]), out[name]
    assert out["still_works"]
