"""Geometry addressed by index: meshes' convex graphs, the faces and polygons of
meshes and skins, the bounding volume and octree hierarchies, and flexes (their
elements, edges, flaps and shells as ids of their own vertices, their
interpolation cells and nodes)."""

import numpy as np

from .mjb import check_slice, covers, fail, first


@covers("mesh_graph", "mesh_extrema", "mesh_graphadr", "mesh_polyvertnum", "mesh_polymapnum")
def check_meshes(m):
    """Convex graphs (numvert, numface, edge addresses, global ids, edge lists ending
    in -1, faces), the extremal vertices into them, and the polygon maxima."""
    graph = m.arrays["mesh_graph"].ravel().astype(np.int64)
    extrema = m.arrays["mesh_extrema"]
    for k, (adr, nvert) in enumerate(zip(m.flat("mesh_graphadr"), m.flat("mesh_vertnum"))):
        if adr < 0:
            check_slice(extrema[k], "mesh_extrema", 27 * k, 0, max(nvert, 1))
            continue
        if adr + 2 > len(graph):
            fail("mesh_graphadr", k, adr, f"a graph's header runs past {len(graph)}")
        numvert, numface = int(graph[adr]), int(graph[adr + 1])
        nedge = numvert + 3 * numface
        end = adr + 2 + 2 * numvert + nedge + 3 * numface
        if not 0 < numvert <= nvert or numface < 0 or end > len(graph):
            fail("mesh_graph", adr, numvert, f"mesh {k}'s graph of {numvert} vertices and "
                 f"{numface} faces fits its {nvert} vertices and the {len(graph)} numbers")
        at = adr + 2
        check_slice(graph[at:at + numvert], "mesh_graph", at, 0, nedge)
        check_slice(graph[at + numvert:at + 2 * numvert], "mesh_graph", at + numvert, 0, nvert)
        edges = graph[at + 2 * numvert:at + 2 * numvert + nedge]
        check_slice(edges, "mesh_graph", at + 2 * numvert, -1, numvert)
        if nedge and edges[-1] != -1:
            fail("mesh_graph", at + 2 * numvert + nedge - 1, int(edges[-1]),
                 "a graph's edge lists end with -1")
        check_slice(graph[end - 3 * numface:end], "mesh_graph", end - 3 * numface, 0, nvert)
        check_slice(extrema[k], "mesh_extrema", 27 * k, 0, numvert)
    for size, field in (("npolygonmax", "mesh_polyvertnum"), ("nmeshdegmax", "mesh_polymapnum")):
        largest = int(m.arrays[field].max(initial=0))
        if m.sizes[size] != largest:
            fail(size, None, m.sizes[size], f"the largest {field} is {largest}")


_ANY = np.iinfo(np.int64).max


def _limits(m, adr_field, num_field, size, limits):
    """Per row of an array of `size` rows, the limit of the object whose block
    (adr_field, num_field) holds the row; rows of no object: no limit."""
    adr, num = m.arrays[adr_field].ravel(), m.arrays[num_field].ravel()
    limits = np.asarray(limits, np.int64)
    starts = np.cumsum(num, dtype=np.int64) - num
    if num.sum() == size and (adr[num > 0] == starts[num > 0]).all():
        return np.repeat(limits, num)           # blocks one after another, as compiled
    out = np.full(size, _ANY)
    for a, n, limit in zip(adr.tolist(), num.tolist(), limits.tolist()):
        out[a:a + n] = np.minimum(out[a:a + n], limit)
    return out


def _check_local(m, name, limits, why):
    """Each row of field `name` holds ids in [0, its limit)."""
    values = m.arrays[name]
    bad = (values < 0) | (values >= limits[:, None])
    if bad.any():
        k = first(bad)
        row, col = divmod(k, values.shape[1])
        fail(name, row if values.shape[1] == 1 else f"{row}, {col}", int(values.ravel()[k]),
             f"{why}, in [0, {int(limits[row])})")


@covers("mesh_face", "mesh_facenormal", "mesh_facetexcoord", "mesh_polyvert", "mesh_polymap",
        "skin_face", "skin_bonevertid")
