"""Write mjcffi/structs/: one thin Python class per MuJoCo struct.

One module per MuJoCo header (structs/mjmodel.py holds MjOption, MjVisual,
MjStatistic, MjModel, ...).  Each class is a list of fields built from
mjcffi/_support/views.py's pieces: scalars are properties, arrays cached zero-copy
views, nested structs cached wrappers, arrays of structs StructArrays.  A
struct of values only derives from ValueStruct (compared field by field, with
the official repr); one holding pointers from Struct (compared by identity).
The tables below say where MuJoCo's headers alone do not give the official
behaviour: extents, writable scalars, constructors.
"""

import keyword
import re
import textwrap

from . import outputs

_NUMERIC = {"mjtNum", "double", "float", "int", "unsigned int", "mjtSize", "size_t",
            "uintptr_t", "uint64_t", "mjtByte", "unsigned char", "mjtBool"}
_FLOAT = {"mjtNum", "double", "float"}
_NUMERIC_OR_CHAR = _NUMERIC | {"char"}

# Fields read every step: built when the struct is wrapped, so that reading them
# is a plain instance-attribute hit (see mjcffi/_support/views.py).
_EAGER = {"mjData": ("qpos", "qvel", "act", "ctrl", "qacc", "qfrc_applied", "xfrc_applied",
                     "mocap_pos", "mocap_quat", "sensordata", "xpos", "xquat")}

# The public classes of these structs are hand-written subclasses (loading,
# copying, pickling); the generated ones are their bases and are not exported.
_EXTENDED = {"mjModel": "mjcffi/model.py", "mjData": "mjcffi/data.py"}

# char arrays of NUL-separated strings, shown as bytes as the official bindings do
_STRING_BLOBS = {"names", "paths", "text_data"}

# Extents the header comments do not give in a form we can read, or give as the
# count in use where the official bindings show the whole allocation, or in
# another shape than the official.  `self.` names a field of the same struct;
# total(p, n) sums n ints at p.
_EXTENTS = {
    ("mjvGeom", "mat"): (3, 3),
    ("mjvScene", "geoms"): ("self.maxgeom",),
    ("mjvScene", "geomorder"): ("self.maxgeom",),
    ("mjvScene", "flexedge"): ("2*total(self.flexedgenum, self.nflex)",),
    ("mjvScene", "flexvert"): ("3*total(self.flexvertnum, self.nflex)",),
    ("mjvScene", "flexface"): ("9*total(self.flexfacenum, self.nflex)",),
    ("mjvScene", "flexnormal"): ("9*total(self.flexfacenum, self.nflex)",),
    ("mjvScene", "flextexcoord"): ("6*total(self.flexfacenum, self.nflex)",),
    ("mjvScene", "skinvert"): ("3*total(self.skinvertnum, self.nskin)",),
    ("mjvScene", "skinnormal"): ("3*total(self.skinvertnum, self.nskin)",),
}

# Scalars of mjData that may be written (the official bindings let every one be).
# The sizes and addresses stay read-only: a wrong ncon or parena would make
# views and MuJoCo itself reach outside the allocated memory.  pstack, an offset
# into the arena, is bounded by it (see _BOUNDS), so that a test can provoke a
# stack overflow; pbase is an address (of the last mj_markStack's record, 0 when
# none), which no value written from Python can make valid: read-only.
_DATA_WRITABLE = {"time", "pstack"}
_DATA_WRITABLE_PREFIXES = ("maxuse_", "flg_")

# Counts the official MjData lets be written and MJX's get_data_into writes: written
# within what keeps memory safe (mjcffi/_support/official_class.py, efc_count)
_EFC_COUNTS = {("mjData", name) for name in ("ne", "nf", "nl", "ncon", "nefc")}

# Bounds on scalars that nothing in the headers ties to their limit: the value
# must stay within 0..<field of the same struct>.
_BOUNDS = {"mjData": {"pstack": "narena"}}

# Counts and offsets whose fixed array the headers name neither by a "(n<X>)"
# comment nor by the count's name (n<X> for <X> or <X>s): (struct, field) -> the
# array whose rows they count, within 0..rows.
_COUNTS = {
    ("mjuiItemMulti_", "nelem"): "name",          # one name per element of the group
    ("mjuiItemEdit_", "nelem"): "range",          # one range per element of the list
    ("mjvFigure", "legendoffset"): "linename",    # the legend starts at that line
}

# Ids into a fixed array, within -1 (none)..rows-1: MuJoCo's renderer indexes
# the array with them unchecked.
_IDS = {("mjvFigure", "highlightid"): "linepnt"}

# Sizes of memory allocated by mj*_make<Struct> that stay read-only, rather than
# bounded by what was allocated: the official bindings do not let them be
# written either.
_READONLY_SIZES = {("mjrContext", "nskin")}

# Writing the flag also writes the legacy count, 1 or 0, as the official bindings do.
_MIRRORS = {("mjModel", "flg_gravcomp"): "ngravcomp"}

# Structs with value equality by the rules below that the official bindings
# compare by identity instead (and so keep hashable).
_IDENTITY = {"mjvFigure"}

# Structs the official bindings build from their fields: (field, default or
# None for a required argument), in order.
_FIELD_CONSTRUCTORS = {
    "mjrRect": (("left", None), ("bottom", None), ("width", None), ("height", None)),
    "mjrVertexAttribute": (("usage", 0), ("type", 0)),
}

