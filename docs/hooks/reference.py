"""The API reference's Markdown, written at build time from the tables codegen generated.

- Functions: one page per section of mujoco.h (and one for mjbatch.h), in the header's
  order. Each function is a heading with the public anchor `mjcffi.<name>`, its Python
  signature, the header's doc comment, a parameters table (type, shape in MuJoCo's sizes,
  direction, nullable, C declaration), Returns, Raises, the Python notes and a link to
  the function in MuJoCo's C reference. Sources: mjcffi/_generated/funcinfo.py (C
  arguments and header comments), each function's signature line and argument notes
  (written by codegen, or by hand for the overrides, and read here at build time).
- Structs: one page per struct class, with a table of every field (shape in MuJoCo's
  sizes, dtype, C declaration, header comment, a link into the C or XML reference), from
  mjcffi/_generated/structinfo.py.
- Enums: every member with its value and header comment (the comments are read from
  MuJoCo's headers, which codegen's tables do not keep).

Nothing here depends on the machine that builds: no paths, no addresses, no timings.
"""

import ast
import enum
import inspect
import pathlib
import re

C_API = "https://mujoco.readthedocs.io/en/stable/APIreference/"
XML_REF = "https://mujoco.readthedocs.io/en/stable/XMLreference.html"


def anchor(label):
    """The HTML id Sphinx (docutils) gives MuJoCo's label: lower case, `_` as `-`."""
    return re.sub(r"[^a-z0-9]+", "-", label.lower()).strip("-")


def c_function_url(name):
    return f"{C_API}APIfunctions.html#{anchor(name)}"


def c_type_url(cname):
    """MuJoCo's C reference entry of a struct or enum ('mjVisual.global' -> mjVisual)."""
    base = cname.split(".")[0].rstrip("_")
    if base.startswith("mjuiItem"):
        base = "mjuiItem"
    return f"{C_API}APItypes.html#{anchor(base)}"


# ------------------------------------------------------------------ Markdown text

_NAME = re.compile(r"\b(mj[a-zA-Z]*_\w+|mj[A-Z]\w*|mjt[A-Z]\w*|mjs[A-Z]\w*|mjv[A-Z]\w*|"
                   r"mjr[A-Z]\w*|mjui[A-Z]\w*|mjp[A-Z]\w*)\b")
_SPECIAL = re.compile(r"([\\`*_{}\[\]<>#|!~])")


class Linker:
    """Markdown text from plain header text: Markdown's specials escaped, MuJoCo names in
    code spans, linked to their entry in this reference where they have one."""

    def __init__(self):
        self.targets = {}           # name -> (page path under docs/, anchor or None)
        self.c_structs = {}         # C struct name ('mjData', 'mjVisual.global') -> class

    def add(self, name, page, anchor_id=None):
        self.targets.setdefault(name, (page, anchor_id))

    def link(self, name, here, label=None):
        page, anchor_id = self.targets[name]
        href = relative(here, page) + (f"#{anchor_id}" if anchor_id else "")
        if page == here and anchor_id:
            href = f"#{anchor_id}"
        return f"[`{label or name}`]({href})"

    def text(self, text, here, skip=()):
        """`text` (one paragraph of header prose) as Markdown."""
        out = []
        for i, part in enumerate(text.split("`")):
            if i % 2:                       # already a code span in the source
                out.append(self._name(part, here, skip) if part in self.targets else f"`{part}`")
                continue
            pos = 0
            for match in _NAME.finditer(part):
                out.append(_SPECIAL.sub(r"\\\1", part[pos:match.start()]))
                out.append(self._name(match.group(1), here, skip))
                pos = match.end()
            out.append(_SPECIAL.sub(r"\\\1", part[pos:]))
        return "".join(out)

    def _name(self, name, here, skip):
        if name in self.targets and name not in skip:
            return self.link(name, here)
        return f"`{name}`"


