"""The valid objects a fuzzed call draws its arguments from, fresh for each call.

`Env` builds what a call asks for on first use (`env.m`, `env.scene`,
`env.struct('mjsGeom')`, ...) and nothing else, so that one call cannot leave
state behind for the next: the model is a copy of a template compiled once per
worker, the data is made for it, the spec is new.  `Env.close()` drops
everything (its owner then collects), so that a crash on freeing is charged to
the call that made the objects.
"""

import copy
import os

import mjcffi

# Every name category, a flex (mj_rayFlex), a height field and a mesh (the ray
# functions), actuators and sensors with delay buffers (mj_readCtrl, ...), a
# tendon, an equality, a keyframe, and contacts at rest.
XML = """
<mujoco model="fuzz">
  <asset>
    <texture name="grid" type="2d" builtin="checker" width="8" height="8"
             rgb1="0 0 0" rgb2="1 1 1"/>
    <material name="mat" texture="grid" rgba="1 0 0 1"/>
    <mesh name="tet" vertex="0 0 0  1 0 0  0 1 0  0 0 1"/>
    <hfield name="hf" nrow="3" ncol="3" size="1 1 0.1 0.1"/>
  </asset>
  <custom>
    <numeric name="num" data="1 2 3"/>
    <text name="txt" data="hello"/>
    <tuple name="tup"><element objtype="body" objname="free" prm="0.5"/></tuple>
  </custom>
  <worldbody>
    <light name="lamp" pos="0 0 3"/>
    <camera name="cam" pos="0 -3 1" xyaxes="1 0 0 0 0 1"/>
    <geom name="floor" type="plane" size="5 5 .1" material="mat"/>
    <geom name="terrain" type="hfield" hfield="hf" pos="3 3 0"/>
    <body name="free" pos="0 0 .09">
      <freejoint name="free"/>
      <geom name="box" type="box" size=".1 .1 .1"/>
      <site name="s1" pos="0 0 .1"/>
    </body>
    <body name="arm" pos="1 0 1">
      <joint name="ball" type="ball"/>
      <geom name="cap" type="capsule" fromto="0 0 0 0 0 -.3" size=".03"/>
      <site name="s2" pos="0 0 -.3"/>
      <body name="lower" pos="0 0 -.3">
        <joint name="hinge" type="hinge" axis="0 1 0"/>
        <joint name="slide" type="slide" axis="0 0 1"/>
        <geom name="mesh" type="mesh" mesh="tet"/>
      </body>
    </body>
    <flexcomp name="cloth" type="grid" count="3 3 1" spacing=".1 .1 .1" pos="-2 0 1" dim="2"
              radius=".01">
      <edge equality="true"/>
    </flexcomp>
  </worldbody>
  <contact>
    <pair name="pair" geom1="box" geom2="floor"/>
    <exclude name="excl" body1="free" body2="arm"/>
  </contact>
  <equality>
    <connect name="eq" body1="free" body2="world" anchor="0 0 1" active="false"/>
  </equality>
  <tendon>
    <spatial name="ten" width=".01"><site site="s1"/><site site="s2"/></spatial>
  </tendon>
  <actuator>
    <motor name="motor" joint="hinge" gear="2" delay="0.01" nsample="4"/>
    <position name="pos" joint="slide" kp="10"/>
  </actuator>
  <sensor>
    <jointpos name="jp" joint="hinge" delay="0.01" nsample="3"/>
    <framepos name="fp" objtype="site" objname="s1"/>
    <tendonpos name="tp" tendon="ten"/>
  </sensor>
  <keyframe>
    <key name="home" time="0"/>
  </keyframe>
</mujoco>
"""

# A model of other sizes, for a model/data mismatch.
OTHER_XML = """
<mujoco model="other">
  <worldbody>
    <body>
      <joint name="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -1" size=".05"/>
    </body>
  </worldbody>
  <actuator><motor joint="hinge"/></actuator>
  <sensor><jointpos joint="hinge"/></sensor>
</mujoco>
"""