# Initializers that are not mj*_default<Struct>(s): MjvGeom() is an mjGEOM_NONE
# geom with MuJoCo's defaults, as in the official bindings.
_INITIALIZERS = {
    "mjvGeom": "lib.mjv_initGeom(root, lib.mjGEOM_NONE, ffi.NULL, ffi.NULL, ffi.NULL, ffi.NULL)",
}

# Made by mj*_make<Struct> even with no arguments: MjvScene() is
# mjv_makeScene(NULL, scn, 0), whose defaults (scale 1, flags) the official has.
_MAKE_WITHOUT_ARGUMENTS = {"mjvScene"}

# Made for a model whose sizes its buffers take: the constructor records the
# model with this function of mjcffi/_support/checks.py, which the functions that
# write the model into it check (codegen/functions.py, SCENES).
_MADE_FOR = {"mjvScene": "made_for"}

# Made in the OpenGL context current on the calling thread: mjcffi/_support/mjr.py makes and
# frees them, and records that context, which the mjr_* functions check.
_GL_MADE = {"mjrContext"}

# Spec structs.  Their pointer fields to another spec struct (MjsBody.element,
# mjsDefault.joint) give one wrapper, kept on the element's (member_ref), not a raw
# pointer; their char arrays are MjCharVec (char_array).
_SPEC_STRUCT = re.compile(r"^(mjSpec|mjs[A-Z]\w*)$")

# Handle kinds of the spec structs' fields that read and write as Python values
# (mjcffi/_support/element_fields.py, _element_vectors.py): str, live vectors of
# numbers, bytes, lists of str or arrays.
_CONVERTED = {"mjString", "mjDoubleVec", "mjFloatVec", "mjIntVec", "mjByteVec", "mjStringVec",
              "mjIntVecVec", "mjFloatVecVec"}

# Structs whose memory MuJoCo allocates and frees itself: no Python constructor here
# (mjcffi.MjModel and mjcffi.MjData add theirs).  Spec elements live inside an
# mjSpec; a zero-filled mjCache, mjResource or mjSDF has NULL internals that
# MuJoCo would dereference.
_NOT_CONSTRUCTIBLE = re.compile(r"^(mjModel|mjData|mjSpec|mjs[A-Z]\w*|mjCache|mjResource|mjSDF)$")


def class_name(cname):
    """'mjvScene' -> 'MjvScene'; 'mjVisual.global' -> 'MjVisualGlobal'."""
    parts = cname.rstrip("_").split(".")
    return "".join(p[0].upper() + p[1:] for p in parts)


def handle_kinds(decls):
    """The types the headers declare as `typedef void` (mjString, mjDoubleVec, ...):
    handles whose kind cffi cannot see, typed by mjcffi/_support/handles.py."""
    return {name for name, target in decls.typedefs.items() if target.strip() == "void"}


def attr_name(field):
    """C field name as a Python attribute: keywords get a trailing '_' (global_)."""
    return field + "_" if keyword.iskeyword(field) else field


def _header_of(decls, header_texts):
    """struct name -> header file stem, from `struct tag {` in the header text."""
    tag_header = {}
    for header, text in header_texts.items():
        for tag in re.findall(r"\bstruct\s+(\w+)\s*\{", text):
            tag_header.setdefault(tag, header[:-2])
    out = {}
    for name, struct in decls.structs.items():
        out[name] = tag_header.get(struct.tag) or tag_header.get(name)
    return out


class _Context:
    """What the writer of one class needs to know about all the others."""

    def __init__(self, described, decls, header_of, notes):
        self.described = described
        self.header_of = header_of
        self.functions = decls.functions
        self.comment_of = {name: d.doc for name, d in notes.functions.items()}
        # the comment on a struct's opening line, e.g. "physics options"
        self.comment = {name: notes.fields.get((s.tag, ""), "")
                        for name, s in decls.structs.items()}
        self.handles = handle_kinds(decls)
        self.enums = set(decls.enums)
        self._sizing = None
        self.bounds = {}           # struct -> its bounds, see _bounds

    def module_of(self, cname):
        return self.header_of[cname.split(".")[0]]

    def is_struct(self, elem):
        return elem in self.described

    def plain(self, cname, seen=()):
        """No pointer or function-pointer field, recursively: copyable by bytes."""
        for f in self.described[cname]:
            if f.kind in ("pointer", "function"):
                return False
            if self.is_struct(f.elem) and f.elem not in seen and \
                    not self.plain(f.elem, seen + (cname,)):
                return False
        return True

    def sizing(self):
        """{struct: its scalars that size or offset memory a view shows}.

        Every extent of every pointer field counts, whichever struct holds it:
        `self.X` names a field of that struct, `m.X` of mjModel, `d.X` of mjData
        (mjData's arrays are sized by the model, mjvScene.flexedge by nflex)."""
        owners = {"m": "mjModel", "d": "mjData"}
        found = {}
        for cname, infos in self.described.items():
            for f in infos:
                if f.kind != "pointer":
                    continue
                for extent in _extents(cname, f):
                    for owner, name in re.findall(r"\b(self|m|d)\.(\w+)", str(extent)):
                        found.setdefault(owners.get(owner, cname), set()).add(name)
        return {cname: {f.name for f in self.described[cname]
                        if f.kind == "scalar" and f.name in names}
                for cname, names in found.items()}

    def sizes(self, cname):
        """Scalars that size the arrays the struct points to (mjvScene.nflex, maxgeom)."""
        if self._sizing is None:
            self._sizing = self.sizing()
        return self._sizing.get(cname, set())

    def made(self, cname):
        """The void mj*_make<Struct> that allocates the struct's memory, or None."""
        make, _ = self.function("make", cname)
        return make if make is not None and make.restype.decl == "void" else None

    def values(self, cname, seen=()):
        """Only values inside, recursively (C strings count as values): comparable
        field by field."""
        for f in self.described[cname]:
            if f.kind == "function" or f.kind == "pointer" and not _is_cstring(f):
                return False
            if self.is_struct(f.elem) and f.elem not in seen and \
                    not self.values(f.elem, seen + (cname,)):
                return False
        return True

    def function(self, verb, cname, nargs=None):
        """The function `mj*_<verb><Suffix>` for struct `cname`, and its struct argument.

        The suffix must end the struct's name (mjv_makeScene for mjvScene,
        mjb_defaultConfig for mjBatchConfig) and the function must take a
        non-const `cname *`.
        """
        for name, func in self.functions.items():
            match = re.fullmatch(rf"mj[a-z]*_{verb}(\w+)", name)
            if not match or not cname.endswith(match.group(1)):
                continue
            args = [a for a in func.args if a.type.base == cname and a.type.pointer == 1
                    and not a.type.const]
            if args and (nargs is None or len(func.args) == nargs):
                return func, args[0]
        return None, None


