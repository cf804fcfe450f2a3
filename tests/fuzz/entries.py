"""The public entry points other than MuJoCo's functions, as fuzz targets.

- `new:<Class>`: struct constructors (MjvScene(m, maxgeom), MjData(m), ...);
- `set:<Class>.<field>`: struct field setters, each followed by reading the
  struct back (every field), so that a count set out of range (scn.nflex =
  10**9) is caught when the arrays it sizes are read;
- `named:<model|data>.<category>`: named access, m.geom(key), d.joint(key);
- `load:<loader>`: MjModel.from_xml_string / from_xml_path / from_binary_path,
  with garbage text, truncated and byte-flipped XML and MJB;
- `pickle:<MjModel|MjData>`: corrupted pickles (header counts, pointers, flips);
- `vfs:<op>`: MjVfs;
- `rollout:rollout`, `rollout:Rollout`, `batch:Batch`, `batch:<method>`,
  `minimize:least_squares`, `sim:<...>`;
- `cb:<setter>`: set_mjcb_* and set_mju_user_*, each followed by a step.

A target's params are fuzzed like a function's (values.py by kind); `case:`
targets are hand-written calls with their own labels.
"""

import copy
import inspect
import keyword
import pickle

import numpy as np

import mjcffi
from mjcffi._generated.structinfo import STRUCTS

from . import guard
from .env import XML, class_name
from .target import Case, Param, Target
from .values import NotApplicable


class FuzzError(Exception):
    """What the fuzzer's own callbacks raise: it must come back to the caller."""


class CallTarget(Target):
    """A target from a list of (Param, valid maker) and a call function."""

    def __init__(self, name, params, call, allowed=(), group="entry", labels=None):
        super().__init__(name)
        self.params = [p for p, _ in params]
        self._valid = {p.name: make for p, make in params}
        self._call = call
        self.allowed = tuple(allowed) + (FuzzError,)
        self.group = group
        self._labels = labels or {}

    def valid(self, env):
        return {p.name: self._valid[p.name](env) for p in self.params}

    def call(self, env, kwargs):
        return self._call(env, **kwargs)

    def labels(self, param):
        from .functions import _LONG_RUNNING, WORK
        base = super().labels(param)
        if param.name in WORK:
            base = [label for label in base if label not in _LONG_RUNNING]
        return base + [label for label in self._labels.get(param.name, ()) if label not in base]

    def make(self, param_name, label, env):
        custom = self._labels.get(param_name, {})
        if label in custom:
            kwargs = self.valid(env)
            kwargs[param_name] = custom[label](env)

            def thunk():
                return self._call(env, **kwargs)
            thunk.keep = {}
            from .target import _describe
            return thunk, _describe(self, kwargs, param_name)
        return super().make(param_name, label, env)


def _read_all(obj, cname):
    """Read every field of a struct wrapper (and its repr): what a user may do next."""
    out = []
    for field in STRUCTS.get(cname, ()):
        name = field.name.split(".")[0]
        try:
            value = getattr(obj, name)
        except (AttributeError, TypeError, ValueError, IndexError, KeyError, NotImplementedError):
            continue
        if isinstance(value, np.ndarray):
            out.append(value.sum() if value.dtype.kind in "biuf" else value.size)
        elif hasattr(value, "__len__") and hasattr(value, "__getitem__") \
                and not isinstance(value, (str, bytes)):
            try:
                n = len(value)
                if n:
                    repr(value[n - 1])
            except (TypeError, ValueError, IndexError, KeyError):
                pass
    repr(obj)
    return out


# ------------------------------------------------------------------ structs

def _instance(env, cname):
    """(wrapper, description) of a struct to set fields on, or None."""
    if cname == "mjWarningStat":
        return env.d.warning[0]
    if cname == "mjContact":
        return env.d.contact[0]
    if cname == "mjvGeom":
        return env.scene.geoms[0]
    if cname in ("mjsCompiler",):
        return None
    return env.struct(cname)


def _field_kind(field):
    if field.kind == "scalar":
        if field.elem in ("mjtNum", "double", "float"):
            return "float"
        return "int"
    if field.elem == "char" and field.kind == "array":
        return "text"
    if field.kind in ("array", "pointer") and field.elem in (
            "mjtNum", "double", "float", "int", "mjtByte", "mjtSize", "mjtBool", "unsigned char"):
        return "array"
    if field.kind == "struct":
        return "struct"
    return None


# Fields that a user sets to what MuJoCo then follows unchecked, outside the promise
# ("users who corrupt struct fields by hand"): pointers and addresses are kept out.
def _settable_fields(cname):
    for field in STRUCTS.get(cname, ()):
        if "." in field.name or field.kind == "function":
            continue
        kind = _field_kind(field)
        if kind is None:
            continue
        if field.kind == "pointer" and cname not in ("mjModel", "mjData", "mjvScene"):
            continue
        yield field, kind


_SET_STRUCTS = ("mjvScene", "mjvOption", "mjvCamera", "mjvPerturb", "mjvGLCamera", "mjvGeom",
                "mjvFigure", "mjvLight", "mjLROpt", "mjContact", "mjOption", "mjVisual",
                "mjuiState", "mjrRect", "mjStatistic", "mjWarningStat", "mjsBody", "mjsGeom",
                "mjsJoint", "mjsActuator", "mjsSensor", "mjsMesh", "mjsFlex", "mjSpec",
                "mjData", "mjModel", "mjLogConfig")


def _setter_target(cname, field, kind):
    name = field.name + ("_" if keyword.iskeyword(field.name) else "")

    def valid(env):
        obj = _instance(env, cname)
        value = getattr(obj, name)
        if isinstance(value, np.ndarray):
            return guard.guarded(value)
        return value

    def call(env, value):
        obj = _instance(env, cname)
        setattr(obj, name, value)
        _read_all(obj, cname)

    param = Param("value", kind, elem=field.elem, const=True)
    # AttributeError is Python's (and the official bindings') error for a read-only field
    return CallTarget(f"set:{class_name(cname)}.{name}", [(param, valid)], call,
                      allowed=(AttributeError,))


