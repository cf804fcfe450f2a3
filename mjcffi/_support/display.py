"""Notebook display: the HTML that Jupyter shows for MjModel, MjSpec and TuneResult.

IPython's display protocol asks an object for `_repr_html_()` (or `_repr_markdown_()`,
...).  Those methods import this module when first called, so `import mjcffi` loads
none of it, and no IPython is needed.  Every text that goes into the HTML is escaped
here, the spec's body tree is cut at BODY_LIMIT bodies, and `safe` turns any failure
into the object's plain repr: a notebook display must never raise.

Support module: imports only the standard library, and in the spec summary the
compiled module, marshal, spec_claims and spec_kinds.
"""

import html
import re

BODY_LIMIT = 200           # bodies shown in a spec's tree; the rest are counted

# MJCF's spellings of the mjtIntegrator, mjtSolver and mjtCone values
INTEGRATORS = ("Euler", "RK4", "implicit", "implicitfast", "discrete")
SOLVERS = ("PGS", "CG", "Newton")
CONES = ("pyramidal", "elliptic")

# MjModel sizes shown when nonzero (nq, nv, nu and nbody always are)
MODEL_SIZES = ("na", "njnt", "ngeom", "nsite", "ncam", "nlight", "nflex", "nmesh", "nskin",
               "nhfield", "ntex", "nmat", "npair", "nexclude", "neq", "ntendon", "nsensor",
               "nnumeric", "ntext", "ntuple", "nkey", "nmocap", "nplugin")

_TABLE = '<table style="border-collapse:collapse;margin:2px 0">'
_BOLD = re.compile(r"\*\*(.+?)\*\*")


# ------------------------------------------------------------------ helpers

def escape(value):
    """`value` as text, with the HTML special characters (& < > " ') escaped."""
    return html.escape(str(value), quote=True)


def plain(obj):
    """The plain repr of `obj`, escaped, in a <pre>; a stand-in if repr itself fails."""
    try:
        text = repr(obj)
    except Exception:
        text = f"<{type(obj).__name__} object>"
    return f"<pre>{escape(text)}</pre>"


def safe(obj, build):
    """`build()`, or the plain repr of `obj` if that raises."""
    try:
        return build()
    except Exception:
        return plain(obj)


def number(x):
    """A float as %g, anything else as str."""
    return f"{x:g}" if isinstance(x, float) else str(x)


def named(names, value):
    """The name of enum `value` in `names` (by index), or the value itself."""
    value = int(value)
    return names[value] if 0 <= value < len(names) else str(value)


def row_table(pairs):
    """A two-row table: the names of `pairs` (name, value) as the header, their values
    below; both escaped."""
    head = "".join(f'<th style="padding:1px 6px">{escape(name)}</th>' for name, _ in pairs)
    cells = "".join(f'<td style="padding:1px 6px">{escape(number(value))}</td>'
                    for _, value in pairs)
    return f"{_TABLE}<tr>{head}</tr><tr>{cells}</tr></table>"


# ------------------------------------------------------------------ markdown

def _inline(text):
    return _BOLD.sub(r"<b>\1</b>", escape(text))


def _cells(line):
    return [cell.strip() for cell in line.strip().strip("|").split("|")]


def _md_table(lines):
    """A markdown pipe table (header, alignment row, rows) as an HTML table."""
    head = _cells(lines[0])
    align = ["right" if cell.endswith(":") else "left" for cell in _cells(lines[1])] \
        if len(lines) > 1 else []
    out = [_TABLE, "<tr>"]
    out += [f'<th style="padding:1px 6px">{_inline(cell)}</th>' for cell in head]
    out.append("</tr>")
    for line in lines[2:]:
        out.append("<tr>")
        for i, cell in enumerate(_cells(line)):
            side = align[i] if i < len(align) else "left"
            out.append(f'<td style="padding:1px 6px;text-align:{side}">{_inline(cell)}</td>')
        out.append("</tr>")
    out.append("</table>")
    return "".join(out)


def markdown_html(text):
    """The markdown that mjcffi writes (headings, paragraphs, **bold**, pipe tables) as
    HTML, every text escaped.  Anything else reads as paragraph text."""
    out, paragraph, rows = [], [], []

    def flush():
        if paragraph:
            out.append(f"<p>{_inline(' '.join(paragraph))}</p>")
            paragraph.clear()
        if rows:
            out.append(_md_table(rows))
            rows.clear()

    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith("|"):
            if paragraph:
                flush()
            rows.append(stripped)
            continue
        if rows or not stripped:
            flush()
        if not stripped:
            continue
        heading = re.match(r"(#{1,6})\s+(.*)", stripped)
        if heading:
            flush()
            level = min(len(heading.group(1)) + 2, 6)
            out.append(f"<h{level}>{_inline(heading.group(2))}</h{level}>")
        else:
            paragraph.append(stripped)
    flush()
    return "\n".join(out)


