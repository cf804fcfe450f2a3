"""MuJoCo's UI (mjui_add, mjui_resize, mjui_update, mjui_event, mjui_render), checked.

An mjuiDef's `pdata` points at the value its item edits (a checkbox's int, a
slider's mjtNum, an edit field's text), and the mjUI keeps that pointer for as
long as the item exists: MuJoCo reads and writes it at every event and redraw.
So mjui_add takes `pdata` only as memory that Python owns and can keep alive: a
writable, C-contiguous NumPy array, a ctypes object that owns its memory, or a
cffi cdata from ffi.new.  The MjUI wrapper keeps each one (and, for a NumPy array,
a weak reference to it and to the arrays its memory comes from, for which NumPy
refuses `resize` even with refcheck=False) while an item in use points at it.

MuJoCo follows what the mjUI holds without checks, and every field of it can be
written from Python: item types and counts, the element counts of radio and edit
items, the mouse and edit indices, the value of a radio or select item (an index
into its element names).  Before each call the mjUI is checked against what was
recorded at mjui_add: each data item's pointer is one of the kept buffers, of the
element type and size its item type needs; indices and counts lie within MuJoCo's
arrays; text is ASCII (MuJoCo's fonts have 128 characters).  mjui_add itself
checks each definition as MuJoCo would, before MuJoCo runs, so that a bad one
raises TypeError or ValueError; should MuJoCo still raise, the mjUI is restored
as it was.  Calls on one mjUI are serialized by a lock.

The drawing calls need an OpenGL context: `con` must be an MjrContext made in
the context current on this thread (mjcffi/_support/mjr.py).
"""

import ctypes
import math
import operator
import re
import threading
import weakref
from collections.abc import Mapping

import numpy as np

from .._support import marshal as _m
from .._support import mjr as _mjr
from .._support import prepared as _p
from .._generated.constants import (mjMAXUIEDIT, mjMAXUIITEM, mjMAXUIMULTI, mjMAXUINAME, mjMAXUIRECT,
                         mjMAXUISECT, mjMAXUITEXT, mjNAUX, mjPRESERVE)
from .._generated.enums import mjtItem, mjtSection
from .._support.library import ffi, lib
from ..structs import MjuiDef, MjuiItem

__all__ = ["mjui_add", "mjui_addToSection", "mjui_resize", "mjui_update", "mjui_event",
           "mjui_render", "SIGNATURES"]

_UI, _STATE = "mujoco._structs.MjUI", "mujoco._structs.MjuiState"
_CON, _DEF = "mujoco._structs.MjrContext", "mujoco._structs.MjuiDef"
SIGNATURES = {
    "mjui_add": f"mjui_add(ui: {_UI}, def_: Sequence[{_DEF} | tuple | dict]) -> None",
    "mjui_addToSection": f"mjui_addToSection(ui: {_UI}, sect: int, def_: Sequence[{_DEF} | "
                         "tuple | dict]) -> None",
    "mjui_resize": f"mjui_resize(ui: {_UI}, con: {_CON}) -> None",
    "mjui_update": f"mjui_update(section: int, item: int, ui: {_UI}, state: {_STATE}, "
                   f"con: {_CON}) -> None",
    "mjui_event": f"mjui_event(ui: {_UI}, state: {_STATE}, con: {_CON}) -> "
                  "mujoco._structs.MjuiItem | None",
    "mjui_render": f"mjui_render(ui: {_UI}, state: {_STATE}, con: {_CON}) -> None",
}

_I = mjtItem
_NITEM = int(_I.mjNITEM)
_SECTION = int(_I.mjITEM_SECTION)
_BUTTON = int(_I.mjITEM_BUTTON)
_MULTI = {int(_I.mjITEM_STATIC), int(_I.mjITEM_RADIO), int(_I.mjITEM_RADIOLINE),
          int(_I.mjITEM_SELECT)}
