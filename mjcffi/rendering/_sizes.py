"""Image and buffer sizes, as every rendering entry point takes them: an int
number of pixels, positive, and at most a limit where one applies."""

import operator

import numpy as np


def pixels(value, name, limit=None):
    """`value` as a positive int of at most `limit`; TypeError or ValueError naming `name`."""
    if isinstance(value, (bool, np.bool_)) or not hasattr(value, "__index__"):
        raise TypeError(f"{name} must be an int, not {type(value).__name__}")
    size = operator.index(value)
    if size <= 0:
        raise ValueError(f"{name} must be a positive number of pixels, not {size}")
    if limit is not None and size > limit:
        raise ValueError(f"{name} must be at most {limit} pixels, not {size}")
    return size
