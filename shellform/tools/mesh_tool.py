"""A rigid tool whose surface is a triangle mesh (an STL file, or a gmsh .msh file's triangles),
interpolated by Nagata patches.

The tool gives what the analytic tools give (tools.py) and the CAD tool (surface_tool.py): for
points x, placed by a translation and moved by dz along z,

    gap(x, offset, dz)    the signed distance to the surface minus offset (> 0 clear), and the
                          unit normal pointing from the tool towards the point;
    shape(x, offset, dz)  H = dn/dx (n, 3, 3), the Hessian of the signed distance.

Vertex normals. Each triangle's facet normal comes from its vertices' order (right-handed:
outward on a solid written as STL asks); ``normals = "inward"`` turns them all. A vertex's normal
is the normalised sum over its facets of (x_a - x) x (x_b - x) / (|x_a - x|^2 |x_b - x|^2), x_a,
x_b the facet's other vertices (N. Max, Weights for computing vertex normals from facet normals,
J. Graphics Tools 4 (1999): the facet normal times sin(angle) / (|x_a - x| |x_b - x|); exact
for vertices on a sphere, docs/tools.md has the angle-weighted mean's numbers). An edge whose facets'
normals differ by more than FEATURE_ANGLE is a feature edge (a crease, a box's rim): the facets
around a vertex are split by the feature edges into fans, each fan with its own normal, so that a
crease stays sharp. A feature edge is not a smoothed one: its curve is the crease's (below). A fan
with exactly one plane in it (facets of one normal, to 1e-12, whose angles at the vertex add up
to PLANE_ANGLE or more: a vertex on the tangent seam between a flat face and a fillet) takes the
plane's normal, the true one there: the flat face stays flat up to its seam (the mean would lean
towards the fillet and bulge the face's first row of triangles).

Nagata patches (T. Nagata, Simple local interpolation of surfaces using normal vectors, CAGD 22
(2005) 327-347). An edge from x_a to x_b, d = x_b - x_a, is the quadratic curve

    x(t) = x_a + d t - c t (1 - t),   t in [0, 1],

whose tangents at its ends, d - c and d + c, are orthogonal to the normals n_a and n_b there:
n_a . c = n_a . d, n_b . c = -n_b . d. Nagata takes the c of least norm, in the plane of n_a and
n_b: with g = n_a . n_b,

    c = alpha n_a + beta n_b,  alpha = (n_a . d + g n_b . d) / (1 - g^2),
                               beta = -(n_b . d + g n_a . d) / (1 - g^2),

and c = 0 (a straight edge) where the normals are parallel or opposite (1 - g^2 below
PARALLEL). A feature edge takes the crease's tangents instead: at each end the direction
t = n_1 x n_2 of the two fans' normals there (turned along d; d itself where they are parallel),
and the c whose end tangents are nearest those, (d . t_b) t_b and (d . t_a) t_a: c = ((d . t_b) t_b
- (d . t_a) t_a) / 2. Then only c's part along the edge's mean normal is kept: c <- (c . m) m, m
the unit part of n_a + n_b orthogonal to d (a crease: of d x ((n_a + n_b) x d)). It changes
nothing on a circular arc (whose c is that) and little on a smooth curve (its other parts bend
the parametrisation, not the surface). But where a vertex normal leans along the edge (a vertex
on a tangent seam between a plane and a fillet, whose mean normal leans towards the fillet)
Nagata's c is large and tangential to the surface (c = d itself for an edge that leaves the seam
at a right angle: a straight edge with a zero tangent at one end), and such parts fold a patch
over itself in its plane, its normal turned over where it folds. Every edge's c depends only
on its own two vertices and normals, so two triangles that share an edge share its curve: the
surface has no cracks.

A triangle with vertices x_0, x_1, x_2 and barycentric coordinates (1 - u - v, u, v) on u, v >= 0,
u + v <= 1 is the quadratic patch

    X(u, v) = x_0 (1 - u - v) + x_1 u + x_2 v - c_01 (1 - u - v) u - c_12 u v - c_02 (1 - u - v) v
            = a_0 + a_1 u + a_2 v + a_3 u^2 + a_4 v^2 + a_5 u v,

a_0 = x_0, a_1 = x_1 - x_0 - c_01, a_2 = x_2 - x_0 - c_02, a_3 = c_01, a_4 = c_02,
a_5 = c_01 + c_02 - c_12; its edges are the edges' curves. The tool is the set of these patches
(a MeshTool is made from any such coefficients: flat facets are c = 0). The patches meet along
their edges (C0); their normals across an edge differ a little (Nagata's patches are not G1).

Closest point. For a point y, a k-d tree of points sampled on every flat triangle (a barycentric
grid no coarser than the mesh's median edge) gives the triangles that can hold its closest
point: each patch lies within b_T of its flat triangle (b_T <= max|c| / 3, the largest of the
products (1-u-v) u etc. summing to 1/3), so the distance to the patch lies within b_T of the flat
triangle's. The least upper bound over the triangles of the nearest samples bounds the
distance; every triangle whose lower bound lies within it is a candidate. On each candidate,
Newton minimises |X(u, v) - y|^2 in (u, v) from the flat triangle's closest point (the Hessian
J^T J + (X - y) . X_ij, or J^T J where that is not positive). A point whose minimiser leaves the
triangle is projected onto its three edge curves instead (Newton in t, clamped to [0, 1]). The
nearest of all candidates' points is the closest point c.

Signed distance, normal and shape operator. On a patch's inside, n_c = X_u x X_v / |X_u x X_v|
(turned for "inward"), d = (y - c) . n_c, n = n_c and H = H0 (I + d H0)^-1 from the patch's
derivatives (surface_geometry.distance_hessian). On an edge curve (the point lies beside the
edge, where the two patches' normals fans leave a gap, or beside a crease), d = +/-|y - c| with
the sign of (y - c) . n_c, n = (y - c) / d, and H the Hessian of the distance to the curve:
(I - n n^T - x' x'^T / (|x'|^2 - (y - c) . x'')) / d; at a vertex (I - n n^T) / d.

Neighbour lists. The search keeps for each point y the triangles whose samples lie within
U + m + reach of it (U the least upper bound above, m = BALL_MARGIN times the sampling's
spacing, reach the farthest any patch point lies from its triangle's nearest sample: the
patches not kept lie farther than R = U + m) and whose lower bound (flat distance less b_T)
lies within R: y's list, each triangle with a lower bound L_T of the distance to its patch,
its distance itself where it was a candidate. Every patch outside the list lies farther than R.

The last call's points are remembered with their answers, lists, L_T and R. A point given again
(in the tool's frame: the same x and dz) takes its answer without a search (the contact set asks
gap about three times and shape once per iterate at the same points). A moved point y' = y +
delta e starts warm, y its remembered point (|e| = 1, closest point c there): the point of the
same index where the call has as many points as the last and each moved less than m (a contact
set's nodes, moved by an iterate: no k-d tree to build and query), else the nearest. The
distance to any set is 1-Lipschitz: the patches outside the list lie farther than R - delta,
each listed patch farther than L_T - delta; c lies on the surface, so y' lies within U' =
|y' - c| of it. Where U' <= R - delta - TIE (of the tool's size), the nearest patch is in the
list and its lower bound is at most U': the candidates are the listed patches with L_T - delta
<= U'. For those other than y's own patch two more bounds: a patch lies within the sphere of
its flat triangle's centroid and radius (farthest corner plus b_T), so seen from y its points
x lie in a cone of half-angle a = asin(radius / |centroid - y|) around the centroid's
direction; then |x - y'| >= w . (x - y') = |x - y| - delta w . e >= L_T - delta cos(max(0, p -
a)), w the unit direction of x - y and p the angle between e and the cone's axis (a point
moved across its far neighbours' directions hardly nears them); and the flat distance less b_T.
The candidates still within U' are projected as in the search (y's own patch by Newton from
y's (u, v)), the nearest taken. Every patch left out lies provably farther than U' >= the distance found, so the
answer is the search's (the same candidates' projections; ties at equal distances go to the
lesser patch). The list goes on with the candidates' new distances and the others' L_T -
delta, R - delta; where R - delta < U' + TIE (a point moved about m in all since its search)
the point is searched afresh. `counts` counts the points answered each way.

Compiled. The projections (Newton on a patch, the edge curves), the flat triangles' distances,
the warm start's and the search's bounds over each point's list and the signed answers are
loops compiled by numba, one call of each a tool call (numpy's cost per operation, some 500
array operations a call of 60 points, was most of a call's time: docs/tools.md). The k-d trees'
queries, a search's pairs and the patches' H (surface_geometry.distance_hessian) stay numpy's
and scipy's. The first use in a process compiles them (about 9 s CPU) unless shellform's numba
cache holds them (shellform._jit; loaded from it, 0.2 s).

Reading a file: STL (binary, or ASCII), or a gmsh .msh in its ASCII format (2.2 or 4.1: its
3-node triangles; the corners of 6-node ones), parsed here without gmsh, so no script (a FILE.opt
beside it) runs. At most MAX_MESH_BYTES. Vertices nearer than MERGE_TOLERANCE of the model's
size are one; triangles that collapse are dropped. Refused (InputError naming the field): a
missing file, another kind, a file with no triangles, an edge shared by more than two triangles
(non-manifold), two triangles whose orders disagree across their edge (inconsistent
orientation). An open surface is taken as it is (beside its boundary the distance is to the
boundary curve). Lengths are in the file's units, mm.
"""