def _owner_expr(struct, extent):
    """Python expression for one extent, given the wrapper `s`."""
    if isinstance(extent, int):
        return str(extent)
    expr = extent
    model = "s._ptr" if struct == "mjModel" else "s._model._ptr"
    expr = re.sub(r"\bm\.", model + ".", expr)
    expr = re.sub(r"\bd\.", "s._ptr.", expr)
    expr = re.sub(r"\bself\.", "s._ptr.", expr)
    return expr


def _shape_lambda(struct, extents):
    dims = list(extents)
    if len(dims) == 2 and dims[1] == 1:      # qpos is (nq,), not (nq, 1)
        dims.pop()
    inner = ", ".join(_owner_expr(struct, e) for e in dims)
    return f"lambda s: ({inner},)"


def _count_lambda(struct, extents):
    dims = [e for e in extents if e != 1] or [1]
    return "lambda s: " + " * ".join(_owner_expr(struct, e) for e in dims)


def _pytype(elem):
    if elem in _FLOAT:
        return "float"
    if elem == "mjtBool":
        return "bool"
    return "int"


def _is_cstring(f):
    """A `const char *` of no stated extent: a NUL-terminated string."""
    return f.kind == "pointer" and f.elem == "char" and f.const and not f.extents


def _extents(struct, f):
    return _EXTENTS.get((struct, f.name), f.extents)


def _moves(struct, f):
    return f.moves or any("self." in str(e) for e in _extents(struct, f))


def _field_line(ctx, struct, f, refs):
    """The class-body text for one field: `name = builder(...)` or a property."""
    attr = attr_name(f.name)
    doc = repr(f.doc)
    if f.kind == "scalar" and f.elem in ctx.enums and _SPEC_STRUCT.match(struct) \
            and struct != "mjsElement":
        return f"{attr} = enum_field({f.name!r}, {f.elem!r}, {doc})"
    if (struct, f.name) in _EFC_COUNTS:
        return f"{attr}: int = efc_count({f.name!r}, {doc})"
    if f.kind == "scalar":
        options = _scalar_options(ctx, struct, f)
        return f"{attr}: {_pytype(f.elem)} = scalar({f.name!r}, {doc}{options})"
    if f.kind == "struct":
        refs.add(f.elem)
        return f"{attr} = Nested({f.name!r}, lambda: {class_name(f.elem)}, {doc})"
    if f.kind == "array":
        return _array_line(ctx, struct, f, refs)
    extents = _extents(struct, f)
    if _is_cstring(f):
        return f"{attr}: str = cstring({f.name!r}, {doc})"
    if f.kind == "pointer" and not extents and f.ctype.count("*") == 1:
        if f.elem in ctx.handles:
            if _SPEC_STRUCT.match(struct) and f.elem in _CONVERTED:
                if f.elem == "mjString":
                    return f"{attr}: str = string_field({f.name!r}, {doc})"
                return f"{attr} = vector_field({f.name!r}, {f.elem!r}, {doc})"
            return f"{attr} = handle_field({f.name!r}, {f.elem!r}, {doc})"
        if ctx.is_struct(f.elem) and _SPEC_STRUCT.match(struct) and _SPEC_STRUCT.match(f.elem):
            refs.add(f.elem)
            return f"{attr} = member_ref({f.name!r}, lambda: {class_name(f.elem)}, {doc})"
    if f.kind == "pointer" and extents:
        if f.elem == "char" and f.name in _STRING_BLOBS:
            return (f"{attr}: bytes = chars({f.name!r}, "
                    f"{_count_lambda(struct, extents)}, {doc})")
        if ctx.is_struct(f.elem):
            refs.add(f.elem)
            return (f"{attr} = Records({f.name!r}, lambda: {class_name(f.elem)}, "
                    f"{_count_lambda(struct, extents)}, {doc})")
        if f.elem in _NUMERIC_OR_CHAR:
            kind = "DynamicArray" if _moves(struct, f) else "Array"
            if f.name in _allocated_views(ctx, struct):
                kind = "AllocatedArray"
            fill = ", fill=-1" if "-1: none" in f.doc else ""
            return (f"{attr} = {kind}({f.name!r}, {f.elem!r}, "
                    f"{_shape_lambda(struct, extents)}, {doc}{fill})")
    return f"{attr} = pointer({f.name!r}, {doc})"


