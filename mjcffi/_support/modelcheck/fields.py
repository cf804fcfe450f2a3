"""The integer fields classified from the struct metadata (mjcffi/_generated/structinfo.py),
and the checks that need nothing but the classification: the ids of another
category (`jnt_bodyid`, `geom_matid`, `*_plugin`...) within its count; the
address/count pairs (`body_dofadr`/`body_dofnum`, `*_rowadr`/`*_rownnz`,
`name_*adr`...) within the array they address; the types (`(mjtGeom)` in a
field's comment) within their enum.

INDEX_FIELDS are the integer fields whose values MuJoCo uses as ids, addresses,
counts or types of other arrays: the checks cover them all but a few flags and
bits that are only compared (tests/test_model_validation.py lists them), and
Batch.expand refuses to let them differ between simulations (mjcffi/batch/_batch.py).
"""

import re

import numpy as np

from ..._generated import enums as _enums
from ..._generated.structinfo import STRUCTS
from .mjb import DOCS, INT_FIELDS, POINTERS, ROWS, SIZES, check_range, covers, fail, first

# ------------------------------------------------------------------ categories and ids
#
# The categories of objects are the prefixes of mjModel's arrays; a category's count
# is n<prefix>, or the row count all its arrays share (dof_* have nv rows).


def _categories():
    rows = {}
    for field in POINTERS:
        prefix = field.name.split("_")[0]
        if prefix.islower() and prefix.isalpha() and prefix not in ("name", field.name):
            rows.setdefault(prefix, set()).add(ROWS[field.name])
    out = {prefix: "n" + prefix if "n" + prefix in SIZES else next(iter(counts))
           for prefix, counts in rows.items() if "n" + prefix in SIZES or len(counts) == 1}
    out["mocap"] = "nmocap"                 # body_mocapid: no mocap_* array, only keys'
    return out


CATEGORIES = _categories()          # 'body' -> 'nbody', 'dof' -> 'nv', ...

# Ids whose category a type decides, and ids local to one object (a flex's
# vertices): checked by the relations of the other modules, not as plain ids.
_NOT_PLAIN_IDS = {"geom_dataid", "site_dataid", "bvh_nodeid", "sensor_objid", "sensor_refid",
                  "eq_obj1id", "eq_obj2id", "tuple_objid", "wrap_objid", "actuator_trnid",
                  "skin_bonevertid"}


def _id_category(name):
    """(count size, lowest id) of an id field, from its name and comment; None if not one.

    An id field ends with 'id' (or is a plugin instance, or its comment says ids);
    its category is the longest category name its stem ends with ('targetbodyid'
    -> body), or its own for a parent, root or weld.  An owner (a joint's body, a
    dof's joint or tree, a body's root) always exists: its lowest id is 0; where
    the comment allows none ('-1: none'), or the name ('target'), -1; and an
    'id of' a comment does not say may be -1 is always one."""
    doc = DOCS[name]
    prefix, _, stem = name.partition("_")
    if name in _NOT_PLAIN_IDS or not stem or "index" in doc:
        return None
    if not (stem.endswith("id") or stem == "plugin" or re.search(r"\bids?\b|\bindices\b", doc)):
        return None
    stem = re.sub(r"ids?$|\d$", "", stem)       # 'parentid' -> 'parent', 'geom1' -> 'geom'
    if stem in ("parent", "root", "weld"):
        return CATEGORIES[prefix], (-1 if prefix == "dof" else 0)
    for word in sorted(CATEGORIES, key=len, reverse=True):
        if stem.endswith(word):
            owner = doc.startswith("id of") or (prefix, word) == ("dof", "tree") or (
                stem.endswith(("body", "jnt")) and "target" not in stem)
            return CATEGORIES[word], 0 if owner and "-1" not in doc else -1
    return None


ID_FIELDS = {name: cat for name in INT_FIELDS if (cat := _id_category(name))}
ID_FIELDS["efmC_perm"] = ("nv", -1)         # 'vertex dof or -1'
ID_FIELDS["flex_vertbodyid"] = ("nbody", -1)  # -1: an interpolated flex's (geometry.py)

# ------------------------------------------------------------------ spans
#
# An address field and what it addresses: `<p>_<x>adr` with its count `<p>_<x>num`
# (`<p>_adr` with `<p>_num`, `_size` or `_dim`; `rowadr` with `rownnz`), into the
# array of n<p><x>, n<x>, n<p>data or an alias.

_ALIASES = {"dof": "nv", "qpos": "nq", "ctrl": "nu", "act": "na", "path": "npaths",
            "contenttype": "npaths", "state": "npluginstate", "attr": "npluginattr",
            ("skin", "texcoord"): "nskintexvert", ("tendon", ""): "nwrap"}


