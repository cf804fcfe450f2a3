"""mujoco-py's `MjRenderPool`: one model rendered in many states by worker processes.

Each worker is a process of its own, started with multiprocessing's 'spawn'
method, holding an OpenGL context of MUJOCO_GL's backend, an MjSim on a copy
of the model (sent as MJB bytes) and an MjRenderContextOffscreen; with EGL,
worker k draws on EGL device `device_ids[k % len(device_ids)]`.  A batch of
states is dealt out in turn (state i to worker i mod n_workers), each worker
draws its share one after another, and writes each image into shared memory
at the state's place in the batch, so the batch comes back in the order of
the states and the same state always lands on the same worker.

The parent waits for the workers with a time limit and watches their
processes: a worker that dies or stops answering closes the pool with a
RuntimeError instead of a hang.  An exception raised inside a worker (a
MujocoException from `forward`, say) is raised again in the caller, with the
worker's traceback as its cause, and the pool stays usable.
"""

import inspect
import multiprocessing
import operator
import os
import pickle
import signal
import threading
import time
import traceback
from multiprocessing import connection as _connection

import numpy as np

from ._render_checks import MAX_BUFFER, camera_name as _camera_id
from ..rendering._sizes import pixels

_DEVICE_ENV = "MUJOCO_EGL_DEVICE_ID"
_SPAWN_HELP = ("MjRenderPool needs multiprocessing's 'spawn' start method (OpenGL contexts "
               "do not survive a fork). Put this at the top of the main script, before other "
               "imports set another method:\n"
               "    import multiprocessing\n"
               "    if __name__ == '__main__':\n"
               "        multiprocessing.set_start_method('spawn')")


class WorkerTraceback(Exception):
    """The traceback of an exception raised in a render pool worker (as text)."""


