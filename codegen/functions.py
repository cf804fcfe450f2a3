"""Write mjcffi/_functions/: one Python function per function of mujoco.h and mjbatch.h.

Each function converts its arguments with mjcffi/_support/marshal.py, calls the
guarded twin `lib.mjcffi_guard_F` (so that mju_error raises FatalError) and
converts the result.  The rules are generic, driven by the C declaration and
the header's `Nullable:` notes:

- struct pointers take the wrapper classes; `const char *` takes str;
- numeric pointers are arrays: inputs are converted, outputs must be writable
  C-contiguous arrays of the exact dtype; fixed extents (`mjtNum res[3]`)
  come from the declaration, all other extents from SHAPES below;
- size arguments named as an extent in SHAPES are deduced from the arrays and
  leave the Python signature, as in the official bindings (mju_add(res, vec1,
  vec2)); `(char* error, int error_sz)` pairs leave it too (ERRORS);
- a function whose arguments the rules cannot express safely must have an
  entry in OVERRIDES (hand-written in mjcffi/functions/_overrides.py) or UNSUPPORTED
  (it raises NotImplementedError); codegen fails otherwise.

The tables below are the only special cases.
"""

import keyword
import re
import textwrap
from collections.abc import Mapping
from dataclasses import dataclass

from . import outputs
from .fastpath import FastPath
from .structs import class_name

# ------------------------------------------------------------------ tables

# Extents of pointer arguments that the declaration does not give, as
# comma-separated dims.  A dim is a number, a #define or enum constant, a size
# argument of the function (deduced from the first array that has it alone,
# or K*it, in its dims, then left out of the Python signature unless listed in
# KEEP), or a Python expression over the arguments: `m.nv` reads the model,
# `state_size(m, sig)` calls a helper of mjcffi/_support/marshal.py.  "*": any size
# (checked by a CHECKS entry).  For `void *` and `char *` buffers the dim is
# the byte count.
SHAPES = {
    "mj_addBufferVFS": {"buffer": "nbuffer"},
    "mj_defaultSolRefImp": {"solref": "mjNREF", "solimp": "mjNIMP"},
    "mj_saveModel": {"buffer": "buffer_sz"},
    "mju_printMat": {"mat": "nr, nc"},
    "mju_printMatSparse": {"mat": "*", "rownnz": "nr", "rowadr": "nr", "colind": "*"},
    "mj_solveM": {"x": "n, m.nv", "y": "n, m.nv"},
    "mj_solveM2": {"x": "n, m.nv", "y": "n, m.nv", "sqrtInvD": "m.nv"},
    "mj_rne": {"result": "m.nv"},
    "mj_constraintUpdate": {"jar": "d.nefc"},
    "mj_getState": {"state": "state_size(m, sig)"},
    "mj_extractState": {"src": "state_size(m, srcsig, 'srcsig')",
                        "dst": "state_size(m, dstsig, 'dstsig')"},
    "mj_setState": {"state": "state_size(m, sig)"},
    "mj_readCtrl": {"result": "m.actuator_ctrlnum[id]"},
    "mj_readSensor": {"result": "m.sensor_dim[id]"},
    "mj_initCtrlHistory": {"times": "m.actuator_history[2*id]",
                           "values": "m.actuator_history[2*id], m.actuator_ctrlnum[id]"},
    "mj_initSensorHistory": {"times": "m.sensor_history[2*id]",
                             "values": "m.sensor_history[2*id], m.sensor_dim[id]"},
    "mj_mulJacVec": {"res": "d.nefc", "vec": "m.nv"},
    "mj_mulJacTVec": {"res": "m.nv", "vec": "d.nefc"},
    "mj_jac": {"jacp": "3, m.nv", "jacr": "3, m.nv"},
    "mj_jacBody": {"jacp": "3, m.nv", "jacr": "3, m.nv"},
    "mj_jacBodyCom": {"jacp": "3, m.nv", "jacr": "3, m.nv"},
    "mj_jacSubtreeCom": {"jacp": "3, m.nv"},
    "mj_jacGeom": {"jacp": "3, m.nv", "jacr": "3, m.nv"},
    "mj_jacSite": {"jacp": "3, m.nv", "jacr": "3, m.nv"},
    "mj_jacPointAxis": {"jacPoint": "3, m.nv", "jacAxis": "3, m.nv"},
    "mj_jacDot": {"jacp": "3, m.nv", "jacr": "3, m.nv"},
    "mj_angmomMat": {"mat": "3, m.nv"},
    "mj_fullM": {"dst": "m.nv, m.nv"},
    "mj_mulM": {"res": "m.nv", "vec": "m.nv"},
    "mj_mulM2": {"res": "m.nv", "vec": "m.nv"},
    "mj_addM": {"dst": "m.nv, m.nv", "rownnz": "*", "rowadr": "*", "colind": "*"},
    "mj_applyFT": {"qfrc_target": "m.nv"},
    "mj_differentiatePos": {"qvel": "m.nv", "qpos1": "m.nq", "qpos2": "m.nq"},
    "mj_integratePos": {"qpos": "m.nq", "qvel": "m.nv"},
    "mj_normalizeQuat": {"qpos": "m.nq"},
    "mj_ray": {"geomgroup": "mjNGROUP"},
    "mj_multiRay": {"vec": "nray, 3", "geomgroup": "mjNGROUP", "geomid": "nray",
                    "dist": "nray", "normal": "nray, 3"},
    "mju_raySkin": {"face": "nface, 3", "vert": "nvert, 3"},
    "mju_zero": {"res": "n"},
    "mju_fill": {"res": "n"},
    "mju_copy": {"res": "n", "vec": "n"},
    "mju_sum": {"vec": "n"},
    "mju_L1": {"vec": "n"},
    "mju_scl": {"res": "n", "vec": "n"},
    "mju_add": {"res": "n", "vec1": "n", "vec2": "n"},
    "mju_sub": {"res": "n", "vec1": "n", "vec2": "n"},
    "mju_addTo": {"res": "n", "vec": "n"},
    "mju_subFrom": {"res": "n", "vec": "n"},
    "mju_addToScl": {"res": "n", "vec": "n"},
    "mju_addScl": {"res": "n", "vec1": "n", "vec2": "n"},
    "mju_normalize": {"res": "n"},
    "mju_norm": {"res": "n"},
    "mju_dot": {"vec1": "n", "vec2": "n"},
    "mju_mulMatVec": {"res": "nr", "mat": "nr, nc", "vec": "nc"},
    "mju_mulMatTVec": {"res": "nc", "mat": "nr, nc", "vec": "nr"},
    "mju_mulVecMatVec": {"vec1": "n", "mat": "n, n", "vec2": "n"},
    "mju_transpose": {"res": "nc, nr", "mat": "nr, nc"},
    "mju_symmetrize": {"res": "n, n", "mat": "n, n"},
    "mju_eye": {"mat": "n, n"},
    "mju_mulMatMat": {"res": "r1, c2", "mat1": "r1, c1", "mat2": "c1, c2"},
    "mju_mulMatMatT": {"res": "r1, r2", "mat1": "r1, c1", "mat2": "r2, c1"},
    "mju_mulMatTMat": {"res": "c1, c2", "mat1": "r1, c1", "mat2": "r1, c2"},
    "mju_sqrMatTD": {"res": "nc, nc", "mat": "nr, nc", "diag": "nr"},
    "mju_dense2sparse": {"res": "nnz", "mat": "nr, nc", "rownnz": "nr", "rowadr": "nr",
                         "colind": "nnz"},
    "mju_sparse2dense": {"res": "nr, nc", "mat": "*", "rownnz": "nr", "rowadr": "nr",
                         "colind": "*"},
    "mju_sym2dense": {"res": "n, n", "mat": "*", "rownnz": "n", "rowadr": "n", "colind": "*"},
    "mju_cholFactor": {"mat": "n, n"},
    "mju_cholSolve": {"res": "n", "mat": "n, n", "vec": "n"},
    "mju_cholUpdate": {"mat": "n, n", "x": "n"},
    "mju_cholFactorBand": {"mat": "band_size(ntotal, nband, ndense)"},
    "mju_cholSolveBand": {"res": "ntotal", "mat": "band_size(ntotal, nband, ndense)",
                          "vec": "ntotal"},
    "mju_band2Dense": {"res": "ntotal, ntotal", "mat": "band_size(ntotal, nband, ndense)"},
    "mju_dense2Band": {"res": "band_size(ntotal, nband, ndense)", "mat": "ntotal, ntotal"},
    "mju_bandMulMatVec": {"res": "nvec, ntotal", "mat": "band_size(ntotal, nband, ndense)",
                          "vec": "nvec, ntotal"},
    "mju_boxQP": {"res": "n", "R": "n*(n+7)", "index": "n", "H": "n, n", "g": "n",
                  "lower": "n", "upper": "n"},
    "mju_encodePyramid": {"pyramid": "2*dim", "force": "dim+1", "mu": "dim"},
    "mju_decodePyramid": {"force": "dim+1", "pyramid": "2*dim", "mu": "dim"},
    "mju_isZero": {"vec": "n"},
    "mju_standardNormal": {"num2": "1"},
    "mju_f2n": {"res": "n", "vec": "n"},
    "mju_n2f": {"res": "n", "vec": "n"},
    "mju_d2n": {"res": "n", "vec": "n"},
    "mju_n2d": {"res": "n", "vec": "n"},
    "mju_insertionSort": {"list": "n"},
    "mju_insertionSortInt": {"list": "n"},
    "mju_strncpy": {"dst": "n"},
    "mjd_transitionFD": {"A": "2*m.nv+m.na, 2*m.nv+m.na", "B": "2*m.nv+m.na, m.nu",
                         "C": "m.nsensordata, 2*m.nv+m.na", "D": "m.nsensordata, m.nu"},
    "mjd_inverseFD": {"DfDq": "m.nv, m.nv", "DfDv": "m.nv, m.nv", "DfDa": "m.nv, m.nv",
                      "DsDq": "m.nv, m.nsensordata", "DsDv": "m.nv, m.nsensordata",
                      "DsDa": "m.nv, m.nsensordata", "DmDq": "m.nv, m.nC"},
    "mjp_getPlugin": {"slot": "1"},
    "mju_writeResource": {"buffer": "nbytes"},
    "mjs_makeMesh": {"params": "nparams"},
    "mjs_setBuffer": {"array": "size"},
    "mjs_setInt": {"array": "size"},
    "mjs_appendIntVec": {"array": "size"},
    "mjs_setFloat": {"array": "size"},
    "mjs_appendFloatVec": {"array": "size"},
    "mjs_setDouble": {"array": "size"},
}

# Size arguments that stay in the Python signature (as in the official
# bindings), checked against the arrays instead of deduced from them.
KEEP = {
    "mj_multiRay": ("nray",),
    "mju_raySkin": ("nface", "nvert"),
    "mju_cholSolveBand": ("ntotal",),
    "mju_band2Dense": ("ntotal",),
    "mju_dense2Band": ("ntotal",),
    "mju_bandMulMatVec": ("ntotal", "nvec"),
}