_CHOICE = {int(_I.mjITEM_RADIO), int(_I.mjITEM_RADIOLINE), int(_I.mjITEM_SELECT)}
_EDIT = {int(_I.mjITEM_EDITINT), int(_I.mjITEM_EDITNUM), int(_I.mjITEM_EDITFLOAT)}
_SHORTCUT = {int(_I.mjITEM_BUTTON), int(_I.mjITEM_CHECKINT), int(_I.mjITEM_CHECKBYTE)}
_SLIDER = {int(_I.mjITEM_SLIDERINT), int(_I.mjITEM_SLIDERNUM)}
_SECTION_STATES = {int(mjtSection.mjSECT_CLOSED), int(mjtSection.mjSECT_OPEN),
                   int(mjtSection.mjSECT_FIXED), mjPRESERVE}

# The element each data item's pdata points at: buffer format letters it accepts,
# the element size, and how many elements MuJoCo touches (None: the edit count).
_CHAR = ("B", "b", "c", "s")
_NEEDS = {
    int(_I.mjITEM_CHECKINT): (("i",), 4, 1, "int32"),
    int(_I.mjITEM_CHECKBYTE): (("B",), 1, 1, "uint8 (mjtByte)"),
    int(_I.mjITEM_RADIO): (("i",), 4, 1, "int32"),
    int(_I.mjITEM_RADIOLINE): (("i",), 4, 1, "int32"),
    int(_I.mjITEM_SELECT): (("i",), 4, 1, "int32"),
    int(_I.mjITEM_SLIDERINT): (("i",), 4, 1, "int32"),
    int(_I.mjITEM_SLIDERNUM): (("d",), 8, 1, "float64 (mjtNum)"),
    int(_I.mjITEM_EDITINT): (("i",), 4, None, "int32"),
    int(_I.mjITEM_EDITNUM): (("d",), 8, None, "float64 (mjtNum)"),
    int(_I.mjITEM_EDITFLOAT): (("f",), 4, None, "float32"),
    int(_I.mjITEM_EDITTXT): (_CHAR, 1, mjMAXUINAME, "char (uint8, int8 or bytes_)"),
}
_CFFI_FORMATS = {"int": "i", "unsigned char": "B", "signed char": "b", "char": "c",
                 "double": "d", "float": "f"}
_NUMPY_FORMATS = {np.dtype(np.int32): "i", np.dtype(np.uint8): "B", np.dtype(np.int8): "b",
                  np.dtype(np.float64): "d", np.dtype(np.float32): "f"}


def _item_name(value):
    try:
        return _I(value).name
    except ValueError:
        return str(value)


# ------------------------------------------------------------ pdata buffers

class _Buffer:
    """A buffer an item edits: what keeps it alive, its address, size and format."""

    __slots__ = ("keep", "address", "nbytes", "format")

    def __init__(self, keep, address, nbytes, format):
        self.keep, self.address, self.nbytes, self.format = keep, address, nbytes, format


def _format_of_view(view):
    """The element letter of a memoryview's format ('<i' -> 'i'), or None if foreign."""
    fmt = view.format
    if fmt[:1] in ("<", "@", "="):
        fmt = fmt[1:]
    if fmt.rstrip("s").isdigit() and fmt.endswith("s"):
        return "s"
    return fmt if len(fmt) == 1 else None


