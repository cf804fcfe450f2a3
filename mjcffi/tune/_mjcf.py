"""The tuned model's MJCF: the source file with only its <option>/<flag> changed.

Two routes, tried in order, each checked before it is accepted:

1. "text": the source text edited in place; every byte outside the edits is
   kept (comments, quoting, spacing, line ends).  The file's one top-level
   <option> gets the changed attribute values where it has them and the new
   attributes after its last one, and its <flag> child likewise (a <flag> child
   is added where there is none, on its own line where the <option> is on its
   own line).  Where the file has no <option>, several, or an <include> that may
   hold one, a new <option> holding only the changes goes just before
   </mujoco>: MuJoCo applies it last.  A source in another encoding than UTF-8
   has its XML declaration say utf-8, since the text is written as UTF-8.
2. "spec": MjSpec.from_file(source), set spec.option, spec.to_xml().  MuJoCo's
   writer rewrites the whole model: it prints reals with about six significant
   digits and replaces fromto, euler and degree angles by the compiled pos, quat
   and size, so most hand-written models do not come back bit for bit; it is the
   fallback for sources the text route cannot read (no single <mujoco> root
   element, undecodable bytes) or cannot anchor (see below).

The check: the candidate text is saved next to where the file will live and
compiled from there (a hidden temporary file, removed at once, so that folder
must be writable); its binary model (mj_saveModel) must equal, byte for byte,
the source model with the same option changes made in memory.  Equal binary
models give bit-identical simulations.  If neither route passes, ValueError.

Asset paths: MuJoCo resolves meshdir, texturedir, assetdir, file= of meshes,
height fields, skins, textures and <include>s relative to the model file's own
folder.  Only when the output goes to another folder than the source are they
anchored there with absolute paths (by the text route only where the file
names a file at all): the text route makes relative meshdir,
texturedir and assetdir of the file's <compiler>s and file= of its <include>s and
<model>s absolute and, for a folder no <compiler> names, adds a <compiler
meshdir=... texturedir=...> naming the source folder right after the <mujoco>
start tag; the spec route sets absolute compiler.meshdir/texturedir.  Relative
folders named inside an included file stay relative (the text route edits the
main file only).  Written to the source's own folder, the paths stay as they were.
"""

import codecs
import errno
import html
import math
import numbers
import os
import re
import tempfile
import warnings
from dataclasses import dataclass, field

import numpy as np

import mjcffi

# MJCF keywords of the enum options, indexed by the enum value (mjtIntegrator, ...).
ENUM_WORDS = {
    "integrator": ("Euler", "RK4", "implicit", "implicitfast", "discrete"),
    "cone": ("pyramidal", "elliptic"),
    "solver": ("PGS", "CG", "Newton"),
    "jacobian": ("dense", "sparse", "auto"),
}
INT_OPTIONS = ("iterations", "ls_iterations", "noslip_iterations")
REAL_OPTIONS = ("timestep", "tolerance", "ls_tolerance", "noslip_tolerance")
OPTIONS = tuple(ENUM_WORDS) + REAL_OPTIONS + INT_OPTIONS

# <flag> attribute names are MuJoCo's flag strings in lower case ("contact", "nativeccd").
DISABLE_NAMES = tuple(name.lower() for name in mjcffi.mjDISABLESTRING)
ENABLE_NAMES = tuple(name.lower() for name in mjcffi.mjENABLESTRING)

# Relative paths the text route anchors when the folder changes.
_DIR_ATTRIBUTES = ("meshdir", "texturedir", "assetdir")
_FILE_ELEMENTS = ("include", "model")


@dataclass(frozen=True)
class TunedMjcf:
    """MJCF text, the route that made it ('text' or 'spec'), and why the routes
    tried before it were refused ('' when the first was taken)."""
    text: str
    route: str
    refusal: str = ""


@dataclass(frozen=True)
class _Changes:
    options: dict
    disable_set: int
    disable_clear: int
    enable_set: int
    enable_clear: int