import re
from itertools import chain
from pathlib import Path

import numpy as np

from shellform._jit import njit
from shellform.tools.holder_edge import closed_loops
from shellform.tools.surface_geometry import distance_hessian
from shellform.errors import InputError

MESH_SUFFIXES = (".stl", ".msh")  # any case
MAX_MESH_BYTES = 200_000_000  # a tool's mesh file larger than this is refused
MERGE_TOLERANCE = 1e-8  # vertices nearer than this times the model's size are one
FEATURE_ANGLE = 45.0  # degrees: facets whose normals differ by more meet at a crease
PLANE_ANGLE = 150.0  # degrees: coplanar facets spanning this much at a vertex make its normal the plane's
PARALLEL = 1e-12  # 1 - (n_a . n_b)^2 below this: Nagata's c = 0 (parallel or opposite normals)
NEWTON_ITERATIONS = 30  # the most Newton iterations of a projection
NEAREST_SAMPLES = 4  # samples whose triangles give each point's first upper bound
BALL_MARGIN = 1.0  # the search's ball reaches this times the sampling's spacing beyond the candidates'
TIE = 1e-9  # times the tool's size: a warm start's point is this much nearer than every other patch
NORMALS = ("outward", "inward")


# -- reading ---------------------------------------------------------------------------------
def read_surface_mesh(path, field: str = "tools.file"):
    """The vertices (V, 3) and triangles (T, 3) of an STL or ASCII gmsh .msh file, vertices
    merged, collapsed triangles dropped (module docstring). InputError naming `field`."""
    path = Path(path)
    if not path.is_file():
        raise InputError(field, f"no such file: {path}")
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise InputError(field, f"{path.name} is not a surface mesh: a tool's mesh file must end in .stl or .msh")
    size = path.stat().st_size
    if size > MAX_MESH_BYTES:
        raise InputError(field, f"{path} is larger than {MAX_MESH_BYTES:,} bytes")
    data = path.read_bytes()
    corners = _stl(data, path, field) if suffix == ".stl" else _msh(data, path, field)
    if len(corners) == 0:
        raise InputError(field, f"{path} holds no triangles")
    if not np.all(np.isfinite(corners)):
        raise InputError(field, f"{path} holds a vertex that is not a finite number")
    vertices, triangles = merge_vertices(corners.reshape(-1, 3))
    triangles = triangles.reshape(-1, 3)
    e1 = vertices[triangles[:, 1]] - vertices[triangles[:, 0]]
    e2 = vertices[triangles[:, 2]] - vertices[triangles[:, 0]]
    scale = float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))
    area = np.linalg.norm(np.cross(e1, e2), axis=1)
    keep = (triangles[:, 0] != triangles[:, 1]) & (triangles[:, 1] != triangles[:, 2]) \
        & (triangles[:, 0] != triangles[:, 2]) & (area > 1e-14 * scale ** 2)
    triangles = triangles[keep]
    if len(triangles) == 0:
        raise InputError(field, f"{path} holds no triangles of nonzero area")
    _check_topology(vertices, triangles, path, field)
    return vertices, triangles


def _stl(data: bytes, path, field):
    """The corners (T, 3, 3) of a binary or ASCII STL file."""
    if len(data) >= 84:
        count = int(np.frombuffer(data, dtype="<u4", count=1, offset=80)[0])
        if len(data) == 84 + 50 * count:  # binary: 80-byte header, count, 50 bytes a facet
            rows = np.frombuffer(data, dtype=np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)),
                                                        ("attribute", "<u2")]), count=count, offset=84)
            return rows["corners"].astype(float)
    if not data.lstrip()[:5].lower() == b"solid":
        raise InputError(field, f"{path} is neither a binary STL (its size does not match its facet count) nor an "
                         "ASCII one (it does not begin with 'solid')")
    text = data.decode("ascii", errors="replace")
    found = re.findall(r"\bvertex\s+(\S+)\s+(\S+)\s+(\S+)", text)
    try:
        corners = np.array(found, dtype=float).reshape(-1, 3)
    except ValueError:
        raise InputError(field, f"{path}: a vertex of its facets is not three numbers") from None
    if len(corners) % 3:
        raise InputError(field, f"{path}: its facets hold {len(corners)} vertices, not three each")
    return corners.reshape(-1, 3, 3)


