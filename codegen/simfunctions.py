"""Write mjcffi/sim/generated/functions.py: mujoco-py's `functions`, with its signatures.

mujoco-py 2.1.2.14 made `mujoco_py.functions` from its Cython file
`mujoco_py/generated/wrappers.pxi`: one `def _mj_X(typed args)` per MuJoCo
function, exposed without the leading underscore (mujoco_py/builder.py takes
every name of `cymj` that starts with `_mj`).  That file is read here from
mujoco-py's wheel (conformance/_mujoco_py_wheel.py: cached in ~/.cache/mjcffi/,
else downloaded with pip and checked against its SHA-256), and each of its
functions becomes a Python function with mujoco-py's parameter names, in its
order, that calls mjcffi's function of that name (mjcffi.functions, the
official bindings' signature).  The rules are generic:

- an argument of the same name is passed on;
- NumPy arrays: mujoco-py took flat (ndim=1) arrays and let MuJoCo read from
  their start, where mjcffi takes arrays of the exact shape MuJoCo reads; the
  shape comes from the MuJoCo 4 declaration (`mjtNum res[9]`) or from
  codegen/functions.py's SHAPES, and a 1-D array is cut to it and, for a
  matrix, viewed in it (`_shaped`, never a copy);
- size arguments that mjcffi reads from the arrays (n, nr, nc, r1, ...) are
  checked and give those shapes;
- `(str X, int X_sz)` pairs (error buffers): mujoco-py passed MuJoCo
  `X.encode()`, a copy, so nothing came back through them: accepted, ignored;
- `uintptr_t` arguments (raw addresses of C ints, 0 for NULL) become int32
  views of the ints there (`_ints`); an int32 array is taken too.

The tables below are the only special cases; codegen fails on a parameter of
either side that no rule or table accounts for.  mujoco-py's functions that
mjcffi/sim/functions.py writes by hand (HAND_WRITTEN) are left out here.
"""

import ast
import keyword
import pathlib
import re
import sys
import textwrap
import zipfile
from dataclasses import dataclass, field

from conformance import _mujoco_py_wheel as _wheel

from . import functions, outputs

REPO = pathlib.Path(__file__).resolve().parent.parent
OUTPUT = "mjcffi/sim/generated/functions.py"
WRAPPERS = "mujoco_py/generated/wrappers.pxi"

# Hand-written in mjcffi/sim/functions.py: the VFS functions, which keep mujoco-py's
# return codes on a PyMjVFS (mj_findFileVFS is gone from MuJoCo 4).
HAND_WRITTEN = ("mj_defaultVFS", "mj_addFileVFS", "mj_findFileVFS", "mj_deleteFileVFS",
                "mj_deleteVFS")

# MuJoCo 2.1 functions that MuJoCo 4 has under another name, with the same meaning.
TARGETS = {
    "mju_rotVecMat": "mju_mulMatVec3",
    "mju_rotVecMatT": "mju_mulMatTVec3",
    "mjv_makeConnector": "mjv_connector",
    "mju_error_i": "mju_error",
    "mju_error_s": "mju_error",
    "mju_warning_i": "mju_warning",
    "mju_warning_s": "mju_warning",
}

# mujoco-py parameters that mjcffi names otherwise, same meaning: {mujoco-py: mjcffi}.
RENAMED = {
    "mju_copy": {"data": "vec"},
    "mju_normalize3": {"res": "vec"},
    "mju_normalize4": {"res": "vec"},
}

_FORMATTED = "_printf(msg, {})"
# mjcffi arguments given as Python expressions over mujoco-py's parameters and the
# helpers of the generated module; a parameter they use gets no generic conversion.
ARGS = {
    "mju_error_i": {"msg": _FORMATTED.format("i")},
    "mju_error_s": {"msg": _FORMATTED.format("text")},
    "mju_warning_i": {"msg": _FORMATTED.format("i")},
    "mju_warning_s": {"msg": _FORMATTED.format("text")},
    "mjv_makeConnector": {"from_": "(a0, a1, a2)", "to": "(b0, b1, b2)"},
    "mju_muscleDynamics": {"prm": "_np.append(_shaped(prm, (2,), 'prm'), 0.0)"},
    "mj_solveM2": {"sqrtInvD": "_np.sqrt(d.qLDiagInv)"},
    "mjv_select": {"flexid": "_np.empty(1, _np.int32)"},
    "mjui_add": {"def_": "_definitions(_def)"},
    "mjui_addToSection": {"def_": "_definitions(_def)"},
}

