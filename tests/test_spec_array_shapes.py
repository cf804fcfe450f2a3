"""The shapes a spec element's fixed-array attribute takes, against the official
bindings (issue 36, item 5).

The official setters take an Eigen vector: a sequence or array of shape (n,), or
a column (n, 1) (nested lists [[a], [b], ...] too; sysid's model modifier does
`body.fullinertia = np.full((6, 1), np.nan)`), and refuse (1, n), 3-D arrays,
other lengths, scalars (except the scalable frame.scale), strings, None, ragged
lists, sets and generators with a TypeError (frame.scale: ValueError).  Each input
of the table below goes through both bindings, on every 1-D numeric fixed array
of the elements made here, and both must make the same decision and store the
same values.

Where the official would change a value, mjcffi refuses instead, by design
(`_support/element_fields.py`, `_exactly`): strings ("1" parsed as 1.0), None
(stored as NaN), complex numbers (the imaginary part dropped), and, for int
fields, fractions (1.5 truncated to 1) and NaN (stored as INT_MIN).  Those inputs
are the DEVIATIONS; for them the test checks that the official takes them (so
that the table stays true) and that mjcffi refuses them naming the attribute.

add_* keywords follow other rules in the official (C++ arrays): a column or a
nested list is refused there, and is refused by mjcffi too.
"""

import warnings

import mujoco
import numpy as np
import pytest

import mjcffi
from mjcffi._support.element_fields import _array_length


def _inputs(n):
    """name -> value, for a fixed array of length n (fresh values each call)."""
    base = list(range(1, n + 1))
    column = np.array(base, float).reshape(n, 1)
    return {
        # shapes the official takes
        "list": base,
        "tuple": tuple(base),
        "array (n,)": np.array(base, float),
        "int array (n,)": np.array(base),
        "float32 array (n,)": np.array(base, np.float32),
        "array (n, 1)": column,
        "int array (n, 1)": np.array(base).reshape(n, 1),
        "Fortran array (n, 1)": np.asfortranarray(column),
        "strided array (n,)": np.arange(2 * n, dtype=float)[::2],
        "nested lists [[a], [b], ...]": [[x] for x in base],
        "nested tuples": tuple((x,) for x in base),
        "list of (1,) arrays": [np.array([x]) for x in base],
        "list of numpy scalars": [np.float64(x) for x in base],
        "object array of numbers": np.array(base, dtype=object),
        "bools": [True] * n,
        "bool array": np.ones(n, bool),
        "negative": [-x for x in base],
        "2**40": [2 ** 40] * n,
        "NaN column": np.full((n, 1), np.nan),
        # shapes it refuses
        "array (1, n)": column.T.copy(),
        "nested [[a, b, ...]]": [base],
        "array (n, 1, 1)": column.reshape(n, 1, 1),
        "array (1, n, 1)": column.reshape(1, n, 1),
        "array (1, 1, n)": column.reshape(1, 1, n),
        "length n - 1": base[:-1],
        "length n + 1": base + [9],
        "array (n - 1, 1)": column[:-1],
        "array (n, 2)": np.ones((n, 2)),
        "array (2n,)": np.ones(2 * n),
        "array (2n, 1)": np.ones((2 * n, 1)),
        "empty list": [],
        "empty array": np.zeros(0),
        "float": 5.0,
        "int": 5,
        "numpy scalar": np.float64(5),
        "0-d array": np.array(5.0),
        "str": "abc",
        "str of n digits": "1" * n,
        "bytes": b"a",
        "None": None,
        "ragged nested lists": [[1, 2]] + [[x] for x in base[1:]],
        "nested and flat mixed": [[1]] + base[1:],
        "dict": {i: i for i in range(n)},
        "set": set(base),
        "generator": (x for x in base),
        # values the official changes, mjcffi refuses: DEVIATIONS
        "list of str": ["1"] * n,
        "str array": np.array(["1"] * n),
        "complex array": np.ones(n, complex),
        "list of None": [None] * n,
        "fractions": [x + 0.5 for x in base],
    }


def _deviations(integer):
    """The inputs that the official takes by changing a value and mjcffi refuses."""
    found = {"list of str", "str array", "complex array"}
    found |= {"fractions", "NaN column"} if integer else {"list of None"}
    return found


# kind -> make(a spec of either binding): the same element in both
_MAKERS = {
    "body": lambda s: s.worldbody.add_body(),
    "frame": lambda s: s.worldbody.add_frame(),
    "joint": lambda s: s.worldbody.add_body().add_joint(),
    "geom": lambda s: s.worldbody.add_geom(),
    "site": lambda s: s.worldbody.add_site(),
    "camera": lambda s: s.worldbody.add_camera(),
    "light": lambda s: s.worldbody.add_light(),
    "actuator": lambda s: s.add_actuator(),
    "sensor": lambda s: s.add_sensor(),
    "tendon": lambda s: s.add_tendon(),
    "equality": lambda s: s.add_equality(),
    "material": lambda s: s.add_material(),
    "texture": lambda s: s.add_texture(),
    "mesh": lambda s: s.add_mesh(),
    "hfield": lambda s: s.add_hfield(),
    "flex": lambda s: s.add_flex(),
    "skin": lambda s: s.add_skin(),
    "pair": lambda s: s.add_pair(),
    "key": lambda s: s.add_key(),
    "compiler": lambda s: s.compiler,
}


