"""Valid calls of the generated functions, shared by the function-layer tests.

`valid_call(func, env)` builds a call of an array function that both bindings
accept (env from `model_env(mjcffi)` or `model_env(mujoco)`): SHAPES gives each
array's extents, with small sizes that differ per size argument, so that a
transposed matrix is a wrong shape.  `full_call(func, pool)` extends it to every
generated function whose arguments a `Pool` can fill (structs, spec elements,
strings, buffers), for mjcffi alone.

`reaches_c(func, kwargs)` runs a call with the compiled module replaced by a
stub that records the C call and runs nothing: whether the call's checks take
every argument, without running MuJoCo.
"""

import contextlib
import inspect
import os
import tempfile

import numpy as np

from codegen import functions as table
from mjcffi._generated.funcinfo import FUNCTIONS

XML = """
<mujoco>
  <asset>
    <mesh name="tet" vertex="0 0 0  1 0 0  0 1 0  0 0 1"/>
    <hfield name="hill" nrow="3" ncol="3" size="1 1 .1 .1"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 .1"/>
    <camera name="fixed" pos="0 -3 1" xyaxes="1 0 0 0 0.3 1"/>
    <frame name="frame" pos="0 0 2"><site name="framed"/></frame>
    <body name="base" pos="0 0 1">
      <freejoint/>
      <geom name="ball" size=".1" pos="0 0 -.92"/>
      <body name="arm" pos="0 0 .3">
        <joint name="hinge" type="hinge"/>
        <geom name="rod" type="capsule" size=".05" fromto="0 0 0 0 0 .3"/>
        <site name="tip" pos="0 0 .3"/>
      </body>
    </body>
    <geom name="terrain" type="hfield" hfield="hill" pos="5 0 0"/>
    <geom name="tet" type="mesh" mesh="tet" pos="-5 0 0" contype="0" conaffinity="0"/>
    <flexcomp name="cloth" type="grid" count="2 2 1" spacing=".1 .1 .1" pos="0 5 1" dim="2"
              radius=".01">
      <edge equality="true"/>
    </flexcomp>
  </worldbody>
  <actuator>
    <position name="delayed" joint="hinge" delay="0.01" nsample="4"/>
    <pid name="pid" joint="hinge" kp="10" kv="2" input="pos vel ff" delay="0.01" nsample="3"/>
  </actuator>
  <sensor>
    <accelerometer name="accel" site="tip" delay="0.01" nsample="3"/>
    <jointpos joint="hinge"/>
  </sensor>
</mujoco>
"""

# Size arguments: distinct small values, so that swapped extents do not match.
SIZES = {"n": 3, "nr": 2, "nc": 4, "r1": 2, "c1": 3, "c2": 4, "r2": 5, "nvec": 2,
         "ntotal": 4, "nband": 2, "ndense": 1, "dim": 2, "nray": 2, "nface": 1, "nvert": 3,
         "nnz": 8}

# Scalar arguments by name; others get 0 (int) or 0.5 (float).
SCALARS = {"body": 1, "objtype": 1, "objid": 1, "bodyexclude": -1, "cutoff": 10.0,
           "time": 0.02, "phase": 0.0, "sig": 4356, "srcsig": 4356, "dstsig": 4356,
           "eps": 1e-6, "scl": 1.0, "mindiag": 1e-9, "flg_static": 1, "diagadd": 0.0,
           "diagmul": 0.0, "base": 2, "index": 1, "flg_centered": 0, "nstep": 1}


def _geom_of_type(env, geomtype):
    return int(np.flatnonzero(np.asarray(env["m"].geom_type) == geomtype)[0])


# Scalars that need the model: (function, argument) -> value from env.
MODEL_SCALARS = {
    ("mj_rayHfield", "geomid"): lambda env: _geom_of_type(env, 1),       # mjGEOM_HFIELD
    ("mj_rayMesh", "geomid"): lambda env: _geom_of_type(env, 7),         # mjGEOM_MESH
    ("mjs_firstElement", "type"): lambda env: 1,                         # mjOBJ_BODY
    ("mjv_connector", "type"): lambda env: 3,                            # mjGEOM_CAPSULE
    ("mjr_changeFont", "fontscale"): lambda env: 100,                    # mjFONTSCALE_100
}