def relative(here, target):
    """The relative link from page `here` to page `target` (both paths under docs/)."""
    if here == target:
        return ""
    up = here.split("/")[:-1]
    parts = target.split("/")
    common = 0
    while common < min(len(up), len(parts) - 1) and up[common] == parts[common]:
        common += 1
    return "/".join([".."] * (len(up) - common) + parts[common:])


def cell(text):
    """Table-cell safe: one line, pipes escaped."""
    return " ".join(text.split()).replace("|", "\\|")


# ------------------------------------------------------------------ functions

_ARRAY = re.compile(r"^(\w+): (output )?array of (?:shape|the size of) (\(.*\))( or None)?\.$")
_RANGE = re.compile(r"^(\w+) must be within (-?\w+)\.\.(.+?)\.$")
_RETURN = re.compile(r"\breturns? (.+?)(?:\.\s|\.$|$)", re.S)
_UNAVAILABLE = "Not available in mjcffi"


def _dtype_name(annotation):
    """A type annotation of the official stubs, in words a reader scans."""
    text = annotation
    text = re.sub(r"numpy\.typing\.NDArray\[numpy\.(\w+)\]", r"ndarray[\1]", text)
    text = text.replace("mujoco._structs.", "").replace("mjcffi._support.handles.", "")
    text = re.sub(r"\bmjcffi\.[\w.]*\.", "", text)
    return text


def _parse_signature(line):
    """(params [(name, annotation, default)], return annotation) of a signature line."""
    tree = ast.parse(f"def {line}: pass").body[0]
    args = tree.args
    positional = args.posonlyargs + args.args
    defaults = [None] * (len(positional) - len(args.defaults)) + list(args.defaults)
    params = [(a.arg, ast.unparse(a.annotation) if a.annotation else "", d)
              for a, d in zip(positional, defaults)]
    params += [(a.arg, ast.unparse(a.annotation) if a.annotation else "", d)
               for a, d in zip(args.kwonlyargs, args.kw_defaults)]
    returns = ast.unparse(tree.returns) if tree.returns else "None"
    return [(n, a, ast.unparse(d) if d is not None else None) for n, a, d in params], returns


def _shape_text(shape):
    """A shape as the reader knows its sizes: codegen's helper calls in MuJoCo's terms."""
    shape = re.sub(r"state_size\(m, (\w+)(?:, '\w+')?\)", r"mj_stateSize(m, \1)", shape)
    return shape.replace("band_size(ntotal, nband, ndense)",
                         "(ntotal-ndense)*nband + ndense*ntotal")


def _type_cell(annotation, linker, here):
    text = _dtype_name(annotation)
    parts = [p.strip() for p in text.split("|")]
    shown = []
    for part in parts:
        if part == "None":
            continue
        if part in linker.targets:
            shown.append(linker.link(part, here))
        else:
            shown.append(f"`{part}`")
    return " or ".join(shown) or "`None`"


def _declaration(ctype, name):
    """'const mjtNum [3]', 'point' -> 'const mjtNum point[3]', as C declares it."""
    base, bracket, extents = ctype.partition(" [")
    return f"{_ctype(base)} {name}" + (f"[{extents.replace(' ', '')}" if bracket else "")


def _ctype(ctype):
    """'mjtNum *' -> 'mjtNum*', 'mjSolverStat [20 * 200]' -> 'mjSolverStat[20*200]'."""
    base, bracket, extents = ctype.partition(" [")
    base = re.sub(r"\s*\*", "*", base)
    return base + (f"[{extents.replace(' ', '')}" if bracket else "")