# The official bindings' own messages for a wrong argument, by function and C
# argument name: where mjcffi refuses the same argument, str(exc) is this (the
# expected shape goes in a note).  A str applies to any axis; for a matrix,
# ((axis, message), ...) lists the axes in the order the official bindings check
# them (an axis not listed gets mjcffi's own message).  Arrays listed here are
# checked first, in this order, so that a call with one wrong argument blames
# the argument the official bindings blame.  Ids (IDS) and kept sizes (KEEP)
# take their message from here too.
_SAME = "{} and {} should have the same size"
_JAC = {"jacp": "jacp should be of shape (3, nv)", "jacr": "jacr should be of shape (3, nv)"}
_NV = {"res": "res should be of size nv", "vec": "vec should be of size nv"}
_BAND = "mat must have size (ntotal-ndense)*nband + ndense*ntotal"
_PYRAMID = {"mu": "size of pyramid should be twice as large as size of mu",
            "pyramid": "size of pyramid should be twice as large as size of mu",
            "force": "size of force should be exactly one larger than size of mu"}
_SOLVE = {"x": ((0, "the first dimension of x and y should be of the same size"),
                (1, "the last dimension of x should be of size nv")),
          "y": ((1, "the last dimension of y should be of size nv"),)}
MESSAGES = {
    "mj_solveM": _SOLVE,
    "mj_solveM2": {**_SOLVE, "sqrtInvD": "the size of sqrtInvD should be nv"},
    "mj_rne": {"result": "result should have length nv"},
    "mj_constraintUpdate": {"jar": "size of jar should equal nefc"},
    "mj_getState": {"state": "state size should equal mj_stateSize(m, sig)"},
    "mj_setState": {"state": "state size should equal mj_stateSize(m, sig)"},
    "mj_extractState": {"src": "src size should equal mj_stateSize(m, srcsig)",
                        "dst": "dst size should equal mj_stateSize(m, dstsig)"},
    "mj_readCtrl": {"id": "actuator id out of range",
                    "result": "result should have length actuator_ctrlnum[id]"},
    "mj_readSensor": {"id": "sensor id out of range",
                      "result": "result should have length sensor_dim[id]"},
    "mj_initCtrlHistory": {
        "id": "actuator id out of range",
        "times": "times should have length actuator_history[2*id]",
        "values": "values should have shape (actuator_history[2*id], actuator_ctrlnum[id])"},
    "mj_initSensorHistory": {
        "id": "sensor id out of range",
        "times": "times should have length sensor_history[2*id]",
        "values": "values should have shape (sensor_history[2*id], sensor_dim[id])"},
    "mj_mulJacVec": {"res": "res should be of length nefc", "vec": "vec should be of length nv"},
    "mj_mulJacTVec": {"res": "res should be of length nv", "vec": "vec should be of length nefc"},
    **{name: _JAC for name in ("mj_jac", "mj_jacBody", "mj_jacBodyCom", "mj_jacGeom",
                               "mj_jacSite", "mj_jacDot")},
    "mj_jacSubtreeCom": {"jacp": _JAC["jacp"]},
    "mj_jacPointAxis": {"jacPoint": _JAC["jacp"], "jacAxis": _JAC["jacr"]},
    "mj_angmomMat": {"mat": "mat should be of shape (3, nv)"},
    "mj_fullM": {"dst": "dst should be of shape (nv, nv)"},
    "mj_mulM": _NV,
    "mj_mulM2": _NV,
    "mj_applyFT": {"qfrc_target": "qfrc_target should be of size nv"},
    "mj_geomDistance": {"fromto": "fromto should be of size 6"},
    "mj_differentiatePos": {"qvel": "qvel should be of size nv",
                            "qpos1": "qpos1 should be of size nq",
                            "qpos2": "qpos2 should be of size nq"},
    "mj_integratePos": {"qpos": "qpos should be of size nq", "qvel": "qvel should be of size nv"},
    "mj_normalizeQuat": {"qpos": "qpos should be of size nq"},
    "mj_multiRay": {"vec": "vec should be of size 3*nray",
                    "normal": "normal should be of size 3*nray",
                    "geomid": "dist and geomid should be of size nray",
                    "dist": "dist and geomid should be of size nray"},
    "mju_raySkin": {"nface": "nface and nvert must be non-negative",
                    "nvert": "nface and nvert must be non-negative",
                    "face": "face should be of size 3*nface",
                    "vert": "vert should be of size 3*nvert"},
    "mju_copy": {"res": _SAME.format("res", "data"), "vec": _SAME.format("res", "data")},
    **{name: {"res": _SAME.format("res", "vec"), "vec": _SAME.format("res", "vec")} for name in (
        "mju_scl", "mju_addTo", "mju_subFrom", "mju_addToScl", "mju_f2n", "mju_n2f",
        "mju_d2n", "mju_n2d")},
    **{name: {"res": _SAME.format("res", "vec1"), "vec2": _SAME.format("res", "vec2")}
       for name in ("mju_add", "mju_sub", "mju_addScl")},
    "mju_dot": {"vec2": _SAME.format("vec1", "vec2")},
    "mju_mulMatVec": {"mat": ((0, "size of res should equal the number of rows in mat"),
                              (1, "size of vec should equal the number of columns in mat"))},
    "mju_mulMatTVec": {"mat": ((1, "size of res should equal the number of columns in mat"),
                               (0, "size of vec should equal the number of rows in mat"))},
    "mju_mulVecMatVec": {"vec2": "size of vec1 should equal the size of vec2",
                         "mat": "size of vectors should equal the number of columns in mat"},
    "mju_transpose": {"res": ((1, "#columns in res should equal #rows in mat"),)},
    "mju_symmetrize": {"mat": "mat should be square", "res": "res and mat should have the same shape"},
    "mju_eye": {"mat": "mat should be square"},
    "mju_mulMatMat": {"res": ((0, "#rows in res should equal #rows in mat1"),
                              (1, "#columns in res should equal #columns in mat2")),
                      "mat2": ((0, "#columns in mat1 should equal #rows in mat2"),)},
    "mju_mulMatMatT": {"res": ((0, "#rows in res should equal #rows in mat1"),
                               (1, "#columns in res should equal #rows in mat2")),
                       "mat2": ((1, "#columns in mat1 should equal #columns in mat2"),)},
    "mju_mulMatTMat": {"res": ((0, "#rows in res should equal #columns in mat1"),
                               (1, "#columns in res should equal #columns in mat2")),
                       "mat2": ((0, "#rows in mat1 should equal #rows in mat2"),)},
    "mju_sqrMatTD": {"res": "#rows in res should equal #columns in mat",
                     "diag": "size of diag should equal the number of rows in mat"},
    "mju_dense2sparse": {"mat": ((0, "#rows in mat should equal size of rownnz"),),
                         "rowadr": "#rows in mat should equal size of rowadr",
                         "colind": "#size of res should equal size of colind"},
    "mju_cholFactor": {"mat": "mat should be a square matrix"},
    "mju_cholSolve": {"mat": "mat should be a square matrix",
                      "res": "size of res should equal the number of rows in mat",
                      "vec": "size of vec should equal the number of rows in mat"},
    "mju_cholUpdate": {"mat": "mat should be a square matrix",
                       "x": "size of x should equal the number of rows in mat"},
    "mju_cholFactorBand": {"mat": _BAND},
    "mju_cholSolveBand": {"res": "size of res should equal ntotal",
                          "mat": "mat must have (ntotal-ndense)*nband + ndense*ntotal elements",
                          "vec": "size of vec should equal ntotal"},
    "mju_band2Dense": {"res": ((0, "res should have ntotal rows"),
                               (1, "res should have ntotal columns")), "mat": _BAND},
    "mju_dense2Band": {"res": "res must have size (ntotal-ndense)*nband + ndense*ntotal",
                       "mat": ((0, "mat should have ntotal rows"),
                               (1, "mat should have ntotal columns"))},
    "mju_encodePyramid": _PYRAMID,
    "mju_decodePyramid": _PYRAMID,
    "mjd_inverseFD": {name: f"{name} should be of shape (nv, {cols})" for name, cols in (
        ("DfDq", "nv"), ("DfDv", "nv"), ("DfDa", "nv"), ("DsDq", "nsensordata"),
        ("DsDv", "nsensordata"), ("DsDa", "nsensordata"), ("DmDq", "nC"))},
    "mju_boxQP": {"R": "size of R should be n*(n+7)"},
    "mjd_subQuat": {"qa": "qa must have size 4", "qb": "qb must have size 4",
                    "Da": "Da must have size 9", "Db": "Db must have size 9"},
}

# Arrays that the official bindings check by their number of elements alone:
# any shape of that size is taken (mju_raySkin's face may be (nface, 3) or flat).
SIZED = {
    "mju_raySkin": ("face", "vert"),
    "mj_multiRay": ("vec", "normal"),
    "mj_solveM2": ("sqrtInvD",),
    "mj_geomDistance": ("fromto",),
    "mjd_subQuat": ("Da", "Db"),
    "mju_bandMulMatVec": ("res", "vec"),
    "mju_boxQP": ("R",),
}

# Arrays that give the sizes they hold before any other (as the official
# bindings read them): the other arrays are then blamed for a mismatch.
BIND = {
    "mju_symmetrize": ("mat",),
    "mju_sqrMatTD": ("mat",),
    "mju_cholSolve": ("mat",),
    "mju_cholUpdate": ("mat",),
}

# Object ids, derived from the declarations (derive_ids).  In a function that
# takes an mjModel or mjData, an `int` argument is an object id when its name is an
# object word of OBJECTS (or an ID_ALIASES prefix: g1, g2 are geoms), alone or
# followed by `id`, `_id`, `exclude` or a digit (body, bodyexclude, flexid, geom1,
# siteid, plugin_id), or when it is a plain `id` and the doc comment names the
# object (its first object word: "for actuator", "given contact id", "from geom
# id").  MuJoCo follows most ids unchecked, so each is checked against the count of
# its object type, from 0, or from -1 (none) for an exclusion or where the comment
# says "<name> ... -1".  An id whose range the comment states ("If 0 <= key <
# nkey") is MuJoCo's to check, and so are those of ID_EXCEPTIONS.  An `objtype`,
# `objid` pair is checked by `_marshal.object_id` against the count of the type.
OBJECTS = {
    "body": "m.nbody", "jnt": "m.njnt", "joint": "m.njnt", "dof": "m.nv", "geom": "m.ngeom",
    "site": "m.nsite", "cam": "m.ncam", "camera": "m.ncam", "light": "m.nlight",
    "flex": "m.nflex", "mesh": "m.nmesh", "skin": "m.nskin", "hfield": "m.nhfield",
    "tex": "m.ntex", "texture": "m.ntex", "mat": "m.nmat", "material": "m.nmat",
    "pair": "m.npair", "eq": "m.neq", "equality": "m.neq", "tendon": "m.ntendon",
    "actuator": "m.nu", "sensor": "m.nsensor", "numeric": "m.nnumeric", "tuple": "m.ntuple",
    "key": "m.nkey", "keyframe": "m.nkey", "plugin": "m.nplugin", "contact": "d.ncon",
}
ID_ALIASES = {"g": "geom"}

# Ids derive_ids finds that are left to MuJoCo: (function, argument) -> why.
ID_EXCEPTIONS = {
    ("mj_id2name", "id"): "its object type is the `type` argument; MuJoCo checks the range "
                          "and returns NULL (None), as in the official bindings",
    ("mj_actuatorInputName", "id"): "MuJoCo checks it and returns NULL (None), as in the "
                                    "official bindings",
    ("mj_getPluginConfig", "plugin_id"): "MuJoCo checks it and returns NULL (None), as its "
                                         "header says",
    ("mj_contactForce", "id"): "MuJoCo checks it and leaves result zero, as in the official "
                               "bindings",
}

