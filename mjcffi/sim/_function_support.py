"""What the generated mujoco-py functions (mjcffi/sim/generated/functions.py) call.

A support module, as _getter_support.py is for the generated getters: mujoco-py's
argument conventions (size arguments, flat arrays, addresses of C ints, printf
messages) turned into what mjcffi's functions take, and the few calls whose whole
meaning is mapped here (mj_printSchema's file, mj_addM's dense form).  Hand-written,
imported by the generated module only.
"""

import ctypes as _ctypes
import math as _math
import operator as _operator

import numpy as _np

from .. import functions as _mj
from ..structs.mjui import MjuiDef as _MjuiDef
def _count(value, name):
    """A size argument of mujoco-py's: an int >= 0, the number of values MuJoCo reads."""
    count = _operator.index(value)
    if count < 0:
        raise ValueError(f"{name} must be >= 0, not {count}")
    return count


def _size(struct, name):
    """struct.name (m.nv, d.nefc), or None when struct has no such field (it is not
    an MjModel or MjData): the arrays it sizes are then handed on as they are, and
    mjcffi names the argument that is wrong."""
    return getattr(struct, name, None)


def _shaped(array, shape, name):
    """`array` seen in `shape`, without a copy.

    mujoco-py took flat (ndim=1) NumPy arrays and let MuJoCo read as many values as
    it needed from their start; mjcffi takes arrays of exactly the shape MuJoCo
    reads.  A 1-D array is cut to the values MuJoCo reads (ValueError when it holds
    fewer) and, when C-contiguous, viewed in `shape`; anything else is handed on as
    it is, for mjcffi to check."""
    if (not isinstance(array, _np.ndarray) or array.ndim != 1 or array.shape == shape
            or None in shape):
        return array
    size = _math.prod(shape)
    if array.shape[0] < size:
        raise ValueError(f"{name} holds {array.shape[0]} values, fewer than the {size} "
                         f"MuJoCo reads (shape {shape})")
    if len(shape) == 1:
        return array[:size]
    if not array.flags.c_contiguous:
        return array                # refused by mjcffi, as by mujoco-py (mode="c")
    return array[:size].reshape(shape)


def _ints(value, count, name):
    """A `uintptr_t` argument of mujoco-py's: the address of C ints (such as
    `array.ctypes.data`), 0 for NULL.  An address gives an int32 view of the `count`
    ints there (None for 0); an int32 array, as mjcffi takes, is cut as by _shaped."""
    if isinstance(value, (int, _np.integer)) and not isinstance(value, bool):
        address = int(value)
        if address == 0:
            return None
        if address < 0:
            raise ValueError(f"{name} must be an address, not {address}")
        count = _count(count, "the count of " + name)
        if count == 0:
            return _np.zeros(0, _np.int32)
        return _np.frombuffer((_ctypes.c_int32 * count).from_address(address), _np.int32)
    return _shaped(value, (count,), name)


def _extent(rownnz, rowadr):
    """How many values a sparse matrix given by rownnz and rowadr holds."""
    if rownnz is None or rowadr is None or len(rownnz) == 0:
        return 0
    return int(_np.max(_np.asarray(rowadr) + _np.asarray(rownnz)))


def _printf(template, value):
    """MuJoCo 2's message of mju_error_i / mju_error_s (and the warnings): the printf
    format `template` filled with `value`; with no place for it, `template` as it is."""
    try:
        return template % (value,)
    except (TypeError, ValueError):
        return template


def _definitions(value):
    """mjui_add's definitions: mujoco-py passed one PyMjuiDef, mjcffi takes a sequence."""
    return [value] if isinstance(value, _MjuiDef) else value


def _write_schema(filename, text):
    """mj_printSchema's file and result: `text` written to `filename` unless that is
    empty, and the length of the text."""
    if filename:
        with open(filename, "w", encoding="utf-8") as f:
            f.write(text)
    return len(text)


def _is_null(value):
    return value is None or (isinstance(value, (int, _np.integer))
                             and not isinstance(value, bool) and value == 0)


def _add_inertia(m, d, dst, rownnz, rowadr, colind):
    """MuJoCo 2's mj_addM in its dense form: dst += the whole nv x nv inertia matrix."""
    if not (_is_null(rownnz) and _is_null(rowadr) and _is_null(colind)):
        raise NotImplementedError(
            "mj_addM: only the dense form (rownnz, rowadr and colind 0) is supported: "
            "MuJoCo 4's sparse form adds the lower triangle only, in another layout")
    nv = _size(m, "nv")
    full = None if nv is None else _np.zeros((nv, nv))
    _mj.mj_fullM(m, d, full)                  # checks m and d
    dst = _shaped(dst, (nv, nv), "dst")
    _np.add(dst, full, out=dst)