def function_sections():
    """[(slug, title, [names])]: mujoco.h's sections in the header's order, then mjbatch.h.
    A function's section is the `//---- Title ----` line above its declaration in the
    installed mujoco.h (mjbatch.h's functions make a section of their own)."""
    import mjcffi
    from mjcffi import _functions
    section_of, title = {}, None
    for header in ("mujoco.h", "mjbatch.h"):
        path = pathlib.Path(mjcffi.HEADERS_DIR) / header
        title = "Batch" if header == "mjbatch.h" else None
        for line in path.read_text().splitlines():
            marker = re.match(r"^//-+ ([^-].*?) -{3,}", line)
            if marker and header == "mujoco.h":
                title = marker.group(1).strip()
            declared = re.match(r"^MJAPI\s+(?!extern\b)[^;(]*?\b(\w+)\s*\(", line)
            if declared and title:
                section_of.setdefault(declared.group(1), title)
    sections = {}
    for name in _functions.NAMES:
        sections.setdefault(section_of.get(name, "Other"), []).append(name)
    return [(re.sub(r"[^a-z0-9]+", "-", t.lower()).strip("-"), t, names)
            for t, names in sections.items()]


def function_docs(name):
    """(signature line, header comment, [note lines]) of public function `name`."""
    import mjcffi
    from mjcffi._generated import funcinfo
    doc = inspect.getdoc(getattr(mjcffi, name)) or ""
    header = funcinfo.FUNCTIONS[name].doc
    first, _, body = doc.partition("\n")
    body = body.strip()
    rest = body[len(header):] if body.startswith(header) else body
    return first.strip(), header, rest.strip()


def function_markdown(name, linker, here):
    """The Markdown of one function: heading, signature, doc, tables, links."""
    from mjcffi._generated import funcinfo
    info = funcinfo.FUNCTIONS[name]
    signature, header, rest = function_docs(name)
    params, returns = _parse_signature(signature)
    c_args = {a.name: a for a in info.args}
    shapes, ranges, notes = {}, {}, []
    for paragraph in re.split(r"\n\s*\n", rest):
        kept = []
        for line in paragraph.splitlines():
            line = line.strip()
            array = _ARRAY.match(line)
            bounded = _RANGE.match(line)
            if array:
                shapes[array.group(1)] = (_shape_text(array.group(3)), bool(array.group(2)),
                                          bool(array.group(4)))
            elif bounded:
                ranges[bounded.group(1)] = f"{bounded.group(2)}..{bounded.group(3)}"
            else:
                kept.append(line)
        if kept:
            notes.append(" ".join(kept))
    unavailable = any(n.startswith(_UNAVAILABLE) for n in notes)

    lines = [f"## {name} {{ #mjcffi.{name} }}", ""]
    shown = ", ".join(p if d is None else f"{p}={d}" for p, _, d in params)
    ret = _dtype_name(returns)
    lines += ["```python", f"{name}({shown}) -> {ret}", "```", ""]
    lines += _header_markdown(header, linker, here)

    # parameters
    rows = []
    for pname, annotation, default in params:
        carg = c_args.get(pname) or c_args.get(pname.rstrip("_"))
        shape, output, nullable_shape = shapes.get(pname, ("", False, False))
        nullable = ("None" in annotation.split(" | ") or default == "None" or nullable_shape
                    or bool(carg and carg.nullable))
        if carg is None:
            direction, cdecl = "in", "(Python only)"
        else:
            cdecl = f"`{_declaration(carg.ctype, carg.name)}`"
            if carg.pointer and not carg.const and carg.elem not in ("char",):
                direction = "out" if output else "in/out"
            elif carg.pointer and not carg.const:
                direction = "out"
            else:
                direction = "in"
            if carg.extents and not shape:
                shape = "(" + ", ".join(str(e) for e in carg.extents) + \
                        ("," if len(carg.extents) == 1 else "") + ")"
        if pname in ranges:
            shape = shape or f"id in {ranges[pname]}"
        label = f"`{pname}`" + (f" = `{default}`" if default not in (None, "None") else "")
        rows.append(f"| {label} | {_type_cell(annotation, linker, here)} | {cell(shape)} | "
                    f"{direction} | {'yes' if nullable else 'no'} | {cdecl} |")
    lines += ["**Parameters**", ""]
    if rows:
        lines += ["| parameter | type | shape | in/out | None allowed | C declaration |",
                  "| --- | --- | --- | --- | --- | --- |", *rows, ""]
    else:
        lines += ["| parameter | type | shape | in/out | None allowed | C declaration |",
                  "| --- | --- | --- | --- | --- | --- |",
                  "| (none) | | | | | |", ""]
    deduced = [a.name for a in info.args
               if a.name not in {p.rstrip("_") for p, _, _ in params} and a.name not in
               {p for p, _, _ in params}]
    if deduced and not unavailable:
        lines += ["Left out of the Python signature (deduced from the arrays, or handled "
                  "by mjcffi): " + ", ".join(f"`{d}`" for d in deduced) + ".", ""]

    # returns
    lines += ["**Returns**", ""]
    if ret == "None":
        lines += ["`None`.", ""]
    else:
        what = ""
        found = _RETURN.search(header)
        if found and info.restype != "void":
            what = " " + linker.text(found.group(1).strip().rstrip(";"), here)
        lines += [f"{_type_cell(returns, linker, here)} (C `{_ctype(info.restype)}`)"
                  + (f":{what}" if what else "") + ".", ""]

    # raises
    raises = []
    if unavailable:
        raises.append("`NotImplementedError`: always; see the note below.")
    else:
        if params:
            raises.append(f"{linker.link('ArgumentError', here)} (a `TypeError` and "
                          "a `ValueError`): an argument of the wrong type, dtype, shape or "
                          "memory layout.")
        if ranges:
            ids = ", ".join(f"`{p}`" for p in ranges)
            raises.append(f"{linker.link('IdError', here)} (an `IndexError` and a "
                          f"`ValueError`): {ids} out of range.")
        kinds = {a.elem for a in info.args}
        if {"mjModel", "mjData"} <= kinds:
            raises.append("`ValueError`: `d` was made for a model of other sizes.")
        raises.append(f"{linker.link('FatalError', here)}: MuJoCo raised an error "
                      "(`mju_error`) during the call; the process goes on.")
        if any("MjWarningError" in n for n in notes):
            raises.append(f"{linker.link('MjWarningError', here)}: a MuJoCo "
                          "warning, while warnings are errors.")
    lines += ["**Raises**", ""] + [f"- {r}" for r in raises] + [""]

    if notes:
        lines += ["**In Python**", ""]
        for note in notes:
            lines += [linker.text(note, here, skip={name}), ""]
    lines += [f"MuJoCo's C reference: [{name}]({c_function_url(name)})", ""]
    return "\n".join(lines)