def _array_line(ctx, struct, f, refs):
    """A fixed-size array field: text, rows of text, structs or numbers."""
    attr = attr_name(f.name)
    doc = repr(f.doc)
    if f.elem == "char" and len(f.extents) == 1 and _SPEC_STRUCT.match(struct):
        return f"{attr} = char_array({f.name!r}, {f.extents[0]}, {doc})"
    if f.elem == "char" and len(f.extents) == 1:
        return f"{attr}: str = text({f.name!r}, {f.extents[0]}, {doc})"
    if f.elem == "char" and len(f.extents) == 2:      # rows of bytes, as the official shows
        rows, size = f.extents
        return f"{attr} = FixedArray({f.name!r}, 'S{size}', lambda s: ({rows},), {doc})"
    if ctx.is_struct(f.elem):
        refs.add(f.elem)
        return (f"{attr} = FixedRecords({f.name!r}, lambda: {class_name(f.elem)}, "
                f"{_size(f.extents)}, {doc})")
    if f.elem in _NUMERIC_OR_CHAR:
        return (f"{attr} = FixedArray({f.name!r}, {f.elem!r}, "
                f"{_shape_lambda(struct, _extents(struct, f))}, {doc})")
    return f"{attr} = pointer({f.name!r}, {doc})"


def _scalar_options(ctx, struct, f):
    options = ""
    if _readonly(ctx, struct, f):
        options += ", readonly=True"
    if f.elem == "mjtBool":
        options += ", boolean=True"
    mirror = _MIRRORS.get((struct, f.name))
    if mirror:
        options += f", mirror={mirror!r}"
    return options


def _readonly(ctx, struct, f):
    """Scalars whose writing would break MuJoCo's invariants or overrun memory."""
    if struct == "mjModel":
        return not f.name.startswith("flg_")     # sizes and addresses of the compiled model
    if struct == "mjData":
        return not (f.name in _DATA_WRITABLE or f.name.startswith(_DATA_WRITABLE_PREFIXES))
    return f.name in ctx.sizes(struct) and f.name not in _bounds(ctx, struct)


def _bounds(ctx, struct):
    """{scalar: (low, high, label)}, computed once per struct (see _derive_bounds)."""
    cached = ctx.bounds.get(struct)
    if cached is None:
        cached = ctx.bounds[struct] = _derive_bounds(ctx, struct)
    return cached


def _derive_bounds(ctx, struct):
    """{scalar: (low, high, label)}: the values each bounded scalar may take.

    `high` is an int, a field of the same struct, or None for what MuJoCo
    allocated (the field's value when the struct is wrapped); see _views.Bound.
    Derived from the headers:
    - n<X> within max<X> of the same struct (ngeom within 0..maxgeom);
    - a count within the fixed array it counts: the array's comment ends in
      "(n<X>)" (nlight: lights), or it is named <X> or <X>s (nsect: sect);
    - a size of memory that mj*_make<Struct> allocates within what it allocated
      (a scene's maxgeom, nflex and nskin), but for _READONLY_SIZES;
    and from the tables _COUNTS, _IDS and _BOUNDS for the rest.
    """
    infos = ctx.described[struct]
    scalars = {f.name for f in infos if f.kind == "scalar" and f.elem not in _FLOAT}
    rows = {f.name: f.extents[0] for f in infos if f.kind == "array" and f.extents}
    out = {}
    for f in infos:
        counted = re.search(r"\((n\w+)\)$", f.doc)
        if f.name in rows and counted and counted.group(1) in scalars:
            out[counted.group(1)] = (0, rows[f.name], f"len({f.name})")
    for name in sorted(scalars):
        if not name.startswith("n") or name in out:
            continue
        if "max" + name[1:] in scalars:
            out[name] = (0, "max" + name[1:], "max" + name[1:])
        for array in (name[1:], name[1:] + "s"):
            if array in rows:
                out[name] = (0, rows[array], f"len({array})")
    for (owner, name), array in _COUNTS.items():
        if owner == struct:
            out[name] = (0, rows[array], f"len({array})")
    for (owner, name), array in _IDS.items():
        if owner == struct:
            out[name] = (-1, rows[array] - 1, f"an index into {array}, -1: none")
    make = ctx.made(struct)
    if make is not None:
        for name in sorted(ctx.sizes(struct) - {n for o, n in _READONLY_SIZES if o == struct}):
            out.setdefault(name, (0, None, f"the {name} allocated by {make.name}"))
    for name, limit in _BOUNDS.get(struct, {}).items():
        out[name] = (0, limit, limit)
    return out


def _allocated_views(ctx, struct):
    """Pointer fields sized by counts held in other arrays of the struct (a scene's
    flexedge: 2*sum(flexedgenum)), in a struct that mj*_make<Struct> allocates:
    their size is kept within what was allocated (see _views.AllocatedArray)."""
    if ctx.made(struct) is None:
        return ()
    arrays = {f.name for f in ctx.described[struct] if f.kind == "pointer"}
    return tuple(f.name for f in ctx.described[struct] if f.kind == "pointer" and any(
        name in arrays for extent in _extents(struct, f)
        for name in re.findall(r"\bself\.(\w+)", str(extent))))


