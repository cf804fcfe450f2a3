"""Pickles of MjModel and MjData written by the official bindings, read into mjcffi.

The official bindings pickle an MjModel or MjData as `mujoco._structs.MjModel`
(`MjData`) made with no arguments, then `__setstate__(bytes)`.  Under
`sys.modules['mujoco'] = mjcffi`, `mujoco._structs` is mjcffi._structs, and the
__setstate__ of mjcffi's MjModel and MjData read those bytes here
(python/mujoco/structs_wrappers.cc, Serialize, in the official sources):

- MjModel: a version byte (1), then the MJB's size (size_t), then the MJB
  (mj_saveModel) as `bytes`, each `bytes` being a size_t count and the bytes.
- MjData: a version byte (1), its model as above, then as `bytes` each of
  maxuse_stack ... energy (SCALARS), each array of MJDATA_POINTERS in mjxmacro.h's
  order, and the arena arrays of MJDATA_ARENA_POINTERS_CONTACT and _SOLVER, then of
  _DUAL when the model's solver is dual, and of _ISLAND when nisland > 0: each array
  whose extent is not zero, as `bytes` of its full size or of 0 bytes for NULL.
  Nothing may follow.

Nothing here is trusted: the MJB loads through MjModel.from_bytes's checks, and the
data becomes mjcffi's own pickled parts (header, buffer, arena, layout), which
mjcffi_restore_data checks in full (mjcffi/_c/unpickle.c) before it copies anything.
Counts the official format leaves out (nl, the sleep and efm counts) stay those of a
fresh mjData, as in the official bindings' own unpickling.

Support module: imports only the compiled module, errors.py and the tables.
"""

import struct
import sys

from .errors import with_note
from .library import ffi, lib
from .._generated.structinfo import STRUCTS

_VERSION = 1
_SIZE = struct.Struct("N")       # size_t, native: as the writer's machine (this one) has it

# mjData's fields the official format writes before the arrays, in its order
SCALARS = ("maxuse_stack", "maxuse_arena", "maxuse_con", "maxuse_efc", "solver", "timer",
           "warning", "ncon", "ne", "nf", "nJ", "nY", "nA", "nefc", "nisland", "nidof", "time",
           "energy")

# mjxmacro.h's MJDATA_ARENA_POINTERS_* of MuJoCo 4.0 (tests/test_official_objects.py
# checks them against the installed header)
ARENA = {
    "CONTACT": ("contact",),
    "SOLVER": ("efc_type", "efc_id", "efc_J_rownnz", "efc_J_rowadr", "efc_J_rowsuper",
               "efc_J_colind", "efc_J", "efc_pos", "efc_margin", "efc_frictionloss",
               "efc_diagA", "efc_KBIP", "efc_D", "efc_R", "tendon_efcadr", "efc_vel",
               "efc_aref", "efc_b", "efc_state", "efc_force"),
    "DUAL": ("efc_Y_rownnz", "efc_Y_rowadr", "efc_Y_colind", "efc_Y", "efc_AR_rownnz",
             "efc_AR_rowadr", "efc_AR_colind", "efc_AR"),
    "ISLAND": ("tree_island", "island_ntree", "island_itreeadr", "map_itree2tree",
               "dof_island", "island_nv", "island_idofadr", "island_dofadr", "map_dof2idof",
               "map_idof2dof", "ifrc_smooth", "iacc_smooth", "iacc", "efc_island",
               "island_ne", "island_nf", "island_nefc", "island_iefcadr", "map_efc2iefc",
               "map_iefc2efc", "iefc_type", "iefc_id", "iefc_frictionloss", "iefc_D",
               "iefc_R", "iefc_aref", "iefc_state", "iefc_force", "ifrc_constraint"),
    "EFM": ("efm_c", "efm_diag", "efm_ck", "efm_sdiag", "efm_fluid", "efm_tid", "efm_ts",
            "efm_tk", "efm_aid", "efm_as", "efm_ak", "efm_ca", "efm_K_rownnz",
            "efm_K_rowadr", "efm_K_colind", "efm_K_val", "efm_dofid", "efm_con_ind",
            "efm_con_val", "efm_L"),
}
ARENA_ORDER = tuple(name for block in ARENA.values() for name in block)

_FIELDS = {f.name: f for f in STRUCTS["mjData"]}
_ARENA_SET = set(ARENA_ORDER)
# MJDATA_POINTERS: mjData's pointer fields in the buffer, in the header's order
POINTERS = tuple(f.name for f in STRUCTS["mjData"]
                 if f.kind == "pointer" and f.name not in ("buffer", "arena")
                 and f.name not in _ARENA_SET)
_C_FIELDS = dict(ffi.typeof("mjData").fields)
_TAG = b"mjcffiD1"              # mjcffi's layout (mjcffi/_c/unpickle.c)

_ADVICE = ("the official bindings of another MuJoCo version, or no MjModel/MjData pickle: "
           "load the model from its MJB or XML (mj_saveModel), or pickle it under mjcffi")