# Whole calls replaced by a Python expression, whose value is returned.
CALLS = {
    "mj_activate": "1",
    "mj_deactivate": "None",
    "mj_loadXML": "_SimModel.from_xml_path(filename, vfs=vfs)",
    "mj_loadModel": "_SimModel.from_binary_path(filename, vfs=vfs)",
    "mj_addM": "_add_inertia(m, d, dst, rownnz, rowadr, colind)",
}

# mujoco-py's result where mjcffi's differs: an expression over `ret` (mjcffi's
# result) and the parameters.
RETURNS = {
    "mj_saveLastXML": "1",
    "mj_setLengthRange": "1",
    "mj_printSchema": "_write_schema(filename, ret)",
}

# Parameters accepted and not used: {function: {parameter: why}}.
IGNORED = {
    "mj_activate": {"filename": "there is no licence: MuJoCo 2.1's mj_activate already "
                                "returned 1 without reading it"},
    "mjv_moveCamera": {"scn": "MuJoCo 4's mjv_moveCamera takes no scene"},
}

# How many ints an address argument points to, where neither the declaration nor
# SHAPES says: {function: {parameter: expression}}.
ADDRESS_COUNTS = {
    "mju_printMatSparse": {"colind": "_extent(rownnz, rowadr)"},
}

# Functions whose meaning MuJoCo 4 changed or dropped: they raise NotImplementedError
# with this reason.  The ones mjcffi itself does not support (codegen/functions.py's
# UNSUPPORTED) join them with its reason.
REMOVED = {
    "mj_fullM": "MuJoCo 4's mj_fullM(m, d, dst) reads the inertia from d (d.M, in a sparse "
                "layout unlike MuJoCo 2's d.qM that mujoco-py's M argument held), so an M "
                "array cannot be converted; call mjcffi.functions.mj_fullM(m, d, dst)",
    "mj_makeEmptyFileVFS": "MuJoCo 4 has no mj_makeEmptyFileVFS: its VFS is opaque, so a file "
                           "cannot be made empty and filled in place afterwards; add the "
                           "contents with mj_addBufferVFS(vfs, filename, data)",
}

# Why a special case keeps mujoco-py's meaning, for the docstring and CHANGED.
NOTES = {
    "mj_activate": "returns 1 as MuJoCo 2.1's (licences are gone since MuJoCo 2.1)",
    "mj_deactivate": "does nothing, as MuJoCo 2.1's",
    "mj_loadXML": "returns a SimModel (mujoco-py's PyMjModel) compiled by "
                  "SimModel.from_xml_path, which calls MuJoCo's mj_loadXML; an XML error "
                  "raises ValueError",
    "mj_loadModel": "returns a SimModel loaded by SimModel.from_binary_path, which calls "
                    "MuJoCo's mj_loadModel",
    "mj_addM": "MuJoCo 2's dense form: dst += the whole inertia matrix (mjcffi.functions."
               "mj_fullM), as MuJoCo 2 did; MuJoCo 4's mj_addM adds the lower triangle only.  "
               "rownnz, rowadr, colind must be 0 (NULL): the sparse form raises "
               "NotImplementedError",
    "mj_saveLastXML": "returns 1 as MuJoCo's C function; a failure raises mjcffi.FatalError "
                      "(or goes to the error callback) with MuJoCo's message",
    "mj_setLengthRange": "returns 1 as MuJoCo's C function; a failure raises "
                         "mjcffi.FatalError (or goes to the error callback) with MuJoCo's "
                         "message",
    "mj_printSchema": "writes the schema to filename unless it is '' (MuJoCo opens no file "
                      "of that name) and returns its length, as MuJoCo 2",
    "mj_solveM2": "MuJoCo 4 takes sqrt(inv(D)) as an argument: it is sqrt(d.qLDiagInv), "
                  "what MuJoCo 2 kept in d.qLDiagSqrtInv",
    "mjv_select": "MuJoCo 4 also selects flexes: their id is dropped (mujoco-py's models have "
                  "none)",
    "mjv_makeConnector": "MuJoCo 4's mjv_connector takes the two points as arrays",
    "mju_rotVecMat": "MuJoCo 4's mju_mulMatVec3(res, mat, vec): res = mat * vec",
    "mju_rotVecMatT": "MuJoCo 4's mju_mulMatTVec3(res, mat, vec): res = mat' * vec",
    "mju_error_i": "msg is a printf format for i, filled as MuJoCo 2 did",
    "mju_error_s": "msg is a printf format for text, filled as MuJoCo 2 did",
    "mju_warning_i": "msg is a printf format for i, filled as MuJoCo 2 did",
    "mju_warning_s": "msg is a printf format for text, filled as MuJoCo 2 did",
    "mju_muscleDynamics": "MuJoCo 4 reads a third parameter, the smoothing width: it is 0 "
                          "(none), MuJoCo 2's behaviour",
    "mjui_add": "mujoco-py passed one PyMjuiDef; a lone MjuiDef is made a sequence of one",
    "mjui_addToSection": "mujoco-py passed one PyMjuiDef; a lone MjuiDef is made a sequence "
                         "of one",
}



