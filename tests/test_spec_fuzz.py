"""Bad input to the MjSpec surface, swept in worker processes.

What is swept (names found with dir() of the classes, so new methods and
attributes are covered as they come):

- `methods`: every public method of MjSpec and of each element class, each of its
  parameters in turn given each bad value (the others a good value);
- `attributes`: every public attribute of MjSpec, of the structs it holds
  (option, compiler, visual, ...) and of each element class (fields and
  properties, the nested ones such as `alt` and a default's `geom` too), set to
  each bad value;
- `adders`: every add_* / wrap_* of MjSpec, MjsBody, MjsFrame and MjsTendon, with a
  bad positional argument, a bad default=, and each keyword attribute of the new
  element given each bad value;
- `files`: from_string / from_file / from_zip with garbage, to_zip / to_file /
  encode to bad targets, compile / recompile with odd vfs and assets;
- `bind`: m.bind / d.bind of odd things and bad writes through a list binding;
- `sequences`: delete then use, delete of odd things, attach then delete, attach
  cycles, copies of specs with attached children, compile after delete, the
  garbage collection of a spec while wrappers of its elements live.

The bad values: None, bools, huge and negative ints, NaN and inf, str with NUL,
bytes, empty and long str, sequences of the wrong length, shape or dtype (complex,
object), dicts, objects, an element of another spec, a deleted element, a spec, a
model.

A case passes when it returns, or raises an exception of a sensible type
(`_SENSIBLE`) with a message.  After a refused call the spec must be as it was: an
attribute keeps its value, no element is left half-added, and the spec compiles
as it did before.  A value that was accepted must read back as given (no silent
truncation, wraparound or loss of an imaginary part).

Each group runs in a worker process (`python -m tests.test_spec_fuzz GROUP START
LIB [SELECT]`) that prints one line per case: a worker killed by a signal names
the case it was in, and the sweep goes on in a new worker after that case.
Problems known outside the files fixed with this sweep are in KNOWN_OPEN.

By hand: `python -m tests.test_spec_fuzz --report [GROUP...]` lists every finding
(the known ones too); `--compare GROUP` runs the cases on the official binding
as well (LIB `mujoco`) and lists where the two differ (the official crashes on
some: bind of a default's template, attach of an element attached before, ...).
"""

import atexit
import functools
import gc
import inspect
import io
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import types
import warnings
import zipfile

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_MARK = "@@"

# ------------------------------------------------------------------ the models

BASE_XML = """<mujoco model="base">
  <asset>
    <mesh name="tet" vertex="0 0 0 1 0 0 0 1 0 0 0 1"/>
    <mesh name="cube" file="cube.obj"/>
    <texture name="tex" type="2d" builtin="checker" width="8" height="8"/>
    <material name="mat" texture="tex"/>
  </asset>
  <default><default class="c"><geom size=".1" rgba="1 0 0 1"/></default></default>
  <worldbody>
    <light name="sun" pos="0 0 3"/>
    <geom name="floor" type="plane" size="1 1 .1"/>
    <body name="b1" pos="0 0 1">
      <joint name="j1" type="hinge"/>
      <geom name="g1" size=".1" material="mat"/>
      <site name="s1"/>
      <frame name="f1" pos="0 0 .1">
        <geom name="g2" size=".1"/>
        <frame name="f2"><site name="s3"/></frame>
      </frame>
      <body name="b2" pos="0 0 .3">
        <joint name="j2" type="slide"/>
        <geom name="g3" class="c" type="mesh" mesh="tet"/>
        <geom name="g4" type="mesh" mesh="cube"/>
        <camera name="cam"/>
        <site name="s2"/>
      </body>
    </body>
  </worldbody>
  <contact><pair name="p" geom1="g1" geom2="floor"/><exclude body1="b1" body2="b2"/></contact>
  <equality><joint name="eq" joint1="j1" joint2="j2"/></equality>
  <tendon>
    <spatial name="t"><site site="s1"/><geom geom="g1" sidesite="s3"/><site site="s2"/></spatial>
    <fixed name="tf"><joint joint="j1" coef="1"/></fixed>
  </tendon>
  <actuator><motor name="a" joint="j1"/></actuator>
  <sensor><jointpos name="sen" joint="j1"/></sensor>
  <custom>
    <numeric name="num" data="1 2"/><text name="txt" data="hello"/>
    <tuple name="tup"><element objtype="body" objname="b1" prm="1"/></tuple>
  </custom>
  <keyframe><key name="k" qpos="0 0"/></keyframe>
</mujoco>"""

CUBE_OBJ = b"""v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
f 1 3 2
f 1 2 4
f 1 4 3
f 2 3 4
"""

CHILD_XML = """<mujoco model="child">
  <worldbody>
    <frame name="cf"><geom name="cg" size=".1"/></frame>
    <body name="cb"><joint name="cj"/><geom name="cg2" size=".1"/><site name="cs"/></body>
  </worldbody>
</mujoco>"""


def _base(mj):
    """A new spec of BASE_XML, with its mesh file as an asset."""
    return mj.MjSpec.from_string(BASE_XML, assets={"cube.obj": CUBE_OBJ})


def _child(mj):
    return mj.MjSpec.from_string(CHILD_XML)


# Each element kind of the sweeps: how to find (or make) one in a base spec.
ELEMENTS = {
    "world": lambda s: s.worldbody,
    "body": lambda s: s.body("b1"),
    "body2": lambda s: s.body("b2"),
    "frame": lambda s: s.frame("f1"),
    "site": lambda s: s.site("s1"),
    "geom": lambda s: s.geom("g1"),
    "joint": lambda s: s.joint("j1"),
    "camera": lambda s: s.camera("cam"),
    "light": lambda s: s.light("sun"),
    "mesh": lambda s: s.mesh("tet"),
    "texture": lambda s: s.texture("tex"),
    "material": lambda s: s.material("mat"),
    "pair": lambda s: s.pair("p"),
    "exclude": lambda s: s.excludes[0],
    "equality": lambda s: s.equality("eq"),
    "tendon": lambda s: s.tendon("t"),
    "wrap": lambda s: s.tendon("t").path[1],
    "actuator": lambda s: s.actuator("a"),
    "sensor": lambda s: s.sensor("sen"),
    "numeric": lambda s: s.numeric("num"),
    "text": lambda s: s.text("txt"),
    "tuple": lambda s: s.tuple("tup"),
    "key": lambda s: s.key("k"),
    "default": lambda s: s.find_default("c"),
    "main_default": lambda s: s.default,
    "flex": lambda s: s.flex("fx") or s.add_flex(name="fx"),
    "skin": lambda s: s.skin("sk") or s.add_skin(name="sk"),
    "hfield": lambda s: s.hfield("hf") or s.add_hfield(name="hf", nrow=2, ncol=2,
                                                      size=[1, 1, 1, 1]),
    "plugin": lambda s: s.plugin("pl") or s.add_plugin(name="pl"),
    # structs of the element classes that are no element of a spec: the templates
    # a default class holds, and the plugin slot of a body
    "body_plugin": lambda s: s.body("b1").plugin,
    **{f"default_{member}": (lambda s, member=member: getattr(s.find_default("c"), member))
       for member in ("joint", "geom", "site", "camera", "light", "flex", "mesh", "texture",
                      "material", "pair", "equality", "tendon", "actuator")},
}

# The kinds that are no element of a spec (see ELEMENTS), and what to delete to
# free them.
_TEMPLATES = {kind: "default" for kind in ELEMENTS if kind.startswith("default_")}
_TEMPLATES["body_plugin"] = "body"


# ------------------------------------------------------------ verdicts

class _Defect(Exception):
    """A case found the spec changed by a refused call, or a value not stored as given."""


def _sensible_types(mj):
    found = [TypeError, ValueError, IndexError, KeyError, AttributeError, OverflowError,
             OSError, RuntimeError, zipfile.BadZipFile]
    fatal = getattr(mj, "FatalError", None)
    if isinstance(fatal, type):
        found.append(fatal)
    return tuple(found)


# Exceptions that come from a bug of the binding, not from the input.
_NEVER = (RecursionError, SystemError, AssertionError, NameError, ZeroDivisionError,
          MemoryError)

# Messages of exceptions leaking from the binding's inside rather than naming the
# problem: cffi's conversions, Python's own errors about private attributes.
_LEAKS = ("object has no attribute '_", "initializer for ctype", "cdata",
          "'NoneType' object", "unsupported operand", "not subscriptable",
          "object is not iterable", "referenced before assignment")


def _verdict(mj, exc):
    """(outcome, detail) of an exception a case's call raised."""
    kind = type(exc).__name__
    text = str(exc)
    if isinstance(exc, _NEVER) or not isinstance(exc, _sensible_types(mj)):
        return "bad-exception", f"{kind}: {text}"
    if not text.strip():
        return "bad-exception", f"{kind} without a message"
    if any(leak in text for leak in _LEAKS):
        return "leaky-exception", f"{kind}: {text}"
    return "raised", f"{kind}: {text}"


def _attempt(call):
    """The exception `call()` raised (None when it returned)."""
    try:
        call()
    except _Defect:
        raise
    except Exception as exc:        # noqa: BLE001  judged by _verdict
        return exc
    return None


def _compiles(spec):
    """Whether `spec` compiles (its compile error's type name if not)."""
    exc = _attempt(spec.compile)
    return "ok" if exc is None else type(exc).__name__


def _fingerprint(spec):
    """The number of elements of each kind: what an add_* that was refused must
    leave as it was.  (Counted in C for mjcffi: the sweep makes it often.)"""
    if type(spec).__module__.startswith("mjcffi"):
        from mjcffi._support.library import ffi, lib
        from mjcffi._support import spec_kinds as kinds
        counts = []
        for _, _, type_, _ in kinds.KINDS:
            count, element = 0, lib.mjs_firstElement(spec._ptr, type_)
            while element != ffi.NULL:
                count, element = count + 1, lib.mjs_nextElement(spec._ptr, element)
            counts.append(count)
        return tuple(counts)
    return tuple(len(getattr(spec, plural)) for plural in _PLURALS)


_PLURALS = ("bodies", "frames", "geoms", "joints", "sites", "cameras", "lights", "flexes",
            "meshes", "skins", "hfields", "textures", "materials", "pairs", "excludes",
            "equalities", "tendons", "actuators", "sensors", "numerics", "texts", "tuples",
            "keys", "plugins")


def _snapshot(value):
    """A comparable copy of what an attribute read gave."""
    if value is None or isinstance(value, (str, bytes, bool, int, float)):
        return value
    if isinstance(value, (list, tuple)) and all(isinstance(v, str) for v in value):
        return tuple(value)
    if hasattr(value, "_ptr") or type(value).__module__.startswith("mujoco"):
        if hasattr(value, "__len__") or hasattr(value, "__array__"):
            try:
                return ("array", np.array(value).tolist())
            except Exception:       # noqa: BLE001  not an array after all
                pass
        return ("object", type(value).__name__, _name_of(value))
    try:
        array = np.array(value)
    except Exception:               # noqa: BLE001
        return ("object", type(value).__name__)
    if array.dtype == object:
        return ("object", type(value).__name__)
    return ("array", array.tolist())