# mjs* struct -> how to make one in a fresh spec (`s` the spec, `w` its world body, `b` a body)
_SPEC_MAKERS = {
    "mjsBody": lambda F, s, w, b: b,
    "mjsGeom": lambda F, s, w, b: F.mjs_addGeom(b, None),
    "mjsJoint": lambda F, s, w, b: F.mjs_addJoint(b, None),
    "mjsSite": lambda F, s, w, b: F.mjs_addSite(b, None),
    "mjsCamera": lambda F, s, w, b: F.mjs_addCamera(b, None),
    "mjsLight": lambda F, s, w, b: F.mjs_addLight(b, None),
    "mjsFrame": lambda F, s, w, b: _frame(F, s, b),
    "mjsActuator": lambda F, s, w, b: F.mjs_addActuator(s, None),
    "mjsSensor": lambda F, s, w, b: F.mjs_addSensor(s),
    "mjsTendon": lambda F, s, w, b: _tendon_with_wrap(F, s),
    "mjsFlex": lambda F, s, w, b: F.mjs_addFlex(s),
    "mjsMesh": lambda F, s, w, b: F.mjs_addMesh(s, None),
    "mjsHField": lambda F, s, w, b: F.mjs_addHField(s),
    "mjsSkin": lambda F, s, w, b: F.mjs_addSkin(s),
    "mjsTexture": lambda F, s, w, b: F.mjs_addTexture(s, None),
    "mjsMaterial": lambda F, s, w, b: F.mjs_addMaterial(s, None),
    "mjsPair": lambda F, s, w, b: F.mjs_addPair(s, None),
    "mjsExclude": lambda F, s, w, b: F.mjs_addExclude(s),
    "mjsEquality": lambda F, s, w, b: F.mjs_addEquality(s, None),
    "mjsNumeric": lambda F, s, w, b: F.mjs_addNumeric(s),
    "mjsText": lambda F, s, w, b: F.mjs_addText(s),
    "mjsTuple": lambda F, s, w, b: F.mjs_addTuple(s),
    "mjsKey": lambda F, s, w, b: F.mjs_addKey(s),
    "mjsPlugin": lambda F, s, w, b: F.mjs_addPlugin(s),
    "mjsDefault": lambda F, s, w, b: F.mjs_getSpecDefault(s),
    "mjsWrap": lambda F, s, w, b: F.mjs_wrapPulley(F.mjs_addTendon(s, None), 1.0),
    "mjsOrientation": lambda F, s, w, b: b.alt,
    "mjsElement": lambda F, s, w, b: b.element,
}

def _frame(F, s, body):
    """A frame: mjs_addFrame(body, None) is refused (parentframe has no Nullable note),
    so the first frame comes from a parsed spec's body."""
    try:
        return F.mjs_addFrame(body, None)
    except TypeError:
        parsed = F.mj_parseXMLString("<mujoco><worldbody><frame name='f'/></worldbody>"
                                     "</mujoco>")
        return F.mjs_addFrame(F.mjs_findBody(parsed, "world"), F.mjs_findFrame(parsed, "f"))


def _tendon_with_wrap(F, s):
    tendon = F.mjs_addTendon(s, None)
    F.mjs_wrapSite(tendon, "s")
    return tendon


# Structs that have a plain constructor (the rest come from _SPEC_MAKERS or Env).
_PLAIN = ("mjvOption", "mjvCamera", "mjvPerturb", "mjvGLCamera", "mjvGeom", "mjvFigure",
          "mjvLight", "mjLROpt", "mjContact", "mjOption", "mjVisual", "mjuiState", "mjUI",
          "mjrContext", "mjpResourceProvider", "mjpPlugin", "mjpDecoder", "mjpEncoder",
          "mjLogMessage", "mjrRendererInfo", "mjuiDef", "mjBatchConfig", "mjBatchRecord",
          "mjStatistic", "mjWarningStat", "mjTimerStat", "mjSolverStat", "mjLogConfig")


def class_name(cname):
    """'mjvScene' -> 'MjvScene' (the struct class of a C struct)."""
    return cname[0].upper() + cname[1:]


class _Templates:
    """What each worker compiles once."""

    def __init__(self):
        self.model = mjcffi.MjModel.from_xml_string(XML)
        self.other = mjcffi.MjModel.from_xml_string(OTHER_XML)
        data = mjcffi.MjData(self.model)
        mjcffi.mj_forward(self.model, data)
        self.ncon = data.ncon
        self.mjb = self.model.to_bytes()


def write_files(folder):
    """The files the loaders read by name: model.xml and model.mjb."""
    with open(os.path.join(folder, "model.xml"), "w") as f:
        f.write(XML)
    with open(os.path.join(folder, "model.mjb"), "wb") as f:
        f.write(templates().mjb)


_templates = None


def templates():
    global _templates
    if _templates is None:
        _templates = _Templates()
    return _templates