def check_faces(m):
    """Mesh faces, polygons and the polygons of each vertex, skin faces and bones: ids
    local to their mesh or skin (its vertices, normals, texture coordinates, polygons)."""
    if m.nmeshface:
        faces = ("mesh_faceadr", "mesh_facenum", m.nmeshface)
        _check_local(m, "mesh_face", _limits(m, *faces, m.arrays["mesh_vertnum"].ravel()),
                     "a face's vertex is one of its mesh's")
        _check_local(m, "mesh_facenormal",
                     _limits(m, *faces, m.arrays["mesh_normalnum"].ravel()),
                     "a face's normal is one of its mesh's")
        texcoords = np.maximum(m.arrays["mesh_texcoordnum"].ravel(), 1)    # none: all 0
        _check_local(m, "mesh_facetexcoord", _limits(m, *faces, texcoords),
                     "a face's texture coordinate is one of its mesh's")
    if m.nmeshpolyvert:
        polygons = _limits(m, "mesh_polyadr", "mesh_polynum", m.nmeshpoly,
                           m.arrays["mesh_vertnum"].ravel())
        _check_local(m, "mesh_polyvert", _limits(m, "mesh_polyvertadr", "mesh_polyvertnum",
                                                 m.nmeshpolyvert, polygons),
                     "a polygon's vertex is one of its mesh's")
    if m.nmeshpolymap:
        vertices = _limits(m, "mesh_vertadr", "mesh_vertnum", m.nmeshvert,
                           m.arrays["mesh_polynum"].ravel())
        _check_local(m, "mesh_polymap", _limits(m, "mesh_polymapadr", "mesh_polymapnum",
                                                m.nmeshpolymap, vertices),
                     "a vertex's polygon is one of its mesh's")
    if m.nskin:
        skin_vertices = m.arrays["skin_vertnum"].ravel()
        _check_local(m, "skin_face", _limits(m, "skin_faceadr", "skin_facenum", m.nskinface,
                                             skin_vertices),
                     "a face's vertex is one of its skin's")
        bones = _limits(m, "skin_boneadr", "skin_bonenum", m.nskinbone, skin_vertices)
        _check_local(m, "skin_bonevertid", _limits(m, "skin_bonevertadr", "skin_bonevertnum",
                                                   m.nskinbonevert, bones),
                     "a bone's vertex is one of its skin's")


# ------------------------------------------------------------------ hierarchies

def _check_tree_nodes(m, kind, adr_field, num_field, leaf_ids=None):
    """A bvh or octree per owner, node ids local to the owner's block: children come
    after their node; with leaf_ids, a leaf (no children) names an element in
    [0, leaf_ids[o]), an inner node has both children and names none (-1)."""
    children = m.arrays[f"{kind}_child"]
    nodeids = m.arrays["bvh_nodeid"].ravel() if leaf_ids is not None else None
    width = children.shape[1]
    for o, (adr, num) in enumerate(zip(m.flat(adr_field), m.flat(num_field))):
        if num <= 0:
            continue
        block = children[adr:adr + num].astype(np.int64)
        index = np.arange(num)[:, None]
        leaf = (block == -1).all(axis=1)
        bad = (block != -1) & ((block <= index) | (block >= num))
        if nodeids is not None:
            bad |= ~leaf[:, None] & (block == -1)
        if bad.any():
            k = first(bad)
            fail(f"{kind}_child", f"{adr + k // width}, {k % width}", int(block.ravel()[k]),
                 f"a child is a later node of the same tree, in ({k // width}, {num})")
        if nodeids is None:
            continue
        ids = nodeids[adr:adr + num]
        bad = np.where(leaf, (ids < 0) | (ids >= leaf_ids[o]), ids != -1)
        if bad.any():
            k = first(bad)
            fail("bvh_nodeid", adr + k, int(ids[k]), f"a leaf names an element in [0, "
                 f"{leaf_ids[o]}), an inner node -1")


def _nodes_hold(m, kind, adr_field, num_field, low=None, high=None):
    """Whether the trees hold what _check_tree_nodes checks, all nodes in one pass; with
    low and high, a leaf of owner o names an element in [low[o], high[o])."""
    adr, num = m.arrays[adr_field].ravel(), m.arrays[num_field].ravel()
    owned = num > 0
    adr, num = adr[owned].astype(np.int64), num[owned].astype(np.int64)
    children = m.arrays[f"{kind}_child"]
    total = int(num.sum())
    if total > len(children):
        return False                # trees that overlap: the slow path says where
    local = np.arange(total) - np.repeat(np.cumsum(num) - num, num)
    rows = np.repeat(adr, num) + local
    block = children[rows].astype(np.int64)
    ok = (block == -1) | ((block > local[:, None]) & (block < np.repeat(num, num)[:, None]))
    if low is None:
        return bool(ok.all())
    leaf = (block == -1).all(axis=1)
    both = (block != -1) | leaf[:, None]                # an inner node has two children
    ids = m.arrays["bvh_nodeid"].ravel()[rows]
    named = np.where(leaf, (ids >= np.repeat(np.asarray(low)[owned], num))
                     & (ids < np.repeat(np.asarray(high)[owned], num)), ids == -1)
    return bool(ok.all() and both.all() and named.all())


