"""One rollout call, checked and normalized on the driver by mjcffi.rollout's own checks.

`check` runs `mjcffi.rollout.Rollout.rollout` on a pool whose C call is replaced by
recording its arguments: the same inference, repetition, messages and output allocation
as a local rollout, without copying them, and without rolling anything out here.
"""

import dataclasses

import numpy as np

from .. import rollout as _rollout
from .._generated.enums import mjtState
from .._support.library import lib

_FULLPHYSICS = int(mjtState.mjSTATE_FULLPHYSICS)


@dataclasses.dataclass
class Request:
    """A checked call: models (one, or one per rollout) and inputs at their strides."""
    models: object                 # an MjModel, or a list of nbatch MjModels
    nbatch: int
    nstep: int
    control_spec: int
    chunk_size: object
    initial_state: np.ndarray      # (1 or nbatch, nstate)
    initial_warmstart: object      # None or (1 or nbatch, nv)
    control: object                # None or (1 or nbatch, 1 or nstep, ncontrol)
    state: object                  # the output the caller gave or the check allocated
    sensordata: object

    def rows(self, a, b):
        """The inputs of rollouts a..b: (models, initial_state, initial_warmstart, control);
        a repeated row stays one row."""
        def cut(array):
            if array is None or array.shape[0] == 1:
                return array
            return array[a:b]
        models = self.models[a:b] if isinstance(self.models, list) else self.models
        return models, cut(self.initial_state), cut(self.initial_warmstart), cut(self.control)


class _Recorder(_rollout.Rollout):
    """A Rollout (no threads) that records the C call instead of making it."""

    def __init__(self):
        super().__init__(nthread=0)
        self.request = None

    def _datas(self, data, model):
        return []                  # workers own their MjData

    def _call(self, pool, models, datas, nbatch, nstep, control_spec, chunk_size,
              state0, state0_stride, warmstart0, warmstart0_stride,
              control, control_rstride, control_tstride, state, sensordata):
        first = models[0] if isinstance(models, list) else models
        nstate = lib.mj_stateSize(first._ptr, _FULLPHYSICS)
        ncontrol = lib.mj_stateSize(first._ptr, control_spec)
        # skip_checks passes flat arrays at full size: give every input its rows again
        state0 = state0.reshape(nbatch if state0_stride else 1, nstate)
        if warmstart0 is not None:
            warmstart0 = warmstart0.reshape(nbatch if warmstart0_stride else 1, first.nv)
        if control is not None:
            control = control.reshape(nbatch if control_rstride else 1,
                                      nstep if control_tstride else 1, ncontrol)
        self.request = Request(models, nbatch, nstep, control_spec, chunk_size, state0,
                               warmstart0, control, state, sensordata)


def check(model, initial_state, control, *, control_spec, skip_checks, nstep,
          initial_warmstart, state, sensordata, chunk_size):
    """(Request or None, (state, sensordata)): None when there is nothing to roll out
    (nbatch or nstep 0); raises as `mjcffi.rollout.rollout` does on bad input."""
    recorder = _Recorder()
    try:
        outputs = recorder.rollout(model, None, initial_state, control,
                                   control_spec=control_spec, skip_checks=skip_checks,
                                   nstep=nstep, initial_warmstart=initial_warmstart,
                                   state=state, sensordata=sensordata, chunk_size=chunk_size)
    finally:
        recorder.close()
    return recorder.request, outputs