def _header_markdown(header, linker, here):
    """The header's doc comment: prose as paragraphs, an indented table as a text block."""
    lines = header.splitlines()
    block = next((i for i, line in enumerate(lines) if i and line[:1].isspace()), None)
    prose = lines if block is None else lines[:block]
    out = []
    if prose:
        out += [linker.text(" ".join(line.strip() for line in prose), here), ""]
    if block is not None:
        out += ["```text", *lines[block:], "```", ""]
    return out


# ------------------------------------------------------------------ structs

def struct_classes():
    """{class name: C struct name} of every public struct class."""
    import mjcffi
    from mjcffi._generated import structinfo
    out = {}
    for name in mjcffi.__all__:
        obj = getattr(mjcffi, name)
        cname = getattr(obj, "_cname", None) if inspect.isclass(obj) else None
        if cname in structinfo.STRUCTS:
            out[name] = cname
    return out


_DTYPE_OF = {"mjtNum": "float64", "double": "float64", "float": "float32", "int": "int32",
             "unsigned int": "uint32", "mjtSize": "int64", "int64_t": "int64",
             "size_t": "uintp", "uintptr_t": "uintp", "uint64_t": "uint64", "mjtByte": "uint8",
             "unsigned char": "uint8", "char": "str (char)", "mjtBool": "bool", "_Bool": "bool"}
_SIZE = re.compile(r"\b(?:m|d|self)\.")


