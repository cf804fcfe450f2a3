"""The MJB read in place: its sizes, its options and its arrays as NumPy views of
its bytes, in mjxmacro.h's order (which the struct metadata keeps); and what every
check shares: the registry of checks and the way a problem is reported."""

from collections.abc import Callable

import numpy as np

from ..library import ffi
from ..._generated.structinfo import STRUCTS

FIELDS = STRUCTS["mjModel"]
DOCS = {f.name: f.doc for f in FIELDS}
SIZES = tuple(f.name for f in FIELDS if f.ctype == "mjtSize" and f.kind == "scalar")
POINTERS = tuple(f for f in FIELDS if f.kind == "pointer" and f.name != "buffer")
ROWS = {f.name: f.extents[0][2:] for f in POINTERS}      # 'm.nbody' -> 'nbody'
INT_FIELDS = tuple(f.name for f in POINTERS if f.elem in ("int", "mjtSize"))
_FLAGS = tuple(f.name for f in FIELDS if f.kind == "scalar" and f.ctype == "mjtBool")
_NHEADER = 5                  # ints before the sizes: id, sizeof(mjtNum), nsize, version, nptr
_DTYPE = {"int": np.int32, "mjtSize": np.int64, "mjtNum": np.float64, "float": np.float32,
          "mjtByte": np.uint8, "mjtBool": np.uint8, "char": np.uint8}
_INT_MAX = 2**31 - 1
_MAY_BE_NEGATIVE = {"njmax", "nconmax"}            # -1: as large as needed
# Sizes past _INT_MAX: the arena, the buffer, and arrays addressed by an mjtSize (tex_adr).
_LONG_SIZES = {"narena", "nbuffer"} | {ROWS[f.name[:-3] + "data"] for f in POINTERS
                                       if f.elem == "mjtSize" and f.name.endswith("_adr")}


class Bad(Exception):
    """A problem found: its text is the note of the caller's ValueError."""


def fail(name, index, value, why):
    where = name if index is None else f"{name}[{index}]"
    raise Bad(f"{where} is {value}: {why}")


def first(bad):
    """The flat index of the first True of `bad`."""
    return int(np.flatnonzero(np.ravel(bad))[0])


def check_range(m, name, low, high, why):
    """Every value of field `name` in [low, high)."""
    values = m.arrays[name].ravel()
    bad = (values < low) | (values >= high)
    if bad.any():
        k = first(bad)
        fail(name, k, int(values[k]), why)


def check_slice(values, name, offset, low, high):
    """Every one of `values`, elements `offset`... of field `name`, in [low, high)."""
    bad = (values < low) | (values >= high)
    if bad.any():
        k = first(bad)
        fail(name, offset + k, int(np.ravel(values)[k]), f"an index in [{low}, {high})")


# check function -> the fields it covers (tests/test_model_validation.py)
CHECKED: dict[Callable[["Model"], None], frozenset[str]] = {}


def covers(*fields):
    """Register a check with the fields it covers."""
    def register(check):
        CHECKED[check] = frozenset(fields)
        return check
    return register


def _struct(mjb, at, cname):
    out = ffi.new(f"{cname} *")
    ffi.memmove(out, mjb[at:at + ffi.sizeof(cname)], ffi.sizeof(cname))
    return out


def _check_sizes(sizes):
    for name, value in sizes.items():
        if value < 0 and not (name in _MAY_BE_NEGATIVE and value == -1):
            fail(name, None, value, "a count cannot be negative")
        if value > _INT_MAX and name not in _LONG_SIZES:
            fail(name, None, value, f"MuJoCo counts these in an int, up to {_INT_MAX}")


# The arrays' shapes as indices into the sizes: rows, and columns (a constant, or a
# size times a factor: 'm.nmocap*3'), so that one MJB's layout is a few array operations.
_NAMES = tuple(f.name for f in POINTERS)
_INDEX = {name: i for i, name in enumerate(_NAMES)}
_DTYPES = tuple(np.dtype(_DTYPE[f.elem]) for f in POINTERS)
_ITEMSIZE = np.array([d.itemsize for d in _DTYPES], np.int64)
_ROW = np.array([SIZES.index(ROWS[name]) for name in _NAMES])