# Bounds of scalar arguments that are not object ids: argument -> (lowest, count).
BOUNDS = {
    "mju_threadpool": {"nthread": (0, "1025")},      # a sanity bound: a failed thread aborts
}

_ID_NAME = re.compile(r"^([a-z]+?)(?:_?id|exclude|[0-9])?$")

# Arguments declared as a C enum (mjs_findElement's `mjtObj type`) must be one of
# its members (derive_enums): MuJoCo follows some unchecked.  Those MuJoCo handles
# safely for any value take any int the C type holds, as the official bindings take
# any int for their enum arguments: (function, argument) -> where MuJoCo handles it
# (the audit is in CONFORMANCE.md, "Strictness beyond the official bindings";
# tests/test_enum_strictness.py).  mjs_findElement stays checked: an unknown type
# indexes mjCModel::FindObject's object lists (a segfault), and so do mjOBJ_DEFAULT
# and mjOBJ_MODEL (CHECKS).
ENUM_EXCEPTIONS: dict = {
    ("mjs_firstChild", "type"): "mjCBody::NextChild's switch has a default: it sets the "
                                "spec's error and mjs_firstChild returns NULL",
    ("mjs_firstElement", "type"): "mjCModel::NextObject's switch has a default that returns "
                                  "NULL (mjOBJ_UNKNOWN throws: CHECKS refuses it)",
    ("mjs_makeMesh", "builtin"): "its switch has a default: it sets the spec's error "
                                 "\"Unsupported mesh type\" and returns 1",
}

# Arguments declared `int` whose header comment names their enum ("font is mjtFont"),
# to check as members of it where MuJoCo follows them unchecked: (function, argument)
# -> enum.  None does in MuJoCo 4.0; the official bindings take any int for them all,
# and so does mjcffi, for MuJoCo handles every value:
#   mjr_text, mjr_label, mjr_overlay font: only compared with mjFONT_SHADOW and
#     mjFONT_BIG (render_gl2.c): any other value draws as mjFONT_NORMAL;
#   mjr_overlay gridpos: a switch without a default sets the viewport; another value
#     leaves the current one (render_gl2.c, draw_overlay);
#   mjr_setBuffer framebuffer: another value than mjFB_WINDOW binds the offscreen
#     buffer and is stored in con.currentBuffer, which MuJoCo (and mjr_readPixels
#     here) only compare with mjFB_WINDOW;
#   mjr_changeFont fontscale: makeFont's switch has a default, mju_error("Invalid
#     fontscale"): FatalError, the old font freed (rangeFont 0: text draws nothing).
ENUM_INTS: dict = {}

# The mjr_* functions that draw with OpenGL (mjcffi/_support/mjr.py): the mjrContext they take
# must have been made, not freed, in the OpenGL context current on this thread; those
# without one need some context current and MuJoCo's OpenGL functions loaded.  Checked
# after every argument.  The others of mjr_* make no OpenGL call.
NO_OPENGL = frozenset({"mjr_defaultContext", "mjr_defaultRendererInfo", "mjr_getRendererInfo",
                       "mjr_findRect"})


def draws(name):
    """Whether function `name` draws with OpenGL (see NO_OPENGL)."""
    return name.startswith("mjr_") and name not in NO_OPENGL


# Functions that write a model's flexes and skins into the buffers of their
# mjvScene, or read them (MuJoCo does neither check): the scene must have been made
# for a model of that flex and skin layout (mjcffi/_support/checks.py, scene), or
# MuJoCo writes past its buffers.  Function -> what it does with them.
SCENES = {
    "mjv_updateScene": "writes flex vertices and faces, and skin vertices and normals",
    "mjv_updateSkin": "writes skin vertices and normals",
    "mjv_select": "reads skin vertices",
}


def _id_object(func, arg, doc):
    """The object type of int argument `arg`, if it is an object id, else None."""
    if arg == "id":
        words = re.findall(r"[a-z]+", doc.lower())
        return next((w for w in words if w in OBJECTS), None) or "?"
    match = _ID_NAME.match(arg)
    if not match:
        return None
    word = ID_ALIASES.get(match.group(1), match.group(1))
    if word not in OBJECTS or (word != match.group(1) and arg == match.group(1)):
        return None                         # `g` alone is not an id
    return word


def derive_enums(decls, skip=()):
    """{function: {argument: enum}}: the scalar arguments declared as a C enum (typedef of
    an enum with members), but for ENUM_EXCEPTIONS and the functions in `skip`."""
    found = {}
    for name, func in decls.functions.items():
        if name in skip:
            continue
        for a in func.args:
            t = a.type
            if t.pointer or t.dims or (name, a.name) in ENUM_EXCEPTIONS:
                continue
            enum = decls.enums.get(t.base)
            if enum is not None and enum.members and \
                    decls.typedefs.get(t.base, "").startswith("enum"):
                found.setdefault(name, {})[a.name] = t.base
    return found


def derive_ids(decls, notes, skip=()):
    """{function: {argument: (lowest, count)}}: the object ids MuJoCo does not check,
    and BOUNDS; functions in `skip` (hand-written or unsupported) are left out."""
    ids = {}
    for name, func in decls.functions.items():
        if name in skip:
            continue
        doc = notes.functions[name].doc if name in notes.functions else ""
        if not any(a.type.base in ("mjModel", "mjData") for a in func.args):
            continue                        # ids index a model: mjs_makeFlex's `equality` is a flag
        for a in func.args:
            t = a.type
            if t.base != "int" or t.pointer or t.dims:
                continue
            word = _id_object(name, a.name, doc)
            if word is None or (name, a.name) in ID_EXCEPTIONS:
                continue
            if word == "?":
                raise ValueError(f"{name}: the object of argument `id` is not named in its "
                                 f"doc comment; add it to ID_EXCEPTIONS or OBJECTS")
            if re.search(rf"<=?\s*{a.name}\s*<|\b{a.name}\s*<\s*n", doc):
                continue                    # the header states the range MuJoCo checks
            low = -1 if a.name.endswith("exclude") or re.search(
                rf"\b{a.name}\b[^.;]*-1", doc) else 0
            ids.setdefault(name, {})[a.name] = (low, OBJECTS[word])
    for name, bounds in BOUNDS.items():
        ids.setdefault(name, {}).update(bounds)
    return ids


class _DerivedIds(Mapping):
    """IDS: derive_ids of the installed headers, computed when first read (generate
    fills it), so that tests can sweep the ids the generated code checks."""

    def __init__(self):
        self._table = None

    def _get(self):
        if self._table is None:
            from . import comments, headers, parse
            decls = parse.parse(headers.mujoco_declarations())
            notes = comments.read(headers.header_texts())
            self._table = derive_ids(decls, notes, set(OVERRIDES) | set(UNSUPPORTED))
        return self._table

    def __getitem__(self, key):
        return self._get()[key]

    def __iter__(self):
        return iter(self._get())

    def __len__(self):
        return len(self._get())


IDS = _DerivedIds()

# Which generated functions have a fast path (codegen/fastpath.py), filled by generate:
# the tests sweep those.
FAST_PATHS: dict = {}


def fast_path_functions():
    """The names of the generated functions that have a fast path (generating them from
    the installed headers first, if this process has not)."""
    if not FAST_PATHS:
        from . import comments, extents, fields, headers, parse
        decls = parse.parse(headers.mujoco_declarations())
        header_texts = headers.header_texts()
        notes = comments.read(header_texts)
        known = {name: value for enum in decls.enums.values() for name, value in enum.members}
        described = fields.describe(decls, notes, extents.from_xmacros(known), known)
        generate(decls, notes, described, header_texts)
    return sorted(name for name, fast in FAST_PATHS.items() if fast)

# Further checks before the call: statements over the converted arguments,
# calling helpers of mjcffi/_support/marshal.py.
CHECKS = {
    "mju_printMatSparse": ["csr(rownnz, rowadr, colind, min(mat.size, colind.size), None)"],
    "mju_sparse2dense": ["csr(rownnz, rowadr, colind, min(mat.size, colind.size), nc)"],
    "mju_sym2dense": ["csr(rownnz, rowadr, colind, min(mat.size, colind.size), n)"],
    "mju_raySkin": ["below(face, nvert, 'face', 'face vertex index out of bounds')"],
    "mj_addM": ["require(rownnz is None and rowadr is None and colind is None, "
                "'mj_addM: only the dense form (rownnz, rowadr, colind None) is supported: "
                "MuJoCo follows a given sparse structure unchecked')"],
    # MuJoCo reads m->plugin[m->geom_plugin[id]] unchecked: -1 for a geom without one
    "mjc_getSDF": ["require(m.geom_plugin[id] >= 0, 'mjc_getSDF: the geom has no SDF plugin')"],
    # the camera's fixedcamid / trackbodyid, where MuJoCo follows them unchecked
    "mjv_cameraFrame": ["camera(model_of(@d, 'd'), cam, 'cam')"],
    "mjv_camera2GLCamera": ["camera(m, cam, 'cam', fixed=False)"],
    "mju_strncpy": ["require(n > 0, 'dst must not be empty')"],
    "mju_Halton": ["index(base, 2 ** 31, 'base', 2)"],     # it divides by base, loops on 1
    # mjOBJ_UNKNOWN throws a C++ exception through the C API: the process aborts
    "mjs_firstElement": ["require(type != 0, 'type must not be mjOBJ_UNKNOWN')"],
    # mjCModel::FindObject indexes its object lists (mjNOBJECT of them) by the type:
    # mjNOBJECT, mjOBJ_DEFAULT and mjOBJ_MODEL, values of mjtObj, read past them (the
    # enum check refuses the rest; mjOBJ_DEFAULT segfaults on a compiled spec)
    "mjs_findElement": ["require(type < mjNOBJECT or type == mjOBJ_FRAME, f'type={type} is a "
                        "value of mjtObj that mjs_findElement cannot take: it must be below "
                        "mjNOBJECT or mjOBJ_FRAME, for MuJoCo indexes its object lists by it')"],
    # the renderer (mjcffi/_support/mjr.py): what MuJoCo follows in the scene, figure and text
    "mjr_render": ["render_scene(@scn, scn, @con, con)"],
    "mjr_figure": ["figure_fields(fig)"],
    "mjr_text": ["ascii_text(c_txt, 'txt')"],
    "mjr_label": ["ascii_text(c_txt, 'txt')"],
    "mjr_overlay": ["overlay_text(c_overlay, 'overlay')", "overlay_text(c_overlay2, 'overlay2')"],
    "mjr_resizeOffscreen": ["count(width, 'width')", "count(height, 'height')"],
    "mjr_blitBuffer": ["rect_fits(src, 'src')", "rect_fits(dst, 'dst')"],
    "mjr_blitAux": ["rect_fits(src, 'src')"],
    **{name: ["same_model(m, @con)"] for name in (
        "mjr_uploadTexture", "mjr_uploadMesh", "mjr_uploadHField")},
}

