"""The blank holder's inner edge in plan: where the die's flat top begins and the holder's face
ends (tools.BlankHolder, holder.py).

Every edge gives, for plan points (x, y),

    distance(x, y)   s, the signed distance from the edge: > 0 outside the die's opening (under
                     the holder), < 0 over the opening;
    offset(x, y)     (s, j): j the edge's length per unit length of the offset line through the
                     point, 1 / (1 + kappa s) with kappa the edge's curvature at its nearest
                     point (> 0 where the opening is convex: the offset line is longer);
    reach()          the distance from the centre to the edge along +x (where the die's
                     shoulder is measured: pinch_edge.shoulder_curvature).

RoundedSquareEdge is the analytic tools' (a rounded square); OutlineEdge is any closed curve
sampled densely in plan, counter-clockwise: the inner boundary of a CAD die's flat top
(SurfaceTool.flat_top_boundary), so that the holder covers exactly the die's flat top whatever
the opening's shape. Its distance is exact to the polyline (the nearest of the segments next
to the nearest sampled points); its curvature at a vertex is the turning angle over the mean
length of the two segments, linear along a segment.
"""

import numpy as np
from scipy.spatial import cKDTree

from shellform.tools.analytic import rounded_square_hessian, rounded_square_sdf


def signed_area(points) -> float:
    """The area a closed polyline (m, 2) encloses, > 0 counter-clockwise (the shoelace formula)."""
    p = np.asarray(points, dtype=float)
    return 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))


class RoundedSquareEdge:
    """The rounded square |x|, |y| <= half_width with plan corner radius corner_radius."""

    def __init__(self, half_width: float, corner_radius: float):
        if not 0 <= corner_radius <= half_width:
            raise ValueError(f"holder edge: needs 0 <= corner_radius <= half_width, got {corner_radius}, {half_width}")
        self.half_width, self.corner_radius = float(half_width), float(corner_radius)

    def distance(self, x, y):
        return rounded_square_sdf(x, y, self.half_width, self.corner_radius)[0]

    def offset(self, x, y):
        """1 - s tr(Hs) = rc / (rc + s) beside a corner arc, 1 beside a side."""
        s = self.distance(x, y)
        Hs = rounded_square_hessian(np.asarray(x, dtype=float), np.asarray(y, dtype=float),
                                    self.half_width, self.corner_radius)
        return s, 1.0 - s * np.trace(Hs, axis1=1, axis2=2)

    def reach(self) -> float:
        return self.half_width

    def length(self) -> float:
        """The whole edge's length: four sides and four quarter arcs."""
        return 8.0 * (self.half_width - self.corner_radius) + 2.0 * np.pi * self.corner_radius


