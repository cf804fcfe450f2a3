"""What sizes mjData's buffers: the actuators' transmissions (the moment entries
they write), outputs, controls and activations; the delay buffers; plugin states
and gravity-compensated bodies; and the strings and the name hash map."""

import numpy as np

from ..._generated import enums as _enums
from ..library import lib
from .mjb import POINTERS, ROWS, check_range, check_slice, covers, fail
from .references import JOINT, SITE, check_object
from .tree import NV, body_dofs, chain

_OBJ = _enums.mjtObj
_TRN = _enums.mjtTrn
_TRN_OBJECTS = {_TRN.mjTRN_JOINT: (JOINT, None), _TRN.mjTRN_JOINTINPARENT: (JOINT, None),
                _TRN.mjTRN_TENDON: (int(_OBJ.mjOBJ_TENDON), None),
                _TRN.mjTRN_BODY: (int(_OBJ.mjOBJ_BODY), None),
                _TRN.mjTRN_SLIDERCRANK: (SITE, SITE)}


def _transmission(m, tree, a, trntype, first, second):
    """Check actuator a's transmission ids; the moment entries it writes (nJmom's).
    `tree`: body_parentid, body_weldid, the bodies' dofs, site_bodyid, jnt_type."""
    if trntype == _TRN.mjTRN_UNDEFINED:
        return 0
    if trntype in _TRN_OBJECTS:
        kinds = _TRN_OBJECTS[trntype]
    elif trntype == _TRN.mjTRN_SITE:
        kinds = (SITE, SITE if second != -1 else None)
    else:                                               # SO3: a ball joint, or two sites
        kinds = (JOINT, None) if second == -1 else (SITE, SITE)
    for col, (kind, value) in enumerate(zip(kinds, (first, second))):
        if kind is None and value != -1:
            fail("actuator_trnid", f"{a}, {col}", value, "this transmission has one id (-1)")
        if kind is not None:
            check_object(m, "actuator_trnid", f"{a}, {col}", kind, value)
    parent, weld, own, site_body, jnt_type = tree
    if trntype in (_TRN.mjTRN_JOINT, _TRN.mjTRN_JOINTINPARENT):
        return NV[jnt_type[first]]
    if trntype == _TRN.mjTRN_SO3:
        if second == -1 and jnt_type[first] != 1:
            fail("actuator_trnid", f"{a}, 0", first, "an SO3 transmission drives a ball joint")
        return 3 if second == -1 else 3 * m.nv
    if trntype == _TRN.mjTRN_TENDON:
        return int(m.arrays["ten_J_rownnz"][first, 0])
    if trntype == _TRN.mjTRN_BODY:
        return m.nv
    one = chain(site_body[first], parent, weld, own)
    if trntype == _TRN.mjTRN_SLIDERCRANK:
        return len(one | chain(site_body[second], parent, weld, own))
    other = chain(site_body[second] if second >= 0 else 0, parent, weld, own)
    return len(one ^ other)


def _blocks(m, adr_field, num_field, total_size, none=False):
    """Addresses one block after another (actuator_ctrladr/ctrlnum), summing to a size;
    with `none`, an empty block has the address -1."""
    at = 0
    for k, (adr, num) in enumerate(zip(m.flat(adr_field), m.flat(num_field))):
        want = -1 if none and num == 0 else at
        if adr != want:
            fail(adr_field, k, adr, f"its block of {num} starts at {want}")
        at += num
    if at != m.sizes[total_size]:
        fail(total_size, None, m.sizes[total_size], f"{num_field} adds up to {at}")


@covers("actuator_trntype", "actuator_trnid", "actuator_outadr", "actuator_outnum",
        "actuator_ctrladr", "actuator_ctrlnum", "actuator_actadr", "actuator_actnum")
def check_actuators(m):
    """Transmissions by type, outputs, controls and activations in blocks, and nJmom:
    exactly the moment entries the transmissions write (mj_transmission)."""
    entries = 0
    outnum = m.flat("actuator_outnum")
    tree = (m.flat("body_parentid"), m.flat("body_weldid"), body_dofs(m),
            m.flat("site_bodyid"), m.flat("jnt_type"))
    for a, (t, (first, second)) in enumerate(zip(m.flat("actuator_trntype"),
                                                 m.arrays["actuator_trnid"].tolist())):
        entries += _transmission(m, tree, a, t, first, second)
        want = 3 if t == _TRN.mjTRN_SO3 else 1
        if outnum[a] != want:
            fail("actuator_outnum", a, outnum[a], f"this transmission has {want} outputs")
    if m.nJmom != entries:
        fail("nJmom", None, m.nJmom, f"the transmissions write {entries} moment entries")
    _blocks(m, "actuator_outadr", "actuator_outnum", "nout")
    _blocks(m, "actuator_ctrladr", "actuator_ctrlnum", "nu")
    _blocks(m, "actuator_actadr", "actuator_actnum", "na", none=True)


