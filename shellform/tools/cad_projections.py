"""A CAD tool's closest points found with gmsh: Newton on a face (local, warm) and the candidates'
projections (getClosestPoint) where the closed forms do not answer (surface_tool.py's docstring:
"local", "candidates", "warm").
"""

import numpy as np

from shellform.tools.cad_exact import CadExact

LOCAL_ITERATIONS = 8  # Newton iterations of the local projection before the candidates' projections take over


class CadProjections(CadExact):
    """The gmsh steps of a CAD tool's closest points: the search from the samples, the warm start
    from the remembered points, Newton on a face and the candidates' projections."""

    def _search_samples(self, m, y):
        """Closest points: first the local projection from the nearest sample (_local), where
        it is sure; the other points by the candidates' projections (_candidates). Also returns
        lower bounds of every point's distance to every entity (points, entities): the bounding
        boxes', raised to a face's projection distance onto its untrimmed surface (an edge's onto
        its curve) where one was computed, and to the distance found on its face (and its
        edges) where the local projection converged inside it."""
        upper, sample = self._samples.query(y)
        upper = upper * (1 + 1e-9) + 1e-9 * self.size
        lower = self._lower(y)  # (points, entities)
        bound = lower.copy()
        c, dist, ent, par = np.zeros_like(y), np.full(len(y), np.inf), np.full(len(y), -1), np.zeros((len(y), 2))
        done = self._local(m, y, sample, lower, c, dist, ent, par, bound)
        rest = np.flatnonzero(~done)
        if rest.size:  # a point found by the local projection bounds the distance and is a candidate
            seed = (c[rest], dist[rest], ent[rest], par[rest])
            upper = np.minimum(upper[rest], dist[rest] * (1 + 1e-9) + 1e-9 * self.size)
            sub = bound[rest]
            c[rest], dist[rest], ent[rest], par[rest] = self._candidates(m, y[rest], upper, lower[rest], seed, sub)
            bound[rest] = sub
        r = np.flatnonzero(ent >= 0)
        bound[r, ent[r]] = dist[r]
        return c, dist, ent, par, bound

    def _newton(self, m, f, uv, y):
        """Newton on face f from its parameters uv (modified in place) towards the points y:
        min |X(u, v) - y|^2, the step -A^-1 g with g = J (X - y), A = J J^T + X_ij . (X - y),
        at most LOCAL_ITERATIONS steps (on a plane one: X is affine in (u, v), the step exact),
        until a step moves the point by less than 1e-13 of the tool's size. Returns the points
        X(uv) (the last evaluation plus J step), where it converged inside the face (its
        parametric bounds; a trimmed face's sampled boundary, sure of the side), and the
        derivatives J, S of the last evaluation (a step before uv: within 1e-13 of the size)."""
        ok = np.zeros(len(y), dtype=bool)
        plane = (2, f) in self._flat
        for _ in range(1 if plane else LOCAL_ITERATIONS):
            X = np.asarray(m.getValue(2, f, uv.ravel())).reshape(-1, 3)
            J = np.asarray(m.getDerivative(2, f, uv.ravel())).reshape(-1, 2, 3)
            S = np.zeros((len(uv), 3, 3)) if plane else \
                np.asarray(m.getSecondDerivative(2, f, uv.ravel())).reshape(-1, 3, 3)
            r = X - y
            g = np.einsum("pai,pi->pa", J, r)
            Sr = np.einsum("pki,pi->pk", S, r)
            A = np.einsum("pai,pbi->pab", J, J)
            A[:, 0, 0] += Sr[:, 0]
            A[:, 1, 1] += Sr[:, 1]
            A[:, 0, 1] += Sr[:, 2]
            A[:, 1, 0] += Sr[:, 2]
            det = A[:, 0, 0] * A[:, 1, 1] - A[:, 0, 1] * A[:, 1, 0]
            good = (det > 0) & (A[:, 0, 0] > 0)
            det = np.where(good, det, 1.0)
            step = -np.stack([A[:, 1, 1] * g[:, 0] - A[:, 0, 1] * g[:, 1],
                              A[:, 0, 0] * g[:, 1] - A[:, 1, 0] * g[:, 0]], axis=1) / det[:, None]
            step[~good] = 0.0
            uv += step
            move = np.einsum("pai,pa->pi", J, step)
            ok = good & (plane | (np.linalg.norm(move, axis=1) < 1e-13 * self.size))
            if ok.all():
                break
        X = X + move  # the last step's change: exact on a plane, within its square elsewhere
        b0, b1 = self._bounds[(2, f)]
        tol = 1e-9 * (b1 - b0 + 1.0)
        ok &= np.all((uv >= b0 - tol) & (uv <= b1 + tol), axis=1)
        if not self._filled[f]:
            inside, sure = self._in_trim(f, uv)
            ok &= inside & sure
        return X, ok, J, S

    def _local(self, m, y, sample, lower, c, dist, ent, par, bound):
        """Newton on the face of each point's nearest sample (on both faces of a sample on an
        edge), from the sample's parameters (_newton). Where it converges inside a face, that
        face and its edges are known for the point (the nearest point of a face found inside it
        is nearer than its edges: their bounds in `bound` are raised to it); the nearest point
        found is sure (True) where no other entity's bounding box lies nearer. Fills c, dist,
        ent, par with the nearest point found inside a face (sure or not: a point of the
        surface, which bounds the distance)."""
        npts, nent = len(y), len(self._ents)
        k0 = self._samples.owner[sample]
        on_face = self._is_face[k0]
        pts, ks, uvs = [np.flatnonzero(on_face)], [k0[on_face]], [self._samples.params[sample[on_face]]]
        for k in np.unique(k0[~on_face]):
            e = self._ents[k][1]
            i = np.flatnonzero(k0 == k)
            t = self._samples.params[sample[i], 0]
            for f in self._face_adjacent[e]:
                pts.append(i)
                ks.append(np.full(len(i), self._index[(2, f)]))
                uvs.append(np.asarray(m.reparametrizeOnSurface(1, e, t, f)).reshape(-1, 2))
        pts, ks, uvs = np.concatenate(pts), np.concatenate(ks), np.vstack(uvs)
        known = np.zeros((npts, nent), dtype=bool)
        for k in np.unique(ks):
            f = self._ents[k][1]
            sel = ks == k
            idx, uv = pts[sel], uvs[sel].copy()
            yk = y[idx]
            X, ok, _, _ = self._newton(m, f, uv, yk)
            d = np.linalg.norm(yk - X, axis=1)
            better = ok & (d < dist[idx])
            rows = idx[better]
            c[rows], dist[rows], ent[rows], par[rows] = X[better], d[better], k, uv[better]
            self._settle(known, bound, idx[ok], k, d[ok])
        others = np.where(known, np.inf, lower).min(axis=1)
        return (ent >= 0) & (dist <= others)

    def _settle(self, known, bound, rows, k, d):
        """Face k's nearest points of `rows` found inside it, at distances d: the face and its
        edges known for them, their distances' lower bounds raised to d."""
        known[rows, k] = True
        bound[rows, k] = np.maximum(bound[rows, k], d)
        edges = self._face_edges[k]
        known[np.ix_(rows, edges)] = True
        bound[np.ix_(rows, edges)] = np.maximum(bound[np.ix_(rows, edges)], d[:, None])

    def _warm(self, m, y, warm, last, ref, delta, out):
        """The points y[warm] near the remembered points ref of the last call (at distances
        delta), on a face there: Newton on that face from its parameters (_newton). A point
        that converges inside the face is sure where no other entity may lie nearer: the
        distance to an entity is at least its remembered lower bound less delta (the distance
        is 1-Lipschitz; less 1e-9 of the tool's size, so that a tie goes to the candidates), and
        a rectangle's or a cylinder's (a plane or a cylinder that fills its parameter rectangle)
        its distance (_rectangle_distances). Where another
        entity may lie nearer, the point's candidates are the entities whose bounds allow it
        (_candidates, the face's point the seed). Fills `out` (c, dist, ent, par, bound, J, S,
        has) at the points found; returns which of `warm` were found (those whose Newton did
        not converge inside their face are left to the search)."""
        c, dist, ent, par, bound, Jo, So, has = out
        ks = last.points.ent[ref]
        uvs = last.points.par[ref].copy()
        X, d, ok = np.zeros((warm.size, 3)), np.full(warm.size, np.inf), np.zeros(warm.size, dtype=bool)
        J, S = np.zeros((warm.size, 2, 3)), np.zeros((warm.size, 3, 3))
        for k in np.unique(ks):
            sel = np.flatnonzero(ks == k)
            uv = uvs[sel]
            X[sel], ok[sel], J[sel], S[sel] = self._newton(m, self._ents[k][1], uv, y[warm[sel]])
            uvs[sel] = uv
            d[sel] = np.linalg.norm(y[warm[sel]] - X[sel], axis=1)
        lower = self._remembered_bounds(last, ref) - delta[:, None]
        known = np.zeros_like(lower, dtype=bool)
        for k in np.unique(ks):
            sel = np.flatnonzero((ks == k) & ok)
            self._settle(known, lower, sel, k, d[sel])
        others = np.where(known, np.inf, lower - 1e-9 * self.size).min(axis=1)
        sure = ok & (d <= others)
        i = np.flatnonzero(ok & ~sure)
        if i.size:  # the rectangles' and cylinders' distances
            k, exact = self._exact_distances(y[warm[i]])
            lower[np.ix_(i, k)] = np.maximum(lower[np.ix_(i, k)], exact)
            others = np.where(known[i], np.inf, lower[i] - 1e-9 * self.size).min(axis=1)
            sure[i] = d[i] <= others
        newton = sure.copy()
        i = np.flatnonzero(ok & ~sure)
        if i.size:  # another entity may lie nearer: the candidates among those whose bounds allow it
            sub, seed = lower[i], ks[i].copy()
            X[i], d[i], ks[i], uvs[i] = self._candidates(
                m, y[warm[i]], d[i] * (1 + 1e-9) + 1e-9 * self.size, np.where(known[i], np.inf, sub),
                (X[i], d[i], ks[i], uvs[i]), sub)
            newton[i] = ks[i] == seed  # the face's own point nearest
            sub[np.arange(i.size), ks[i]] = d[i]
            lower[i] = sub
            sure[i] = True
        rows = warm[sure]
        c[rows], dist[rows], ent[rows], par[rows], bound[rows] = X[sure], d[sure], ks[sure], uvs[sure], lower[sure]
        rows = warm[newton]
        Jo[rows], So[rows], has[rows] = J[newton], S[newton], True
        return sure

    def _edge_nearest(self, m, e, y):
        """The nearest points of edge e (a tag) to points y, their parameters and distances: the
        nearer of OCC's projection onto the edge and the edge's ends (getClosestPoint: the
        curve's extremum of least distance within the edge's range, where it has one; an arc's
        farthest point where only that lies in the range). gmsh's parametric coordinate of an
        edge's projection is not used: gmsh 4.15 returns 0 for it wherever OCC's projection
        succeeds (its point is right), so clamping it moved a segment's foot point to an end of
        the segment. The parameter is that of the projected point (getParametrization of a
        point on the curve: exact), clamped to the edge's range and evaluated there."""
        b0, b1 = self._bounds[(1, e)]
        c = np.asarray(m.getClosestPoint(1, e, y.ravel())[0], dtype=float).reshape(-1, 3)
        t = np.clip(np.asarray(m.getParametrization(1, e, c.ravel()), dtype=float), b0[0], b1[0])
        c = np.asarray(m.getValue(1, e, t)).reshape(-1, 3)
        X = np.concatenate([c[:, None], np.broadcast_to(self._ends[e], (len(y), 2, 3))], axis=1)
        T = np.c_[t, np.full(len(y), b0[0]), np.full(len(y), b1[0])]
        D = np.linalg.norm(y[:, None] - X, axis=2)
        j, r = np.argmin(D, axis=1), np.arange(len(y))  # a tie: the projection
        return X[r, j], T[r, j], D[r, j]

    def _candidates(self, m, y, upper, lower, seed, bound):
        """The nearest of every entity's projection whose bounding box lies within `upper`, and
        of the seed (c, dist, entity, parameters: the local projection's point, entity -1 where
        there is none). Raises `bound` to each projection's distance (a face's onto its
        untrimmed surface; an edge's nearest point, _edge_nearest: lower bounds of the distance
        to the entity), and a face's whose projection falls outside it to the least of its
        edges' bounds."""
        npts = len(y)
        cand = lower <= upper[:, None]
        nent = len(self._ents)
        D = np.full((npts, nent), np.inf)
        C = np.zeros((npts, nent, 3))
        P = np.zeros((npts, nent, 2))
        seeded = np.flatnonzero(seed[2] >= 0)
        k = seed[2][seeded]
        C[seeded, k], D[seeded, k], P[seeded, k] = seed[0][seeded], seed[1][seeded], seed[3][seeded]
        cand[seeded, k] = False
        unknown = np.zeros((npts, nent), dtype=bool)  # a trimmed face's projection, not checked yet
        for k in np.flatnonzero(cand.any(axis=0)):
            d, t = self._ents[k]
            idx = np.flatnonzero(cand[:, k])
            b0, b1 = self._bounds[(d, t)]
            if d == 1:  # the edge's nearest point: its distance is the edge's
                c, P[idx, k, 0], dist = self._edge_nearest(m, t, y[idx])
                bound[idx, k] = np.maximum(bound[idx, k], dist)
            else:
                c, p = m.getClosestPoint(d, t, y[idx].ravel())
                c = np.asarray(c).reshape(-1, 3)
                bound[idx, k] = np.maximum(bound[idx, k], np.linalg.norm(y[idx] - c, axis=1))
                p = np.asarray(p, dtype=float).reshape(-1, 2)
                P[idx, k] = p
                tol = 1e-9 * (b1 - b0 + 1.0)
                within = np.all((p >= b0 - tol) & (p <= b1 + tol), axis=1)
                if self._filled[t]:
                    idx, c = idx[within], c[within]
                else:
                    idx, c, p = idx[within], c[within], p[within]
                    inside, sure = self._in_trim(t, p)
                    unknown[idx[~sure], k] = True
                    keep = inside | ~sure
                    idx, c = idx[keep], c[keep]
            C[idx, k] = c
            D[idx, k] = np.linalg.norm(y[idx] - c, axis=1)
        # trimmed faces: check the nearest candidate of each point until a valid one is nearest
        while True:
            best = np.argmin(D, axis=1)
            rows = np.flatnonzero(unknown[np.arange(npts), best])
            if rows.size == 0:
                break
            for i in rows:
                k = best[i]
                unknown[i, k] = False
                if m.isInside(2, self._ents[k][1], P[i, k], True) <= 0:
                    D[i, k] = np.inf
        # a face whose projection falls outside it is nearest on its boundary: at least its edges' bounds
        outside = cand & ~np.isfinite(D) & ~unknown & self._is_face[None, :]
        for k in np.flatnonzero(outside.any(axis=0)):
            rows, edges = np.flatnonzero(outside[:, k]), self._face_edges[k]
            if edges.size:
                bound[rows, k] = np.maximum(bound[rows, k], bound[np.ix_(rows, edges)].min(axis=1))
        best = np.argmin(D, axis=1)
        r = np.arange(npts)
        return C[r, best], D[r, best], best, P[r, best]
