"""A rigid tool whose surface is a triangle mesh (an STL file, or a gmsh .msh file's triangles),
interpolated by Nagata patches.

The tool gives what the analytic tools give (tools.py) and the CAD tool (surface_tool.py): for
points x, placed by a translation and moved by dz along z,

    gap(x, offset, dz)    the signed distance to the surface minus offset (> 0 clear), and the
                          unit normal pointing from the tool towards the point;
    shape(x, offset, dz)  H = dn/dx (n, 3, 3), the Hessian of the signed distance.

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


The flow of a call (points given again, the warm start, the search, the signed pass) is the
closest-point engine's (closest_point.py); the compiled passes are mesh_patches.py's, the
patches nagata.py's, the file's reading mesh_files.py's.
"""

from itertools import chain

import numpy as np

from shellform.tools.closest_point import ClosestPointTool, Points, Samples
from shellform.tools.holder_edge import closed_loops
from shellform.tools.mesh_files import MESH_SUFFIXES, read_surface_mesh  # noqa: F401  (cad.py's, the tests')
from shellform.tools.mesh_patches import _search_pass, _signed_pass, _upper_bounds, _warm_pass
from shellform.tools.nagata import nagata_patches
from shellform.tools.surface_geometry import distance_hessian

NEAREST_SAMPLES = 4  # samples whose triangles give each point's first upper bound
BALL_MARGIN = 1.0  # the search's ball reaches this times the sampling's spacing beyond the candidates'


