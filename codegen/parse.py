"""Parse MuJoCo's preprocessed declarations with pycparser into plain records."""

import copy
from dataclasses import dataclass, field

import pycparser
from pycparser import c_ast, c_generator

# pycparser knows no system headers: give it the few typedefs MuJoCo uses.
_PRELUDE = """
typedef unsigned long size_t;
typedef long int64_t;
typedef unsigned long uint64_t;
typedef unsigned int uint32_t;
typedef unsigned char uint8_t;
typedef unsigned long uintptr_t;
typedef long intptr_t;
"""
_PRELUDE_LINES = _PRELUDE.count("\n")


@dataclass
class CType:
    """A C type split into the parts the generators need."""
    base: str                  # e.g. 'mjtNum', 'mjModel', 'struct mjuiItemSingle_'
    pointer: int = 0           # levels of indirection
    const: bool = False        # the pointee (or value) is const
    dims: tuple = ()           # fixed array extents, outermost first
    decl: str = ""             # the whole type as C would spell it
    function: bool = False     # a pointer to a function


@dataclass
class Field:
    name: str
    type: CType
    nested: object = None      # a Struct for an anonymous struct/union member


@dataclass
class Struct:
    name: str                  # typedef name, or tag when there is none
    tag: str
    union: bool
    fields: list = field(default_factory=list)


@dataclass
class Enum:
    name: str
    members: list              # [(name, value)]


@dataclass
class Arg:
    name: str
    type: CType


@dataclass
class Function:
    name: str
    restype: CType
    args: list


@dataclass
class Global:
    name: str
    type: CType


@dataclass
class Declarations:
    structs: dict = field(default_factory=dict)     # name -> Struct
    enums: dict = field(default_factory=dict)       # name -> Enum
    functions: dict = field(default_factory=dict)   # name -> Function
    globals: dict = field(default_factory=dict)     # name -> Global
    typedefs: dict = field(default_factory=dict)    # name -> C spelling of the target
    tags: dict = field(default_factory=dict)        # struct tag -> typedef name


_GEN = c_generator.CGenerator()


def const_value(node, names):
    """Evaluate an integer constant expression from the headers."""
    if isinstance(node, c_ast.Constant):
        text = node.value.rstrip("uUlL")
        return int(text, 0)
    if isinstance(node, c_ast.ID):
        return names[node.name]
    if isinstance(node, c_ast.UnaryOp):
        value = const_value(node.expr, names)
        return {"-": -value, "+": value, "~": ~value}[node.op]
    if isinstance(node, c_ast.BinaryOp):
        a, b = const_value(node.left, names), const_value(node.right, names)
        if node.op == "/":                  # C truncates toward zero
            quotient = abs(a) // abs(b)
            return quotient if (a < 0) == (b < 0) else -quotient
        ops = {"+": lambda: a + b, "-": lambda: a - b, "*": lambda: a * b,
               "<<": lambda: a << b, ">>": lambda: a >> b, "|": lambda: a | b,
               "&": lambda: a & b}
        return ops[node.op]()
    raise ValueError(f"cannot evaluate {_GEN.visit(node)}")


def _type_of(node, names):
    """Describe a pycparser type node as a CType."""
    pointer, dims, function = 0, [], False
    while True:
        if isinstance(node, c_ast.ArrayDecl):
            dims.append(const_value(node.dim, names) if node.dim is not None else None)
            node = node.type
        elif isinstance(node, c_ast.PtrDecl):
            pointer += 1
            node = node.type
        elif isinstance(node, c_ast.FuncDecl):
            function = True
            break
        else:
            break
    const = False
    if isinstance(node, c_ast.TypeDecl):
        const = "const" in node.quals
        inner = node.type
        if isinstance(inner, c_ast.IdentifierType):
            base = " ".join(inner.names)
        elif isinstance(inner, (c_ast.Struct, c_ast.Union)):
            kind = "struct" if isinstance(inner, c_ast.Struct) else "union"
            base = f"{kind} {inner.name}" if inner.name else kind
        elif isinstance(inner, c_ast.Enum):
            base = f"enum {inner.name}"
        else:
            raise ValueError(f"unexpected type node {inner!r}")
    else:
        base = ""
    return CType(base=base, pointer=pointer, const=const, dims=tuple(dims),
                 function=function)


def _decl_text(type_node, name=""):
    """C spelling of a type, e.g. 'const mjtNum *' (or with a name)."""
    decl = c_ast.Decl(name=name or None, quals=[], align=[], storage=[], funcspec=[],
                      type=_rename(type_node, name), init=None, bitsize=None)
    return _GEN.visit(decl)