class MjRenderPool:
    """Render one model in a batch of states on a pool of worker processes.

    `MjRenderPool(model, device_ids=1, n_workers=None, max_batch_size=None,
    max_image_size=512*512, modder=None, timeout=60.0)`:

    - `model`: the SimModel (or mjcffi MjModel) to render; each worker gets a copy.
    - `device_ids`: EGL devices to draw on, a list of ints, or an int n for
      `[0, ..., n-1]`; ignored by OSMesa and GLFW, which have one device.
    - `n_workers`: worker processes per device (as mujoco-py counted them; default 1),
      so `len(device_ids) * n_workers` in all.
    - `max_batch_size`: the most states one `render` takes (default: the workers'
      number); `max_image_size`: the most pixels (width * height) of an image.
      Both size the shared memory the images come back through.
    - `modder`: a class such as TextureModder; each worker makes one,
      `modder(sim, random_state=k)` for worker k, and whitens the materials.
    - `timeout`: the seconds to wait for a worker to start or to draw a batch (the
      `timeout` attribute; it may be changed later).

    Requires the 'spawn' start method (RuntimeError otherwise).  `close()` stops the
    workers; a pool is also a context manager, and is closed when collected.
    """

    DEFAULT_MAX_IMAGE_SIZE = 512 * 512

    def __init__(self, model, device_ids=1, n_workers=None, max_batch_size=None,
                 max_image_size=DEFAULT_MAX_IMAGE_SIZE, modder=None, timeout=60.0):
        self._closed, self._workers = True, []
        self._lock = threading.Lock()       # one batch at a time: answers come in order
        _require_spawn()
        mjb = _model_bytes(model)
        device_ids = _device_ids(device_ids)
        per_device = 1 if n_workers is None else _positive(n_workers, "n_workers")
        if modder is not None and not inspect.isclass(modder):
            raise ValueError(f"modder must be a class (such as TextureModder), not "
                             f"{type(modder).__name__}")
        _picklable(modder)
        self._timeout = _seconds(timeout)
        self.model = model
        self.n_workers = len(device_ids) * per_device
        self._max_batch_size = (self.n_workers if max_batch_size is None
                                else _positive(max_batch_size, "max_batch_size"))
        self._max_image_size = _positive(max_image_size, "max_image_size")
        self._start(mjb, device_ids, modder)

    # ------------------------------------------------------------ set-up

    def _start(self, mjb, device_ids, modder):
        """Allocate the shared images, start the workers, and wait for them to be ready."""
        context = multiprocessing.get_context("spawn")
        pixels_max = self._max_image_size * self._max_batch_size
        self._shared_rgbs = context.RawArray("B", pixels_max * 3)
        self._shared_depths = context.RawArray("f", pixels_max)
        self._rgbs = np.frombuffer(self._shared_rgbs, dtype=np.uint8)
        self._depths = np.frombuffer(self._shared_depths, dtype=np.float32)
        self._closed = False
        try:
            for index in range(self.n_workers):
                ours, theirs = context.Pipe()
                process = context.Process(
                    target=_worker_main, name=f"MjRenderPool-{index}", daemon=True,
                    args=(index, theirs, mjb, device_ids[index % len(device_ids)],
                          self._shared_rgbs, self._shared_depths, modder))
                process.start()
                theirs.close()
                self._workers.append((process, ours))
            errors = self._collect(range(self.n_workers), "start")
            _raise_first(errors)
        except BaseException:
            self._stop()
            raise

    # ------------------------------------------------------------ rendering

    def render(self, width, height, states=None, camera_name=None, depth=False,
               randomize=False, copy=True):
        """Render a batch: one image per state of `states`, in their order.

        `states`: a sequence of MjSimState, each set in a worker's sim (and forwarded)
        before it draws; None renders `max_batch_size` images of the workers' sims as
        they stand.  `camera_name`: a camera of the model, or None for the render
        context's camera (at first a free camera looking at the model).  `randomize`:
        each worker calls its modder's `randomize()` before each image.

        Returns rgbs, an (n, height, width, 3) uint8 array, and with `depth` the pair
        (rgbs, depths), depths (n, height, width) float32 (OpenGL's depth buffer, as
        `MjSim.render` returns it).  Rows are in OpenGL's order, bottom row first, as
        `MjSim.render` gives them.  With `copy=False` the arrays are views of the
        shared memory, overwritten by the next `render`.
        """
        with self._lock:
            return self._render(width, height, states, camera_name, depth, randomize, copy)

    def _render(self, width, height, states, camera_name, depth, randomize, copy):
        if self._closed:
            raise RuntimeError("this MjRenderPool is closed")
        width = pixels(width, "width", MAX_BUFFER)
        height = pixels(height, "height", MAX_BUFFER)
        if width * height > self._max_image_size:
            raise ValueError(f"an image of {width}x{height} is more than max_image_size="
                             f"{self._max_image_size} pixels: make a pool with a larger "
                             f"max_image_size")
        _camera_id(self.model, camera_name)
        states = self._states(states)
        jobs = [[] for _ in self._workers]
        for slot, state in enumerate(states):
            jobs[slot % len(jobs)].append((slot, state))
        busy = [k for k, share in enumerate(jobs) if share]
        # pickled before any is sent: a state that cannot go fails before a worker starts
        messages = [_pickled(("render", jobs[k], width, height, camera_name, bool(depth),
                              bool(randomize))) for k in busy]
        errors = None
        try:
            for k, message in zip(busy, messages):
                self._send(k, message)
            errors = self._collect(busy, "render")
        finally:
            if errors is None and not self._closed:
                # interrupted (KeyboardInterrupt) with answers still owed: they would
                # be taken for the next batch's
                self._stop(polite=False)
        _raise_first(errors)
        return self._images(len(states), width, height, depth, copy)

    def _states(self, states):
        """The batch's states, checked; max_batch_size Nones for None."""
        from ._state import MjSimState
        if states is None:
            return [None] * self._max_batch_size
        try:
            states = list(states)
        except TypeError:
            raise TypeError(f"states must be a sequence of MjSimState, not "
                            f"{type(states).__name__}") from None
        if len(states) > self._max_batch_size:
            raise ValueError(f"{len(states)} states are more than max_batch_size="
                             f"{self._max_batch_size}: make a pool with a larger "
                             f"max_batch_size")
        shape = ((self.model.nq,), (self.model.nv,))
        for i, state in enumerate(states):
            if not isinstance(state, MjSimState):
                raise TypeError(f"states[{i}] must be an MjSimState, not "
                                f"{type(state).__name__}")
            if (np.shape(state.qpos), np.shape(state.qvel)) != shape:
                raise ValueError(f"states[{i}]: its qpos/qvel sizes do not match the model "
                                 f"(nq={self.model.nq}, nv={self.model.nv})")
        return states

    def _images(self, n, width, height, depth, copy):
        rgbs = self._rgbs[:n * height * width * 3].reshape(n, height, width, 3)
        rgbs = rgbs.copy() if copy else rgbs
        if not depth:
            return rgbs
        depths = self._depths[:n * height * width].reshape(n, height, width)
        return rgbs, (depths.copy() if copy else depths)

    # ------------------------------------------------------------ talking to workers

    def _send(self, index, message):
        process, conn = self._workers[index]
        try:
            conn.send_bytes(message)
        except (OSError, EOFError):
            process.join(1)
            self._broken(f"render pool worker {index} died (exit code {process.exitcode})")

    def _collect(self, indices, doing):
        """One answer from each worker of `indices`: {worker: error} of those that failed."""
        waiting = set(indices)
        errors = {}
        deadline = time.monotonic() + self._timeout
        while waiting:
            left = deadline - time.monotonic()
            watched = [self._workers[k][1] for k in waiting] + \
                [self._workers[k][0].sentinel for k in waiting]
            if left <= 0 or not _connection.wait(watched, timeout=left):
                self._broken(f"render pool workers {sorted(waiting)} did not {doing} within "
                             f"{self._timeout} s (timeout)")
            for k in sorted(waiting):
                process, conn = self._workers[k]
                if conn.poll():
                    try:
                        kind, payload = conn.recv()
                    except (OSError, EOFError):
                        kind, payload = "died", None
                elif not process.is_alive():
                    kind, payload = "died", None
                else:
                    continue
                if kind == "died":
                    process.join(1)
                    self._broken(f"render pool worker {k} died (exit code {process.exitcode}) "
                                 f"during {doing}")
                waiting.discard(k)
                if kind == "error":
                    errors[k] = payload
        return errors

    def _broken(self, message):
        """A worker died or hung: the pool cannot go on."""
        self._stop(polite=False)
        raise RuntimeError(message + "; the MjRenderPool is closed")

    # ------------------------------------------------------------ lifetime

    def close(self):
        """Stop the workers and free their OpenGL contexts; closing twice does nothing."""
        with self._lock:
            self._stop()

    def _stop(self, polite=True):
        """Ask the workers to finish (`polite`), then end those that do not in time."""
        self._closed = True
        workers, self._workers = self._workers, []
        for process, conn in workers:
            try:
                conn.send(("close",))
            except (OSError, EOFError, ValueError):
                pass
        deadline = time.monotonic() + (5.0 if polite else 0.0)
        for process, conn in workers:
            process.join(max(0.0, deadline - time.monotonic()))
            if process.is_alive():
                process.terminate()
                process.join(1.0)
            if process.is_alive():
                process.kill()
                process.join(1.0)
            conn.close()

    @property
    def closed(self):
        """Whether the pool was closed (by close(), or when a worker died or hung)."""
        return self._closed

    @property
    def timeout(self):
        """Seconds to wait for the workers to draw a batch before closing the pool."""
        return self._timeout

    @timeout.setter
    def timeout(self, value):
        self._timeout = _seconds(value)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        if getattr(self, "_workers", None):
            try:
                self._stop()
            except Exception:        # noqa: BLE001  (interpreter shutdown: nothing to tell)
                pass

    def __repr__(self):
        state = "closed" if self._closed else f"{self.n_workers} workers"
        return f"<MjRenderPool ({state})>"