@covers("bvh_child", "bvh_nodeid", "body_bvhadr", "mesh_bvhadr", "flex_bvhadr", "oct_child")
def check_hierarchies(m):
    """Body and mesh trees are static (below nbvhstatic), flex trees dynamic; a body's
    leaves name its geoms, a mesh's its faces and a flex's its elements."""
    for owner in ("body", "mesh", "flex"):
        for o, (a, n) in enumerate(zip(m.flat(f"{owner}_bvhadr"), m.flat(f"{owner}_bvhnum"))):
            static = a + n <= m.nbvhstatic
            if n > 0 and static != (owner != "flex"):
                kind = "dynamic" if static else "static"
                fail(f"{owner}_bvhadr", o, a, f"{owner} trees are {kind} (nbvhstatic = "
                     f"{m.nbvhstatic})")
    geomadr, geomnum = m.flat("body_geomadr"), m.flat("body_geomnum")
    geomend = [a + n for a, n in zip(geomadr, geomnum)]
    if not _nodes_hold(m, "bvh", "body_bvhadr", "body_bvhnum", geomadr, geomend):
        _check_tree_nodes(m, "bvh", "body_bvhadr", "body_bvhnum", geomend)
        nodeids = m.arrays["bvh_nodeid"].ravel()
        for b, (a, n) in enumerate(zip(m.flat("body_bvhadr"), m.flat("body_bvhnum"))):
            ids = nodeids[a:a + max(n, 0)]
            bad = (ids >= 0) & (ids < geomadr[b])
            if bad.any():
                k = first(bad)
                fail("bvh_nodeid", a + k, int(ids[k]), f"body {b}'s geoms are "
                     f"[{geomadr[b]}, {geomend[b]})")
    for owner, elements in (("mesh", "mesh_facenum"), ("flex", "flex_elemnum")):
        count = m.arrays[elements].ravel()
        if not _nodes_hold(m, "bvh", f"{owner}_bvhadr", f"{owner}_bvhnum",
                           np.zeros_like(count), count):
            _check_tree_nodes(m, "bvh", f"{owner}_bvhadr", f"{owner}_bvhnum", count.tolist())
    if not _nodes_hold(m, "oct", "mesh_octadr", "mesh_octnum"):
        _check_tree_nodes(m, "oct", "mesh_octadr", "mesh_octnum")
    if m.nbvhstatic + m.nbvhdynamic != m.nbvh:
        fail("nbvhdynamic", None, m.nbvhdynamic, f"nbvh - nbvhstatic is "
             f"{m.nbvh - m.nbvhstatic}")


# ------------------------------------------------------------------ flexes

_EDGES_PER_ELEM = {1: 1, 2: 3, 3: 6}


def _local(name, values, count, offset):
    """Ids local to one flex (its vertices, its edges), in [0, count)."""
    check_slice(values, name, offset, 0, count)


def _within(name, k, adr, count, size):
    if count and not (0 <= adr and adr + count <= size):
        fail(name, k, adr, f"its {count} elements run past {size}")


_BENDING = 17         # mjtNums of bending stencil per edge of a 2D flex (mj_flexPassiveBend)


@covers("flex_dim", "flex_elem", "flex_edge", "flex_elemedge", "flex_shell",
        "flex_elemdataadr", "flex_elemedgeadr", "flex_shelldataadr", "flex_shellnum",
        "flex_interp", "flex_cellnum", "flex_nodenum", "flex_vertcell", "flex_rigid",
        "flexedge_rigid", "flex_vertbodyid", "flex_edgeflap", "flex_elemtexcoord",
        "flex_bendingadr")