def _buffer(value, name):
    """`value` as a _Buffer, or TypeError/ValueError saying what pdata must be."""
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "S":
            fmt = "s"
        else:
            fmt = _NUMPY_FORMATS.get(value.dtype) if value.dtype.isnative else None
        if fmt is None:
            raise TypeError(f"{name}: a NumPy array of dtype {value.dtype} is no element "
                            f"type an mjUI item edits (int32, uint8, float64, float32)")
        if not value.flags.writeable:
            raise ValueError(f"{name}: the array is read-only; MuJoCo writes the item's value")
        if not value.flags.c_contiguous:
            raise ValueError(f"{name}: the array must be C-contiguous")
        holder = ffi.from_buffer(value, require_writable=True)
        # NumPy refuses resize, even with refcheck=False, to an array with a weak reference
        # (a buffer export alone does not stop it)
        locks = []
        base = value
        while isinstance(base, np.ndarray):
            locks.append(weakref.ref(base))
            base = base.base
        return _Buffer((value, holder, locks), int(ffi.cast("uintptr_t", holder)), value.nbytes,
                       fmt)
    if isinstance(value, (ctypes._SimpleCData, ctypes.Array)):
        # from_address objects own nothing and keep nothing alive
        if not (value._b_needsfree_ or value._b_base_ is not None or value._objects):
            raise TypeError(f"{name}: the ctypes object does not own its memory "
                            f"(from_address): nothing would keep that memory alive")
        fmt = _format_of_view(memoryview(value))
        holder = ffi.from_buffer(value, require_writable=True)
        return _Buffer((value, holder), int(ffi.cast("uintptr_t", holder)),
                       ctypes.sizeof(value), fmt)
    if isinstance(value, ffi.CData):
        ctype = ffi.typeof(value)
        # only memory cffi allocated (ffi.new: "owning") is known to live as long as value
        if ctype.kind not in ("pointer", "array") or " owning " not in repr(value):
            raise TypeError(f"{name}: a cffi cdata must be memory from ffi.new (it owns its "
                            f"memory), not {ctype.cname}: a raw pointer may point anywhere")
        item = ctype.item
        while item.kind == "array":
            item = item.item
        fmt = _CFFI_FORMATS.get(item.cname)
        return _Buffer((value,), int(ffi.cast("uintptr_t", value)), len(ffi.buffer(value)),
                       fmt)
    raise TypeError(f"{name} must be a NumPy array, a ctypes object or a cffi cdata from "
                    f"ffi.new, which mjcffi keeps alive for the UI, not {type(value).__name__}")


def _needed(item_type, nelem):
    """(formats, nbytes, element description) item_type needs at its pdata."""
    formats, size, count, label = _NEEDS[item_type]
    return formats, size * (nelem if count is None else count), label


def _fits(buffer, item_type, nelem, name):
    formats, nbytes, label = _needed(item_type, nelem)
    if buffer.format not in formats:
        raise TypeError(f"{name}: an {_item_name(item_type)} item edits {label} elements, "
                        f"and this buffer holds format {buffer.format!r}")
    if buffer.nbytes < nbytes:
        raise ValueError(f"{name}: an {_item_name(item_type)} item reads and writes "
                         f"{nbytes} bytes there, and the buffer has {buffer.nbytes}")


# ------------------------------------------------------------ an mjUI's record

class _Record:
    """What mjcffi keeps for one MjUI: the kept buffers by address, a lock, and NumPy
    views of the item fields that the checks read (one strided view per field)."""

    def __init__(self, pointer):
        self.lock = threading.RLock()
        self.buffers = {}
        raw = np.frombuffer(ffi.buffer(pointer, ffi.sizeof("mjUI")), np.uint8)
        sect, item = ffi.sizeof("mjuiSection"), ffi.sizeof("mjuiItem")
        base = ffi.offsetof("mjUI", "sect")
        items = base + ffi.offsetof("mjuiSection", "item")

        def field(name, dtype):
            offset = items + ffi.offsetof("mjuiItem", name)
            return np.ndarray((mjMAXUISECT, mjMAXUIITEM), dtype, raw, offset, (sect, item))

        self.nitem = np.ndarray((mjMAXUISECT,), np.intc, raw,
                                base + ffi.offsetof("mjuiSection", "nitem"), (sect,))
        self.sect_name = np.ndarray((mjMAXUISECT, mjMAXUINAME), np.uint8, raw,
                                    base + ffi.offsetof("mjuiSection", "name"), (sect, 1))
        self.type = field("type", np.intc)
        self.pdata = field("pdata", np.uintp)
        self.nelem = field("multi", np.intc)        # multi.nelem and edit.nelem alike
        self.name = np.ndarray((mjMAXUISECT, mjMAXUIITEM, mjMAXUINAME), np.uint8, raw,
                               items + ffi.offsetof("mjuiItem", "name"), (sect, item, 1))
        self.multi = np.ndarray((mjMAXUISECT, mjMAXUIITEM, mjMAXUIMULTI, mjMAXUINAME),
                                np.uint8, raw,
                                items + ffi.offsetof("mjuiItem", "multi") + 4,
                                (sect, item, mjMAXUINAME, 1))

    def used(self, nsect):
        """Mask (nsect, mjMAXUIITEM) of the items in use."""
        return np.arange(mjMAXUIITEM) < self.nitem[:nsect, None]

    def prune(self, nsect):
        """Let go of the buffers no item in use points at any more."""
        inuse = set(self.pdata[:nsect][self.used(nsect)].tolist())
        self.buffers = {a: b for a, b in self.buffers.items() if a in inuse}


