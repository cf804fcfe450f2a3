"""The generated struct metadata: C types, kinds and array extents."""

import math

import numpy as np
import pytest

from mjcffi._generated import structinfo as _structinfo
from mjcffi import mjtTextureRole, mjtWarning

from .conftest import gymnasium_assets

STRUCTS = _structinfo.STRUCTS


def _field(struct, name):
    return next(f for f in STRUCTS[struct] if f.name == name)


def test_headline_structs_are_described():
    for name in ("mjModel", "mjData", "mjOption", "mjVisual", "mjStatistic", "mjContact",
                 "mjWarningStat", "mjSolverStat", "mjTimerStat", "mjLROpt", "mjvScene",
                 "mjvOption", "mjvCamera", "mjvPerturb", "mjvGeom", "mjvLight", "mjvFigure",
                 "mjrContext", "mjrRect", "mjVisual.global", "mjBatchConfig"):
        assert STRUCTS[name], name


@pytest.mark.parametrize("struct, name, expected", [
    ("mjModel", "nq", ("mjtSize", "scalar", "mjtSize", ())),
    ("mjModel", "qpos0", ("mjtNum *", "pointer", "mjtNum", ("m.nq", 1))),
    ("mjModel", "body_user", ("mjtNum *", "pointer", "mjtNum", ("m.nbody", "m.nuser_body"))),
    ("mjModel", "key_mpos", ("mjtNum *", "pointer", "mjtNum", ("m.nkey", "m.nmocap*3"))),
    ("mjModel", "opt", ("mjOption", "struct", "mjOption", ())),
    ("mjData", "xpos", ("mjtNum *", "pointer", "mjtNum", ("m.nbody", 3))),
    ("mjData", "contact", ("mjContact *", "pointer", "mjContact", ("d.ncon", 1))),
    ("mjData", "efc_J", ("mjtNum *", "pointer", "mjtNum", ("d.nJ", 1))),
    ("mjData", "warning", ("mjWarningStat [mjNWARNING]", "array", "mjWarningStat",
                           (int(mjtWarning.mjNWARNING),))),
    ("mjData", "time", ("mjtNum", "scalar", "mjtNum", ())),
    ("mjData", "eq_active", ("mjtBool *", "pointer", "mjtBool", ("m.neq", 1))),
    ("mjOption", "gravity", ("mjtNum [3]", "array", "mjtNum", (3,))),
    ("mjVisual", "global", ("struct", "struct", "mjVisual.global", ())),
    ("mjvScene", "geoms", ("mjvGeom *", "pointer", "mjvGeom", ("self.ngeom",))),
    ("mjvFigure", "linedata", ("float [100][2 * 1001]", "array", "float", (100, 2002))),
    ("mjModel", "geom_solref", ("mjtNum *", "pointer", "mjtNum", ("m.ngeom", 2))),
    ("mjModel", "mat_texid", ("int *", "pointer", "int", ("m.nmat", int(mjtTextureRole.mjNTEXROLE)))),
])
def test_known_fields(struct, name, expected):
    field = _field(struct, name)
    assert (field.ctype, field.kind, field.elem, field.extents) == expected


def test_field_docs_come_from_the_header_comments():
    assert _field("mjModel", "body_pos").doc == "position offset rel. to parent body"
    assert _field("mjVisual.global", "fovy").doc.startswith("y field-of-view")


def test_anonymous_union_members_are_lifted():
    names = [f.name for f in STRUCTS["mjuiItem"]]
    assert {"single", "multi", "slider", "edit"} <= set(names)
    assert "" not in names


def test_model_and_data_pointers_all_have_extents():
    for struct in ("mjModel", "mjData"):
        unknown = [f.name for f in STRUCTS[struct] if f.kind == "pointer" and not f.extents
                   and f.elem != "void"]
        assert unknown == [], struct


def _size(extents, m, d):
    return math.prod(e if isinstance(e, int) else eval(e, {}, {"m": m, "d": d})
                     for e in extents)


@pytest.mark.parametrize("path", gymnasium_assets(), ids=lambda p: p.stem)
def test_extents_give_the_official_array_sizes(mujoco, path):
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mujoco.mj_step(m, d)            # contacts and constraints give arena sizes
    compared = 0
    for struct, owner in (("mjModel", m), ("mjData", d)):
        for field in STRUCTS[struct]:
            if field.kind != "pointer" or not field.extents or not hasattr(owner, field.name):
                continue
            official = getattr(owner, field.name)
            if field.elem in ("mjContact", "char"):   # official: a sequence, or bytes
                size = len(official)
            else:
                size = np.asarray(official).size
            assert _size(field.extents, m, d) == size, f"{struct}.{field.name}"
            compared += 1
    assert compared > 400