# (char *error, int error_sz) pairs: the buffer is made here and the Python
# signature omits both.  func -> (failure test on `ret`, exception, return ret?).
# FatalError where the official bindings raise it, ValueError elsewhere (as
# MjModel.from_xml_path does).
ERRORS = {
    "mj_parseXML": ("ret == NULL", "ValueError", True),
    "mj_parseXMLString": ("ret == NULL", "ValueError", True),
    "mj_parse": ("ret == NULL", "ValueError", True),
    "mj_encode": ("ret < 0", "ValueError", True),
    "mj_saveLastXML": ("ret == 0", "FatalError", False),
    "mj_saveXML": ("ret != 0", "ValueError", False),
    "mj_setLengthRange": ("ret == 0", "FatalError", False),
    "mju_writeResource": ("ret < 0", "ValueError", True),
}

# Results that need more than the generic rule: a Python expression over
# `ret` (the C result) and the converted arguments.
RETURNS = {
    "mj_readCtrl": "fill(result, ret, m.actuator_ctrlnum[id])",     # the value lands in result
    "mj_readSensor": "fill(result, ret, m.sensor_dim[id])",
    "mjs_getTimer": "copy_array(ret, mjNCTIMER, NUM)",
    "mj_copyData": "None",                     # returns dest, as the official bindings: None
    # views of exactly the size asked for, in d's arena (mjcffi/_support/stack.py)
    "mj_stackAllocNum": "stack_array(@d, ret, size, NUM)",
    "mj_stackAllocInt": "stack_array(@d, ret, size, INT)",
    "mj_stackAllocByte": "stack_array(@d, ret, bytes, BYTE)",
}

# Calls that may release arrays of the mjData stack (mjcffi/_support/stack.py): they
# pop a frame, empty the stack (the resets, a copy into the data), or reset a bad state
# (mj_checkPos/Vel/Acc, and the steps that call them).  Function -> its mjData argument.
RELEASES = {
    "mj_freeStack": "d", "mj_resetData": "d", "mj_resetDataDebug": "d",
    "mj_resetDataKeyframe": "d", "mj_copyData": "dest", "mjv_copyData": "dest",
    "mj_step1": "d", "mj_step2": "d", "mj_checkPos": "d", "mj_checkVel": "d",
    "mj_checkAcc": "d",
}

# New structs that the caller owns: func -> the C function that frees them.
OWNED = {
    "mj_parseXML": "mj_deleteSpec",
    "mj_parseXMLString": "mj_deleteSpec",
    "mj_parse": "mj_deleteSpec",
    "mj_makeSpec": "mj_deleteSpec",
    "mj_copySpec": "mj_deleteSpec",
}

# Python names that differ from mujoco.h's, as in the official bindings.
RENAMES = {
    "mjv_camera2GLCamera": {"model": "m", "data": "d", "mjv_camera": "cam"},
}

# Arguments left out of the Python signature and passed as a constant.
OMIT = {
    "mj_loadAllPluginLibraries": {"callback": "NULL"},   # as the official bindings
}

# Pointers MuJoCo tests for NULL although the header has no `Nullable:` note.
NULLABLE = {
    "mj_addFileVFS": ("directory",),           # functions_override.rst says Nullable
    "mju_standardNormal": ("num2",),
    "mjv_updateScene": ("pert",),              # the official bindings pass NULL too
    "mjr_overlay": ("overlay2",),              # `if (overlay2 && overlay2[0])`; official: None
}

# Pointers the header marks `Nullable:` that MuJoCo dereferences all the same (the
# header is wrong; each found by calling the function with NULL there, on the
# default scene): function -> {argument: why}.  They refuse None (TypeError).
NOT_NULLABLE = {
    "mjv_cameraFrame": {"forward": "MuJoCo reads forward to place headpos"},
    **{"mjv_select": {name: "MuJoCo writes it unconditionally (*" + name + " = -1)"
                      for name in ("geomid", "flexid", "skinid")}},
}

# Hand-written in mjcffi/functions/_overrides.py: the documented Python signature
# differs from C's, or the result is an MjModel/MjData (hand-written classes).
OVERRIDES = {
    "mj_step": "nstep=1 repeats the step in C, under one guard (python.rst); warnings as errors",
    "mj_forward": "raises MjWarningError on a new warning when warnings are errors",
    "mj_name2id": "a repeated (type, name) is answered from the model's memo of MuJoCo's "
                  "answers",
    "mj_loadXML": "returns an MjModel; MuJoCo's error becomes ValueError",
    "mj_loadModel": "returns an MjModel",
    "mj_loadModelBuffer": "takes bytes, returns an MjModel",
    "mj_compile": "returns an MjModel; mjs_getError's message becomes ValueError",
    "mj_copyModel": "returns an MjModel (a new one when dest is None)",
    "mj_embedAssets": "returns an MjModel",
    "mj_makeData": "returns an MjData",
    "mj_loadTexture": "returns (pixels, colorspace), as the official bindings",
    "mj_saveXMLString": "returns the XML as str",
    "mj_printSchema": "mj_printSchema(flg_html, flg_pad) returns str, as the official bindings",
    "mjs_getDouble": "returns a NumPy copy of the vector",
    "mjr_findRect": "rect is one MjrRect or a sequence of them",
    "mjr_makeContext": "makes con in the current OpenGL context and records it (mjcffi/_support/mjr.py)",
    "mjr_freeContext": "frees con as MjrContext.free() does: OpenGL objects only in their "
                       "own context",
    "mjr_readPixels": "rgb and depth: output arrays of at least the viewport's pixels (any "
                      "shape, (h, w, 3) and (h, w) included) or None, as the official bindings",
    "mjr_drawPixels": "rgb and depth: input arrays of at least the viewport's pixels or None, "
                      "as the official bindings",
    "mj_defaultVFS": "resets the VFS, freeing what it held (an MjVFS owns its memory)",
    "mj_deleteVFS": "empties the VFS, which stays usable (an MjVFS frees it when collected)",
    "mju_getLogConfig": "returns the public MjLogConfig class, which has get() and set()",
    "mju_getXMLDependencies": "mju_getXMLDependencies(filename) returns a list of str, as the "
                              "official bindings (the C API fills an mjStringVec)",
    # lifetimes: memory that these calls free, or that MuJoCo keeps pointing to
    "mjv_makeScene": "builds the scene in new memory: views of the old one keep it alive",
    "mjv_freeScene": "gives the scene new, empty memory: views of the old one keep it alive",
    "mjv_defaultScene": "as mjv_freeScene (MuJoCo would zero the scene and lose its buffers)",
    "mj_mountVFS": "the VFS keeps the provider alive while MuJoCo holds a pointer to it",
    "mj_unmountVFS": "the VFS lets go of the provider it kept alive",
    "mj_deleteFileVFS": "it unmounts a provider at that path too: the VFS lets go of it",
    "mju_malloc": "records the pointer, which only mju_free frees",
    "mju_free": "frees only what mju_malloc returned, once",
    # MuJoCo's UI (mjcffi/functions/_mjui.py): the mjUI keeps pointers to the values its items edit
    "mjui_add": "takes a sequence of definitions, ended with mjITEM_END for MuJoCo; each "
                "pdata buffer is checked and kept alive by the MjUI (mjcffi/functions/_mjui.py)",
    "mjui_addToSection": "as mjui_add, into a section the UI has",
    **{name: "checks the mjUI's items, indices and kept buffers, and that con was made in "
             "the current OpenGL context, before MuJoCo runs (mjcffi/functions/_mjui.py)"
       for name in ("mjui_resize", "mjui_update", "mjui_event", "mjui_render")},
}

_BATCH = ("the batch API hands out an opaque mjBatch and buffers it owns: use "
          "mjcffi.batch.Batch (from mjcffi import batch)")
_RESOURCE = "mjResource handles are opened and closed by resource providers in C"
_SPEC_DEFAULT = ("it is for structs that C code lays out; on an element that its spec owns (the "
                 "only kind Python has) it clears the pointers the spec manages")
_SPEC_DEFAULTS = ("Spec", "Body", "Frame", "Joint", "Geom", "Site", "Camera", "Light", "Flex",
                  "Mesh", "HField", "Skin", "Texture", "Material", "Pair", "Equality", "Tendon",
                  "Actuator", "Sensor", "Numeric", "Text", "Tuple", "Key", "Plugin")

# Functions the Python layer cannot express safely yet: they raise
# NotImplementedError with this reason (lib.<name> stays available).
UNSUPPORTED = {
    "mj_deleteModel": "an MjModel owns its mjModel and frees it when collected",
    "mj_deleteData": "an MjData owns its mjData and frees it when collected",
    "mj_deleteSpec": "an MjSpec owns its mjSpec and frees it when collected",
    "mj_recompile": "on failure it frees the mjModel and mjData that Python objects own",
    "mjv_copyData": "its copy lacks arrays that simulation functions read",
    "mjv_copyModel": "its copy lacks arrays that simulation functions read",
    "mju_boxQPmalloc": "it allocates raw C arrays (mjtNum **)",
    "mju_setLogHandler": "it installs a C callback",
    "mjs_setUserValueWithCleanup": "it takes a C callback",
    "mjs_setPluginAttributes": "it takes a C++ std::map behind a void *",
    **{name: f"it {what}, to which Python wrappers and NumPy views may still point: use "
             f"{instead}, which ends those wrappers and refuses while views are held"
       for name, what, instead in (
        ("mjs_bodyToFrame", "frees the body it converts (mjsBody **)", "MjsBody.to_frame()"),
        ("mjs_delete", "frees the element (a body: its whole subtree)", "MjSpec.delete"),
        ("mjs_fuseStatic", "frees the static bodies it fuses into their parents",
         "MjSpec.fuse_static"),
        ("mjs_discardVisual", "frees the visual elements it discards",
         "MjSpec.discard_visual"),
        ("mjs_dedupAssets", "frees the duplicate assets it merges", "MjSpec.dedup_assets"))},
    "mjc_distance": "it needs an mjSDF that MuJoCo's SDF plugins fill with raw pointers",
    "mjc_gradient": "it needs an mjSDF that MuJoCo's SDF plugins fill with raw pointers",
    **{name: "it registers C callbacks with MuJoCo" for name in (
        "mjp_registerPlugin", "mjp_registerProvider", "mjp_registerDecoder",
        "mjp_registerEncoder", "mjp_registerArchiveProvider")},
    **{"mjs_default" + kind: _SPEC_DEFAULT for kind in _SPEC_DEFAULTS},
    **{name: _RESOURCE for name in (
        "mju_openResource", "mju_closeResource", "mju_readResource", "mju_getResourceDir",
        "mju_isModifiedResource", "mju_decodeResource", "mjp_findDecoder")},
    **{name: _BATCH for name in (
        "mjb_makeBatch", "mjb_deleteBatch", "mjb_nstate", "mjb_state", "mjb_stateComponent",
        "mjb_warning", "mjb_step", "mjb_forward", "mjb_reset", "mjb_status", "mjb_error",
        "mjb_output", "mjb_expand", "mjb_expanded", "mjb_setConst", "mjb_setModels",
        "mjb_rollout", "mjb_apply", "mjb_getModel", "mjb_getData", "mjb_nsim",
        "mjb_nthread", "mjb_persistent", "mjb_model")},
}

# Helpers of mjcffi/_support/marshal.py that SHAPES, CHECKS and RETURNS may call.
_HELPERS = ("state_size", "band_size", "csr", "below", "require", "object_id", "index",
            "copy_array", "fill", "camera", "model_of", "stack_array", "NULL", "NUM", "INT",
            "BYTE", "count")

# Helpers of mjcffi/_support/mjr.py (the renderer's checks) that CHECKS may call.
_RENDER_HELPERS = ("render_scene", "figure_fields", "ascii_text", "overlay_text", "same_model",
                   "rect_fits")

