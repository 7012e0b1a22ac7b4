"""The Nagata patches of a triangle mesh: quadratic triangles through its vertices with its
vertex normals, one per triangle, that meet along their edges (a tool's surface: mesh_tool.py).


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
"""

import numpy as np

from shellform.tools.mesh_files import _edges

FEATURE_ANGLE = 45.0  # degrees: facets whose normals differ by more meet at a crease
PLANE_ANGLE = 150.0  # degrees: coplanar facets spanning this much at a vertex make its normal the plane's
PARALLEL = 1e-12  # 1 - (n_a . n_b)^2 below this: Nagata's c = 0 (parallel or opposite normals)


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
