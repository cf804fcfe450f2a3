"""Targets for every public MuJoCo function, built from the function metadata.

mjcffi/_generated/funcinfo.py gives each C argument's type, const-ness, fixed extents and
Nullable note; the public wrapper's signature (inspect) gives the Python
parameters; codegen/functions.py's tables give the extents that the
declaration does not (SHAPES, SIZED), the ids MuJoCo follows unchecked (IDS),
and the functions that only raise NotImplementedError (UNSUPPORTED).

For each function a valid call is built first: structs from the Env, scalars
from VALID (or 0 / 0.5), arrays of the SHAPES extents against a guard page.
Each variation then replaces one argument by a bad value of its kind.
"""

import inspect
import re

import numpy as np

from codegen import functions as tables
from mjcffi._generated import constants as _constants, enums as _enums
from mjcffi import functions as F
from mjcffi._generated.funcinfo import FUNCTIONS
from mjcffi._generated.structinfo import STRUCTS

from . import guard
from .target import Param, Target

NUMERIC = {"mjtNum": np.float64, "double": np.float64, "float": np.float32, "int": np.int32,
           "mjtByte": np.uint8, "unsigned char": np.uint8, "mjtSize": np.int64,
           "mjtBool": np.bool_}
_INTS = ("int", "size_t", "mjtSize", "mjtBool", "mjtByte", "unsigned char", "unsigned int",
         "uint64_t", "int64_t")
_FLOATS = ("mjtNum", "double", "float")

# Size arguments: distinct small values, so that swapped extents do not match.
SIZES = {"n": 3, "nr": 2, "nc": 4, "r1": 2, "c1": 3, "c2": 4, "r2": 5, "nvec": 2,
         "ntotal": 4, "nband": 2, "ndense": 1, "dim": 2, "nray": 2, "nface": 1, "nvert": 3,
         "nnz": 8, "nparams": 2, "nbytes": 4, "size": 3}

# Valid scalar and text arguments, by function and argument name ("*" for any function).
VALID = {
    "*": {"body": 1, "objtype": 1, "objid": 1, "bodyexclude": -1, "cutoff": 10.0,
          "time": 0.02, "phase": 0.0, "sig": 4356, "srcsig": 4356, "dstsig": 4356,
          "eps": 1e-6, "scl": 1.0, "mindiag": 1e-9, "flg_static": 1, "diagadd": 0.0,
          "diagmul": 0.0, "base": 2, "index": 1, "flg_centered": 0, "nstep": 1,
          "type": 1, "geom": 1, "site": 0, "geom1": 1, "geom2": 2, "g1": 1, "g2": 2,
          "siteid": 0, "geomid": 1, "flexid": 0, "vertid": 0, "camid": 0, "key": 0,
          "id": 0, "i": 0, "nthread": 1, "name": "free", "filename": "out.txt",
          "directory": ".", "classname": "main", "content_type": "text/xml",
          "seq": "xyz", "str": "body", "xml": None, "msg": "fuzz", "float_format": "%g",
          "attrib": "x", "key_": "k", "text": "a b", "prefix": "p", "suffix": "",
          "sequence": "xyz", "path": "nowhere.so", "resource_name": "x.xml"},
    "mjr_changeFont": {"fontscale": 100},          # an mjtFontScale member
    "mj_loadXML": {"filename": "model.xml"},
    "mj_parseXML": {"filename": "model.xml"},
    "mj_parse": {"filename": "model.xml"},
    "mju_getXMLDependencies": {"filename": "model.xml"},
    "mj_loadModel": {"filename": "model.mjb"},
    "mj_addFileVFS": {"directory": ".", "filename": "model.xml"},
    "mj_containsFileVFS": {"directory": "", "filename": "model.xml"},
    "mj_deleteFileVFS": {"filename": "model.xml"},
    "mj_unmountVFS": {"filename": "model.xml"},
    "mj_containsBufferVFS": {"name": "model.xml"},
    "mj_addBufferVFS": {"name": "extra.xml"},
    "mj_mountVFS": {"filepath": "mnt"},
    "mj_name2id": {"type": 1, "name": "free"},
    "mj_id2name": {"type": 1, "id": 1},
    "mjs_findBody": {"name": "world"},
    "mjs_findElement": {"type": 1, "name": "b"},
    "mjs_findChild": {"name": "b"},
    "mjs_firstChild": {"type": 1},
    "mjs_firstElement": {"type": 1},
    "mjs_setName": {"name": "renamed"},
    "mjs_addDefault": {"classname": "cls"},
    "mjs_wrapSite": {"name": "s"},
    "mjs_wrapGeom": {"name": "g", "sidesite": ""},
    "mjs_wrapJoint": {"name": "j", "coef": 1.0},
    "mjs_makeMesh": {"builtin": 1},
    "mju_writeLog": {"type": "fuzz"},
    "mjp_getPlugin": {"name": "mujoco.pid"},
    "mj_warning": {"warning": 0, "info": 0},
    "mj_contactForce": {"id": 0},
    "mju_Halton": {"index": 1, "base": 2},
    "mj_RungeKutta": {"N": 4},
    "mj_rayMesh": {"geomid": 4},                # env.XML's geoms: floor, terrain, box,
    "mj_rayHfield": {"geomid": 1},              # cap, mesh
    "mjv_connector": {"type": 3},               # mjGEOM_CAPSULE
    "mjv_moveCamera": {"action": 1},            # mjMOUSE_ROTATE_V
    "mjv_movePerturb": {"action": 1},
    "mj_setKeyframe": {"k": 0},
    "mjs_makeFlex": {"name": "flex", "type": "grid", "dof": "full", "dim": 2, "file": None},
}