class _Reader:
    """The official bytes, read from the front; ValueError("Invalid serialized
    <what>.") when they end early or hold what their format does not."""

    def __init__(self, state, what):
        if not isinstance(state, (bytes, bytearray, memoryview)):
            raise TypeError(f"the state of a pickled {what} must be bytes (the official "
                            f"bindings' format), not {type(state).__name__}")
        self.data = bytes(state)
        self.at = 0
        self.what = what

    def fail(self, detail):
        return with_note(ValueError(f"Invalid serialized {self.what}."),
                         f"{detail}; written by {_ADVICE}")

    def take(self, n):
        if n < 0 or self.at + n > len(self.data):
            raise self.fail(f"it ends at byte {len(self.data)}, {n} more were due at byte "
                            f"{self.at}")
        chunk = self.data[self.at:self.at + n]
        self.at += n
        return chunk

    def size(self):
        return _SIZE.unpack(self.take(_SIZE.size))[0]

    def version(self):
        version = self.take(1)[0]
        if version != _VERSION:
            raise with_note(ValueError("Incompatible serialization version."),
                            f"version {version}, mjcffi reads {_VERSION}; written by {_ADVICE}")

    def counted(self, n, name):
        """A `bytes` of exactly `n` bytes (its count first)."""
        count = self.size()
        if count != n:
            raise self.fail(f"{name} holds {count} bytes, {n} were due")
        return self.take(n)

    def model(self):
        """The MJB of a serialized model (after its version byte)."""
        self.version()
        n = self.size()
        if n > len(self.data):
            raise self.fail(f"the model's size {n} exceeds the {len(self.data)} bytes")
        return self.counted(n, "the model")


def model_mjb(state):
    """The MJB bytes an official MjModel pickle holds."""
    reader = _Reader(state, "mjModel")
    mjb = reader.model()
    if reader.at != len(reader.data):
        raise reader.fail(f"{len(reader.data) - reader.at} bytes follow the model")
    return mjb


def split_data(state):
    """(the MJB of its model, the reader at the data's fields) of an official MjData
    pickle."""
    reader = _Reader(state, "mjData")
    reader.version()
    return reader.model(), reader


def _extent(field, m, counts):
    """The number of elements of mjData array `field` for C model `m` and the data's
    `counts` (a dict)."""
    rows, cols = field.extents
    owner, _, name = rows.partition(".")
    rows = getattr(m, name) if owner == "m" else counts[name]
    return int(rows) * int(cols)


def data_parts(m, d, reader):
    """mjcffi's pickled parts (header, buffer, arena, layout) of the data that
    `reader` (split_data's) holds, for C model `m`; `d` is a fresh mjData of `m` (its
    header and buffer layout are the starting point)."""
    header = bytearray(ffi.buffer(d, lib.mjcffi_data_header_size()))
    for name in SCALARS:
        field = _C_FIELDS[name]
        n = ffi.sizeof(field.type)
        header[field.offset:field.offset + n] = reader.counted(n, name)
    counts = {}
    for name in ("ncon", "nefc", "nJ", "nY", "nA", "nisland", "nidof"):
        field = _C_FIELDS[name]
        counts[name] = int.from_bytes(header[field.offset:field.offset + ffi.sizeof(field.type)],
                                      sys.byteorder, signed=True)
        if counts[name] < 0:
            raise reader.fail(f"{name} = {counts[name]} is negative")

    base = int(ffi.cast("uintptr_t", d.buffer))
    buffer = bytearray(ffi.buffer(d.buffer, d.nbuffer))
    for name in POINTERS:
        field = _FIELDS[name]
        n = ffi.sizeof(field.elem) * _extent(field, m, counts)
        chunk = reader.counted(n, name)
        if n:
            at = int(ffi.cast("uintptr_t", getattr(d, name))) - base
            buffer[at:at + n] = chunk

    blocks = ["CONTACT", "SOLVER"]
    if lib.mj_isDual(m):
        blocks.append("DUAL")
    if counts["nisland"]:
        blocks.append("ISLAND")
    arena = bytearray()
    offsets = dict.fromkeys(ARENA_ORDER, -1)
    for block in blocks:
        for name in ARENA[block]:
            field = _FIELDS[name]
            count = _extent(field, m, counts)
            if not count:
                continue                  # the writer skips an empty array altogether
            size = ffi.sizeof(field.elem)
            n = reader.size()
            if n == 0:
                continue                  # NULL
            if n != size * count:
                raise reader.fail(f"{name} holds {n} bytes, {size * count} were due")
            align = ffi.alignof(field.elem)
            arena += bytes(-len(arena) % align)      # as mj_arenaAllocByte aligns
            offsets[name] = len(arena)
            arena += reader.take(n)
    if reader.at != len(reader.data):
        raise reader.fail(f"{len(reader.data) - reader.at} bytes follow the data")

    parena = _C_FIELDS["parena"]
    header[parena.offset:parena.offset + ffi.sizeof(parena.type)] = \
        len(arena).to_bytes(ffi.sizeof(parena.type), sys.byteorder)
    layout = _TAG + d.signature.to_bytes(8, sys.byteorder) + b"".join(
        offsets[name].to_bytes(8, sys.byteorder, signed=True) for name in ARENA_ORDER)
    return bytes(header), bytes(buffer), bytes(arena), layout