def _writable(cname, name):
    """False for a read-only property (a model's counts): setting it only raises
    AttributeError, Python's error for a read-only attribute."""
    cls = getattr(mjcffi, class_name(cname), None)
    for klass in getattr(cls, "__mro__", ()):
        if name in klass.__dict__:
            attr = klass.__dict__[name]
            return not (isinstance(attr, property) and attr.fset is None)
    return True


def setter_targets():
    out = []
    for cname in _SET_STRUCTS:
        for field, kind in _settable_fields(cname):
            name = field.name + ("_" if keyword.iskeyword(field.name) else "")
            if _writable(cname, name):
                out.append(_setter_target(cname, field, kind))
    return out


def _ctor_targets():
    out = []

    def model(env):
        return env.m

    out.append(CallTarget("new:MjvScene", [
        (Param("model", "struct", elem="mjModel"), model),
        (Param("maxgeom", "int"), lambda env: 10)],
        lambda env, model, maxgeom: _read_all(mjcffi.MjvScene(model, maxgeom), "mjvScene")))
    out.append(CallTarget("new:MjData", [(Param("model", "struct", elem="mjModel"), model)],
                          lambda env, model: _read_all(mjcffi.MjData(model), "mjData")))
    out.append(CallTarget("new:MjrContext", [
        (Param("model", "struct", elem="mjModel"), model),
        (Param("fontscale", "int"), lambda env: 100)],
        lambda env, model, fontscale: mjcffi.MjrContext(model, fontscale),
        allowed=(NotImplementedError,)))
    out.append(CallTarget("new:MjrRect", [
        (Param("left", "int"), lambda env: 0), (Param("bottom", "int"), lambda env: 0),
        (Param("width", "int"), lambda env: 10), (Param("height", "int"), lambda env: 10)],
        lambda env, **kw: _read_all(mjcffi.MjrRect(**kw), "mjrRect")))
    simple = {}
    for cname in ("mjvOption", "mjvCamera", "mjvPerturb", "mjvGLCamera", "mjvGeom", "mjvFigure",
                  "mjvLight", "mjLROpt", "mjContact", "mjOption", "mjVisual", "mjuiState", "mjUI",
                  "mjpResourceProvider", "mjStatistic", "mjWarningStat", "mjSolverStat",
                  "mjTimerStat", "mjLogConfig", "mjSDF", "mjResource", "mjCache", "mjsElement",
                  "mjsBody", "mjsOrientation", "mjVFS"):
        def construct(env, cname=cname, args=()):
            return _read_all(getattr(mjcffi, class_name(cname))(*args), cname)
        simple[f"{class_name(cname)}()"] = construct
        simple[f"{class_name(cname)}(None)"] = lambda env, f=construct: f(env, args=(None,))
        simple[f"{class_name(cname)}(model)"] = lambda env, f=construct: f(env, args=(env.m,))
    out.append(Case("new:plain", simple))
    return out


# ---------------------------------------------------------------- named

def _named_targets():
    from mjcffi._support import named
    out = []
    for category in named.CATEGORIES:
        for owner in ("model", "data"):
            method = category
            cls = mjcffi.MjModel if owner == "model" else mjcffi.MjData
            if not inspect.isfunction(getattr(cls, method, None)):
                continue                    # no such accessor (data.mesh), or a field

            def valid(env):
                return 0

            def call(env, key, owner=owner, method=method):
                obj = env.m if owner == "model" else env.d
                accessor = getattr(obj, method)(key)
                for attr in dir(accessor):
                    if not attr.startswith("__"):
                        getattr(accessor, attr, None)
                repr(accessor)

            param = Param("key", "int")
            labels = {"name": lambda env: "box", "unknown name": lambda env: "nope",
                      "bytes name": lambda env: b"box", "empty name": lambda env: "",
                      "NUL name": lambda env: "b\0x", "long name": lambda env: "x" * 100000,
                      "nonascii name": lambda env: "\u00e9\ud800"}
            out.append(CallTarget(f"named:{owner}.{method}", [(param, valid)], call,
                                  labels={"key": labels}))
    return out


# ---------------------------------------------------------------- loaders

_ASSETS = {
    "asset value int": lambda env: {"a.obj": 5},
    "asset key int": lambda env: {5: b""},
    "asset value str": lambda env: {"a.obj": "text"},
    "asset value None": lambda env: {"a.obj": None},
    "asset key NUL": lambda env: {"a\0.obj": b""},
    "assets list": lambda env: [("a.obj", b"")],
    "assets str": lambda env: "a.obj",
}

_XML_BAD = {
    "garbage": lambda env: "\x00\x01<<<>>>&&&;;",
    "not mujoco": lambda env: "<html><body/></html>",
    "deep nesting": lambda env: "<mujoco><worldbody>" + "<body>" * 2000 + "</body>" * 2000
                                + "</worldbody></mujoco>",
    "huge count": lambda env: "<mujoco><size njmax='2147483647' nconmax='2147483647'/>"
                              "<worldbody/></mujoco>",
    "negative size": lambda env: "<mujoco><size memory='-1'/><worldbody/></mujoco>",
    "include missing": lambda env: "<mujoco><include file='missing.xml'/></mujoco>",
    "include self": lambda env: "<mujoco><include file='model.xml'/></mujoco>",
    "mesh missing file": lambda env: "<mujoco><asset><mesh file='x.stl'/></asset></mujoco>",
    "huge hfield": lambda env: "<mujoco><asset><hfield name='h' nrow='100000' ncol='100000' "
                               "size='1 1 1 1'/></asset></mujoco>",
    "huge texture": lambda env: "<mujoco><asset><texture name='t' type='2d' builtin='flat' "
                                "width='2147483647' height='2147483647'/></asset></mujoco>",
    "flexcomp huge": lambda env: "<mujoco><worldbody><flexcomp type='grid' count='100000 "
                                 "100000 1' spacing='1 1 1' dim='2'/></worldbody></mujoco>",
    "bad numbers": lambda env: "<mujoco><option timestep='nan' gravity='inf 1e999 -'/>"
                               "<worldbody/></mujoco>",
    "keyframe too long": lambda env: "<mujoco><worldbody><body><freejoint/><geom size='1'/>"
                                     "</body></worldbody><keyframe><key qpos='" + "1 " * 1000
                                     + "'/></keyframe></mujoco>",
    "plugin unknown": lambda env: "<mujoco><extension><plugin plugin='no.such'/></extension>"
                                  "</mujoco>",
}