# ------------------------------------------------------------------ reading

WheelUnavailable = _wheel.WheelUnavailable     # mujoco-py's wheel cannot be had


@dataclass
class Param:
    name: str
    type: str           # as wrappers.pxi declares it: 'int', 'PyMjModel', 'np.ndarray[...]'

    @property
    def array(self):
        return self.type.startswith("np.ndarray")

    @property
    def address(self):
        return self.type == "uintptr_t"

    def shown(self):
        """The parameter as the docstring shows it: 'float64[] res', 'int n'."""
        found = re.match(r"np\.ndarray\[np\.(\w+)_t", self.type)
        kind = f"{found.group(1)}[]" if found else \
            "address" if self.address else self.type
        return f"{kind} {self.name}"


@dataclass
class PyFunction:
    name: str           # mujoco-py's public name: mj_step (wrappers.pxi has _mj_step)
    params: list
    body: str           # the one line wrappers.pxi calls MuJoCo with


def missing_wheel():
    """Why mujoco-py's wheel cannot be had without downloading it, or None when it is
    cached: for tests that skip what needs it."""
    if _wheel.cached_wheel() is not None:
        return None
    return (f"mujoco-py's wheel {_wheel.WHEEL} is not in {_wheel.cache_dir()} (it is "
            f"downloaded with pip when codegen or the conformance run needs it)")


def _split_params(text):
    """'PyMjModel m, np.ndarray[np.float64_t, mode="c", ndim=1] res' -> [Param]."""
    parts, depth, start = [], 0, 0
    for i, char in enumerate(text):
        if char == "[":
            depth += 1
        elif char == "]":
            depth -= 1
        elif char == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    params = []
    for part in (p.strip() for p in parts):
        if part:
            ctype, name = part.rsplit(" ", 1)
            params.append(Param(name, ctype.strip()))
    return params


def parse_wrappers(text):
    """[PyFunction] of wrappers.pxi's `def _mj...(...)` functions, in the file's order."""
    lines = text.splitlines()
    found = []
    for i, line in enumerate(lines):
        match = re.match(r"def _(mj\w*)\((.*)\):\s*$", line)
        if match:
            found.append(PyFunction(match.group(1), _split_params(match.group(2)),
                                    lines[i + 1].strip()))
    if not found:
        raise ValueError(f"{WRAPPERS} has no `def _mj...` functions")
    return found


def read_wrappers():
    """[PyFunction] of mujoco-py's wheel; WheelUnavailable if it cannot be had."""
    with zipfile.ZipFile(_wheel.wheel()) as archive:
        return parse_wrappers(archive.read(WRAPPERS).decode("utf-8"))


# ------------------------------------------------- mjcffi's signatures

def _signatures(source, names):
    """{name: [(parameter, has a default)]} of the top-level functions of `source`."""
    found = {}
    for node in ast.parse(source).body:
        if isinstance(node, ast.FunctionDef) and node.name in names:
            args = node.args.args
            first_default = len(args) - len(node.args.defaults)
            found[node.name] = [(a.arg, i >= first_default) for i, a in enumerate(args)]
    return found


def mjcffi_signatures(functions_text, decls):
    """mjcffi.functions' parameters per function: the generated mjcffi/_functions/
    (this run's text), and the hand-written overrides for the names they replace."""
    names = set(decls.functions)
    found = _signatures(functions_text, names)
    hand = {}
    for path in ("mjcffi/functions/_overrides.py", "mjcffi/functions/_mjui.py"):
        hand.update(_signatures((REPO / path).read_text(), set(functions.OVERRIDES)))
    missing = set(functions.OVERRIDES) - set(hand)
    if missing:
        raise ValueError(f"overrides without a hand-written function: {sorted(missing)}")
    found.update(hand)
    return found