# C element type of a numeric array -> its Elem in mjcffi/_support/marshal.py.
_ELEMS = {"mjtNum": "NUM", "double": "NUM", "float": "FLOAT", "int": "INT",
          "mjtByte": "BYTE", "unsigned char": "BYTE", "mjtSize": "SIZE", "mjtBool": "BOOL"}

_COMMON = '''"""What every module of mjcffi._functions uses: the support layer and the
converters its fast paths call, bound once, and the members of the enums it checks."""

from .. import structs as _structs
from .._support import contract as _contract
from .._support import checks as _c
from .._support import handles as _h
from .._support import marshal as _m
from .._support import mjr as _r
from .._support import prepared as _p
from .._support.library import lib as _lib

__all__ = ["_structs", "_contract", "_c", "_h", "_m", "_r", "_p", "_lib", "_nd", "_fb",
           "_NULL", "_SLOW", "_int", "_str", "_getattr", "_NUM_dt", "_NUM_ct", "_FLOAT_dt",
           "_FLOAT_ct", "_INT_dt", "_INT_ct", "_BYTE_dt", "_BYTE_ct", "_SIZE_dt", "_SIZE_ct",
           "_BOOL_dt", "_BOOL_ct", "_ENUMS"]

# what the fast paths test and convert with, bound once (and the builtins they use under
# names no argument can shadow: mju_str2Type's argument is `str`)
_nd, _fb, _NULL, _SLOW = _m.ndarray, _m.from_buffer, _m.NULL, _m.SLOW
_int, _str, _getattr = int, str, getattr
_NUM_dt, _NUM_ct = _m.NUM
_FLOAT_dt, _FLOAT_ct = _m.FLOAT
_INT_dt, _INT_ct = _m.INT
_BYTE_dt, _BYTE_ct = _m.BYTE
_SIZE_dt, _SIZE_ct = _m.SIZE
_BOOL_dt, _BOOL_ct = _m.BOOL
'''


# ----------------------------------------------------------------- model

@dataclass
class _Arg:
    name: str               # C name
    py: str                 # Python parameter name
    base: str               # element type, e.g. 'mjtNum', 'mjModel'
    decl: str               # the C type as declared
    level: int              # pointer levels, array extents counting as one
    const: bool
    dims: tuple             # fixed extents
    nullable: bool
    kind: str = ""          # see _classify


def _is_callback(base, decl, typedefs):
    """A function pointer, declared as such or through a typedef (mjfLogHandler)."""
    target = typedefs.get(base, "").lstrip()
    return "(*" in decl or ("(*" in target and not target.startswith(("struct", "union")))


def _classify(arg, described, typedefs):
    """The marshalling kind of an argument."""
    if arg.base == "...":
        return "varargs"
    if _is_callback(arg.base, arg.decl, typedefs):
        return "callback"
    if arg.level == 0:
        return "struct_value" if arg.base in described else "scalar"
    if arg.level > 1:
        return "pointer2"
    if arg.base == "char":
        return "text" if arg.const else "chars"
    if arg.base == "void":
        return "buffer"
    if arg.base in _ELEMS:
        return "array"
    if arg.base in described:
        return "struct"
    if arg.level == 1 and _is_handle(arg.base, typedefs):
        return "handle"
    return "opaque"


def _is_handle(base, typedefs):
    """A type mjspec.h declares as `void` (mjString, mjDoubleVec, ...): a typed handle
    of mjcffi/_support/handles.py."""
    return typedefs.get(base, "").strip() == "void"


def _handle_class(base):
    """'mjString' -> 'MjStringHandle', its class in mjcffi/_support/handles.py."""
    return "Mj" + base[2:] + "Handle"


def _args(func, note, described, typedefs):
    nullable = (set(note.nullable if note else ()) | set(NULLABLE.get(func.name, ()))) \
        - set(NOT_NULLABLE.get(func.name, ()))
    renames = RENAMES.get(func.name, {})
    out = []
    for a in func.args:
        t = a.type
        py = renames.get(a.name, a.name)
        if keyword.iskeyword(py):
            py += "_"
        arg = _Arg(name=a.name, py=py, base=t.base, decl=t.decl,
                   level=t.pointer + (1 if t.dims else 0), const=t.const,
                   dims=tuple(t.dims), nullable=a.name in nullable)
        arg.kind = _classify(arg, described, typedefs)
        out.append(arg)
    return out


def _defines(header_texts, decls):
    """Integer constants usable in SHAPES: #define numbers and enum members."""
    values = {}
    for text in header_texts.values():
        for name, value in re.findall(r"^\s*#\s*define\s+(\w+)\s+\(?(-?\d+)\)?\s*(?://.*)?$",
                                      text, re.M):
            values.setdefault(name, int(value))
    for enum in decls.enums.values():
        for name, value in enum.members:
            values.setdefault(name, value)
    return values


# -------------------------------------------------------- expressions

class _Exprs:
    """Translates the table expressions into Python for one function."""

    def __init__(self, args, constants):
        self.struct_names = {a.py for a in args if a.kind in ("struct", "struct_value")}
        self.constants = constants

    def __call__(self, expr):
        def word(match):
            name = match.group(0)
            if name[0] in "'\"":
                return name                         # a string literal
            if name[0] == "@":
                return name[1:]                     # @d: the Python argument itself
            if match.start() > 0 and match.string[match.start() - 1] == ".":
                return name                         # an attribute: m.nv stays .nv
            if name in self.struct_names:
                return "c_" + name
            call = match.string[match.end():].lstrip().startswith("(")
            if name in _HELPERS and (name.isupper() or call):
                return "_m." + name                 # a helper call, or NULL / NUM
            if name in _RENDER_HELPERS and call:
                return "_r." + name
            if name in self.constants:
                return str(self.constants[name])
            return name
        return re.sub(r"'[^']*'|\"[^\"]*\"|@?[A-Za-z_]\w*", word, expr)


_VAR = re.compile(r"^(?:(\d+)\s*\*\s*)?([A-Za-z_]\w*)$")


def _split_dims(spec):
    """'n, m.nv' -> ['n', 'm.nv']; commas inside brackets (helper calls) do not split."""
    dims, depth, start = [], 0, 0
    for i, char in enumerate(spec):
        if char in "([":
            depth += 1
        elif char in ")]":
            depth -= 1
        elif char == "," and depth == 0:
            dims.append(spec[start:i].strip())
            start = i + 1
    dims.append(spec[start:].strip())
    return dims


def _deducible(dim, sizes):
    """(var, factor) when `dim` is `var` or `K*var` for a size argument."""
    match = _VAR.match(dim)
    if match and match.group(2) in sizes:
        return match.group(2), int(match.group(1) or 1)
    return None


def _human(spec):
    """A shape for the docstring: 'm.nv' -> 'nv'."""
    dims = _split_dims(spec)
    text = ", ".join(re.sub(r"\b[md]\.", "", d) for d in dims)
    return f"({text})" if len(dims) > 1 else f"({text},)"


# ------------------------------------------------------------ writers

def _docstring(signature, doc, notes, indent="    "):
    """The official bindings' shape: the signature line, the header's doc comment
    (its lines kept), then mjcffi's notes; each part ends with a newline.

    The lines after the first start at column 0, so that __doc__ holds no
    indentation, as the official docstrings.
    """
    body = signature + "\n\n" + (doc or "(no header comment)") + "\n"
    if notes:
        body += "\n" + "\n".join(notes) + "\n"
    return f'{indent}"""{outputs._doc_literal(body)}"""'


_INTS = {"int", "unsigned int", "mjtSize", "size_t", "mjtByte", "unsigned char", "mjtBool",
         "uint64_t", "int64_t", "char"}


def _annotation(a, typedefs):
    """The type of an argument as the signature line shows it."""
    if a.kind in ("struct", "struct_value"):
        text = f"mujoco._structs.{class_name(a.base)}"
    elif a.kind == "scalar":
        text = "float" if a.base in ("mjtNum", "double", "float") else \
            "int" if a.base in _INTS or typedefs.get(a.base, "").startswith("enum") else "Any"
    elif a.kind == "text":
        text = "str"
    elif a.kind == "array":
        text = f"numpy.typing.NDArray[numpy.{_NUMPY[a.base]}]"
    elif a.kind in ("buffer", "chars"):
        text = "bytes" if a.const else "bytearray"
    elif a.kind == "handle":
        text = f"mjcffi._support.handles.{_handle_class(a.base)}"
    else:
        text = "Any"
    return text + (" | None" if a.nullable else "")


# What the RETURNS expressions give, for the signature line (others: Any).
_RETURN_TYPES = {"mj_readCtrl": "numpy.typing.NDArray[numpy.float64]",
                 "mj_readSensor": "numpy.typing.NDArray[numpy.float64]",
                 "mjs_getTimer": "numpy.typing.NDArray[numpy.float64]",
                 "mj_copyData": "None",
                 "mj_stackAllocNum": "numpy.typing.NDArray[numpy.float64]",
                 "mj_stackAllocInt": "numpy.typing.NDArray[numpy.int32]",
                 "mj_stackAllocByte": "numpy.typing.NDArray[numpy.uint8]"}

_NUMPY = {"mjtNum": "float64", "double": "float64", "float": "float32", "int": "int32",
          "mjtByte": "uint8", "unsigned char": "uint8", "mjtSize": "int64", "mjtBool": "bool_"}


def _signature(params, annotations=None):
    """Python parameter list; trailing nullable arguments default to None.

    With `annotations` ({name: type text}), the signature line of a docstring.
    """
    parts, optional = [], True
    for py, nullable in reversed(params):
        optional = optional and nullable
        if annotations:
            parts.append(f"{py}: {annotations[py]}" + (" = None" if optional else ""))
        else:
            parts.append(f"{py}=None" if optional else py)
    return ", ".join(reversed(parts))


