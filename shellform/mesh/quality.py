"""Checks of a triangle mesh that a user brings (a .msh file, or the mesh gmsh makes of a .geo or
CAD file), made before DOLFINx gets it: a broken mesh is an InputError naming geometry.file that
says what is wrong and where, instead of a silent wrong answer or a failure deep inside PETSc.

``check(points, triangles)`` refuses, in this order:

- a mesh without triangles;
- a triangle node whose coordinates are not all finite;
- a degenerate triangle: |2A| <= EPS l^2 (A its area, l its longest edge: its smallest angle is
  zero to round-off), or l <= EPS h (h: the mesh size, the median of l over the triangles: its
  vertices coincide);
- a triangle listed twice (the same three nodes);
- an edge of more than two triangles, or two triangles that share an edge and lie on the same
  side of it: the mesh folds over itself (an inverted triangle). This is the consistent
  orientation of a plane mesh whatever the order of each triangle's nodes: two neighbours
  ordered alike have signed areas of the same sign exactly when they lie on opposite sides of
  their edge. (A whole surface ordered the other way round, as gmsh meshes a plane surface whose
  curve loop turns clockwise, is no error: the elements integrate with |det J|.)
- a region in more than one piece (triangles connected through their edges).

Nodes that no triangle uses (such as the centre point of a circle arc) are left out of the
checks: DOLFINx keeps the triangles' nodes only. The smallest angle of the mesh is returned, and
a MeshQualityWarning names the triangle when it is below SLIVER_ANGLE degrees.
"""

import warnings
from dataclasses import dataclass

import numpy as np

from shellform.errors import InputError

FIELD = "geometry.file"
EPS = 1e-10  # a degenerate triangle: its smallest angle, or its size over the mesh size, is below this
SLIVER_ANGLE = 10.0  # degrees: a smaller angle is warned about


class MeshQualityWarning(UserWarning):
    """A triangle of a user's mesh is a sliver: the results near it are less accurate."""


@dataclass(frozen=True)
class Quality:
    triangles: int
    min_angle: float  # degrees
    worst: int  # the triangle (its number in the messages) with that smallest angle
    unused_nodes: int  # nodes no triangle uses, left out