# ------------------------------------------------------------ planning

def _c_name(py):
    """mjcffi's parameter name -> the C argument's ('from_' -> 'from')."""
    return py[:-1] if py.endswith("_") and keyword.iskeyword(py[:-1]) else py


def _names_in(expr):
    """The bare names an expression uses (not attributes)."""
    return set(re.findall(r"(?<![.\w])[A-Za-z_]\w*", re.sub(r"'[^']*'|\"[^\"]*\"", "", expr)))


_ERROR_PAIR = re.compile(r"^(error|buffer)$")


@dataclass
class Plan:
    """How one of mujoco-py's functions is written."""
    py: PyFunction
    target: str = ""                   # the MuJoCo 4 function it calls
    removed: str = ""                  # the reason, for a removed function
    prelude: list = field(default_factory=list)     # statements before the call
    call: str = ""                     # the call (or CALLS' expression)
    returns: str = ""                  # RETURNS' expression over `ret`, if any
    notes: list = field(default_factory=list)       # how the arguments differ


class _Planner:
    """Plans each function of wrappers.pxi against MuJoCo 4's declarations, SHAPES and
    mjcffi's signatures."""

    def __init__(self, decls, constants, signatures):
        self.decls = decls
        self.constants = constants
        self.signatures = signatures

    def plan(self, py):
        name = py.name
        plan = Plan(py, TARGETS.get(name, name))
        if name in REMOVED:
            plan.removed = REMOVED[name]
            return plan
        if plan.target in functions.UNSUPPORTED:
            plan.removed = (f"mjcffi does not support {plan.target}: "
                            f"{functions.UNSUPPORTED[plan.target]}")
            return plan
        if name not in CALLS and (plan.target not in self.decls.functions
                                  or plan.target not in self.signatures):
            raise ValueError(f"mujoco-py's {name}: MuJoCo 4 has no {plan.target}; add it to "
                             f"TARGETS, CALLS or REMOVED")
        self._check_tables(py, plan.target)
        # parameters that ARGS, CALLS and RETURNS use themselves
        mine = {p.name for p in py.params}
        used = set()
        for expr in [*ARGS.get(name, {}).values(), CALLS.get(name, ""), RETURNS.get(name, "")]:
            used |= _names_in(expr) & mine
        passed = self._call(py, plan)
        sizes = self._sizes(py, passed | used)
        self._conversions(py, plan, used, sizes)
        plan.returns = RETURNS.get(name, "")
        self._notes(py, plan, passed, used, sizes)
        return plan

    def _check_tables(self, py, target):
        name, mine = py.name, {p.name for p in py.params}
        for table in (RENAMED, IGNORED):
            unknown = set(table.get(name, {})) - mine
            if unknown:
                raise ValueError(f"a table names unknown parameters of {name}: {sorted(unknown)}")
        unknown = set(ARGS.get(name, {})) - {p for p, _ in self.signatures.get(target, [])}
        if unknown:
            raise ValueError(f"ARGS[{name}] names parameters mjcffi's {target} lacks: "
                             f"{sorted(unknown)}")

    def _call(self, py, plan):
        """Set plan.call; the names of mujoco-py's parameters it passes on as they are."""
        name = py.name
        if name in CALLS:
            plan.call = CALLS[name]
            return set()
        mine = {p.name for p in py.params}
        args = ARGS.get(name, {})
        back = {mjcffi: ours for ours, mjcffi in RENAMED.get(name, {}).items()}
        passed, keywords, call_args = set(), False, []
        for param, has_default in self.signatures[plan.target]:
            if param in args:
                expr = args[param]
            elif param in back:
                expr = back[param]
            elif param in mine:
                expr = param
            elif has_default:
                keywords = True         # left at its default: the ones after go by name
                continue
            else:
                raise ValueError(f"{name}: mjcffi's {plan.target} needs {param!r}, which "
                                 f"mujoco-py does not pass; add it to ARGS")
            if expr in mine:
                passed.add(expr)
            call_args.append(f"{param}={expr}" if keywords else expr)
        plan.call = f"_mj.{plan.target}({', '.join(call_args)})"
        return passed

    def _sizes(self, py, taken):
        """The size parameters among those not `taken`; ValueError for any other
        parameter that nothing accounts for."""
        name, mine = py.name, {p.name for p in py.params}
        ignored = IGNORED.get(name, {})
        sizes = []
        for p in py.params:
            if p.name in taken or p.name in ignored or _is_error_buffer(p, mine):
                continue
            if p.type == "int":
                sizes.append(p.name)
                continue
            raise ValueError(f"{name}: mujoco-py's parameter {p.name!r} goes nowhere; add it "
                             f"to ARGS, CALLS, RETURNS or IGNORED")
        return sizes

    def _conversions(self, py, plan, used, sizes):
        """plan.prelude: the size checks, then each address and array argument made
        what mjcffi takes."""
        name = py.name
        renamed = RENAMED.get(name, {})
        declared = {a.name for a in self.decls.functions[plan.target].args} \
            if plan.target in self.decls.functions else set()
        sized, lines = set(), []
        for p in py.params:
            if p.name in used or p.name in IGNORED.get(name, {}) or not (p.array or p.address):
                continue
            carg = _c_name(renamed.get(p.name, p.name))
            if carg not in declared:
                raise ValueError(f"{name}: {p.name} is no argument of MuJoCo 4's {plan.target}")
            dims = self._dims(plan.target, carg, sizes)
            for dim in dims or ():
                sized |= _names_in(dim) & set(sizes)
            if p.address:
                count = ADDRESS_COUNTS.get(name, {}).get(p.name)
                if count is None:
                    if not dims or len(dims) != 1:
                        raise ValueError(f"{name}: how many ints {p.name} points to is not "
                                         f"known; add it to ADDRESS_COUNTS")
                    count = dims[0]
                sized |= _names_in(count) & set(sizes)
                lines.append(f"{p.name} = _ints({p.name}, {count}, {p.name!r})")
            elif dims:
                shape = f"({dims[0]},)" if len(dims) == 1 else f"({', '.join(dims)})"
                lines.append(f"{p.name} = _shaped({p.name}, {shape}, {p.name!r})")
        unused = set(sizes) - sized
        if unused:
            raise ValueError(f"{name}: the int parameters {sorted(unused)} size no array; add "
                             f"them to IGNORED")
        plan.prelude = [f"{n} = _count({n}, {n!r})" for n in sizes] + lines

    def _dims(self, target, carg, sizes):
        """The shape MuJoCo 4 reads for argument `carg`, as Python text over the
        parameters, or None (unknown, or any size)."""
        spec = functions.SHAPES.get(target, {}).get(carg)
        if spec is None:
            decl = next(a for a in self.decls.functions[target].args if a.name == carg)
            return [str(d) for d in decl.type.dims] or None
        dims = functions._split_dims(spec)
        if "*" in dims:
            return None
        return [self._dim(d, target, sizes) for d in dims]

    def _dim(self, dim, target, sizes):
        def word(match):
            name = match.group(0)
            if name[:2] in ("m.", "d."):
                return f"_size({name[0]}, {name[2:]!r})"
            if name in self.constants:
                return str(self.constants[name])
            if name in sizes:
                return name
            raise ValueError(f"{target}: a dimension names {name!r}, which is neither a "
                             f"constant nor one of mujoco-py's size parameters")
        return re.sub(r"\b[md]\.\w+|[A-Za-z_]\w*", word, dim)

    def _notes(self, py, plan, passed, used, sizes):
        """plan.notes: how the call differs from mujoco-py's arguments, and why."""
        name, mine = py.name, {p.name for p in py.params}
        notes = plan.notes
        if plan.target != name:
            notes.append(f"MuJoCo 4 calls it {plan.target}")
        for ours, theirs in RENAMED.get(name, {}).items():
            notes.append(f"{ours} is mjcffi's {theirs}")
        for param, expr in ARGS.get(name, {}).items():
            notes.append(f"mjcffi's {param} is {expr}")
        if sizes:
            them = "them" if len(sizes) > 1 else "it"
            notes.append(f"{', '.join(sizes)}: checked, and the arrays cut to {them} "
                         f"(mjcffi reads the sizes from the arrays)")
        for p in py.params:
            if p.type == "str" and _is_error_buffer(p, mine) and p.name not in used:
                notes.append(f"{p.name}, {p.name}_sz: accepted and ignored (mujoco-py passed "
                             f"MuJoCo {p.name}.encode(), a copy: nothing came back through it)")
        for param, why in IGNORED.get(name, {}).items():
            notes.append(f"{param}: accepted and ignored: {why}")
        addresses = [p.name for p in py.params if p.address and p.name not in used]
        if addresses:
            notes.append(f"{', '.join(addresses)}: the address of C ints (0 for NULL), as "
                         f"mujoco-py took, or an int32 array")
        if name in NOTES:
            notes.append(NOTES[name])
        elif name in CALLS or name in RETURNS or name in ARGS or plan.target != name:
            raise ValueError(f"{name}: a special case needs a NOTES entry saying why")