# Array functions left out of valid_call, and why.
SKIP = {
    "mj_addBufferVFS": "a byte buffer, not an array",
    "mj_saveModel": "a byte buffer, not an array",
    "mju_strncpy": "a byte buffer, not an array",
    "mju_writeResource": "needs a resource handle",
    "mju_printMat": "prints",
    "mju_printMatSparse": "prints",
    "mju_sparse2dense": "needs a consistent sparse structure",
    "mju_sym2dense": "needs a consistent sparse structure",
    "mj_addM": "only the dense form, with None for the structure",
    "mju_boxQP": "needs a consistent problem; covered by its own tests",
    "mjp_getPlugin": "needs a plugin",
    "mju_threadpool": "makes threads",
    "mju_standardNormal": "the official bindings take num2 as a float, not an output array",
}


def model_env(module, xml=XML):
    """{"m", "d", "module"}: the test model of `module` (mjcffi or mujoco), forwarded."""
    m = module.MjModel.from_xml_string(xml)
    d = module.MjData(m)
    module.mj_forward(m, d)
    return {"m": m, "d": d, "module": module}


class _Flat:
    """A model or data whose array attributes read flat, as the C layout (SHAPES) sees them."""

    def __init__(self, obj):
        self._obj = obj

    def __getattr__(self, name):
        value = getattr(self._obj, name)
        return np.ravel(value) if isinstance(value, np.ndarray) else value


def extents(func, arg, env):
    """The extents of one array argument in a valid call, or None (not an array)."""
    spec = table.SHAPES.get(func, {}).get(arg.name)
    if spec is None:
        return tuple(arg.extents) if arg.extents else None
    if spec == "*":
        return None
    if arg.name in table.SIZED.get(func, ()):           # flat, as the official bindings take
        spec = " * ".join(f"({d})" for d in table._split_dims(spec))
    names = dict(SCALARS, **SIZES, m=_Flat(env["m"]), d=_Flat(env["d"]), mjNREF=2, mjNIMP=5,
                 mjNGROUP=6, mjNCTIMER=6,
                 state_size=lambda m, sig, name=None: env["module"].mj_stateSize(m, sig),
                 band_size=lambda t, b, d: (t - d) * b + d * t, id=0, nparams=2, size=3,
                 nbuffer=8, buffer_sz=8, nbytes=8)
    return tuple(int(eval(dim, {}, names)) for dim in table._split_dims(spec))


DTYPES = {"mjtNum": np.float64, "double": np.float64, "float": np.float32, "int": np.int32,
          "mjtByte": np.uint8, "unsigned char": np.uint8, "mjtSize": np.int64,
          "mjtBool": np.bool_}


def make_array(name, shape, elem):
    """A valid, well-conditioned array: increasing times, an identity-like matrix, or ones."""
    if name == "times":
        return np.arange(shape[0]) * 0.01
    out = np.ones(shape, DTYPES[elem])
    if len(shape) == 2 and shape[0] == shape[1] and elem in ("mjtNum", "double"):
        out[:] = np.eye(shape[0]) * 2.0
    return out


def generated(func):
    """Whether `func` is a generated wrapper (not hand-written, not unsupported)."""
    return func not in table.OVERRIDES and func not in table.UNSUPPORTED


def array_args(func):
    """(C name, Arg) of each numeric array argument of `func`."""
    return [(a.name, a) for a in FUNCTIONS[func].args
            if (a.pointer or a.extents) and a.elem in DTYPES]


def params(func):
    """(python name, Arg) of each parameter of mjcffi's `func`."""
    import mjcffi.functions as F
    by_name = {a.name: a for a in FUNCTIONS[func].args}
    renames = {v: k for k, v in table.RENAMES.get(func, {}).items()}
    out = []
    for py in inspect.signature(getattr(F, func)).parameters:
        arg = by_name.get(renames.get(py, py)) or by_name.get(py.rstrip("_"))
        out.append((py, arg))
    return out