def _check_sizes(ctx):
    """Every scalar that sizes a view is read-only or bounded: fail the generator
    when a new MuJoCo adds one that is neither."""
    for struct, infos in ctx.described.items():
        arrays = {f.name for f in infos if f.kind == "pointer"}
        for f in infos:
            sized_by = {name for extent in _extents(struct, f)
                        for name in re.findall(r"\bself\.(\w+)", str(extent))} & arrays
            if f.kind == "pointer" and sized_by and f.name not in _allocated_views(ctx, struct):
                raise ValueError(f"{struct}.{f.name} is sized by the arrays {sorted(sized_by)} "
                                 f"with nothing to bound it")
    for struct, names in ctx.sizing().items():
        infos = {f.name: f for f in ctx.described[struct]}
        bounds = _bounds(ctx, struct)
        loose = sorted(n for n in names
                       if not _readonly(ctx, struct, infos[n]) and n not in bounds)
        if loose:
            raise ValueError(f"{struct}: {', '.join(loose)} size views but are neither "
                             f"read-only nor bounded; add a bound (see _bounds)")


def _repr_fields(ctx, struct):
    """The fields of the short repr of a struct compared by identity."""
    infos = ctx.described[struct]
    if struct == "mjModel":
        wanted = ["nq", "nv", "nu", "na", "nbody", "njnt", "ngeom", "nsite", "nsensor", "nkey"]
        return tuple(w for w in wanted if any(f.name == w for f in infos))
    if struct == "mjData":
        return ("time", "ncon", "nefc")
    small = [f.name for f in infos if f.kind == "scalar" or
             f.kind == "array" and f.elem in _NUMERIC and _size(f.extents) <= 16]
    return tuple(attr_name(n) for n in small[:12])


def _by_value(ctx, struct):
    """Compared field by field (and so unhashable), as the official bindings do."""
    return ctx.values(struct) and struct not in _IDENTITY and \
        not _NOT_CONSTRUCTIBLE.match(struct)


def _size(extents):
    size = 1
    for n in extents:
        size *= n
    return size


def _constructor(ctx, struct):
    """Lines of __init__ for one class, or [] when it has none."""
    pycls = class_name(struct)
    if struct in _FIELD_CONSTRUCTORS:
        return _field_constructor(struct)
    if "." in struct:
        return []                          # Struct.__init__ zero-initializes
    if _NOT_CONSTRUCTIBLE.match(struct):
        return ["    def __init__(self, *args, **kwargs):",
                f"        raise TypeError({pycls + ' has no constructor: MuJoCo creates it'!r})",
                ""]
    default, _ = ctx.function("default", struct, nargs=1)
    make, made = ctx.function("make", struct)
    if struct in _GL_MADE:
        return _gl_constructor(struct)
    if make is not None and make.restype.decl == "void":
        return _make_constructor(ctx, struct, default, make, made)
    init = f"lib.{default.name}(root)" if default is not None else _INITIALIZERS.get(struct)
    if init is None:
        return []                          # Struct.__init__ zero-initializes
    lines = ["    def __init__(self):"]
    delete, _ = ctx.function("delete", struct, nargs=1)
    lines.append(f'        """A new {struct}, initialized by {init.split("(")[0][4:]}."""')
    lines.append(f"        root = ffi.new({struct + ' *'!r})")
    lines.append(f"        {init}")
    if delete is not None:
        lines.append(f"        root = ffi.gc(root, lib.{delete.name})")
    lines.append("        self._init_root(root)")
    lines.append("")
    return lines


def _make_constructor(ctx, struct, default, make, made):
    """__init__ of a struct made by mj*_make<Struct>: with all its arguments or none."""
    pycls = class_name(struct)
    extra = [a for a in make.args if a is not made]
    free, _ = ctx.function("free", struct, nargs=1)
    names = [_param(a) for a in extra]
    always = struct in _MAKE_WITHOUT_ARGUMENTS
    lines = [f"    def __init__(self, {', '.join(n + '=None' for n in names)}):"]
    lines.append(f'        """{pycls}() is ' +
                 (f"made by {make.name} with no model" if always else "default-initialized") +
                 f'; {pycls}({", ".join(names)}) is made by {make.name}' +
                 (f" and freed by {free.name} when collected" if free else "") + '."""')
    if len(names) > 1:
        lines.append(f"        if len({{x is None for x in ({', '.join(names)})}}) > 1:")
        message = f"{pycls} takes {' and '.join(names)} together, or none of them"
        lines.append(f"            raise TypeError({message!r})")
    lines.append(f"        root = ffi.new({struct + ' *'!r})")
    if default is not None:
        lines.append(f"        lib.{default.name}(root)")
    call = ", ".join("root" if a is made else _arg_expr(a, always) for a in make.args)
    indent = "        "
    if not always:
        lines.append(f"        if {names[0]} is not None:")
        indent += "    "
    lines.append(f"{indent}guarded(lib.mjcffi_guard_{make.name}, {call})")
    if free is not None:
        lines.append(f"{indent}root = ffi.gc(root, lib.{free.name})")
    lines.append("        self._init_root(root)")
    if struct in _MADE_FOR:
        model = next(_param(a) for a in extra if a.type.base == "mjModel")
        lines.append(f"        {_MADE_FOR[struct]}(self, ffi.NULL if {model} is None "
                     f"else {model}._ptr)")
    lines.append("")
    return lines