# Work amounts: values that fit the C type but ask for hours of work (2**31-1 steps)
# are left out; values that do not fit must still raise.
WORK = ("nstep", "nsubsteps", "max_iter")
_LONG_RUNNING = ("2**31-1", "10**9", "count", "count+1")

# Functions whose XML text must be a model.
_XML_TEXT = ("mj_parseXMLString",)

# Allowed beyond the documented set (TypeError, ValueError, IndexError, KeyError,
# FatalError), per function.
ALLOWED = {
    name: (NotImplementedError,) for name in tables.UNSUPPORTED
}

# Functions the fuzzer leaves alone, and why (each is a deliberate exit or a
# process-wide change that no later call in the worker could survive).
SKIP = {
    "mju_threadpool": "makes OS threads that outlive the call",
    "mju_clearHandlers": "clears the error handler that turns mju_error into FatalError",
}


def _constants_table():
    names = {k: v for k, v in vars(_constants).items() if not k.startswith("_")
             and isinstance(v, (int, float))}
    for enum in vars(_enums).values():
        if isinstance(enum, type) and hasattr(enum, "__members__"):
            for k, v in enum.__members__.items():
                names.setdefault(k, int(v))
    return names


CONSTANTS = _constants_table()


class _Flat:
    """A model or data whose array attributes read flat, as the C layout (SHAPES) sees them."""

    def __init__(self, obj):
        self._obj = obj

    def __getattr__(self, name):
        value = getattr(self._obj, name)
        return np.ravel(value) if isinstance(value, np.ndarray) else value


def _kind(arg):
    """The fuzzing kind of a C argument (see values.KINDS)."""
    if arg.elem.startswith("mjf") or "(*" in arg.elem or "(*" in arg.ctype:
        return "callback"
    if arg.elem == "...":
        return "varargs"
    if arg.pointer == 0 and not arg.extents:
        if arg.elem in STRUCTS:
            return "struct"
        if arg.elem in _FLOATS:
            return "float"
        return "int"
    if arg.pointer > 1:
        return "pointer2"
    if arg.elem == "char":
        return "text" if arg.const else "buffer"
    if arg.elem == "void":
        return "buffer"
    if arg.elem in NUMERIC:
        return "array"
    if arg.elem in STRUCTS:
        return "struct"
    return "opaque"


def _scalar_valid(func, name, kind):
    for table in (VALID.get(func, {}), VALID["*"]):
        if name in table:
            return table[name]
    if name in SIZES:
        return SIZES[name]
    return 0.5 if kind == "float" else 0


def _extents(func, arg, env, scalars):
    spec = tables.SHAPES.get(func, {}).get(arg.name)
    if spec is None:
        if arg.extents:
            return tuple(arg.extents)
        return (3,)                              # no size known: three elements
    if spec == "*":
        return (SIZES["nnz"],)
    if arg.name in tables.SIZED.get(func, ()):
        spec = " * ".join(f"({d})" for d in _split_dims(spec))
    names = dict(CONSTANTS, **SIZES)
    names.update(scalars)
    names.update(m=_Flat(env.m), d=_Flat(env.d),
                 state_size=lambda m, sig, name=None: F.mj_stateSize(env.m, sig),
                 band_size=lambda t, b, d: (t - d) * b + d * t)
    return tuple(int(eval(dim, {}, names)) for dim in _split_dims(spec))


def _split_dims(spec):
    """'n, m.nv' -> ['n', 'm.nv']: SHAPES' dims, split at the commas outside brackets."""
    dims, depth, start = [], 0, 0
    for i, char in enumerate(spec):
        depth += (char in "([") - (char in ")]")
        if char == "," and depth == 0:
            dims.append(spec[start:i].strip())
            start = i + 1
    return dims + [spec[start:].strip()]


def _array(name, extents, elem, const):
    dtype = NUMERIC[elem]
    if name in ("lower", "upper"):                      # mju_boxQP: lower < upper
        values = np.full(extents, -1.0 if name == "lower" else 1.0)
    elif name == "times":
        values = np.arange(extents[0]) * 0.01
    elif name in ("quat", "qa", "qb") or (len(extents) == 1 and extents[0] == 4
                                          and "quat" in name):
        values = np.array([1.0, 0.0, 0.0, 0.0])
    else:
        values = np.ones(extents, dtype)
        if len(extents) == 2 and extents[0] == extents[1] and dtype == np.float64:
            values = np.eye(extents[0]) * 2.0
    return guard.guarded(np.asarray(values, dtype).reshape(extents), readonly=const)