def scalar_value(func, arg, env):
    if (func, arg.name) in MODEL_SCALARS:
        return MODEL_SCALARS[(func, arg.name)](env)
    if arg.name in SIZES:
        return SIZES[arg.name]
    if arg.name in SCALARS:
        return SCALARS[arg.name]
    if arg.elem in ("mjtNum", "double", "float"):
        return 0.5
    return 0


# Struct arguments valid_call builds in either binding: C name -> make(module, env).
def _scene(module, env):
    """A scene updated once, so that its camera is valid (frustum_near > 0)."""
    scene = module.MjvScene(env["m"], maxgeom=100)
    module.mjv_updateScene(env["m"], env["d"], module.MjvOption(), None, module.MjvCamera(),
                           7, scene)
    return scene


VALID_STRUCTS = {
    "mjvScene": _scene,
    **{cname: (lambda cls: lambda module, env: getattr(module, cls)())(cls) for cname, cls in (
        ("mjvCamera", "MjvCamera"), ("mjvOption", "MjvOption"), ("mjvGeom", "MjvGeom"),
        ("mjvPerturb", "MjvPerturb"), ("mjvGLCamera", "MjvGLCamera"))},
}

# Text arguments of array functions: (function, argument) -> value.
VALID_TEXTS = {("mju_euler2Quat", "seq"): "xYz"}


def valid_call(func, env):
    """{python name: value} for a call of an array function that both bindings accept,
    or None."""
    if func in SKIP or not generated(func) or not array_args(func):
        return None
    kwargs = {}
    for py, arg in params(func):
        if arg is None:
            return None
        if arg.elem == "mjModel":
            kwargs[py] = env["m"]
        elif arg.elem == "mjData":
            kwargs[py] = env["d"]
        elif arg.elem in VALID_STRUCTS and arg.pointer == 1:
            kwargs[py] = VALID_STRUCTS[arg.elem](env["module"], env)
        elif (func, arg.name) in VALID_TEXTS:
            kwargs[py] = VALID_TEXTS[(func, arg.name)]
        elif arg.pointer == 0 and not arg.extents:
            kwargs[py] = scalar_value(func, arg, env)
        else:
            shape = extents(func, arg, env)
            if shape is None or arg.elem not in DTYPES:
                return None
            kwargs[py] = make_array(arg.name, shape, arg.elem)
    return kwargs


# ------------------------------------------------------------ every function

# Text arguments by name (others get "x"): valid for the calls below.
# The scratch file lives in the temporary directory: functions such as
# mj_saveLastXML write it, and a test must not write into the source tree.
SCRATCH = os.path.join(tempfile.gettempdir(), "mjcffi_scratch_file.xml")
TEXTS = {"xml": XML, "content_type": "text/xml", "filename": SCRATCH,
         "name": "x", "classname": "main", "directory": ".", "filepath": SCRATCH}

# Functions that full_call leaves out, and why.
FULL_SKIP = {
    "mju_error": "raises FatalError by design",
    "mju_info": "variadic",
    "mjc_getSDF": "needs a geom with an SDF plugin",
    "mjr_uploadTexture": "the test model has no texture (tests/test_mjr.py checks its id)",
}


class Pool:
    """Correct values of every struct kind for full_call: a model and data, default
    visualization structs, and a spec with one element of each kind used."""

    def __init__(self, xml=XML):
        import mjcffi
        from mjcffi import functions as F
        from mjcffi import structs
        self.env = model_env(mjcffi, xml)
        m = self.env["m"]
        spec = F.mj_parseXMLString(xml)
        world = F.mjs_findBody(spec, "world")
        body = F.mjs_findBody(spec, "base") or F.mjs_addBody(world, None)
        tendon = F.mjs_addTendon(spec, None)
        self._keep = [spec, world, body, tendon]
        self.instances = {
            "mjModel": m, "mjData": self.env["d"], "mjSpec": spec, "mjsBody": body,
            "mjsElement": body.element, "mjsDefault": F.mjs_getSpecDefault(spec),
            "mjsActuator": F.mjs_addActuator(spec, None), "mjsTendon": tendon,
            "mjsWrap": F.mjs_wrapSite(tendon, "tip"),
            "mjsOrientation": body.alt, "mjsMesh": F.mjs_addMesh(spec, None),
            "mjsSensor": F.mjs_addSensor(spec), "mjsPlugin": F.mjs_addPlugin(spec),
            "mjvScene": _scene(mjcffi, self.env), "mjVFS": structs.MjVFS(),
        }
        frame = F.mjs_findFrame(spec, "frame")
        if frame is not None:
            self.instances["mjsFrame"] = frame
        for cls in ("MjvOption", "MjvCamera", "MjvPerturb", "MjvFigure", "MjvGeom",
                    "MjvGLCamera", "MjLROpt", "MjOption", "MjVisual", "MjContact",
                    "MjLogConfig"):
            value = getattr(structs, cls)()
            self.instances[value._cname] = value
        self.instances["mjrRect"] = structs.MjrRect(0, 0, 10, 10)
        # a default MjrContext: the mjr_* functions check every argument, then refuse it
        # (no OpenGL context here); stubbed() lets their good calls through that check
        self.instances["mjrContext"] = structs.MjrContext()
        F.mj_defaultVFS(self.instances["mjVFS"])