def _msh(data: bytes, path, field):
    """The triangles' corners (T, 3, 3) of an ASCII gmsh .msh file, format 2.2 or 4.1."""
    text = data.decode("ascii", errors="replace")

    def section(name):
        m = re.search(rf"^\${name}\s*$(.*?)^\$End{name}\s*$", text, re.M | re.S)
        if m is None:
            raise InputError(field, f"{path} has no ${name} section: not a gmsh mesh")
        return m.group(1).split()

    head = section("MeshFormat")
    if len(head) < 3 or head[1] != "0":
        raise InputError(field, f"{path} is not an ASCII gmsh mesh (write it with Mesh.Binary = 0)")
    version = head[0]
    try:
        if version.startswith("2"):
            nodes, elements = section("Nodes"), section("Elements")
            count = int(nodes[0])
            table = np.array(nodes[1:1 + 4 * count], dtype=float).reshape(count, 4)
            tags, xyz = table[:, 0].astype(np.int64), table[:, 1:]
            triangles, i = [], 1
            for _ in range(int(elements[0])):
                kind, ntags = int(elements[i + 1]), int(elements[i + 2])
                width = {2: 3, 9: 6}.get(kind, _MSH_NODES.get(kind, -1))
                if width < 0:
                    raise InputError(field, f"{path}: element type {kind} is not read (triangles, lines, points)")
                start = i + 3 + ntags
                if kind in (2, 9):
                    triangles.append([int(t) for t in elements[start:start + 3]])
                i = start + width
        elif version.startswith("4"):
            nodes, elements = section("Nodes"), section("Elements")
            blocks, i = int(nodes[0]), 4
            tag_list, xyz_list = [], []
            for _ in range(blocks):
                dim, parametric, count = int(nodes[i]), int(nodes[i + 2]), int(nodes[i + 3])
                i += 4
                tag_list.append(np.array(nodes[i:i + count], dtype=np.int64))
                i += count
                width = 3 + (dim if parametric else 0)
                xyz_list.append(np.array(nodes[i:i + width * count], dtype=float).reshape(count, width)[:, :3])
                i += width * count
            tags = np.concatenate(tag_list) if tag_list else np.zeros(0, dtype=np.int64)
            xyz = np.vstack(xyz_list) if xyz_list else np.zeros((0, 3))
            blocks, i = int(elements[0]), 4
            triangles = []
            for _ in range(blocks):
                kind, count = int(elements[i + 2]), int(elements[i + 3])
                i += 4
                width = {2: 3, 9: 6}.get(kind, _MSH_NODES.get(kind, -1))
                if width < 0:
                    raise InputError(field, f"{path}: element type {kind} is not read (triangles, lines, points)")
                rows = np.array(elements[i:i + (width + 1) * count], dtype=np.int64).reshape(count, width + 1)
                i += (width + 1) * count
                if kind in (2, 9):
                    triangles.extend(rows[:, 1:4].tolist())
        else:
            raise InputError(field, f"{path}: gmsh mesh format {version} is not read (2.2 or 4.1)")
    except (ValueError, IndexError):
        raise InputError(field, f"{path}: its $Nodes or $Elements section is not as gmsh writes it") from None
    triangles = np.array(triangles, dtype=np.int64).reshape(-1, 3)
    if len(triangles) == 0:
        return np.zeros((0, 3, 3))
    order = np.argsort(tags)
    at = np.searchsorted(tags[order], triangles)
    at = np.minimum(at, len(tags) - 1)
    if not np.all(tags[order][at] == triangles):
        raise InputError(field, f"{path}: a triangle names a node that is not in $Nodes")
    return xyz[order][at]


_MSH_NODES = {1: 2, 15: 1, 8: 3}  # the other element kinds skipped: lines, points, 3-node lines


def merge_vertices(points, tolerance: float = MERGE_TOLERANCE):
    """Points (N, 3) as unique vertices (V, 3) and each point's vertex (N): points nearer than
    `tolerance` times the points' bounding-box diagonal are one vertex (the first of them)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    points = np.asarray(points, dtype=float)
    scale = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))) or 1.0
    pairs = cKDTree(points).query_pairs(tolerance * scale, output_type="ndarray")
    n = len(points)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    first = np.full(label.max() + 1, n)
    np.minimum.at(first, label, np.arange(n))
    return points[first], label


def _edges(triangles):
    """The triangles' edges (T, 3, 2) in the patch's order (0-1, 1-2, 0-2), the unique edges'
    sorted vertex pairs (E, 2), each triangle edge's unique edge (T, 3) and how many triangles
    share each unique edge (E)."""
    local = np.array([[0, 1], [1, 2], [0, 2]])
    directed = triangles[:, local]  # (T, 3, 2)
    key = np.sort(directed, axis=2).reshape(-1, 2)
    unique, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return directed, unique, inverse.reshape(-1, 3), counts


def _check_topology(vertices, triangles, path, field):
    """Non-manifold edges and inconsistent orientation refused (InputError naming `field`)."""
    directed, unique, inverse, counts = _edges(triangles)
    if counts.max() > 2:
        e = unique[np.argmax(counts)]
        raise InputError(field, f"{path}: the edge between vertices at {np.round(vertices[e[0]], 6).tolist()} and "
                         f"{np.round(vertices[e[1]], 6).tolist()} is shared by {counts.max()} triangles "
                         "(a non-manifold surface)")
    # the triangles' own order of their edges: 0->1, 1->2, 2->0
    ring = triangles[:, [[0, 1], [1, 2], [2, 0]]].reshape(-1, 2)
    _, repeated = np.unique(ring, axis=0, return_counts=True)
    if repeated.max() > 1:
        raise InputError(field, f"{path}: two triangles run along a shared edge the same way (their vertices' "
                         "orders, which give their normals, disagree: the surface's orientation is inconsistent)")


# -- patches ---------------------------------------------------------------------------------
def facet_normals(vertices, triangles):
    """Unit facet normals (T, 3) by the vertices' order, and each triangle's angles at its
    corners (T, 3)."""
    x = vertices[triangles]
    normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    angles = np.zeros((len(triangles), 3))
    for k in range(3):
        a = x[:, (k + 1) % 3] - x[:, k]
        b = x[:, (k + 2) % 3] - x[:, k]
        angles[:, k] = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
    return normal, angles


def corner_normals(vertices, triangles, feature_angle: float = FEATURE_ANGLE):
    """Each triangle corner's vertex normal (T, 3, 3): the angle-weighted mean of the facet
    normals of its fan (the facets around the vertex reached without crossing a feature edge),
    and which unique edges are feature edges (_edges' order)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    normal, angles = facet_normals(vertices, triangles)
    directed, unique, inverse, counts = _edges(triangles)
    T = len(triangles)
    owner = np.full((len(unique), 2), -1)  # the (up to) two triangle-edges of each unique edge
    order = np.argsort(inverse.ravel(), kind="stable")
    start = np.searchsorted(inverse.ravel()[order], np.arange(len(unique)))
    owner[:, 0] = order[start]
    two = counts == 2
    owner[two, 1] = order[start[two] + 1]
    ta, tb = owner[two, 0] // 3, owner[two, 1] // 3
    feature = np.zeros(len(unique), dtype=bool)
    feature[two] = np.einsum("ij,ij->i", normal[ta], normal[tb]) < np.cos(np.radians(feature_angle))
    feature[~two] = False
    smooth = np.flatnonzero(two & ~feature)
    # corners joined across smooth edges: corner index 3 t + k of the edge's two vertices in each triangle
    rows, cols = [], []
    for end in range(2):
        v = unique[smooth, end]
        a, b = owner[smooth, 0] // 3, owner[smooth, 1] // 3
        rows.append(3 * a + np.argmax(triangles[a] == v[:, None], axis=1))
        cols.append(3 * b + np.argmax(triangles[b] == v[:, None], axis=1))
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(3 * T, 3 * T))
    # corners at one vertex with the same fan: components of this graph
    _, label = connected_components(graph, directed=False)
    x = vertices[triangles]
    weighted = np.zeros((T, 3, 3))
    for k in range(3):  # Max's weights: the facet normal times sin(angle) / (|a| |b|), a, b the corner's edges
        a = x[:, (k + 1) % 3] - x[:, k]
        b = x[:, (k + 2) % 3] - x[:, k]
        weighted[:, k] = np.cross(a, b) / (np.einsum("ij,ij->i", a, a) * np.einsum("ij,ij->i", b, b))[:, None]
    weighted = weighted.reshape(-1, 3)
    sums = np.zeros((label.max() + 1, 3))
    np.add.at(sums, label, weighted)
    sums /= np.linalg.norm(sums, axis=1)[:, None]
    # a fan with exactly one plane in it (facets with the same normal, to 1e-12, whose angles at the
    # vertex add up to PLANE_ANGLE or more: a vertex on a tangent seam between a plane and a
    # fillet, not two facets of a cylinder's strip): the plane's normal
    facet = np.repeat(normal, 3, axis=0)
    groups, first, inverse = np.unique(np.c_[label, np.round(facet, 12)], axis=0, return_index=True,
                                       return_inverse=True)
    spread = np.zeros(len(groups))
    np.add.at(spread, inverse.ravel(), angles.ravel())
    wide = spread >= np.radians(PLANE_ANGLE)
    planes = groups[wide, 0].astype(np.int64)
    fans, how_many = np.unique(planes, return_counts=True)
    single = fans[how_many == 1]
    if single.size:
        at = first[wide][np.isin(planes, single)]
        sums[label[at]] = facet[at]
    return sums[label].reshape(T, 3, 3), feature


