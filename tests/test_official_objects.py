"""Objects of the official bindings meet mjcffi.

- Passed to an mjcffi function, an official MjModel, MjData, MjvOption, ... raises a
  TypeError that names its module and says what to do: both bindings' classes are
  called MjModel, and "m must be MjModel, not MjModel" said nothing
  (mjcffi/_support/official.py).
- Under `sys.modules['mujoco'] = mjcffi`, an official pickle of an MjModel or MjData
  names `mujoco._structs`, which is then mjcffi._structs: it loads into mjcffi
  objects with the official's field values (mjcffi/_support/official_pickle.py),
  and bytes the official format does not describe raise ValueError.  These run in a
  subprocess: the swap changes sys.modules.
"""

import re

import numpy as np
import pytest

import mjcffi

XML = """<mujoco><worldbody><body><joint name="j"/><geom size=".1" mass="1"/></body>
         </worldbody><actuator><motor joint="j"/></actuator></mujoco>"""


@pytest.fixture
def both(mujoco):
    """(official m, official d, mjcffi m, mjcffi d)."""
    m = mujoco.MjModel.from_xml_string(XML)
    mm = mjcffi.MjModel.from_xml_string(XML)
    return m, mujoco.MjData(m), mm, mjcffi.MjData(mm)


def _calls(mujoco, m, d, mm, md):
    """(label, call, argument name, official class path) of calls given official objects."""
    point = np.zeros(3)
    return [
        ("mj_step m", lambda: mjcffi.mj_step(m, md), "m", "mujoco._structs.MjModel"),
        ("mj_step d", lambda: mjcffi.mj_step(mm, d), "d", "mujoco._structs.MjData"),
        ("mj_forward", lambda: mjcffi.mj_forward(m, d), "m", "mujoco._structs.MjModel"),
        ("mj_jac", lambda: mjcffi.mj_jac(mm, d, None, None, point, 0), "d",
         "mujoco._structs.MjData"),
        ("mj_jac.prepare", lambda: mjcffi.mj_jac.prepare(m, md, None, None, point, 0), "m",
         "mujoco._structs.MjModel"),
        ("mj_name2id", lambda: mjcffi.mj_name2id(m, 1, "x"), "m", "mujoco._structs.MjModel"),
        ("MjData(m)", lambda: mjcffi.MjData(m), "model", "mujoco._structs.MjModel"),
        ("MjvScene(m)", lambda: mjcffi.MjvScene(m, 10), "model", "mujoco._structs.MjModel"),
        ("rollout", lambda: mjcffi.rollout.rollout(m, md, np.zeros((1, 3))), "model",
         "mujoco._structs.MjModel"),
        ("rollout list", lambda: mjcffi.rollout.rollout([mm, m], md, np.zeros((2, 3))),
         r"model\[1\]", "mujoco._structs.MjModel"),
        ("mjv_updateScene opt", lambda: mjcffi.mjv_updateScene(
            mm, md, mujoco.MjvOption(), None, mjcffi.MjvCamera(), 0, mjcffi.MjvScene(mm, 10)),
         "opt", "mujoco._structs.MjvOption"),
        ("mjv_updateScene scn", lambda: mjcffi.mjv_updateScene(
            mm, md, mjcffi.MjvOption(), None, mjcffi.MjvCamera(), 0, mujoco.MjvScene(m, 10)),
         "scn", "mujoco._structs.MjvScene"),
        ("mjr_setBuffer", lambda: mjcffi.mjr_setBuffer(0, mujoco.MjrContext()), "con",
         "mujoco._render.MjrContext"),
        ("Renderer", lambda: mjcffi.Renderer(m), "model", "mujoco._structs.MjModel"),
        ("the class", lambda: mjcffi.mj_step(mujoco.MjModel, md), "m",
         "the class mujoco._structs.MjModel itself"),
        ("mj_saveXMLString", lambda: mjcffi.mj_saveXMLString(mujoco.MjSpec()), "s",
         "mujoco._specs.MjSpec"),
        ("bind", lambda: mm.bind(mujoco.MjSpec().worldbody), "the element",
         "mujoco._specs.MjsBody"),
    ]