def _xml_cut(label, env):
    """XML truncated after N characters."""
    n = int(label.split("@")[1])
    return XML[:n]


def _flip(data, offset, value):
    raw = bytearray(data)
    if not raw:
        raise NotApplicable("empty")
    raw[offset % len(raw)] ^= value or 1
    return bytes(raw)


class Parametric(Case):
    """A Case whose labels carry a number (`cut@123`, `flip@40^8`): a fixed set of
    them is enumerated, and random ones are drawn for long runs (random_key)."""

    def __init__(self, name, families, fixed, allowed=()):
        super().__init__(name, {}, allowed)
        self.families = families          # prefix -> function(label, env)
        self.fixed = fixed                # the labels enumerated in every run

    def keys(self):
        return [f"{self.name}|-|{label}" for label in self.fixed]

    def random_key(self, rng):
        prefix = rng.choice(sorted(self.families))
        return f"{self.name}|-|{prefix}@{rng.randrange(1 << 20)}^{rng.randrange(1, 256)}"

    def make(self, param_name, label, env):
        prefix = label.split("@")[0]
        function = self.families[prefix]

        def thunk():
            return function(label, env)
        thunk.keep = {}
        return thunk, f"{self.name}: {label} ({(function.__doc__ or '').strip()})"


def _offset(label):
    rest = label.split("@")[1]
    offset, _, value = rest.partition("^")
    return int(offset), int(value or 1)


def _simulate(m):
    """What a user does with a model that loaded: make its data, then step it (a
    corrupted model that loads must not crash or hang here either)."""
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    mjcffi.mj_step(m, d, 3)
    mjcffi.mj_resetDataKeyframe(m, d, 0) if m.nkey else mjcffi.mj_resetData(m, d)
    mjcffi.mj_step(m, d)


def _loader_targets():
    out = []

    def from_string(env, xml, assets, vfs):
        m = mjcffi.MjModel.from_xml_string(xml, assets, vfs)
        mjcffi.MjData(m)

    def from_path(env, filename, assets, vfs):
        m = mjcffi.MjModel.from_xml_path(filename, assets, vfs)
        mjcffi.MjData(m)

    def from_binary(env, filename, assets, vfs):
        m = mjcffi.MjModel.from_binary_path(filename, assets, vfs)
        mjcffi.MjData(m)

    def no_vfs(env):
        return None

    def no_assets(env):
        return None

    vfs_param = (Param("vfs", "struct", elem="mjVFS", nullable=True), no_vfs)
    assets_param = (Param("assets", "object"), no_assets)
    out.append(CallTarget("load:from_xml_string", [
        (Param("xml", "text"), lambda env: XML), assets_param, vfs_param], from_string,
        labels={"xml": _XML_BAD, "assets": _ASSETS}))
    out.append(CallTarget("load:from_xml_path", [
        (Param("filename", "text"), lambda env: env.path("model.xml")), assets_param,
        vfs_param], from_path, labels={"assets": _ASSETS}))
    out.append(CallTarget("load:from_binary_path", [
        (Param("filename", "text"), lambda env: env.path("model.mjb")), assets_param,
        vfs_param], from_binary, labels={"assets": _ASSETS}))

    def xml_flip(label, env):
        """valid XML with one byte changed"""
        offset, value = _offset(label)
        text = _flip(XML.encode(), offset, value).decode("latin-1")
        m = mjcffi.MjModel.from_xml_string(text)
        mjcffi.MjData(m)

    def xml_cut(label, env):
        """valid XML truncated"""
        offset, _ = _offset(label)
        m = mjcffi.MjModel.from_xml_string(XML[:offset % len(XML)])
        mjcffi.MjData(m)

    def mjb_flip(label, env):
        """the model's MJB bytes with one byte changed, from a file and from assets"""
        offset, value = _offset(label)
        raw = _flip(env.mjb, offset, value)
        _simulate(mjcffi.MjModel.from_binary_path("m.mjb", {"m.mjb": raw}))

    def mjb_cut(label, env):
        """the model's MJB bytes truncated"""
        offset, _ = _offset(label)
        raw = env.mjb[:offset % len(env.mjb)]
        m = mjcffi.MjModel.from_binary_path("m.mjb", {"m.mjb": raw})
        mjcffi.MjData(m)

    def mjb_header(label, env):
        """an MJB header int (the first 256 bytes, 4-byte aligned) set to a huge value"""
        offset, value = _offset(label)
        raw = bytearray(env.mjb)
        position = (offset * 4) % 256
        raw[position:position + 4] = (0x7FFFFFFF if value & 1 else -1).to_bytes(
            4, "little", signed=True)
        m = mjcffi.MjModel.from_binary_path("m.mjb", {"m.mjb": bytes(raw)})
        mjcffi.MjData(m)

    families = {"xml flip": xml_flip, "xml cut": xml_cut, "mjb flip": mjb_flip,
                "mjb cut": mjb_cut, "mjb header": mjb_header}
    fixed = ([f"xml cut@{n}" for n in range(0, len(XML), 97)]
             + [f"xml flip@{n}^{v}" for n in range(0, len(XML), 131) for v in (1, 0x20)]
             + [f"mjb cut@{n}" for n in range(0, 20000, 331)]
             + [f"mjb flip@{n}^{v}" for n in range(0, 8192, 61) for v in (0x80, 0xff)]
             + [f"mjb header@{n}^{v}" for n in range(64) for v in (1, 2)])
    out.append(Parametric("load:corrupt", families, fixed))
    return out


