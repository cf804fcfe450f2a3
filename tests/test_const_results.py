"""Issue 27, finding 1: what MuJoCo returns as `const` stays const.

`mjp_getPluginAtSlot`, `mjc_getSDF` and the other functions returning a `const`
struct pointer hand out MuJoCo's own global tables; their wrappers are read-only.
The list of such functions comes from the metadata, so a new one is covered
without being named here.
"""

import inspect
import re

import numpy as np
import pytest

import mjcffi
from mjcffi import _functions
from mjcffi._generated.funcinfo import FUNCTIONS
from mjcffi._support.const import const_class, wrap_const

CONST_RESULTS = sorted(name for name, f in FUNCTIONS.items()
                       if f.restype.startswith("const ") and f.restype.endswith("*"))

PID = """
<mujoco>
  <extension><plugin plugin="mujoco.pid"/></extension>
  <worldbody><body><joint name="j"/><geom size=".1" mass="1"/></body></worldbody>
  <actuator>
    <plugin plugin="mujoco.pid" joint="j">
      <config key="kp" value="40"/>
    </plugin>
  </actuator>
</mujoco>
"""


def _result_expression(name):
    """The expression the generated slow path returns (or 'unsupported')."""
    source = inspect.getsource(getattr(_functions, "_" + name, None) or
                               getattr(mjcffi, name))     # a hand-written override
    if "raise NotImplementedError" in source:
        return "unsupported"
    return re.findall(r"^    return (.*)$", source, re.M)[-1]


@pytest.mark.parametrize("name", CONST_RESULTS)
def test_every_const_result_is_a_copy_or_read_only(name):
    """A const pointer comes back as a copy (str, a NumPy copy), a read-only wrapper, an
    opaque `const void *` (which cannot be indexed), or not at all (unsupported)."""
    expression = _result_expression(name)
    restype = FUNCTIONS[name].restype
    if expression == "unsupported":
        return
    if restype == "const char *":
        assert expression == "_m.string(ret)"
    elif restype in ("const mjtNum *", "const double *"):
        assert expression.startswith(("_m.copy_array(", "_m.fill("))
    elif restype == "const void *":
        assert expression == "None if ret == _m.NULL else ret"
    else:
        assert expression.startswith("_m.wrap_const("), (name, expression)


def test_the_metadata_lists_the_plugin_tables():
    """The scan is not empty: it finds the functions of the finding."""
    assert {"mjp_getPluginAtSlot", "mjp_getPlugin", "mjc_getSDF", "mjp_findProvider",
            "mjp_getProviderAtSlot", "mjp_findDecoder", "mjp_findEncoder"} <= set(CONST_RESULTS)


@pytest.fixture
def plugin():
    mjcffi.MjModel.from_xml_string(PID)          # the plugin libraries are loaded
    slot = mjcffi.mjp_pluginCount() - 1
    while slot >= 0 and mjcffi.mjp_getPluginAtSlot(slot).name != "mujoco.pid":
        slot -= 1
    return mjcffi.mjp_getPluginAtSlot(slot)


@pytest.mark.parametrize("field", ["nattribute", "capabilityflags", "needstage", "name",
                                   "attributes", "init", "unknown"])
def test_a_plugin_from_the_global_table_refuses_every_write(plugin, field):
    before = bytes(mjcffi.ffi.buffer(plugin._ptr, mjcffi.ffi.sizeof("mjpPlugin")))
    with pytest.raises(AttributeError):
        setattr(plugin, field, 5)
    assert bytes(mjcffi.ffi.buffer(plugin._ptr, mjcffi.ffi.sizeof("mjpPlugin"))) == before


def test_a_read_only_plugin_is_still_an_MjpPlugin_and_reads_as_one(plugin):
    assert isinstance(plugin, mjcffi.MjpPlugin)
    assert type(plugin).__name__ == "MjpPlugin"
    assert plugin.name == "mujoco.pid" and plugin.nattribute > 0
    assert "MjpPlugin" in repr(plugin)
    slot = np.zeros(1, np.int32)
    found = mjcffi.mjp_getPlugin("mujoco.pid", slot)
    assert found.name == "mujoco.pid" and isinstance(found, mjcffi.MjpPlugin)
    with pytest.raises(AttributeError):
        found.needstage = 3


def test_the_sdf_plugin_of_a_model_is_read_only():
    xml = """<mujoco><extension><plugin plugin="mujoco.sdf.torus"><instance name="t">
             <config key="radius1" value=".3"/><config key="radius2" value=".1"/></instance>
             </plugin></extension><asset><mesh name="m"><plugin instance="t"/></mesh></asset>
             <worldbody><geom type="sdf" mesh="m"><plugin instance="t"/></geom></worldbody>
             </mujoco>"""
    m = mjcffi.MjModel.from_xml_string(xml)
    sdf = mjcffi.mjc_getSDF(m, 0)
    assert isinstance(sdf, mjcffi.MjpPlugin)
    with pytest.raises(AttributeError, match="const"):
        sdf.nattribute = 0


@pytest.mark.parametrize("cls", [mjcffi.MjpResourceProvider, mjcffi.MjpDecoder,
                                 mjcffi.MjpEncoder, mjcffi.MjpPlugin])
def test_each_struct_a_const_result_can_be_is_read_only_when_wrapped_so(cls):
    """The tables of providers, decoders and encoders are empty in a plain process: their
    read-only wrappers are made over a struct of the type instead."""
    table = cls()
    frozen = wrap_const(cls, table._ptr, table)
    size = mjcffi.ffi.sizeof(cls._cname)
    before = bytes(mjcffi.ffi.buffer(table._ptr, size))
    for field in cls._fields:
        with pytest.raises(AttributeError):
            setattr(frozen, field, 0)
    assert bytes(mjcffi.ffi.buffer(table._ptr, size)) == before
    assert isinstance(frozen, cls)


def test_a_copy_of_a_read_only_struct_is_writable_and_its_arrays_read_only():
    option = mjcffi.MjOption()
    frozen = const_class(mjcffi.MjOption)._wrap(option._ptr, option._root)
    with pytest.raises(AttributeError):
        frozen.timestep = 1.0
    with pytest.raises(ValueError):
        frozen.gravity[0] = 1.0
    assert option.gravity.flags.writeable          # the writable wrapper is untouched
    copy = frozen.__copy__()
    copy.timestep = 0.5
    assert copy.timestep == 0.5 and type(copy) is mjcffi.MjOption
    assert wrap_const(mjcffi.MjOption, mjcffi.ffi.NULL, None) is None
    assert np.array_equal(frozen.gravity, option.gravity)


def test_reproducer_a_write_into_the_global_plugin_table_cannot_crash_the_next_load(
        run_python):
    """Finding 1: `p.nattribute = 10**6` on the global pid plugin, then loading a pid
    model, segfaulted."""
    code, out = run_python(f"""
        import mjcffi
        xml = {PID!r}
        mjcffi.MjModel.from_xml_string(xml)
        slot = mjcffi.mjp_pluginCount() - 1
        while mjcffi.mjp_getPluginAtSlot(slot).name != "mujoco.pid":
            slot -= 1
        p = mjcffi.mjp_getPluginAtSlot(slot)
        try:
            p.nattribute = 10**6
        except AttributeError:
            print("refused")
        m = mjcffi.MjModel.from_xml_string(xml)
        print("loaded", m.nplugin)
        """)
    assert code == 0, out
    assert "refused" in out and "loaded 1" in out
