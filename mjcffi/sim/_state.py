"""MjSimState: a copy of a simulation's state, and its flat vector form."""

from collections import namedtuple

import numpy as np

from .._generated.enums import mjtState
from ._base import SimBase

# What an exact replay needs besides mujoco-py's fields: the constraint solver's warm
# start and MuJoCo's other physics state (delay buffers, plastic and plugin state).
# The caller's inputs (ctrl, applied forces, mocap, eq_active, userdata) are left out,
# as mujoco-py's set_state left them alone.
EXTRA_SIG = int(mjtState.mjSTATE_WARMSTART | mjtState.mjSTATE_HISTORY
                | mjtState.mjSTATE_PLASTIC | mjtState.mjSTATE_PLUGIN)


class MjSimState(namedtuple("MjSimState", "time qpos qvel act udd_state")):
    """A copy of a simulation's state: time, qpos, qvel, act (None when na == 0), udd_state,
    and optionally `extra`, what an exact replay needs besides (None when not kept).

    `sim.get_state()` fills `extra` with `mj_getState(m, d, ..., MjSimState.EXTRA_SIG)`:
    qacc_warmstart, the warm start of the constraint solver, and any history, plastic
    and plugin state of the model.  `sim.set_state(state)` writes it back, so the steps
    after it are bit-identical to those of the uninterrupted run given the same inputs
    (ctrl, applied forces, mocap poses: the caller's, left alone as in mujoco-py).
    A state made by hand, by `_replace`, or by `from_flattened` has `extra` None, and
    set_state then leaves the sim's warm start as it is: with contacts the run after
    it agrees with the uninterrupted one only to the solver's tolerance.

    `flatten()` gives one float64 vector in mujoco-py's layout (time, qpos, qvel, act,
    udd_state; not `extra`), and `MjSimState.from_flattened(v, sim)` reads it back with
    the sizes of `sim` (bit-exact both ways, for those parts).  `==` compares the
    five parts by value, as mujoco-py did (a namedtuple of arrays could not); `extra`
    takes no part, so a state equals the same one read back from its flat form.  The
    tuple and its repr are mujoco-py's five fields; pickling and copying keep `extra`.
    """

    EXTRA_SIG = EXTRA_SIG

    def __new__(cls, time, qpos, qvel, act, udd_state, extra=None):
        state = super().__new__(cls, time, qpos, qvel, act, udd_state)
        if extra is not None:
            state.__dict__["_extra"] = extra
        return state

    @property
    def extra(self):
        """mj_getState(m, d, EXTRA_SIG) at get_state() (a float64 vector), or None."""
        return self.__dict__.get("_extra")

    def __reduce__(self):
        # pickle and copy through __new__, `extra` with the five fields, whatever the protocol
        return (type(self), (*self, self.extra))

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
    """The parts of a flattened state, as views of `array` (udd scalars as floats).

    TypeError unless `array` holds real numbers; ValueError unless it is one vector of
    exactly the numbers a state of `sim` has (nothing is split from a wrong one)."""
    if not isinstance(sim, SimBase):
        raise TypeError(f"sim must be an MjSim, not {type(sim).__name__}")
    array = _real_array(array, "the flattened state").astype(np.float64, copy=False)
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


# -- the checks of a state's parts, made before a setter writes any

_REAL_KINDS = "biuf"        # bool, int, unsigned, float: what casts to float64 by value


def _real_array(value, what):
    """`value` as a numpy array of real numbers; TypeError for strings, complex numbers,
    objects (None included), ValueError for a ragged nesting."""
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{what} is no array of numbers: {exc}") from None
    if array.dtype.kind not in _REAL_KINDS:
        raise TypeError(f"{what} must hold real numbers (bool, int or float), not "
                        f"{type(value).__name__} of dtype {array.dtype}")
    return array


def _checked_vector(value, what, size):
    """`value` as a float64 vector of exactly `size` numbers (a copy), or TypeError /
    ValueError naming `what` and both shapes: no broadcasting, no flattening."""
    array = _real_array(value, what)
    if array.shape != (size,):
        raise ValueError(f"{what} has shape {array.shape}, and this model's has ({size},)")
    return np.array(array, dtype=np.float64)


def _checked_time(value):
    """`value` as a float: a real number (NaN and infinity included, as mujoco-py took
    them) or a 0-d array of one; TypeError for a string, a complex number, None."""
    if isinstance(value, (np.ndarray, np.generic)):
        if value.shape != ():
            raise ValueError(f"the state's time must be a number, not an array of shape "
                             f"{value.shape}")
        if value.dtype.kind not in _REAL_KINDS:
            raise TypeError(f"the state's time must be a real number, not {value.dtype}")
    elif isinstance(value, (str, bytes, complex)) or value is None:
        raise TypeError(f"the state's time must be a real number, not {type(value).__name__}")
    try:
        return float(value)
    except TypeError:
        raise TypeError(f"the state's time must be a real number, not "
                        f"{type(value).__name__}") from None
    except OverflowError:
        raise ValueError("the state's time is out of range for a C double") from None