def _record(ui, name="ui"):
    """The _Record of MjUI `ui` (made on first use); a raw pointer is refused."""
    if getattr(ui, "_cname", None) != "mjUI" or isinstance(ui, type):
        given = "a raw mjUI pointer" if isinstance(ui, ffi.CData) else type(ui).__name__
        raise TypeError(f"{name} must be an MjUI, not {given}: the buffers its items edit "
                        f"are kept alive on the MjUI")
    state = ui.__dict__
    record = state.get("_mjui")
    if record is None:
        record = state.setdefault("_mjui", _Record(ui._ptr))
    return record


# ------------------------------------------------------------ definitions

_FIELDS = ("type", "name", "state", "pdata", "other", "otherint")


def _ascii(value, field, limit, name):
    if not isinstance(value, str):
        raise TypeError(f"{name}.{field} must be str, not {type(value).__name__}")
    raw = value.encode("utf-8")
    if not raw.isascii() or b"\0" in raw:
        raise ValueError(f"{name}.{field} must be ASCII text without NUL: MuJoCo's fonts "
                         f"have 128 characters")
    if len(raw) >= limit:
        raise ValueError(f"{name}.{field} takes at most {limit - 1} characters, got "
                         f"{len(raw)}: {value!r}")
    return raw


def _fields_of(value, name):
    """The six fields of one definition as a dict (pdata: None or a Python object)."""
    if isinstance(value, MjuiDef):
        if value.pdata != ffi.NULL:
            raise TypeError(f"{name}: an MjuiDef's pdata is a raw pointer that nothing keeps "
                            f"alive: give the item as a tuple or dict with pdata a NumPy "
                            f"array, ctypes object or ffi.new cdata")
        return {"type": value.type, "name": value.name, "state": value.state, "pdata": None,
                "other": value.other, "otherint": value.otherint}
    if isinstance(value, Mapping):
        unknown = set(value) - set(_FIELDS)
        if unknown:
            raise TypeError(f"{name} has unknown keys {sorted(map(str, unknown))}; an "
                            f"mjuiDef has {', '.join(_FIELDS)}")
        if "type" not in value:
            raise TypeError(f"{name} has no 'type'")
        fields = dict(value)
    elif isinstance(value, (tuple, list)):
        if not 1 <= len(value) <= len(_FIELDS):
            raise TypeError(f"{name} must have 1 to 6 entries ({', '.join(_FIELDS)}), got "
                            f"{len(value)}")
        fields = dict(zip(_FIELDS, value))
    else:
        raise TypeError(f"{name} must be an MjuiDef, a tuple ({', '.join(_FIELDS)}) or a "
                        f"dict, not {type(value).__name__}")
    fields.setdefault("name", "")
    fields.setdefault("state", 1)
    fields.setdefault("pdata", None)
    fields.setdefault("other", "")
    fields.setdefault("otherint", 0)
    return fields


def _int(value, label):
    try:
        number = operator.index(value)
    except TypeError:
        raise TypeError(f"{label} must be an int, not {type(value).__name__}") from None
    if not -2 ** 31 <= number < 2 ** 31:
        raise ValueError(f"{label}={number} does not fit in a C int")
    return number


def _shortcut(other, name):
    """MuJoCo's shortcut syntax: '' or a modifier (' ', 'C', 'S', 'A') then a key
    character, or '#' and a key code."""
    if not other:
        return
    if not 2 <= len(other) <= 5 or other[0] not in " CSA":
        raise ValueError(f"{name}.other={other!r} is no shortcut: '' or a modifier (' ', "
                         f"'C', 'S', 'A') then a key, or '#' and a key code")
    if other[1] == "#":
        if not re.match(r"\s*[+-]?[0-9]", other[2:]):
            raise ValueError(f"{name}.other={other!r}: '#' must be followed by a key code")
    elif len(other) != 2:
        raise ValueError(f"{name}.other={other!r}: one key character after the modifier")