def nagata_coefficient(d, na, nb):
    """Nagata's curvature coefficient c (points, 3) of edges d = x_b - x_a with unit normals na,
    nb at their ends (module docstring): 0 where the normals are parallel or opposite."""
    g = np.einsum("ij,ij->i", na, nb)
    det = 1.0 - g * g
    ok = det > PARALLEL
    det = np.where(ok, det, 1.0)
    da, db = np.einsum("ij,ij->i", na, d), np.einsum("ij,ij->i", nb, d)
    alpha = (da + g * db) / det
    beta = -(db + g * da) / det
    return np.where(ok[:, None], alpha[:, None] * na + beta[:, None] * nb, 0.0)


def crease_coefficient(d, ta, tb):
    """The coefficient c of a crease's edge d = x_b - x_a whose tangent directions at its ends
    are ta, tb (unit, along d): c = ((d . tb) tb - (d . ta) ta) / 2."""
    return 0.5 * (np.einsum("ij,ij->i", d, tb)[:, None] * tb - np.einsum("ij,ij->i", d, ta)[:, None] * ta)


def nagata_patches(vertices, triangles, feature_angle: float = FEATURE_ANGLE):
    """The Nagata patches' coefficients (T, 6, 3) of a triangle mesh (module docstring): a_0 ..
    a_5 of X(u, v) = a_0 + a_1 u + a_2 v + a_3 u^2 + a_4 v^2 + a_5 u v."""
    vertices = np.asarray(vertices, dtype=float)
    triangles = np.asarray(triangles, dtype=np.int64)
    normals, feature = corner_normals(vertices, triangles, feature_angle)
    directed, unique, inverse, counts = _edges(triangles)
    T = len(triangles)
    # each unique edge from its first triangle-edge (and its second, for a crease)
    first = np.zeros(len(unique), dtype=np.int64)
    second = np.full(len(unique), -1, dtype=np.int64)
    order = np.argsort(inverse.ravel(), kind="stable")
    start = np.searchsorted(inverse.ravel()[order], np.arange(len(unique)))
    first[:] = order[start]
    two = counts == 2
    second[two] = order[start[two] + 1]
    local = np.array([[0, 1], [1, 2], [0, 2]])

    def corner_normal(triangle_edge, vertex):
        t, k = triangle_edge // 3, triangle_edge % 3
        corners = local[k]
        at = np.where(triangles[t, corners[:, 0]] == vertex, corners[:, 0], corners[:, 1])
        return normals[t, at]

    a, b = unique[:, 0], unique[:, 1]
    d = vertices[b] - vertices[a]
    na, nb = corner_normal(first, a), corner_normal(first, b)
    c = nagata_coefficient(d, na, nb)
    crease = np.flatnonzero(feature)
    if crease.size:
        tangents = []
        for v, n1 in ((a[crease], na[crease]), (b[crease], nb[crease])):
            n2 = corner_normal(second[crease], v)
            t = np.cross(n1, n2)
            size = np.linalg.norm(t, axis=1)
            along = d[crease] / np.linalg.norm(d[crease], axis=1)[:, None]
            t = np.where(size[:, None] > 1e-6, t / np.maximum(size, 1e-300)[:, None], along)
            t *= np.where(np.einsum("ij,ij->i", t, d[crease]) < 0, -1.0, 1.0)[:, None]
            tangents.append(t)
        c[crease] = crease_coefficient(d[crease], *tangents)
    # only c's part along the edge's mean normal, made orthogonal to d, is kept
    mean = na + nb
    if crease.size:
        mean[crease] = np.cross(d[crease], np.cross(na[crease] + nb[crease], d[crease]))
    m = mean - (np.einsum("ij,ij->i", mean, d) / np.einsum("ij,ij->i", d, d))[:, None] * d
    size = np.linalg.norm(m, axis=1)
    m = np.where(size[:, None] > 1e-12, m / np.maximum(size, 1e-300)[:, None], 0.0)
    c = np.einsum("ij,ij->i", c, m)[:, None] * m
    c01, c12, c02 = c[inverse[:, 0]], c[inverse[:, 1]], c[inverse[:, 2]]
    x = vertices[triangles]
    return np.stack([x[:, 0], x[:, 1] - x[:, 0] - c01, x[:, 2] - x[:, 0] - c02, c01, c02, c01 + c02 - c12], axis=1) \
        .reshape(T, 6, 3)


_EDGE_START = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0]])  # (u, v) at each edge's start
_EDGE_DIRECTION = np.array([[1.0, 0.0], [-1.0, 1.0], [0.0, 1.0]])  # d(u, v)/ds along each edge
_EDGE_CORNERS = np.array([[0, 1], [1, 2], [0, 2]])  # each edge's corners


# -- the closest points, compiled (numba: a call's few loops instead of hundreds of numpy
# operations on a few hundred rows). A patch is A (6, 3), a_0 .. a_5; its flat triangle P (3, 3).


@njit
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit
def _at(A, u, v, X, Xu, Xv):
    """X, X_u, X_v of patch A at (u, v), into X, Xu, Xv (3)."""
    for k in range(3):
        X[k] = A[0, k] + A[1, k] * u + A[2, k] * v + A[3, k] * u * u + A[4, k] * v * v + A[5, k] * u * v
        Xu[k] = A[1, k] + 2.0 * A[3, k] * u + A[5, k] * v
        Xv[k] = A[2, k] + 2.0 * A[4, k] * v + A[5, k] * u


@njit
def _distance(y, X):
    return np.sqrt((y[0] - X[0]) ** 2 + (y[1] - X[1]) ** 2 + (y[2] - X[2]) ** 2)


@njit
def _sub(a, b):
    return a[0] - b[0], a[1] - b[1], a[2] - b[2]


@njit
def _less(a, s, b):
    """a - s b of three-vectors."""
    return a[0] - s * b[0], a[1] - s * b[1], a[2] - s * b[2]