def _attributes():
    """(kind, attribute, length, integer) of every 1-D numeric fixed array of the
    elements of _MAKERS, as mjcffi's classes declare them."""
    spec = mjcffi.MjSpec()
    found = []
    for kind, make in _MAKERS.items():
        cls = type(make(spec))
        for attr in cls._fields:
            field = getattr(cls, attr, None)
            length = _array_length(field)
            if length is not None:
                found.append((kind, attr, length, field.dtype.kind in "iu"))
    return found


ATTRIBUTES = _attributes()


def _outcome(element, attr, value):
    """('ok', stored values as a list) or (exception, message)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")           # the official's ComplexWarning
            setattr(element, attr, value)
    except Exception as exc:                          # noqa: BLE001  (compared below)
        return exc, str(exc)
    return "ok", np.asarray(getattr(element, attr)).tolist()


def _same(a, b):
    return np.array_equal(np.asarray(a, float), np.asarray(b, float), equal_nan=True)


def test_the_table_covers_many_attributes_and_both_int_and_float_ones():
    assert len(ATTRIBUTES) > 60
    assert any(integer for *_, integer in ATTRIBUTES)
    assert {"fullinertia", "pos", "quat", "size", "rgba", "range", "gear", "resolution",
            "scale"} <= {attr for _, attr, _, _ in ATTRIBUTES}


@pytest.mark.parametrize("kind,attr,length,integer", ATTRIBUTES,
                         ids=[f"{k}.{a}" for k, a, _, _ in ATTRIBUTES])
def test_an_attribute_takes_and_refuses_what_the_official_does(kind, attr, length, integer):
    ours = _MAKERS[kind](mjcffi.MjSpec())
    theirs = _MAKERS[kind](mujoco.MjSpec())
    assert hasattr(theirs, attr), f"the official {type(theirs).__name__} has no {attr}"
    deviations = _deviations(integer)
    where = f"{type(ours).__name__}.{attr}"
    # fresh inputs for each binding: a generator is used up by one
    mine_inputs, official_inputs = _inputs(length), _inputs(length)
    start = list(range(length, 0, -1))
    for name, value in mine_inputs.items():
        for element in (ours, theirs):                # the same value before each input
            setattr(element, attr, start)
        official = _outcome(theirs, attr, official_inputs[name])
        mine = _outcome(ours, attr, value)
        case = (where, name, official[1], mine[1])
        if name in deviations and official[0] == "ok":
            assert isinstance(mine[0], TypeError) and where in mine[1], case
        elif official[0] == "ok":
            assert mine[0] == "ok" and _same(mine[1], official[1]), case
        else:
            # the same kind of error: TypeError (ValueError for frame.scale)
            assert isinstance(mine[0], type(official[0])), case
            assert where in mine[1], case
        if mine[0] != "ok":                           # a refusal changes nothing
            assert getattr(ours, attr).tolist() == start, case


def test_a_refusal_names_the_attribute_and_the_shapes_it_takes():
    body = mjcffi.MjSpec().worldbody.add_body()
    with pytest.raises(TypeError) as info:
        body.fullinertia = np.ones((1, 6))
    assert str(info.value) == ("MjsBody.fullinertia takes a list/array of size 6 "
                               "(shape (6,) or (6, 1)), not shape (1, 6)")
    with pytest.raises(TypeError, match=r"MjsBody.pos takes real numbers, not str"):
        body.pos = ["1", "2", "3"]
    with pytest.raises(TypeError, match=r"MjsBody.pos takes real numbers, not NoneType"):
        body.pos = [None, 1, 2]
    with pytest.raises(ValueError, match=r"MjsFrame.scale takes a scalar or a list/array "
                                         r"of size 3 \(shape \(3,\) or \(3, 1\)\), not shape"):
        body.add_frame().scale = [1, 2]


def test_sysid_sets_fullinertia_from_a_nan_column():
    """What sysid's model modifier does (mujoco/sysid), then compiles as the official."""
    specs = mjcffi.MjSpec(), mujoco.MjSpec()
    for spec in specs:
        body = spec.worldbody.add_body(name="b", mass=1)
        body.add_geom(size=[0.1, 0, 0])
        body.add_joint()
        body.fullinertia = np.full((6, 1), np.nan)
        body.inertia = np.array([[1.0], [2.0], [3.0]])
        body.explicitinertial = True
    ours, theirs = specs[0].worldbody.bodies[0], specs[1].worldbody.bodies[0]
    assert _same(ours.fullinertia, theirs.fullinertia) and np.isnan(ours.fullinertia).all()
    assert ours.inertia.tolist() == theirs.inertia.tolist() == [1, 2, 3]
    np.testing.assert_array_equal(mjcffi.mj_compile(specs[0], None).body_inertia,
                                  specs[1].compile().body_inertia)


@pytest.mark.parametrize("value", [np.ones((3, 1)), [[1], [2], [3]], [np.array([1])] * 3,
                                   np.ones((1, 3))],
                         ids=["column", "nested lists", "list of (1,) arrays", "row"])
def test_add_keywords_refuse_a_column_as_the_official(value):
    for spec in (mjcffi.MjSpec(), mujoco.MjSpec()):
        with pytest.raises(TypeError):
            spec.worldbody.add_body(pos=value)
        with pytest.raises(TypeError):
            spec.worldbody.add_geom(size=value)
    body = mjcffi.MjSpec().worldbody.add_body()
    with pytest.raises(TypeError, match=r"MjsBody.pos as a keyword takes a flat"):
        body.add_body(pos=np.ones((3, 1)))
    assert len(body.bodies) == 0                      # the refused body was deleted