@covers("actuator_history", "actuator_historyadr", "sensor_history", "sensor_historyadr")
def check_history(m):
    """Delay buffers: [nsample, interp] and their addresses, one after another (actuators
    2 + 2n numbers, sensors 2 + n + n*dim), summing to nhistory; a delay or an interval
    (floats MuJoCo reads the buffer by) needs samples."""
    total = 0
    dims = m.flat("sensor_dim")
    for kind in ("actuator", "sensor"):
        history = m.arrays[f"{kind}_history"].tolist()
        adrs = m.flat(f"{kind}_historyadr")
        delay = m.arrays[f"{kind}_delay"].ravel()
        interval = (m.arrays["sensor_interval"][:, 0] if kind == "sensor"
                    else np.zeros(len(delay)))
        for i, (n, interp) in enumerate(history):
            if n < 0 or not 0 <= interp <= 2:
                fail(f"{kind}_history", i, [n, interp], "nsample >= 0, interp 0, 1 or 2")
            if n == 0:
                if adrs[i] != -1:
                    fail(f"{kind}_historyadr", i, adrs[i], "no samples: no buffer (-1)")
                if delay[i] > 0 or interval[i] > 0:
                    fail(f"{kind}_history", i, [n, interp], "a delay or an interval needs "
                         "samples")
                continue
            if adrs[i] != total:
                fail(f"{kind}_historyadr", i, adrs[i], f"its buffer starts at {total}")
            total += 2 + 2 * n if kind == "actuator" else 2 + n + n * dims[i]
    if total != m.nhistory:
        fail("nhistory", None, m.nhistory, f"the delay buffers hold {total} numbers")


@covers("plugin", "plugin_statenum", "body_simple")
def check_plugins(m):
    """Plugin slots registered, their state adding up; gravcomp bodies counted."""
    count = lib.mjp_pluginCount()
    for p, slot in enumerate(m.flat("plugin")):
        if not 0 <= slot < count:
            fail("plugin", p, slot, f"a plugin instance names a registered slot, in "
                 f"[0, {count})")
    states = int(m.arrays["plugin_statenum"].sum())
    if states != m.npluginstate:
        fail("npluginstate", None, m.npluginstate, f"the plugins have {states} states")
    gravcomp = int((m.arrays["body_gravcomp"] != 0).sum())
    if gravcomp != m.ngravcomp:
        fail("ngravcomp", None, m.ngravcomp, f"{gravcomp} bodies have gravcomp")
    check_range(m, "body_simple", 0, 3, "0, 1 (diagonal M) or 2 (and sliders only)")


_NAME_SLOTS = 2               # MuJoCo's mjLOAD_MULTIPLE: hash map slots per named object
_NAMED = tuple(f.name for f in POINTERS if f.name.startswith("name_") and f.name.endswith("adr"))


@covers("names_map", "plugin_attr")
def check_strings(m):
    """Strings end with a NUL; the name hash map has its slots per category, each -1
    or an id of that category."""
    for name in ("names", "paths", "text_data", "plugin_attr"):
        data = m.arrays[name].ravel()
        if data.size and data[-1] != 0:
            fail(name, data.size - 1, int(data[-1]), "the strings end with a NUL")
    named = [(name, m.sizes[ROWS[name]]) for name in _NAMED]
    total = _NAME_SLOTS * sum(n for _, n in named)
    if m.nnames_map != total:
        fail("nnames_map", None, m.nnames_map, f"{_NAME_SLOTS} hash map slots per name "
             f"make {total}")
    names_map = m.arrays["names_map"].ravel()
    counts = [n for _, n in named]
    if ((names_map >= -1) & (names_map < np.repeat(counts, [_NAME_SLOTS * n for n in counts]))
            ).all():
        return
    at = 0
    for _, n in named:
        check_slice(names_map[at:at + _NAME_SLOTS * n], "names_map", at, -1, n)
        at += _NAME_SLOTS * n