def check(points, triangles, cell_numbers=None, node_numbers=None, source: str = "the mesh") -> Quality:
    """The Quality of the triangles (rows of three indices into points, whose rows are x, y[, z]),
    or an InputError naming geometry.file. cell_numbers and node_numbers (default: 0, 1, ...) are
    the numbers a message gives a triangle and a node, e.g. gmsh's element and node tags; source
    names the mesh in messages (its file)."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    if len(t) == 0:
        raise InputError(FIELD, f"{source} holds no triangles")
    x = np.asarray(points, dtype=float).reshape(len(points), -1)
    cells = np.arange(len(t)) if cell_numbers is None else np.asarray(cell_numbers)
    nodes = np.arange(len(x)) if node_numbers is None else np.asarray(node_numbers)

    def where(c):
        corners = ", ".join(f"{nodes[v]} at ({x[v, 0]:.6g}, {x[v, 1]:.6g})" for v in t[c])
        return f"triangle {cells[c]} (nodes {corners})"

    used = np.unique(t)
    bad = used[~np.all(np.isfinite(x[used]), axis=1)]
    if bad.size:
        raise InputError(FIELD, f"{source}: node {nodes[bad[0]]} has the coordinates "
                         f"({', '.join(f'{c:g}' for c in x[bad[0]])}): they must be finite")
    p = x[t][:, :, :2]  # (cells, 3 corners, x y)
    e = np.roll(p, -1, axis=1) - p  # edge k joins corner k to corner k + 1
    length = np.hypot(e[..., 0], e[..., 1])
    area2 = e[:, 0, 0] * e[:, 1, 1] - e[:, 0, 1] * e[:, 1, 0]  # twice the signed area
    longest = length.max(axis=1)
    h = float(np.median(longest))
    degenerate = np.flatnonzero((np.abs(area2) <= EPS * longest**2) | (longest <= EPS * h))
    if degenerate.size:
        c = degenerate[0]
        raise InputError(FIELD, f"{source}: {where(c)} has zero area (of {degenerate.size} degenerate "
                         "triangles): its vertices coincide or lie on one line")
    key = np.sort(t, axis=1)
    _, first, count = np.unique(key, axis=0, return_index=True, return_counts=True)
    if np.any(count > 1):
        c = first[np.argmax(count > 1)]
        twin = np.flatnonzero(np.all(key == key[c], axis=1))[1]
        raise InputError(FIELD, f"{source}: {where(c)} is listed twice (again as triangle {cells[twin]})")
    _check_folds(p, t, nodes, where, source)
    pieces = _pieces(t)
    if pieces.max() > 0:
        c = np.argmax(pieces != pieces[0])
        raise InputError(FIELD, f"{source}: the region is in {pieces.max() + 1} pieces not joined by triangle "
                         f"edges; {where(c)} is not connected to {where(0)}")
    cos = -np.sum(e * np.roll(e, 1, axis=1), axis=2) / (length * np.roll(length, 1, axis=1))
    angle = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))).min(axis=1)  # at each corner
    worst = int(np.argmin(angle))
    if angle[worst] < SLIVER_ANGLE:
        warnings.warn(MeshQualityWarning(
            f"{source}: {where(worst)} has an angle of {angle[worst]:.3g} degrees (a sliver; "
            f"triangles with an angle below {SLIVER_ANGLE:g}: {np.count_nonzero(angle < SLIVER_ANGLE)}): "
            "results near it are less accurate"), stacklevel=2)
    return Quality(len(t), float(angle[worst]), int(cells[worst]), int(len(x) - used.size))


def _edges(t):
    """Per edge k = (corner k, corner k + 1) of each triangle (row 3 c + k): its sorted node pair
    and the index of that pair among the unique edges; and per unique edge, its triangles."""
    pairs = np.sort(np.stack([t, np.roll(t, -1, axis=1)], axis=2), axis=2).reshape(-1, 2)
    _, index, count = np.unique(pairs, axis=0, return_inverse=True, return_counts=True)
    return pairs, index.reshape(-1), count


def _check_folds(p, t, nodes, where, source):
    pairs, index, count = _edges(t)
    if np.any(count > 2):
        k = np.flatnonzero(count[index] > 2)[0]
        raise InputError(FIELD, f"{source}: the edge of nodes {nodes[pairs[k][0]]} and {nodes[pairs[k][1]]} is "
                         f"shared by "
                         f"{count[index[k]]} triangles, one of them {where(k // 3)}: the mesh overlaps itself")
    # which side of its (sorted) edge each triangle's third corner lies on
    flat = p.reshape(-1, 3, 2)
    corner = np.arange(3 * len(t)) % 3
    cell = np.arange(3 * len(t)) // 3
    i, j = corner, (corner + 1) % 3
    swap = t[cell, i] > t[cell, j]
    a = np.where(swap[:, None], flat[cell, j], flat[cell, i])
    b = np.where(swap[:, None], flat[cell, i], flat[cell, j])
    r = flat[cell, (corner + 2) % 3]
    side = np.sign((b[:, 0] - a[:, 0]) * (r[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (r[:, 0] - a[:, 0]))
    shared = np.flatnonzero(count[index] == 2)
    order = shared[np.argsort(index[shared], kind="stable")]
    first, second = order[0::2], order[1::2]
    folded = np.flatnonzero(side[first] == side[second])
    if folded.size:
        k, m = first[folded[0]], second[folded[0]]
        raise InputError(FIELD, f"{source}: {where(cell[m])} and {where(cell[k])} lie on the same side of their "
                         f"shared edge: the mesh folds over itself there (an inverted triangle; "
                         f"folded edges: {folded.size})")


def _pieces(t) -> np.ndarray:
    """The connected piece (0, 1, ...) of each triangle, triangles joined through shared edges."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    _, index, count = _edges(t)
    cell = np.arange(3 * len(t)) // 3
    shared = np.flatnonzero(count[index] == 2)
    order = shared[np.argsort(index[shared], kind="stable")]
    u, v = cell[order[0::2]], cell[order[1::2]]
    graph = coo_matrix((np.ones(len(u)), (u, v)), shape=(len(t), len(t)))
    return connected_components(graph, directed=False)[1]