def _is_error_buffer(param, names):
    """`str error` / `int error_sz` (or buffer, buffer_sz) of an error-buffer pair."""
    if param.type == "str" and _ERROR_PAIR.match(param.name):
        return f"{param.name}_sz" in names
    return (param.type == "int" and param.name.endswith("_sz")
            and _ERROR_PAIR.match(param.name[:-3]) is not None and param.name[:-3] in names)


# ------------------------------------------------------------- writing

_WIDTH = 88


def _docstring(plan, doc):
    """mujoco-py's signature, MuJoCo 4's header comment, then what is called and how."""
    py = plan.py
    text = textwrap.wrap(f"mujoco-py's {py.name}({', '.join(p.shown() for p in py.params)}).",
                         _WIDTH)
    if doc:
        text.append("")
        for line in doc.splitlines():
            text += textwrap.wrap(line, _WIDTH) or [""]
    text.append("")
    if plan.removed:
        text += textwrap.wrap(f"Raises NotImplementedError: {plan.removed}.", _WIDTH)
    else:
        if plan.call.startswith("_mj."):
            text += textwrap.wrap(f"Calls mjcffi.functions.{plan.call[len('_mj.'):]}.", _WIDTH)
        for note in plan.notes:
            text += textwrap.wrap(note + ".", _WIDTH, initial_indent="- ",
                                  subsequent_indent="  ")
    body = outputs._doc_literal("\n".join(text))
    body = "\n".join(("    " + line).rstrip() for line in body.split("\n"))
    return f'    """{body[4:]}\n    """'


