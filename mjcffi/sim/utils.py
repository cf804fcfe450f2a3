"""mujoco-py's `mujoco_py.utils`: its small helpers, for code that imports them.

`rec_copy` and `rec_assign` copy a struct's fields to nested dicts and back (mujoco-py
used them to save and restore render options); `remove_empty_lines` tidies text;
`discover_mujoco` gives the folder of the MuJoCo library mjcffi runs on, which is the
mujoco-core wheel's (mujoco-py looked for ~/.mujoco/mujoco210).
"""

import copy
import os

import numpy as np

from .._support.library import _mujoco_library_path

__all__ = ["remove_empty_lines", "rec_assign", "rec_copy", "discover_mujoco"]

_PLAIN = (int, bool, float, type(None), str)


def remove_empty_lines(string):
    """`string` without its blank lines."""
    return "\n".join(line for line in string.splitlines() if line.strip())


def _fields(node):
    """The public data fields of a struct wrapper: no dunders, no methods."""
    for field in dir(node):
        if "__" in field or field.startswith("_"):
            continue
        value = getattr(node, field)
        if isinstance(value, _PLAIN) or isinstance(value, np.ndarray) or not callable(value):
            yield field, value


def rec_copy(node):
    """A dict of `node`'s fields: scalars as they are, arrays copied, structs as dicts."""
    copied = {}
    for field, value in _fields(node):
        if isinstance(value, _PLAIN):
            copied[field] = value
        elif isinstance(value, np.ndarray):
            copied[field] = copy.deepcopy(value)
        else:
            copied[field] = rec_copy(value)
    return copied


def rec_assign(node, assign):
    """Write a dict made by rec_copy back into `node`: arrays in place, so that the
    memory MuJoCo holds is never replaced."""
    for field, value in _fields(node):
        if isinstance(value, _PLAIN):
            setattr(node, field, assign[field])
        elif isinstance(value, np.ndarray):
            value[...] = assign[field]
        else:
            rec_assign(value, assign[field])


def discover_mujoco():
    """The folder of the MuJoCo library (libmujoco) that mjcffi is linked with."""
    return os.path.dirname(_mujoco_library_path())