class _Function:
    """Writes one generated function."""

    def __init__(self, func, note, described, typedefs, constants, ids=None, enums=None):
        self.func = func
        self.name = func.name
        self.doc = note.doc if note else ""
        self.args = _args(func, note, described, typedefs)
        self.described = described
        self.typedefs = typedefs
        self.constants = constants
        self.expr = _Exprs(self.args, constants)
        self.shapes = SHAPES.get(self.name, {})
        unknown = set(self.shapes) - {a.name for a in self.args}
        if unknown:
            raise ValueError(f"SHAPES[{self.name}] names unknown arguments {sorted(unknown)}")
        for name, table in (("MESSAGES", MESSAGES), ("SIZED", SIZED), ("BIND", BIND)):
            unknown = set(table.get(self.name, ())) - {a.name for a in self.args}
            if unknown:
                raise ValueError(f"{name}[{self.name}] names unknown arguments {sorted(unknown)}")
        self.ids = ids.get(self.name, {}) if ids is not None else {}
        self.enums = enums.get(self.name, {}) if enums is not None else {}
        self.lines = []
        self.notes = []
        self.rechecks = []      # why a prepared call must run its checks at every call
        self.sized = set(SIZED.get(self.name, ()))

    # which arguments leave the signature
    def _omitted(self):
        scalars = {a.name for a in self.args if a.kind == "scalar"}
        keep = set(KEEP.get(self.name, ()))
        sizes = set()
        for spec in self.shapes.values():
            for d in _split_dims(spec):
                found = _deducible(d, scalars)
                if found and found[0] not in keep:
                    sizes.add(found[0])
        errors = set()
        for i, a in enumerate(self.args):
            if a.kind == "chars" and a.name == "error" and i + 1 < len(self.args):
                errors |= {a.name, self.args[i + 1].name}
        return sizes, errors, set(OMIT.get(self.name, {}))

    def unsupported_reason(self):
        """Why the generic rules cannot write this function, or None."""
        sizes, errors, omit = self._omitted()
        for a in self.args:
            if a.name in omit or a.name in errors:
                continue
            if a.kind in ("callback", "pointer2"):
                return f"argument {a.name} ({a.decl}) has no generic rule"
            if a.kind in ("array", "chars") and not a.dims and a.name not in self.shapes:
                return f"argument {a.name} ({a.decl}) has no extent in SHAPES"
        if self.name in ERRORS and not errors:
            raise ValueError(f"ERRORS[{self.name}]: it has no (error, error_sz) pair")
        if errors and self.name not in ERRORS:
            return "its (error, error_sz) pair has no ERRORS entry"
        ret = self.func.restype
        if self.name in RETURNS:
            return None
        if ret.pointer and ret.base in _ELEMS:
            return f"its result ({ret.decl}) has no extent in RETURNS"
        if ret.pointer and ret.base in ("mjModel", "mjData"):
            return "it returns an mjModel or mjData: write it in _overrides.py"
        if ret.pointer > 1 or _is_callback(ret.base, ret.decl, self.typedefs):
            return f"its result ({ret.decl}) has no generic rule"
        return None

    def blockers(self):
        """Why this function has no fast path (codegen/fastpath.py), if it has none: a
        special case of the tables, or a check that reads what may change."""
        found = [table for table, names in (
            ("CHECKS", CHECKS), ("ERRORS", ERRORS), ("SCENES", SCENES), ("KEEP", KEEP),
            ("OMIT", OMIT)) if self.name in names]
        if self.name in RETURNS and RETURNS[self.name] not in ("None", "ret"):
            found.append("RETURNS")
        if draws(self.name):
            found.append("OpenGL")
        return found + self.rechecks

    def marshal_block(self, params):
        """`_F(args, *, prepare=False)`: the checks and conversions (the lines write()
        emitted), returning the guarded call."""
        head = _signature(params)
        head = f"def _{self.name}({head + ', ' if head else ''}*, prepare=False):"
        doc = (f'    """{self.name}() through its checks and conversions: the slow path.'
               f'\n\n    prepare: for {self.name}.prepare, which refuses inputs it would '
               f'copy, checks scalars now,\n    and returns the guarded call, ready to '
               f'make."""')
        return "\n".join([head, doc] + self.lines)

    def public_block(self, params):
        """`F(args)`: its docstring, its fast path if it has one, then `_F(args)`."""
        recheck = ", recheck=True" if self.rechecks else ""
        lines = [f"@_p.preparable(_{self.name}{recheck})",
                 f"def {self.name}({_signature(params)}):",
                 _docstring(self.signature_line(params), self.doc, self.notes)]
        fast = FastPath(self).lines()
        self.has_fast_path = fast is not None
        lines += ["    " + line if line else "" for line in fast or ()]
        lines.append(f"    return _{self.name}({', '.join(py for py, _ in params)})")
        return "\n".join(lines)

    def signature_line(self, params):
        """`name(arg: type, ...) -> type`, the first line of the docstring."""
        by_py = {a.py: a for a in self.args}
        typed = _signature(params, {py: _annotation(by_py[py], self.typedefs)
                                    for py, _ in params})
        return f"{self.name}({typed}) -> {self._result_annotation()}"

    def _result_annotation(self):
        ret = self.func.restype
        if self.name in RETURNS:
            return _RETURN_TYPES.get(self.name, "Any")
        if self.name in ERRORS and not ERRORS[self.name][2]:
            return "None"
        if ret.decl == "void":
            return "None"
        if ret.pointer == 0:
            if ret.base in self.described:
                return f"mujoco._structs.{class_name(ret.base)}"
            if ret.base in ("mjtNum", "double", "float"):
                return "float"
            return "int" if ret.base in _INTS or \
                self.typedefs.get(ret.base, "").startswith("enum") else "Any"
        if ret.base == "char":
            return "str"
        if ret.base in self.described:
            return f"mujoco._structs.{class_name(ret.base)}"
        if ret.pointer == 1 and _is_handle(ret.base, self.typedefs):
            return f"mjcffi._support.handles.{_handle_class(ret.base)}"
        return "Any"

    # ------------------------------------------------------------ body

    def emit(self, line=""):
        """One line of the body."""
        self.lines.append("    " + line if line else "")

    def write(self):
        """Emit the body; return the Python parameters as (name, nullable)."""
        sizes, errors, omit = self._omitted()
        params = [(a.py, a.nullable) for a in self.args
                  if a.name not in sizes | errors | set(omit) and a.kind != "varargs"]
        self.sizes, self.errors, self.omit = sizes, errors, set(omit)   # for the fast path
        body_names = {a.py for a in self.args}
        for local in ("ret", "status", "exc", "error", "error_sz", "call", "guard", "prepare",
                      "fast"):
            if local in body_names and local not in errors:
                raise ValueError(f"{self.name}: argument {local!r} clashes with a local name")

        self._structs()
        if self.name in SCENES:
            self.rechecks.append("the scene may be remade")
            self._scene_check()
        for a in self.args:
            if a.kind == "text":
                conv = "opt_text" if a.nullable else "text"
                self.emit(f'c_{a.py} = _m.{conv}({a.py}, "{a.py}")')
            elif a.kind == "handle":
                self.rechecks.append(f"{a.py} is a handle whose element may be deleted")
                nullable = ", True" if a.nullable else ""
                self.emit(f'c_{a.py} = _h.argument({a.py}, "{a.base}", "{a.py}"{nullable})')
                self.notes.append(f"{a.py}: {'an' if a.base.startswith('mj') else 'a'} "
                                  f"{a.base} handle{' or None' if a.nullable else ''} (a field "
                                  f"of a spec element, or a function's result), never a "
                                  f"raw pointer.")
            elif a.kind == "opaque" or (a.kind == "buffer" and a.name not in self.shapes):
                self.rechecks.append(f"{a.py} is a raw pointer")
                self.emit(f'c_{a.py} = _m.opaque({a.py}, "{a.py}", {a.nullable})')
        for argname, enum in self.enums.items():
            py = next(a.py for a in self.args if a.name == argname)
            self.emit(f'if {py}.__class__ is not int or {py} not in _ENUMS["{enum}"]:')
            self.emit(f'    {py} = _c.enum_value({py}, _ENUMS["{enum}"], "{py}", "{enum}")')
            self.notes.append(f"{py} must be a value of {enum}.")
        for var in KEEP.get(self.name, ()):
            message = _message(MESSAGES.get(self.name, {}).get(var))
            self.emit(f'{var} = _m.count({var}, "{var}"{message})')
        messages = MESSAGES.get(self.name, {})
        for argname, (low, count) in self.ids.items():
            self._id_check(argname, low, count, messages.get(argname))
        names = {a.name: a for a in self.args}
        for a in self.args:            # the body, flex and skin an mjvPerturb selects
            if a.kind == "struct" and a.base == "mjvPerturb" and any(
                    b.base in ("mjModel", "mjData") and b.kind == "struct" for b in self.args):
                self.rechecks.append(f"the ids {a.py} selects may change")
                self.emit(f'_m.perturb({self._model_expr()}, c_{a.py}, "{a.py}")')
        if "objtype" in names and "objid" in names:
            model = self._model_expr()
            self.emit(f'_m.object_id({model}, {names["objtype"].py}, {names["objid"].py}, '
                      f'"{names["objid"].py}")')
            self.notes.append(f"{names['objid'].py} must be within 0..count-1 of its "
                              f"{names['objtype'].py}.")
        self._arrays(sizes)
        for statement in CHECKS.get(self.name, ()):
            self.rechecks.append("a check of CHECKS reads values that may change")
            self.emit(self.expr(statement))
        if draws(self.name):
            self.rechecks.append("it draws in the OpenGL context current at the call")
            self._opengl_check()
        for spec in [*self.shapes.values(), RETURNS.get(self.name, "")]:
            if "[" in spec or re.search(r"\bd\.", spec):
                self.rechecks.append(f"an extent reads the model's values or the data ({spec})")
        self._call(errors, omit)
        return params

    def _opengl_check(self):
        """The mjrContext was made, in the OpenGL context current now (mjcffi/_support/mjr.py);
        without one, some context is current.  When it fails, a wrong scalar (which only
        the call itself converts) is named instead."""
        con = next((a for a in self.args if a.kind == "struct" and a.base == "mjrContext"),
                   None)
        if con is None:
            check = f'_r.gl_ready("{self.name}")'
            self.notes.append("An OpenGL context must be current, and an MjrContext made "
                              "(FatalError otherwise).")
        else:
            check = f'_r.context({con.py}, "{con.py}", "{self.name}")'
            self.notes.append(f"{con.py} must be an MjrContext made (not freed) in the "
                              f"OpenGL context current on this thread (ValueError, "
                              f"FatalError otherwise).")
        scalars = [a for a in self.args if a.kind == "scalar"]
        if not scalars:
            self.emit(check)
            return
        entries = [f'"{a.py}": ("{a.decl}", {a.py})' for a in scalars]
        self.emit("try:")
        self.emit(f"    {check}")
        self.emit("except (TypeError, ValueError, _m.FatalError):")
        self.emit("    " + _wrapped(f'bad = _m.bad_scalar("{self.name}", {{', entries, "})",
                                    "        "))
        self.emit("    if bad is not None:")
        self.emit("        raise bad from None")
        self.emit("    raise")

    def _scene_check(self):
        """The scene must be made for a model of the call's flex and skin layout."""
        scene = next(a for a in self.args if a.kind == "struct" and a.base == "mjvScene")
        self.emit(f'_c.scene({self._model_expr()}, {scene.py}, c_{scene.py}, "{scene.py}")')
        self.notes.append(f"{scene.py} must be made for a model with the flexes and skins "
                          f"of this one (MjvScene(m, maxgeom) or mjv_makeScene).")

    def _model_expr(self):
        """The C mjModel of the call: its mjModel argument, or the model of its mjData."""
        model = next((a for a in self.args if a.kind == "struct" and a.base == "mjModel"
                      and not a.nullable), None)
        if model is not None:
            return f"c_{model.py}"
        data = next((a for a in self.args if a.kind == "struct" and a.base == "mjData"), None)
        if data is None:
            raise ValueError(f"{self.name}: an id check needs an mjModel or mjData argument")
        return f'_m.model_of({data.py}, "{data.py}")'

    def _id_check(self, argname, low, count, message):
        """One integer comparison on the fast path; _m.index converts, or raises IdError."""
        py = next(a.py for a in self.args if a.name == argname)
        if count.startswith("m."):
            limit = f"{self._model_expr()}.{count[2:]}"
        else:
            limit = self.expr(count)
        if not count.startswith("m."):
            self.rechecks.append(f"{py}'s range ({count}) may change")
        if limit.startswith("_m.model_of("):          # not a plain read: once
            self.emit(f"limit_{py} = {limit}")
            limit = f"limit_{py}"
        self.emit(f"if {py}.__class__ is not int or not {low} <= {py} < {limit}:")
        self.emit(f'    {py} = _m.index({py}, {limit}, "{py}", {low}{_message(message)})')
        self.notes.append(f"{py} must be within {low}..{re.sub(r'^[md][.]', '', count)}-1.")

    def _structs(self):
        """Struct arguments; each mjData is checked against the function's mjModel."""
        model = next((a for a in self.args if a.kind == "struct" and a.base == "mjModel"
                      and not a.nullable), None)
        datas = [a for a in self.args if a.kind == "struct" and a.base == "mjData"
                 and not a.nullable] if model else []
        if datas:
            first = datas[0]
            self.emit(f'c_{model.py}, c_{first.py} = _m.model_data({model.py}, {first.py}, '
                      f'"{model.py}", "{first.py}")')
            for d in datas[1:]:
                self.emit(f'c_{d.py} = _m.data_of({model.py}, {d.py}, "{model.py}", "{d.py}")')
        done = {id(a) for a in datas} | ({id(model)} if datas else set())
        for a in self.args:
            if id(a) in done:
                continue
            if a.kind == "struct_value":
                self.rechecks.append(f"{a.py} is passed by value")
                self.emit(f'c_{a.py} = _m.struct_value({a.py}, "{a.base}", "{a.py}")')
            elif a.kind == "struct":
                conv = "opt_struct" if a.nullable else "struct"
                if a.base not in ("mjModel", "mjData"):      # those keep their memory
                    self.rechecks.append(f"{a.py}'s wrapper may be given new memory")
                self.emit(f'c_{a.py} = _m.{conv}({a.py}, "{a.base}", "{a.py}")')

    def _arrays(self, sizes):
        """Convert the arrays; deduce the sizes; check every array's extents.

        Arrays that give a size are converted first; the others are converted
        with their expected extents, so that one call converts and checks.
        """
        arrays = [a for a in self.args if a.kind in ("array", "chars", "buffer")
                  and a.name != "error" and (a.dims or a.name in self.shapes)]
        specs = {a.name: _split_dims(self.shapes[a.name]) if a.name in self.shapes
                 else [str(n) for n in a.dims] for a in arrays}
        order = [a.name for a in self.args]
        chains = {}
        for var in sorted(sizes, key=order.index):
            binders = []
            for a in arrays:
                for axis, d in enumerate(specs[a.name]):
                    found = _deducible(d, {var})
                    if found:
                        binders.append((a, len(specs[a.name]), axis, found[1]))
                        break
            if not binders:
                raise ValueError(f"{self.name}: no array gives size {var}")
            # prefer arrays that BIND names, then arrays that are always given,
            # then sizes read from flat (1-D) dims, then inputs
            bind = BIND.get(self.name, ())
            binders.sort(key=lambda b: (b[0].name not in bind, b[0].nullable, b[1] > 1,
                                        not b[0].const))
            chain = []
            for binder in binders:
                chain.append(binder)
                if not binder[0].nullable:
                    break
            chains[var] = chain
        first = {b[0].name for chain in chains.values() for b in chain}
        self.arrays, self.specs, self.chains = arrays, specs, chains   # for the fast path

        messages = MESSAGES.get(self.name, {})
        sized = set(SIZED.get(self.name, ()))

        def convert(a, dims):
            direction = "in" if a.const else "out"
            if a.kind in ("buffer", "chars"):
                conv = f"opt_buffer_{direction}" if a.nullable else f"buffer_{direction}"
                self.emit(f'c_{a.py}, nbytes_{a.py} = _m.{conv}({a.py}, "{a.py}")')
                return
            conv = f"opt_{direction}" if a.nullable else f"array_{direction}"
            extra = f", {dims}{_message(messages.get(a.name))}" if dims else ""
            live = ", live=prepare" if a.const else ""
            self.emit(f'{a.py}, c_{a.py} = _m.{conv}({a.py}, _m.{_ELEMS[a.base]}, '
                      f'"{a.py}"{extra}{live})')

        def extents(a):
            dims = specs[a.name]
            if dims == ["*"] or a.kind in ("buffer", "chars"):
                return None
            if a.name in sized:                   # its number of elements
                return " * ".join(f"({self.expr(d)})" if not d.isdigit() else d
                                  for d in dims)
            if len(dims) == 1:
                return self.expr(dims[0])
            return "(" + ", ".join(self.expr(d) for d in dims) + ")"

        binders = {b[0].name for chain in chains.values() for b in chain}
        if binders & sized:
            raise ValueError(f"{self.name}: SIZED arrays {sorted(binders & sized)} give sizes")
        for a in arrays:                          # the arrays that give sizes
            if a.name in first:
                convert(a, None)
        for var, chain in chains.items():
            for i, (a, ndims, axis, factor) in enumerate(chain):
                if a.kind in ("buffer", "chars"):
                    value = f"nbytes_{a.py} // {factor}" if factor > 1 else f"nbytes_{a.py}"
                else:
                    value = (f'_m.dim({a.py}, {ndims}, {axis}, {factor}, "{a.py}"'
                             f'{_message(messages.get(a.name))})')
                self.emit(f"{var} = {value}" if i == 0 else f"if {var} is None:")
                if i:
                    self.emit(f"    {var} = {value}")
            if chain[-1][0].nullable:
                self.emit(f"if {var} is None:")
                self.emit(f"    {var} = 0")
        order = list(messages)                    # the official bindings' order first
        for a in sorted(arrays, key=lambda a: order.index(a.name) if a.name in order
                        else len(order)):
            dims = extents(a)
            message = _message(messages.get(a.name))
            if a.name in sized and dims is not None:
                if a.name not in first:
                    convert(a, None)
                self.emit(f'_m.size({a.py}, {dims}, "{a.py}"{message})')
            elif a.name not in first:
                convert(a, dims)
            elif dims is not None:
                self.emit(f'_m.shape({a.py}, {dims}, "{a.py}"{message})')
        for a in arrays:                          # the notes, in the arguments' order
            if a.kind not in ("buffer", "chars") and specs[a.name] != ["*"]:
                shape = _human(", ".join(specs[a.name]))
                what = "of the size of" if a.name in sized else "of shape"
                self.notes.append(f"{a.py}: {'output ' if not a.const else ''}array {what} "
                                  f"{shape}{' or None' if a.nullable else ''}.")

    def call_values(self, errors, omit, names=None):
        """The C call's arguments, as Python expressions: `c_<py>` for what was converted
        (or `names[py]`), the argument itself for a scalar; and the scalar arguments."""
        values, scalars = [], []
        for a in self.args:
            if a.kind == "varargs":
                continue
            if a.name in omit:
                values.append(self.expr(OMIT[self.name][a.name]))
            elif a.name == "error":
                values.append("error")
            elif a.name in errors:
                values.append("error_sz")
            elif a.kind == "scalar":
                values.append(a.py)
                scalars.append(a)
            else:
                values.append((names or {}).get(a.py, f"c_{a.py}"))
        return values, scalars

    def _call(self, errors, omit):
        """The end of `_F`: the guarded call, made now; or, for F.prepare, `_bind_F(...)`,
        the call ready to make.  The closure lives in `_bind_F`, so that `_F` itself has
        no cell variables, which would cost every plain call of it."""
        values, scalars = self.call_values(errors, omit)
        entries = [f'"{a.py}": ("{a.decl}", {a.py})' for a in scalars]
        body = self._call_body("guard", values, scalars, entries, "        ")
        self.bound_names = self._locals_read(body)
        self.emit("if prepare:")
        if scalars:
            self.emit("    " + _wrapped(f'_m.check_scalars("{self.name}", {{', entries, "})",
                                        "        "))
        self.emit("    " + _wrapped(f"return _bind_{self.name}(", self.bound_names, ")",
                                    "    "))
        for line in self._call_body(f"_lib.mjcffi_guard_{self.name}", values, scalars,
                                    entries, "    "):
            self.emit(line)
        self.bind_body = body

    def _locals_read(self, body):
        """The names of `_F`'s locals (arguments, converted values, sizes) that `body` reads."""
        text = "\n".join(body)
        candidates = []
        for a in self.args:
            if a.name in self.errors:           # the error buffer is made at each call
                continue
            candidates += [a.py, f"c_{a.py}", f"nbytes_{a.py}", f"limit_{a.py}"]
        candidates += sorted(self.sizes)
        found = []
        for name in candidates:
            if name not in found and re.search(rf"(?<![\w.]){re.escape(name)}\b", text):
                found.append(name)
        return found

    def bind_block(self):
        """`_bind_F(...)`: the guarded call over what `_F` converted, as a closure."""
        head = _wrapped(f"def _bind_{self.name}(", self.bound_names, "):", "")
        doc = (f'    """The guarded call of {self.name} with these converted arguments, ready '
               f'to make\n    ({self.name}.prepare)."""')
        lines = [head, doc, f"    guard = _lib.mjcffi_guard_{self.name}", "", "    def call():"]
        lines += ["        " + line if line else "" for line in self.bind_body]
        return "\n".join(lines + ["    return call"])

    def _call_body(self, guard, values, scalars, entries, indent):
        """The guarded call through `guard` and what follows it (see ending)."""
        body = ["error, error_sz = _m.error_buffer()"] if self.errors else []
        void = self.func.restype.decl == "void"
        call = _wrapped(f"{'status' if void else 'ret'} = {guard}(", values, ")",
                        indent + ("    " if scalars else ""))
        if scalars:
            body += ["try:", "    " + call, "except (TypeError, OverflowError) as exc:",
                     "    " + _wrapped(f'raise _m.scalar_error(exc, "{self.name}", {{',
                                       entries, "}) from None", indent + "    ")]
        else:
            body.append(call)
        return body + self.ending()

    def ending(self):
        """The lines after `status = ...` or `ret = ...`: the error checks, the result."""
        ret = self.func.restype
        # first, as an error may leave the stack released too
        lines = ["if _m.stack.live:", f"    _m.stack.sweep({RELEASES[self.name]})"] \
            if self.name in RELEASES else []
        if ret.decl == "void":
            return lines + ["if status or _contract.pending:", "    _m.check(status)"]
        if ret.pointer == 0 and ret.base in self.described:
            lines.append("_m.check_error()")      # a struct returned by value: no zero test
        else:                                     # a guard returns zero on an error
            lines += ["if not ret or _contract.pending:", "    _m.check_error()"]
        if self.name in ERRORS:
            test, exc, returns = ERRORS[self.name]
            exc = "_m.FatalError" if exc == "FatalError" else exc
            lines += [f"if {self.expr(test)}:",
                      f'    raise {exc}(_m.error_text(error, "{self.name}"))']
            if not returns:
                return lines
        return lines + [f"return {self._result(ret)}"]

    def _result(self, ret):
        if self.name in RETURNS:
            return self.expr(RETURNS[self.name])
        if ret.pointer == 0:
            if ret.base in self.described:
                return f"_m.struct_copy(_structs.{class_name(ret.base)}, ret)"
            return "ret"
        if ret.base == "char":
            return "_m.string(ret)"
        if ret.base in self.described:
            cls = f"_structs.{class_name(ret.base)}"
            owner = next((a.py for a in self.args if a.kind == "struct"), "None")
            if ret.decl.startswith("const "):     # MuJoCo's own (a global plugin table)
                return f"_m.wrap_const({cls}, ret, {owner})"
            if self.name in OWNED:
                return f"_m.own({cls}, ret, _lib.{OWNED[self.name]})"
            return f"_m.wrap({cls}, ret, {owner})"
        if ret.pointer == 1 and _is_handle(ret.base, self.typedefs):
            owner = next((a.py for a in self.args if a.kind == "struct"), "None")
            return f'_h.result(ret, "{ret.base}", {owner})'
        return "None if ret == _m.NULL else ret"     # void *


