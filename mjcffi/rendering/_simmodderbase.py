"""What mujoco-py's modders share: the sim they edit, a random state, lookups of
named model objects, and checks of the values they write into the model.

Every check raises before the model is touched, so a refused edit leaves the
model as it was.
"""

import numpy as np

from .. import functions as _f
from .._enums import mjtObj


def make_random_state(value):
    """mujoco-py's random_state: None (a fresh, unseeded RandomState), a seed (an int),
    or a RandomState (anything with `uniform` and `randint`), used as given."""
    if value is None:
        return np.random.RandomState()
    if isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_)):
        return np.random.RandomState(int(value))
    if not all(callable(getattr(value, m, None)) for m in ("uniform", "randint")):
        raise TypeError(f"random_state must be None, a seed or a numpy RandomState, not "
                        f"{type(value).__name__}")
    return value


def numbers(value, size, name):
    """`value` as a float64 array of shape (size,), all finite; TypeError when it is not
    numbers, ValueError when it is the wrong shape or not finite."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be {size} numbers, not {value!r}") from None
    if array.shape != (size,):
        raise ValueError(f"{name} must be {size} numbers (shape ({size},)), not an array "
                         f"of shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite, not {array.tolist()}")
    return array


def colour(value, name):
    """An RGB triple of 0..255, as float64 (the caller casts to uint8, truncating as
    mujoco-py's assignment did); ValueError naming `name` otherwise."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        array = None
    if array is None or array.shape != (3,) or not np.all(np.isfinite(array)) \
            or np.any((array < 0) | (array > 255)):
        raise ValueError(f"{name} must be three numbers from 0 to 255 (R, G, B), not {value!r}")
    return array


def real(value, name):
    """`value` as a finite float; TypeError when it is not a real number."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer,
                                                                   np.floating)):
        raise TypeError(f"{name} must be a number, not {type(value).__name__}")
    value = float(value)
    if not np.isfinite(value):
        raise ValueError(f"{name} must be finite, not {value}")
    return value


def unit(value, name):
    """A number from 0 to 1."""
    value = real(value, name)
    if not 0.0 <= value <= 1.0:
        raise ValueError(f"{name} must be from 0 to 1, not {value}")
    return value


def flag(value, name):
    """A switch: True, False, 1 or 0."""
    if isinstance(value, (bool, np.bool_, int, np.integer)) and int(value) in (0, 1):
        return bool(value)
    raise ValueError(f"{name} must be True, False, 1 or 0, not {value!r}")


class BaseModder:
    """The sim a modder edits (`sim`, `model`), its `random_state`, and name lookups."""

    def __init__(self, sim, random_state=None):
        from ..sim import MjSim
        if not isinstance(sim, MjSim):
            raise TypeError(f"sim must be an MjSim, not {type(sim).__name__}")
        self.sim = sim
        self.random_state = make_random_state(random_state)

    @property
    def model(self):
        return self.sim.model

    def _name2id(self, kind, name):
        """The id of the model's `kind` ('geom', 'light', 'camera') named `name`;
        ValueError naming it when there is none."""
        if not isinstance(name, str):
            raise TypeError(f"a {kind} name must be a str, not {type(name).__name__}")
        objtype = int(getattr(mjtObj, f"mjOBJ_{kind.upper()}"))
        found = _f.mj_name2id(self.model, objtype, name) if name else -1
        if found < 0:
            raise ValueError(f"the model has no {kind} named {name!r}")
        return found