@njit  # a division by 0 gives inf or nan (_jit.OPTIONS)
def _flat(y, P):
    """The closest point's barycentric (u, v) on the flat triangle P and the distance to it:
    the plane's foot point where it lies inside, else the nearest of the three edges' (clamped
    to the edge; the first of equals)."""
    e1, e2, w = _sub(P[1], P[0]), _sub(P[2], P[0]), _sub(y, P[0])
    g11, g12, g22, r1, r2 = _dot(e1, e1), _dot(e1, e2), _dot(e2, e2), _dot(w, e1), _dot(w, e2)
    det = g11 * g22 - g12 * g12
    u = (g22 * r1 - g12 * r2) / det
    v = (g11 * r2 - g12 * r1) / det
    if u >= 0.0 and v >= 0.0 and u + v <= 1.0:
        r = _less(_less(w, u, e1), v, e2)
        return u, v, np.sqrt(_dot(r, r))
    best_u, best_v, dist = 0.0, 0.0, np.inf
    for e in range(3):
        q0 = P[_EDGE_CORNERS[e, 0]]
        s = _sub(P[_EDGE_CORNERS[e, 1]], q0)
        w = _sub(y, q0)
        t = min(max(_dot(w, s) / _dot(s, s), 0.0), 1.0)
        r = _less(w, t, s)
        dd = np.sqrt(_dot(r, r))
        if dd < dist:
            dist, best_u, best_v = dd, _EDGE_START[e, 0] + _EDGE_DIRECTION[e, 0] * t, \
                _EDGE_START[e, 1] + _EDGE_DIRECTION[e, 1] * t
    return best_u, best_v, dist


@njit  # a division by 0 gives inf or nan (_jit.OPTIONS)
def _newton(A, y, u, v, X, Xu, Xv):
    """Newton on patch A from (u, v) for the minimiser of |X - y|^2 (the Hessian J^T J + (X - y)
    . X_ij, or J^T J where that is not positive): (u, v) and whether it converged inside the
    triangle (within 1e-10; then clamped onto it). A step that leaves u, v >= -1, u + v <= 2
    stops it (the edges decide)."""
    converged = False
    for _ in range(NEWTON_ITERATIONS):
        _at(A, u, v, X, Xu, Xv)
        g0 = g1 = guu = guv = gvv = huu = hvv = huv = 0.0
        for k in range(3):
            r = X[k] - y[k]
            g0 += Xu[k] * r
            g1 += Xv[k] * r
            guu += Xu[k] * Xu[k]
            guv += Xu[k] * Xv[k]
            gvv += Xv[k] * Xv[k]
            huu += r * (2.0 * A[3, k])
            hvv += r * (2.0 * A[4, k])
            huv += r * A[5, k]
        huu, hvv, huv = guu + huu, gvv + hvv, guv + huv
        det = huu * hvv - huv * huv
        if det <= 1e-12 * (guu * gvv) or huu <= 0.0:
            huu, hvv, huv = guu, gvv, guv
            det = huu * hvv - huv * huv
        du = -(hvv * g0 - huv * g1) / det
        dv = -(huu * g1 - huv * g0) / det
        u += du
        v += dv
        if abs(du) + abs(dv) < 1e-13:
            converged = True
            break
        if u < -1.0 or v < -1.0 or u + v > 2.0:
            break
    eps = 1e-10
    if converged and u >= -eps and v >= -eps and u + v <= 1.0 + eps:
        return min(max(u, 0.0), 1.0), min(max(v, 0.0), 1.0), True
    return u, v, False


@njit
def _edge_curve(A, k, u0, v0, du, dv, y):
    """Component k of the edge curve's x(s) - y = Q0 + Q1 s + Q2 s^2 from (u0, v0) along (du, dv)."""
    return A[0, k] + A[1, k] * u0 + A[2, k] * v0 + A[3, k] * (u0 * u0) + A[4, k] * (v0 * v0) \
        + A[5, k] * (u0 * v0) - y[k], \
        (A[1, k] + 2.0 * A[3, k] * u0 + A[5, k] * v0) * du + (A[2, k] + 2.0 * A[4, k] * v0 + A[5, k] * u0) * dv, \
        A[3, k] * (du * du) + A[4, k] * (dv * dv) + A[5, k] * (du * dv)


@njit  # a division by 0 gives inf or nan (_jit.OPTIONS)
def _edge_curves(A, P, y, X, Xu, Xv):
    """The nearest point on patch A's three edge curves (0: u-axis, 1: u + v = 1, 2: v-axis):
    on each, Newton in its parameter s from the flat edge's closest point, clamped to [0, 1],
    on the cubic (x(s) - y) . x'(s) (x(s) = Q0 + Q1 s + Q2 s^2; x'(s) . x'(s) its derivative
    where that is not positive). Returns the nearest edge's (u, v), distance and edge (the
    first of equals)."""
    best_u, best_v, best, edge = 0.0, 0.0, np.inf, -1
    for e in range(3):
        u0, v0 = _EDGE_START[e, 0], _EDGE_START[e, 1]
        du, dv = _EDGE_DIRECTION[e, 0], _EDGE_DIRECTION[e, 1]
        a = P[_EDGE_CORNERS[e, 0]]
        d = _sub(P[_EDGE_CORNERS[e, 1]], a)
        s = min(max(_dot(_sub(y, a), d) / _dot(d, d), 0.0), 1.0)
        qx, qy, qz = _edge_curve(A, 0, u0, v0, du, dv, y), _edge_curve(A, 1, u0, v0, du, dv, y), \
            _edge_curve(A, 2, u0, v0, du, dv, y)
        Q0, Q1, Q2 = (qx[0], qy[0], qz[0]), (qx[1], qy[1], qz[1]), (qx[2], qy[2], qz[2])
        c0, c1 = _dot(Q0, Q1), _dot(Q1, Q1) + 2.0 * _dot(Q0, Q2)
        c2, c3 = 3.0 * _dot(Q1, Q2), 2.0 * _dot(Q2, Q2)
        ff0 = _dot(Q1, Q1)
        for _ in range(NEWTON_ITERATIONS):
            g = c0 + s * (c1 + s * (c2 + s * c3))
            h = c1 + s * (2.0 * c2 + 3.0 * c3 * s)
            ff = ff0 + s * (4.0 * c2 / 3.0 + 2.0 * c3 * s)  # |x'|^2
            new = min(max(s - g / (h if h > 0 else ff), 0.0), 1.0)
            done = abs(new - s) < 1e-13
            s = new
            if done:
                break
        u, v = u0 + du * s, v0 + dv * s
        _at(A, u, v, X, Xu, Xv)
        dist = _distance(y, X)
        if dist < best:
            best_u, best_v, best, edge = u, v, dist, e
    return best_u, best_v, best, edge


@njit
def _exact(A, P, y, u, v, X, Xu, Xv):
    """The nearest point of y on patch A (flat triangle P): Newton from (u, v); the edge curves
    where the minimiser leaves the triangle. Its (u, v), distance and kind (-1 inside, 0, 1, 2
    the edge)."""
    u, v, inside = _newton(A, y, u, v, X, Xu, Xv)
    if inside:
        _at(A, u, v, X, Xu, Xv)
        return u, v, _distance(y, X), -1
    return _edge_curves(A, P, y, X, Xu, Xv)