# ---------------------------------------------------------------- checks


def _require_spawn():
    # the first of get_all_start_methods() is the default: asking it fixes nothing
    method = multiprocessing.get_start_method(allow_none=True) or \
        multiprocessing.get_all_start_methods()[0]
    if method != "spawn":
        raise RuntimeError(f"the multiprocessing start method is {method!r}. " + _SPAWN_HELP)


def _model_bytes(model):
    to_bytes = getattr(model, "to_bytes", None)
    if not callable(to_bytes) or not hasattr(model, "nq"):
        raise TypeError(f"model must be a SimModel (or mjcffi MjModel), not "
                        f"{type(model).__name__}")
    return to_bytes()


def _device_ids(value):
    if isinstance(value, (bool, np.bool_)):
        raise TypeError("device_ids must be an int or a list of ints, not bool")
    if hasattr(value, "__index__"):
        return list(range(_positive(value, "device_ids")))
    if not isinstance(value, (list, tuple)):
        raise TypeError(f"device_ids must be an int or a list of ints, not "
                        f"{type(value).__name__}")
    if not value:
        raise ValueError("device_ids must name at least one device")
    ids = []
    for item in value:
        if isinstance(item, (bool, np.bool_)) or not hasattr(item, "__index__"):
            raise TypeError(f"device_ids must hold ints, not {type(item).__name__}")
        if operator.index(item) < 0:
            raise ValueError(f"device ids must not be negative, not {operator.index(item)}")
        ids.append(operator.index(item))
    return ids