def test_an_official_object_is_named_with_its_module(mujoco, both):
    failures = []
    for label, call, name, what in _calls(mujoco, *both):
        try:
            call()
        except TypeError as error:
            text = str(error)
            if not (re.match(rf"{name} must be an mjcffi[. ]", text) and f"not {what}" in text
                    and "objects of the official bindings are not accepted here" in text
                    and "pass mjcffi objects" in text):
                failures.append(f"{label}: {text}")
        else:
            failures.append(f"{label}: no TypeError")
    assert not failures, "\n".join(failures)


def test_the_message_says_how_to_get_an_mjcffi_model(mujoco, both):
    m, d, mm, md = both
    with pytest.raises(TypeError) as caught:
        mjcffi.mj_step(m, d)
    assert str(caught.value) == (
        "m must be an mjcffi.MjModel, not mujoco._structs.MjModel: objects of the official "
        "bindings are not accepted here; load the model with mjcffi (mjcffi.MjModel."
        "from_xml_path / from_binary_path / from_xml_string), or pass mjcffi objects; "
        "mjcffi.MjModel.from_official(m) views an official one without a copy")


def test_other_wrong_types_keep_their_short_message(both):
    m, d, mm, md = both
    with pytest.raises(TypeError, match=r"^m must be MjModel, not int$"):
        mjcffi.mj_step(3, md)
    with pytest.raises(TypeError, match=r"^d must be MjData, not MjModel$"):
        mjcffi.mj_step(mm, mm)


# ------------------------------------------------------------- official pickles

_SWAP = """
import pickle, sys, importlib.resources
import numpy as np
import mujoco as official
folder = importlib.resources.files("gymnasium") / "envs" / "mujoco" / "assets"

def made(name, steps, solver=None):
    m = official.MjModel.from_xml_string((folder / name).read_text())
    if solver is not None:
        m.opt.solver = solver
    d = official.MjData(m)
    d.ctrl[:] = 0.3
    official.mj_step(m, d, steps)
    return m, d

cases = {{"humanoid": made("humanoid.xml", 60), "ant": made("ant.xml", 40),
          "hopper PGS": made("hopper.xml", 30, official.mjtSolver.mjSOL_PGS),
          "fresh": made("walker2d.xml", 0)}}
pickles = {{k: (pickle.dumps(m), pickle.dumps(d)) for k, (m, d) in cases.items()}}
# what the official bindings themselves unpickle: the reference
expected = {{k: (pickle.loads(pm), pickle.loads(pd)) for k, (pm, pd) in pickles.items()}}
step = official.mj_step

import mjcffi
for name in [k for k in sys.modules if k == "mujoco" or k.startswith("mujoco.")]:
    del sys.modules[name]
sys.modules["mujoco"] = mjcffi
{body}
"""


_COMPARE = """
def fields(obj):
    out = {}
    for name in dir(obj):
        if name.startswith("_") or name in ("signature", "plugin_data"):
            continue
        try:
            value = getattr(obj, name)
        except Exception:
            continue
        if isinstance(value, (np.ndarray, int, float)) and not isinstance(value, bool):
            out[name] = value
    return out

def differ(a, b):
    fa, fb = fields(a), fields(b)
    bad = [n for n in fa if n not in fb]
    for n in fa:
        if n in fb:
            x, y = np.asarray(fa[n]), np.asarray(fb[n])
            if x.shape != y.shape or not np.array_equal(x, y, equal_nan=True):
                bad.append(n)
    return bad, len(fa)
"""