def _name_of(value):
    try:
        name = value.name
    except Exception:               # noqa: BLE001
        return None
    return name if isinstance(name, str) else None


def _same(a, b):
    """Whether two snapshots are equal (NaN equal to NaN)."""
    if a == b:
        return True
    if isinstance(a, tuple) and isinstance(b, tuple) and a[:1] == b[:1] == ("array",):
        try:
            return np.array_equal(np.asarray(a[1], float), np.asarray(b[1], float),
                                  equal_nan=True)
        except (TypeError, ValueError):
            return False
    return isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b)


def _reads_as_given(read, given):
    """Whether an attribute that accepted `given` reads it back: None when that
    cannot be told (an element, a struct, a value converted on purpose)."""
    if isinstance(given, (bool, np.bool_)) or given is None or isinstance(read, bool):
        return None             # a bool attribute takes any number by its truth
    if isinstance(given, bytes):
        return read in (given, given.decode("utf-8", "replace"))
    if isinstance(given, str):
        return read == given if isinstance(read, str) else None
    if isinstance(given, (int, float, complex, np.number)):
        numbers = _numeric(read)
        if numbers is None:
            return None
        if isinstance(given, (complex, np.complexfloating)):
            return bool(np.all(numbers.astype(complex) == given))
        flat = numbers.reshape(-1)
        if flat.size > 1 and _close(flat[:1], float(given)) and not np.any(flat[1:]):
            return True             # a keyword's official padding: size=r is [r, 0, 0]
        return _close(numbers, float(given)) and \
            (not isinstance(given, (int, np.integer)) or numbers.size != 1 or
             numbers.dtype.kind == "f" or int(numbers.reshape(-1)[0]) == given)
    if isinstance(given, (list, tuple, np.ndarray)):
        try:
            wanted = np.asarray(given)
        except Exception:           # noqa: BLE001
            return None
        if wanted.dtype == object or wanted.dtype.kind in "USb":
            return None
        numbers = _numeric(read)
        if numbers is None:
            return None
        if wanted.dtype.kind == "c":
            return numbers.shape == wanted.shape and \
                bool(np.all(numbers.astype(complex) == wanted))
        if numbers.shape != wanted.shape:
            return wanted.size == numbers.size and _close(numbers.reshape(-1),
                                                          wanted.reshape(-1))
        return _close(numbers, wanted)
    return None


def _numeric(read):
    try:
        numbers = np.array(read)
    except Exception:               # noqa: BLE001
        return None
    if numbers.dtype.kind not in "biufc":
        return None
    return numbers


def _close(numbers, wanted):
    numbers = np.asarray(numbers, dtype=float)
    wanted = np.asarray(wanted, dtype=float)
    with np.errstate(all="ignore"):
        both_nan = np.isnan(numbers) & np.isnan(wanted)
        near = np.isclose(numbers, wanted, rtol=1e-6, atol=0) | (numbers == wanted)
    return bool(np.all(both_nan | near))


# ------------------------------------------------------------ bad values

class _Ctx:
    """What the bad values are made from, kept for the worker's life: an element of
    another spec, a deleted element, a model."""

    def __init__(self, mj):
        self.mj = mj
        self.other = _child(mj)
        self.grave = mj.MjSpec()
        body = self.grave.worldbody.add_body(name="gone")
        self.dead = {"body": body, "geom": body.add_geom(name="gone_g"),
                     "frame": body.add_frame(name="gone_f"),
                     "site": body.add_site(name="gone_s")}
        self.grave.delete(body)
        self.dead["default"] = self.grave.add_default("gone_c", self.grave.default)
        self.grave.delete(self.dead["default"])
        self.model = _base(mj).compile()
        # the folder the parent gives (a crashed worker cleans nothing up)
        self.tmp = tempfile.mkdtemp(prefix="case_", dir=os.environ.get("SPEC_FUZZ_TMP"))
        if "SPEC_FUZZ_TMP" not in os.environ:
            atexit.register(shutil.rmtree, self.tmp, True)


BAD = {
    "None": lambda c: None,
    "True": lambda c: True,
    "int_2**31": lambda c: 2 ** 31,
    "int_-2**31-1": lambda c: -2 ** 31 - 1,
    "int_2**64": lambda c: 2 ** 64,
    "int_10**400": lambda c: 10 ** 400,
    "int_-1": lambda c: -1,
    "float_1.5": lambda c: 1.5,
    "nan": lambda c: math.nan,
    "inf": lambda c: math.inf,
    "complex": lambda c: 1 + 2j,
    "np_int64_2**62": lambda c: np.int64(2 ** 62),
    "np_float32_nan": lambda c: np.float32("nan"),
    "str": lambda c: "nope",
    "str_empty": lambda c: "",
    "str_nul": lambda c: "a\0b",
    "str_long": lambda c: "x" * 5000,
    "str_surrogate": lambda c: "\udc80",
    "bytes": lambda c: b"nope",
    "list_empty": lambda c: [],
    "list_1": lambda c: [0.5],
    "list_13": lambda c: [0.5] * 13,
    "list_str": lambda c: ["a", "b", "c"],
    "list_none": lambda c: [None, None, None],
    "list_nested": lambda c: [[1.0, 2.0], [3.0, 4.0]],
    "array_2x3": lambda c: np.ones((2, 3)),
    "array_complex": lambda c: np.full(3, 1 + 2j),
    "array_object": lambda c: np.array([object(), object(), object()], dtype=object),
    "array_int8_4": lambda c: np.ones(4, dtype=np.int8),
    "array_bool_3": lambda c: np.ones(3, dtype=bool),
    "generator": lambda c: (i for i in range(3)),
    "dict": lambda c: {"a": 1},
    "object": lambda c: object(),
    "other_body": lambda c: c.other.body("cb"),
    "other_frame": lambda c: c.other.frame("cf"),
    "other_default": lambda c: c.other.default,
    "dead_body": lambda c: c.dead["body"],
    "dead_geom": lambda c: c.dead["geom"],
    "dead_frame": lambda c: c.dead["frame"],
    "dead_default": lambda c: c.dead["default"],
    "spec": lambda c: c.other,
    "model": lambda c: c.model,
}

# The set for attributes: one value of each sort (the whole of BAD for methods).
BAD_ATTRIBUTES = ("None", "True", "int_2**64", "int_10**400", "float_1.5", "nan", "complex",
                  "np_int64_2**62", "str_nul", "str_long", "bytes", "list_empty", "list_13",
                  "list_nested", "array_complex", "array_object", "array_bool_3", "object",
                  "dead_body", "other_body")

# The smaller set for the keyword arguments of add_* and nested structs: one value
# of each sort.
BAD_KEYWORDS = ("None", "int_2**64", "float_1.5", "nan", "complex", "str_nul", "bytes",
                "list_empty", "list_13", "list_nested", "array_complex", "array_object",
                "object", "dead_body", "other_body")


# ------------------------------------------------------------ good arguments

def _good(mj, spec, ctx, owner, method, param):
    """A good value of parameter `param` of `owner.method` (owner in `spec`), or
    _NONE when the sweep knows none: the case is then skipped (listed as such)."""
    s = spec
    table = {
        ("MjSpec", "activate_plugin", "name"): lambda: "mujoco.pid",
        ("MjSpec", "add_default", "classname"): lambda: "newclass",
        ("MjSpec", "adopt_inertial", "body"): lambda: s.body("b2"),
        ("MjSpec", "attach", "child"): lambda: _child(mj),
        ("MjSpec", "attach", "frame"): lambda: "f1",
        ("MjSpec", "copy_back", "model"): lambda: s.compile(),
        ("MjSpec", "delete", "element"): lambda: s.geom("g2"),
        ("MjSpec", "encode", "filename"): lambda: os.path.join(ctx.tmp, "enc.xml"),
        ("MjSpec", "find_all", "type"): lambda: "geom",
        ("MjSpec", "find_default", "classname"): lambda: "c",
        ("MjSpec", "from_file", "filename"): lambda: _written(ctx),
        ("MjSpec", "from_string", "xml"): lambda: BASE_XML,
        ("MjSpec", "from_string", "assets"): lambda: {"cube.obj": CUBE_OBJ},
        ("MjSpec", "from_file", "assets"): lambda: {"cube.obj": CUBE_OBJ},
        ("MjSpec", "from_zip", "file"): lambda: _zipped(mj, ctx),
        ("MjSpec", "recompile", "m"): lambda: _compiled(s)[0],
        ("MjSpec", "recompile", "d"): lambda: _compiled(s)[1],
        ("MjSpec", "resolve_orientation", "degree"): lambda: True,
        ("MjSpec", "resolve_orientation", "orientation"): lambda: s.body("b1").alt,
        ("MjSpec", "to_file", "filename"): lambda: os.path.join(ctx.tmp, "out.xml"),
        ("MjSpec", "to_zip", "file"): lambda: os.path.join(ctx.tmp, "out.zip"),
        ("MjsBody", "attach_frame", "frame"): lambda: _child(mj).frame("cf"),
        ("MjsBody", "find_all", "type"): lambda: "geom",
        ("MjsBody", "find_child", "name"): lambda: "b2",
        ("MjsBody", "make_flex", "name"): lambda: "flexy",
        ("MjsBody", "make_flex", "type"): lambda: "grid",
        ("MjsBody", "make_flex", "count"): lambda: [3, 3, 1],
        ("MjsBody", "make_flex", "spacing"): lambda: [0.1, 0.1, 0.1],
        ("MjsBody", "make_flex", "dim"): lambda: 2,
        ("MjsBody", "set_frame", "frame"): lambda: s.frame("f1"),
        ("MjsFrame", "attach_body", "body"): lambda: _child(mj).body("cb"),
        ("MjsSite", "attach_body", "body"): lambda: _child(mj).body("cb"),
        ("MjsMesh", "make_cone", "nedge"): lambda: 5,
        ("MjsMesh", "make_cone", "radius"): lambda: 0.5,
        ("MjsMesh", "make_sphere", "subdivision"): lambda: 1,
        ("MjsMesh", "make_hemisphere", "resolution"): lambda: 2,
        ("MjsMesh", "make_supersphere", "resolution"): lambda: 4,
        ("MjsMesh", "make_supertorus", "resolution"): lambda: 4,
        ("MjsMesh", "make_supertorus", "radius"): lambda: 0.5,
        ("MjsActuator", "set_to_cylinder", "timeconst"): lambda: 1.0,
        ("MjsActuator", "set_to_cylinder", "bias"): lambda: 1.0,
        ("MjsActuator", "set_to_cylinder", "area"): lambda: 1.0,
        ("MjsActuator", "set_to_dcmotor", "motorconst"): lambda: [1.0, 1.0],
        ("MjsActuator", "set_to_dcmotor", "resistance"): lambda: 1.0,
        ("MjsActuator", "set_to_muscle", "tausmooth"): lambda: 0.0,
    }
    by_name = {
        "name": lambda: "b1", "frame": lambda: s.frame("f1"), "count": lambda: [3, 3, 3],
        "spacing": lambda: [0.1, 0.1, 0.1], "e": lambda: 1.0, "n": lambda: 1.0,
        "s": lambda: 1.0, "t": lambda: 1.0, "kp": lambda: 1.0, "kv": lambda: 1.0,
        "gain": lambda: 1.0,
    }
    if (owner, method, param) in table:
        return table[(owner, method, param)]()
    if method.startswith("next_") and param == "child":
        kind = method[5:]
        return getattr(_ELEMENT_OF_KIND[kind](s), f"first_{kind}")() or _NONE
    if param in by_name:
        return by_name[param]()
    return _NONE


