"""Checks the model an MJB holds before MuJoCo loads it: no id, address, count or
type that would make MuJoCo read or write out of bounds, loop forever or crash.

MuJoCo's loader (mj_loadModelBuffer) checks an MJB's sizes and many of its
references, but not all of them: a flipped byte of an MJB (a pickled MjModel, the
model inside a pickled MjData) could load, and then mj_makeData or mj_forward
crashed or never returned.  `mjb_problem` reads the MJB in place (mjb.py) and
checks, before MuJoCo sees a byte of it, the fields the metadata classifies
(fields.py), the kinematic tree and its sparse structures (tree.py), the
references whose category a type decides (references.py), what sizes mjData's
buffers (buffers.py), and meshes, hierarchies and flexes (geometry.py).

Every check is listed in CHECKED with the fields it covers; the tests hold
INDEX_FIELDS (the fields Batch.expand refuses to vary) to be covered by them.
"""

from . import buffers, fields, geometry, references, tree
from .fields import ENUM_FIELDS, ID_FIELDS, INDEX_FIELDS, SPANS
from .mjb import CHECKED, Bad, Model, is_this_layout

__all__ = ["CHECKED", "ENUM_FIELDS", "ID_FIELDS", "INDEX_FIELDS", "SPANS", "Model",
           "mjb_problem"]

# The order matters: a check relies on what the ones before it made sure of
# (ids and spans in range before the tree is walked, the tree before what hangs on it).
_CHECKS = (fields.check_options, fields.check_enums, fields.check_condims,
           fields.check_ids, fields.check_spans, fields.check_colind,
           tree.check_bodies, tree.check_joints, tree.check_dofs, tree.check_trees,
           tree.check_inertia, tree.check_body_dofs,
           references.check_geoms, geometry.check_meshes, geometry.check_faces,
           references.check_tendons, tree.check_tendon_jacobian, references.check_sensors,
           buffers.check_actuators, buffers.check_history,
           references.check_equalities, references.check_tuples,
           geometry.check_hierarchies, geometry.check_flexes,
           buffers.check_strings, buffers.check_plugins)


def mjb_problem(mjb):
    """None if the model in the MJB bytes `mjb` is one MuJoCo can load and simulate
    without reading or writing out of bounds; otherwise a text naming the field,
    index and value that is wrong, the first the checks meet."""
    if not is_this_layout(mjb):
        return None                     # another version's header: MuJoCo refuses it
    try:
        m = Model(mjb)
        for check in _CHECKS:
            check(m)
    except Bad as bad:
        return str(bad)
    return None
