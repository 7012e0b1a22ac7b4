"""A CAD tool's closest points in closed form: the pass over the faces evaluated in numpy (faces.py)
and the lower bounds of the distances to every entity (boxes, closed forms, remembered bounds) that
prove a closest point (surface_tool.py's docstring: "exact", "warm").
"""

import numpy as np

from shellform.tools.cad_model import CadModel
from shellform.tools.faces import cross as faces_cross
from shellform.tools.faces import within as faces_within


class CadExact(CadModel):
    """The closed-form pass and the distances' lower bounds of a CAD tool's model."""

    def _exact(self, m, y, upper):
        """Closest points on the faces evaluated in numpy (faces.py) of points y whose distance
        is at most `upper`: the nearest point in closed form of each filled face whose bounding
        box lies within upper, each trimmed plane's foot point where it lies inside the trim
        (its sampled boundary, isInside within the sampling's margin; checked only where it may
        be the nearest). The nearest of these is the closest point (found) where it lies inside
        its face's parameter rectangle (not on its boundary: an edge's point, answered by the
        search as before), the face's parametrisation is regular there, and every entity no
        exact face answers for (a face of another kind, an edge that bounds no filled exact
        face) lies farther by its bounding box (less 1e-9 of the tool's size: a tie goes to
        the search). Ties between faces go to the lower face tag. Returns c, dist, ent, par,
        J, S and found."""
        npts, nent = len(y), len(self._ents)
        faces = self._exact_index
        pi, k = faces_within(y, upper * (1 + 1e-9) + 1e-9 * self.size, self._box[faces, 0], self._box[faces, 1])
        k = faces[k]
        kind_of = self._kind_of[k]
        D, U = np.full((npts, nent), np.inf), np.zeros((npts, nent, 2))
        inside = np.zeros((npts, nent), dtype=bool)
        evaluated = []  # a kind's pairs whose X, J, S its nearest gave
        for i, kind in enumerate(self._kinds):
            sel = np.flatnonzero(kind_of == i)
            if sel.size:
                p, e = pi[sel], k[sel]
                out = kind.nearest(y[p], self._position[e])
                U[p, e], D[p, e], inside[p, e] = out[:3]
                if len(out) > 3:
                    evaluated.append((i, p, e, out[3]))
        sel = np.flatnonzero(kind_of == len(self._kinds))  # the trimmed planes
        if sel.size:
            p, e = pi[sel], k[sel]
            uv, d, _ = self._trimmed_planes.nearest(y[p], self._position[e])
            check = np.flatnonzero(d <= D.min(axis=1)[p] * (1 + 1e-9) + 1e-9 * self.size)
            for e0 in np.unique(e[check]):
                rows = check[e[check] == e0]
                f = self._ents[e0][1]
                ins, sure = self._in_trim(f, uv[rows])
                for i in np.flatnonzero(~sure):
                    ins[i] = m.isInside(2, f, uv[rows[i]], True) > 0
                rows = rows[ins]
                U[p[rows], e0], D[p[rows], e0], inside[p[rows], e0] = uv[rows], d[rows], True
        best = np.argmin(D, axis=1)
        r = np.arange(npts)
        dist, par = D[r, best], U[r, best]
        found = np.isfinite(dist) & inside[r, best]
        if self._rest.size:
            found &= self._lower(y, self._rest).min(axis=1) > dist * (1 + 1e-9) + 1e-9 * self.size
        c, J, S = np.zeros((npts, 3)), np.zeros((npts, 2, 3)), np.zeros((npts, 3, 3))
        for i, p, e, (Xe, Je, Se) in evaluated:
            w = found[p] & (best[p] == e)
            c[p[w]], J[p[w]], S[p[w]] = Xe[w], Je[w], Se[w]
        for i, kind in enumerate(self._kinds + [self._trimmed_planes]):
            rows = np.flatnonzero(found & (self._kind_of[best] == i))
            if rows.size and i not in [v[0] for v in evaluated]:
                c[rows], J[rows], S[rows] = kind.derivatives(self._position[best[rows]], par[rows])
        cross = faces_cross(J[:, 0], J[:, 1])
        found &= np.einsum("pi,pi->p", cross, cross) > 1e-24 * np.einsum("pai,pai->p", J, J) ** 2  # not a pole
        r = y - c
        dist = np.where(found, np.sqrt(np.einsum("pi,pi->p", r, r)), dist)
        return c, dist, best, par, J, S, found

    def _face_distances(self, y, kinds):
        """The faces of `kinds` (their indices) and the points' distances to them (points,
        faces), in closed form (faces.py; a trimmed plane's: to its plane)."""
        ks, ds = [np.zeros(0, dtype=int)], [np.zeros((len(y), 0))]
        for kind in kinds:
            if len(kind):
                j = np.tile(np.arange(len(kind)), len(y))
                ks.append(np.asarray(kind.index))
                ds.append(kind.nearest(np.repeat(y, len(kind), axis=0), j)[1].reshape(len(y), -1))
        return np.concatenate(ks), np.hstack(ds)

    def _exact_distances(self, y):
        """The faces evaluated in numpy that fill their parameter rectangle (their indices) and
        the points' distances to them (in closed form)."""
        return self._face_distances(y, self._covering)

    def _remembered_bounds(self, last, ref):
        """The lower bounds of the remembered points ref's distances to every entity (points,
        entities); those of points the exact pass answered computed now: the bounding boxes',
        raised to the exact faces' distances and the trimmed planes' distances to their
        planes."""
        bound = last.points.bound[ref]
        miss = np.flatnonzero(np.isnan(bound[:, 0]))
        if miss.size:
            y = last.y[ref[miss]]
            sub = self._lower(y)
            k, d = self._face_distances(y, self._covering + [self._trimmed_planes])
            sub[:, k] = np.maximum(sub[:, k], d)
            bound[miss] = sub
        return bound

    def _lower(self, y, entities=slice(None)):
        """The distance of points y to the entities' bounding boxes (points, entities; every
        entity unless given): a lower bound of their distance to the entity."""
        lo, hi = self._box[entities, 0], self._box[entities, 1]
        square = 0.0
        for a in range(3):
            t = np.maximum(lo[:, a] - y[:, a, None], y[:, a, None] - hi[:, a])
            np.maximum(t, 0.0, out=t)
            square = square + t * t
        return np.sqrt(square)