class OutlineEdge:
    """A closed polyline `points` (m, 2) in plan, counter-clockwise around the opening (the
    last point not repeating the first)."""

    CANDIDATES = 4  # nearest sampled points whose segments are measured

    def __init__(self, points):
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        if len(p) < 3:
            raise ValueError("holder edge: an outline needs at least three points")
        if signed_area(p) < 0:
            p = p[::-1].copy()
        self.points = p
        self.ends = np.roll(p, -1, axis=0)
        d = self.ends - p
        self.lengths = np.linalg.norm(d, axis=1)
        if self.lengths.min() <= 0:
            raise ValueError("holder edge: two consecutive points coincide")
        self.tangents = d / self.lengths[:, None]
        # the turning angle at each vertex (from the segment before to the one after) over the
        # mean length: the curvature there, > 0 turning left (a convex opening, counter-clockwise)
        before = np.roll(self.tangents, 1, axis=0)
        turn = np.arctan2(before[:, 0] * self.tangents[:, 1] - before[:, 1] * self.tangents[:, 0],
                          np.sum(before * self.tangents, axis=1))
        self.curvature = turn / (0.5 * (self.lengths + np.roll(self.lengths, 1)))
        self.tree = cKDTree(p)

    def _nearest(self, x, y):
        """For each point: the nearest segment k, the parameter t in [0, 1] of the nearest point on
        it, and the distance."""
        q = np.column_stack([np.ravel(x), np.ravel(y)]).astype(float)
        m = len(self.points)
        _, near = self.tree.query(q, k=min(self.CANDIDATES, m))
        near = near.reshape(len(q), -1)
        segs = np.concatenate([near, (near - 1) % m], axis=1)  # the segments starting and ending there
        a, d = self.points[segs], self.ends[segs] - self.points[segs]
        t = np.clip(np.einsum("nki,nki->nk", q[:, None] - a, d) / np.einsum("nki,nki->nk", d, d), 0.0, 1.0)
        dist = np.linalg.norm(q[:, None] - (a + t[..., None] * d), axis=2)
        best = np.argmin(dist, axis=1)
        rows = np.arange(len(q))
        return q, segs[rows, best], t[rows, best], dist[rows, best]

    def distance(self, x, y):
        return self._signed(*self._nearest(x, y))

    def _signed(self, q, k, t, dist):
        """The distance with the sign of the side: outside (right of the counter-clockwise
        polyline) > 0. At a vertex (t = 0 or 1) the side is the mean of its two segments'."""
        a = self.points[k] + t[:, None] * (self.ends[k] - self.points[k])
        r = q - a
        tang = self.tangents[k].copy()
        at_start, at_end = t <= 0.0, t >= 1.0
        tang[at_start] += self.tangents[(k[at_start] - 1) % len(self.points)]
        tang[at_end] += self.tangents[(k[at_end] + 1) % len(self.points)]
        right = tang[:, 1] * r[:, 0] - tang[:, 0] * r[:, 1]  # (tangent x r) . -e_z
        return np.where(right >= 0.0, dist, -dist)

    def offset(self, x, y):
        """Where the opening is re-entrant, the edge bends round a tip of the die's top (kappa <
        0) and the offset lines on the holder's side shorten, to nothing at the tip's radius:
        there j is taken at half the radius at most (j <= 2), so that a band wider than the
        tip's radius (a mesh coarser than it) does not gather the edge load of the whole tip on
        the nodes beyond its centre."""
        q, k, t, dist = self._nearest(x, y)
        s = self._signed(q, k, t, dist)
        kappa = (1 - t) * self.curvature[k] + t * self.curvature[(k + 1) % len(self.points)]
        return s, 1.0 / np.maximum(1.0 + kappa * s, 0.5)

    def length(self) -> float:
        return float(self.lengths.sum())

    def reach(self) -> float:
        """Where the polyline crosses the +x axis nearest the centre."""
        a, b = self.points, self.ends
        crosses = (a[:, 1] <= 0.0) != (b[:, 1] <= 0.0)
        t = -a[crosses, 1] / (b[crosses, 1] - a[crosses, 1])
        x = a[crosses, 0] + t * (b[crosses, 0] - a[crosses, 0])
        x = x[x > 0.0]
        if x.size == 0:
            raise ValueError("holder edge: the outline does not cross the +x axis")
        return float(x.min())


def closed_loops(pieces, tol):
    """Closed loops from curve pieces (each (k, 3), from one end to the other) that meet end to
    end within tol: each loop's points in order, its last piece's end (its first point) left out."""
    pieces, loops = list(pieces), []
    while pieces:
        loop = [pieces.pop(0)]
        while np.linalg.norm(loop[-1][-1] - loop[0][0]) > tol:
            end = loop[-1][-1]
            k = next((i for i, p in enumerate(pieces)
                      if min(np.linalg.norm(p[0] - end), np.linalg.norm(p[-1] - end)) <= tol), None)
            if k is None:
                raise ValueError("the boundary does not close into loops")
            p = pieces.pop(k)
            loop.append(p if np.linalg.norm(p[0] - end) <= tol else p[::-1])
        loops.append(np.vstack([loop[0]] + [p[1:] for p in loop[1:]])[:-1])
    return loops