def _gl_constructor(struct):
    """__init__, free() and __repr__ of an mjrContext: made and freed through
    mjcffi/_support/mjr.py, which records the OpenGL context it was made in."""
    pycls = class_name(struct)
    return [
        "    def __init__(self, model=None, fontscale=None):",
        f'        """{pycls}() is default-initialized: it cannot draw.  {pycls}(model, '
        'fontscale)',
        "        is made by mjr_makeContext in the OpenGL context current on this thread "
        "(FatalError",
        "        if none is: make a GLContext current first), and freed by free() or when "
        "collected.",
        "",
        "        Every mjr_* function checks that it was made and not freed, and that the "
        "OpenGL",
        "        context it was made in is current (mjcffi/_support/mjr.py).",
        '        """',
        "        if len({x is None for x in (model, fontscale)}) > 1:",
        "            raise TypeError(" + repr(f"{pycls} takes model and fontscale together, "
                                             "or none of them") + ")",
        "        root, record = new_context()",
        "        if model is not None:",
        "            make_context(root, record, struct_pointer(model, 'mjModel', 'model'),",
        "                         int_argument(fontscale, 'fontscale', 'int'))",
        "        self._init_root(root, _mjr=record)",
        "",
        "    def free(self):",
        '        """Free its OpenGL resources now (mjr_freeContext), as the official '
        'free(); it is',
        "        then default, and the mjr_* functions refuse it.  Freeing again does "
        "nothing.  With",
        "        another OpenGL context current (or none), only MuJoCo's memory is freed "
        "here: its",
        '        OpenGL objects go with the context they were made in."""',
        "        release_context(self._ptr, self._mjr)",
        "",
        "    def __repr__(self):",
        "        return context_repr(self, super().__repr__())",
        "",
    ]


def _field_constructor(struct):
    """__init__ taking the struct's fields, as the official MjrRect(left, bottom, ...)."""
    fields = _FIELD_CONSTRUCTORS[struct]
    params = ", ".join(n if d is None else f"{n}={d!r}" for n, d in fields)
    lines = [f"    def __init__(self, {params}):",
             f'        """{class_name(struct)}({", ".join(n for n, _ in fields)}): '
             f'a new {struct} with these fields."""',
             "        super().__init__()"]
    lines += [f"        self.{n} = {n}" for n, _ in fields]
    return lines + [""]


def _param(arg):
    return "model" if arg.type.base == "mjModel" else ("data" if arg.type.base == "mjData"
                                                       else arg.name)


def _arg_expr(arg, optional=False):
    """The C argument for the Python parameter of `arg`: NULL or 0 when `optional`
    and the parameter is None."""
    name = _param(arg)
    if arg.type.pointer and arg.type.base in ("mjModel", "mjData"):
        expr = f"struct_pointer({name}, {arg.type.base!r}, {name!r})"
        return f"ffi.NULL if {name} is None else {expr}" if optional else expr
    expr = f"int_argument({name}, {name!r}, {arg.type.decl!r})"
    return f"0 if {name} is None else {expr}" if optional else expr


def _class(ctx, struct, refs):
    infos = ctx.described[struct]
    pycls = class_name(struct)
    doc = ctx.comment.get(struct) or ""
    by_value = _by_value(ctx, struct)
    lines = [f"class {pycls}({'ValueStruct' if by_value else 'Struct'}):",
             f'    """{struct}' + (f": {doc}" if doc else "") + '."""',
             "",
             f"    _cname = {struct!r}",
             f"    _ctype = struct_type({struct!r})",
             f"    _fields = {tuple(attr_name(f.name) for f in infos)!r}"]
    if not by_value:
        lines.append(f"    _repr_fields = {_repr_fields(ctx, struct)!r}")
    if not ctx.plain(struct):
        lines.append("    _plain = False")
    bounds = _bounds(ctx, struct)
    if bounds:
        lines.append("    _bounds = {")
        lines += [f"        {name!r}: Bound({low!r}, {high!r}, {label!r}),"
                  for name, (low, high, label) in bounds.items()]
        lines.append("    }")
    capacities = tuple(name for name, (_, high, _) in bounds.items() if high is None)
    if capacities:
        lines.append(f"    _capacities = {capacities!r}")
    allocated = _allocated_views(ctx, struct)
    if allocated:
        lines.append(f"    _allocated_views = {allocated!r}")
    aliases = _nested_aliases(ctx, struct)
    lines += [""] + (["    # the nested structs under their official names"] + aliases + [""]
                     if aliases else [])
    lines += _constructor(ctx, struct)
    lines += _official_class(ctx, struct)
    hot = _EAGER.get(struct, ())
    if hot:
        # slots: descriptors in the class dict, as the official's fields are, that
        # read as fast as the plain instance attributes they replace
        names = textwrap.wrap(", ".join(repr(name) for name in hot), 80)
        lines += ["    __slots__ = (" + "\n                 ".join(names) + ")", ""]
    eager = []
    for f in infos:
        line = _field_line(ctx, struct, f, refs)
        if f.name in hot:            # an `_eager` entry, with no class attribute
            name, _, builder = line.partition(" = ")
            lines.append(f"    {name}: ndarray")
            eager.append(builder)
        else:
            lines.append("    " + line)
    lines += _element_methods(ctx, struct)
    if eager:
        lines += ["", "    _eager = eager("] + [f"        {e}," for e in eager] + ["    )"]
    return lines