def test_official_pickles_load_under_the_swap_with_the_official_values(run_python):
    code, out = run_python(_SWAP.format(body=_COMPARE + """
import mujoco._structs as structs
assert structs is mjcffi._structs, structs
assert structs.MjModel is mjcffi.MjModel and structs.MjData is mjcffi.MjData
for key, (pm, pd) in pickles.items():
    m2, d2 = pickle.loads(pm), pickle.loads(pd)
    assert type(m2) is mjcffi.MjModel and type(d2) is mjcffi.MjData, (type(m2), type(d2))
    em, ed = expected[key]
    bad_m, nm = differ(em, m2)
    bad_d, nd = differ(ed, d2)
    print(key, "model fields", nm, "differ", bad_m)
    print(key, "data fields", nd, "differ", bad_d, "ncon", d2.ncon, "nefc", d2.nefc,
          "nisland", d2.nisland)
    contacts = ed.contact, d2.contact
    print(key, "contacts same", all(np.array_equal(getattr(contacts[0], f), getattr(contacts[1], f))
                                     for f in ("pos", "frame", "dist", "geom", "efc_address")))
    # both step on alike
    step(em, ed, 5)
    mjcffi.mj_step(d2.model, d2, 5)
    print(key, "stepped same", np.array_equal(ed.qpos, d2.qpos) and
          np.array_equal(ed.qvel, d2.qvel) and ed.time == d2.time)
"""))
    assert code == 0, out
    for key in ("humanoid", "ant", "hopper PGS", "fresh"):
        assert f"{key} model fields" in out and f"{key} data fields" in out, out
    assert "differ [" in out and not re.search(r"differ \['", out), out
    assert out.count("contacts same True") == 4, out
    assert out.count("stepped same True") == 4, out
    assert re.search(r"humanoid data fields \d+ differ \[\] ncon [1-9]", out), out


@pytest.mark.parametrize("cls", ["MjModel", "MjData"])
def test_official_states_of_other_bytes_raise_valueerror(mujoco, cls):
    """What __setstate__ reads when the swap sends an official pickle to mjcffi: bytes
    cut short, of another version, with bytes after, or none, raise ValueError."""
    m = mujoco.MjModel.from_xml_string(XML)
    d = mujoco.MjData(m)
    mujoco.mj_step(m, d, 3)
    state = (m if cls == "MjModel" else d).__getstate__()
    assert isinstance(state, bytes) and state[0] == 1
    target = getattr(mjcffi, cls)
    loaded = target.__new__(target)
    loaded.__setstate__(state)                  # the bytes themselves load
    assert loaded.nq == 1 if cls == "MjModel" else loaded.time == d.time
    for label, bad in (("cut", state[:-9]), ("version", b"\x07" + state[1:]),
                       ("padded", state + b"\x00"), ("empty", b""),
                       ("sizes", state[:1] + b"\xff" * 8 + state[9:])):
        with pytest.raises(ValueError) as caught:
            target.__new__(target).__setstate__(bad)
        text = str(caught.value)
        assert text.startswith(("Invalid serialized", "Incompatible serialization")), (label, text)
        assert "pickle it under mjcffi" in " ".join(getattr(caught.value, "__notes__", ())), \
            (label, caught.value.__notes__)


def test_the_format_tables_match_the_installed_headers(mujoco_include):
    from mjcffi._support import official_pickle
    text = (mujoco_include / "mujoco" / "mjxmacro.h").read_text()

    def names(macro):
        body = text[text.index(f"#define {macro}"):]
        return tuple(re.findall(r"X\w*\s*\(\s*\w+\s*,\s*(\w+)", body[:body.index("\n\n")]))

    for block, fields in official_pickle.ARENA.items():
        assert names(f"MJDATA_ARENA_POINTERS_{block}") == fields, block
    assert names("MJDATA_POINTERS") == official_pickle.POINTERS
    ffi, lib = mjcffi.ffi, mjcffi.lib
    assert lib.mjcffi_data_layout_size() == 16 + 8 * len(official_pickle.ARENA_ORDER)
    scalars = dict(ffi.typeof("mjData").fields)
    assert all(name in scalars for name in official_pickle.SCALARS)


def test_mjcffi_pickles_do_not_pass_through_the_official_reader():
    m = mjcffi.MjModel.from_xml_string(XML)
    d = mjcffi.MjData(m)
    mjcffi.mj_step(m, d, 3)
    import pickle
    blob = pickle.dumps(d)
    assert b"mujoco._structs" not in blob
    again = pickle.loads(blob)
    assert again.time == d.time and np.array_equal(again.qpos, d.qpos)
    with pytest.raises(ValueError, match="made already"):
        d.__setstate__(b"\x01")
    with pytest.raises(TypeError, match="must be bytes"):
        mjcffi.MjModel.__new__(mjcffi.MjModel).__setstate__({"a": 1})