# ------------------------------------------------------------------ public

def tuned_mjcf(source, options, disable_set=0, disable_clear=0, enable_set=0,
               enable_clear=0, out_path=None):
    """The MJCF of `source` with only these option changes, as a TunedMjcf (see
    tuned_xml for the arguments)."""
    source = _source_path(source)
    changes = _Changes(_checked_options(options),
                       *_checked_flags(disable_set, disable_clear, len(DISABLE_NAMES), "disable"),
                       *_checked_flags(enable_set, enable_clear, len(ENABLE_NAMES), "enable"))
    source_dir = os.path.dirname(source)
    out_dir = source_dir if out_path is None else os.path.dirname(os.path.abspath(os.fspath(out_path)))
    if not os.path.isdir(out_dir):
        raise FileNotFoundError(errno.ENOENT, "the output folder does not exist", out_dir)
    moved = os.path.realpath(out_dir) != os.path.realpath(source_dir)
    expected = _expected_model(source, changes)

    refusals = []
    for route, make_text in (("text", _via_text), ("spec", _via_spec)):
        text, refusal = _attempt(lambda: make_text(source, changes, source_dir, moved),
                                 out_dir, expected)
        if refusal is None:
            return TunedMjcf(text, route, "; ".join(refusals))
        refusals.append(f"{route} route: {refusal}")
    raise ValueError(f"cannot write {source} with these option changes faithfully: "
                     + "; ".join(refusals))


def tuned_xml(source, options, disable_set=0, disable_clear=0, enable_set=0,
              enable_clear=0, out_path=None):
    """The MJCF text of `source` (a path to an .xml file) with only these option changes.

    options: MjOption field name -> new value, among 'integrator', 'timestep', 'solver',
      'iterations', 'tolerance', 'ls_iterations', 'ls_tolerance', 'noslip_iterations',
      'noslip_tolerance', 'cone', 'jacobian' (values as in MjModel.opt: ints for enums,
      floats, ints).
    disable_set / disable_clear: mjtDisableBit bits to switch off / back on; enable_*:
      mjtEnableBit likewise.
    out_path: where the file will be written (asset paths must still resolve from there);
      None: the source's folder.
    See the module docstring for the two routes and how asset paths are kept working.
    """
    return tuned_mjcf(source, options, disable_set, disable_clear, enable_set,
                      enable_clear, out_path).text


def write_tuned_xml(source, out_path, options=None, **flags):
    """Write tuned_xml(source, options, **flags, out_path=out_path) to `out_path`
    (as UTF-8, line ends as they are); returns its path."""
    text = tuned_xml(source, {} if options is None else options, out_path=out_path, **flags)
    out_path = os.fspath(out_path)
    with open(out_path, "w", encoding="utf-8", newline="") as file:
        file.write(text)
    return out_path


# ------------------------------------------------------------------ checks

def _source_path(source):
    if not isinstance(source, (str, os.PathLike)):
        raise TypeError(f"source must be a path to an MJCF file, not {type(source).__name__}")
    path = os.path.abspath(os.fspath(source))
    if not os.path.isfile(path):
        raise FileNotFoundError(errno.ENOENT, "no MJCF file", path)
    return path


def _checked_options(options):
    if not hasattr(options, "items"):
        raise TypeError(f"options must be a dict of option name -> value, "
                        f"not {type(options).__name__}")
    checked = {}
    for name, value in options.items():
        if name not in OPTIONS:
            raise ValueError(f"unknown option {name!r}; allowed: {', '.join(OPTIONS)}")
        checked[name] = _checked_value(name, value)
    return checked