def _numbers(other, most):
    """The leading numbers of `other`, at most `most` (sscanf's "%lf %lf ...")."""
    out = []
    for token in other.split()[:most]:
        try:
            out.append(float(token))
        except ValueError:
            break
    return out


def _other(kind, other, name):
    """What MuJoCo parses from an item's `other`; returns the edit count (or 0)."""
    if kind in _SHORTCUT:
        _shortcut(other, name)
    elif kind in _MULTI:
        parts = other.split("\n")
        if other.endswith("\n"):
            parts.pop()
        parts = parts if other else []
        if len(parts) > mjMAXUIMULTI:
            raise ValueError(f"{name}.other has {len(parts)} elements, at most "
                             f"{mjMAXUIMULTI} (mjMAXUIMULTI)")
        for part in parts:
            if not part or len(part) >= mjMAXUINAME - 1:
                raise ValueError(f"{name}.other: element {part!r} must have 1 to "
                                 f"{mjMAXUINAME - 2} characters (newline-separated names)")
        if kind in _CHOICE and not parts:
            raise ValueError(f"{name}.other must name the choices, one per line")
    elif kind in _SLIDER:
        if len(_numbers(other, 3)) < 2:
            raise ValueError(f"{name}.other={other!r}: a slider takes 'min max [divisions]'")
    elif kind in _EDIT:
        x = _numbers(other, 1 + 2 * mjMAXUIEDIT)
        if not x:
            raise ValueError(f"{name}.other={other!r}: an edit takes 'n [min max]*n'")
        nelem = math.floor(x[0] + 0.5)          # mju_round
        if not 1 <= nelem <= mjMAXUIEDIT:
            raise ValueError(f"{name}.other: the edit length {nelem} must be within "
                             f"1..{mjMAXUIEDIT} (mjMAXUIEDIT)")
        if len(x) > 1 and len(x) - 1 != 2 * nelem:
            raise ValueError(f"{name}.other: {nelem} elements need {2 * nelem} range "
                             f"numbers, got {len(x) - 1}")
        return nelem
    return 0


def _checked(fields, name):
    """(C values of one definition, its _Buffer or None)."""
    kind = _int(fields["type"], f"{name}.type")
    if kind == int(_I.mjITEM_END):
        raise ValueError(f"{name}.type is mjITEM_END: mjui_add ends the list itself")
    if kind != _SECTION and not 0 <= kind < _NITEM:
        raise ValueError(f"{name}.type={kind} is no mjtItem (mjITEM_SECTION or "
                         f"0..{_NITEM - 1})")
    state = _int(fields["state"], f"{name}.state")
    otherint = _int(fields["otherint"], f"{name}.otherint")
    limit = mjMAXUINAME - 1 if kind == _SECTION else mjMAXUINAME
    label = _ascii(fields["name"], "name", limit, name)
    other = _ascii(fields["other"], "other", mjMAXUITEXT, name)
    pdata, buffer = fields["pdata"], None
    if kind == _SECTION:
        if state not in _SECTION_STATES:
            raise ValueError(f"{name}.state={state} is no section state (mjSECT_CLOSED, "
                             f"mjSECT_OPEN, mjSECT_FIXED or mjPRESERVE)")
        _shortcut(other.decode(), name)
    else:
        if state < 0:
            raise ValueError(f"{name}.state={state}: an item state is 0 (disabled), 1 "
                             f"(enabled) or more (the predicate's category)")
        nelem = _other(kind, other.decode(), name)
    if kind > _BUTTON:
        if pdata is None:
            raise TypeError(f"{name}: an {_item_name(kind)} item edits a value: pdata must "
                            f"be a NumPy array, ctypes object or ffi.new cdata")
        buffer = _buffer(pdata, f"{name}.pdata")
        _fits(buffer, kind, nelem, f"{name}.pdata")
    elif pdata is not None:
        raise TypeError(f"{name}: an {_item_name(kind)} has no data; pdata must be None")
    return (kind, label, state, buffer, other, otherint), buffer


def _definitions(defs, name="def_"):
    if isinstance(defs, (str, bytes, Mapping, MjuiDef)) or not hasattr(defs, "__iter__"):
        raise TypeError(f"{name} must be a sequence of definitions (MjuiDef, tuple or dict), "
                        f"not {type(defs).__name__}")
    return [_checked(_fields_of(d, f"{name}[{i}]"), f"{name}[{i}]")[0]
            for i, d in enumerate(defs)]