def _message(message):
    """The trailing `, message` argument of a check, or ""."""
    return "" if message is None else f", {message!r}"


def _wrapped(head, items, tail, indent, width=100):
    """`head` + comma-separated `items` + `tail`, broken over lines to fit `width`."""
    line = head + ", ".join(items) + tail
    if len(indent) + len(line) <= width:
        return line
    lines, current = [head.rstrip()], indent + "    "
    for item in items:
        piece = item + ","
        if len(current) + len(piece) + 1 > width and current.strip():
            lines.append(current.rstrip())
            current = indent + "    "
        current += piece + " "
    lines.append(current.rstrip().rstrip(",") + tail)
    return ("\n").join(lines)


def _unsupported(func, note, reason, described, typedefs):
    args = [a for a in _args(func, note, described, typedefs) if a.kind != "varargs"]
    params = _signature([(a.py, a.nullable) for a in args])
    notes = textwrap.wrap(f"Not available in mjcffi: {reason}.", 92)
    typed = _signature([(a.py, a.nullable) for a in args],
                       {a.py: _annotation(a, typedefs) for a in args})
    doc = _docstring(f"{func.name}({typed}) -> None", note.doc if note else "",
                     notes + [f"The raw C function is mjcffi.lib.{func.name}."])
    return "\n".join([
        f"@_p.preparable(None, unsupported={reason!r})",
        f"def {func.name}({params}):",
        doc,
        "    raise NotImplementedError(",
        f"        {func.name + ': ' + reason!r})",
    ])