def field_shape(field):
    """The shape of a field's view in MuJoCo's size names: (nbody, 3), (nv,), (), ...
    A pointer's trailing 1 is dropped, as the official bindings drop it."""
    extents = list(field.extents)
    if field.kind == "pointer" and len(extents) == 2 and extents[1] == 1:
        extents = extents[:1]
    if field.kind in ("scalar", "struct", "function") or not extents:
        return "()" if field.kind == "scalar" else ""
    shown = [_SIZE.sub("", str(e)) for e in extents]
    if field.elem == "char" and field.kind == "array" and len(shown) == 1:
        return f"string of ≤ {int(shown[0]) - 1} chars"
    return "(" + ", ".join(shown) + ("," if len(shown) == 1 else "") + ")"


_XML_ELEMENT = {
    "mjOption": "option", "mjStatistic": "statistic", "mjVisual.global": "visual-global",
    "mjVisual.quality": "visual-quality", "mjVisual.headlight": "visual-headlight",
    "mjVisual.map": "visual-map", "mjVisual.scale": "visual-scale",
    "mjVisual.rgba": "visual-rgba", "mjsCompiler": "compiler", "mjsBody": "body",
    "mjsFrame": "body-frame", "mjsJoint": "body-joint", "mjsGeom": "body-geom",
    "mjsSite": "body-site", "mjsCamera": "body-camera", "mjsLight": "body-light",
    "mjsFlex": "deformable-flex", "mjsMesh": "asset-mesh", "mjsHField": "asset-hfield",
    "mjsSkin": "deformable-skin", "mjsTexture": "asset-texture",
    "mjsMaterial": "asset-material", "mjsPair": "contact-pair", "mjsExclude": "contact-exclude",
    "mjsTendon": "tendon-spatial", "mjsActuator": "actuator-general", "mjsSensor": "sensor",
    "mjsNumeric": "custom-numeric", "mjsText": "custom-text", "mjsTuple": "custom-tuple",
    "mjsKey": "keyframe-key", "mjsPlugin": "extension-plugin-instance",
    "mjsEquality": "equality-connect", "mjsDefault": "default",
}


def xml_labels():
    """The labels of MuJoCo's XML reference, from the copy of its docs that mujoco-core
    ships (the same 4.0.0 files on every machine); empty if it ships none."""
    import mjcffi
    doc = pathlib.Path(mjcffi.HEADERS_DIR).parent.parent / "doc" / "XMLreference.rst"
    if not doc.is_file():
        return set()
    return set(re.findall(r"^\.\. _([\w-]+):", doc.read_text(), re.M))


def field_reference(cname, field, labels):
    """(label, url): the field's entry in the XML reference where it has one, else its
    struct's entry in the C reference."""
    element = _XML_ELEMENT.get(cname)
    if element:
        for attr in (field, field.removeprefix("o_"), field.split("_")[0]):
            label = f"{element}-{attr}"
            if label in labels:
                return f"XML {label.replace('-', '/')}", f"{XML_REF}#{anchor(label)}"
        if cname == "mjOption" and field in ("disableflags", "enableflags") and \
                "option-flag" in labels:
            return "XML option/flag", f"{XML_REF}#option-flag"
    return cname.split(".")[0], c_type_url(cname)


# The two structs whose declaration in the header carries no comment of its own.
_ABOUT = {"mjModel": "the model: its sizes, options and the constant parameters of every "
                     "element, made once when the model is compiled",
          "mjData": "the state of a simulation (time, positions, velocities, controls) and "
                    "everything MuJoCo computes from it"}