def _c_array(rows):
    """An mjuiDef[] of `rows`, ended by mjITEM_END."""
    array = ffi.new("mjuiDef[]", len(rows) + 1)
    for i, (kind, label, state, buffer, other, otherint) in enumerate(rows):
        entry = array[i]
        entry.type, entry.name, entry.state = kind, label, state
        entry.pdata = ffi.cast("void *", buffer.address) if buffer else ffi.NULL
        entry.other, entry.otherint = other, otherint
    array[len(rows)].type = int(_I.mjITEM_END)
    return array


def _layout(rows, nsect, nitem, name):
    """Refuse what MuJoCo would: too many sections or items, items before a section."""
    current = nsect - 1
    counts = list(nitem[:nsect]) + [0] * (mjMAXUISECT - nsect)
    for i, row in enumerate(rows):
        if row[0] == _SECTION:
            current += 1
            if current >= mjMAXUISECT:
                raise ValueError(f"{name}[{i}]: the UI would have more than {mjMAXUISECT} "
                                 f"sections (mjMAXUISECT)")
            counts[current] = 0
        else:
            if current < 0:
                raise ValueError(f"{name}[{i}]: an item before any section (the first "
                                 f"definition of an empty UI must be mjITEM_SECTION)")
            counts[current] += 1
            if counts[current] > mjMAXUIITEM:
                raise ValueError(f"{name}[{i}]: section {current} would have more than "
                                 f"{mjMAXUIITEM} items (mjMAXUIITEM)")


def _add(ui, record, rows, call):
    """Run `call(c_array)` with the buffers recorded; on an error restore the mjUI."""
    pointer = ui._ptr
    before = ffi.buffer(pointer, ffi.sizeof("mjUI"))[:]
    added = {row[3].address: row[3] for row in rows if row[3] is not None}
    saved = dict(record.buffers)
    record.buffers.update(added)
    array = _c_array(rows)
    try:
        _m.check(call(array))
    except BaseException:
        ffi.memmove(pointer, before, len(before))
        record.buffers = saved
        raise
    _forget_stale_focus(pointer, record)
    record.prune(pointer.nsect)


def _forget_stale_focus(pointer, record):
    """Drop mouse and edit focus on an item that the new layout no longer has."""
    for sect, item in (("mousesect", "mouseitem"), ("editsect", "edititem")):
        s = getattr(pointer, sect)
        if s > 0 and (s > pointer.nsect or not 0 <= getattr(pointer, item) < record.nitem[s - 1]):
            setattr(pointer, sect, 0)


@_p.preparable(None)
def mjui_add(ui, def_):
    """Python: def_ is a sequence of definitions, each an MjuiDef (items without data),
    a tuple (type, name, state, pdata, other, otherint) or a dict of those keys (name
    '', state 1, pdata None, other '', otherint 0 by default); mjcffi ends the list
    with mjITEM_END.  pdata, for the items that edit a value, must be a writable
    C-contiguous NumPy array, a ctypes object owning its memory or a cffi ffi.new cdata,
    of the item's element type (int32; uint8 for mjITEM_CHECKBYTE; float64 for
    mjITEM_SLIDERNUM and mjITEM_EDITNUM; float32 for mjITEM_EDITFLOAT; 40 chars for
    mjITEM_EDITTXT) and size; the MjUI keeps it alive.  Bad definitions raise
    TypeError or ValueError (too many sections or items: ValueError) and leave ui as
    it was."""
    record = _record(ui)
    rows = _definitions(def_)
    with record.lock:
        pointer = ui._ptr
        _layout(rows, pointer.nsect, record.nitem, "def_")
        _add(ui, record, rows, lambda array: lib.mjcffi_guard_mjui_add(pointer, array))


