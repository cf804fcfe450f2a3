"""The fast path of a generated function: one test per argument, then the C call.

codegen/functions.py writes each function F as `_F(args)`, which checks and
converts every argument (mjcffi/_support/marshal.py) and returns the guarded call, and
the public `F(args)`, which begins with the fast path written here:

    try:
        c_m, c_d = m._ptr, d._ptr
        fast = (d._model is m and body.__class__ is int and 0 <= body < c_m.nbody
                and point.__class__ is _nd and point.dtype is _NUM_dt
                and point.shape == (3,))
        if fast:
            c_point = _fb(_NUM_ct, point)
    except _SLOW:
        fast = False
    if fast:
        <the guarded call, then the checks of its result>
    return _F(args)

The tests take the common case only: exact ndarrays of the right dtype and shape
(outputs also C-contiguous, aligned and writable: `flags.carray`; inputs must be
C-contiguous, which `ffi.from_buffer` checks), ids in range, enum values, str
without NUL, the mjData made for this very model.  They never raise: an
argument they are unsure of (a list, another dtype, an (n, 1) vector, a
subclass, a model of the same sizes) sends the call down the slow path, which
converts it or raises its own error with its own message.  A scalar that C
cannot take fails in cffi before MuJoCo runs, and goes down the slow path too.
So the fast path loosens nothing: it accepts a subset of what the slow path
accepts, and hands the same C arguments to the same guard.

A function has no fast path when one of its arguments is of another kind (a
struct other than mjModel/mjData, a handle, a buffer, a callback) or when
codegen/functions.py gives it a special case (`blockers`).
"""

import re

# the fast path's own local names: no argument may be called so
LOCALS = ("fast", "status", "ret")

_MODEL_FIELD = re.compile(r"\bm\.(\w+)")