_NONE = object()

# The body holding each kind of child, for next_*.
_ELEMENT_OF_KIND = {"body": lambda s: s.body("b1"), "frame": lambda s: s.body("b1"),
                    "geom": lambda s: s.body("b1"), "site": lambda s: s.body("b1"),
                    "joint": lambda s: s.body("b1"), "camera": lambda s: s.body("b2"),
                    "light": lambda s: s.worldbody}


def _written(ctx):
    path = os.path.join(ctx.tmp, "base.xml")
    if not os.path.exists(path):
        with open(path, "w") as file:
            file.write(BASE_XML)
        with open(os.path.join(ctx.tmp, "cube.obj"), "wb") as file:
            file.write(CUBE_OBJ)
    return path


def _zipped(mj, ctx):
    path = os.path.join(ctx.tmp, "base.zip")
    if not os.path.exists(path):
        with zipfile.ZipFile(path, "w") as archive:
            archive.writestr("base.xml", BASE_XML)
            archive.writestr("cube.obj", CUBE_OBJ)
    return path


def _compiled(spec):
    cache = _compiled.__dict__.setdefault("cache", {})
    key = id(spec)
    if key not in cache or cache[key][0] is not spec:
        model = spec.compile()
        import importlib
        mj = importlib.import_module(type(spec).__module__.split(".")[0])
        cache.clear()
        cache[key] = (spec, model, mj.MjData(model))
    return cache[key][1:]


# ------------------------------------------------------------ discovery

def _public(cls):
    """(methods, attributes): the public names of `cls`, each sorted."""
    methods, attributes = [], []
    for name in sorted(dir(cls)):
        if name.startswith("_"):
            continue
        static = inspect.getattr_static(cls, name)
        if isinstance(static, (types.FunctionType, classmethod, staticmethod)):
            methods.append(name)
        elif not isinstance(static, type):
            attributes.append(name)
    return methods, attributes


def _parameters(function):
    """The parameters of a method one may pass (no self, no *args/**kwargs)."""
    params = list(inspect.signature(function).parameters.values())
    return [p for p in params if p.name not in ("self", "cls") and
            p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]


def _element_classes():
    import mjcffi
    from mjcffi.structs import mjspec
    found = {}
    for kind, find in ELEMENTS.items():
        spec = _base(mjcffi)
        found[kind] = type(find(spec))
    found["spec"] = mjspec.MjSpec
    del mjcffi
    return found


# Methods that change nothing when they return: the spec they ran on can be used
# for the next case.
_PURE = {"children", "subtree", "find_all", "find_child", "find_default", "copy",
         "get_data_size", "default", "to_xml", "compile", "resolve_orientation",
         "from_string", "from_file", "from_zip", "to_zip", "to_file", "encode"}


def _is_pure(method):
    from mjcffi._support import spec_kinds as kinds
    return method in _PURE or method.startswith(("first_", "next_")) or \
        method in {kind[1] for kind in kinds.KINDS}


# ------------------------------------------------------------ group: methods

class _Cache:
    """A base spec per key (with the element of kind `key` made, where ELEMENTS makes
    one), kept while cases leave it as it was; `compiled[key]`: how it compiles."""

    def __init__(self, mj):
        self.mj = mj
        self.specs, self.compiled = {}, {}

    def get(self, key):
        spec = self.specs.get(key)
        if spec is None:
            spec = self.specs[key] = _base(self.mj)
            if key in ELEMENTS:
                ELEMENTS[key](spec)
            self.compiled[key] = _compiles(spec)
        return spec

    def drop(self, key):
        self.specs.pop(key, None)


def _owner_of(spec, kind):
    return spec if kind == "spec" else ELEMENTS[kind](spec)


def group_methods(mj, ctx):
    """Every public method of MjSpec and of the element classes, each parameter given
    each bad value."""
    cache = _Cache(mj)
    for kind, cls in _element_classes().items():
        if kind in ("body2", "main_default"):
            continue
        methods, _ = _public(cls)
        for method in methods:
            if method.startswith(("add_", "wrap_")):
                continue        # the adders group
            params = _parameters(getattr(cls, method))
            for index, param in enumerate(params):
                for bad in BAD:
                    key = f"method:{kind}.{method}({param.name}={bad})"
                    yield key, functools.partial(_method_case, mj, ctx, cache, kind, cls,
                                                 method, params, index, bad)


def _method_case(mj, ctx, cache, kind, cls, method, params, index, bad):
    spec = cache.get(kind)
    owner = _owner_of(spec, kind)
    owner_name = "MjSpec" if kind == "spec" else cls.__name__
    args = []
    for i, param in enumerate(params):
        if i == index:
            args.append(BAD[bad](ctx))
            continue
        if param.default is not inspect.Parameter.empty:
            if i > index:
                break
            value = _good(mj, spec, ctx, owner_name, method, param.name)
            args.append(param.default if value is _NONE else value)
            continue
        value = _good(mj, spec, ctx, owner_name, method, param.name)
        if value is _NONE:
            raise _Skip(f"no good value for {owner_name}.{method}({param.name})")
        args.append(value)
    before_fp, before_compile = _fingerprint(spec), cache.compiled[kind]
    exc = _attempt(lambda: getattr(owner, method)(*args))
    if exc is not None:
        _check_unchanged(spec, before_fp, before_compile, cache, kind)
    elif not _is_pure(method):
        cache.drop(kind)
    return exc


class _Skip(Exception):
    """A case the sweep cannot make (no good value of a parameter)."""


def _check_unchanged(spec, fingerprint, compiled, cache=None, key=None):
    """After a refused call: the spec holds the elements it held and compiles as it
    did; else a _Defect (and the cached spec is dropped)."""
    problems = []
    after = _attempt(lambda: _fingerprint(spec))
    if after is not None:
        problems.append(f"its elements cannot be listed ({after!r})")
    elif _fingerprint(spec) != fingerprint:
        changed = [f"{p} {a}->{b}" for p, a, b in zip(_PLURALS, fingerprint,
                                                         _fingerprint(spec)) if a != b]
        problems.append("the refused call changed the spec: " + ", ".join(changed))
    now = _compiles(spec)
    if now != compiled:
        problems.append(f"the spec compiled ({compiled}) before the refused call, "
                        f"{now} after")
    if problems:
        if cache is not None:
            cache.drop(key)
        raise _Defect("; ".join(problems))


# ------------------------------------------------------------ group: attributes

def _nested_classes():
    """The structs a spec holds (option, compiler, visual and its parts, stat)."""
    import mjcffi
    spec = _base(mjcffi)
    found = {}
    for name in ("option", "compiler", "visual", "stat"):
        found[f"spec.{name}"] = type(getattr(spec, name))
    visual = spec.visual
    for name in _public(type(visual))[1]:
        value = getattr(visual, name)
        if hasattr(value, "_ptr"):
            found[f"spec.visual.{name}"] = type(value)
    return found


def _resolve(spec, path):
    """The object at dotted `path`: 'spec.visual.global_', 'geom', 'geom.alt'."""
    head, *rest = path.split(".")
    value = spec if head == "spec" else ELEMENTS[head](spec)
    for part in rest:
        value = getattr(value, part)
    return value


def _attribute_targets():
    """{path: class}: MjSpec, its structs, each element kind and the structs an
    element holds (alt, plugin, a default's geom, ...)."""
    import mjcffi
    from mjcffi._support.views import Struct
    targets = {"spec": mjcffi.MjSpec, **_nested_classes()}
    for kind, cls in _element_classes().items():
        if kind in ("spec", "body2", "main_default"):
            continue            # (as body and default)
        targets[kind] = cls
        spec = _base(mjcffi)
        element = ELEMENTS[kind](spec)
        for name in _public(cls)[1]:
            if name not in getattr(cls, "_fields", ()):
                continue        # a property may crash before a fix: read in cases only
            try:
                value = getattr(element, name)
            except Exception:       # noqa: BLE001
                continue
            if isinstance(value, Struct) and kind != "default" and name not in (
                    "element", "frame", "parent", "classname", "target", "sidesite",
                    "compiler", "plugin"):
                targets[f"{kind}.{name}"] = type(value)
    return targets


def group_attributes(mj, ctx):
    """Every public attribute of MjSpec, its structs and the element kinds, set to
    each bad value."""
    cache = _Cache(mj)
    for path, cls in _attribute_targets().items():
        nested = path.count(".") > (1 if path.startswith("spec.") else 0)
        for name in _public(cls)[1]:
            for bad in BAD_KEYWORDS if nested else BAD_ATTRIBUTES:
                key = f"attr:{path}.{name}={bad}"
                yield key, functools.partial(_attribute_case, mj, ctx, cache, path, name, bad)


_UNREADABLE = object()


def _attribute_case(mj, ctx, cache, path, name, bad):
    key = path.split(".")[0]
    spec = cache.get(key)
    target = _resolve(spec, path)
    try:
        before = _snapshot(getattr(target, name))
    except Exception:               # noqa: BLE001  write-only (copy_during_attach)
        before = _UNREADABLE
    fingerprint = _fingerprint(spec)
    value = BAD[bad](ctx)
    exc = _attempt(lambda: setattr(target, name, value))
    if exc is not None:
        problems = []
        if before is not _UNREADABLE:
            after_exc = _attempt(lambda: getattr(target, name))
            if after_exc is None and not _same(_snapshot(getattr(target, name)), before):
                problems.append(f"refused, yet {name} changed from {before!r:.80} to "
                                f"{_snapshot(getattr(target, name))!r:.80}")
        if problems:
            cache.drop(key)
            raise _Defect("; ".join(problems))
        _check_unchanged(spec, fingerprint, cache.compiled[key], cache, key)
        return exc
    cache.drop(key)
    read_exc = _attempt(lambda: getattr(target, name))
    if read_exc is None and before is not _UNREADABLE:
        verdict = _reads_as_given(getattr(target, name), BAD[bad](ctx))
        if verdict is False:
            raise _Defect(f"accepted {value!r:.60} but reads "
                          f"{_snapshot(getattr(target, name))!r:.80}")
    _attempt(spec.compile)          # whatever was accepted must not crash the compiler
    return None


# ------------------------------------------------------------ group: adders