@njit
def _nearer(dist, t, best, best_t):
    """Whether patch t at dist is nearer than the best so far (ties: the lesser patch)."""
    return dist < best or (dist == best and t < best_t)


@njit  # a division by 0 gives inf or nan (_jit.OPTIONS)
def _warm_pass(y, delta, ref, last_y, last_c, last_t, last_u, last_v, last_kind, last_dist, last_rest, start,
               length, near, bound, patches, corners, centre, radius, bulge, size):
    """Points y moved by delta from the remembered points ref: their closest points from the
    remembered lists (module docstring; last_* the remembered points' y, closest points, patches,
    (u, v), kinds, distances and R, their lists `length` pairs (near, bound) from `start`; size
    the tool's); a point given again (delta 0) its remembered answer and list. Returns which
    were found; their patches, (u, v), kinds, distances and R - delta; their lists: patches,
    lower bounds (one pool), each found point's start and length in it."""
    n = len(y)
    found = np.zeros(n, dtype=np.bool_)
    t_out, kind_out = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
    u_out, v_out, dist_out, rest_out = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    total = 0
    for i in range(n):
        total += length[ref[i]]
    near_out, bound_out = np.empty(total, dtype=np.int64), np.empty(total)
    start_out, length_out = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
    X, Xu, Xv = np.empty(3), np.empty(3), np.empty(3)
    at = 0
    for i in range(n):
        r, moved = ref[i], delta[i]
        rest = last_rest[r] - moved  # the distance is 1-Lipschitz
        if moved == 0.0:  # given again: its answer and list
            found[i] = True
            t_out[i], u_out[i], v_out[i], kind_out[i], dist_out[i], rest_out[i] = last_t[r], last_u[r], last_v[r], \
                last_kind[r], last_dist[r], rest
            near_out[at:at + length[r]] = near[start[r]:start[r] + length[r]]
            bound_out[at:at + length[r]] = bound[start[r]:start[r] + length[r]]
            start_out[i], length_out[i] = at, length[r]
            at += length[r]
            continue
        upper = _distance(y[i], last_c[r])  # the remembered closest point lies on the surface
        if not upper <= rest - TIE * size:  # a patch outside the list may be nearer: searched
            continue
        limit = upper * (1 + 1e-12) + 1e-12 * size
        step = _sub(y[i], last_y[r])
        best, best_t, best_u, best_v, best_kind = np.inf, -1, 0.0, 0.0, -1
        for j in range(length[r]):
            k = near[start[r] + j]
            lower = bound[start[r] + j] - moved
            if lower <= limit:
                u, v = last_u[r], last_v[r]
                if k != last_t[r]:  # the cone from the remembered point to the patch's sphere
                    w = _sub(centre[k], last_y[r])
                    far = np.sqrt(_dot(w, w))
                    sin_a = min(radius[k] / far, 1.0)
                    cos_p = min(max(_dot(w, step) / (far * moved), -1.0), 1.0)
                    cos_a = np.sqrt(1.0 - sin_a * sin_a)
                    toward = 1.0
                    if not (cos_p >= cos_a or far <= radius[k]):
                        toward = cos_p * cos_a + np.sqrt(1.0 - cos_p * cos_p) * sin_a
                    lower = max(lower, bound[start[r] + j] - moved * toward)
                    if lower <= limit:  # the flat triangle's distance less the bulge
                        u, v, flat = _flat(y[i], corners[k])
                        lower = max(lower, flat - bulge[k])
                if lower <= limit:  # a candidate: projected
                    u, v, lower, kind = _exact(patches[k], corners[k], y[i], u, v, X, Xu, Xv)
                    if _nearer(lower, k, best, best_t):
                        best, best_t, best_u, best_v, best_kind = lower, k, u, v, kind
            near_out[at + j], bound_out[at + j] = k, lower
        if best_t < 0:
            continue
        found[i] = True
        t_out[i], u_out[i], v_out[i], kind_out[i], dist_out[i], rest_out[i] = best_t, best_u, best_v, best_kind, \
            best, rest
        start_out[i], length_out[i] = at, length[r]
        at += length[r]
    return found, t_out, u_out, v_out, kind_out, dist_out, rest_out, near_out[:at], bound_out[:at], start_out, \
        length_out


@njit
def _upper_bounds(y, near, corners, bulge):
    """Each point's least upper bound (flat distance plus bulge) over the patches `near` (points,
    k)."""
    n, k = near.shape
    upper = np.full(n, np.inf)
    for i in range(n):
        for j in range(k):
            t = near[i, j]
            upper[i] = min(upper[i], _flat(y[i], corners[t])[2] + bulge[t])
    return upper


@njit
def _search_pass(y, p, t, upper, rest, patches, corners, bulge, size):
    """The search's pairs (point p, patch t; by point): each pair's lower bound the flat
    distance less the bulge, kept where it lies within the point's rest; the candidates (lower
    bound within upper) projected, their distances their bounds. Returns the points' closest
    patches, (u, v), kinds and distances, and their lists (patches, lower bounds, start,
    length)."""
    n = len(y)
    t_out, kind_out = np.full(n, -1, dtype=np.int64), np.zeros(n, dtype=np.int64)
    u_out, v_out, dist_out = np.zeros(n), np.zeros(n), np.full(n, np.inf)
    near_out, bound_out = np.empty(len(p), dtype=np.int64), np.empty(len(p))
    length = np.zeros(n, dtype=np.int64)
    X, Xu, Xv = np.empty(3), np.empty(3), np.empty(3)
    at = 0
    for q in range(len(p)):
        i, k = p[q], t[q]
        u, v, flat = _flat(y[i], corners[k])
        lower = flat - bulge[k]
        if not lower <= rest[i]:
            continue
        if lower <= upper[i] * (1 + 1e-12) + 1e-12 * size:
            u, v, lower, kind = _exact(patches[k], corners[k], y[i], u, v, X, Xu, Xv)
            if _nearer(lower, k, dist_out[i], t_out[i]):
                t_out[i], u_out[i], v_out[i], kind_out[i], dist_out[i] = k, u, v, kind, lower
        near_out[at], bound_out[at] = k, lower
        length[i] += 1
        at += 1
    return t_out, u_out, v_out, kind_out, dist_out, near_out[:at], bound_out[:at], np.cumsum(length) - length, length