def _official_class(ctx, struct):
    """What the official MjModel and MjData classes show beyond the fields
    (mjcffi/_support/official_class.py): their fields in the hand-written subclass's
    own class dict, and MjModel._sizes."""
    if struct not in _EXTENDED:
        return []
    pycls = class_name(struct)
    lines = ["    def __init_subclass__(cls, **kwargs):",
             f'        """The fields in the subclass\'s own class dict too, as in the official '
             f'{pycls}\'s."""',
             "        super().__init_subclass__(**kwargs)",
             "        hoist(cls)",
             ""]
    if struct == "mjModel":
        count = 0
        for f in ctx.described[struct]:
            if f.kind != "scalar" or f.ctype != "mjtSize":
                break
            count += 1
        lines += ["    @property",
                  "    def _sizes(self):",
                  f'        """The {count} sizes at the head of mjModel (nq ... nbuffer) as a '
                  f'new read-only',
                  '        int64 array, as the official MjModel._sizes; MJX reads them."""',
                  f"        return sizes(self._ptr, {count})",
                  ""]
    return lines


def _element_methods(ctx, struct):
    """A spec element's `name`, and its add_* / wrap_* methods, one per mjs_add* /
    mjs_wrap* function taking the struct first (mjs_addGeom: MjsBody.add_geom)."""
    if not _SPEC_STRUCT.match(struct) or struct == "mjsElement":
        return []
    infos = ctx.described[struct]
    lines = []
    if struct != "mjSpec" and infos and infos[0].name == "element" and \
            all(f.name != "name" for f in infos):
        lines.append("    name: str = element_name()")
    if struct != "mjSpec":
        lines.append("    __setattr__ = element_setattr()")
    for fname, func in ctx.functions.items():
        match = re.fullmatch(r"mjs_(add|wrap)(\w+)", fname)
        if not match or not func.args or func.args[0].type.base != struct \
                or not _SPEC_STRUCT.match(func.restype.base or ""):
            continue
        method = f"{match.group(1)}_{match.group(2).lower()}"
        params = tuple((a.name, _adder_kind(a)) for a in func.args[1:])
        doc = ctx.comment_of.get(fname, "") or fname
        result = class_name(func.restype.base)
        lines.append(f"    {method} = adder({fname!r}, lambda: {result}, {params!r}, {doc!r})")
    if struct == "mjsFrame":
        lines += _frame_methods(ctx)
    return lines


# What a body has that a frame does not (the official MjsFrame has no add_freejoint:
# a free joint cannot sit in a frame).
_NOT_IN_FRAMES = {"mjs_addFreeJoint"}


def _frame_methods(ctx):
    """MjsFrame.add_*: the body's mjs_add* functions, placing the element in the frame."""
    lines = []
    for fname, func in ctx.functions.items():
        match = re.fullmatch(r"mjs_add(\w+)", fname)
        if not match or fname in _NOT_IN_FRAMES or not func.args \
                or func.args[0].type.base != "mjsBody":
            continue
        params = tuple((a.name, _adder_kind(a)) for a in func.args[1:])
        doc = ctx.comment_of.get(fname, "") or fname
        result = class_name(func.restype.base)
        lines.append(f"    add_{match.group(1).lower()} = frame_adder({fname!r}, lambda: {result}, "
                     f"{params!r}, {doc!r})")
    return lines


def _adder_kind(arg):
    """How an add_* method takes one argument of its mjs_add* function (see
    mjcffi/_support/element_adders.py, adder)."""
    if arg.name == "def" and arg.type.base == "mjsDefault":
        return "default"
    if arg.type.base == "char" and arg.type.pointer == 1:
        return "text"
    if arg.type.base == "double" and not arg.type.pointer:
        return "double"
    if _SPEC_STRUCT.match(arg.type.base) and arg.type.pointer == 1:
        return arg.type.base
    raise ValueError(f"no add_* argument for {arg.type.decl} {arg.name}")


# Elements that are no MjStruct: the official's union holds those a compiled model
# binds to (model.bind), which a wrap and a default are not.
_NOT_MJSTRUCT = {"mjsWrap", "mjsDefault"}


def _elements_of(ctx, structs):
    return [s for s in structs
            if s != "mjsElement" and _SPEC_STRUCT.match(s) and ctx.described[s]
            and ctx.described[s][0].name == "element" and s != "mjSpec"]


def _element_classes(ctx, structs):
    """The line registering the element classes of mjspec.h with _elements.register,
    and MjStruct: the union of the element classes, as the official's."""
    elements = _elements_of(ctx, structs)
    if not elements:
        return []
    wrapped = textwrap.wrap(", ".join(class_name(s) for s in elements), 88)
    members = textwrap.wrap(", ".join(class_name(s) for s in elements
                                      if s not in _NOT_MJSTRUCT), 80)
    return ["register(" + "\n         ".join(wrapped) + ")",
            "",
            "# the spec elements a compiled model binds to (model.bind), as a type",
            "MjStruct = Union[" + "\n                 ".join(members) + "]"]