def struct_markdown(class_name, cname, linker, here, struct_comments, labels):
    from mjcffi._generated import structinfo
    fields = structinfo.STRUCTS[cname]
    lines = [f"# {class_name} {{ #mjcffi.{class_name} }}", ""]
    comment = struct_comments.get(cname.split(".")[0].rstrip("_")) or _ABOUT.get(cname)
    about = f"MuJoCo's `{cname}`" + (f": {linker.text(comment, here)}" if comment else "")
    lines += [about + f". C reference: [{cname}]({c_type_url(cname)}).", ""]
    lines += [f"{len(fields)} fields. Shapes are in MuJoCo's size names (`nv` is `m.nv`, the "
              "model's; `ngeom` on a scene is the scene's own). Arrays are writable zero-copy "
              "NumPy views; assigning to a field writes into C. Each field name links to its "
              "entry in MuJoCo's reference: the XML attribute it comes from where it has one, "
              "else the struct in the C reference.", ""]
    lines += ["| field | type | shape | C declaration | header comment |",
              "| --- | --- | --- | --- | --- |"]
    for field in fields:
        if field.kind == "struct" or field.elem in linker.c_structs:
            target = linker.c_structs.get(field.elem)
            kind = linker.link(target, here) if target else f"`{field.elem}`"
        elif field.kind == "function":
            kind = "C function pointer"
        elif field.elem in linker.targets and field.elem.startswith("mjt"):
            kind = f"{linker.link(field.elem, here)} (int)"
        else:
            kind = f"`{_DTYPE_OF.get(field.elem, field.elem)}`"
        ref_label, ref_url = field_reference(cname, field.name.split(".")[-1], labels)
        name = field.name
        lines.append(f"| <span id=\"mjcffi.{class_name}.{name}\"></span>[`{name}`]({ref_url} "
                     f"\"{ref_label}\") | {kind} | {cell(field_shape(field))} | "
                     f"`{cell(_ctype(field.ctype))}` | {cell(linker.text(field.doc, here))} |")
    lines.append("")
    return "\n".join(lines)


# ------------------------------------------------------------------ header comments

_ENUM_OPEN = re.compile(r"^typedef enum (\w+?)_? *\{\s*(?://\s*(.*))?$")
_ENUM_MEMBER = re.compile(r"^\s*(\w+)\s*(?:=\s*[^,/]+)?,?\s*(?://\s*(.*))?$")
_STRUCT_OPEN = re.compile(r"^(?:typedef )?struct (\w+?)_? *\{\s*//\s*(.*)$")


def header_comments():
    """({enum: comment}, {member: comment}, {struct: comment}) from MuJoCo's headers."""
    import mjcffi
    enums, members, structs = {}, {}, {}
    for path in sorted(pathlib.Path(mjcffi.HEADERS_DIR).glob("*.h")):
        current = None
        for line in path.read_text().splitlines():
            opened = _ENUM_OPEN.match(line)
            if opened:
                current = opened.group(1)
                enums[current] = (opened.group(2) or "").strip()
                continue
            struct = _STRUCT_OPEN.match(line)
            if struct:
                structs.setdefault(struct.group(1), struct.group(2).strip())
            if current:
                if line.lstrip().startswith("}"):
                    current = None
                    continue
                member = _ENUM_MEMBER.match(line)
                if member and member.group(1).startswith("mj"):
                    members[member.group(1)] = " ".join((member.group(2) or "").split())
    return enums, members, structs


def enum_markdown(name, cls, linker, here, enum_comments, member_comments):
    lines = [f"## {name} {{ #mjcffi.{name} }}", ""]
    comment = enum_comments.get(name, "")
    if comment:
        lines += [linker.text(comment[:1].upper() + comment[1:], here, skip={name}) + ".", ""]
    lines += [f"`enum.IntEnum`, {len(cls)} members. C reference: "
              f"[{name}]({c_type_url(name)}).", "",
              "| member | value | header comment |", "| --- | --- | --- |"]
    for member in cls:
        lines.append(f"| `{member.name}` | {int(member.value)} | "
                     f"{cell(linker.text(member_comments.get(member.name, ''), here))} |")
    lines.append("")
    return "\n".join(lines)


def is_enum(obj):
    return inspect.isclass(obj) and issubclass(obj, enum.Enum)