@njit  # a division by 0 gives inf or nan (_jit.OPTIONS)
def _signed_pass(y, t, u, v, kind, patches, sign, tiny, c, d, n, H, J, S):
    """Closest points c, signed distances d, normals n at the closest points (u, v) of patches t;
    H on the edge curves (kind 0, 1, 2: the curve's, (I - n n^T - x' x'^T / (|x'|^2 - (y - c)
    . x'')) / d; at a vertex (I - n n^T) / d; 0 within `tiny` of the curve), and J, S (X_u, X_v;
    X_uu, X_vv, X_uv) for the patches' H of the points inside (kind -1)."""
    Xu, Xv = np.empty(3), np.empty(3)
    for i in range(len(y)):
        A = patches[t[i]]
        _at(A, u[i], v[i], c[i], Xu, Xv)
        for k in range(3):
            J[i, 0, k], J[i, 1, k] = Xu[k], Xv[k]
            S[i, 0, k], S[i, 1, k], S[i, 2, k] = 2.0 * A[3, k], 2.0 * A[4, k], A[5, k]
        nc = (Xu[1] * Xv[2] - Xu[2] * Xv[1], Xu[2] * Xv[0] - Xu[0] * Xv[2], Xu[0] * Xv[1] - Xu[1] * Xv[0])
        norm = max(np.sqrt(_dot(nc, nc)), 1e-300)
        nc = (sign * nc[0] / norm, sign * nc[1] / norm, sign * nc[2] / norm)
        r = _sub(y[i], c[i])
        dist = np.sqrt(_dot(r, r))
        d[i] = _dot(r, nc)
        for k in range(3):
            n[i, k] = nc[k]
        if kind[i] < 0:
            continue
        s = -1.0 if d[i] < 0.0 else 1.0
        far = dist > tiny
        d[i] = s * dist
        if far:
            for k in range(3):
                n[i, k] = s * r[k] / dist
        du, dv = _EDGE_DIRECTION[kind[i], 0], _EDGE_DIRECTION[kind[i], 1]
        first = (Xu[0] * du + Xv[0] * dv, Xu[1] * du + Xv[1] * dv, Xu[2] * du + Xv[2] * dv)
        w0, w1, w2 = du * du, dv * dv, 2 * du * dv
        second = (w0 * S[i, 0, 0] + w1 * S[i, 1, 0] + w2 * S[i, 2, 0], w0 * S[i, 0, 1] + w1 * S[i, 1, 1]
                  + w2 * S[i, 2, 1], w0 * S[i, 0, 2] + w1 * S[i, 1, 2] + w2 * S[i, 2, 2])
        position = u[i] if kind[i] == 0 else v[i]
        vertex = position <= 0.0 or position >= 1.0
        ff = _dot(first, first)
        stiff = max(ff - _dot(r, second), 1e-12 * ff)
        scale = d[i] if far else np.inf
        for a in range(3):
            for b in range(3):
                P = (1.0 if a == b else 0.0) - n[i, a] * n[i, b]
                if not vertex:
                    P = P - first[a] * first[b] / stiff
                H[i, a, b] = P / scale


class _Remembered:
    """A call's points y (tool frame) and their answers: closest points c, signed distances d,
    normals n, H; the closest points' patches t, (u, v), kind (-1 inside, 0, 1, 2 the edge) and
    distances; each point's neighbour list, `length` patches `near` with lower bounds `bound`
    of their distances from `start`, every patch outside the list farther than `rest`."""

    def __init__(self, y, c, d, n, H, t, u, v, kind, dist, rest, start, length, near, bound):
        self.y = y
        self.c, self.d, self.n, self.H, self.t, self.u, self.v, self.kind = c, d, n, H, t, u, v, kind
        self.dist, self.rest, self.start, self.length, self.near, self.bound = dist, rest, start, length, near, bound

    def references(self, y, margin):
        """Each point of y's remembered point and its distance from it: the point of the same
        index where y has as many points as the remembered ones and each lies within margin
        of its own (a contact set's nodes, moved by an iterate), else the nearest (a k-d tree)."""
        if len(y) == len(self.y):
            step = y - self.y
            delta = np.sqrt(np.einsum("ij,ij->i", step, step))
            if delta.max() <= margin:
                return delta, np.arange(len(y))
        if not hasattr(self, "tree"):
            from scipy.spatial import cKDTree

            self.tree = cKDTree(self.y)
        return self.tree.query(y)