def _span(name):
    """(count field or None, target size) of an address field; None if not one."""
    if name.startswith("name_"):
        return None, "nnames"
    if not name.endswith("adr"):
        return None
    prefix, _, stem = name.partition("_")
    x = stem[:-3]
    if x.endswith("row"):                               # CSR: rowadr, rownnz, colind
        base = name[:-len("rowadr")]
        return base + "rownnz", ROWS[base + "colind"]
    counts = (f"{prefix}_{x}num",) if x else (f"{prefix}_num", f"{prefix}_size", f"{prefix}_dim")
    count = next((c for c in counts if c in INT_FIELDS), None)
    for target in (_ALIASES.get((prefix, x)), _ALIASES.get(x),
                   f"n{prefix}{x}" if x else f"n{prefix}data", f"n{x}" if x else None):
        if target in SIZES:
            return count, target
    return None


SPANS = {name: span for name in INT_FIELDS if (span := _span(name))}

# ------------------------------------------------------------------ enums

ENUMS = {name.lower(): getattr(_enums, name) for name in dir(_enums) if name.startswith("mjt")}


def _enum_values(name):
    """The values an enum field holds: its enum's members below the mjN count member."""
    match = re.search(r"\((mjt\w+)\)", DOCS.get(name, ""))
    enum = ENUMS.get(match.group(1).lower()) if match else None
    if enum is None:
        return None
    counts = [int(v) for k, v in enum.__members__.items() if k.startswith("mjN")]
    limit = min(counts) if counts else None
    return enum.__name__, frozenset(int(v) for k, v in enum.__members__.items()
                                    if not k.startswith("mjN") and (limit is None or v < limit))


ENUM_FIELDS = {f.name: e for f in POINTERS if f.elem in ("int", "mjtByte")
               and (e := _enum_values(f.name))}
ENUM_FIELDS["tuple_objtype"] = ENUM_FIELDS["sensor_objtype"]
CONDIM_FIELDS = ("geom_condim", "pair_dim", "flex_condim")
_CONDIMS = (1, 3, 4, 6)

# ------------------------------------------------------------------ index fields
#
# Integer fields named or described as ids, addresses, counts, sizes, sparse
# structure, maps or types, and the few structural flags their comments do not mark.

_INDEX_SUFFIXES = ("id", "ids", "adr", "num", "nnz", "colind", "diag", "signature", "perm",
                   "type", "_size", "_dim", "_history")
_INDEX_WORDS = re.compile(r"\bids?\b|address|\baddr\b|number of|\bindex|indices|pointers|"
                          r"\(mjt\w+|\btype\b|resolution|parameters|signature|history|"
                          r"interpolation|bits")
_STRUCTURAL = {"body_simple", "flex_dim", "flex_edgeequality", "flex_elemlayer", "flex_elem",
               "flex_edge", "flex_shell", "flex_edgeflap", "flex_elemedge", "flex_elemtexcoord",
               "flex_rigid", "flexedge_rigid", "plugin", "plugin_attr", "names_map",
               "mesh_face", "mesh_facenormal", "mesh_facetexcoord", "mesh_polyvert",
               "mesh_polymap", "mesh_graph", "mesh_extrema", "skin_face", "bvh_child",
               "oct_child"}


def _is_index_field(field):
    name = field.name
    if field.elem in ("mjtNum", "float", "void") or name.endswith("contype"):
        return False                    # numbers, and contact bitmasks (compared only)
    if name in _STRUCTURAL:
        return True
    return field.elem != "char" and (
        name.endswith(_INDEX_SUFFIXES) or name.startswith(("name_", "map"))
        or bool(_INDEX_WORDS.search(field.doc)))


INDEX_FIELDS = frozenset(f.name for f in POINTERS if _is_index_field(f))

# ------------------------------------------------------------------ checks


@covers()
def check_options(m):
    for name in ("integrator", "cone", "jacobian", "solver"):
        doc = next(f.doc for f in STRUCTS["mjOption"] if f.name == name)
        enum = ENUMS[re.search(r"\((mjt\w+)\)", doc).group(1).lower()]
        value = getattr(m.opt, name)
        if value not in {int(v) for v in enum}:
            fail(f"opt.{name}", None, value, f"not a value of {enum.__name__}")


# Each check below first tests all its fields in one pass over their values joined
# (the fast path, taken by every sound model), and only on a failure walks them
# one by one to name the first wrong value.

def _joined(m, names):
    """The values of fields `names` in one array, and how many each field has."""
    columns = [m.arrays[name].ravel() for name in names]
    return np.concatenate(columns).astype(np.int64), [len(c) for c in columns]


