"""Tests that kill the deliberate bugs (mutants) the suite let through (issue 11).

`python -m tests.mutants` applies each mutant of its list to a copy of the
tree and runs the tests named to catch it.  This file holds the tests that
were missing: every id check of the function layer at its bounds, derived
from the generator's id table (codegen.functions.IDS) so that it grows with
it; the object ids of mj_objectVelocity/mj_objectAcceleration; and the bound
of a sparse (CSR) structure, whose off-by-one no other test would notice.
Named access to the plastic state has its own file, test_named_plastic.py.
"""

import inspect
import json
import keyword
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

import mjcffi
from mjcffi import _functions
from codegen import functions as codegen_functions

REPO = pathlib.Path(__file__).resolve().parent.parent

# Every count the id table uses is nonzero here: bodies, geoms (one of them a
# mesh and one an hfield), sites, a flex, a texture, actuators, sensors and, after
# mj_forward, contacts.
MODEL = """
<mujoco>
  <asset>
    <mesh name="tet" vertex="0 0 0  1 0 0  0 1 0  0 0 1"/>
    <hfield name="hill" nrow="3" ncol="3" size="1 1 .1 .1"/>
    <texture name="grid" type="2d" builtin="checker" width="8" height="8"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 .1"/>
    <geom name="terrain" type="hfield" hfield="hill" pos="5 0 0"/>
    <site name="origin"/>
    <body name="ball" pos="0 0 .05">
      <freejoint/>
      <geom name="ball" size=".1"/>
      <site name="top" pos="0 0 .1"/>
    </body>
    <body name="arm" pos="1 0 1">
      <joint name="hinge"/>
      <geom name="tet" type="mesh" mesh="tet"/>
    </body>
    <flexcomp name="cloth" type="grid" count="2 2 1" spacing=".1 .1 .1" dim="2" radius=".01"
              pos="0 3 1">
      <edge equality="true"/>
    </flexcomp>
  </worldbody>
  <actuator><motor name="m" joint="hinge"/><motor name="m2" joint="hinge"/></actuator>
  <sensor><jointpos name="q" joint="hinge"/><framepos name="p" objtype="site" objname="top"/></sensor>
</mujoco>
"""


def _py_name(func, c_name):
    """The Python parameter of C argument `c_name` (a keyword gets a trailing _)."""
    params = inspect.signature(func).parameters
    name = c_name + "_" if keyword.iskeyword(c_name) else c_name
    assert name in params, (func.__name__, c_name, list(params))
    return name


def _struct_arguments(func, m, d):
    """Parameter -> a struct of its type, as the official signature in the docstring
    names it: m, d, or a new default one."""
    first = (func.__doc__ or "").split("\n", 1)[0]
    found = {}
    for name, cls in re.findall(r"(\w+): mujoco\._structs\.(\w+)", first):
        found[name] = m if cls == "MjModel" else d if cls == "MjData" else getattr(mjcffi, cls)()
    return found


def _sweep():
    """Call every id-checked function with each of its ids at low-1, low, count-1 and
    count, its structs valid, its other ids valid, its sizes (KEEP) 1 and every other
    argument None, so that no call with a valid id reaches MuJoCo with bad
    arguments; print {case: the exception's class names, [] if none}."""
    m = mjcffi.MjModel.from_xml_string(MODEL)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    assert d.ncon > 0
    scope = {"m": m, "d": d}
    results = {}
    for fname, ids in sorted(codegen_functions.IDS.items()):
        func = getattr(mjcffi, fname)
        structs = _struct_arguments(func, m, d)
        bounds = {c: (low, int(eval(count, scope))) for c, (low, count) in ids.items()}
        for c_name, (low, count) in bounds.items():
            assert count > low, (fname, c_name, count)
            for label, value in (("low-1", low - 1), ("low", low), ("count-1", count - 1),
                                 ("count", count)):
                if fname == "mju_threadpool" and label in ("low", "count-1"):
                    continue            # a valid call: it would start the threads
                kwargs = dict.fromkeys(inspect.signature(func).parameters)
                kwargs.update(structs)
                for size in codegen_functions.KEEP.get(fname, ()):
                    kwargs[size] = 1            # sizes the caller passes are checked first
                for other, (other_low, _) in bounds.items():
                    kwargs[_py_name(func, other)] = other_low
                kwargs[_py_name(func, c_name)] = value
                try:
                    func(**kwargs)
                    outcome = []
                except BaseException as exc:      # noqa: BLE001  (reported, then judged)
                    outcome = [cls.__name__ for cls in type(exc).__mro__]
                results[f"{fname}({c_name}={label})"] = outcome
    print(json.dumps(results))


