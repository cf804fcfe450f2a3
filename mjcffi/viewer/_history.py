"""`History`: the viewer's ring buffer of past physics states, bounded in memory.

Each entry is one `mj_getState(m, d, state, mjSTATE_INTEGRATION)` snapshot, the
state from which `mj_setState` and `mj_forward` give back that instant exactly
(time, qpos, qvel, act, warm start, controls, applied forces, mocap, ...).  The
capacity is fixed when the buffer is made, as in MuJoCo's simulate: MAX_STATES
states, or fewer when those would take more than MAX_BYTES, but at least one.
Once full, each new state overwrites the oldest.

The managed viewer records a state after each frame that stepped the physics
(the LEFT arrow then steps back through them, as in simulate); the passive
handle records one at launch and one at each `sync()`, and gives the caller the
buffer as `handle.history`, which MuJoCo's own passive viewer does not keep.
"""

import numpy as np

from .._generated.enums import mjtState
from .._functions import mj_getState, mj_setState, mj_stateSize

MAX_STATES = 2000            # states kept at most, as MuJoCo's simulate
MAX_BYTES = 100_000_000      # bytes the buffer may take at most, as MuJoCo's simulate
SPEC = mjtState.mjSTATE_INTEGRATION


class History:
    """The last `capacity` states of a model's data, oldest first (index 0)."""

    def __init__(self, model, capacity=None):
        """capacity: states kept; by default MAX_STATES, less when they would take more
        than MAX_BYTES."""
        self.state_size = int(mj_stateSize(model, SPEC))
        if capacity is None:
            by_bytes = MAX_BYTES // max(1, self.state_size * 8)
            capacity = min(MAX_STATES, by_bytes)
        self.capacity = max(1, int(capacity))
        # np.empty: the pages are only touched as states arrive
        self._states = np.empty((self.capacity, self.state_size))
        self._next = 0               # the row the next state goes into
        self._count = 0

    @property
    def nbytes(self):
        """The bytes the full buffer takes."""
        return self._states.nbytes

    def __len__(self):
        return self._count

    def _row(self, index):
        """The buffer row of the state at `index` (negative: from the newest)."""
        if not isinstance(index, (int, np.integer)) or isinstance(index, bool):
            raise TypeError(f"a history index must be an int, not {type(index).__name__}")
        position = index + self._count if index < 0 else index
        if not 0 <= position < self._count:
            raise IndexError(f"history index {index} is out of range: {self._count} "
                             f"state(s) kept (at most {self.capacity})")
        return (self._next - self._count + position) % self.capacity

    def __getitem__(self, index):
        """A copy of the state at `index`: 0 the oldest kept, -1 the newest."""
        return self._states[self._row(index)].copy()

    def _rows(self):
        """The buffer rows of the states kept, oldest first."""
        return (self._next - self._count + np.arange(self._count)) % self.capacity

    def states(self):
        """A copy of all the states kept, oldest first: shape (len(self), state_size)."""
        return self._states[self._rows()]

    def times(self):
        """The simulation time of each state kept, oldest first (a state starts with it)."""
        return self._states[self._rows(), 0]

    def record(self, model, data):
        """Add the state of `data` now, dropping the oldest when full."""
        mj_getState(model, data, self._states[self._next], SPEC)
        self._next = (self._next + 1) % self.capacity
        self._count = min(self._count + 1, self.capacity)

    def restore(self, model, data, index):
        """Put the state at `index` into `data` (mj_setState; the caller runs mj_forward)."""
        mj_setState(model, data, self._states[self._row(index)], SPEC)

    def drop_newest(self, count):
        """Forget the newest `count` states (a run resumed from an older one)."""
        count = min(max(0, int(count)), self._count)
        self._next = (self._next - count) % self.capacity
        self._count -= count

    def clear(self):
        self._next = self._count = 0