def check_flexes(m):
    """Per flex: its dimension, element, edge and flap data as ids of its own vertices
    and edges, texture coordinates, bending stencils, cells and nodes for
    interpolation, and the rigid flags from the bodies of its vertices."""
    elem, edge = m.arrays["flex_elem"].ravel(), m.arrays["flex_edge"]
    elemedge, shell = m.arrays["flex_elemedge"].ravel(), m.arrays["flex_shell"].ravel()
    flaps, elemtex = m.arrays["flex_edgeflap"], m.arrays["flex_elemtexcoord"].ravel()
    vertcell = m.arrays["flex_vertcell"].ravel()
    columns = ("flex_dim", "flex_vertadr", "flex_vertnum", "flex_elemnum", "flex_elemdataadr",
               "flex_edgeadr", "flex_edgenum", "flex_elemedgeadr", "flex_shelldataadr",
               "flex_shellnum", "flex_interp", "flex_nodenum", "flex_texcoordadr",
               "flex_bendingadr")
    cells = m.arrays["flex_cellnum"].tolist()
    for f, row in enumerate(zip(*(m.flat(c) for c in columns))):
        dim, vadr, vnum, enum, dadr, ladr, lnum, eeadr, sadr, snum, interp, nodes, tadr, \
            badr = row
        if dim not in (1, 2, 3):
            fail("flex_dim", f, dim, "a flex has dimension 1, 2 or 3")
        _within("flex_elemdataadr", f, dadr, enum * (dim + 1), m.nflexelemdata)
        _local("flex_elem", elem[dadr:dadr + enum * (dim + 1)], vnum, dadr)
        _local("flex_edge", edge[ladr:ladr + lnum].ravel(), vnum, 2 * ladr)
        _check_flaps(flaps[ladr:ladr + lnum], vnum, ladr)
        if tadr >= 0:
            check_slice(elemtex[dadr:dadr + enum * (dim + 1)], "flex_elemtexcoord", dadr, 0,
                        m.nflextexcoord - tadr)
        if dim == 2 and interp == 0 and badr >= 0:
            _within("flex_bendingadr", f, badr, _BENDING * lnum, m.nflexbending)
        if eeadr >= 0 and m.nflexelemedge:
            count = enum * _EDGES_PER_ELEM[dim]
            _within("flex_elemedgeadr", f, eeadr, count, m.nflexelemedge)
            _local("flex_elemedge", elemedge[eeadr:eeadr + count], lnum, eeadr)
        if snum < 0:
            fail("flex_shellnum", f, snum, "a count cannot be negative")
        _within("flex_shelldataadr", f, sadr, snum * dim, m.nflexshelldata)
        _local("flex_shell", shell[sadr:sadr + snum * dim], vnum, sadr)
        _check_cells(f, interp, cells[f], nodes, vertcell[vadr:vadr + vnum], vadr)
        if interp == 0:                 # an interpolated flex's vertices have no body (-1)
            _check_rigid(m, f, vadr, vnum, ladr, lnum)


def _check_flaps(flaps, vnum, ladr):
    """A 2D flex's edge flaps: the two vertices opposite the edge; -1 for the second
    (a boundary edge: MuJoCo skips it) or for both."""
    check_slice(flaps, "flex_edgeflap", 2 * ladr, -1, vnum)
    bad = (flaps[:, 0] == -1) & (flaps[:, 1] != -1)
    if bad.any():
        k = first(bad)
        fail("flex_edgeflap", f"{ladr + k}, 0", -1, "an edge with a second flap vertex has "
             "a first")


def _check_rigid(m, f, vadr, vnum, ladr, lnum):
    """A flex's vertices are on bodies; the flex is rigid when they share one, an edge
    when its two vertices' bodies share a weld."""
    check_slice(m.arrays["flex_vertbodyid"][vadr:vadr + vnum], "flex_vertbodyid", vadr, 0,
                m.nbody)
    bodies = m.arrays["flex_vertbodyid"].ravel()[vadr:vadr + vnum]
    rigid = int(m.arrays["flex_rigid"][f, 0])
    if vnum and bool(rigid) != bool((bodies == bodies[0]).all()):
        fail("flex_rigid", f, rigid, "a flex is rigid when its vertices share a body")
    weld = m.arrays["body_weldid"].ravel()[bodies]
    ends = m.arrays["flex_edge"][ladr:ladr + lnum]
    same = weld[ends[:, 0]] == weld[ends[:, 1]]
    edge_rigid = m.arrays["flexedge_rigid"].ravel()[ladr:ladr + lnum]
    bad = edge_rigid.astype(bool) != same
    if bad.any():
        k = first(bad)
        fail("flexedge_rigid", ladr + k, int(edge_rigid[k]),
             "an edge is rigid when its two vertices' bodies share a weld")


def _check_cells(f, interp, cells, nodes, vertcell, vadr):
    """Interpolated flexes (interp: order 1 or 2, negative for a shell) have a grid of
    cells; the full grid has (cells * order + 1) nodes per dimension."""
    if not -2 <= interp <= 2:
        fail("flex_interp", f, interp, "an interpolation order is 0, 1 or 2 (negative: shell)")
    if min(cells) < 1:
        fail("flex_cellnum", f, cells, "a flex has at least one cell per dimension")
    order = abs(interp)
    grid = int(np.prod([c * order + 1 for c in cells])) if order else 0
    if (interp > 0 and nodes != grid) or (interp < 0 and not 0 < nodes <= grid) \
            or (interp == 0 and nodes != 0):
        fail("flex_nodenum", f, nodes, f"interpolation {interp} on {cells} cells has "
             f"{grid if interp >= 0 else f'at most {grid}'} nodes")
    low = 0 if interp else -1
    check_slice(vertcell, "flex_vertcell", vadr, low, int(np.prod(cells)) if interp else 0)
