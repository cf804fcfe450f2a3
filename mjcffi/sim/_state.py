"""MjSimState: a copy of a simulation's state, and its flat vector form."""

from collections import namedtuple

import numpy as np


class MjSimState(namedtuple("MjSimState", "time qpos qvel act udd_state")):
    """A copy of a simulation's state: time, qpos, qvel, act (None when na == 0), udd_state.

    `flatten()` gives one float64 vector, and `MjSimState.from_flattened(v, sim)`
    reads it back with the sizes of `sim` (bit-exact both ways).  `==` compares the
    parts by value, as mujoco-py did (a namedtuple of arrays could not).
    """

    __slots__ = ()

    def __eq__(self, other):
        """Equal parts: time, qpos, qvel and act by value (act None only equals None), and
        the same udd_state keys with equal values (numbers or arrays)."""
        if not isinstance(other, MjSimState):
            return NotImplemented
        return (self.time == other.time and np.array_equal(self.qpos, other.qpos)
                and np.array_equal(self.qvel, other.qvel) and _same_act(self.act, other.act)
                and _same_udd(self.udd_state or {}, other.udd_state or {}))

    def __ne__(self, other):
        equal = self.__eq__(other)
        return equal if equal is NotImplemented else not equal

    __hash__ = None  # type: ignore[assignment]  # it holds arrays

    def flatten(self):
        """time, qpos, qvel, act, then the udd_state values in key order, as one vector."""
        parts = [np.array([self.time], dtype=np.float64), np.ravel(self.qpos),
                 np.ravel(self.qvel)]
        if self.act is not None:
            parts.append(np.ravel(self.act))
        for key in sorted(self.udd_state or {}):
            parts.append(np.ravel(np.asarray(self.udd_state[key], dtype=np.float64)))
        return np.concatenate(parts).astype(np.float64, copy=False)

    @staticmethod
    def from_flattened(array, sim):
        """The MjSimState that `flatten()` gave, read with the sizes of `sim`."""
        time, qpos, qvel, act, udd_state = _split_flat(array, sim)
        return MjSimState(float(time), qpos.copy(), qvel.copy(),
                          None if act is None else act.copy(),
                          {k: (v.copy() if isinstance(v, np.ndarray) else v)
                           for k, v in udd_state.items()})


def _same_act(a, b):
    if a is None or b is None:
        return a is None and b is None
    return np.array_equal(a, b)


def _same_udd(a, b):
    if set(a) != set(b):
        return False
    return all(np.array_equal(a[key], b[key]) for key in a)


def _split_flat(array, sim):
    """The parts of a flattened state, as views of `array` (udd scalars as floats)."""
    from ._sim import MjSim     # _sim imports this module
    if not isinstance(sim, MjSim):
        raise TypeError(f"sim must be an MjSim, not {type(sim).__name__}")
    array = np.asarray(array, dtype=np.float64)
    nq, nv, na = sim.model.nq, sim.model.nv, sim.model.na
    udd = [(key, np.shape(sim.udd_state[key])) for key in sorted(sim.udd_state)]
    size = 1 + nq + nv + na + sum(int(np.prod(shape)) for _, shape in udd)
    if array.ndim != 1 or array.size != size:
        raise ValueError(f"a flattened state of this sim has {size} numbers, not {array.size}"
                         + ("" if array.ndim == 1 else f" (shape {array.shape})"))
    qpos = array[1:1 + nq]
    qvel = array[1 + nq:1 + nq + nv]
    at = 1 + nq + nv
    act = None
    if na:
        act, at = array[at:at + na], at + na
    udd_state = {}
    for key, shape in udd:
        if shape == ():
            udd_state[key], at = float(array[at]), at + 1
        else:
            n = int(np.prod(shape))
            udd_state[key], at = array[at:at + n].reshape(shape), at + n
    return array[0], qpos, qvel, act, udd_state