def nullable(func):
    """The C names of `func`'s arguments that mjcffi takes as None (NULL)."""
    return ({a.name for a in FUNCTIONS[func].args if a.nullable}
            | set(table.NULLABLE.get(func, ()))) - set(table.NOT_NULLABLE.get(func, ()))


def full_call(func, pool):
    """{python name: value}: a call of mjcffi's `func` whose every argument is correct,
    or None where the pool cannot fill one."""
    if func in FULL_SKIP or not generated(func):
        return None
    call = valid_call(func, pool.env)
    if call is not None:
        return call
    env = pool.env
    kwargs = {}
    for py, arg in params(func):
        if arg is None:
            return None
        if arg.elem in pool.instances and arg.pointer <= 1:
            kwargs[py] = pool.instances[arg.elem]
        elif arg.pointer == 0 and not arg.extents:
            if "(*" in arg.ctype:
                return None
            kwargs[py] = scalar_value(func, arg, env)
        elif arg.elem == "char" and arg.const:
            kwargs[py] = TEXTS.get(arg.name, "x")
        elif arg.pointer > 1:
            return None
        elif arg.elem in DTYPES:
            shape = extents(func, arg, env)
            if shape is None:
                return None
            value = make_array(arg.name, shape, arg.elem)
            kwargs[py] = value
        elif arg.elem in ("void", "char") and arg.name in table.SHAPES.get(func, {}):
            nbytes = int(np.prod(extents(func, arg, env)))
            kwargs[py] = bytes(nbytes) if arg.const else bytearray(nbytes)
        elif arg.nullable:
            kwargs[py] = None
        else:
            return None
    return kwargs


class _Stub:
    """Stands for the compiled module: a guarded call records its name and returns 0."""

    def __init__(self, real):
        self._real = real
        self.called = []

    def __getattr__(self, name):
        if not name.startswith("mjcffi_guard_"):
            return getattr(self._real, name)

        def call(*args):
            self.called.append(name)
            raise _Reached(name)
        return call


class _Reached(Exception):
    pass


@contextlib.contextmanager
def stubbed():
    """The generated functions call a stub instead of MuJoCo, within the block."""
    from mjcffi import _functions
    modules = _functions.modules()       # each section's module binds _lib and _r itself
    real, checks = modules[0]._lib, modules[0]._r
    stub = _Stub(real)
    for module in modules:
        module._lib, module._r = stub, _NoOpenGL(checks)
    try:
        yield stub
    finally:
        for module in modules:
            module._lib, module._r = real, checks


class _NoOpenGL:
    """Stands for mjcffi/_support/mjr.py: its OpenGL-state checks pass (the C call is stubbed)."""

    def __init__(self, real):
        self._real = real

    def __getattr__(self, name):
        if name in ("context", "gl_ready"):
            return lambda *args: None
        return getattr(self._real, name)


def reaches_c(func, kwargs):
    """Whether mjcffi's `func(**kwargs)` passes every check and reaches the C call (which
    is not made); an exception raised before it propagates."""
    from mjcffi import _functions
    with stubbed():
        try:
            getattr(_functions, func)(**kwargs)
        except _Reached:
            return True
    return False
