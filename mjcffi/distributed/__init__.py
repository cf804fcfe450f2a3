"""Rollouts spread over a Ray cluster: `mjcffi.rollout` beyond one machine.

    from mjcffi import distributed
    state, sensordata = distributed.rollout(model, initial_state, control)
    with distributed.RolloutCluster(num_workers=4) as cluster:
        state, sensordata = cluster.rollout(model, initial_state, control)

Workers are persistent Ray actors, each running mjcffi's C rollout pool on its node's
cores.  Models travel as MJB bytes through Ray's object store, once per content; workers
keep them, and their MjData, between calls.  The rollouts of a call are split into shards
handed to idle workers; a worker that dies under a shard is replaced and the shard run
again, so a call returns complete results, bit for bit those of a local rollout.

Ray is optional: this package imports without it, and its calls then raise ImportError
naming the extra that installs it (pip install 'mjcffi[distributed]').
"""

from ._cluster import RolloutCluster
from ._default import default_cluster, rollout, shutdown
from ._ray import EXTRA_HINT
from ._tasks import map_calls

__all__ = ["EXTRA_HINT", "RolloutCluster", "default_cluster", "map_calls", "rollout",
           "shutdown"]
