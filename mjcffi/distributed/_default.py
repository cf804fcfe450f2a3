"""`rollout` on a default RolloutCluster, started on first use and kept until `shutdown`."""

import threading

from .. import rollout as _rollout
from ._cluster import RolloutCluster, positive_count

_default = None
_lock = threading.Lock()


def default_cluster(num_workers=None):
    """The default RolloutCluster, started anew when there is none, it is closed, Ray was
    restarted since, or `num_workers` asks for another size."""
    global _default
    with _lock:
        stale = _default is None or not _default.alive or (
            num_workers is not None and num_workers != _default.num_workers)
        if stale:
            if _default is not None:
                _default.close()
            _default = None
            _default = RolloutCluster(num_workers)
        return _default


def shutdown():
    """End the default cluster's workers (the next `rollout` starts new ones)."""
    global _default
    with _lock:
        if _default is not None:
            _default.close()
        _default = None


def rollout(model, initial_state, control=None, *, control_spec=_rollout._CTRL,
            skip_checks=False, nstep=None, initial_warmstart=None, state=None,
            sensordata=None, chunk_size=None, num_workers=None, shard_size=None,
            progress=False):
    """Roll out open-loop trajectories on Ray workers; get the states and sensor values.

    `mjcffi.rollout.rollout` without `data` (each worker owns its MjData), run on the
    default RolloutCluster: `num_workers` actors (default: one per node), started on the
    first call and kept between calls.  Results are bit for bit the local ones.

    Args:
      model: an MjModel, or a sequence of nbatch MjModels of the same sizes.
      initial_state: ([nbatch or 1] x nstate) mjSTATE_FULLPHYSICS states.
      control: ([nbatch or 1] x [nstep or 1] x ncontrol); optional.
      control_spec, skip_checks, nstep, initial_warmstart, state, sensordata, chunk_size:
        as in `mjcffi.rollout.rollout`.
      num_workers: the default cluster's size (a new one is started when it changes).
      shard_size: rollouts per shard (default: nbatch shared evenly among workers).
      progress: show a tqdm bar of shards done (when tqdm is installed).

    Returns:
      (state, sensordata): (nbatch x nstep x nstate) and (nbatch x nstep x nsensordata).

    Raises:
      ImportError: Ray is not installed (pip install 'mjcffi[distributed]').
      ValueError, TypeError: bad input, as the local rollout raises it.
      mjcffi.FatalError: MuJoCo raised a fatal error in some rollouts; `failed` lists them.
    """
    return default_cluster(positive_count(num_workers, "num_workers")).rollout(
        model, initial_state, control, control_spec=control_spec, skip_checks=skip_checks,
        nstep=nstep, initial_warmstart=initial_warmstart, state=state, sensordata=sensordata,
        chunk_size=chunk_size, shard_size=shard_size, progress=progress)