def png_img(png, alt):
    """An <img> holding the PNG bytes `png` inline (a data: URL)."""
    import base64
    data = base64.b64encode(png).decode("ascii")
    return f'<img src="data:image/png;base64,{data}" alt="{escape(alt)}"/>'


# ------------------------------------------------------------------ MjModel

def model_html(m):
    """An MjModel's name, sizes and main options."""
    name = m.names.split(b"\0", 1)[0].decode("utf-8", "replace")
    sizes = [(f, getattr(m, f)) for f in ("nq", "nv", "nu", "nbody")]
    sizes += [(f, value) for f in MODEL_SIZES if (value := getattr(m, f))]
    opt = m.opt
    options = [("timestep", float(opt.timestep)),
               ("integrator", named(INTEGRATORS, opt.integrator)),
               ("solver", named(SOLVERS, opt.solver)),
               ("iterations", int(opt.iterations)),
               ("cone", named(CONES, opt.cone)),
               ("gravity", " ".join(f"{g:g}" for g in opt.gravity))]
    title = f"<b>MjModel</b> {escape(repr(name))}" if name else "<b>MjModel</b>"
    return f"<div>{title}{row_table(sizes)}{row_table(options)}</div>"


# ------------------------------------------------------------------ MjSpec

def spec_html(spec, what=b"MjSpec._repr_html_"):
    """An MjSpec's name, timestep, element counts and body tree (BODY_LIMIT bodies
    at most).  The spec is held while it is read: a spec another thread holds gives a
    short note instead (spec_claims)."""
    import contextlib
    from . import spec_claims
    with contextlib.ExitStack() as stack:
        try:
            stack.enter_context(spec_claims.holding(spec._ptr, what))
        except RuntimeError:
            return "<pre>&lt;MjSpec: in use by another thread; no summary&gt;</pre>"
        return _spec_summary(spec._ptr)


def _spec_summary(c_spec):
    from . import marshal
    from . import spec_kinds
    from .library import ffi, lib

    def call(guard, *args):
        result = guard(*args)
        marshal.check_error()
        return result

    def name_of(element):
        return marshal.string(lib.mjs_getString(lib.mjs_getName(element))) or ""

    def children(body, type_):
        element = call(lib.mjcffi_guard_mjs_firstChild, body, type_, 0)
        while element != ffi.NULL:
            yield element
            element = call(lib.mjcffi_guard_mjs_nextChild, body, element, 0)

    counts = []
    for plural, _, type_, _ in spec_kinds.KINDS:
        n, element = 0, call(lib.mjcffi_guard_mjs_firstElement, c_spec, type_)
        while element != ffi.NULL:
            n += 1
            element = call(lib.mjcffi_guard_mjs_nextElement, c_spec, element)
        if n > 0:                           # bodies: the world body too, as spec.bodies
            counts.append((plural, n))

    mjtObj = spec_kinds.mjtObj
    BODY, GEOM, JOINT, SITE = (int(mjtObj.mjOBJ_BODY), int(mjtObj.mjOBJ_GEOM),
                               int(mjtObj.mjOBJ_JOINT), int(mjtObj.mjOBJ_SITE))
    rows, more = [], 0
    stack = [(call(lib.mjcffi_guard_mjs_findBody, c_spec, b"world"), 0)]
    while stack:
        body, depth = stack.pop()
        kids = list(children(body, BODY))
        stack.extend((lib.mjs_asBody(k), depth + 1) for k in reversed(kids))
        if len(rows) > BODY_LIMIT:          # the world, then BODY_LIMIT bodies shown
            more += 1
            continue
        held = [(sum(1 for _ in children(body, t)), word)
                for t, word in ((GEOM, "geom"), (JOINT, "joint"), (SITE, "site"))]
        label = escape(name_of(body.element)) or "<i>unnamed</i>"
        parts = [f"{n} {word}{'s' if n != 1 else ''}" for n, word in held if n]
        if parts:
            label += f" <small>({', '.join(parts)})</small>"
        rows.append((depth, label))

    name = marshal.string(lib.mjs_getString(c_spec.modelname)) or ""
    title = f"<b>MjSpec</b> {escape(repr(name))}" if name else "<b>MjSpec</b>"
    title += f" timestep {escape(number(float(c_spec.option.timestep)))}"
    tree = _tree(rows)
    if more:
        tree += f"<div>… and {more} more bodies</div>"
    counts_html = row_table(counts) if counts else "<div>no elements</div>"
    return f"<div>{title}{counts_html}{tree}</div>"


def _tree(rows):
    """Nested <ul> lists from (depth, label HTML) in pre-order; depth grows by one at most."""
    out, current = [], -1
    style = '<ul style="margin:0;padding-left:1.2em">'
    for depth, label in rows:
        if depth > current:
            out.append(style * (depth - current))
        else:
            out.append("</li>" + "</ul></li>" * (current - depth))
        out.append(f"<li>{label}")
        current = depth
    if current >= 0:
        out.append("</li>" + "</ul></li>" * current + "</ul>")
    return "".join(out)
