"""Extents of the arrays that mjModel, mjData and friends point to.

An extent is an int or a Python expression over `m` (the mjModel), `d` (the
mjData) or `self` (the struct holding the field), e.g. 'm.nbody' or
'm.nmocap*3'.  mjxmacro.h's X-macros are the first source; the `(a x b)`
comments in the headers fill in the rest.
"""

import re

from . import headers

ARENA = "mjData arena"

# X-macro lists of pointer fields, and the struct they belong to.
_XMACROS = {
    "mjModel": ("MJMODEL_POINTERS",),
    "mjData": ("MJDATA_POINTERS",),
    ARENA: ("MJDATA_ARENA_POINTERS",),    # in d->arena: addresses change every step
}

# Expanded by the preprocessor: MJ_M(n)/MJ_D(n) mark model and data members.
_XMACRO_SOURCE = """
#include <mujoco/mujoco.h>
#include <mujoco/mjxmacro.h>
#undef MJ_M
#undef MJ_D
#define MJ_M(n) m_##n
#define MJ_D(n) d_##n
#define X(type, name, nr, nc) @FIELD name | nr | nc @END
"""

_COMMENT_SHAPE = re.compile(r"\(([\w*+ ]+(?: x [\w*+ ]+)?)\)\s*$")
_TOKEN = re.compile(r"[A-Za-z_]\w*|\d+|[*+]")
_PRODUCT = re.compile(r"^\w+(\s*[*+]\s*\w+)*$")


def _as_extent(parts):
    """Join qualified tokens; a product of plain numbers becomes an int."""
    joined = "".join(parts)
    if re.fullmatch(r"[\d*+]+", joined):
        return eval(joined)          # only digits, '*' and '+': safe
    return joined


def _qualify(expr, plain_owner, known):
    """'m_nmocap*3' -> 'm.nmocap*3'; a bare name belongs to `plain_owner`.

    `known` maps constant names (enumerators such as mjNTEXROLE) to values.
    """
    parts = []
    for token in _TOKEN.findall(expr):
        if token.isdigit() or token in "*+":
            parts.append(token)
        elif token in known:
            parts.append(str(known[token]))
        elif token.startswith(("m_", "d_")):
            parts.append(f"{token[0]}.{token[2:]}")
        else:
            parts.append(f"{plain_owner}.{token}")
    return _as_extent(parts)


def from_xmacros(known):
    """{struct: {field: (rows, cols)}} for every X-macro pointer field.

    mjData's arena fields are listed under ARENA rather than 'mjData'.

    `known` maps enumerator names to values; #define constants are expanded
    by the preprocessor.
    """
    body = _XMACRO_SOURCE + "".join(
        f"@STRUCT {struct.replace(' ', '_')} {name}\n"
        for struct, names in _XMACROS.items() for name in names)
    text = headers.expand(body)
    out = {}
    for struct, rest in re.findall(r"@STRUCT (\w+) (.*)", text):
        struct = struct.replace("_", " ")
        table = out.setdefault(struct, {})
        for name, rows, cols in re.findall(r"@FIELD (\w+) \| ([^|]+) \| (.+?) @END", rest):
            # bare sizes in mjData's lists are model sizes (nq, nbody, ...)
            table[name] = (_qualify(rows, "m", known), _qualify(cols, "m", known))
    return out


def from_comment(comment, owner_fields, struct_name, known):
    """Extents in a trailing `(a x b)` or `(n)` comment, or None.

    A name is qualified by the struct it belongs to: the struct's own fields
    are `self.` (or `m.`/`d.` for mjModel/mjData), other names are model sizes.
    """
    match = _COMMENT_SHAPE.search(comment or "")
    if not match:
        return None
    own = {"mjModel": "m", "mjData": "d"}.get(struct_name, "self")
    dims = []
    for part in match.group(1).split(" x "):
        if not _PRODUCT.match(part.strip()):
            return None
        tokens = _TOKEN.findall(part)
        qualified = []
        for token in tokens:
            if token.isdigit() or token in "*+":
                qualified.append(token)
            elif token in known:
                qualified.append(str(known[token]))
            elif token in owner_fields:
                qualified.append(f"{own}.{token}")
            elif struct_name == "mjData":
                qualified.append(f"m.{token}")
            else:
                return None
        dims.append(_as_extent(qualified))
    return tuple(dims)