# ------------------------------------------------------------------ pickle

# The parts of an MjData's pickle, in its __reduce__ order (mjcffi/data.py): a part
# that a later format adds goes at the end.
PARTS = ("model", "header", "buffer", "arena", "layout")


def _reduced(obj):
    """(function, [arguments]) of obj.__reduce__(), the arguments as a list to change."""
    func, args = obj.__reduce__()[:2]
    return func, list(args)


def _pickle_targets():
    from mjcffi import ffi

    def use_data(m, d):
        _read_all(d, "mjData")
        mjcffi.mj_forward(m, d)
        mjcffi.mj_step(m, d)

    def data_pickle(env, **changes):
        """MjData pickled with some of its parts (PARTS) replaced"""
        func, args = _reduced(env.d)
        for name, value in changes.items():
            args[PARTS.index(name)] = value

        class Reduced:
            def __reduce__(self):
                return func, tuple(args)
        return pickle.dumps(Reduced())

    def header_field(field, value):
        def make(env):
            """MjData pickle with a header field changed"""
            raw = bytearray(_reduced(env.d)[1][1])
            off = ffi.offsetof("mjData", field)
            size = ffi.sizeof(dict(ffi.typeof("mjData").fields)[field].type)
            if off + size > len(raw):
                raise NotApplicable(f"{field} is not in the pickled header")
            raw[off:off + size] = (value & ((1 << (8 * size)) - 1)).to_bytes(size, "little")
            d2 = pickle.loads(data_pickle(env, header=bytes(raw)))
            use_data(env.m, d2)
        return make

    def pointer_flip(field, xor):
        def make(env):
            """MjData pickle with a pointer in its header changed"""
            raw = bytearray(_reduced(env.d)[1][1])
            off = ffi.offsetof("mjData", field)
            if off + 8 > len(raw):
                raise NotApplicable(f"{field} is not in the pickled header")
            value = int.from_bytes(raw[off:off + 8], "little") ^ xor
            raw[off:off + 8] = value.to_bytes(8, "little")
            d2 = pickle.loads(data_pickle(env, header=bytes(raw)))
            use_data(env.m, d2)
        return make

    fixed = {
        "ncon=10**7": header_field("ncon", 10**7),
        "ncon=-1": header_field("ncon", -1),
        "nefc=10**9": header_field("nefc", 10**9),
        "nefc=-5": header_field("nefc", -5),
        "nbuffer=1": header_field("nbuffer", 1),
        "narena=2**40": header_field("narena", 2**40),
        "parena=2**40": header_field("parena", 2**40),
        "pstack=2**40": header_field("pstack", 2**40),
        "pbase=2**40": header_field("pbase", 2**40),
        "nplugin=5": header_field("nplugin", 5),
        "nisland=10**6": header_field("nisland", 10**6),
        "nJ=10**8": header_field("nJ", 10**8),
        "ne=10**6": header_field("ne", 10**6),
        "nl=10**6": header_field("nl", 10**6),
        "nA=10**8": header_field("nA", 10**8),
        "qvel pointer ^1": pointer_flip("qvel", 1),
        "qvel pointer ^0x100000": pointer_flip("qvel", 0x100000),
        "buffer pointer ^0x1000": pointer_flip("buffer", 0x1000),
        "arena pointer ^0x1000": pointer_flip("arena", 0x1000),
        "contact pointer ^8": pointer_flip("contact", 8),
        "efc_J pointer ^0x40": pointer_flip("efc_J", 0x40),
    }

    def short_header(env):
        """MjData pickle with a header one byte short"""
        header = _reduced(env.d)[1][1]
        use_data(env.m, pickle.loads(data_pickle(env, header=header[:-1])))

    def other_model(env):
        """MjData pickle whose model is another model"""
        use_data(env.m, pickle.loads(data_pickle(env, model=env.m_other)))

    def arena_long(env):
        """MjData pickle with an arena far longer than the data's"""
        arena = _reduced(env.d)[1][3]
        use_data(env.m, pickle.loads(data_pickle(env, arena=arena + b"\0" * (1 << 22))))

    def buffer_none(env):
        """MjData pickle with an empty buffer"""
        use_data(env.m, pickle.loads(data_pickle(env, buffer=b"")))

    fixed.update({"header short": short_header, "other model": other_model,
                  "arena long": arena_long, "buffer empty": buffer_none})
    cases = [Case("pickle:MjData", fixed)]

    def part_flip(part):
        def make(label, env):
            """MjData pickle with one byte of a part changed"""
            offset, value = _offset(label)
            args = _reduced(env.d)[1]
            index = PARTS.index(part)
            if index >= len(args) or not isinstance(args[index], bytes):
                raise NotApplicable(f"the pickle has no {part}")
            d2 = pickle.loads(data_pickle(env, **{part: _flip(args[index], offset, value)}))
            use_data(env.m, d2)
        return make

    def stream_flip(which):
        def make(label, env):
            """a pickle stream with one byte changed"""
            offset, value = _offset(label)
            raw = pickle.dumps(env.d if which == "data" else env.m)
            obj = pickle.loads(_flip(raw, offset, value))
            if isinstance(obj, mjcffi.MjData):
                use_data(obj._model, obj)
            elif isinstance(obj, mjcffi.MjModel):
                _simulate(obj)
        return make

    def model_flip(label, env):
        """MjModel pickle (MJB bytes) with one byte changed"""
        offset, value = _offset(label)
        func, args = _reduced(env.m)
        _simulate(func(_flip(args[0], offset, value), *args[1:]))

    families = {"header flip": part_flip("header"), "buffer flip": part_flip("buffer"),
                "arena flip": part_flip("arena"), "layout flip": part_flip("layout"),
                "data stream flip": stream_flip("data"),
                "model stream flip": stream_flip("model"), "mjb flip": model_flip}
    # The header's sizes (before `solver`) and its pointers (from `buffer` on), every
    # word; the statistics between them, sparsely.
    header_size, stats, pointers = (ffi.sizeof("mjData"), ffi.offsetof("mjData", "solver"),
                                    ffi.offsetof("mjData", "buffer"))
    offsets = (list(range(0, stats, 8)) + list(range(stats, pointers, 4099))
               + list(range(pointers, header_size, 8)))
    fixed_labels = ([f"header flip@{n}^{v}" for n in offsets for v in (1, 0x80)]
                    + [f"buffer flip@{n}^0x40" for n in range(0, 4096, 97)]
                    + [f"arena flip@{n}^0xff" for n in range(0, 4096, 89)]
                    + [f"layout flip@{n}^0x80" for n in range(0, 2048, 8)]
                    + [f"data stream flip@{n}^1" for n in range(0, 400, 7)]
                    + [f"model stream flip@{n}^1" for n in range(0, 400, 7)]
                    + [f"mjb flip@{n}^0xff" for n in range(0, 4096, 67)])
    fixed_labels = [label.replace("^0x40", "^64").replace("^0xff", "^255")
                    .replace("^0x80", "^128") for label in fixed_labels]
    allowed = (pickle.UnpicklingError, EOFError)
    flips = Parametric("pickle:flip", families, fixed_labels, allowed=allowed)
    # A flipped byte of the pickle stream itself can make pickle fail in any way of its
    # own (a module name changed: ModuleNotFoundError); only mjcffi's errors count.
    flips.foreign_ok = True
    cases.append(flips)
    return cases