def _adders():
    """(owner kind, adder name, class of what it makes)."""
    import mjcffi
    found = []
    for kind in ("spec", "world", "frame", "tendon"):
        cls = mjcffi.MjSpec if kind == "spec" else _element_classes()[kind]
        for method in _public(cls)[0]:
            if method.startswith(("add_", "wrap_")):
                found.append((kind, method))
    return found


def _keywords_of(mj, kind, method):
    """The keywords an adder takes: the attributes of what it makes, and the
    orientation keywords where it has an `alt`."""
    spec = _base(mj)
    owner = _owner_of(spec, kind)
    made = _make(owner, method, spec)
    attrs = [a for a in _public(type(made))[1] if a not in (
        "element", "id", "signature", "compiler", "parent", "frame", "path", "target",
        "sidesite", "coef", "divisor")]
    for field, prefix in (("alt", ""), ("ialt", "i")):
        if hasattr(made, field):
            attrs += [prefix + k for k in ("euler", "axisangle", "xyaxes", "zaxis")]
    return attrs


def _make(owner, method, spec, **attrs):
    args = {"wrap_site": ("s1",), "wrap_geom": ("g1", ""), "wrap_joint": ("j1", 1.0),
            "wrap_pulley": (1.0,), "add_default": ("kw_class",)}.get(method, ())
    if method == "add_default" and "classname" in attrs:
        args = ()
    return getattr(owner, method)(*args, **attrs)


def group_adders(mj, ctx):
    """Every add_* / wrap_*: a bad first argument, a bad default=, and each keyword
    attribute given each bad value of BAD_KEYWORDS."""
    cache = _Cache(mj)
    for kind, method in _adders():
        for bad in BAD:
            yield (f"adder:{kind}.{method}({bad})",
                   functools.partial(_adder_case, mj, ctx, cache, kind, method, "arg", bad))
            yield (f"adder:{kind}.{method}(default={bad})",
                   functools.partial(_adder_case, mj, ctx, cache, kind, method, "default",
                                     bad))
        for keyword in _keywords_of(mj, kind, method):
            for bad in BAD_KEYWORDS:
                yield (f"adder:{kind}.{method}({keyword}={bad})",
                       functools.partial(_adder_case, mj, ctx, cache, kind, method,
                                         keyword, bad))


def _adder_case(mj, ctx, cache, kind, method, how, bad):
    spec = cache.get("adders")
    owner = _owner_of(spec, kind)
    value = BAD[bad](ctx)
    fingerprint = _fingerprint(spec)
    made = []
    if how == "arg":
        call = lambda: made.append(getattr(owner, method)(value))  # noqa: E731
    elif how == "default":
        call = lambda: made.append(_make(owner, method, spec, default=value))  # noqa: E731
    else:
        call = lambda: made.append(_make(owner, method, spec, **{how: value}))  # noqa: E731
    exc = _attempt(call)
    if exc is not None:
        _check_unchanged(spec, fingerprint, cache.compiled["adders"], cache, "adders")
        return exc
    cache.drop("adders")
    if how not in ("arg", "default") and made and not how.startswith(
            ("euler", "axisangle", "xyaxes", "zaxis", "ieuler", "iaxisangle", "ixyaxes",
             "izaxis")):
        read_exc = _attempt(lambda: getattr(made[0], how))
        if read_exc is None:
            verdict = _reads_as_given(getattr(made[0], how), BAD[bad](ctx))
            if verdict is False:
                raise _Defect(f"accepted {how}={value!r:.60} but reads "
                              f"{_snapshot(getattr(made[0], how))!r:.80}")
    _attempt(spec.compile)
    return None


# ------------------------------------------------------------ group: files