def _checked_value(name, value):
    if name in REAL_OPTIONS:
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise TypeError(f"option {name} must be a real number, not {type(value).__name__}")
        value = float(value)
        if not math.isfinite(value) or value < 0 or (name == "timestep" and value == 0):
            raise ValueError(f"option {name} must be finite and "
                             f"{'positive' if name == 'timestep' else 'non-negative'}, got {value}")
        return value
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"option {name} must be an int, not {type(value).__name__}")
    value = int(value)
    if name in ENUM_WORDS and not 0 <= value < len(ENUM_WORDS[name]):
        raise ValueError(f"option {name} must be in 0..{len(ENUM_WORDS[name]) - 1} "
                         f"({', '.join(ENUM_WORDS[name])}), got {value}")
    if value < 0:
        raise ValueError(f"option {name} must be non-negative, got {value}")
    return value


def _checked_flags(set_bits, clear_bits, count, what):
    checked = []
    for label, bits in ((f"{what}_set", set_bits), (f"{what}_clear", clear_bits)):
        if isinstance(bits, bool) or not isinstance(bits, numbers.Integral):
            raise TypeError(f"{label} must be an int of mjt{what.title()}Bit bits, "
                            f"not {type(bits).__name__}")
        bits = int(bits)
        if bits < 0 or bits >> count:
            raise ValueError(f"{label}={bits:#x} has bits outside the {count} {what} flags")
        checked.append(bits)
    if checked[0] & checked[1]:
        raise ValueError(f"{what}_set and {what}_clear share bits {checked[0] & checked[1]:#x}")
    return checked


# ------------------------------------------------------------ verification

def _apply(opt, changes):
    """Make `changes` on an MjOption (of a model or a spec)."""
    for name, value in changes.options.items():
        setattr(opt, name, value)
    opt.disableflags = (int(opt.disableflags) | changes.disable_set) & ~changes.disable_clear
    opt.enableflags = (int(opt.enableflags) | changes.enable_set) & ~changes.enable_clear


def _model_bytes(model):
    buffer = np.zeros(mjcffi.mj_sizeModel(model), np.uint8)
    mjcffi.mj_saveModel(model, None, buffer)
    return buffer.tobytes()


def _expected_model(source, changes):
    model = mjcffi.MjModel.from_xml_path(source)
    _apply(model.opt, changes)
    return model


def _differing_fields(got, expected):
    """Names of the model's arrays and options whose bytes differ (why a check failed)."""
    names = []
    for prefix, a, b in (("", got, expected), ("opt.", got.opt, expected.opt)):
        for name in dir(b):
            if name.startswith("_"):
                continue
            x, y = getattr(a, name, None), getattr(b, name, None)
            if isinstance(y, (np.ndarray, numbers.Number)) and \
                    np.asarray(x).tobytes() != np.asarray(y).tobytes():
                names.append(prefix + name)
    return names


def _attempt(make_text, out_dir, expected):
    """(text, None) if the text from make_text() compiles, from out_dir, to the
    expected model; else (text or None, why not)."""
    try:
        text = make_text()
    except Exception as error:    # MuJoCo's or the XML parser's refusal, reported as a reason
        return None, f"{type(error).__name__}: {error}"
    return text, _differs(text, out_dir, expected)


def _differs(text, out_dir, expected):
    """Why `text`, saved in out_dir, does not compile to `expected`; None if it does.
    The check file is hidden and removed at once; out_dir must be writable."""
    try:
        handle, path = tempfile.mkstemp(suffix=".xml", prefix=".tuned-", dir=out_dir)
    except OSError as error:
        return f"cannot write a check file in {out_dir}: {error}"
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as file:
            file.write(text)
        model = mjcffi.MjModel.from_xml_path(path)
    except Exception as error:
        return f"the written MJCF does not load: {type(error).__name__}: {error}"
    finally:
        os.remove(path)
    if _model_bytes(model) == _model_bytes(expected):
        return None
    fields = _differing_fields(model, expected)
    shown = ", ".join(fields[:8]) + (f" and {len(fields) - 8} more" if len(fields) > 8 else "")
    return f"the reloaded model differs in {shown or 'its binary form'}"


# ------------------------------------------------------------- spec route