# --------------------------------------------------------------------- vfs

def _vfs_targets():
    def setitem(env, name, content):
        vfs = mjcffi.MjVfs()
        vfs[name] = content
        _ = name in vfs
        del vfs[name]

    out = [CallTarget("vfs:setitem", [
        (Param("name", "text"), lambda env: "a.xml"),
        (Param("content", "buffer"), lambda env: b"<mujoco/>")], setitem,
        allowed=(RuntimeError,))]

    def closed_ops(env):
        """every MjVfs operation after close()"""
        vfs = mjcffi.MjVfs()
        vfs.close()
        for op in (lambda: vfs.__setitem__("a", b""), lambda: "a" in vfs,
                   lambda: vfs.__delitem__("a"), vfs.close,
                   lambda: mjcffi.MjModel.from_xml_string(XML, vfs=vfs)):
            try:
                op()
            except (RuntimeError, ValueError, TypeError, KeyError):
                pass

    def delete_missing(env):
        """del vfs['missing']"""
        vfs = mjcffi.MjVfs()
        del vfs["missing"]

    def mount_then_drop(env):
        """mj_mountVFS(vfs, 'x', MjpResourceProvider()); del vfs; collect"""
        import gc
        vfs = mjcffi.MjVfs()
        mjcffi.mj_mountVFS(vfs, "x", mjcffi.MjpResourceProvider())
        del vfs
        gc.collect()

    def load_through_closed(env):
        """from_xml_string(vfs=closed)"""
        vfs = env.vfs
        vfs.close()
        mjcffi.MjModel.from_xml_string(XML, vfs=vfs)

    out.append(Case("vfs:misuse", {"closed ops": closed_ops, "delete missing": delete_missing,
                                   "mount then drop": mount_then_drop,
                                   "load through closed": load_through_closed},
                    allowed=(RuntimeError,)))
    return out


# ----------------------------------------------------------------- rollout

def _rollout_targets():
    from mjcffi import rollout as R

    nroll, nstep = 2, 3

    def nstate(env):
        return mjcffi.mj_stateSize(env.m, mjcffi.mjtState.mjSTATE_FULLPHYSICS)

    def initial_state(env):
        state = np.zeros((nroll, nstate(env)))
        mjcffi.mj_getState(env.m, env.d, state[0], mjcffi.mjtState.mjSTATE_FULLPHYSICS)
        state[1] = state[0]
        return guard.guarded(state)

    def call(env, **kw):
        R.rollout(**kw)

    params = [
        (Param("model", "struct", elem="mjModel"), lambda env: env.m),
        (Param("data", "struct", elem="mjData"), lambda env: env.d),
        (Param("initial_state", "array", elem="mjtNum"), initial_state),
        (Param("control", "array", elem="mjtNum"),
         lambda env: guard.zeros((nroll, nstep, env.m.nu))),
        (Param("nstep", "int"), lambda env: nstep),
        (Param("state", "array", elem="mjtNum", const=False),
         lambda env: guard.zeros((nroll, nstep, nstate(env)))),
        (Param("sensordata", "array", elem="mjtNum", const=False),
         lambda env: guard.zeros((nroll, nstep, env.m.nsensordata))),
        (Param("chunk_size", "int"), lambda env: None),
        (Param("control_spec", "int"), lambda env: int(mjcffi.mjtState.mjSTATE_CTRL)),
        (Param("initial_warmstart", "array", elem="mjtNum"), lambda env: None),
    ]
    lists = {
        "model": {"list of models": lambda env: [env.m, env.m],
                  "list of other models": lambda env: [env.m, env.m_other],
                  "empty list": lambda env: [],
                  "list with None": lambda env: [env.m, None]},
        "data": {"list of datas": lambda env: [env.d, mjcffi.MjData(env.m)],
                 "same data twice": lambda env: [env.d, env.d],
                 "list with None": lambda env: [env.d, None],
                 "1000 datas": lambda env: [env.d] * 1000},
    }
    return [CallTarget("rollout:rollout", params, call, labels=lists),
            CallTarget("rollout:Rollout", [
                (Param("nthread", "int"), lambda env: 2),
                (Param("model", "struct", elem="mjModel"), lambda env: env.m),
                (Param("initial_state", "array", elem="mjtNum"), initial_state)],
                _rollout_pool_call)]


def _rollout_pool_call(env, nthread, model, initial_state):
    from mjcffi import rollout as R
    with R.Rollout(nthread=nthread) as pool:
        pool.rollout(model, [env.d, mjcffi.MjData(env.m)], initial_state, nstep=2)
    pool.close()


