"""Describe every struct field once, for both the metadata and the classes.

`describe(...)` turns the parsed structs into FieldInfo records: kind,
element type, extents (see extents.py) and the header's comment.
"""

import re
from dataclasses import dataclass

from . import extents

_EXTENTS_COMMENT = re.compile(r"\s*\([\w*+ ]+(?: x [\w*+ ]+)?\)\s*$")


@dataclass
class FieldInfo:
    name: str
    ctype: str        # the C type as declared
    kind: str         # 'scalar', 'array', 'pointer', 'struct' or 'function'
    elem: str         # element type, e.g. 'mjtNum', 'mjContact', 'mjVisual.global'
    extents: tuple
    doc: str
    const: bool = False
    moves: bool = False   # a pointer whose address or extents change after creation


def _kind(ctype, nested, struct_names):
    if ctype.function:
        return "function"
    if ctype.pointer:
        return "pointer"
    if ctype.dims:
        return "array"
    if nested is not None or ctype.base.startswith(("struct", "union")) or \
            ctype.base in struct_names:
        return "struct"
    return "scalar"


def _element(ctype, nested, tag_names):
    if ctype.function:
        return ctype.decl
    if nested is not None:
        return nested.name
    base = ctype.base
    for prefix in ("struct ", "union ", "enum "):
        if base.startswith(prefix):
            tag = base[len(prefix):]
            base = tag_names.get(tag, tag)
    return base + " *" * (ctype.pointer - 1 if ctype.pointer else 0)


def _flat_fields(struct):
    """Fields, with the members of anonymous unions lifted into the parent."""
    for fld in struct.fields:
        if not fld.name and fld.nested is not None:
            yield from _flat_fields(fld.nested)
        else:
            yield fld


def all_structs(decls):
    """(name, Struct) for every struct, nested anonymous ones after their parent."""
    for struct in decls.structs.values():
        yield struct.name, struct
        stack = [f.nested for f in struct.fields if f.nested is not None and f.name]
        while stack:
            inner = stack.pop(0)
            yield inner.name, inner
            stack += [f.nested for f in inner.fields if f.nested is not None and f.name]


def describe(decls, notes, xmacro_extents, known):
    """{struct name: [FieldInfo]} in header order.

    `known` maps constant names to values, for names in extents comments.
    """
    out = {}
    for name, struct in all_structs(decls):
        own = {f.name for f in _flat_fields(struct)}
        infos = out[name] = []
        for fld in _flat_fields(struct):
            ctype = fld.type
            kind = _kind(ctype, fld.nested, decls.structs)
            comment = notes.fields.get((struct.tag, fld.name), "")
            dims = tuple(ctype.dims)
            moves = False
            if kind == "pointer":
                arena = xmacro_extents.get(extents.ARENA, {}) if name == "mjData" else {}
                dims = xmacro_extents.get(name, {}).get(fld.name) or arena.get(fld.name) or \
                    extents.from_comment(comment, own, name, known) or ()
                comment = _EXTENTS_COMMENT.sub("", comment)
                moves = fld.name in arena or any(
                    isinstance(e, str) and e.startswith(("d.", "self.")) for e in dims)
            infos.append(FieldInfo(
                name=fld.name, ctype=ctype.decl, kind=kind,
                elem=_element(ctype, fld.nested, decls.tags), extents=dims,
                doc=re.sub(r"\s+", " ", comment).strip(), const=ctype.const, moves=moves))
    return out
