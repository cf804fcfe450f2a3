"""The kinematic tree recomputed as MuJoCo's compiler makes it, and compared: parents
before children, roots and welds, trees, the joints' qpos and dof addresses, the
dofs' bodies, joints and parents; and the sparse structures that follow from it
(the inertia M and D with their maps, the body-dof matrix B, the tendon Jacobian),
so that MuJoCo's tree walks end and its buffers are as large as what it writes."""

import numpy as np

from ..._generated import enums as _enums
from .mjb import covers, fail, first

NQ = {0: 7, 1: 4, 2: 1, 3: 1}          # mjtJoint -> qpos count: free, ball, slide, hinge
NV = {0: 6, 1: 3, 2: 1, 3: 1}
_WRAP = _enums.mjtWrap


@covers("body_parentid", "body_rootid", "body_weldid", "body_mocapid")
def check_bodies(m):
    """Parents before children; roots, welds and mocap ids recomputed from them."""
    if m.nbody < 1:
        fail("nbody", None, m.nbody, "a model has at least the world body")
    parent, root = m.flat("body_parentid"), m.flat("body_rootid")
    weld, mocap = m.flat("body_weldid"), m.flat("body_mocapid")
    dofnum = m.flat("body_dofnum")
    if parent[0] != 0 or root[0] != 0 or weld[0] != 0 or mocap[0] != -1:
        fail("body_parentid", 0, parent[0], "the world is its own parent, root and weld")
    for b in range(1, m.nbody):
        p = parent[b]
        if not 0 <= p < b:
            fail("body_parentid", b, p, f"a body's parent comes before it, in [0, {b})")
        if root[b] != (b if p == 0 else root[p]):
            fail("body_rootid", b, root[b], f"body {b}'s root is {b if p == 0 else root[p]}")
        own = b if dofnum[b] > 0 or mocap[b] >= 0 else weld[p]
        if weld[b] != own:
            fail("body_weldid", b, weld[b], f"body {b}'s weld is {own}")
        if mocap[b] >= 0 and p != 0:
            fail("body_mocapid", b, mocap[b], "a mocap body is a child of the world")
    ids = sorted(i for i in mocap if i >= 0)
    if ids != list(range(m.nmocap)):
        fail("body_mocapid", None, ids, f"the mocap bodies hold the ids 0..{m.nmocap - 1} once")


def _owned(m, owner, adr, num):
    """Objects listed by owner (jnt_bodyid), in order, in blocks (body_jntadr/num)."""
    ids = m.arrays[owner].ravel().astype(np.int64)
    n = len(m.arrays[adr])
    if len(ids) > 1 and (ids[1:] < ids[:-1]).any():
        k = 1 + first(ids[1:] < ids[:-1])
        fail(owner, k, int(ids[k]), "objects are stored in the order of their owners")
    counts = np.bincount(ids, minlength=n)[:n]
    nums = m.arrays[num].ravel()
    if (counts != nums).any():
        b = first(counts != nums)
        fail(num, b, int(nums[b]), f"{owner} gives it {int(counts[b])}")
    starts = np.searchsorted(ids, np.arange(n))
    adrs = m.arrays[adr].ravel()
    bad = (nums > 0) & (adrs != starts)
    if bad.any():
        b = first(bad)
        fail(adr, b, int(adrs[b]), f"its first one is {int(starts[b])}")


@covers("jnt_qposadr", "jnt_dofadr", "jnt_bodyid", "dof_jntid", "dof_bodyid", "body_jntadr",
        "body_jntnum", "body_dofadr", "body_dofnum", "body_geomadr", "body_geomnum",
        "geom_bodyid")
def check_joints(m):
    """Joint qpos/dof addresses from their types; dofs' joints and bodies from them."""
    types = m.flat("jnt_type")
    qposadr, dofadr = m.flat("jnt_qposadr"), m.flat("jnt_dofadr")
    jbody = m.flat("jnt_bodyid")
    dof_jnt, dof_body = m.flat("dof_jntid"), m.flat("dof_bodyid")
    nq = nv = 0
    for j, t in enumerate(types):
        if qposadr[j] != nq:
            fail("jnt_qposadr", j, qposadr[j], f"joint {j}'s qpos start at {nq}")
        if dofadr[j] != nv:
            fail("jnt_dofadr", j, dofadr[j], f"joint {j}'s dofs start at {nv}")
        for i in range(nv, min(nv + NV[t], m.nv)):
            if dof_jnt[i] != j:
                fail("dof_jntid", i, dof_jnt[i], f"dof {i} belongs to joint {j}")
            if dof_body[i] != jbody[j]:
                fail("dof_bodyid", i, dof_body[i], f"dof {i} belongs to body {jbody[j]}")
        nq, nv = nq + NQ[t], nv + NV[t]
    if nq != m.nq:
        fail("nq", None, m.nq, f"the joints have {nq} qpos")
    if nv != m.nv:
        fail("nv", None, m.nv, f"the joints have {nv} dofs")
    _owned(m, "jnt_bodyid", "body_jntadr", "body_jntnum")
    _owned(m, "dof_bodyid", "body_dofadr", "body_dofnum")
    _owned(m, "geom_bodyid", "body_geomadr", "body_geomnum")