# ------------------------------------------------------------------- batch

def _batch_targets():
    from mjcffi import batch as B

    def make(env, model, nsim, nthread):
        with B.Batch(model, nsim, nthread) as b:
            b.step()
            b.forward()
            b.reset()

    out = [CallTarget("batch:Batch", [
        (Param("model", "struct", elem="mjModel"), lambda env: env.m),
        (Param("nsim", "int"), lambda env: 2),
        (Param("nthread", "int"), lambda env: 0)], make)]

    def method(name, params):
        def call(env, **kw):
            with B.Batch(env.m, 2) as b:
                result = getattr(b, name)(**kw)
                if isinstance(result, np.ndarray):
                    result.sum()
        return CallTarget(f"batch:{name}", params, call)

    ids = (Param("ids", "array", elem="int"), lambda env: None)
    out += [
        method("step", [ids, (Param("nstep", "int"), lambda env: 1),
                        (Param("stage", "int"), lambda env: 0)]),
        method("forward", [ids, (Param("stage", "int"), lambda env: 3)]),
        method("reset", [ids, (Param("keyframe", "int"), lambda env: -1),
                         (Param("stage", "int"), lambda env: 3)]),
        method("expand", [(Param("name", "text"), lambda env: "body_mass")]),
        method("expanded", [(Param("name", "text"), lambda env: "body_mass")]),
        method("bind", [(Param("name", "text"), lambda env: "qpos")]),
        method("get_data", [(Param("sim", "int"), lambda env: 0)]),
        method("get_model", [(Param("sim", "int"), lambda env: 0)]),
        method("error", [(Param("sim", "int"), lambda env: 0)]),
        method("set_const", [ids]),
        method("geom", [(Param("key", "text"), lambda env: "box")]),
        method("jac", [(Param("body", "int"), lambda env: 1),
                       (Param("point", "array", elem="mjtNum"),
                        lambda env: guard.zeros((2, 3))), ids]),
        method("ray", [(Param("pnt", "array", elem="mjtNum"), lambda env: guard.zeros((2, 3))),
                       (Param("vec", "array", elem="mjtNum"),
                        lambda env: guard.guarded(np.tile([0.0, 0.0, -1.0], (2, 1)))),
                       (Param("geomgroup", "array", elem="mjtByte"), lambda env: None),
                       (Param("bodyexclude", "int"), lambda env: -1), ids]),
        method("rollout", [(Param("nstep", "int"), lambda env: 2),
                           (Param("control", "array", elem="mjtNum"),
                            lambda env: guard.zeros((2, 2, env.m.nu))),
                           (Param("record", "object"), lambda env: ("qpos",)), ids]),
        method("set_models", [(Param("models", "object"), lambda env: [env.m, env.m])]),
    ]

    def closed_step(env):
        """Batch.close() then step()"""
        b = B.Batch(env.m, 2)
        b.close()
        b.step()

    def expand_parentid(env):
        """Batch.expand('body_parentid')"""
        with B.Batch(env.m, 2) as b:
            b.expand("body_parentid")
            b.step()

    def big_nstep(env):
        """Batch.step(nstep=2**31)"""
        with B.Batch(env.m, 2) as b:
            b.step(nstep=2**31)

    def view_after_close(env):
        """a Batch view read after close()"""
        b = B.Batch(env.m, 2)
        qpos = b.bind("qpos")
        b.close()
        np.asarray(qpos).sum()

    out.append(Case("batch:misuse", {"close then step": closed_step,
                                     "expand body_parentid": expand_parentid,
                                     "step nstep=2**31": big_nstep,
                                     "view after close": view_after_close}))
    return out


# ---------------------------------------------------------------- minimize

def _minimize_targets():
    from mjcffi import minimize as M

    def residual(x):
        return np.atleast_1d(x) - 1.0

    residuals = {
        "raises": lambda env: _raiser,
        "wrong shape": lambda env: (lambda x: np.ones((2, 2, 2))),
        "returns None": lambda env: (lambda x: None),
        "returns str": lambda env: (lambda x: "r"),
        "returns nan": lambda env: (lambda x: np.full(2, np.nan)),
        "returns int": lambda env: (lambda x: np.ones(2, np.int32)),
        "not callable": lambda env: 5,
        "wrong arity": lambda env: (lambda: None),
    }

    def call(env, **kw):
        M.least_squares(verbose=0, **kw)

    return [CallTarget("minimize:least_squares", [
        (Param("x0", "array", elem="mjtNum"), lambda env: guard.guarded(np.zeros(2))),
        (Param("residual", "object"), lambda env: residual),
        (Param("bounds", "object"), lambda env: None),
        (Param("max_iter", "int"), lambda env: 5),
        (Param("eps", "float"), lambda env: 1e-6),
        (Param("mu_min", "float"), lambda env: 1e-6),
        (Param("x_scale", "object"), lambda env: None)], call,
        labels={"residual": residuals,
                "bounds": {"short": lambda env: [np.zeros(1), np.ones(1)],
                           "inverted": lambda env: [np.ones(2), np.zeros(2)],
                           "nan": lambda env: [np.full(2, np.nan), np.ones(2)],
                           "three": lambda env: [np.zeros(2)] * 3},
                "x_scale": {"jac": lambda env: "jac", "zeros": lambda env: np.zeros(2),
                            "negative": lambda env: -np.ones(2), "str": lambda env: "x"}})]


def _raiser(*args):
    raise FuzzError("raised by the fuzzer's callback")


# --------------------------------------------------------------------- sim

