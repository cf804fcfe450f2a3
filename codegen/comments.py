"""Read what only the header text carries: doc comments and `Nullable:` notes.

The preprocessor strips comments, so these come from the raw `.h` files.
"""

import re
from dataclasses import dataclass, field

_MJAPI_FUNC = re.compile(r"^MJAPI\s+(?!extern\b)[^;(]*?\b(\w+)\s*\(")
_COMMENT = re.compile(r"^\s*//\s?(.*)$")
_FIELD = re.compile(r"^\s*[^/{}]*?\b(\w+)\s*(?:\[[^;]*\])*\s*;\s*//\s*(.*?)\s*$")
_BLOCK_OPEN = re.compile(r"^\s*(?:typedef\s+)?(struct|union)\s*(\w*)\s*\{")
_BLOCK_CLOSE = re.compile(r"^\s*\}\s*(\w*)\s*;")


@dataclass
class FunctionDoc:
    doc: str
    nullable: tuple = ()


@dataclass
class HeaderComments:
    functions: dict = field(default_factory=dict)   # name -> FunctionDoc
    fields: dict = field(default_factory=dict)      # (struct tag path, field) -> comment


def _function_docs(text, out):
    lines = text.splitlines()
    for i, line in enumerate(lines):
        match = _MJAPI_FUNC.match(line)
        if not match:
            continue
        block = []
        j = i - 1
        while j >= 0 and _COMMENT.match(lines[j]) and not lines[j].lstrip().startswith("//---"):
            block.insert(0, _COMMENT.match(lines[j]).group(1).rstrip())
            j -= 1
        doc, nullable = [], ()
        for entry in block:
            if entry.startswith("Nullable:"):
                nullable = tuple(n.strip() for n in entry[len("Nullable:"):].split(",") if n.strip())
            else:
                doc.append(entry)
        out[match.group(1)] = FunctionDoc(doc="\n".join(doc).strip(), nullable=nullable)


def _field_comments(text, out):
    """Comments after struct fields, keyed by (struct path, field name).

    The struct path is the tag of the outermost struct (e.g. 'mjModel_'),
    extended with '.name' inside a nested anonymous struct ('mjVisual_.global').
    """
    stack = []            # [tag or None, pending comments]
    for line in text.splitlines():
        opened = _BLOCK_OPEN.match(line)
        if opened:
            stack.append([opened.group(2) or None, {}])
            comment = re.search(r"\{\s*//\s*(.*?)\s*$", line)
            if comment and opened.group(2):     # the struct's own comment, field ""
                out[(opened.group(2), "")] = comment.group(1)
            continue
        closed = _BLOCK_CLOSE.match(line)
        if closed and stack:
            tag, comments = stack.pop()
            if tag is None and stack:
                tag = f"{stack[0][0]}.{closed.group(1)}" if closed.group(1) else stack[0][0]
            for name, comment in comments.items():
                out[(tag, name)] = comment
            continue
        if stack:
            fld = _FIELD.match(line)
            if fld:
                stack[-1][1][fld.group(1)] = fld.group(2)


def read(header_texts):
    """Collect function docs and field comments from every header's text."""
    out = HeaderComments()
    for text in header_texts.values():
        _function_docs(text, out.functions)
        _field_comments(text, out.fields)
    return out