class MeshTool(ClosestPointTool):
    """A rigid tool: quadratic triangular patches (T, 6, 3), X(u, v) = a_0 + a_1 u + a_2 v + a_3 u^2
    + a_4 v^2 + a_5 u v on u, v >= 0, u + v <= 1 (nagata_patches of a mesh; flat facets have
    a_3 = a_4 = a_5 = 0), placed by `translation` (mm), their normals X_u x X_v pointing to the
    sheet (`normals` "outward") or away from it ("inward": turned). Build it from a file with
    from_file, from a mesh with from_triangles."""

    def __init__(self, patches, translation=(0.0, 0.0, 0.0), normals: str = "outward"):
        super().__init__(translation, normals)
        A = np.asarray(patches, dtype=float).reshape(-1, 6, 3)
        if len(A) == 0:
            raise ValueError("the tool has no patches")
        self.patches = A
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
        self._samples = Samples(np.vstack(points), np.concatenate(owner))
        self._reach = float((reach + self.bulge).max()) * (1 + 1e-9) + 1e-12 * self.size
        self._margin = BALL_MARGIN * spacing  # a moved point's own remembered point within it

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

    check_file = staticmethod(read_surface_mesh)  # the file read and checked (cad.read_tool_file)

    @classmethod
    def from_file(cls, path, translation=(0.0, 0.0, 0.0), normals: str = "outward",
                  field: str = "tools.file") -> "MeshTool":
        """The tool of an STL or ASCII gmsh .msh file (a bad file: InputError naming `field`)."""
        vertices, triangles = cls.check_file(path, field)
        return cls.from_triangles(vertices, triangles, translation, normals)

    # -- the closest-point engine's hooks (closest_point.py) -----------------------------------
    COUNTS = ("repeated", "warm", "searched")

    def _placed(self, c, shift, dz):
        return c + self.translation + np.array([0.0, 0.0, dz])

    def _blank(self, npts) -> Points:
        """A call's arrays: closest points c, signed distances d, normals n, H; the closest
        points' patches t, (u, v), kind (-1 inside, 0, 1, 2 the edge) and distances; each point's
        neighbour list, `length` patches of the pool `near` with lower bounds `bound` of their
        distances from `start`, every patch outside the list farther than `rest`."""
        p = Points(extras=("near", "bound"), c=np.zeros((npts, 3)), d=np.zeros(npts), n=np.zeros((npts, 3)),
                   H=np.zeros((npts, 3, 3)), t=np.zeros(npts, dtype=np.int64), u=np.zeros(npts), v=np.zeros(npts),
                   kind=np.zeros(npts, dtype=np.int64), dist=np.zeros(npts), rest=np.zeros(npts),
                   start=np.zeros(npts, dtype=np.int64), length=np.zeros(npts, dtype=np.int64))
        p.near, p.bound = np.zeros(0, dtype=np.int64), np.zeros(0)
        return p

    def _repeat(self, points, rows, last, ref):
        """Points given again: their answers, and their lists gathered into the call's pool."""
        points.put(rows, last.points, ref)
        lp = last.points
        length = lp.length[ref]
        first = np.cumsum(length) - length
        pick = np.repeat(lp.start[ref] - first, length) + np.arange(int(length.sum()))
        points.start[rows] = first + len(points.near)
        points.near = np.concatenate([points.near, lp.near[pick]])
        points.bound = np.concatenate([points.bound, lp.bound[pick]])

    def _pool(self, points, rows, answers, lists):
        """Rows' answers (t, u, v, kind, dist, rest) and lists (near, bound, start, length) into
        the call's arrays, their lists appended to its pool."""
        points.t[rows], points.u[rows], points.v[rows], points.kind[rows], points.dist[rows], points.rest[rows] = \
            answers
        near, bound, start, length = lists
        points.start[rows], points.length[rows] = start + len(points.near), length
        points.near, points.bound = np.concatenate([points.near, near]), np.concatenate([points.bound, bound])

    def _steps(self):
        return (("warm", self._warm),)

    def _warm(self, y, todo, last, ref, delta, points):
        """The moved points from their remembered neighbours' lists (module docstring): the rows
        found."""
        if last is None:
            return np.zeros(0, dtype=int)
        rows = np.flatnonzero(todo)
        lp = last.points
        found, t, u, v, kind, dist, rest, near, bound, start, length = _warm_pass(
            y[rows], delta[rows], ref[rows], last.y, lp.c, lp.t, lp.u, lp.v, lp.kind, lp.dist, lp.rest, lp.start,
            lp.length, lp.near, lp.bound, self.patches, self.corners, self.centre, self.radius, self.bulge, self.size)
        self._pool(points, rows[found], (t[found], u[found], v[found], kind[found], dist[found], rest[found]),
                   (near, bound, start[found], length[found]))
        return rows[found]

    def _search(self, y, rows, points):
        answers, lists = self._search_lists(y[rows])
        self._pool(points, rows, answers, lists)

    def _search_lists(self, y):
        """The closest points of points y (tool frame), as _warm gives them, and their lists: every
        triangle with a sample within upper + margin + reach of a point, upper the least of its
        nearest samples' triangles' upper bounds (flat distance plus bulge), is in its list
        with the lower bound flat distance less bulge, where that lies within upper + margin
        (every other patch lies beyond it); the candidates, lower bound <= upper, projected,
        their distances their bounds."""
        npts, T = len(y), len(self.patches)
        k = min(NEAREST_SAMPLES, self._samples.n)
        _, near = self._samples.query(y, k=k)
        upper = _upper_bounds(y, self._samples.owner[np.asarray(near).reshape(npts, k)], self.corners, self.bulge)
        rest = upper + self._margin
        lists = self._samples.ball(y, rest + self._reach)
        lengths = np.fromiter(map(len, lists), dtype=np.int64, count=npts)
        samples = np.fromiter(chain.from_iterable(lists), dtype=np.int64, count=int(lengths.sum()))
        # a point's samples come sorted, a triangle's samples are consecutive: one pair per run
        pair = np.repeat(np.arange(npts) * T, lengths) + self._samples.owner[samples]
        pair = pair[np.r_[True, pair[1:] != pair[:-1]]]
        t, u, v, kind, dist, near, bound, start, length = _search_pass(y, pair // T, pair % T, upper, rest,
                                                                        self.patches, self.corners, self.bulge,
                                                                        self.size)
        return (t, u, v, kind, dist, rest), (near, bound, start, length)

    def _signed(self, y, rows, points):
        """Closest points, signed distances, normals and H of rows at their closest points (u, v)
        of patches t: inside (kind -1) the patch's; on an edge (kind 0, 1, 2) the curve's."""
        m = len(rows)
        c, d, n, H = np.zeros((m, 3)), np.zeros(m), np.zeros((m, 3)), np.zeros((m, 3, 3))
        J, S = np.zeros((m, 2, 3)), np.zeros((m, 3, 3))
        kind = points.kind[rows]
        _signed_pass(y[rows], points.t[rows], points.u[rows], points.v[rows], kind, self.patches, self.sign,
                     1e-12 * self.size, c, d, n, H, J, S)
        inside = kind < 0
        if inside.any():
            H[inside] = distance_hessian(J[inside], S[inside], n[inside], d[inside])
        points.c[rows], points.d[rows], points.n[rows], points.H[rows] = c, d, n, H

    def _hessian(self, points):
        return points.H