def _sim_targets():
    from mjcffi import sim as S

    def make_sim(env, model, nsubsteps, udd_callback):
        s = S.MjSim(model, None, nsubsteps, udd_callback)
        s.step()
        s.forward()
        s.get_state()

    udd = {"raises": lambda env: _raiser, "returns None": lambda env: (lambda sim: None),
           "returns list": lambda env: (lambda sim: [1]),
           "returns huge dict": lambda env: (lambda sim: {"x": np.ones(10**6)}),
           "not callable": lambda env: 5}
    out = [CallTarget("sim:MjSim", [
        (Param("model", "struct", elem="mjModel"), lambda env: env.m),
        (Param("nsubsteps", "int"), lambda env: 1),
        (Param("udd_callback", "object"), lambda env: None)], make_sim,
        labels={"udd_callback": udd},
        allowed=_sim_allowed())]

    def pool(env, sims, nsubsteps, nthreads):
        p = S.MjSimPool(sims, nsubsteps, nthreads)
        p.step()
        p.forward()
        p.reset()

    out.append(CallTarget("sim:MjSimPool", [
        (Param("sims", "object"), lambda env: [S.MjSim(env.m), S.MjSim(copy.copy(env.m))]),
        (Param("nsubsteps", "int"), lambda env: 1),
        (Param("nthreads", "int"), lambda env: 2)], pool,
        labels={"sims": {"same sim twice": lambda env: [S.MjSim(env.m)] * 2,
                         "empty": lambda env: [],
                         "with None": lambda env: [S.MjSim(env.m), None],
                         "sims sharing data": lambda env: _sharing_sims(env)}},
        allowed=_sim_allowed()))

    def set_state(env, value):
        s = S.MjSim(env.m)
        s.set_state(value)
        s.step()

    def valid_state(env):
        return S.MjSim(env.m).get_state()

    out.append(CallTarget("sim:set_state", [(Param("value", "object"), valid_state)],
                          set_state, labels={"value": {
                              "short qpos": lambda env: S.MjSimState(0.0, np.zeros(1),
                                                                    np.zeros(1), None, {}),
                              "nan time": lambda env: S.MjSimState(np.nan, np.zeros(env.m.nq),
                                                                  np.zeros(env.m.nv), None, {}),
                              "other model's": lambda env: S.MjSim(env.m_other).get_state(),
                              "tuple": lambda env: (0.0, None, None, None, None)}},
                          allowed=_sim_allowed()))

    def from_flat(env, array):
        s = S.MjSim(env.m)
        state = S.MjSimState.from_flattened(array, s)
        s.set_state(state)

    out.append(CallTarget("sim:from_flattened", [
        (Param("array", "array", elem="mjtNum"),
         lambda env: guard.guarded(S.MjSim(env.m).get_state().flatten()))], from_flat,
        allowed=_sim_allowed()))

    def pool_closed(env):
        """MjSimPool.close() then step()"""
        p = S.MjSimPool([S.MjSim(env.m)])
        p.close()
        p.step()

    def pool_same(env):
        """MjSimPool([sim, sim]).step()"""
        s = S.MjSim(env.m)
        S.MjSimPool([s, s]).step()

    def pool_nsims(env):
        """MjSimPool.step(nsims=10**6)"""
        S.MjSimPool([S.MjSim(env.m)]).step(nsims=10**6)

    def pool_nsims_negative(env):
        """MjSimPool.step(nsims=-1)"""
        S.MjSimPool([S.MjSim(env.m)]).step(nsims=-1)

    def create_from_sim(env):
        """MjSimPool.create_from_sim(sim, -1)"""
        S.MjSimPool.create_from_sim(S.MjSim(env.m), -1)

    def save_bad(env):
        """MjSim.save(file, format='nope')"""
        import io
        S.MjSim(env.m).save(io.StringIO(), format="nope")

    out.append(Case("sim:misuse", {"pool close then step": pool_closed,
                                   "pool same sim twice": pool_same,
                                   "pool nsims=10**6": pool_nsims,
                                   "pool nsims=-1": pool_nsims_negative,
                                   "create_from_sim -1": create_from_sim,
                                   "save bad format": save_bad},
                    allowed=_sim_allowed()))
    return out


def _sharing_sims(env):
    from mjcffi import sim as S
    a = S.MjSim(env.m)
    return [a, S.MjSim(env.m, a.data)]


def _sim_allowed():
    from mjcffi import sim as S
    return tuple(getattr(S, name) for name in ("MujocoException",) if hasattr(S, name))


# --------------------------------------------------------------- callbacks

_CALLBACK_VALUES = {
    "raises": lambda env: _raiser,
    "wrong arity": lambda env: (lambda: None),
    "returns str": lambda env: (lambda *a: "x"),
    "returns nan": lambda env: (lambda *a: float("nan")),
    "returns 2**80": lambda env: (lambda *a: 2**80),
    "returns array": lambda env: (lambda *a: np.ones(3)),
    "steps the same data": lambda env: (lambda m, d, *a: mjcffi.mj_step(m, d)),
    "resets the data": lambda env: (lambda m, d, *a: mjcffi.mj_resetData(m, d)),
    "cffi pointer of another signature": lambda env: mjcffi.ffi.cast("void (*)(int)", 0),
    "cffi NULL": lambda env: mjcffi.ffi.NULL,
    "ctypes int": lambda env: __import__("ctypes").c_int(3),
}


def _callback_targets():
    out = []
    names = ("passive", "control", "contactfilter", "sensor", "time", "act_dyn", "act_gain",
             "act_bias")
    for name in names:
        def call(env, callback, name=name):
            getattr(mjcffi, f"set_mjcb_{name}")(callback)
            m, d = env.m, env.d
            for _ in range(3):
                mjcffi.mj_step(m, d)
            getattr(mjcffi, f"get_mjcb_{name}")()
            getattr(mjcffi, f"set_mjcb_{name}")(None)
            mjcffi.mj_step(m, d)

        result = 0 if name == "contactfilter" else (
            None if name in ("passive", "control", "sensor") else 0.0)
        # RecursionError: documented for a callback that steps or resets its own data
        # (the official raises it too, at Python's recursion limit)
        out.append(CallTarget(f"cb:set_mjcb_{name}", [
            (Param("callback", "object"), lambda env, r=result: (lambda *a: r))], call,
            allowed=(RecursionError,), labels={"callback": _CALLBACK_VALUES},
            group="callback"))

    for name, trigger in (("warning", lambda env: mjcffi.mju_warning("fuzz")),
                          ("malloc", lambda env: mjcffi.MjData(env.m)),
                          ("free", lambda env: mjcffi.MjData(env.m))):
        def call(env, handler, name=name, trigger=trigger):
            getattr(mjcffi, f"set_mju_user_{name}")(handler)
            try:
                trigger(env)
            finally:
                getattr(mjcffi, f"set_mju_user_{name}")(None)

        out.append(CallTarget(f"cb:set_mju_user_{name}", [
            (Param("handler", "object"), lambda env: None)], call,
            labels={"handler": _CALLBACK_VALUES}, group="callback"))
    return out