def _top_level_pieces(text):
    """`text` cut after each comma outside brackets: the pieces keep their commas."""
    pieces, depth, start = [], 0, 0
    for i, char in enumerate(text):
        if char in "([{":
            depth += 1
        elif char in ")]}":
            depth -= 1
        elif char == "," and depth == 1:
            pieces.append(text[start:i + 1])
            start = i + 1
    pieces.append(text[start:])
    return [piece.strip() for piece in pieces]


def _statement(text):
    """An indented statement; a long call is broken after the commas between its
    arguments."""
    width = _WIDTH + 8
    if len(text) + 4 <= width:
        return ["    " + text]
    lines, line = [], "    "
    for piece in _top_level_pieces(text):
        if line.strip() and len(line) + 1 + len(piece) > width:
            lines.append(line)
            line = "        " + piece
        else:
            line += (" " if line.strip() else "") + piece
    return lines + [line]


def _function(plan, doc):
    py = plan.py
    lines = [f"def {py.name}({', '.join(p.name for p in py.params)}):", _docstring(plan, doc)]
    if plan.removed:
        lines.append(f"    raise NotImplementedError({py.name + ': '!r} + REMOVED[{py.name!r}])")
        return lines
    for line in plan.prelude:
        lines += _statement(line)
    if plan.returns:
        lines += _statement(f"ret = {plan.call}" if "ret" in _names_in(plan.returns) else
                            plan.call)
        lines += _statement(f"return {plan.returns}")
    else:
        lines += _statement(f"return {plan.call}")
    return lines


def _table(name, entries, comment):
    """`name = {key: text}` with each text in string literals of at most one line."""
    lines = [f"# {comment}", f"{name} = {{"]
    for key, value in entries:
        chunks = textwrap.wrap(value, 80, break_long_words=False, drop_whitespace=False,
                               replace_whitespace=False)
        if "".join(chunks) != value:
            raise ValueError(f"{name}[{key}]: the text does not split into lines")
        lines.append(f"    {key!r}:")
        lines += [f"        {chunk!r}" for chunk in chunks]
        lines[-1] += ","
    lines.append("}")
    return lines