def _positive(value, name):
    if isinstance(value, (bool, np.bool_)) or not hasattr(value, "__index__"):
        raise TypeError(f"{name} must be an int, not {type(value).__name__}")
    value = operator.index(value)
    if value < 1:
        raise ValueError(f"{name} must be at least 1, not {value}")
    return value


def _seconds(value):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
        raise ValueError(f"timeout must be a positive number of seconds, not {value!r}")
    return float(value)


def _picklable(modder):
    """Workers get the modder class by reference: it must be importable by name."""
    if modder is None:
        return
    try:
        pickle.dumps(modder)
    except Exception:
        raise ValueError(f"modder {modder.__qualname__} cannot be sent to worker processes: "
                         f"define it at the top level of an importable module") from None


def _pickled(message):
    try:
        return pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception as error:
        raise TypeError(f"the states cannot be sent to the worker processes: {error} "
                        f"(a udd_state must pickle)") from None


def _raise_first(errors):
    """Raise the error of the first worker that failed (in the caller's process)."""
    if not errors:
        return
    index = min(errors)
    error, text = errors[index]
    if not isinstance(error, BaseException):
        error = RuntimeError(str(error))
    raise error from WorkerTraceback(f"in render pool worker {index}:\n{text}")


# ---------------------------------------------------------------- the worker process


class _Worker:
    """What one worker holds: its sim, its render context, its modder, the shared images."""

    def __init__(self, index, mjb, device, shared_rgbs, shared_depths, modder):
        from ._model import load_model_from_mjb
        from ._sim import MjSim
        from ._render_gl import context_class
        from ._render import MjRenderContextOffscreen
        device_id = -1
        if getattr(context_class(), "backend", "") == "egl":
            os.environ[_DEVICE_ENV] = str(device)    # this process's one EGL device
            device_id = device
        self.sim = MjSim(load_model_from_mjb(mjb))
        # the render context first: the modder uploads textures to it
        try:
            self.context = MjRenderContextOffscreen(self.sim, device_id=device_id)
        except (RuntimeError, ValueError) as error:
            if device_id < 0:
                raise
            raise ValueError(f"device_ids: worker {index} cannot draw on EGL device "
                             f"{device_id}: {error}") from None
        self.modder = None
        if modder is not None:
            self.modder = modder(self.sim, random_state=index)
            self.modder.whiten_materials()
        self.rgbs = np.frombuffer(shared_rgbs, dtype=np.uint8)
        self.depths = np.frombuffer(shared_depths, dtype=np.float32)

    def render(self, jobs, width, height, camera_name, depth, randomize):
        con = self.context.con
        if width > con.offWidth or height > con.offHeight:
            self.context.update_offscreen_size(max(width, con.offWidth),
                                               max(height, con.offHeight))
        size = width * height
        for slot, state in jobs:
            moved = state is not None
            if moved:
                self.sim.set_state(state)
            if randomize and self.modder is not None:
                self.modder.randomize()
                moved = True
            if moved:
                self.sim.forward()
            image = self.sim.render(width, height, camera_name=camera_name, depth=depth)
            rgb, depth_image = image if depth else (image, None)
            self.rgbs[slot * size * 3:(slot + 1) * size * 3] = rgb.reshape(-1)
            if depth:
                self.depths[slot * size:(slot + 1) * size] = depth_image.reshape(-1)

    def free(self):
        self.context.free()


def _worker_main(index, conn, mjb, device, shared_rgbs, shared_depths, modder):
    """A worker's life: set up, answer 'ready', then draw batches until told to close."""
    # Ctrl-C is the caller's to handle: it closes the pool (a worker ends on EOF too)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        worker = _Worker(index, mjb, device, shared_rgbs, shared_depths, modder)
    except BaseException as error:
        _answer_error(conn, error)
        return
    conn.send(("ready", None))
    try:
        while True:
            try:
                message = conn.recv()
            except (EOFError, OSError):      # the parent is gone
                return
            if message[0] == "close":
                return
            try:
                worker.render(*message[1:])
            except Exception as error:
                _answer_error(conn, error)
            else:
                conn.send(("ok", None))
    finally:
        worker.free()


def _answer_error(conn, error):
    text = "".join(traceback.format_exception(error))
    try:
        pickle.loads(pickle.dumps(error))
    except Exception:
        error = RuntimeError(f"{type(error).__name__}: {error}")
    try:
        conn.send(("error", (error, text)))
    except (OSError, EOFError):
        pass