def _rename(node, name):
    """Copy of a type node whose innermost TypeDecl declares `name`."""
    node = copy.deepcopy(node)
    inner = node
    while not isinstance(inner, c_ast.TypeDecl):
        inner = inner.type
    inner.declname = name or None
    return node


class _Collector:
    def __init__(self):
        self.out = Declarations()
        self.names = {}            # enumerator -> value, for array extents

    def struct(self, node, name):
        """Record a struct/union definition and return its Struct."""
        union = isinstance(node, c_ast.Union)
        record = Struct(name=name, tag=node.name or "", union=union)
        for decl in node.decls or []:
            nested = None
            inner = decl.type
            if isinstance(inner, c_ast.TypeDecl) and isinstance(
                    inner.type, (c_ast.Struct, c_ast.Union)) and inner.type.decls:
                nested = self.struct(inner.type, f"{name}.{decl.name}")
                if inner.type.name:        # a named struct defined inline
                    self.out.structs.setdefault(inner.type.name, nested)
                    nested = None
                else:                      # comments are keyed 'outer_tag.field'
                    nested.tag = f"{record.tag}.{decl.name}"
            elif isinstance(decl.type, (c_ast.Struct, c_ast.Union)):   # anonymous member
                nested = self.struct(decl.type, name)
            ctype = _type_of(decl.type, self.names)
            if nested is not None:
                ctype.base = "union" if nested.union else "struct"
                ctype.decl = ctype.base
            else:
                ctype.decl = _decl_text(decl.type)
            record.fields.append(Field(name=decl.name or "", type=ctype, nested=nested))
        return record

    def enum(self, node, name):
        value, members = -1, []
        for item in node.values.enumerators if node.values else []:
            value = const_value(item.value, self.names) if item.value is not None else value + 1
            self.names[item.name] = value
            members.append((item.name, value))
        self.out.enums[name] = Enum(name=name, members=members)

    def typedef(self, node):
        target = node.type.type if isinstance(node.type, c_ast.TypeDecl) else None
        if isinstance(target, (c_ast.Struct, c_ast.Union)):
            if target.name:
                self.out.tags[target.name] = node.name
            if target.decls is not None:
                self.out.structs[node.name] = self.struct(target, node.name)
            elif target.name in self.out.structs:
                self.out.structs[node.name] = self.out.structs.pop(target.name)
                self.out.structs[node.name].name = node.name
            self.out.typedefs[node.name] = _decl_text(node.type)
            return
        if isinstance(target, c_ast.Enum):
            if target.values is not None:
                self.enum(target, node.name)
            self.out.typedefs[node.name] = _decl_text(node.type)
            return
        self.out.typedefs[node.name] = _decl_text(node.type)

    def decl(self, node):
        if isinstance(node.type, c_ast.FuncDecl):
            self.function(node)
        elif isinstance(node.type, (c_ast.Struct, c_ast.Union)):
            if node.type.decls is not None:       # `struct tag { ... };`
                self.out.structs[node.type.name] = self.struct(node.type, node.type.name)
        elif isinstance(node.type, c_ast.Enum):
            if node.type.values is not None:
                self.enum(node.type, node.type.name)
        elif "extern" in node.storage:
            ctype = _type_of(node.type, self.names)
            ctype.decl = _decl_text(node.type)
            self.out.globals[node.name] = Global(name=node.name, type=ctype)

    def function(self, node):
        func = node.type
        restype = _type_of(func.type, self.names)
        restype.decl = _decl_text(func.type)
        args = []
        for param in func.args.params if func.args else []:
            if isinstance(param, c_ast.EllipsisParam):
                args.append(Arg(name="...", type=CType(base="...", decl="...")))
                continue
            ctype = _type_of(param.type, self.names)
            if ctype.base == "void" and not ctype.pointer and not ctype.dims:
                continue                                   # f(void)
            ctype.decl = _decl_text(param.type)
            args.append(Arg(name=param.name or f"arg{len(args)}", type=ctype))
        self.out.functions[node.name] = Function(name=node.name, restype=restype, args=args)


def parse(declarations_text):
    """Parse the preprocessed MuJoCo declarations into a Declarations record."""
    parser = pycparser.CParser()
    ast = parser.parse(_PRELUDE + declarations_text, filename="<mujoco>")
    collector = _Collector()
    for node in ast.ext:
        if node.coord is not None and node.coord.line <= _PRELUDE_LINES:
            continue
        if isinstance(node, c_ast.Typedef):
            collector.typedef(node)
        elif isinstance(node, c_ast.Decl):
            collector.decl(node)
    return collector.out