def _column_extent(field):
    extent = field.extents[1] if len(field.extents) > 1 else 1
    if isinstance(extent, int):
        return -1, extent
    name, _, factor = extent[2:].partition("*")
    return SIZES.index(name), int(factor or 1)


_COLUMN, _FACTOR = (np.array(c, np.int64) for c in zip(*map(_column_extent, POINTERS)))
_HEADER = 4 * _NHEADER + 8 * len(SIZES)
_START = (_HEADER + ffi.sizeof("mjOption") + ffi.sizeof("mjVisual") + ffi.sizeof("mjStatistic")
          + len(_FLAGS))


def _layout(sizes, length):
    """(rows, columns, byte offsets) of the arrays; Bad if they are not the MJB's bytes."""
    rows = sizes[_ROW]
    cols = np.where(_COLUMN >= 0, sizes[_COLUMN] * _FACTOR, _FACTOR)
    estimate = rows.astype(float) * cols * _ITEMSIZE        # no overflow: checked first
    if _START + estimate.sum() > length:
        at = _START
        for name, r, c, size in zip(_NAMES, rows.tolist(), cols.tolist(), _ITEMSIZE.tolist()):
            if at + r * c * size > length:
                raise Bad(f"{name} runs past the {length} bytes of the MJB")
            at += r * c * size
    nbytes = rows * cols * _ITEMSIZE
    total = _START + int(nbytes.sum())
    if total != length:
        raise Bad(f"the MJB holds {length} bytes, but its sizes describe {total}")
    return rows.tolist(), cols.tolist(), (_START + np.cumsum(nbytes) - nbytes).tolist()


class _Views(dict):
    """Field name -> its (rows, columns) NumPy view of the MJB, made on first use."""

    def __init__(self, mjb, layout):
        super().__init__()
        self._mjb = mjb
        self._rows, self._cols, self.offsets = layout

    def __missing__(self, name):
        i = _INDEX[name]
        rows, cols = self._rows[i], self._cols[i]
        view = np.frombuffer(self._mjb, _DTYPES[i], rows * cols, self.offsets[i])
        self[name] = view = view.reshape(rows, cols)
        return view


class Model:
    """The sizes, the options and the arrays of an MJB, as NumPy views of its bytes:
    `m.nbody`, `m.arrays["body_parentid"]` (an (nbody, 1) int32 array),
    `m.opt.integrator`, and `m.offset("body_parentid")`, a field's byte offset."""

    def __init__(self, mjb):
        sizes = np.frombuffer(mjb, np.int64, len(SIZES), 4 * _NHEADER)
        self.sizes = dict(zip(SIZES, sizes.tolist()))
        _check_sizes(self.sizes)                # before they size any view
        self.opt = _struct(mjb, _HEADER, "mjOption")
        self.arrays = _Views(mjb, _layout(sizes, len(mjb)))

    def __getattr__(self, name):
        if name in self.sizes:
            return self.sizes[name]
        raise AttributeError(name)

    def offset(self, name):
        """The byte offset of field `name` (or 'opt.<field>') in the MJB."""
        if name.startswith("opt."):
            return _HEADER + ffi.offsetof("mjOption", name[4:])
        return self.arrays.offsets[_INDEX[name]]

    def flat(self, name):
        """The field as a flat list of Python ints (fast to walk in a loop)."""
        return self.arrays[name].ravel().tolist()


def is_this_layout(mjb):
    """Whether the header is of the layout this module reads (else MuJoCo refuses it)."""
    if len(mjb) < _HEADER:
        return False
    header = np.frombuffer(mjb, np.int32, _NHEADER)
    return header[2] == len(SIZES) and header[4] == len(POINTERS)