@_p.preparable(None)
def mjui_addToSection(ui, sect, def_):
    """Python: as mjui_add, adding items (no sections) to section sect, one of the
    sections ui has."""
    record = _record(ui)
    sect = _int(sect, "sect")
    rows = _definitions(def_)
    with record.lock:
        pointer = ui._ptr
        if not 0 <= sect < pointer.nsect:
            raise ValueError(f"sect={sect}: ui has sections 0..{pointer.nsect - 1}")
        for i, row in enumerate(rows):
            if row[0] == _SECTION:
                raise ValueError(f"def_[{i}] is a section: mjui_addToSection adds items")
        if record.nitem[sect] + len(rows) > mjMAXUIITEM:
            raise ValueError(f"section {sect} would have {record.nitem[sect] + len(rows)} "
                             f"items, more than {mjMAXUIITEM} (mjMAXUIITEM)")
        _add(ui, record, rows,
             lambda array: lib.mjcffi_guard_mjui_addToSection(pointer, sect, array))


# ------------------------------------------------------------ checks before a call

def _check_text(raw, what):
    """Bytes of a char[] field: a NUL within, and ASCII before it."""
    zero = raw == 0
    if not zero.any(axis=-1).all():
        raise ValueError(f"{what} has no terminating NUL")
    first = zero.argmax(axis=-1)
    high = (raw >= 128) & (np.arange(raw.shape[-1]) < first[..., None])
    if high.any():
        raise ValueError(f"{what} must be ASCII: MuJoCo's fonts have 128 characters")


def _check_ui(pointer, record):
    """What MuJoCo follows in the mjUI without checks (see the module docstring)."""
    nsect = pointer.nsect
    if not 0 <= nsect <= mjMAXUISECT:
        raise ValueError(f"ui.nsect={nsect} is outside 0..{mjMAXUISECT}")
    nitem = record.nitem[:nsect]
    if ((nitem < 0) | (nitem > mjMAXUIITEM)).any():
        raise ValueError(f"ui.sect[].nitem must be within 0..{mjMAXUIITEM}")
    if not 0 <= pointer.rectid < mjMAXUIRECT:
        raise ValueError(f"ui.rectid={pointer.rectid} is outside 0..{mjMAXUIRECT - 1} "
                         f"(mjuiState.rect)")
    if not 0 <= pointer.auxid < mjNAUX:
        raise ValueError(f"ui.auxid={pointer.auxid} is outside 0..{mjNAUX - 1} (mjNAUX)")
    if pointer.radiocol < 0:
        raise ValueError(f"ui.radiocol={pointer.radiocol} must not be negative")
    _check_focus(pointer, nsect, nitem)
    used = record.used(nsect)
    _check_text(record.sect_name[:nsect], "a section name")
    _check_text(record.name[:nsect][used], "an item name")
    types = record.type[:nsect]
    bad = used & ((types < 0) | (types >= _NITEM))
    if bad.any():
        s, i = map(int, np.argwhere(bad)[0])
        raise ValueError(f"ui.sect[{s}].item[{i}].type={int(types[s, i])} is no item type")
    for s, i in np.argwhere(used & (types > _BUTTON)).tolist():
        _check_data(record, s, i, int(types[s, i]), int(record.nelem[s, i]),
                    int(record.pdata[s, i]))
    for s, i in np.argwhere(used & np.isin(types, list(_MULTI))).tolist():
        nelem = int(record.nelem[s, i])
        if nelem:
            _check_text(record.multi[s, i, :nelem], f"ui.sect[{s}].item[{i}].multi.name")


def _check_focus(pointer, nsect, nitem):
    for sect, item, low in (("mousesect", "mouseitem", -1), ("editsect", "edititem", 0)):
        s = getattr(pointer, sect)
        if not low <= s <= nsect:
            raise ValueError(f"ui.{sect}={s} is outside {low}..{nsect} (ui.nsect)")
        if s > 0 and not 0 <= getattr(pointer, item) < nitem[s - 1]:
            raise ValueError(f"ui.{item}={getattr(pointer, item)} is no item of section "
                             f"{s - 1} ({nitem[s - 1]} items)")
    text = ffi.string(pointer.edittext)
    if not text.isascii():
        raise ValueError("ui.edittext must be ASCII")
    for field in ("editcursor", "editscroll"):
        if pointer.editsect > 0 and not 0 <= getattr(pointer, field) <= len(text):
            raise ValueError(f"ui.{field}={getattr(pointer, field)} is outside "
                             f"0..{len(text)} (the edit text's length)")