def generate(described, decls, header_texts, notes):
    """{relative path: text} for mjcffi/structs/*.py."""
    header_of = _header_of(decls, header_texts)
    ctx = _Context(described, decls, header_of, notes)
    _check_sizes(ctx)
    modules, order = {}, []
    for struct in described:
        module = ctx.module_of(struct)
        if module not in modules:
            modules[module] = []
            order.append(module)
        modules[module].append(struct)

    files, exports, deps = {}, {}, {}
    for module in order:
        refs, body = set(), []
        for struct in _nested_first(modules[module]):
            body += _class(ctx, struct, refs) + ["", ""]
            if struct not in _EXTENDED:
                exports[class_name(struct)] = module
        body += _element_classes(ctx, modules[module])
        others = sorted({ctx.module_of(r) for r in refs} - {module})
        deps[module] = others
        head = [outputs.HEADER_PY.rstrip("\n"),
                f'"""The structs of MuJoCo\'s {module}.h, as thin classes over C memory."""',
                "",
                *_imports(body)]
        for other in others:
            names = sorted({class_name(r) for r in refs if ctx.module_of(r) == other})
            head.append(f"from .{other} import {', '.join(names)}")
        head.append("")
        public = [class_name(s) for s in modules[module] if s not in _EXTENDED]
        if _elements_of(ctx, modules[module]):
            public.append("MjStruct")          # a type, not a struct: not in MODULES
        head.append("__all__ = [" + ", ".join(repr(name) for name in public) + "]")
        head += ["", ""]
        files[f"mjcffi/structs/{module}.py"] = "\n".join(head + body).rstrip("\n") + "\n"
    _check_acyclic(deps)
    files["mjcffi/structs/__init__.py"] = _package(exports)
    files["mjcffi/structs/__init__.pyi"] = _package_stub(order)
    return files


def _nested_first(structs):
    """The module's structs with each nested one before the struct holding it, so
    that the outer class can name it (MjVisual.Global)."""
    roots = [s for s in structs if "." not in s]
    return sorted(structs, key=lambda s: (roots.index(s.split(".")[0]), "." not in s))


def _nested_aliases(ctx, struct):
    """`Global = MjVisualGlobal`: the official names of the struct's nested structs."""
    return [f"    {inner.rpartition('.')[2].capitalize()} = {class_name(inner)}"
            for inner in ctx.described if inner.rpartition(".")[0] == struct]


def _package_stub(modules):
    """The type stub of the lazy package: what its __getattr__ can return."""
    lines = [outputs.HEADER_PY.rstrip("\n")]
    lines += [f"from .{module} import *" for module in modules]
    return "\n".join(lines) + "\n"


_VIEWS_NAMES = ("AllocatedArray", "Array", "Bound", "DynamicArray", "FixedArray", "FixedRecords", "Nested",
                "Records", "Struct", "ValueStruct", "chars", "cstring", "eager", "guarded",
                "int_argument", "pointer", "scalar", "struct_pointer", "struct_type", "text",
                "total")


def _imports(body):
    """Import lines for exactly the names the class bodies use."""
    text = "\n".join(body)
    library = [n for n in ("ffi", "lib") if re.search(rf"\b{n}\.", text)]
    lines = ["from typing import Union", ""] if "= Union[" in text else []
    lines += ["from numpy import ndarray", ""] if ": ndarray" in text else []
    lines += [f"from .._support.library import {', '.join(library)}"] if library else []
    views = [n for n in _VIEWS_NAMES if re.search(rf"\b{n}\(|\({n}\):", text)]
    line = "from .._support.views import " + ", ".join(views)
    if len(line) > 99:
        wrapped = textwrap.wrap(", ".join(views), 76)
        line = "from .._support.views import (" + "\n                              ".join(wrapped) + ")"
    lines.append(line)
    for module, names in (("checks", sorted(set(_MADE_FOR.values()))),
                          ("handles", ("handle_field", "struct_ref")),
                          ("element_adders", ("adder", "frame_adder")),
                          ("element_fields", ("char_array", "element_name", "element_setattr",
                                              "enum_field", "member_ref", "string_field")),
                          ("element_vectors", ("vector_field",)),
                          ("elements", ("register",)),
                          ("mjr", ("context_repr", "make_context", "new_context",
                                   "release_context")),
                          ("official_class", ("efc_count", "hoist", "sizes"))):
        used = [n for n in names if re.search(rf"\b{n}\(", text)]
        if used:
            line = f"from .._support.{module} import {', '.join(used)}"
            if len(line) > 99:
                indent = " " * len(f"from .._support.{module} import (")
                wrapped = textwrap.wrap(", ".join(used), 99 - len(indent))
                line = (f"from .._support.{module} import (" + f"\n{indent}".join(wrapped)
                        + ")")
            lines.append(line)
    return lines


def _check_acyclic(deps):
    state = {}

    def visit(module, path):
        if state.get(module) == "done":
            return
        if state.get(module) == "active":
            raise ValueError(f"struct modules import each other: {' -> '.join(path + [module])}")
        state[module] = "active"
        for other in deps.get(module, ()):
            visit(other, path + [module])
        state[module] = "done"

    for module in deps:
        visit(module, [])


def _package(exports):
    lines = [outputs.HEADER_PY.rstrip("\n"),
             '"""Thin classes over MuJoCo\'s structs, one module per header.',
             "",
             "Modules load on first use of one of their classes, so that `import mjcffi`",
             "stays cheap.",
             '"""',
             "",
             "import importlib",
             "",
             "# class name -> module (MuJoCo header) that defines it",
             "MODULES = {"]
    lines += [f"    {name!r}: {module!r}," for name, module in exports.items()]
    lines += ["}",
              "",
              "__all__ = list(MODULES)",
              "",
              "",
              "def __getattr__(name):",
              "    module = MODULES.get(name)",
              "    if module is None:",
              '        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")',
              '    value = getattr(importlib.import_module(f".{module}", __name__), name)',
              "    globals()[name] = value",
              "    return value",
              "",
              "",
              "def __dir__():",
              "    return sorted(set(globals()) | set(MODULES))",
              ""]
    return "\n".join(lines)