def generate(decls, notes, described, header_texts):
    """{path: text} of mjcffi/_functions/: its __init__ (names, lazy lookup), _common and
    one module per section of mujoco.h (and mjbatch.h), every function of the headers."""
    constants = _defines(header_texts, decls)
    for table in (SHAPES, KEEP, BOUNDS, CHECKS, ERRORS, RETURNS, RELEASES, OWNED, RENAMES, OMIT,
                  NULLABLE, NOT_NULLABLE, OVERRIDES, UNSUPPORTED, MESSAGES, SIZED, BIND,
                  SCENES, {f for f, _ in ID_EXCEPTIONS}, {f for f, _ in ENUM_EXCEPTIONS},
                  {f for f, _ in ENUM_INTS}, NO_OPENGL):
        unknown = set(table) - set(decls.functions)
        if unknown:
            raise ValueError(f"special-case table names unknown functions {sorted(unknown)}")
    both = set(OVERRIDES) & set(UNSUPPORTED)
    if both:
        raise ValueError(f"both overridden and unsupported: {sorted(both)}")

    for name, args in NOT_NULLABLE.items():
        marked = set(notes.functions[name].nullable) if name in notes.functions else set()
        if set(args) - marked:
            raise ValueError(f"NOT_NULLABLE[{name}]: {sorted(set(args) - marked)} are not "
                             f"marked Nullable in the header")
    ids = derive_ids(decls, notes, set(OVERRIDES) | set(UNSUPPORTED))
    IDS._table = ids
    enums = derive_enums(decls, set(OVERRIDES) | set(UNSUPPORTED))
    for (name, arg), enum in ENUM_INTS.items():
        if arg not in {a.name for a in decls.functions[name].args} or enum not in decls.enums:
            raise ValueError(f"ENUM_INTS[{name}, {arg}]: no such argument or enum {enum}")
        enums.setdefault(name, {})[arg] = enum
    group_of = sections(header_texts, decls.functions)
    groups = {}            # section -> ([blocks], [names defined])
    for name, func in decls.functions.items():
        note = notes.functions.get(name)
        if name in OVERRIDES:          # hand-written: mjcffi/functions/__init__.py puts it in place
            continue
        blocks, defined = groups.setdefault(group_of[name], ([], []))
        if name in UNSUPPORTED:
            blocks.append(_unsupported(func, note, UNSUPPORTED[name], described,
                                       decls.typedefs))
            defined.append(name)
            continue
        writer = _Function(func, note, described, decls.typedefs, constants, ids, enums)
        reason = writer.unsupported_reason()
        if reason:
            raise ValueError(f"{name}: {reason}; add it to SHAPES, OVERRIDES or UNSUPPORTED")
        params = writer.write()
        blocks.append(writer.bind_block())
        blocks.append(writer.marshal_block(params))
        blocks.append(writer.public_block(params))
        defined += [name, "_" + name, "_bind_" + name]
        FAST_PATHS[name] = writer.has_fast_path
    hand_docs = {name: (notes.functions[name].doc if name in notes.functions else "")
                 for name in decls.functions if name in OVERRIDES}
    files = {f"{PACKAGE}/__init__.py": _package_init(groups, list(decls.functions), hand_docs),
             f"{PACKAGE}/_common.py": outputs.HEADER_PY + _COMMON + _enum_table(decls, enums)}
    # for type checkers, which do not run __getattr__: every section's names
    files[f"{PACKAGE}/__init__.pyi"] = outputs.HEADER_PY + "".join(
        f"from .{section} import *\n" for section in sorted(groups)) + \
        "from .._support.arena import _realloc_con_efc as _realloc_con_efc\n" \
        "from .._support.arena import _realloc_island as _realloc_island\n\n" \
        "NAMES: tuple[str, ...]\nHAND_WRITTEN_DOCS: dict[str, str]\n"
    for section, (blocks, defined) in sorted(groups.items()):
        home = ("\n\n# their module is the package, as the official's are mujoco._functions's "
                "(reprs, pickles)\n" + _wrapped("for _f in (", defined, "):", "    ")
                + "\n    _f.__module__ = __package__\ndel _f\n")
        files[f"{PACKAGE}/{section}.py"] = (
            outputs.HEADER_PY + f'"""MuJoCo\'s functions of {_SECTION_TITLES[section]} (see '
            f'the package\'s docstring)."""\n\nfrom ._common import *  # noqa: F401,F403  '
            f'(the names every function uses)\n\n\n' + "\n\n\n".join(blocks) + "\n"
            + home)
    return files


def text_of(files):
    """The whole function layer as one text, sections in order (for readers of its
    source, such as codegen/simfunctions.py)."""
    return "\n".join(text for path, text in sorted(files.items())
                     if path.startswith(PACKAGE + "/"))


# the function layer: a package at the official path mujoco._functions, one module per
# section of mujoco.h, each imported on first use of one of its names
PACKAGE = "mjcffi/_functions"
_SECTION_HEADING = re.compile(r"^//-+\s*(.+?)\s*-+\s*$")
_SECTION_TITLES = {}


def sections(header_texts, functions):
    """{function: module name}: the section of mujoco.h it is declared under (its
    `//---- Main simulation ----` heading, as main_simulation), and batch for mjbatch.h."""
    out = {}
    for header, default in (("mujoco.h", None), ("mjbatch.h", "batch")):
        section = default
        if default:
            _SECTION_TITLES[default] = "mjbatch.h"
        for line in header_texts[header].splitlines():
            heading = _SECTION_HEADING.match(line)
            if heading and not default:
                title = heading.group(1)
                section = re.sub(r"\W+", "_", title.lower()).strip("_")
                _SECTION_TITLES[section] = f"mujoco.h's section {title!r}"
                continue
            for name in re.findall(r"\b(mj\w+)\s*\(", line):
                if name in functions and name not in out and section:
                    out[name] = section
    missing = sorted(set(functions) - set(out))
    if missing:
        raise ValueError(f"functions under no section of mujoco.h or mjbatch.h: {missing}")
    return out


def _package_init(groups, names, hand_docs):
    """mjcffi/_functions/__init__.py: every function's name, which module defines each
    generated name, and the lazy lookup."""
    lines = [outputs.HEADER_PY.rstrip("\n"), _PACKAGE_DOC, "",
             "import importlib as _importlib", "",
             "from .._support import hand_written as _hand_written",
             "from .._support.arena import _realloc_con_efc, _realloc_island  # noqa: F401  "
             "(official private)", "",
             "# every function of mujoco.h and mjbatch.h, in the headers' order; those not in",
             "# _MODULE_OF are hand-written (mjcffi/functions/_overrides.py)",
             _wrapped("NAMES = (", [f'"{n}"' for n in names], ")", "    "), "",
             "# name -> the module of this package that defines it",
             "_MODULE_OF = {"]
    for section, (_, defined) in sorted(groups.items()):
        lines.append(_wrapped("    **dict.fromkeys((", [f'"{n}"' for n in defined],
                              f'), "{section}"),', "        "))
    lines += ["}", "", "# the header's doc comment of each hand-written one (mjcffi/functions puts it in",
              "# their docstrings without loading the whole table of mjcffi._generated.funcinfo)",
              "HAND_WRITTEN_DOCS = {"]
    lines += [f"    {name!r}: {doc!r}," for name, doc in hand_docs.items()]
    lines += ["}", "", "", _PACKAGE_TAIL]
    return "\n".join(lines)


_PACKAGE_DOC = '''"""MuJoCo's functions, one Python function each, with the official bindings' signatures.

One module per section of mujoco.h (main_simulation, support, vector_math, ...) and
one for mjbatch.h.  A module is imported on first use of one of its names, here or
through mjcffi, so that a process without .pyc files compiles only what it calls.

Each function F comes in three parts.  `_F(args)`, the slow path, checks and
converts the arguments with mjcffi/_support/marshal.py (see its docstring for the rules)
and calls the guarded C twin `lib.mjcffi_guard_F`, so that a mju_error raises
mjcffi.FatalError.  `F(args)` first tries its fast path, where one exists:
exact NumPy arrays of the right dtype, layout and shape, ids in range, tested
inline and passed straight to C; anything else, or anything the fast path is
unsure of, goes to `_F(args)`, with its conversions and its messages.
`F.prepare(args)` runs `_F(args, prepare=True)`, which hands what it converted
to `_bind_F`: the guarded call, ready to make (mjcffi/_support/prepared.py).
Sizes such as mju_add's `n` are deduced from the arrays.  `lib.<name>` is the
raw C function.
"""'''

_PACKAGE_TAIL = '''def __getattr__(name):
    module = _MODULE_OF.get(name)
    if module is not None:
        value = getattr(_importlib.import_module(f"{__name__}.{module}"), name)
    elif name in HAND_WRITTEN_DOCS:  # as the official's path holds them too
        value = _hand_written.function(name)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value          # the next lookup is a plain global
    return value


def __dir__():
    return sorted(set(globals()) | set(_MODULE_OF) | set(HAND_WRITTEN_DOCS))


def modules():
    """Every module of the layer, imported."""
    return [_importlib.import_module(f"{__name__}.{m}") for m in sorted(set(_MODULE_OF.values()))]
'''


def _enum_table(decls, enums):
    """`_ENUMS`: the members of each enum an argument is declared as, for its check."""
    used = sorted({enum for table in enums.values() for enum in table.values()})
    lines = ["", "# the values of the C enums that arguments are declared as (derive_enums)",
             "_ENUMS = {"]
    for enum in used:
        values = sorted({value for _, value in decls.enums[enum].members})
        lines.append(_wrapped(f'    "{enum}": frozenset((', [str(v) for v in values], ")),",
                              "    "))
    return "\n".join(lines + ["}", ""])