def _dof_parents(m):
    """Each dof's parent dof: the one before it in its body, else the last dof of the
    nearest ancestor body that has dofs, else -1."""
    parent = m.flat("body_parentid")
    dofadr, dofnum = m.flat("body_dofadr"), m.flat("body_dofnum")
    last = [-1] * m.nbody                   # the last dof at or above each body
    out = [-1] * m.nv
    for b in range(1, m.nbody):
        above = last[parent[b]]
        for k in range(dofnum[b]):
            out[dofadr[b] + k] = above if k == 0 else dofadr[b] + k - 1
        last[b] = dofadr[b] + dofnum[b] - 1 if dofnum[b] else above
    return out


@covers("dof_parentid", "dof_simplenum")
def check_dofs(m):
    for i, (actual, expected) in enumerate(zip(m.flat("dof_parentid"), _dof_parents(m))):
        if actual != expected:
            fail("dof_parentid", i, actual, f"dof {i}'s parent is {expected}")
    for i, run in enumerate(m.flat("dof_simplenum")):
        if not 0 <= run <= m.nv - i:
            fail("dof_simplenum", i, run, f"a run of simple dofs from {i} ends by nv = {m.nv}")


@covers("body_treeid", "dof_treeid", "tree_bodyadr", "tree_bodynum", "tree_dofadr",
        "tree_dofnum", "tendon_treenum", "tendon_treeid")
def check_trees(m):
    """Each dof's tree is its body's; each tree's bodies and dofs are one block of
    them; a tendon's first two trees are given as it counts them."""
    body_tree, dof_tree = m.flat("body_treeid"), m.flat("dof_treeid")
    for i, b in enumerate(m.flat("dof_bodyid")):
        if dof_tree[i] != body_tree[b]:
            fail("dof_treeid", i, dof_tree[i], f"dof {i}'s body {b} is in tree {body_tree[b]}")
    for kind, ids in (("body", body_tree), ("dof", dof_tree)):
        adrs, nums = m.flat(f"tree_{kind}adr"), m.flat(f"tree_{kind}num")
        counts = np.bincount([i for i in ids if i >= 0], minlength=m.ntree)
        for t, (adr, num) in enumerate(zip(adrs, nums)):
            if num != counts[t] or any(x != t for x in ids[adr:adr + num]):
                fail(f"tree_{kind}adr", t, adr, f"tree {t}'s {counts[t]} {kind}s (with "
                     f"{kind}_treeid {t}) are one block, of tree_{kind}num = {num}")
    for k, (num, ids) in enumerate(zip(m.flat("tendon_treenum"),
                                       m.arrays["tendon_treeid"].tolist())):
        want = [i < num for i in range(2)]
        if num < 0 or [i >= 0 for i in ids] != want:
            fail("tendon_treeid", k, ids, f"tendon {k} spans {num} trees")


# ------------------------------------------------------------------ sparse structure

def _ancestors(parent):
    """Each dof's ancestor dofs, nearest first."""
    out = []
    for p in parent:
        out.append([p] + out[p] if p >= 0 else [])
    return out


def _csr(rows):
    nnz = [len(r) for r in rows]
    adr = np.concatenate([[0], np.cumsum(nnz)[:-1]]).astype(int).tolist() if rows else []
    return nnz, adr, [c for r in rows for c in r]


def _compare(m, name, expected):
    actual = m.flat(name)
    if actual != list(expected):
        k = next((k for k, (a, e) in enumerate(zip(actual, expected)) if a != e),
                 min(len(actual), len(expected)))
        value = actual[k] if k < len(actual) else "missing"
        want = expected[k] if k < len(expected) else "nothing"
        fail(name, k, value, f"the model's tree makes it {want}")


@covers("dof_Madr", "M_rownnz", "M_rowadr", "M_colind", "D_rownnz", "D_rowadr", "D_colind",
        "D_diag", "mapM2D", "mapD2M", "mapM2M")