def _check_data(record, s, i, kind, nelem, address):
    where = f"ui.sect[{s}].item[{i}]"
    buffer = record.buffers.get(address)
    if buffer is None:
        raise ValueError(f"{where}.pdata points at memory that mjui_add did not record: "
                         f"add the item with mjui_add")
    if kind in _EDIT and not 0 <= nelem <= mjMAXUIEDIT:
        raise ValueError(f"{where}.edit.nelem={nelem} is outside 0..{mjMAXUIEDIT}")
    _fits(buffer, kind, nelem, f"{where}.pdata")
    if kind in _CHOICE:
        value = ffi.cast("int *", address)[0]
        if not 0 <= value < max(nelem, 1):
            raise ValueError(f"{where} ({_item_name(kind)}): its value {value} is no index "
                             f"of its {nelem} choices")


def _state(state):
    pointer = _m.struct(state, "mjuiState", "state")
    if not 0 <= pointer.nrect <= mjMAXUIRECT:
        raise ValueError(f"state.nrect={pointer.nrect} is outside 0..{mjMAXUIRECT}")
    return pointer


def _begin(ui, state, con, func):
    """(record, ui pointer, state pointer, con pointer), all checked, for `func`."""
    record = _record(ui)
    c_state = _state(state) if state is not None else None
    _m.struct(con, "mjrContext", "con")
    _mjr.context(con, "con", func)
    return record, c_state


def _rect_in_use(pointer, c_state):
    if pointer.rectid >= max(c_state.nrect, 1):
        raise ValueError(f"ui.rectid={pointer.rectid}, but state.nrect={c_state.nrect}: "
                         f"state.rect[{pointer.rectid}] (the UI's rectangle) is not in use")


@_p.preparable(None)
def mjui_resize(ui, con):
    """Python: con must be an MjrContext made in the OpenGL context current on this
    thread."""
    record, _ = _begin(ui, None, con, "mjui_resize")
    with record.lock:
        _check_ui(ui._ptr, record)
        _m.check(lib.mjcffi_guard_mjui_resize(ui._ptr, con._ptr))


@_p.preparable(None)
def mjui_update(section, item, ui, state, con):
    """Python: section is -1 (all) or a section of ui, item -1 (all) or an item of that
    section; con must be an MjrContext made in the OpenGL context current on this
    thread."""
    section, item = _int(section, "section"), _int(item, "item")
    record, c_state = _begin(ui, state, con, "mjui_update")
    with record.lock:
        pointer = ui._ptr
        _check_ui(pointer, record)
        _rect_in_use(pointer, c_state)
        if not -1 <= section < pointer.nsect:
            raise ValueError(f"section={section} is outside -1..{pointer.nsect - 1}")
        if section >= 0 and not -1 <= item < record.nitem[section]:
            raise ValueError(f"item={item} is outside -1..{record.nitem[section] - 1}")
        _m.check(lib.mjcffi_guard_mjui_update(section, item, pointer, c_state, con._ptr))


@_p.preparable(None)
def mjui_event(ui, state, con):
    """Python: returns the MjuiItem the event changed (a view into ui), or None; con
    must be an MjrContext made in the OpenGL context current on this thread."""
    record, c_state = _begin(ui, state, con, "mjui_event")
    with record.lock:
        pointer = ui._ptr
        _check_ui(pointer, record)
        _rect_in_use(pointer, c_state)
        changed = lib.mjcffi_guard_mjui_event(pointer, c_state, con._ptr)
        _m.check_error()
    return None if changed == ffi.NULL else MjuiItem._wrap(changed, ui._root)


@_p.preparable(None)
def mjui_render(ui, state, con):
    """Python: con must be an MjrContext made in the OpenGL context current on this
    thread; the UI's image is the aux buffer ui.auxid (mjr_addAux, then mjui_update)."""
    record, c_state = _begin(ui, state, con, "mjui_render")
    with record.lock:
        pointer = ui._ptr
        _check_ui(pointer, record)
        _rect_in_use(pointer, c_state)
        _m.check(lib.mjcffi_guard_mjui_render(pointer, c_state, con._ptr))