def _via_spec(source, changes, source_dir, moved):
    spec = mjcffi.MjSpec.from_file(source)
    _apply(spec.option, changes)
    if moved:
        spec.meshdir = _anchored(spec.meshdir, source_dir)
        spec.texturedir = _anchored(spec.texturedir, source_dir)
    with warnings.catch_warnings():     # the compile's warnings are the source model's own
        warnings.simplefilter("ignore")
        return spec.to_xml()


def _anchored(path, folder):
    """`path` (relative to `folder`, '' for the folder itself) as an absolute path."""
    if path and os.path.isabs(path):
        return path
    joined = os.path.join(folder, path)
    return joined if joined.endswith(os.sep) else joined + os.sep


# ------------------------------------------------------------- text route

def _via_text(source, changes, source_dir, moved):
    with open(source, "rb") as file:
        text = _decoded(file.read(), source)
    elements = _elements(text, source)
    newline = "\r\n" if "\r\n" in text else "\n"
    edits = _option_edits(text, elements, changes, newline)
    if moved and _names_files(text, elements):
        edits += _anchor_edits(text, elements, source_dir, newline)
    for start, end, piece in sorted(edits, key=lambda edit: edit[:2], reverse=True):
        text = text[:start] + piece + text[end:]
    return text


def _decoded(raw, source):
    """The source's text, decoded as its XML declaration says (UTF-8 without one);
    a declaration naming another encoding is made to say utf-8, as written."""
    declared = re.match(rb"""(?:\xef\xbb\xbf)?<\?xml[^>]*?encoding\s*=\s*["']([\w.:-]+)["']""", raw)
    encoding = declared.group(1).decode("ascii") if declared else "utf-8"
    try:
        codec = codecs.lookup(encoding)
    except LookupError:
        raise ValueError(f"{source}: unknown encoding {encoding!r}") from None
    text = raw.decode(codec.name)       # UnicodeDecodeError is a ValueError: a refusal
    if codec.name != "utf-8":
        text = re.sub(r"""\A(\ufeff?<\?xml[^>]*?encoding\s*=\s*)(["'])[^"']*\2""",
                      r"\g<1>\g<2>utf-8\g<2>", text, count=1)
    return text


# One piece of markup, matched where its '<' is.  Quoted attribute values may hold
# '>' and '<', so a tag ends only at a '>' outside quotes; comments hide their tags.
_MARKUP = re.compile(r"""
    <!--.*?-->
  | <!\[CDATA\[.*?\]\]>
  | <\?.*?\?>
  | <!DOCTYPE(?:[^\[>]|\[.*?\])*>
  | </(?P<end>[^\s>]+)\s*>
  | <(?P<name>[^\s/>!?]+)(?:\s+[^\s=/>]+\s*=\s*(?:"[^"]*"|'[^']*'))*\s*(?P<empty>/)?>
""", re.S | re.X)
_ATTRIBUTE = re.compile(r"""\s+([^\s=/>]+)\s*=\s*(?:"([^"]*)"|'([^']*)')""")


@dataclass
class _Element:
    """Where one element of the text is: its start tag [start, tag_end) and its
    end tag [close, close_end) (both tag_end for an empty element)."""
    name: str
    start: int
    tag_end: int
    empty: bool
    close: int = -1
    close_end: int = -1
    children: list = field(default_factory=list)

    def attributes(self, text):
        """name -> (value start, value end, quote) of the start tag's attributes."""
        found = {}
        for match in _ATTRIBUTE.finditer(text, self.start + 1 + len(self.name), self.tag_end):
            group = 2 if match.group(2) is not None else 3
            found[match.group(1)] = (match.start(group), match.end(group), text[match.start(group) - 1])
        return found

    def value(self, text, name):
        """The unescaped value of attribute `name`, None where it is absent."""
        span = self.attributes(text).get(name)
        return None if span is None else html.unescape(text[span[0]:span[1]])


