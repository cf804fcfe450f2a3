"""RolloutCluster: persistent Ray actors that share out the rollouts of a call."""

import collections
import math

import numpy as np

from .._support import progress as _progress
from .. import rollout as _rollout
from .._support.errors import FatalError
from ..data import MjData
from ._models import Store
from ._ray import connect
from ._request import check
from ._worker import Worker

_CTRL = _rollout._CTRL
MAX_ATTEMPTS = 3          # tries of one shard on workers that die under it


def positive_count(value, name):
    """`value` as an int of at least 1 (None stays None): TypeError or ValueError naming it."""
    if value is None:
        return None
    value = _rollout._integer(value, name, TypeError)
    if value < 1:
        raise ValueError(f"{name} must be positive, got {value}")
    return value


class RolloutCluster:
    """Rollout workers (Ray actors), kept between calls; a drop-in for a local `Rollout`.

    `RolloutCluster(num_workers=n)` starts n actors (default: one per node of the Ray
    cluster, connecting to it with ray.init() if this process is not connected yet).
    Each runs mjcffi's C rollout pool on its share of its node's cores (`nthread`, if
    given, for every worker), keeps the models it was sent and its MjData between calls.
    Use it as a context manager, or call `close()`.

    `rollout` splits a call's rollouts into shards, one per worker unless `shard_size` is
    given, and hands them to idle workers; a worker that dies under a shard is replaced
    and the shard run again.  Results are those of a local `mjcffi.rollout.rollout`, bit
    for bit.  Python callbacks (mjcb_*) set in this process do not reach the workers.
    """

    def __init__(self, num_workers=None, *, nthread=None):
        """Start `num_workers` actors (default: one per alive node) of `nthread` threads
        each (default: the node's CPUs shared among the workers on it)."""
        num_workers = positive_count(num_workers, "num_workers")
        nthread = positive_count(nthread, "nthread")
        self._ray = ray = connect()
        # no CPU is held for the life of an actor: tasks (accuracy --ray) still get the CPUs
        self._actor = ray.remote(num_cpus=0, max_restarts=0, max_task_retries=0)(Worker)
        self._store = Store(ray)
        self._nthread = nthread
        self._nodes = {}            # actor -> node id
        self._threads = {}          # actor -> threads it rolls out on
        self._session = ray.get_runtime_context().get_job_id()
        count = num_workers or max(1, sum(1 for n in ray.nodes() if n.get("Alive")))
        self._workers = [self._actor.options(scheduling_strategy="SPREAD").remote()
                         for _ in range(count)]
        self._place(self._workers)
        self._open = True

    # ------------------------------------------------------------ workers

    @property
    def workers(self):
        """The live actors' handles (a copy of the list)."""
        return list(self._workers)

    @property
    def num_workers(self):
        return len(self._workers)

    def threads(self):
        """Threads each worker rolls out on, in the order of `workers`."""
        return [self._threads[w] for w in self._workers]

    def _place(self, actors):
        """Learn where `actors` run and give each its share of its node's CPUs."""
        ray = self._ray
        for actor, (node, _pid) in zip(actors, ray.get([a.where.remote() for a in actors])):
            self._nodes[actor] = node
        cpus = {n["NodeID"]: n.get("Resources", {}).get("CPU", 1) for n in ray.nodes()}
        peers = collections.Counter(self._nodes[w] for w in self._workers)
        share = {a: self._nthread or max(1, int(cpus.get(self._nodes[a], 1))
                                        // peers[self._nodes[a]]) for a in actors}
        done = ray.get([a.configure.remote(share[a]) for a in actors])
        self._threads.update(zip(actors, done))

    def _replace(self, actor):
        """Drop a dead actor; start and place another in its stead; return it."""
        self._ray.kill(actor, no_restart=True)
        index = self._workers.index(actor)
        self._nodes.pop(actor, None)
        self._threads.pop(actor, None)
        fresh = self._actor.options(scheduling_strategy="SPREAD").remote()
        self._workers[index] = fresh
        self._place([fresh])
        return fresh

    def close(self):
        """End the actors (their models and MjData go with them)."""
        if getattr(self, "_open", False):
            self._open = False
            if self._ray.is_initialized():
                for actor in self._workers:
                    self._ray.kill(actor, no_restart=True)
            self._workers = []

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc_val, exc_tb):
        self.close()

    @property
    def alive(self):
        """Open, and its Ray session is the one this process is connected to."""
        ray = self._ray
        return (self._open and ray.is_initialized()
                and ray.get_runtime_context().get_job_id() == self._session)

    # ------------------------------------------------------------ rollout

    def rollout(self, model, initial_state, control=None, *more, data=None,
                control_spec=_CTRL, skip_checks=False, nstep=None, initial_warmstart=None,
                state=None, sensordata=None, chunk_size=None, shard_size=None,
                progress=False):
        """Roll out open-loop trajectories on the workers; the states and sensor values.

        The arguments are those of `mjcffi.rollout.rollout` without `data` (workers
        own their MjData); the local call shape `rollout(model, data, initial_state,
        control, ...)` is accepted too and its `data` ignored, so this object can stand in
        for a local `Rollout`.  `control_spec`, `skip_checks`, `nstep`, `initial_warmstart`,
        `state`, `sensordata` and `chunk_size` are as in `mjcffi.rollout.rollout`
        (`chunk_size` within a worker).

        Args:
          model: an MjModel, or a sequence of nbatch MjModels of the same sizes.
          initial_state: ([nbatch or 1] x nstate) mjSTATE_FULLPHYSICS states.
          control: ([nbatch or 1] x [nstep or 1] x ncontrol); optional.
          shard_size: rollouts per shard (default: nbatch shared evenly among workers).
          progress: show a tqdm bar of shards done (when tqdm is installed).

        Returns:
          (state, sensordata): (nbatch x nstep x nstate) and (nbatch x nstep x nsensordata).

        Raises:
          ValueError, TypeError: bad input, as the local rollout raises it.
          mjcffi.FatalError: MuJoCo raised a fatal error in some rollouts (the others
            completed); `failed` lists their indices in this call.
          RuntimeError: the cluster is closed, or a shard's workers died MAX_ATTEMPTS times.
        """
        if _is_data(initial_state):
            if len(more) > 1:
                raise TypeError("rollout takes at most 4 positional arguments "
                                "(model, data, initial_state, control)")
            initial_state, control = control, (more[0] if more else None)
        elif more:
            raise TypeError("rollout takes at most 3 positional arguments "
                            "(model, initial_state, control) besides a data argument")
        if not self.alive:
            raise RuntimeError("rollout requested on a closed RolloutCluster (or after "
                               "ray.shutdown)")
        if shard_size is not None:
            shard_size = _rollout._integer(shard_size, "shard_size", ValueError)
            if shard_size < 1:
                raise ValueError("shard_size must be a positive integer")
        request, outputs = check(model, initial_state, control, control_spec=control_spec,
                                 skip_checks=skip_checks, nstep=nstep,
                                 initial_warmstart=initial_warmstart, state=state,
                                 sensordata=sensordata, chunk_size=chunk_size)
        if request is None:
            return outputs
        self._run(request, _shards(request.nbatch, shard_size or
                                   math.ceil(request.nbatch / len(self._workers))), progress)
        return outputs

    def _run(self, request, shards, progress):
        """Run `shards` ((a, b) rollout ranges) on idle workers; write their outputs."""
        ray = self._ray
        names = self._store.names(request.models)
        n, t = request.nbatch, request.nstep
        state = None if request.state is None else request.state.reshape(n, t, -1)
        sensordata = None if request.sensordata is None else request.sensordata.reshape(n, t, -1)
        pending = collections.deque(shards)
        attempts = collections.Counter()
        running = {}                        # ObjectRef -> (shard, actor)
        idle = list(self._workers)
        failures = []                       # (first global index, message), failed indices
        failed = []
        with _progress.bar(len(shards), "rollout", "shard", progress) as bar:
            while pending or running:
                while pending and idle:
                    shard, actor = pending.popleft(), idle.pop(0)
                    running[self._submit(actor, request, names, *shard)] = (shard, actor)
                done, _ = ray.wait(list(running), num_returns=1)
                ref = done[0]
                shard, actor = running.pop(ref)
                try:
                    st, sd, bad, message = ray.get(ref)
                except ray.exceptions.RayActorError as exc:
                    attempts[shard] += 1
                    if attempts[shard] >= MAX_ATTEMPTS:
                        raise RuntimeError(f"rollouts {shard[0]}..{shard[1] - 1}: the worker "
                                           f"died under them {attempts[shard]} times") from exc
                    idle.append(self._replace(actor))
                    pending.appendleft(shard)
                    continue
                a, b = shard
                if state is not None:
                    state[a:b] = st
                if sensordata is not None:
                    sensordata[a:b] = sd
                if len(bad):
                    failed.append(bad + a)
                    failures.append((a + int(bad[0]), message))
                idle.append(actor)
                bar.update(1)
        if failed:
            error = FatalError(min(failures)[1])
            error.failed = np.sort(np.concatenate(failed))
            raise error

    def _submit(self, actor, request, names, a, b):
        """Start rollouts a..b on `actor`: its ObjectRef."""
        models, state0, warmstart0, control = request.rows(a, b)
        shard_names = names[a:b] if isinstance(names, list) else names
        return actor.run.remote(shard_names, self._store.refs(shard_names), state0,
                                warmstart0, control, request.control_spec, request.nstep,
                                request.chunk_size)


def _shards(nbatch, size):
    """(a, b) ranges of at most `size` rollouts covering 0..nbatch, near equal in size."""
    count = math.ceil(nbatch / size)
    edges = [nbatch * i // count for i in range(count + 1)]
    return [(edges[i], edges[i + 1]) for i in range(count)]


def _is_data(value):
    """An MjData, or a non-empty list or tuple of them: the `data` of the local call shape."""
    if isinstance(value, MjData):
        return True
    return (isinstance(value, (list, tuple)) and len(value) > 0
            and all(isinstance(d, MjData) for d in value))