def _check_tables(found):
    names = {f.name for f in found}
    for title, table in (("HAND_WRITTEN", HAND_WRITTEN), ("TARGETS", TARGETS),
                         ("RENAMED", RENAMED), ("ARGS", ARGS), ("CALLS", CALLS),
                         ("RETURNS", RETURNS), ("IGNORED", IGNORED),
                         ("ADDRESS_COUNTS", ADDRESS_COUNTS), ("REMOVED", REMOVED),
                         ("NOTES", NOTES)):
        unknown = set(table) - names
        if unknown:
            raise ValueError(f"{title} names functions mujoco-py's module lacks: "
                             f"{sorted(unknown)}")


def render(found, decls, notes, header_texts, functions_text):
    """The text of the generated module, from wrappers.pxi's functions `found`."""
    _check_tables(found)
    planner = _Planner(decls, functions._defines(header_texts, decls),
                       mjcffi_signatures(functions_text, decls))
    plans = [planner.plan(f) for f in found if f.name not in HAND_WRITTEN]
    header_doc = {n: note.doc for n, note in notes.functions.items()}
    blocks = []
    for plan in plans:
        doc = "" if plan.removed and plan.target not in header_doc else \
            header_doc.get(plan.target, "")
        blocks.append("\n".join(_function(plan, doc)))
    removed = [(p.py.name, p.removed) for p in plans if p.removed]
    changed = [(p.py.name, "; ".join(p.notes)) for p in plans if not p.removed and p.notes]
    names = [f.name for f in found]
    lines = [outputs.HEADER_PY.rstrip("\n"),
             '"""mujoco-py\'s `mujoco_py.functions`, with mujoco-py\'s own signatures.',
             "",
             f"Generated by codegen/simfunctions.py from {WRAPPERS} of mujoco-py's",
             f"wheel ({_wheel.WHEEL}): each `def _mj_X(typed args)` there is",
             "`mj_X(args)` here, with mujoco-py's parameter names in its order, calling",
             "mjcffi.functions.mj_X (the official bindings' signature).  Flat NumPy arrays",
             "are viewed in the shapes mjcffi takes and cut to the size arguments, which are",
             "checked; error buffers (`error, error_sz`) are accepted and ignored; a",
             "`uintptr_t` argument is an address of C ints, or an int32 array.  CHANGED says",
             "how each function whose arguments are mapped differs; REMOVED why the ones",
             "MuJoCo 4 changed or dropped raise NotImplementedError.  The functions of",
             "HAND_WRITTEN are in mjcffi/sim/functions.py, which exposes these (and routes",
             "a MuJoCo error to mujoco-py's error callback).",
             '"""',
             "",
             "import numpy as _np",
             "",
             "from ... import functions as _mj",
             "from .._function_support import (_add_inertia, _count, _definitions, _extent,"
             " _ints,",
             "                                 _printf, _shaped, _size, _write_schema)",
             "from .._model import SimModel as _SimModel",
             "",
             "# Every function of mujoco-py's `functions` module, in wrappers.pxi's order.",
             "NAMES = (",
             *textwrap.wrap(", ".join(repr(n) for n in names) + ",", 88,
                            initial_indent="    ", subsequent_indent="    "),
             ")",
             "",
             "# Written by hand in mjcffi/sim/functions.py.",
             "HAND_WRITTEN = (",
             *textwrap.wrap(", ".join(repr(n) for n in HAND_WRITTEN) + ",", 88,
                            initial_indent="    ", subsequent_indent="    "),
             ")",
             "",
             *_table("REMOVED", removed, "Functions whose meaning MuJoCo 4 changed or "
                                         "dropped, and why: they raise NotImplementedError."),
             "",
             *_table("CHANGED", changed, "Functions called with other arguments than "
                                         "mujoco-py's, and how."),
             "",
             "",
             "\n\n\n".join(blocks)]
    return "\n".join(lines) + "\n"


def generate(decls, notes, header_texts, functions_text):
    """{OUTPUT: text}, or {} (with the reason on stderr) when mujoco-py's wheel cannot
    be had: the committed file stays as it is."""
    try:
        found = read_wrappers()
    except WheelUnavailable as error:
        print(f"codegen: {OUTPUT} not written: mujoco-py's wheel ({_wheel.WHEEL}) cannot "
              f"be had: {error}", file=sys.stderr)
        return {}
    return {OUTPUT: render(found, decls, notes, header_texts, functions_text)}