# Object word -> the count of that object (codegen's OBJECTS where it has one).
_OBJECTS = dict(getattr(tables, "OBJECTS", {})) or {
    "body": "m.nbody", "geom": "m.ngeom", "site": "m.nsite", "flex": "m.nflex",
    "cam": "m.ncam", "key": "m.nkey", "actuator": "m.nu", "sensor": "m.nsensor",
    "contact": "d.ncon"}
_OBJECTS.update({"objid": "m.nbody", "vertid": "m.nflexvert", "g1": "m.ngeom",
                 "g2": "m.ngeom"})


def _id_count(func, name, env):
    """The count an id argument must stay below, or None.  The names follow codegen's
    rule for object ids (an object word, alone or with `id`, `_id`, `exclude` or a
    digit; a plain `id` takes the first object word of the doc comment); the IDS table
    itself is derived from the headers on first use, too slow for every worker."""
    if name in _OBJECTS:
        return lambda: eval(_OBJECTS[name], {}, {"m": env.m, "d": env.d})
    word = None
    if name == "id":
        doc = FUNCTIONS[func].doc.lower()
        word = next((w for w in re.findall(r"[a-z]+", doc) if w in _OBJECTS), None)
    else:
        match = re.match(r"^([a-z]+?)(?:_?id|exclude|[0-9])?$", name)
        if match and match.group(1) in _OBJECTS:
            word = match.group(1)
    if word is None:
        return None
    return lambda: eval(_OBJECTS[word], {}, {"m": env.m, "d": env.d})


class FunctionTarget(Target):
    """One MuJoCo function: the public wrapper, its Python parameters mapped to C args."""

    group = "function"

    def __init__(self, name):
        super().__init__("fn:" + name)
        self.func_name = name
        info = FUNCTIONS[name]
        by_name = {a.name: a for a in info.args}
        renames = {v: k for k, v in tables.RENAMES.get(name, {}).items()}
        self.allowed = ALLOWED.get(name, ())
        self.params = []
        self.args = {}
        for p in inspect.signature(getattr(F, name)).parameters.values():
            arg = by_name.get(renames.get(p.name, p.name)) or by_name.get(p.name.rstrip("_"))
            if arg is None:                     # an override's own parameter (mj_step's nstep)
                self.params.append(Param(p.name, "int", elem="int"))
                continue
            self.args[p.name] = arg
            self.params.append(Param(p.name, _kind(arg), elem=arg.elem, const=arg.const,
                                     nullable=arg.nullable))

    def valid(self, env):
        """{param: valid value}; a value the fuzzer cannot make is None."""
        scalars, out = {}, {}
        for p in self.params:
            if p.kind in ("int", "float"):
                value = _scalar_valid(self.func_name, p.name, p.kind)
                out[p.name] = value
                arg = self.args.get(p.name)
                scalars[arg.name if arg else p.name] = value
        for p in self.params:
            if p.name not in out:
                out[p.name] = self._valid_value(p, env, scalars)
        return {p.name: out[p.name] for p in self.params}

    def _valid_value(self, p, env, scalars):
        func = self.func_name
        arg = self.args.get(p.name)
        if p.kind == "struct":
            return env.struct(p.elem)
        if p.kind == "array":
            return _array(arg.name, _extents(func, arg, env, scalars), arg.elem, arg.const)
        if p.kind == "text":
            if func in _XML_TEXT:
                from .env import XML
                return XML
            value = _scalar_valid(func, p.name, "text")
            if not isinstance(value, str) and value is not None:
                value = "x"
            if p.name in ("filename", "directory", "path", "file", "filepath") and value:
                value = env.path(value)
            return value
        if p.kind == "buffer":
            if func == "mju_free":
                return F.mju_malloc(16)
            if func == "mjs_setUserValue":
                from mjcffi import ffi
                return ffi.cast("void *", env.keep(ffi.new("int *", 7)))
            if func == "mj_loadModelBuffer":
                return env.mjb
            if func == "mj_saveModel":
                return bytearray(F.mj_sizeModel(env.m))
            size = tables.SHAPES.get(func, {}).get(arg.name) if arg else None
            n = SIZES.get(size, 8) if size else 8
            return bytes(n) if p.const else bytearray(max(n, 64))
        if p.kind == "opaque":
            if func == "mju_free":
                return F.mju_malloc(16)
            return env.opaque(p.elem)
        return None

    def call(self, env, kwargs):
        function = getattr(F, self.func_name)
        return function(*[kwargs[p.name] for p in self.params])

    def labels(self, param):
        labels = super().labels(param)
        if param.name in WORK:
            labels = [label for label in labels if label not in _LONG_RUNNING]
        return labels

    def count(self, param, env):
        c = _id_count(self.func_name, param.name, env)
        return c() if c else None


def targets():
    out = []
    for name in F.NAMES:
        if name in SKIP:
            continue
        out.append(FunctionTarget(name))
    return out