class FastPath:
    """Writes the fast path of one function from its writer (`_Function`, after write())."""

    def __init__(self, writer):
        self.w = writer
        self.setup = []          # statements before the test (they may raise: slow path)
        self.tests = []          # the conjuncts of `fast = ...`
        self.converts = []       # statements run when the tests pass
        self.names = {}          # Python argument -> the C value passed for it
        self.model = None        # the mjModel argument
        self.bound = {}          # array -> {axis: size}, when its shape gives them all
        self.hoisted = []        # locals holding a model size read once

    # ------------------------------------------------------------- arguments

    def _structs(self):
        args = self.w.args
        model = next((a for a in args if a.kind == "struct" and a.base == "mjModel"), None)
        datas = [a for a in args if a.kind == "struct" and a.base == "mjData"]
        self.model = model
        for a in [model, *datas] if model else datas:
            self.setup.append(f"c_{a.py} = {a.py}._ptr")
        if model is not None:
            if datas:
                self.tests += [f"{d.py}._model is {model.py}" for d in datas]
            else:
                self.tests.append(f'{model.py}._cname == "mjModel"')
        else:
            self.tests += [f'{d.py}._cname == "mjData"' for d in datas]

    def _dim(self, dim):
        """A dim of SHAPES (or a declared extent) as an expression of the fast path."""
        if dim.isdigit():
            return dim
        if dim in self.w.sizes:
            return dim
        if dim in self.w.constants:
            return str(self.w.constants[dim])
        match = re.fullmatch(r"m\.(\w+)", dim)
        if match and self.model is not None:
            return f"c_{self.model.py}.{match.group(1)}"
        product = re.fullmatch(r"(\w+)\s*\*\s*\((\w+)\s*\+\s*(\d+)\)", dim)   # n*(n+7)
        if product and product.group(1) in self.w.sizes and product.group(2) in self.w.sizes:
            return f"{product.group(1)} * ({product.group(2)} + {product.group(3)})"
        if re.fullmatch(r"(state_size|band_size)\(.*\)", dim):
            # a helper's size (mj_stateSize): computed in the setup, where its error (a bad
            # signature) sends the call down the slow path, which raises it
            local = f"size_{len(self.setup)}"
            self.setup.append(f"{local} = {self.w.expr(dim)}")
            return local
        return None

    def _binders(self):
        """Unpack the shape of the array that gives each deduced size: `nr, nc = mat.shape`."""
        given = {}                      # array -> (ndims, {axis: size})
        for var, chain in self.w.chains.items():
            a, ndims, axis, factor = chain[0]
            if factor != 1 or a.kind != "array":
                return False
            given.setdefault(a.py, (ndims, {}))[1][axis] = var
        for py, (ndims, axes) in given.items():
            if len(set(axes.values())) == ndims:          # each axis a size of its own
                self.bound[py] = axes
            targets = [axes.get(axis, "_") for axis in range(ndims)]
            self.setup.append(f"{', '.join(targets)}, = {py}.shape" if ndims == 1 else
                              f"{', '.join(targets)} = {py}.shape")
        return True

    def _arrays(self):
        for a in self.w.arrays:
            dims = self.w.specs[a.name]
            exprs = [self._dim(d) for d in dims]
            if None in exprs:
                return False
            if a.name in self.w.sized and len(exprs) > 1:
                exprs = [" * ".join(f"({e})" for e in exprs)]
            shape = f"({exprs[0]},)" if len(exprs) == 1 else f"({', '.join(exprs)})"
            elem = _elem(self.w, a)
            test = [f"{a.py}.__class__ is _nd", f"{a.py}.dtype is _{elem}_dt"]
            if self.bound.get(a.py) != dict(enumerate(dims)):   # not its shape's own sizes
                test.append(f"{a.py}.shape == {shape}")
            if not a.const:
                test.append(f"{a.py}.flags.carray")
            convert = f"_fb(_{elem}_ct, {a.py})"
            if a.nullable:
                self.tests.append(f"({a.py} is None or {' and '.join(test)})")
                convert = f"_NULL if {a.py} is None else {convert}"
            else:
                self.tests += test
            self.converts.append(f"c_{a.py} = {convert}")
        return True

    def _scalars(self):
        names = {a.name: a for a in self.w.args}
        for argname, (low, count) in self.w.ids.items():
            py = names[argname].py
            limit = self._dim(count)
            if limit is None:
                return False
            self.tests += [f"{py}.__class__ is _int", f"{low} <= {py} < {limit}"]
        for argname, enum in self.w.enums.items():
            py = names[argname].py
            self.tests += [f"{py}.__class__ is _int", f'{py} in _ENUMS["{enum}"]']
        if "objtype" in names and "objid" in names:
            if self.model is None:
                return False
            kind, obj = names["objtype"].py, names["objid"].py   # an mjtObj member is fine
            self.tests += [f"{obj}.__class__ is _int",
                           f"0 <= {obj} < _getattr(c_{self.model.py}, _m.COUNT_OF[{kind}])"]
        for a in self.w.args:
            if a.kind != "text":
                continue
            test = f'{a.py}.__class__ is _str and "\\0" not in {a.py}'
            convert = f"{a.py}.encode()"
            if a.nullable:
                test, convert = f"({a.py} is None or {test})", \
                    f"_NULL if {a.py} is None else {convert}"
            self.tests.append(test)
            self.converts.append(f"c_{a.py} = {convert}")
        return True

    def _hoist(self):
        """A model size read by several tests (c_m.nv) is read once, in the setup."""
        text = " ".join(self.tests)
        for field in sorted(set(re.findall(r"\bc_\w+\.(\w+)", text))):
            reads = re.findall(rf"\b(c_\w+)\.{field}\b", text)
            if len(reads) > 1 and len(set(reads)) == 1:
                local = f"{reads[0][2:]}_{field}"
                self.hoisted.append(local)
                self.setup.append(f"{local} = {reads[0]}.{field}")
                self.tests = [re.sub(rf"\b{reads[0]}\.{field}\b", local, t) for t in self.tests]

    # ------------------------------------------------------------------ body

    def lines(self):
        """The fast path's lines (indented for the function body), or None."""
        if self.w.blockers():
            return None
        kinds = {a.kind for a in self.w.args}
        if kinds - {"scalar", "array", "text", "struct"} or any(
                a.kind == "struct" and (a.base not in ("mjModel", "mjData") or a.nullable)
                for a in self.w.args):
            return None
        if any(a.name in self.w.omit or a.name in self.w.errors for a in self.w.args):
            return None
        self._structs()
        if not (self._binders() and self._arrays() and self._scalars()):
            return None
        values, scalars = self.w.call_values(self.w.errors, self.w.omit)
        void = self.w.func.restype.decl == "void"
        call = f"{'status' if void else 'ret'} = _lib.mjcffi_guard_{self.w.name}(" + \
            ", ".join(values) + ")"
        ending = self.w.ending()
        if not ending[-1].startswith("return"):
            ending.append("return")
        self._hoist()
        for a in self.w.args:
            if a.py in (*LOCALS, *self.hoisted) or (a.kind != "scalar" and a.py in self.w.sizes):
                raise ValueError(f"{self.w.name}: argument {a.py!r} clashes with a fast-path "
                                 f"local")
        out = []
        if self.tests or self.setup or self.converts:
            out += ["try:", *["    " + line for line in self.setup]]
            out += _test(self.tests)
            if self.converts:
                out += ["    if fast:", *["        " + line for line in self.converts]]
            out += ["except _SLOW:", "    fast = False", "if fast:"]
            indent = "    "
        else:
            indent = ""
        if scalars or self.w.sizes:
            out += [indent + "try:", indent + "    " + call,
                    indent + "except (TypeError, OverflowError):",
                    indent + "    pass                # a scalar C cannot take: the slow "
                    "path names it",
                    indent + "else:", *[indent + "    " + line for line in ending]]
        else:
            out += [indent + call, *[indent + line for line in ending]]
        return out


def _test(tests):
    """`fast = (a and b ...)`, one conjunct a line after the first."""
    if not tests:
        return ["    fast = True"]
    lines = [f"    fast = ({tests[0]}"]
    lines += [f"            and {t}" for t in tests[1:]]
    lines[-1] += ")"
    return lines


_ELEMS = {"mjtNum": "NUM", "double": "NUM", "float": "FLOAT", "int": "INT",
          "mjtByte": "BYTE", "unsigned char": "BYTE", "mjtSize": "SIZE", "mjtBool": "BOOL"}


def _elem(writer, a):
    return _ELEMS[a.base]