def _elements(text, source):
    """The text's elements in document order; the first is the one root, <mujoco>."""
    elements, roots, stack, pos = [], [], [], 0
    while (pos := text.find("<", pos)) >= 0:
        match = _MARKUP.match(text, pos)
        if match is None:
            raise ValueError(f"{source}: malformed markup at line {_line(text, pos)}")
        if match.group("name"):
            element = _Element(match.group("name"), pos, match.end(), bool(match.group("empty")))
            (stack[-1].children if stack else roots).append(element)
            elements.append(element)
            if element.empty:
                element.close = element.close_end = match.end()
            else:
                stack.append(element)
        elif match.group("end"):
            if not stack or stack[-1].name != match.group("end"):
                raise ValueError(f"{source}: </{match.group('end')}> at line "
                                 f"{_line(text, pos)} closes no open element")
            element = stack.pop()
            element.close, element.close_end = pos, match.end()
        pos = match.end()
    if stack:
        raise ValueError(f"{source}: <{stack[-1].name}> at line "
                         f"{_line(text, stack[-1].start)} is never closed")
    found = [f"<{root.name}{'/' if root.empty else ''}>" for root in roots]
    if found != ["<mujoco>"]:
        raise ValueError(f"{source}: the text route needs one <mujoco>...</mujoco> root "
                         f"element, found {', '.join(found) or 'none'}")
    return elements


def _line(text, pos):
    return text.count("\n", 0, pos) + 1


def _indent_at(text, pos):
    """The spaces and tabs before `pos` on its line; None where anything else is there."""
    prefix = text[text.rfind("\n", 0, pos) + 1:pos]
    return None if prefix.strip(" \t") else prefix


def _child_indent(text, parent):
    """The indentation of the first child of `parent` that starts a line; None if none does."""
    for child in parent.children:
        indent = _indent_at(text, child.start)
        if indent is not None:
            return indent
    return None


def _deeper(indent):
    return indent + (indent or "  ")


def _escaped(value, quote='"'):
    value = value.replace("&", "&amp;").replace("<", "&lt;")
    return value.replace(quote, "&quot;" if quote == '"' else "&apos;")


def _attributes_text(values):
    return "".join(f' {name}="{_escaped(value)}"' for name, value in values.items())


def _new_tag(name, values, end="/>"):
    return "<" + name + _attributes_text(values) + end


def _edited_tag(text, element, values):
    """The start tag of `element` with `values` (name -> value) set: attributes it
    has keep their place and quotes, new ones follow its last attribute."""
    attributes = element.attributes(text)
    pieces, last = [], element.start
    for name, (start, end, quote) in attributes.items():
        if name in values:
            pieces += [text[last:start], _escaped(values[name], quote)]
            last = end
    after_attributes = max((end + 1 for _, end, _ in attributes.values()),
                           default=element.start + 1 + len(element.name))
    pieces.append(text[last:after_attributes])
    pieces.append(_attributes_text({k: v for k, v in values.items() if k not in attributes}))
    pieces.append(text[after_attributes:element.tag_end])
    return "".join(pieces)


def _flag_words(changes):
    """<flag> attribute -> 'enable'/'disable' for the changed flags."""
    words = {}
    for bits, names, word in ((changes.disable_set, DISABLE_NAMES, "disable"),
                              (changes.disable_clear, DISABLE_NAMES, "enable"),
                              (changes.enable_set, ENABLE_NAMES, "enable"),
                              (changes.enable_clear, ENABLE_NAMES, "disable")):
        words.update((names[i], word) for i in range(len(names)) if bits >> i & 1)
    return words


def _mjcf_value(name, value):
    if name in ENUM_WORDS:
        return ENUM_WORDS[name][value]
    return repr(value) if isinstance(value, float) else str(value)   # repr: exact round trip


def _option_edits(text, elements, changes, newline):
    """(start, end, replacement) edits that make the option changes."""
    values = {name: _mjcf_value(name, value) for name, value in changes.options.items()}
    flags = _flag_words(changes)
    if not values and not flags:
        return []
    root = elements[0]
    options = [child for child in root.children if child.name == "option"]
    if len(options) == 1 and not any(element.name == "include" for element in elements):
        flag_children = [child for child in options[0].children if child.name == "flag"]
        if len(flag_children) <= 1:
            return _edits_of_option(text, options[0], flag_children, values, flags, newline)
    return [_trailing_option(text, root, values, flags, newline)]


