"""Write mjcffi/structs/: one thin Python class per MuJoCo struct.

One module per MuJoCo header (structs/mjmodel.py holds MjOption, MjVisual,
MjStatistic, MjModel, ...).  Each class is a list of fields built from
mjcffi/_views.py's pieces: scalars are properties, arrays cached zero-copy
views, nested structs cached wrappers, arrays of structs StructArrays.
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
# is a plain instance-attribute hit (see mjcffi/_views.py).
_EAGER = {"mjData": ("qpos", "qvel", "act", "ctrl", "qacc", "qfrc_applied", "xfrc_applied",
                     "mocap_pos", "mocap_quat", "sensordata", "xpos", "xquat")}

# The public classes of these structs are hand-written subclasses (loading,
# copying, pickling); the generated ones are their bases and are not exported.
_EXTENDED = {"mjModel": "mjcffi/model.py", "mjData": "mjcffi/data.py"}

# char arrays of NUL-separated strings, shown as bytes as the official bindings do
_STRING_BLOBS = {"names", "paths", "text_data"}

# Structs whose memory MuJoCo allocates and frees itself: no Python constructor here
# (mjcffi.MjModel and mjcffi.MjData add theirs).  Spec elements live inside an
# mjSpec; a zero-filled mjCache, mjResource or mjSDF has NULL internals that
# MuJoCo would dereference.
_NOT_CONSTRUCTIBLE = re.compile(r"^(mjModel|mjData|mjSpec|mjs[A-Z]\w*|mjCache|mjResource|mjSDF)$")


def class_name(cname):
    """'mjvScene' -> 'MjvScene'; 'mjVisual.global' -> 'MjVisualGlobal'."""
    parts = cname.rstrip("_").split(".")
    return "".join(p[0].upper() + p[1:] for p in parts)


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
        # the comment on a struct's opening line, e.g. "physics options"
        self.comment = {name: notes.fields.get((s.tag, ""), "")
                        for name, s in decls.structs.items()}

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


def _field_line(ctx, struct, f, refs):
    """The class-body text for one field: `name = builder(...)` or a property."""
    attr = attr_name(f.name)
    doc = repr(f.doc)
    if f.kind == "scalar":
        readonly = ", readonly=True" if _readonly(struct, f) else ""
        return f"{attr}: {_pytype(f.elem)} = scalar({f.name!r}, {doc}{readonly})"
    if f.kind == "struct":
        refs.add(f.elem)
        return f"{attr} = Nested({f.name!r}, lambda: {class_name(f.elem)}, {doc})"
    if f.kind == "array":
        if f.elem == "char" and len(f.extents) == 1:
            return f"{attr}: str = text({f.name!r}, {f.extents[0]}, {doc})"
        if ctx.is_struct(f.elem):
            refs.add(f.elem)
            return (f"{attr} = FixedRecords({f.name!r}, lambda: {class_name(f.elem)}, "
                    f"{_size(f.extents)}, {doc})")
        if f.elem in _NUMERIC_OR_CHAR:
            return (f"{attr} = FixedArray({f.name!r}, {f.elem!r}, "
                    f"{_shape_lambda(struct, f.extents)}, {doc})")
        return f"{attr} = pointer({f.name!r}, {doc})"
    if f.kind == "pointer" and f.extents:
        if f.elem == "char" and f.name in _STRING_BLOBS:
            return (f"{attr}: bytes = chars({f.name!r}, "
                    f"{_count_lambda(struct, f.extents)}, {doc})")
        if ctx.is_struct(f.elem):
            refs.add(f.elem)
            return (f"{attr} = Records({f.name!r}, lambda: {class_name(f.elem)}, "
                    f"{_count_lambda(struct, f.extents)}, {doc})")
        if f.elem in _NUMERIC_OR_CHAR:
            kind = "DynamicArray" if f.moves else "Array"
            return (f"{attr} = {kind}({f.name!r}, {f.elem!r}, "
                    f"{_shape_lambda(struct, f.extents)}, {doc})")
    return f"{attr} = pointer({f.name!r}, {doc})"


def _readonly(struct, f):
    """Scalars whose writing would break MuJoCo's invariants."""
    if struct == "mjModel":
        return True                        # sizes and addresses of the compiled model
    if struct == "mjData":
        return f.name != "time"            # sizes, stack and arena bookkeeping
    return f.name.startswith("max") or f.name in ("nbuffer", "narena")


def _bounds(ctx, struct):
    """Scalars n<X> that must stay within max<X> of the same struct (ngeom <= maxgeom)."""
    names = {f.name for f in ctx.described[struct]}
    return {f.name: "max" + f.name[1:] for f in ctx.described[struct]
            if f.kind == "scalar" and f.name.startswith("n") and "max" + f.name[1:] in names}


def _repr_fields(ctx, struct):
    infos = ctx.described[struct]
    if struct == "mjModel":
        wanted = ["nq", "nv", "nu", "na", "nbody", "njnt", "ngeom", "nsite", "nsensor", "nkey"]
        return tuple(w for w in wanted if any(f.name == w for f in infos))
    if struct == "mjData":
        return ("time", "ncon", "nefc")
    small = [f.name for f in infos if f.kind == "scalar" or
             f.kind == "array" and f.elem in _NUMERIC and _size(f.extents) <= 16]
    return tuple(attr_name(n) for n in small[:12])


def _size(extents):
    size = 1
    for n in extents:
        size *= n
    return size