@pytest.fixture(scope="module")
def id_sweep():
    # in a subprocess: a broken bound would hand MuJoCo an id out of range
    run = subprocess.run([sys.executable, "-c",
                          "from tests.test_mutation_gaps import _sweep; _sweep()"],
                         cwd=REPO, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    return json.loads(run.stdout.strip().splitlines()[-1])


def test_item_mutants_the_id_table_is_swept(id_sweep):
    expected = sum(len(ids) for ids in codegen_functions.IDS.values())
    assert len({case.split("=")[0] for case in id_sweep}) == expected
    assert "mj_jac(body=count)" in id_sweep


def test_item_mutants_an_id_at_its_count_or_below_its_lowest_raises_iderror(id_sweep):
    # mj_jac(body=nbody) would read past the model's arrays: id == count is the
    # first value out of range, and an `<=` in the check lets it through.
    wrong = {case: outcome for case, outcome in id_sweep.items()
             if case.endswith(("=count)", "=low-1)")) and "IdError" not in outcome}
    assert not wrong, wrong
    for case, outcome in id_sweep.items():
        if "IdError" in outcome:
            assert {"IndexError", "ValueError"} <= set(outcome), case


def test_item_mutants_ids_within_range_pass_the_id_check(id_sweep):
    # with the other arguments None, a valid id fails later, on those arguments
    wrong = {case: outcome for case, outcome in id_sweep.items()
             if case.endswith(("=count-1)", "=low)")) and "IdError" in outcome}
    assert not wrong, wrong


def test_item_mutants_every_id_of_the_table_is_checked_in_the_generated_code():
    # the slow path (_F) converts and checks each id; a fast path in F tests its range
    for fname, ids in codegen_functions.IDS.items():
        slow = inspect.getsource(getattr(_functions, "_" + fname))
        public = inspect.getsource(getattr(_functions, fname))
        for c_name, (low, _) in ids.items():
            py = _py_name(getattr(_functions, fname), c_name)
            assert re.search(rf"_m\.index\({py}, ", slow), (fname, c_name)
            if "fast = (" in public:
                assert re.search(rf"{py}\.__class__ is _int\s+and {low} <= {py} < ", public), \
                    (fname, c_name)


# The checks below call MuJoCo with an argument just out of range, which only
# the check under test stands in front of: each runs in a subprocess, so that a
# broken check fails its test instead of crashing pytest.

def _isolated(check, *args):
    """Run `check(*args)`, a function of this module, in a fresh interpreter."""
    code = (f"from tests.test_mutation_gaps import {check}; {check}(*{args!r}); "
            f"print('checked')")
    run = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0 and run.stdout.strip().endswith("checked"), \
        f"exit status {run.returncode}\n{run.stderr[-3000:]}"


def _raises(exc_type, func, *args, match=None):
    """pytest.raises for the subprocesses: `func(*args)` raises `exc_type`."""
    try:
        func(*args)
    except exc_type as exc:
        assert match is None or re.search(match, str(exc)), str(exc)
        return
    raise AssertionError(f"{getattr(func, '__name__', func)} with {args[2:]!r} "
                         f"raised no {exc_type.__name__}")


def _check_mj_jac_body():
    m = mjcffi.MjModel.from_xml_string(MODEL)
    d = mjcffi.MjData(m)
    jacp = np.zeros((3, m.nv))
    _raises(mjcffi.IdError, mjcffi.mj_jac, m, d, jacp, None, np.zeros(3), m.nbody,
            match=rf"body={m.nbody} is out of range")
    mjcffi.mj_jac(m, d, jacp, None, np.zeros(3), m.nbody - 1)


def test_item_mutants_mj_jac_body_nbody_raises():
    _isolated("_check_mj_jac_body")


def _check_object_ids():
    m = mjcffi.MjModel.from_xml_string(MODEL)
    d = mjcffi.MjData(m)
    mjcffi.mj_forward(m, d)
    obj, res = mjcffi.mjtObj, np.zeros(6)
    for func in (mjcffi.mj_objectVelocity, mjcffi.mj_objectAcceleration):
        for objtype, count in ((obj.mjOBJ_BODY, m.nbody), (obj.mjOBJ_XBODY, m.nbody),
                               (obj.mjOBJ_GEOM, m.ngeom), (obj.mjOBJ_SITE, m.nsite),
                               (obj.mjOBJ_CAMERA, m.ncam)):
            for bad in (count, -1):
                _raises(mjcffi.IdError, func, m, d, objtype, bad, res, 0)
            if count:
                func(m, d, objtype, count - 1, res, 0)


def test_item_mutants_object_ids_are_checked_against_their_type():
    # mj_objectVelocity and mj_objectAcceleration, for each object type they take
    _isolated("_check_object_ids")


# A 2x3 matrix with four nonzeros: rows [0 1 .] and [. 1 2].
def _csr(rowadr=(0, 2), rownnz=(2, 2), colind=(0, 1, 1, 2)):
    return dict(mat=np.array([1.0, 2.0, 3.0, 4.0]), rownnz=np.array(rownnz, np.int32),
                rowadr=np.array(rowadr, np.int32), colind=np.array(colind, np.int32))


def test_item_mutants_a_sparse_structure_may_end_at_its_last_element():
    res = np.zeros((2, 3))
    mjcffi.mju_sparse2dense(res, **_csr())
    np.testing.assert_array_equal(res, [[1, 2, 0], [0, 3, 4]])


def _check_csr_past_the_end():
    # each row structure reaches element 5 of the 4 given
    for rowadr, rownnz in (((0, 3), (2, 2)), ((0, 2), (2, 3)), ((0, 4), (2, 1))):
        bad = _csr(rowadr, rownnz)
        _raises(ValueError, lambda: mjcffi.mju_sparse2dense(np.zeros((2, 3)), **bad),
                match="beyond the 4 given")
        bad = _csr(rowadr, rownnz, colind=(0, 0, 1, 1))
        _raises(ValueError, lambda: mjcffi.mju_sym2dense(np.zeros((2, 2)), **bad),
                match="beyond the 4 given")


def test_item_mutants_a_sparse_structure_one_element_past_the_matrix_is_refused():
    # rowadr + rownnz reaching nnz + 1 would read mat and colind one past their end
    _isolated("_check_csr_past_the_end")