class Env:
    """Fresh valid objects for one call, made on first use."""

    def __init__(self, workdir=None):
        self._cache = {}
        self.workdir = workdir or os.getcwd()

    def _get(self, key, make):
        try:
            return self._cache[key]
        except KeyError:
            value = self._cache[key] = make()
            return value

    # ------------------------------------------------------------ models
    @property
    def m(self):
        return self._get("m", lambda: copy.copy(templates().model))

    @property
    def d(self):
        def make():
            d = mjcffi.MjData(self.m)
            mjcffi.mj_forward(self.m, d)
            return d
        return self._get("d", make)

    @property
    def m_other(self):
        return self._get("m_other", lambda: copy.copy(templates().other))

    @property
    def d_other(self):
        return self._get("d_other", lambda: mjcffi.MjData(self.m_other))

    @property
    def scene(self):
        def make():
            scn = mjcffi.MjvScene(self.m, maxgeom=100)
            mjcffi.mjv_updateScene(self.m, self.d, mjcffi.MjvOption(), None,
                                   mjcffi.MjvCamera(), 7, scn)
            return scn
        return self._get("scene", make)

    @property
    def mjb(self):
        """The model's MJB bytes."""
        return self._get("mjb", lambda: templates().mjb)

    @property
    def vfs(self):
        def make():
            vfs = mjcffi.MjVfs()
            vfs["model.xml"] = XML.encode()
            return vfs
        return self._get("vfs", make)

    # -------------------------------------------------------------- spec
    @property
    def spec(self):
        def make():
            from mjcffi import functions as F
            s = F.mj_makeSpec()
            world = F.mjs_findBody(s, "world")
            body = F.mjs_addBody(world, None)
            F.mjs_setName(body.element, "b")
            geom = F.mjs_addGeom(body, None)
            geom.size = [0.1, 0.1, 0.1]
            F.mj_compile(s, None)           # mj_saveXML and mj_encode write compiled specs
            return s, world, body
        return self._get("spec", make)

    def spec_struct(self, cname):
        from mjcffi import functions as F
        s, world, body = self.spec
        return self._get(("spec", cname), lambda: _SPEC_MAKERS[cname](F, s, world, body))

    # ----------------------------------------------------------- structs
    def struct(self, cname):
        """A valid wrapper of C struct `cname`, or None when the fuzzer cannot make one."""
        if cname == "mjModel":
            return self.m
        if cname == "mjData":
            return self.d
        if cname == "mjvScene":
            return self.scene
        if cname == "mjVFS":
            return self.vfs
        if cname == "mjSpec":
            return self.spec[0]
        if cname in _SPEC_MAKERS:
            return self.spec_struct(cname)
        if cname == "mjrRect":
            return self._get("mjrRect", lambda: mjcffi.MjrRect(0, 0, 64, 48))
        if cname == "mjCache":
            from mjcffi import functions as F
            return F.mj_getCache()
        if cname in _PLAIN:
            return self._get(cname, lambda: getattr(mjcffi, class_name(cname))())
        return None

    def opaque(self, elem):
        """A raw handle of MuJoCo's opaque type `elem` (mjString, mjDoubleVec, ...), taken
        from a spec element's field of that type, or None."""
        fields = _OPAQUE_FIELDS.get(elem)
        if not fields:
            return None
        owner, field = fields[0]
        return getattr(self.spec_struct(owner), field)

    def wrong_opaque(self, elem):
        """A raw handle of another opaque type than `elem` (MuJoCo cannot tell them apart)."""
        for other in _OPAQUE_FIELDS:
            if other != elem:
                value = self.opaque(other)
                if value is not None:
                    return value
        return None

    def keep(self, value):
        """Keep `value` alive as long as the call's objects (raw memory a call points to)."""
        self._cache.setdefault("kept", []).append(value)
        return value

    def path(self, name):
        return os.path.join(self.workdir, name)

    def close(self):
        self._cache.clear()


def _opaque_fields():
    from mjcffi._generated.structinfo import STRUCTS
    out = {}
    for owner in _SPEC_MAKERS:
        for field in STRUCTS.get(owner, ()):
            if field.kind == "pointer" and field.elem.startswith("mj") and \
                    field.elem not in STRUCTS and field.ctype.count("*") == 1:
                out.setdefault(field.elem, []).append((owner, field.name))
    return out


_OPAQUE_FIELDS = _opaque_fields()


__all__ = ["Env", "XML", "OTHER_XML", "templates", "class_name"]