def _constructor(ctx, struct):
    """Lines of __init__ for one class, or [] when it has none."""
    pycls = class_name(struct)
    if "." in struct:
        return []                          # Struct.__init__ zero-initializes
    if _NOT_CONSTRUCTIBLE.match(struct):
        return ["    def __init__(self, *args, **kwargs):",
                f"        raise TypeError({pycls + ' has no constructor: MuJoCo creates it'!r})",
                ""]
    default, _ = ctx.function("default", struct, nargs=1)
    make, made = ctx.function("make", struct)
    lines = []
    if make is not None and make.restype.decl == "void":
        extra = [a for a in make.args if a is not made]
        free, _ = ctx.function("free", struct, nargs=1)
        params = ", ".join(f"{_param(a)}=None" for a in extra)
        lines.append(f"    def __init__(self, {params}):")
        lines.append(f'        """{pycls}() is zero- or default-initialized; {pycls}('
                     f'{", ".join(_param(a) for a in extra)}) is made by {make.name}'
                     + (f" and freed by {free.name} when collected" if free else "") + '."""')
        lines.append(f"        root = ffi.new({struct + ' *'!r})")
        if default is not None:
            lines.append(f"        lib.{default.name}(root)")
        given = " or ".join(f"{_param(a)} is not None" for a in extra)
        lines.append(f"        if {given}:")
        call = ", ".join("root" if a is made else _arg_expr(a) for a in make.args)
        lines.append(f"            guarded(lib.mjcffi_guard_{make.name}, {call})")
        if free is not None:
            lines.append(f"            root = ffi.gc(root, lib.{free.name})")
        lines.append("        self._init_root(root)")
        lines.append("")
        return lines
    if default is None:
        return []                          # Struct.__init__ zero-initializes
    lines.append("    def __init__(self):")
    delete, _ = ctx.function("delete", struct, nargs=1)
    lines.append(f'        """A new {struct}, initialized by {default.name}."""')
    lines.append(f"        root = ffi.new({struct + ' *'!r})")
    lines.append(f"        lib.{default.name}(root)")
    if delete is not None:
        lines.append(f"        root = ffi.gc(root, lib.{delete.name})")
    lines.append("        self._init_root(root)")
    lines.append("")
    return lines


def _param(arg):
    return "model" if arg.type.base == "mjModel" else ("data" if arg.type.base == "mjData"
                                                       else arg.name)


def _arg_expr(arg):
    if arg.type.pointer and arg.type.base in ("mjModel", "mjData"):
        return f"struct_pointer({_param(arg)}, {arg.type.base!r}, {_param(arg)!r})"
    return f"int_argument({_param(arg)}, {_param(arg)!r})"


def _class(ctx, struct, refs):
    infos = ctx.described[struct]
    pycls = class_name(struct)
    doc = ctx.comment.get(struct) or ""
    lines = [f"class {pycls}(Struct):",
             f'    """{struct}' + (f": {doc}" if doc else "") + '."""',
             "",
             f"    _cname = {struct!r}",
             f"    _ctype = struct_type({struct!r})",
             f"    _repr_fields = {_repr_fields(ctx, struct)!r}"]
    if not ctx.plain(struct):
        lines.append("    _plain = False")
    bounds = _bounds(ctx, struct)
    if bounds:
        lines.append(f"    _bounds = {bounds!r}")
    lines.append("")
    lines += _constructor(ctx, struct)
    hot = _EAGER.get(struct, ())
    eager = []
    for f in infos:
        line = _field_line(ctx, struct, f, refs)
        if f.name in hot:            # an `_eager` entry, with no class attribute
            name, _, builder = line.partition(" = ")
            lines.append(f"    {name}: ndarray")
            eager.append(builder)
        else:
            lines.append("    " + line)
    if eager:
        lines += ["", "    _eager = eager("] + [f"        {e}," for e in eager] + ["    )"]
    return lines


def generate(described, decls, header_texts, notes):
    """{relative path: text} for mjcffi/structs/*.py."""
    header_of = _header_of(decls, header_texts)
    ctx = _Context(described, decls, header_of, notes)
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
        for struct in modules[module]:
            body += _class(ctx, struct, refs) + ["", ""]
            if struct not in _EXTENDED:
                exports[class_name(struct)] = module
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
        head.append("__all__ = [" + ", ".join(repr(name) for name in public) + "]")
        head += ["", ""]
        files[f"mjcffi/structs/{module}.py"] = "\n".join(head + body).rstrip("\n") + "\n"
    _check_acyclic(deps)
    files["mjcffi/structs/__init__.py"] = _package(exports)
    files["mjcffi/structs/__init__.pyi"] = _package_stub(order)
    return files


def _package_stub(modules):
    """The type stub of the lazy package: what its __getattr__ can return."""
    lines = [outputs.HEADER_PY.rstrip("\n")]
    lines += [f"from .{module} import *" for module in modules]
    return "\n".join(lines) + "\n"


_VIEWS_NAMES = ("Array", "DynamicArray", "FixedArray", "FixedRecords", "Nested", "Records",
                "Struct", "chars", "eager", "guarded", "int_argument", "pointer", "scalar",
                "struct_pointer", "struct_type", "text")


def _imports(body):
    """Import lines for exactly the names the class bodies use."""
    text = "\n".join(body)
    library = [n for n in ("ffi", "lib") if re.search(rf"\b{n}\.", text)]
    lines = ["from numpy import ndarray", ""] if ": ndarray" in text else []
    lines += [f"from .._library import {', '.join(library)}"] if library else []
    views = [n for n in _VIEWS_NAMES if re.search(rf"\b{n}\(", text)] + ["Struct"]
    views.sort(key=_VIEWS_NAMES.index)
    line = "from .._views import " + ", ".join(views)
    if len(line) > 99:
        wrapped = textwrap.wrap(", ".join(views), 76)
        line = "from .._views import (" + "\n                      ".join(wrapped) + ")"
    return lines + [line]


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