def _table(allowed):
    """(lowest, one past the highest, allowed[value - lowest]) of a set of values."""
    low, high = min(allowed), max(allowed) + 1
    table = np.zeros(high - low, bool)
    table[[v - low for v in allowed]] = True
    return low, high, table


def _all_allowed(values, counts, tables):
    """Whether each value is allowed by the table (`_table`) of its field."""
    low = np.repeat([t[0] for t in tables], counts)
    high = np.repeat([t[1] for t in tables], counts)
    if not ((values >= low) & (values < high)).all():
        return False
    starts = np.cumsum([0] + [len(t[2]) for t in tables[:-1]])
    joined = np.concatenate([t[2] for t in tables])
    return bool(joined[np.repeat(starts, counts) + values - low].all())


_ENUM_TABLES = [_table(values) for _, values in ENUM_FIELDS.values()]


@covers(*ENUM_FIELDS)
def check_enums(m):
    values, counts = _joined(m, ENUM_FIELDS)
    if _all_allowed(values, counts, _ENUM_TABLES):
        return
    for name, (enum, allowed) in ENUM_FIELDS.items():
        column = m.arrays[name].ravel()
        bad = ~np.isin(column, np.fromiter(allowed, np.int64))
        if bad.any():
            k = first(bad)
            fail(name, k, int(column[k]), f"not a value of {enum} that a model holds")


_CONDIM_TABLE = _table(_CONDIMS)


@covers(*CONDIM_FIELDS)
def check_condims(m):
    values, counts = _joined(m, CONDIM_FIELDS)
    if _all_allowed(values, counts, [_CONDIM_TABLE] * len(CONDIM_FIELDS)):
        return
    for name in CONDIM_FIELDS:
        column = m.arrays[name].ravel()
        bad = ~np.isin(column, _CONDIMS)
        if bad.any():
            k = first(bad)
            fail(name, k, int(column[k]), "a contact dimensionality is 1, 3, 4 or 6")


_ID_LOWEST = [lowest for _, lowest in ID_FIELDS.values()]


@covers(*ID_FIELDS)
def check_ids(m):
    values, counts = _joined(m, ID_FIELDS)
    high = np.repeat([m.sizes[count] for count, _ in ID_FIELDS.values()], counts)
    if ((values >= np.repeat(_ID_LOWEST, counts)) & (values < high)).all():
        return
    for name, (count, lowest) in ID_FIELDS.items():
        n = m.sizes[count]
        check_range(m, name, lowest, n, f"an id of {count[1:]} must be in [{lowest}, {n})")


_ADDRESSES = tuple(name for name, (count, _) in SPANS.items() if count is None)
_COUNTED = tuple(name for name, (count, _) in SPANS.items() if count is not None)


def _spans_hold(m):
    """Whether every span is in range (the conditions of check_spans, all at once)."""
    adr, counts = _joined(m, _ADDRESSES)
    size = np.repeat([m.sizes[SPANS[name][1]] for name in _ADDRESSES], counts)
    if not ((adr >= -1) & (adr < size)).all():
        return False
    adr, counts = _joined(m, _COUNTED)
    num, _ = _joined(m, [SPANS[name][0] for name in _COUNTED])
    size = np.repeat([m.sizes[SPANS[name][1]] for name in _COUNTED], counts)
    return bool(((num >= 0) & (adr >= -1) & (adr <= size)
                 & ((num == 0) | ((adr >= 0) & (adr + num <= size)))).all())


@covers(*SPANS, *(count for count, _ in SPANS.values() if count))
def check_spans(m):
    if _spans_hold(m):
        return
    for name, (count, target) in SPANS.items():
        size = m.sizes[target]
        adr = m.arrays[name].ravel().astype(np.int64)
        if count is None:
            bad = (adr != -1) & ((adr < 0) | (adr >= size))
            if bad.any():
                k = first(bad)
                fail(name, k, int(adr[k]), f"an address must be -1 or in [0, {size})")
            continue
        num = m.arrays[count].ravel().astype(np.int64)
        if (num < 0).any():
            k = first(num < 0)
            fail(count, k, int(num[k]), "a count cannot be negative")
        bad = (adr < -1) | (adr > size) | ((num > 0) & ((adr < 0) | (adr + num > size)))
        if bad.any():
            k = first(bad)
            fail(name, k, int(adr[k]), f"with {count}[{k}] = {int(num[k])} it runs past the "
                 f"{size} elements of {target[1:]}")


_COLINDS = tuple(f.name for f in POINTERS if f.name.endswith("colind"))


@covers(*_COLINDS)
def check_colind(m):
    """Sparse column indices are dofs."""
    for name in _COLINDS:
        check_range(m, name, 0, m.nv, f"a column is a dof, in [0, {m.nv})")