def _edits_of_option(text, option, flag_children, values, flags, newline):
    """Edits of the file's only <option> and its <flag> child (added where missing)."""
    edits = []
    start_tag = _edited_tag(text, option, values) if values else text[option.start:option.tag_end]
    if flags and flag_children:
        flag = flag_children[0]
        edits.append((flag.start, flag.tag_end, _edited_tag(text, flag, flags)))
    elif flags and option.empty:                # <option .../> becomes <option ...>...</option>
        start_tag = re.sub(r"\s*/>\Z", ">", start_tag)
        indent, flag = _indent_at(text, option.start), _new_tag("flag", flags)
        if indent is None:
            start_tag += flag + "</option>"
        else:
            start_tag += newline + _deeper(indent) + flag + newline + indent + "</option>"
    elif flags:
        edits.append(_inserted_child(text, option, _new_tag("flag", flags), newline))
    if start_tag != text[option.start:option.tag_end]:
        edits.append((option.start, option.tag_end, start_tag))
    return edits


def _inserted_child(text, parent, piece, newline):
    """An edit putting `piece` last inside the non-empty `parent`: on a line of its
    own where the end tag starts a line, else right before the end tag."""
    close_indent = _indent_at(text, parent.close)
    if close_indent is None:
        return parent.close, parent.close, piece
    indent = _child_indent(text, parent)
    if indent is None:      # comments or text only: the first indented line inside
        inner = re.search(r"\n([ \t]*)\S", text[parent.tag_end:parent.close])
        indent = inner.group(1) if inner else _deeper(close_indent)
    at = parent.close - len(close_indent)
    return at, at, indent + piece + newline


def _trailing_option(text, root, values, flags, newline):
    """An edit adding a last <option> holding only the changes, which MuJoCo applies
    after any other."""
    indent = _child_indent(text, root)
    on_lines = indent is not None and _indent_at(text, root.close) is not None
    if not flags:
        option = _new_tag("option", values)
    elif not on_lines:
        option = _new_tag("option", values, ">") + _new_tag("flag", flags) + "</option>"
    else:
        option = (_new_tag("option", values, ">") + newline + _deeper(indent)
                  + _new_tag("flag", flags) + newline + indent + "</option>")
    if not on_lines:
        return root.close, root.close, option
    return _inserted_child(text, root, option, newline)


def _names_files(text, elements):
    """Whether any element has a file attribute (file=, a cube texture's fileup=...,
    an <include>'s): without one no path resolves from the model's folder."""
    return any(name.startswith("file") for element in elements
               for name in element.attributes(text))


def _anchor_edits(text, elements, source_dir, newline):
    """Edits making the main file's relative asset folders and included files
    absolute, and naming the source folder for the folders no <compiler> names."""
    edits, named = [], set()
    for element in elements:
        if element.name == "compiler":
            attributes = [a for a in _DIR_ATTRIBUTES if element.value(text, a) is not None]
            named.update(attributes)
        elif element.name in _FILE_ELEMENTS:
            attributes = ["file"] if element.value(text, "file") else []
        else:
            continue
        values = {a: element.value(text, a) for a in attributes}
        values = {a: (_anchored(v, source_dir) if element.name == "compiler"
                      else os.path.join(source_dir, v))
                  for a, v in values.items() if not os.path.isabs(v)}
        if values:
            edits.append((element.start, element.tag_end, _edited_tag(text, element, values)))
    unnamed = [a for a in ("meshdir", "texturedir") if a not in named and "assetdir" not in named]
    if unnamed:
        root = elements[0]
        compiler = _new_tag("compiler", {a: _anchored("", source_dir) for a in unnamed})
        indent = _child_indent(text, root)
        edits.append((root.tag_end, root.tag_end,
                      compiler if indent is None else newline + indent + compiler))
    return edits