def check_inertia(m):
    """dof_Madr, nM, and the M (reduced) and D (full) sparse structures with the maps
    between them, recomputed from dof_parentid and dof_simplenum."""
    nv = m.nv
    simple = m.flat("dof_simplenum")
    anc = _ancestors(m.flat("dof_parentid"))
    madr, at = [], 0
    for i in range(nv):
        madr.append(at)
        at += 1 + len(anc[i])
    _compare(m, "dof_Madr", madr)
    if m.nM != at:
        fail("nM", None, m.nM, f"the tree has {at} inertia elements")
    mrows = [[i] if simple[i] else sorted(anc[i]) + [i] for i in range(nv)]
    drows = [set(a) | {i} for i, a in enumerate(anc)]
    for i in range(nv):
        for j in anc[i]:
            drows[j].add(i)
    drows = [sorted(r) for r in drows]
    for name, rows in (("M", mrows), ("D", drows)):
        nnz, adr, colind = _csr(rows)
        _compare(m, f"{name}_rownnz", nnz)
        _compare(m, f"{name}_rowadr", adr)
        _compare(m, f"{name}_colind", colind)
    # A row's columns are its ancestors (each dof after its parent) and itself, and in
    # D its descendants after it: a column's place among them is its depth.
    depth = np.array([len(a) for a in anc], np.int64)
    _compare_array(m, "D_diag", depth)
    mnnz, cadr, mcol = (np.array(x, np.int64) for x in _csr(mrows))
    dnnz, dadr, dcol = (np.array(x, np.int64) for x in _csr(drows))
    mrow, drow = np.repeat(np.arange(nv), mnnz), np.repeat(np.arange(nv), dnnz)
    high, low = np.maximum(drow, dcol), np.minimum(drow, dcol)
    reduced = np.array(simple, np.int64)[high] != 0         # a simple dof's row: itself
    _compare_array(m, "mapM2D", np.where(reduced, np.where(low == high, cadr[high], -1),
                                         cadr[high] + depth[low]))
    _compare_array(m, "mapD2M", dadr[mrow] + depth[mcol])
    _compare_array(m, "mapM2M", np.array(madr, np.int64)[mrow] + depth[mrow] - depth[mcol])


def _compare_array(m, name, expected):
    if not np.array_equal(m.arrays[name].ravel(), expected):
        _compare(m, name, expected.tolist())


def body_dofs(m):
    """Each body's dofs, as a range."""
    dofadr, dofnum = m.flat("body_dofadr"), m.flat("body_dofnum")
    return [range(a, a + n) for a, n in zip(dofadr, dofnum)]


@covers("B_rownnz", "B_rowadr", "B_colind")
def check_body_dofs(m):
    """B: each body's row holds the dofs of its subtree and of its ancestors."""
    parent = m.flat("body_parentid")
    own = body_dofs(m)
    subtree = [list(dofs) for dofs in own]
    for b in range(m.nbody - 1, 0, -1):
        subtree[parent[b]].extend(subtree[b])
    rows = []
    for b in range(m.nbody):
        dofs = set(subtree[b])
        p = parent[b]
        while p > 0:
            dofs.update(own[p])
            p = parent[p]
        rows.append(sorted(dofs))
    nnz, adr, colind = _csr(rows)
    _compare(m, "B_rownnz", nnz)
    _compare(m, "B_rowadr", adr)
    _compare(m, "B_colind", colind)


def chain(body, parent, weld, own):
    """The dofs of a body's weld and of its ancestors (mj_mergeChain's chain)."""
    dofs = set()
    b = weld[body]
    while b > 0:
        dofs.update(own[b])
        b = parent[b]
    return dofs


def _tendon_dofs(m):
    """The dofs each tendon's Jacobian row holds: a fixed tendon's joints, a spatial
    tendon's chains of the bodies its sites and geoms are on."""
    parent, own = m.flat("body_parentid"), body_dofs(m)
    wtype, wobj = m.flat("wrap_type"), m.flat("wrap_objid")
    jdof, site_body, geom_body = m.flat("jnt_dofadr"), m.flat("site_bodyid"), m.flat("geom_bodyid")
    out = []
    for adr, num in zip(m.flat("tendon_adr"), m.flat("tendon_num")):
        path = range(adr, adr + num)
        if num and wtype[adr] == _WRAP.mjWRAP_JOINT:
            out.append(sorted(jdof[wobj[w]] for w in path))
            continue
        dofs = set()
        for w in path:
            b = (site_body[wobj[w]] if wtype[w] == _WRAP.mjWRAP_SITE else
                 geom_body[wobj[w]] if wtype[w] in (_WRAP.mjWRAP_SPHERE, _WRAP.mjWRAP_CYLINDER)
                 else -1)
            while b > 0:
                dofs.update(own[b])
                b = parent[b]
        out.append(sorted(dofs))
    return out


@covers("ten_J_rownnz", "ten_J_rowadr", "ten_J_colind")
def check_tendon_jacobian(m):
    """Each tendon's row of the Jacobian holds the dofs it moves (in any order)."""
    dofs = _tendon_dofs(m)
    nnz, adr, colind = _csr(dofs)
    _compare(m, "ten_J_rownnz", nnz)
    _compare(m, "ten_J_rowadr", adr)
    if m.nJten != len(colind):
        fail("nJten", None, m.nJten, f"the tendons move {len(colind)} dofs")
    actual = m.flat("ten_J_colind")
    for t, (a, n, want) in enumerate(zip(adr, nnz, dofs)):
        row = actual[a:a + n]
        if sorted(row) != want:
            j = next(j for j, c in enumerate(row) if c not in want or row.count(c) > 1)
            fail("ten_J_colind", a + j, row[j], f"tendon {t} moves the dofs {want}")