class MeshTool:
    """A rigid tool: quadratic triangular patches (T, 6, 3), X(u, v) = a_0 + a_1 u + a_2 v + a_3 u^2
    + a_4 v^2 + a_5 u v on u, v >= 0, u + v <= 1 (nagata_patches of a mesh; flat facets have
    a_3 = a_4 = a_5 = 0), placed by `translation` (mm), their normals X_u x X_v pointing to the
    sheet (`normals` "outward") or away from it ("inward": turned). Build it from a file with
    from_file, from a mesh with from_triangles."""

    def __init__(self, patches, translation=(0.0, 0.0, 0.0), normals: str = "outward"):
        if normals not in NORMALS:
            raise ValueError(f"normals must be one of {NORMALS}, got {normals!r}")
        from scipy.spatial import cKDTree

        A = np.asarray(patches, dtype=float).reshape(-1, 6, 3)
        if len(A) == 0:
            raise ValueError("the tool has no patches")
        self.patches, self.sign = A, 1.0 if normals == "outward" else -1.0
        self.translation = np.asarray(translation, dtype=float).reshape(3)
        self.corners = np.stack([A[:, 0], A[:, 0] + A[:, 1] + A[:, 3], A[:, 0] + A[:, 2] + A[:, 4]], axis=1)
        c01, c02 = A[:, 3], A[:, 4]
        c12 = c01 + c02 - A[:, 5]
        sizes = np.stack([np.linalg.norm(c, axis=1) for c in (c01, c12, c02)], axis=1)
        self.bulge = np.minimum(sizes.max(axis=1) / 3.0, sizes.sum(axis=1) / 4.0) * (1 + 1e-9)
        lo, hi = self.corners.reshape(-1, 3).min(axis=0), self.corners.reshape(-1, 3).max(axis=0)
        self.size = float(np.linalg.norm(hi - lo))
        # each patch within a sphere: its flat triangle's centroid, the farthest corner plus the bulge
        self.centre = self.corners.mean(axis=1)
        self.radius = (np.linalg.norm(self.corners - self.centre[:, None], axis=2).max(axis=1) + self.bulge) \
            * (1 + 1e-9)
        # samples on each flat triangle: a barycentric grid of m intervals, m = longest edge / spacing
        edges = np.linalg.norm(self.corners[:, [1, 2, 0]] - self.corners, axis=2)
        spacing = float(np.median(edges))
        m = np.maximum(1, np.ceil(edges.max(axis=1) / spacing)).astype(int)
        points, owner, reach = [], [], np.zeros(len(A))
        for k in np.unique(m):
            tri = np.flatnonzero(m == k)
            i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
            keep = i + j <= k
            u, v = i[keep] / k, j[keep] / k
            P = self.corners[tri]
            pts = P[:, None, 0] * (1 - u - v)[None, :, None] + P[:, None, 1] * u[None, :, None] \
                + P[:, None, 2] * v[None, :, None]
            points.append(pts.reshape(-1, 3))
            owner.append(np.repeat(tri, len(u)))
            reach[tri] = edges[tri].max(axis=1) / k  # every flat point lies within this of a sample
        self._samples = cKDTree(np.vstack(points))
        self._sample_owner = np.concatenate(owner)
        self._reach = float((reach + self.bulge).max()) * (1 + 1e-9) + 1e-12 * self.size
        self._margin = BALL_MARGIN * spacing
        self._last = None  # the last call's points (tool frame) and their answers (_Remembered)
        self.counts = {"repeated": 0, "warm": 0, "searched": 0}  # points answered each way, all calls

    def flat_top_boundary(self) -> list[np.ndarray]:
        """The boundary loops, in the model's frame ((m, 3) points at the mesh's vertices), of the
        highest flat facets whose (turned) normal is +z: a die's flat top, on which the holder
        pinches the flange (the edges that one of those facets alone uses, chained into loops)."""
        c = self.corners
        n = self.sign * np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
        n /= np.linalg.norm(n, axis=1)[:, None]
        up = n[:, 2] > 1.0 - 1e-9
        if not up.any():
            raise ValueError("the mesh has no flat facet whose normal is +z (a die's flat top)")
        height = c[up][:, :, 2].max()
        top = np.flatnonzero(up & (np.abs(c[:, :, 2] - height).max(axis=1) <= 1e-9 * self.size))
        grid = 1e-9 * self.size  # vertices that coincide within it are one

        def key(p, q):
            return tuple(sorted((tuple(np.round(p / grid)), tuple(np.round(q / grid)))))

        count = {}
        for t in top:
            for a, b in ((0, 1), (1, 2), (2, 0)):
                count.setdefault(key(c[t, a], c[t, b]), [0, c[t, a], c[t, b]])[0] += 1
        pieces = [np.array([p, q]) for k, p, q in count.values() if k == 1]
        return closed_loops(pieces, 1e-6 * self.size)

    @classmethod
    def from_triangles(cls, vertices, triangles, translation=(0.0, 0.0, 0.0), normals: str = "outward") -> "MeshTool":
        """The Nagata patches of a triangle mesh (vertices (V, 3), triangles (T, 3))."""
        return cls(nagata_patches(vertices, triangles), translation, normals)

    @classmethod
    def from_file(cls, path, translation=(0.0, 0.0, 0.0), normals: str = "outward",
                  field: str = "tools.file") -> "MeshTool":
        """The tool of an STL or ASCII gmsh .msh file (a bad file: InputError naming `field`)."""
        vertices, triangles = read_surface_mesh(path, field)
        return cls.from_triangles(vertices, triangles, translation, normals)

    # -- evaluation --------------------------------------------------------------------------
    def gap(self, x, offset=0.0, dz: float = 0.0):
        """Signed distance minus offset (> 0 clear) and unit normal from the tool towards x."""
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        _, d, n, _ = self._answers(x, dz)
        return d - np.broadcast_to(np.asarray(offset, dtype=float), d.shape), n + 0.0

    def shape(self, x, offset=0.0, dz: float = 0.0):
        """H = dn/dx (n, 3, 3) (module docstring)."""
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        return self._answers(x, dz)[3] + 0.0

    def closest(self, x, dz: float = 0.0):
        """For points x (n, 3): the closest surface points (placed), the signed distances and
        the normals."""
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        c, d, n, _ = self._answers(x, dz)
        return c + self.translation + np.array([0.0, 0.0, dz]), d.copy(), n.copy()

    def _answers(self, x, dz):
        """Closest points c (tool frame), signed distances, normals and H (module docstring:
        points given again take their last answers, moved points start warm from their
        remembered neighbours' bounds, the rest are searched)."""
        y = x - self.translation - np.array([0.0, 0.0, dz])
        npts = len(y)
        last = self._last
        if last is None or not npts:
            (t, u, v, kind, dist, rest), (near, bound, start, length) = self._search(y)
            searched = np.arange(npts)
            same = np.zeros(npts, dtype=bool)
        else:
            if np.array_equal(y, last.y):  # every point given again: the remembered points stay
                self.counts["repeated"] += npts
                return last.c, last.d, last.n, last.H
            delta, ref = last.references(y, self._margin)
            same = delta == 0.0
            if same.all():  # given again, some of them (the points in contact): the remembered points stay
                self.counts["repeated"] += npts
                return last.c[ref], last.d[ref], last.n[ref], last.H[ref]
            found, t, u, v, kind, dist, rest, near, bound, start, length = self._warm(y, last, ref, delta)
            searched = np.flatnonzero(~found)
            self.counts["repeated"] += int(same.sum())
            self.counts["warm"] += npts - int(same.sum()) - searched.size
            if searched.size:
                answers, lists = self._search(y[searched])
                t[searched], u[searched], v[searched], kind[searched], dist[searched], rest[searched] = answers
                start[searched], length[searched] = lists[2] + len(near), lists[3]
                near, bound = np.concatenate([near, lists[0]]), np.concatenate([bound, lists[1]])
        self.counts["searched"] += searched.size
        c, d, n, H = self._signed(y, t, u, v, kind)
        if same.any():
            rows = np.flatnonzero(same)
            r = ref[rows]
            c[rows], d[rows], n[rows], H[rows] = last.c[r], last.d[r], last.n[r], last.H[r]
        if npts:
            self._last = _Remembered(y, c, d, n, H, t, u, v, kind, dist, rest, start, length, near, bound)
        return c, d, n, H

    def _warm(self, y, last, ref, delta):
        """Points y moved by delta from the remembered points ref (_Remembered last), or given
        again (delta 0: their remembered answers and lists): their closest points from the
        remembered neighbour lists (module docstring). Returns which were found; their patches
        t, (u, v), kinds, distances and bounds beyond their lists; their lists (patches, lower
        bounds; each found point's start and length)."""
        return _warm_pass(y, delta, ref, last.y, last.c, last.t, last.u, last.v, last.kind, last.dist, last.rest,
                          last.start, last.length, last.near, last.bound, self.patches, self.corners, self.centre,
                          self.radius, self.bulge, self.size)

    def _search(self, y):
        """The closest points of points y (tool frame), as _warm gives them, and their lists: every
        triangle with a sample within upper + margin + reach of a point, upper the least of its
        nearest samples' triangles' upper bounds (flat distance plus bulge), is in its list
        with the lower bound flat distance less bulge, where that lies within upper + margin
        (every other patch lies beyond it); the candidates, lower bound <= upper, projected,
        their distances their bounds."""
        npts, T = len(y), len(self.patches)
        k = min(NEAREST_SAMPLES, self._samples.n)
        _, near = self._samples.query(y, k=k)
        upper = _upper_bounds(y, self._sample_owner[np.asarray(near).reshape(npts, k)], self.corners, self.bulge)
        rest = upper + self._margin
        lists = self._samples.query_ball_point(y, rest + self._reach, return_sorted=True)
        lengths = np.fromiter(map(len, lists), dtype=np.int64, count=npts)
        samples = np.fromiter(chain.from_iterable(lists), dtype=np.int64, count=int(lengths.sum()))
        # a point's samples come sorted, a triangle's samples are consecutive: one pair per run
        pair = np.repeat(np.arange(npts) * T, lengths) + self._sample_owner[samples]
        pair = pair[np.r_[True, pair[1:] != pair[:-1]]]
        t, u, v, kind, dist, near, bound, start, length = _search_pass(y, pair // T, pair % T, upper, rest,
                                                                        self.patches, self.corners, self.bulge,
                                                                        self.size)
        return (t, u, v, kind, dist, rest), (near, bound, start, length)

    def _signed(self, y, t, u, v, kind):
        """Closest points, signed distances, normals and H at the closest points (u, v) of
        patches t: inside (kind -1) the patch's; on an edge (kind 0, 1, 2) the curve's."""
        m = len(y)
        c, d, n, H = np.zeros((m, 3)), np.zeros(m), np.zeros((m, 3)), np.zeros((m, 3, 3))
        J, S = np.zeros((m, 2, 3)), np.zeros((m, 3, 3))
        _signed_pass(y, t, u, v, kind, self.patches, self.sign, 1e-12 * self.size, c, d, n, H, J, S)
        inside = kind < 0
        if inside.any():
            H[inside] = distance_hessian(J[inside], S[inside], n[inside], d[inside])
        return c, d, n, H