# ------------------------------------------------------------------ spec

def _spec_targets():
    from mjcffi import functions as F

    def deleted_read(env):
        """mjs_delete(spec, geom.element) then read the geom's wrapper"""
        s, world, body = env.spec
        geom = F.mjs_addGeom(body, None)
        F.mjs_delete(s, geom.element)
        repr(geom)
        geom.size = [1, 1, 1]

    def delete_world(env):
        """mjs_delete(spec, world.element) then free the spec"""
        import gc
        s = F.mj_makeSpec()
        world = F.mjs_findBody(s, "world")
        F.mjs_delete(s, world.element)
        del s, world
        gc.collect()

    def element_outlives_spec(env):
        """a spec element's wrapper read after its spec is collected"""
        import gc
        s = F.mj_makeSpec()
        body = F.mjs_addBody(F.mjs_findBody(s, "world"), None)
        del s
        gc.collect()
        repr(body)

    def delete_twice(env):
        """mjs_delete of the same element twice"""
        s, world, body = env.spec
        geom = F.mjs_addGeom(body, None)
        F.mjs_delete(s, geom.element)
        F.mjs_delete(s, geom.element)

    def delete_other_spec(env):
        """mjs_delete(spec, element of another spec)"""
        s, world, body = env.spec
        other = F.mj_makeSpec()
        b2 = F.mjs_addBody(F.mjs_findBody(other, "world"), None)
        F.mjs_delete(s, b2.element)

    def compile_after_delete(env):
        """compile a spec after deleting a body that a geom's wrapper still holds"""
        s, world, body = env.spec
        geom = F.mjs_addGeom(body, None)
        F.mjs_delete(s, body.element)
        F.mj_compile(s, None)
        repr(geom)

    return [Case("spec:lifetime", {"deleted element read": deleted_read,
                                   "delete world then free": delete_world,
                                   "element outlives spec": element_outlives_spec,
                                   "delete twice": delete_twice,
                                   "delete other spec's element": delete_other_spec,
                                   "compile after delete": compile_after_delete},
                 allowed=(NotImplementedError,))]      # while mjs_delete is unsupported


# ------------------------------------------------------------- lifetimes

def _lifetime_targets():
    def view_outlives_model(env):
        """a model's array view read after the model is collected"""
        import gc
        m = copy.copy(env.m)
        view = m.body_pos
        del m
        gc.collect()
        view.sum()

    def accessor_outlives_data(env):
        """a named accessor read after its data is collected"""
        import gc
        d = mjcffi.MjData(env.m)
        acc = d.joint("hinge")
        del d
        gc.collect()
        acc.qpos.sum()
        repr(acc)

    def contact_outlives_data(env):
        """d.contact[0] read after its data is collected"""
        import gc
        d = mjcffi.MjData(env.m)
        mjcffi.mj_forward(env.m, d)
        c = d.contact[0]
        del d
        gc.collect()
        repr(c)

    def geom_after_free_scene(env):
        """scn.geoms[0] read and written after mjv_freeScene / mjv_makeScene"""
        scn = mjcffi.MjvScene(env.m, maxgeom=100)
        mjcffi.mjv_updateScene(env.m, env.d, mjcffi.MjvOption(), None, mjcffi.MjvCamera(),
                               7, scn)
        g = scn.geoms[0]
        mjcffi.mjv_freeScene(scn)
        repr(g)
        g.size = [1, 1, 1]
        mjcffi.mjv_makeScene(env.m, scn, 10)
        repr(g)
        g.size = [1, 1, 1]

    def scene_count(env):
        """scn.nflex = 10**9, then scn.flexvertadr.sum()"""
        scn = mjcffi.MjvScene(env.m, maxgeom=10)
        scn.nflex = 10**9
        scn.flexvertadr.sum()

    def warning_number(env):
        """d.warning[0].number = 2**40"""
        env.d.warning[0].number = 2**40

    def two_threads_step(env):
        """the same MjData stepped from two Python threads at once (started together,
        500 steps per call in C)"""
        import threading
        m, d = env.m, env.d
        errors = []
        start = threading.Barrier(2)

        def run():
            start.wait()
            try:
                for _ in range(20):
                    mjcffi.mj_step(m, d, 500)
            except Exception as exc:       # a documented error is fine; record the rest
                errors.append(exc)
        for _ in range(5):                  # a race may end in a FatalError instead
            mjcffi.mj_resetData(m, d)
            threads = [threading.Thread(target=run) for _ in range(2)]
            for t in threads:
                t.start()
            for t in threads:
                t.join()
        for exc in errors:
            raise exc

    return [Case("lifetime:misuse", {"view outlives model": view_outlives_model,
                                     "accessor outlives data": accessor_outlives_data,
                                     "contact outlives data": contact_outlives_data,
                                     "scene geom after free": geom_after_free_scene,
                                     "scene count 10**9": scene_count,
                                     "warning number 2**40": warning_number,
                                     "two threads step one data": two_threads_step})]


def targets():
    out = []
    for build in (_ctor_targets, setter_targets, _named_targets, _loader_targets,
                  _pickle_targets, _vfs_targets, _rollout_targets, _batch_targets,
                  _minimize_targets, _sim_targets, _callback_targets, _spec_targets,
                  _lifetime_targets):
        out.extend(build())
    return out


__all__ = ["targets", "FuzzError"]
