"""A rollout worker: a Ray actor that runs shards on mjcffi's C rollout pool.

It keeps, between calls, its Rollout (threads), the models it was sent (by name) and an
MjData per thread for each model size it has seen.
"""

import collections
import os

import numpy as np

from .. import rollout as _rollout
from .._generated.enums import mjtState
from .._support.errors import FatalError
from .._support.library import lib
from ..data import MjData
from ..functions import mj_resetData
from ..model import MjModel
from ._models import sizes_of

_FULLPHYSICS = int(mjtState.mjSTATE_FULLPHYSICS)
_KEEP_MODELS = 256
_KEEP_DATAS = 8


class Worker:
    """The body of the rollout actor (made a Ray actor by `mjcffi.distributed._cluster`)."""

    def __init__(self):
        self._models = collections.OrderedDict()    # name -> MjModel
        self._datas = collections.OrderedDict()     # model sizes -> [MjData, one per thread]
        self._pool = _rollout.Rollout(nthread=0)
        self._exit_after = None                     # test hook: shards left before os._exit

    def where(self):
        """(node id, pid): where this worker runs."""
        import ray
        return ray.get_runtime_context().get_node_id(), os.getpid()

    def configure(self, nthread):
        """Roll out on `nthread` threads (this process's share of its node's cores)."""
        nthread = max(1, int(nthread))
        if nthread != max(1, self._pool.nthread):
            self._pool.close()
            self._pool = _rollout.Rollout(nthread=nthread if nthread > 1 else 0)
            self._datas.clear()
        return nthread

    def exit_on_shard(self, n):
        """Test hook: end this process (os._exit) when its n-th shard from now arrives."""
        self._exit_after = int(n)

    def run(self, names, refs, initial_state, initial_warmstart, control, control_spec, nstep,
            chunk_size):
        """Roll out one shard: (state, sensordata, failed, message).

        A MuJoCo fatal error fails its rollouts alone: `failed` lists them (shard-local
        indices, empty if none) and `message` is MuJoCo's; the outputs hold the rest."""
        if self._exit_after is not None:
            self._exit_after -= 1
            if self._exit_after <= 0:
                os._exit(1)
        models = self._load(names, refs)
        first = models[0] if isinstance(models, list) else models
        nbatch = max(initial_state.shape[0], len(models) if isinstance(models, list) else 1)
        state = np.empty((nbatch, nstep, lib.mj_stateSize(first._ptr, _FULLPHYSICS)))
        sensordata = np.empty((nbatch, nstep, first.nsensordata))
        try:
            self._pool.rollout(models, self._data_for(first), initial_state, control,
                               control_spec=control_spec, nstep=nstep,
                               initial_warmstart=initial_warmstart, state=state,
                               sensordata=sensordata, chunk_size=chunk_size)
        except FatalError as error:
            return state, sensordata, np.asarray(error.failed), str(error)
        return state, sensordata, np.empty(0, np.intp), ""

    def _load(self, names, refs):
        """The models named `names` (a name or a list), fetching the ones not cached."""
        import ray
        single = isinstance(names, str)
        wanted = [names] if single else names
        missing = sorted({n for n in wanted if n not in self._models})
        for name, mjb in zip(missing, ray.get([refs[n] for n in missing])):
            self._models[name] = MjModel.from_bytes(mjb)
        for name in set(wanted):
            self._models.move_to_end(name)
        out = [self._models[n] for n in wanted]
        while len(self._models) > max(_KEEP_MODELS, len(set(wanted))):
            self._models.popitem(last=False)
        return out[0] if single else out

    def _data_for(self, model):
        """One MjData per thread for models of `model`'s sizes, kept between calls."""
        key = sizes_of(model)
        datas = self._datas.get(key)
        if datas is None:
            datas = [MjData(model) for _ in range(max(1, self._pool.nthread))]
            self._datas[key] = datas
            while len(self._datas) > _KEEP_DATAS:
                self._datas.popitem(last=False)
        self._datas.move_to_end(key)
        # as new ones: inputs that no argument sets (ctrl when control is None) start at
        # their defaults, not at what an earlier call left there
        for d in datas:
            mj_resetData(model, d)
        return datas