_GARBAGE_XML = {
    "empty": "",
    "not_xml": "hello",
    "binary": "\x01\x02\x03<\xff",
    "unclosed": "<mujoco><worldbody><body>",
    "nested_deep": "<mujoco><worldbody>" + "<body>" * 3000 + "</body>" * 3000 +
                   "</worldbody></mujoco>",
    "frames_deep": "<mujoco><worldbody>" + "<frame>" * 3000 + "</frame>" * 3000 +
                   "</worldbody></mujoco>",
    "huge_number": "<mujoco><worldbody><geom size='1e999'/></worldbody></mujoco>",
    "nan_number": "<mujoco><worldbody><geom size='nan'/></worldbody></mujoco>",
    "long_name": "<mujoco><worldbody><body name='" + "n" * 100000 +
                 "'/></worldbody></mujoco>",
    "many_values": "<mujoco><worldbody><geom size='" + "1 " * 10000 +
                   "'/></worldbody></mujoco>",
    "unknown_element": "<mujoco><nope/></mujoco>",
    "include_missing": "<mujoco><include file='missing.xml'/></mujoco>",
    "include_self": "<mujoco><include file='self.xml'/></mujoco>",
    "bad_class": "<mujoco><worldbody><geom class='nope'/></worldbody></mujoco>",
    "int_overflow": "<mujoco><size nkey='99999999999999999999'/></mujoco>",
    "negative_size": "<mujoco><size memory='-5'/></mujoco>",
    "bad_mesh_ref": "<mujoco><worldbody><geom type='mesh' mesh='x'/></worldbody></mujoco>",
    "entity": "<!DOCTYPE m [<!ENTITY a 'aaaa'>]><mujoco model='&a;'/>",
    "cut_half": BASE_XML[:len(BASE_XML) // 2],
    "nul_inside": "<mujoco>\0</mujoco>",
    "plugin_unknown": "<mujoco><extension><plugin plugin='no.such'/></extension></mujoco>",
    "childclass_loop": "<mujoco><default><default class='a'><default class='a'/></default>"
                       "</default></mujoco>",
    "attach_missing": "<mujoco><asset><model name='x' file='none.xml'/></asset>"
                      "<worldbody><attach model='x' prefix='p'/></worldbody></mujoco>",
}

_INCLUDES = {
    "None": None, "str_value": {"a.xml": "<mujoco/>"}, "int_value": {"a.xml": 5},
    "int_key": {5: b"x"}, "list": [b"x"], "self": {"self.xml": b"<mujoco><include "
                                                    b"file='self.xml'/></mujoco>"},
    "garbage": {"a.xml": b"\xff\xfe"},
}


def _xml_cuts():
    step = max(1, len(BASE_XML) // 12)
    return {f"cut_{i}": BASE_XML[:i] for i in range(step, len(BASE_XML), step)}


def group_files(mj, ctx):
    """Parsing garbage, saving to bad targets, compiling with odd files."""
    for name, xml in {**_GARBAGE_XML, **_xml_cuts()}.items():
        yield f"files:from_string({name})", functools.partial(
            _parse_case, mj, lambda xml=xml: mj.MjSpec.from_string(xml))
    for bad in BAD:
        yield f"files:from_string(xml={bad})", functools.partial(
            _parse_case, mj, lambda bad=bad: mj.MjSpec.from_string(BAD[bad](ctx)))
    for name, include in _INCLUDES.items():
        xml = "<mujoco><include file='self.xml'/></mujoco>" if name == "self" else "<mujoco/>"
        for arg in ("include", "assets"):
            yield f"files:from_string({arg}={name})", functools.partial(
                _parse_case, mj, lambda include=include, arg=arg, xml=xml:
                mj.MjSpec.from_string(xml, **{arg: include}))
    for name, path in _bad_paths(ctx).items():
        yield f"files:from_file({name})", functools.partial(
            _parse_case, mj, lambda path=path: mj.MjSpec.from_file(path))
        yield f"files:from_zip({name})", functools.partial(
            _parse_case, mj, lambda path=path: mj.MjSpec.from_zip(path))
    for name, make in _bad_zips(ctx).items():
        yield f"files:from_zip({name})", functools.partial(
            _parse_case, mj, lambda make=make: mj.MjSpec.from_zip(make()))
    for name, target in _bad_targets(ctx).items():
        for method in ("to_zip", "to_file", "encode"):
            yield f"files:{method}({name})", functools.partial(
                _save_case, mj, method, target)
    for name, vfs in _odd_vfs(mj).items():
        for method in ("compile", "fuse_static", "discard_visual", "recompile"):
            yield f"files:{method}(vfs={name})", functools.partial(
                _vfs_case, mj, method, vfs)
    for name, assets in _odd_assets().items():
        yield f"files:assets={name}", functools.partial(_assets_case, mj, assets)


def _parse_case(mj, parse):
    made = []
    exc = _attempt(lambda: made.append(parse()))
    if exc is None:
        _attempt(made[0].compile)
    return exc


def _bad_paths(ctx):
    garbage = os.path.join(ctx.tmp, "garbage.xml")
    with open(garbage, "wb") as file:
        file.write(b"\x00\xff garbage")
    binary = os.path.join(ctx.tmp, "garbage.mjb")
    with open(binary, "wb") as file:
        file.write(b"\x01" * 4096)
    empty = os.path.join(ctx.tmp, "empty.mjb")
    open(empty, "wb").close()
    return {"missing": os.path.join(ctx.tmp, "missing.xml"), "directory": ctx.tmp,
            "nul": "a\0b.xml", "empty_str": "", "int": 5, "None": None,
            "garbage_xml": garbage, "garbage_mjb": binary, "empty_mjb": empty,
            "unknown_ext": os.path.join(ctx.tmp, "x.nope"), "bytes_path": garbage.encode(),
            "list": [garbage]}


def _bad_zips(ctx):
    def archive(files):
        buffer = io.BytesIO()
        with zipfile.ZipFile(buffer, "w") as out:
            for name, content in files.items():
                out.writestr(name, content)
        buffer.seek(0)
        return buffer
    return {
        "no_xml": lambda: archive({"a.txt": b"x"}),
        "two_xml": lambda: archive({"a.xml": "<mujoco/>", "b.xml": "<mujoco/>"}),
        "garbage_xml": lambda: archive({"a.xml": b"\xff\xfe\x00"}),
        "bad_utf8": lambda: archive({"a.xml": b"<mujoco model='\xff'/>"}),
        "truncated": lambda: io.BytesIO(archive({"a.xml": BASE_XML}).getvalue()[:40]),
        "not_zip_bytes": lambda: io.BytesIO(b"PK\x03\x04" + b"\x00" * 100),
        "text_io": lambda: io.StringIO("x"),
        "dir_only": lambda: archive({"d/": b""}),
        "escaping_name": lambda: archive({"../../evil.xml": "<mujoco/>"}),
    }


def _bad_targets(ctx):
    blocker = os.path.join(ctx.tmp, "file_not_dir")
    open(blocker, "w").close()
    read_only = open(blocker, "rb")
    return {"None": None, "int": 5, "directory": ctx.tmp, "nul": "a\0b.zip",
            "under_a_file": os.path.join(blocker, "x.zip"), "empty_str": "",
            "read_only_file": read_only, "text_io": io.StringIO(), "list": [],
            "object": object(), "bytes_path": os.path.join(ctx.tmp, "b.zip").encode()}


def _save_case(mj, method, target):
    spec = _base(mj)
    if method == "to_zip":
        exc = _attempt(lambda: spec.to_zip(target))
    elif method == "to_file":
        exc = _attempt(lambda: spec.to_file(target))
    else:
        exc = _attempt(lambda: spec.encode(target))
    if exc is not None:
        _check_unchanged(spec, _fingerprint(_base(mj)), "ok")
    return exc


def _odd_vfs(mj):
    closed = mj.MjVfs()
    closed.close()
    return {"closed": closed, "dict": {"cube.obj": CUBE_OBJ}, "int": 5, "str": "cube.obj",
            "model": object(), "empty": mj.MjVfs(), "spec": mj.MjSpec()}


def _vfs_case(mj, method, vfs):
    spec = _base(mj)
    spec.compile()
    fingerprint = _fingerprint(spec)
    if method == "recompile":
        m, d = _compiled(spec)
        exc = _attempt(lambda: spec.recompile(m, d, vfs=vfs))
    else:
        exc = _attempt(lambda: getattr(spec, method)(vfs=vfs))
    if exc is not None:
        _check_unchanged(spec, fingerprint, "ok")
    return exc


def _odd_assets():
    return {"list": [b"x"], "int_value": {"cube.obj": 5}, "none_value": {"cube.obj": None},
            "int_key": {5: b"x"}, "str": "cube.obj", "None": None,
            "garbage_mesh": {"cube.obj": b"\xff\x00garbage"},
            "empty_mesh": {"cube.obj": b""}}


def _assets_case(mj, assets):
    spec = _base(mj)
    fingerprint = _fingerprint(spec)
    exc = _attempt(lambda: setattr(spec, "assets", assets))
    if exc is not None:
        _check_unchanged(spec, fingerprint, "ok")
    else:
        _attempt(spec.compile)
    return exc


# ------------------------------------------------------------ group: bind

def group_bind(mj, ctx):
    """m.bind / d.bind of odd things; writes of bad values through a list binding."""
    targets = {
        **{bad: (lambda s, bad=bad: BAD[bad](ctx)) for bad in BAD},
        "name": lambda s: "g1", "frame": lambda s: s.frame("f1"),
        "default": lambda s: s.default, "wrap": lambda s: s.tendon("t").path[0],
        "orientation": lambda s: s.geom("g1").alt, "option": lambda s: s.option,
        "spec_itself": lambda s: s, "list_with_none": lambda s: [s.geom("g1"), None],
        "list_mixed": lambda s: [s.geom("g1"), s.joint("j1")],
        "list_nested": lambda s: [[s.geom("g1")]], "tuple_empty": lambda s: (),
        "generator": lambda s: (g for g in s.geoms), "array": lambda s: np.array(s.geoms),
        "set": lambda s: set(s.geoms), "dict": lambda s: {"g": s.geom("g1")},
        "other_geom": lambda s: ctx.other.geom("cg"),
        "list_other": lambda s: [s.geom("g1"), ctx.other.geom("cg")],
        "list_dead": lambda s: [s.geom("g1"), ctx.dead["geom"]],
        "added_since": lambda s: s.worldbody.add_geom(size=[1, 0, 0]),
        **{kind: ELEMENTS[kind] for kind in _TEMPLATES},
    }
    for name in targets:
        for owner in ("model", "data"):
            yield f"bind:{owner}.bind({name})", functools.partial(
                _bind_case, mj, owner, targets[name])
    for bad in BAD:
        for attr in ("qpos", "xpos", "range", "nope"):
            yield f"bind:write({attr}={bad})", functools.partial(_bind_write_case, mj, ctx,
                                                                  attr, bad)


def _bind_case(mj, owner, target):
    spec = _base(mj)
    model = spec.compile()
    data = mj.MjData(model)
    value = target(spec)
    bound = model if owner == "model" else data
    exc = _attempt(lambda: bound.bind(value))
    if exc is None:
        result = bound.bind(value)
        _attempt(lambda: repr(result))
    return exc


def _bind_write_case(mj, ctx, attr, bad):
    spec = _base(mj)
    model = spec.compile()
    data = mj.MjData(model)
    owner = model if attr == "range" else data
    bound = owner.bind(spec.joints)
    before = np.array(data.qpos).copy(), np.array(model.jnt_range).copy()
    exc = _attempt(lambda: setattr(bound, attr, BAD[bad](ctx)))
    if exc is not None:
        after = np.array(data.qpos), np.array(model.jnt_range)
        if not (np.array_equal(after[0], before[0], equal_nan=True) and
                np.array_equal(after[1], before[1], equal_nan=True)):
            raise _Defect(f"refused, yet wrote: qpos {before[0]} -> {after[0]}, "
                          f"jnt_range {before[1].tolist()} -> {after[1].tolist()}")
    return exc


# ------------------------------------------------------------ group: sequences

def group_sequences(mj, ctx):
    """Sequences of calls: each `_seq_*` function below, and use after delete of each
    public method and attribute of each element kind."""
    for name in sorted(globals()):
        if name.startswith("_seq_"):
            yield f"seq:{name[5:]}", functools.partial(globals()[name], mj, ctx)
    for kind, cls in _element_classes().items():
        if kind in ("spec", "world", "main_default"):
            continue
        methods, attributes = _public(cls)
        for name in methods:
            yield f"seq:deleted_{kind}.{name}()", functools.partial(
                _deleted_use_case, mj, ctx, kind, name, "call")
        for name in attributes:
            yield f"seq:deleted_{kind}.{name}", functools.partial(
                _deleted_use_case, mj, ctx, kind, name, "get")
            yield f"seq:deleted_{kind}.{name}=", functools.partial(
                _deleted_use_case, mj, ctx, kind, name, "set")


_DELETED: dict = {}


def _deleted(mj, kind):
    """(spec, element, values) for `kind`: a base spec after the delete of its
    element of `kind` (or of what holds it: a wrap's tendon, a template's default
    class or body, held meanwhile), the element's wrapper, and the values of its
    attributes read before.  Made once per kind: a refused use changes nothing."""
    found = _DELETED.get(kind)
    if found is None:
        spec = _base(mj)
        holder = spec.tendon("t") if kind == "wrap" else \
            ELEMENTS[_TEMPLATES[kind]](spec) if kind in _TEMPLATES else None
        element = ELEMENTS[kind](spec)
        values = {}
        for name in _public(type(element))[1]:
            try:
                values[name] = _plain(getattr(element, name))
            except Exception:       # noqa: BLE001  a write-only or refused read
                values[name] = 1
        spec.delete(holder if holder is not None else element)
        found = _DELETED[kind] = (spec, element, values)
    return found


def _plain(value):
    """`value`, an array view as a copy (a held view would refuse the delete)."""
    return np.array(value) if hasattr(value, "__array__") else value


def _deleted_use_case(mj, ctx, kind, name, how):
    """Use `name` of the wrapper of a deleted element: read, write or call."""
    spec, element, values = _deleted(mj, kind)
    if how == "get":
        exc = _attempt(lambda: getattr(element, name))
    elif how == "set":
        exc = _attempt(lambda: setattr(element, name, values[name]))
        if exc is None:
            raise _Defect(f"{name} of a deleted element was written")
    else:
        exc = _attempt(lambda: getattr(element, name))
        if exc is not None:
            return exc
        method = getattr(element, name)
        exc = _attempt(lambda: method())
        if exc is not None and isinstance(exc, TypeError) and "argument" in str(exc):
            good = _good(mj, spec, ctx, type(element).__name__, name, _parameters(
                getattr(type(element), name))[0].name)
            if good is not _NONE:
                exc = _attempt(lambda: method(good))
    _attempt(spec.compile)
    return exc


def _seq_template_outlives_its_default(mj, ctx):
    """A default class's template (default.geom) kept after its default's wrapper
    was dropped, then the default deleted: the template must not reach freed
    memory.  As a deleted element's wrapper, it reads the values it had (a copy,
    read-only) and refuses writes."""
    spec = _base(mj)
    template = spec.find_default("c").geom        # the default's wrapper dropped here
    before = np.array(template.size)
    gc.collect()
    spec.delete(spec.find_default("c"))
    for _ in range(20):                            # reuse the freed memory
        _base(mj).add_default("filler")
    excs = [_must_refuse(lambda: setattr(template, "name", "x"),
                         "a write to the template of a deleted default"),
            _must_refuse(lambda: setattr(template, "size", [1, 1, 1]),
                         "a write of an array of the template of a deleted default")]
    size = template.size
    if not np.array_equal(size, before) or size.flags.writeable:
        raise _Defect("the template of a deleted default does not read its kept values, "
                      "read-only")
    _raise_worst(mj, excs)


def _must_refuse(call, what):
    exc = _attempt(call)
    if exc is None:
        raise _Defect(f"{what} was not refused")
    return exc


def _seq_delete_odd_things(mj, ctx):
    spec = _base(mj)
    refused = []
    for what, element in (("world", spec.worldbody), ("spec", spec), ("other spec", ctx.other),
                          ("None", None), ("name", "b1"), ("int", 3),
                          ("other body", ctx.other.body("cb")),
                          ("dead body", ctx.dead["body"]), ("dead default", ctx.dead["default"]),
                          ("orientation", spec.body("b1").alt), ("option", spec.option),
                          ("other default", ctx.other.default),
                          ("wrap", spec.tendon("t").path[0])):
        fingerprint = _fingerprint(spec)
        refused.append(_must_refuse(lambda e=element: spec.delete(e), f"delete({what})"))
        _check_unchanged(spec, fingerprint, "ok")
    _raise_worst(mj, refused)


def _raise_worst(mj, excs):
    """Raise the first exception of a bad sort among `excs`, so the case reports it."""
    for exc in excs:
        if exc is not None and _verdict(mj, exc)[0] != "raised":
            raise exc


def _seq_delete_twice(mj, ctx):
    spec = _base(mj)
    body = spec.body("b2")
    spec.delete(body)
    exc = _must_refuse(lambda: spec.delete(body), "a second delete")
    spec.compile()
    _raise_worst(mj, [exc])


def _seq_delete_main_default(mj, ctx):
    spec = _base(mj)
    exc = _attempt(lambda: spec.delete(spec.default))
    _attempt(spec.compile)
    _attempt(lambda: spec.worldbody.add_geom(size=[1, 0, 0]))
    _attempt(spec.compile)
    _raise_worst(mj, [exc])


def _seq_delete_default_then_use(mj, ctx):
    spec = _base(mj)
    default = spec.find_default("c")
    geom = spec.geom("g3")
    spec.delete(default)
    excs = [_attempt(lambda: geom.classname), _attempt(spec.compile),
            _must_refuse(lambda: spec.worldbody.add_geom(default=default),
                         "add_geom(default=deleted)"),
            _must_refuse(lambda: spec.add_default("x", default), "add_default(parent=deleted)"),
            _must_refuse(lambda: setattr(geom, "classname", default), "classname=deleted")]
    _raise_worst(mj, excs)


def _seq_every_kind_deleted_then_compile(mj, ctx):
    excs = []
    for kind in ELEMENTS:
        if kind in ("world", "main_default", "wrap"):
            continue
        spec = _base(mj)
        element = ELEMENTS[kind](spec)
        excs.append(_attempt(lambda: spec.delete(element)))
        _attempt(spec.compile)
        _attempt(spec.to_xml)
        excs.append(_attempt(lambda: spec.delete(element)))
    _raise_worst(mj, excs)


def _seq_attach_then_delete_child(mj, ctx):
    parent, child = _base(mj), _child(mj)
    cb = child.body("cb")
    frame = parent.attach(child, frame="f1", prefix="c_")
    parent.compile()
    parent.delete(frame)
    parent.compile()
    excs = [_attempt(lambda: cb.name), _attempt(lambda: cb.pos), _attempt(child.compile),
            _attempt(lambda: child.delete(child.body("cb")))]
    child = None                # (the lambdas above ran already)
    gc.collect()
    parent.compile()
    _raise_worst(mj, excs)


def _seq_element_attach_then_gc_parent(mj, ctx):
    """Elements attached by reference are listed by both specs: the child's lists
    must stay usable when the parent is collected first."""
    parent, child = _base(mj), _child(mj)
    parent.body("b1").attach_frame(child.frame("cf"), "", "")
    parent.frame("f1").attach_body(child.body("cb"), "r/", "")
    parent.compile()
    del parent
    gc.collect()
    frame = child.frame("cf")
    excs = [_attempt(lambda: frame.parent.name), _attempt(lambda: frame.signature),
            _attempt(lambda: [g.parent.name for g in child.geoms]),
            _attempt(lambda: frame.parent.add_geom(size=[1, 0, 0])),
            _attempt(child.compile), _attempt(lambda: child.delete(child.geom("cg"))),
            _attempt(lambda: _base(mj).body("b1").attach_frame(frame, "again", "")),
            _attempt(lambda: _base(mj).frame("f1").attach_body(child.body("r/cb"), "x", ""))]
    _raise_worst(mj, excs)


def _seq_element_attach_twice(mj, ctx):
    """An element moved into one spec by attach_frame cannot move on to another."""
    first, second, child = _base(mj), _base(mj), _child(mj)
    frame = child.frame("cf")
    first.body("b1").attach_frame(frame, "a_", "")
    fingerprint = _fingerprint(second)
    excs = [_must_refuse(lambda: second.body("b1").attach_frame(frame, "b_", ""),
                         "a second attach of a moved frame"),
            _must_refuse(lambda: second.body("b1").attach_frame(child.frame("a_cf"), "c_",
                                                                 ""),
                         "an attach of a moved frame found in its first spec")]
    _check_unchanged(second, fingerprint, "ok")
    first.compile()
    _raise_worst(mj, excs)


def _seq_attach_then_gc_child(mj, ctx):
    parent = _base(mj)
    child = _child(mj)
    geom = child.geom("cg2")
    parent.attach(child, site="s1", prefix="c_")
    del child
    gc.collect()
    geom.size = [0.2, 0, 0]
    parent.compile()
    parent.delete(parent.body("c_cb"))
    excs = [_attempt(lambda: geom.size), _attempt(lambda: setattr(geom, "size", [1, 0, 0]))]
    parent.compile()
    _raise_worst(mj, excs)


def _seq_gc_parent_while_child_wrappers_live(mj, ctx):
    parent, child = _base(mj), _child(mj)
    body = child.body("cb")
    parent.attach(child, frame="f1", prefix="c_")
    geom = parent.geom("g1")
    del parent
    gc.collect()
    excs = [_attempt(lambda: body.name), _attempt(lambda: body.add_geom(size=[1, 0, 0])),
            _attempt(child.compile), _attempt(lambda: geom.size),
            _attempt(lambda: geom.parent), _attempt(lambda: body.parent)]
    spec = geom.parent
    del child
    gc.collect()
    excs.append(_attempt(lambda: body.subtree()))
    excs.append(_attempt(lambda: spec.name))
    _raise_worst(mj, excs)


def _seq_gc_spec_while_element_lives(mj, ctx):
    spec = _base(mj)
    geom, wrap, default = spec.geom("g1"), spec.tendon("t").path[1], spec.find_default("c")
    alt, size = spec.body("b1").alt, None
    del spec
    gc.collect()
    excs = [_attempt(lambda: geom.size), _attempt(lambda: wrap.target),
            _attempt(lambda: default.geom.size), _attempt(lambda: alt.quat),
            _attempt(lambda: geom.parent.name), _attempt(lambda: geom.compiler.degree)]
    del size
    _raise_worst(mj, excs)


def _seq_attach_same_child_twice(mj, ctx):
    parent, child = _base(mj), _child(mj)
    parent.attach(child, frame="f1", prefix="a_")
    exc = _attempt(lambda: parent.attach(child, frame="f2", prefix="b_"))
    _attempt(parent.compile)
    _raise_worst(mj, [exc])


def _seq_attach_spec_to_itself(mj, ctx):
    spec = _base(mj)
    exc = _must_refuse(lambda: spec.attach(spec, frame="f1", prefix="me_"),
                       "attaching a spec to itself")
    _check_unchanged(spec, _fingerprint(_base(mj)), "ok")
    _raise_worst(mj, [exc])


def _seq_attach_parent_into_child(mj, ctx):
    parent, child = _base(mj), _child(mj)
    parent.attach(child, frame="f1", prefix="c_")
    exc = _attempt(lambda: child.attach(parent, frame="cf", prefix="p_"))
    _attempt(parent.compile)
    _attempt(child.compile)
    _raise_worst(mj, [exc])


def _seq_attach_body_into_own_subtree(mj, ctx):
    spec = _base(mj)
    fingerprint = _fingerprint(spec)
    excs = [_must_refuse(lambda: spec.frame("f1").attach_body(spec.body("b1"), "x_", ""),
                         "attaching a body inside itself")]
    _check_unchanged(spec, fingerprint, "ok")
    excs.append(_attempt(lambda: spec.site("s2").attach_body(spec.body("b1"), "y_", "")))
    _check_unchanged(spec, fingerprint, "ok")
    _raise_worst(mj, excs)


def _seq_attach_body_of_same_spec(mj, ctx):
    spec = _base(mj)
    exc = _attempt(lambda: spec.frame("f1").attach_body(spec.body("b2"), "x_", ""))
    _attempt(spec.compile)
    _raise_worst(mj, [exc])


def _seq_attach_frame_into_itself(mj, ctx):
    spec = _base(mj)
    fingerprint = _fingerprint(spec)
    excs = [_attempt(lambda: spec.body("b1").attach_frame(spec.frame("f1"), "x_", "")),
            _attempt(lambda: spec.body("b2").attach_frame(spec.frame("f1"), "y_", ""))]
    if excs[0] is not None and excs[1] is not None:
        _check_unchanged(spec, fingerprint, "ok")
    _attempt(spec.compile)
    _raise_worst(mj, excs)


def _seq_attach_world_body(mj, ctx):
    parent, child = _base(mj), _child(mj)
    exc = _attempt(lambda: parent.frame("f1").attach_body(child.worldbody, "w_", ""))
    _attempt(parent.compile)
    _attempt(child.compile)
    _raise_worst(mj, [exc])


def _seq_attach_deleted_frame(mj, ctx):
    parent, child = _base(mj), _child(mj)
    frame = parent.frame("f2")
    parent.delete(frame)
    fingerprint = _fingerprint(parent)
    excs = [_must_refuse(lambda: parent.attach(child, frame=frame), "attach at a deleted frame"),
            _must_refuse(lambda: parent.attach(child, frame="f2"), "attach at a missing frame"),
            _must_refuse(lambda: frame.attach_body(child.body("cb"), "x", ""),
                         "attach_body to a deleted frame")]
    _check_unchanged(parent, fingerprint, "ok")
    child.compile()
    _raise_worst(mj, excs)


def _seq_attach_then_delete_in_child(mj, ctx):
    parent, child = _base(mj), _child(mj)
    parent.attach(child, frame="f1", prefix="c_")
    excs = [_attempt(lambda: child.delete(child.body("cb"))), _attempt(child.fuse_static),
            _attempt(child.discard_visual), _attempt(child.dedup_assets)]
    parent.compile()
    _raise_worst(mj, excs)


def _seq_copy_of_spec_with_attached_children(mj, ctx):
    parent, child, grandchild = _base(mj), _child(mj), _child(mj)
    child.attach(grandchild, frame="cf", prefix="g_")
    parent.attach(child, frame="f1", prefix="c_")
    copy = parent.copy()
    del parent, child, grandchild
    gc.collect()
    copy.compile()
    copy.to_xml()
    copy.delete(copy.body("c_cb"))
    copy.compile()


def _seq_copy_of_attached_child(mj, ctx):
    parent, child = _base(mj), _child(mj)
    parent.attach(child, frame="f1", prefix="c_")
    exc = _attempt(child.copy)
    parent.compile()
    _raise_worst(mj, [exc])


def _seq_nested_attach_then_gc(mj, ctx):
    parent, child, grandchild = _base(mj), _child(mj), _child(mj)
    gbody = grandchild.body("cb")
    child.attach(grandchild, frame="cf", prefix="g_")
    parent.attach(child, site="s1", prefix="c_")
    del child, grandchild
    gc.collect()
    parent.compile()
    excs = [_attempt(lambda: gbody.name)]
    parent.delete(parent.body("c_g_cb"))
    excs += [_attempt(lambda: gbody.name), _attempt(lambda: gbody.pos)]
    parent.compile()
    _raise_worst(mj, excs)


def _seq_set_frame_cycle(mj, ctx):
    spec = _base(mj)
    f1, f2 = spec.frame("f1"), spec.frame("f2")
    excs = [_attempt(lambda: f1.set_frame(f1)), _attempt(lambda: f1.set_frame(f2))]
    excs.append(_attempt(spec.compile))
    _attempt(spec.to_xml)
    _raise_worst(mj, excs)


def _seq_set_frame_of_other_body(mj, ctx):
    spec = _base(mj)
    fingerprint = _fingerprint(spec)
    excs = [_attempt(lambda: spec.geom("g3").set_frame(spec.frame("f1"))),
            _must_refuse(lambda: spec.geom("g1").set_frame(ctx.other.frame("cf")),
                         "set_frame(frame of another spec)"),
            _must_refuse(lambda: spec.geom("g1").set_frame(ctx.dead["frame"]),
                         "set_frame(deleted frame)")]
    _attempt(spec.compile)
    _check_unchanged(spec, fingerprint, _compiles(spec))
    _raise_worst(mj, excs)


def _seq_to_frame_odd(mj, ctx):
    spec = _base(mj)
    excs = [_must_refuse(lambda: spec.worldbody.to_frame(), "world.to_frame()")]
    body = spec.body("b2")
    excs.append(_attempt(body.to_frame))
    excs.append(_must_refuse(lambda: body.to_frame(), "to_frame() of a body gone"))
    excs.append(_attempt(lambda: body.add_geom()))
    _attempt(spec.compile)
    _raise_worst(mj, excs)


def _seq_wrap_target_deleted(mj, ctx):
    spec = _base(mj)
    wrap = spec.tendon("t").path[0]
    spec.delete(spec.site("s1"))
    excs = [_attempt(lambda: wrap.target), _attempt(lambda: wrap.sidesite),
            _attempt(lambda: spec.tendon("t").path[1].sidesite)]
    spec.delete(spec.frame("f2"))
    excs += [_attempt(lambda: spec.tendon("t").path[1].sidesite), _attempt(spec.compile),
             _attempt(spec.to_xml)]
    _raise_worst(mj, excs)


def _seq_make_flex_then_delete_body(mj, ctx):
    spec = _base(mj)
    body = spec.body("b2")
    excs = [_attempt(lambda: body.make_flex("fl", type="grid", count=[3, 3, 1],
                                            spacing=[0.1, 0.1, 0.1], dim=2))]
    excs.append(_attempt(spec.compile))
    spec.delete(body)
    excs.append(_attempt(spec.compile))
    _raise_worst(mj, excs)


def _seq_recompile_odd(mj, ctx):
    spec = _base(mj)
    model = spec.compile()
    data = mj.MjData(model)
    other_model = ctx.model
    excs = [_attempt(lambda: spec.recompile(other_model, data)),
            _must_refuse(lambda: spec.recompile(model, None), "recompile(d=None)"),
            _must_refuse(lambda: spec.recompile(data, model), "recompile(d, m)")]
    spec.delete(spec.body("b2"))
    m2, d2 = spec.recompile(model, data)
    excs.append(_attempt(lambda: spec.recompile(model, data)))
    spec.worldbody.add_geom(name="g_new", size=[0.1, 0, 0])
    excs.append(_attempt(lambda: spec.recompile(m2, d2)))
    excs.append(_attempt(lambda: spec.recompile(m2, d2)))
    spec.delete(spec.geoms[-1])
    spec.recompile(m2, d2)
    _raise_worst(mj, excs)


def _seq_bind_after_edits(mj, ctx):
    spec = _base(mj)
    model = spec.compile()
    data = mj.MjData(model)
    geom = spec.geom("g2")
    bound = data.bind(geom)
    spec.delete(geom)
    excs = [_attempt(lambda: data.bind(geom)), _attempt(lambda: bound.xpos)]
    model2 = spec.compile()
    excs += [_attempt(lambda: mj.MjData(model2).bind(geom)),
             _attempt(lambda: model.bind(spec.geom("g1")))]
    _raise_worst(mj, excs)


def _seq_defaults_odd(mj, ctx):
    spec = _base(mj)
    fingerprint = _fingerprint(spec)
    excs = [_must_refuse(lambda: spec.add_default("c"), "a second default 'c'"),
            _must_refuse(lambda: spec.add_default("main"), "a second default 'main'"),
            _must_refuse(lambda: spec.add_default("x", ctx.other.default),
                         "add_default(parent of another spec)"),
            _must_refuse(lambda: setattr(spec.geom("g1"), "classname", ctx.other.default),
                         "classname = default of another spec"),
            _attempt(lambda: spec.worldbody.add_geom(default=ctx.other.find_default("main")))]
    _attempt(spec.compile)
    if excs[-1] is not None:
        _check_unchanged(spec, fingerprint, "ok")
    _raise_worst(mj, excs)


def _seq_add_frame_of_other_spec(mj, ctx):
    spec, other = _base(mj), _child(mj)
    fingerprint = _fingerprint(spec)
    exc = _attempt(lambda: spec.body("b1").add_frame(other.frame("cf")))
    if exc is not None:
        _check_unchanged(spec, fingerprint, "ok")
    other = None
    gc.collect()
    _attempt(spec.compile)
    _attempt(spec.to_xml)
    _raise_worst(mj, [exc])


def _seq_freeing_during_attach(mj, ctx):
    parent, child = _base(mj), _child(mj)
    parent.copy_during_attach = True
    parent.attach(child, frame="f1", prefix="a_")
    parent.attach(child, frame="f2", prefix="b_")
    child.delete(child.body("cb"))
    child.compile()
    parent.fuse_static()
    parent.discard_visual()
    parent.dedup_assets()
    parent.compile()


def _seq_compile_flags_free(mj, ctx):
    spec = _base(mj)
    geom, body = spec.geom("g2"), spec.body("b1")
    spec.compiler.fusestatic = True
    spec.compiler.discardvisual = True
    excs = [_attempt(spec.compile), _attempt(lambda: geom.size), _attempt(lambda: body.pos)]
    excs.append(_attempt(spec.compile))
    _raise_worst(mj, excs)


def _seq_tendon_path_odd_index(mj, ctx):
    spec = _base(mj)
    path = spec.tendon("t").path
    excs = [_attempt(lambda: path[i]) for i in (3, -4, 2 ** 63, "0", 1.0, None)]
    spec.delete(spec.tendon("t"))
    excs += [_attempt(lambda: len(path)), _attempt(lambda: path[0]), _attempt(lambda: list(path))]
    _raise_worst(mj, excs)


def _seq_vectors_odd(mj, ctx):
    spec = _base(mj)
    numeric = spec.numeric("num")
    data = numeric.data
    excs = [_attempt(lambda: data[5]), _attempt(lambda: data.__setitem__(0, "x")),
            _attempt(lambda: data.__setitem__(2 ** 70, 1)),
            _attempt(lambda: data.__setitem__(slice(0, 5), [1] * 9))]
    spec.delete(numeric)
    excs += [_attempt(lambda: data[0]), _attempt(lambda: data.__setitem__(0, 1.0)),
             _attempt(lambda: np.asarray(data)), _attempt(lambda: len(data))]
    spec.compile()
    _raise_worst(mj, excs)


def _seq_views_held_then_delete(mj, ctx):
    spec = _base(mj)
    size = spec.geom("g3").size
    exc = _attempt(lambda: spec.delete(spec.body("b2")))
    size[0] = 0.5
    spec.compile()
    del size
    spec.delete(spec.body("b2"))
    spec.compile()
    if exc is None:
        return None
    _raise_worst(mj, [exc])


# ------------------------------------------------------------ the worker

GROUPS = {
    "methods": group_methods,
    "attributes": group_attributes,
    "adders": group_adders,
    "files": group_files,
    "bind": group_bind,
    "sequences": group_sequences,
}


def _emit(record):
    sys.stdout.write(_MARK + json.dumps(record) + "\n")
    sys.stdout.flush()


def _run_case(mj, case):
    try:
        exc = case()
    except _Skip as skip:
        return {"out": "skip", "detail": str(skip)}
    except _Defect as defect:
        return {"out": "defect", "detail": str(defect)}
    except Exception as exc:        # noqa: BLE001  a step the case did not expect to fail
        outcome, detail = _verdict(mj, exc)
        return {"out": "unexpected" if outcome == "raised" else outcome, "detail": detail}
    if exc is None:
        return {"out": "ok"}
    outcome, detail = _verdict(mj, exc)
    return {"out": outcome, "detail": detail}


def worker(group, start, lib, select=None):
    """Run the cases of `group` from index `start` on, printing a line before each
    (so that a crash names it) and one with its outcome.  `select`: {"only": keys}
    runs those alone, {"skip": patterns} all but the keys holding one."""
    import importlib
    mj = importlib.import_module(lib)
    warnings.simplefilter("ignore")
    ctx = _Ctx(mj)
    only = set((select or {}).get("only") or ()) or None
    skip = (select or {}).get("skip") or ()
    for index, (key, case) in enumerate(GROUPS[group](mj, ctx)):
        if index < start or (only is not None and key not in only) or \
                any(re.search(pattern, key) for pattern in skip):
            continue
        _emit({"start": index, "key": key})
        record = _run_case(mj, case)
        record.update(i=index, key=key)
        _emit(record)
    _emit({"done": True})


# ------------------------------------------------------------ the parent side

def sweep(group, lib="mjcffi", only=None, skip=(), limit=300.0):
    """The records of the cases of `group` (those of `only`; none holding a pattern
    of `skip`), run in workers: a worker that dies (by a signal) or runs past
    `limit` seconds leaves a 'crash' or 'hang' record for the case it was in, and
    a new worker goes on after it."""
    with tempfile.TemporaryDirectory(prefix="spec_fuzz_") as tmp:
        return _sweep(group, lib, only, skip, limit, tmp)


def _sweep(group, lib, only, skip, limit, tmp):
    records, start = [], 0
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1", PYTHONFAULTHANDLER="1",
               SPEC_FUZZ_TMP=tmp)
    select = json.dumps({"only": sorted(only or ()), "skip": list(skip)})
    while True:
        command = [sys.executable, "-m", "tests.test_spec_fuzz", group, str(start), lib,
                   select]
        proc = subprocess.Popen(command, cwd=ROOT, env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        try:
            out, err = proc.communicate(timeout=limit)
            hung = False
        except subprocess.TimeoutExpired:
            proc.kill()
            out, err = proc.communicate()
            hung = True
        started, done = None, False
        for line in out.splitlines():
            if not line.startswith(_MARK):
                continue
            record = json.loads(line[len(_MARK):])
            if "start" in record:
                started = record
            elif record.get("done"):
                done = True
            else:
                records.append(record)
                started = None
        if done and proc.returncode == 0:
            return records
        if started is None:
            raise RuntimeError(f"the {group} worker failed outside a case "
                               f"(exit {proc.returncode}):\n{err[-3000:]}")
        code = proc.returncode
        how = "hang" if hung else (f"crash: {signal.Signals(-code).name}" if code < 0
                                   else f"exit {code}")
        records.append({"i": started["start"], "key": started["key"],
                        "out": "hang" if hung else "crash",
                        "detail": f"{how}; stderr: {err[-1500:]}"})
        start = started["start"] + 1


_FINE = {"ok", "raised", "skip"}


def findings(records):
    return [r for r in records if r["out"] not in _FINE]


# Known problems outside the files whose fixes came with this sweep (the
# structs layer: mjcffi/structs/_element_*.py, _views.py): a key pattern (a
# regular expression), one key that shows it, and what goes wrong.  The sweep
# leaves the keys matching a pattern out (a crash costs a new worker), and
# test_known_problems_still_show runs each key given, so that the table cannot
# go stale.
KNOWN_OPEN: dict = {}      # pattern -> (a case key, why): none open today


def _known(key):
    return next((pattern for pattern in KNOWN_OPEN if re.search(pattern, key)), None)


@pytest.fixture(scope="module")
def swept():
    """The records of every group, the groups run at once."""
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max_workers=max(2, min(len(GROUPS), os.cpu_count() or 2))) as pool:
        futures = {group: pool.submit(sweep, group, skip=list(KNOWN_OPEN))
                   for group in GROUPS}
        return {group: future.result() for group, future in futures.items()}


def _report(found):
    return "\n".join(f"{r['out']}: {r['key']}  ({r.get('detail', '')[:300]})"
                     for r in found[:40])


@pytest.mark.parametrize("group", sorted(GROUPS))
def test_no_crash_and_only_sensible_exceptions(swept, group):
    """Every case of the group returns or raises a sensible exception naming the
    problem, leaves the spec as it was when refused, and stores what it accepted."""
    records = swept[group]
    assert len(records) > 100, f"the {group} sweep made only {len(records)} cases"
    found = findings(records)
    assert not found, f"{len(found)} finding(s) in {group}:\n{_report(found)}"


def test_known_problems_still_show():
    """Each KNOWN_OPEN problem is still there (else its entry goes)."""
    by_group = {}
    for pattern, (key, _) in KNOWN_OPEN.items():
        assert re.search(pattern, key), (pattern, key)
        group = {"adder": "adders", "attr": "attributes", "method": "methods",
                 "seq": "sequences"}[key.split(":")[0]]
        by_group.setdefault(group, set()).add(key)
    for group, keys in by_group.items():
        records = {r["key"]: r for r in sweep(group, only=keys)}
        for key in keys:
            assert key in records, f"{key} is no case of the {group} sweep"
            assert records[key]["out"] not in _FINE, f"{key} is fixed: drop it from KNOWN_OPEN"


def test_the_sweep_covers_every_public_method_and_class():
    """The methods group takes every public method of MjSpec and of every element
    class (dir() of the classes): a new method is swept without editing this file."""
    import mjcffi
    from mjcffi.spec import elements
    keys = {key for key, _ in group_methods(mjcffi, _Ctx(mjcffi))}
    swept_methods = {key.split("(")[0].split(":", 1)[1] for key in keys}
    classes = _element_classes()
    for kind, cls in classes.items():
        if kind in ("body2", "main_default"):
            continue
        for method in _public(cls)[0]:
            if method.startswith(("add_", "wrap_")) or not _parameters(getattr(cls, method)):
                continue
            assert f"{kind}.{method}" in swept_methods, f"{kind}.{method} is not swept"
    missing = set(elements.CLASSES) - set(classes.values())
    assert not missing, f"no element of {sorted(c.__name__ for c in missing)} is swept"


def test_the_sweep_sees_a_crash_and_a_defect():
    """The harness itself: a worker killed by a signal is a 'crash' of the case it
    was in, and the sweep goes on after it; a defect is reported as such."""
    records = sweep("selftest")
    outcomes = {r["key"]: r["out"] for r in records}
    assert outcomes == {"self:ok": "ok", "self:crash": "crash", "self:after": "ok",
                        "self:defect": "defect", "self:leak": "bad-exception"}


# ------------------------------------------------ the fixes, one test each

def _isolated(code):
    """stdout of `code` run in a new interpreter (after `import mjcffi as mj` and the
    base models of this module), asserting it exited normally: each of these was a
    crash before its fix."""
    preamble = ("import gc\nimport numpy as np\nimport mjcffi as mj\n"
                "from tests.test_spec_fuzz import _base, _child\n")
    done = subprocess.run([sys.executable, "-c", preamble + code], cwd=ROOT,
                          capture_output=True, text=True, timeout=120,
                          env=dict(os.environ, PYTHONDONTWRITEBYTECODE="1"))
    assert done.returncode == 0, f"exit {done.returncode}:\n{done.stderr[-3000:]}"
    return done.stdout


def test_deleting_a_default_in_use_leaves_a_spec_that_saves():
    """MuJoCo leaves the elements of a deleted class naming it, and to_xml crashed on
    them: they fall back to the main class, with their values kept."""
    out = _isolated("""
spec = _base(mj)
before = spec.compile()
spec.delete(spec.find_default("c"))
print(spec.geom("g3").classname.name)
xml = spec.to_xml()
again = mj.MjSpec.from_string(xml, assets=spec.assets).compile()
print(np.array_equal(before.geom_size, again.geom_size),
      np.array_equal(before.geom_rgba, again.geom_rgba))
""")
    assert out.split() == ["main", "True", "True"]


def test_a_frame_cannot_be_placed_in_itself_or_in_a_frame_inside_it():
    """MuJoCo took such a loop of frames and recursed without end when compiling."""
    out = _isolated("""
spec = _base(mj)
f1, f2 = spec.frame("f1"), spec.frame("f2")
for frame in (f1, f2):
    try:
        f1.set_frame(frame)
    except ValueError as e:
        print("refused:", "in itself" in str(e))
spec.compile()
spec.geom("g1").set_frame(f2)          # an element of the same body: taken
print(spec.geom("g1").frame.name)
""")
    assert out.split() == ["refused:", "True", "refused:", "True", "f2"]


def test_a_default_class_template_or_an_empty_plugin_slot_is_refused_as_an_element():
    """spec.default.geom (a template, in no spec) and body.plugin (no plugin) are no
    elements: what needs one raised nothing and crashed in MuJoCo."""
    out = _isolated("""
spec = _base(mj)
model = spec.compile()
data = mj.MjData(model)
template, slot = spec.find_default("c").geom, spec.body("b1").plugin
calls = [lambda: template.classname, lambda: template.signature, lambda: template.compiler,
         lambda: setattr(template, "classname", spec.default),
         lambda: spec.find_default("c").mesh.make_sphere(9),
         lambda: spec.find_default("c").tendon.default(),
         lambda: spec.find_default("c").site.attach_body(_child(mj).body("cb"), "x", ""),
         lambda: spec.delete(template), lambda: spec.delete(slot),
         lambda: model.bind(template), lambda: data.bind(slot), lambda: model.bind([slot])]
for call in calls:
    try:
        call()
        print("taken")
    except (TypeError, ValueError) as e:
        print(type(e).__name__)
spec.compile()
""")
    assert "taken" not in out.split() and len(out.split()) == 12


def test_a_refused_builtin_mesh_leaves_the_mesh_as_it_was():
    """make_grid with counts MuJoCo refuses used to empty the mesh first; complex and
    bool counts were taken (as their real part, or as 1)."""
    import mjcffi
    spec = _base(mjcffi)
    mesh = spec.mesh("tet")
    before = np.array(mesh.uservert)
    with pytest.raises(ValueError, match="grid"):
        mesh.make_grid([1, 1, 1], [0.1, 0.1, 0.1])
    for count in (np.full(3, 2 + 1j), np.ones(3, dtype=bool)):
        with pytest.raises(TypeError, match="real numbers"):
            mesh.make_grid(count, [0.1, 0.1, 0.1])
    assert np.array_equal(np.array(mesh.uservert), before)
    spec.compile()


def test_a_refused_actuator_shortcut_leaves_the_actuator_as_it_was():
    """mjs_setToAdhesion set the gain before refusing it as negative."""
    import mjcffi
    spec = _base(mjcffi)
    actuator = spec.actuator("a")
    gain, limited = np.array(actuator.gainprm), actuator.ctrllimited
    for shortcut in (lambda: actuator.set_to_adhesion(-1), lambda: actuator.set_to_damper(-1)):
        with pytest.raises(ValueError, match="negative"):
            shortcut()
        assert np.array_equal(actuator.gainprm, gain) and actuator.ctrllimited == limited
    spec.compile()


def test_what_the_compiler_would_crash_on_is_refused_before_it():
    """A plugin element naming no plugin and a mesh maxhullvert of 0 to 3 crashed
    mj_compile (the MJCF parser refuses them; a spec edited in code may hold them)."""
    out = _isolated("""
spec = _base(mj)
spec.add_plugin(name="p")
for call in (spec.compile, spec.to_xml):
    try:
        call()
    except ValueError as e:
        print("names no plugin" in str(e))
spec.delete(spec.plugin("p"))
spec.mesh("tet").maxhullvert = 2
try:
    spec.compile()
except ValueError as e:
    print("larger than 3" in str(e))
spec.mesh("tet").maxhullvert = 4
spec.compile()
""")
    assert out.split() == ["True", "True", "True"]


def test_an_element_attached_by_reference_cannot_be_attached_again():
    """Its first spec still lists it: attaching it again moved part of it (and left
    the receiving spec changed), or read the spec it moved into after that was
    freed."""
    out = _isolated("""
child = _child(mj)
first = _base(mj)
first.body("b1").attach_frame(child.frame("cf"), "", "")
del first
gc.collect()
second = _base(mj)
before = len(second.frames)
for frame in (child.frame("cf"),):
    try:
        second.body("b1").attach_frame(frame, "x", "")
    except ValueError as e:
        print("attached before" in str(e))
print(len(second.frames) == before)
second.compile()
""")
    assert out.split() == ["True", "True"]


def test_a_child_spec_outlives_the_spec_its_elements_were_attached_to():
    """attach_frame / attach_body move elements that both specs then list: the child
    kept using them after the parent was collected, and read freed memory.  The
    two now keep each other alive, and are collected together."""
    out = _isolated("""
import weakref
child = _child(mj)
parent = _base(mj)
parent.body("b1").attach_frame(child.frame("cf"), "", "")
parent.frame("f1").attach_body(child.body("cb"), "r/", "")
parent.compile()
parent_root = weakref.ref(parent._root)
del parent
gc.collect()
print(parent_root() is not None)
frame = child.frame("cf")
print(frame.parent.name, [g.parent.name for g in child.geoms], frame.signature != 0)
child_root = weakref.ref(child._root)
del child, frame
gc.collect()
print(parent_root() is None and child_root() is None)
""")
    assert out.split() == ["True", "b1", "['b1',", "'r/cb']", "True", "True"]


def group_selftest(mj, ctx):
    def crash():
        os.kill(os.getpid(), signal.SIGSEGV)

    def defect():
        raise _Defect("a refused call changed the spec")

    def leak():
        return SystemError("an error of the binding's inside")
    yield "self:ok", lambda: None
    yield "self:crash", crash
    yield "self:after", lambda: None
    yield "self:defect", defect
    yield "self:leak", leak


GROUPS_ALL = dict(GROUPS, selftest=group_selftest)


def _compare(group):
    """Where the official binding's outcome differs from mjcffi's (for the eye)."""
    ours = {r["key"]: r for r in sweep(group)}
    theirs = {r["key"]: r for r in sweep(group, lib="mujoco")}
    for key in sorted(ours):
        a, b = ours[key], theirs.get(key)
        if b is None:
            continue
        if (a["out"] == "ok") != (b["out"] == "ok") or b["out"] in ("crash", "hang"):
            print(f"{key}\n   mjcffi:  {a['out']} {a.get('detail', '')[:150]}\n"
                  f"   mujoco:  {b['out']} {b.get('detail', '')[:150]}")


if __name__ == "__main__":
    if sys.argv[1] == "--compare":
        _compare(sys.argv[2])
    elif sys.argv[1] == "--report":
        for group in sys.argv[2:] or GROUPS:
            for record in findings(sweep(group)):
                print(f"{record['out']}: {record['key']}  ({record.get('detail', '')[:400]})")
    else:
        GROUPS.update(GROUPS_ALL)
        worker(sys.argv[1], int(sys.argv[2]), sys.argv[3],
               json.loads(sys.argv[4]) if len(sys.argv) > 4 else None)
