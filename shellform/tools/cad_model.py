"""A CAD tool's model in gmsh's OpenCASCADE kernel, as its closest points need it: its faces and
edges, their bounding boxes and parametric bounds, points sampled on them (the search's spatial
index), the faces evaluated in numpy (faces.py) and the trimmed faces' sides (surface_tool.py's
docstring tells how they are used).

gmsh runs in this process, initialised once per process (_gmsh); each tool is a gmsh model of its
own, made current while it is evaluated (_Current).
"""

import numpy as np

from shellform.tools.closest_point import Samples
from shellform.tools.faces import CurveRevolutions, Cylinders, Planes, Revolutions

SAMPLES = 24  # points per parametric direction sampled on a face (per edge: along it) for the upper bounds
BOUNDARY_SAMPLES = 4000  # a trimmed face's boundary sampled every 1/BOUNDARY_SAMPLES of the tool's size
SIDE_TESTS = 9  # segments of an edge of a trimmed face at which the face's side is asked
RASTER = 256  # at most as many cells along each parameter of a trimmed face's raster of its sides


def _gmsh():
    import gmsh

    if not gmsh.isInitialized():
        gmsh.initialize(readConfigFiles=False, interruptible=False)
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.Verbosity", 0)
    return gmsh


class _Current:
    """The tool's gmsh model made current; the previous current model restored afterwards."""

    def __init__(self, name):
        self.name = name

    def __enter__(self):
        gmsh = _gmsh()
        self.previous = gmsh.model.getCurrent()
        gmsh.model.setCurrent(self.name)
        return gmsh

    def __exit__(self, *exc):
        import gmsh

        if self.previous and self.previous != self.name:
            gmsh.model.setCurrent(self.previous)


def _degenerate(gmsh, edge: int) -> bool:
    """Whether an edge of the model is a point with no curve: OCC's degenerated edge at a
    sphere's pole or a cone's apex (its bounding box is a point grown by OCC's tolerance). It
    has nothing to project onto, and the face around it holds that point, so the tool leaves it
    out."""
    box = np.array(gmsh.model.getBoundingBox(1, edge))
    extent = float(np.max(box[3:] - box[:3]))
    return gmsh.model.getType(1, edge) == "Unknown" and extent <= 1e-6 * (1.0 + float(np.abs(box).max()))



def _curve_length(m, c, t0, t1, n=64):
    x = np.asarray(m.getValue(1, c, np.linspace(t0, t1, n + 1))).reshape(-1, 3)
    return float(np.linalg.norm(np.diff(x, axis=0), axis=1).sum())


class CadModel:
    """The model's entities (faces, then edges: `_ents`), their boxes and parametric bounds, the
    sampled points, the faces evaluated in numpy and the trims (set up by _setup, in the tool's
    gmsh model)."""

    def _setup(self, gmsh):
        """Bounding boxes, parametric bounds, whether each face fills its parametric bounds, the
        sampled points of the upper bounds, and the faces evaluated in numpy (faces.py): the
        planes, cylinders and surfaces of revolution of a circle that fill their parameter
        rectangle (their nearest points in closed form), and the trimmed planes (their foot
        points, checked against the trim)."""
        m = gmsh.model
        self._ents = [(2, f) for f in self.faces] + [(1, e) for e in self.edges]
        self._box = np.array([m.getBoundingBox(d, t) for d, t in self._ents]).reshape(-1, 2, 3)
        lo, hi = self._box[:, 0].min(axis=0), self._box[:, 1].max(axis=0)
        self.size = float(np.linalg.norm(hi - lo))
        self._box += np.array([-1.0, 1.0])[None, :, None] * 1e-9 * self.size
        self._bounds, self._filled, self._trims, self._flat, self._orient, self._ends = {}, {}, {}, set(), {}, {}
        # the faces evaluated in numpy that fill their rectangle: the first three in closed form,
        # also on their boundary; the surfaces of revolution of a curve only inside
        self._kinds = [Planes(self.size), Cylinders(self.size), Revolutions(self.size),
                       CurveRevolutions(self.size, self._evaluate)]
        self._covering = self._kinds[:3]
        self._trimmed_planes = Planes(self.size)
        points, owner, params = [], [], []
        s = np.linspace(0.0, 1.0, SAMPLES)
        for k, (d, t) in enumerate(self._ents):
            b0, b1 = (np.asarray(v, dtype=float) for v in m.getParametrizationBounds(d, t))
            self._bounds[(d, t)] = (b0, b1)
            if m.getType(d, t) in ("Plane", "Line"):
                self._flat.add((d, t))
            if d == 2:
                u, v = np.meshgrid(b0[0] + s * (b1[0] - b0[0]), b0[1] + s * (b1[1] - b0[1]))
                uv = np.c_[u.ravel(), v.ravel()]
                inside = np.array([m.isInside(2, t, q, True) > 0 for q in uv])
                self._filled[t] = bool(inside.all())
                if not self._filled[t]:
                    self._trims[t] = self._trim(m, t, uv, inside)
                uv = uv[inside]
                if uv.size == 0:
                    continue
                xyz = np.asarray(m.getValue(2, t, uv.ravel())).reshape(-1, 3)
                J = np.asarray(m.getDerivative(2, t, uv.ravel())).reshape(-1, 2, 3)
                normal = np.asarray(m.getNormal(t, uv.ravel())).reshape(-1, 3)
                self._orient[t] = 1.0 if np.einsum("pi,pi->", np.cross(J[:, 0], J[:, 1]), normal) >= 0 else -1.0
                self._fit(m, k, t, b0, b1, uv, xyz, J)
            else:
                uv = np.c_[b0[0] + s * (b1[0] - b0[0]), np.zeros(SAMPLES)]
                xyz = np.asarray(m.getValue(1, t, uv[:, 0])).reshape(-1, 3)
                self._ends[t] = xyz[[0, -1]]  # the edge's ends, at b0 and b1
            points.append(xyz)
            owner.append(np.full(len(xyz), k))
            params.append(uv)
        self._samples = Samples(np.vstack(points), np.concatenate(owner), np.vstack(params))
        self._index_of = {de: k for k, de in enumerate(self._ents)}
        self._exact_faces = np.zeros(len(self._ents), dtype=bool)  # evaluated in numpy
        covered = np.zeros(len(self._ents), dtype=bool)  # an exact face's, or an edge of a filled one
        for kind in self._kinds + [self._trimmed_planes]:
            self._exact_faces[kind.index] = True
        for kind in self._covering:
            covered[kind.index] = True
        filled = covered.copy()
        covered |= self._exact_faces
        for k, (d, t) in enumerate(self._ents):
            if d == 1:
                covered[k] = any(filled[self._index_of[(2, f)]] for f in self._face_adjacent[t])
        self._rest = np.flatnonzero(~covered)  # the entities the exact faces do not answer for
        self._kind_of, self._position = np.full(len(self._ents), -1), np.zeros(len(self._ents), dtype=int)
        for i, kind in enumerate(self._kinds + [self._trimmed_planes]):  # kind i's face, at its position
            self._kind_of[kind.index], self._position[kind.index] = i, np.arange(len(kind))
        self._exact_index = np.flatnonzero(self._exact_faces)
        self._orientation = np.array([self._orient.get(t, 1.0) if d == 2 else 0.0 for d, t in self._ents])

    def _fit(self, m, k, f, b0, b1, uv, xyz, J):
        """Face k (tag f) evaluated in numpy where gmsh names it a plane, a cylinder or a surface
        of revolution (a torus, a sphere) and the kind's parametrisation fitted from it is gmsh's
        at its samples uv (faces.py)."""
        kind = m.getType(2, f)
        S = np.asarray(m.getSecondDerivative(2, f, uv.ravel())).reshape(-1, 3, 3)
        filled = self._filled[f]
        if kind == "Plane":
            (self._kinds[0] if filled else self._trimmed_planes).add(
                k, b0 if filled else np.full(2, -np.inf), b1 if filled else np.full(2, np.inf), xyz, J, S, uv)
        elif kind == "Cylinder" and filled:
            origin = [np.asarray(g(2, f, [0.0, 0.0])).reshape(shape) for g, shape in
                      ((m.getValue, 3), (m.getDerivative, (2, 3)), (m.getSecondDerivative, (3, 3)))]
            self._kinds[1].add(k, b0, b1, xyz, J, S, uv, origin)
        elif kind in ("Torus", "Sphere", "Surface of Revolution") and filled:
            mid = 0.5 * (b0 + b1)
            middle = [mid] + [np.asarray(g(2, f, mid)).reshape(shape) for g, shape in
                              ((m.getValue, 3), (m.getDerivative, (2, 3)), (m.getSecondDerivative, (3, 3)))]
            if not self._kinds[2].add(k, b0, b1, xyz, J, S, uv, middle) and kind == "Surface of Revolution":
                meridian = self._evaluate(k, np.c_[np.full(len(uv), mid[0]), uv[:, 1]])
                self._kinds[3].add(k, b0, b1, xyz, J, S, uv, middle, meridian)

    def _evaluate(self, k, uv):
        """gmsh's X, J (X_u, X_v) and S (X_uu, X_vv, X_uv) of face k (an index) at parameters uv
        (the tool's model current)."""
        m, f, flat = _gmsh().model, self._ents[k][1], np.ravel(uv)
        return (np.asarray(m.getValue(2, f, flat)).reshape(-1, 3),
                np.asarray(m.getDerivative(2, f, flat)).reshape(-1, 2, 3),
                np.asarray(m.getSecondDerivative(2, f, flat)).reshape(-1, 3, 3))

    def _trim(self, m, f, uv, inside):
        """A trimmed face's boundary in its parameters: its edges sampled every 1/BOUNDARY_SAMPLES
        of the tool's size (at least 16 points an edge, at most 4096) as segments; their
        midpoints in a k-d tree with each segment's normal pointing into the face (the face lies
        on one side of an edge all along it: that side found by isInside at SIDE_TESTS segments
        spread along the edge, at the points 1/800 of the tool's size to either side of their
        midpoints, and asked the same at all of them); the margin within which the sampled
        boundary may differ from the true one (half the longest segment plus twice the largest
        deviation of an edge's mid-parameter point from its segment). None where the sides are
        not told apart or where that classifies the sampled parameters `uv` other than isInside
        does."""
        from scipy.spatial import cKDTree

        mids, normals, margin, ends_all = [], [], 0.0, []
        for e in m.getAdjacencies(2, f)[1]:
            e = abs(int(e))
            x0, y0, z0, x1, y1, z1 = m.getBoundingBox(1, e)
            count = int(np.clip(np.hypot(np.hypot(x1 - x0, y1 - y0), z1 - z0) / self.size * BOUNDARY_SAMPLES,
                                16, 4096))
            b0, b1 = m.getParametrizationBounds(1, e)
            t = np.linspace(b0[0], b1[0], 2 * count + 1)
            q = np.asarray(m.reparametrizeOnSurface(1, e, t, f)).reshape(-1, 2)
            ends, mid = q[::2], q[1::2]
            chord = ends[1:] - ends[:-1]
            length = np.linalg.norm(chord, axis=1)
            keep = length > 0
            normal = np.c_[-chord[:, 1], chord[:, 0]][keep] / length[keep, None]
            centre = 0.5 * (ends[:-1] + ends[1:])[keep]
            # the side, at points clear of OCC's classifier's tolerance (it takes those within as inside)
            test = np.unique(np.linspace(0, len(centre) - 1, SIDE_TESTS).round().astype(int))
            step = 0.5 * self.size / 400 * normal[test]
            into = np.array([m.isInside(2, f, q, True) > 0 for q in centre[test] + step])
            out = np.array([m.isInside(2, f, q, True) > 0 for q in centre[test] - step])
            if np.any(into == out) or np.any(into != into[0]):  # the boundary's sides not told apart
                return None
            mids.append(centre)
            normals.append(normal if into[0] else -normal)
            ends_all.append(ends)
            sag = np.linalg.norm(mid - 0.5 * (ends[:-1] + ends[1:]), axis=1)
            margin = max(margin, 0.5 * float(length.max()) + 2.0 * float(sag.max()))
        trim = (cKDTree(np.vstack(mids)), np.vstack(normals), margin * (1 + 1e-6) + 1e-9 * self.size, None)
        self._trims[f] = trim
        self._trims[f] = trim[:3] + (self._raster(m, f, trim, np.vstack(ends_all)),)
        ins, sure = self._in_trim(f, uv)
        return self._trims[f] if bool(np.all(ins[sure] == inside[sure])) else None

    def _raster(self, m, f, trim, boundary):
        """The sides of trimmed face f in a raster of its parameter rectangle (at most RASTER
        cells along each parameter, of about the margin's size): (origin, cell, inside, sure),
        cell k centred at origin + k cell. A cell is sure where no sampled boundary point lies
        within the margin and half the cell's diagonal of its centre: no boundary crosses it.
        Sure cells that touch hold one side; each such region's is its first cell's (by the
        nearest boundary segment). None where the face's sampled boundary leaves its parameter
        rectangle (outside the rectangle a point is outside the face: the face lies within its
        boundary's hull)."""
        from scipy.ndimage import label

        tree, normals, margin, _ = trim
        b0, b1 = (np.asarray(b, dtype=float) for b in m.getParametrizationBounds(2, f))
        tol = 1e-9 * (b1 - b0 + 1.0)
        if np.any(boundary < b0 - tol) or np.any(boundary > b1 + tol):
            return None
        cells = np.minimum(np.ceil((b1 - b0) / margin), RASTER).astype(int) + 1
        cell = np.maximum((b1 - b0) / np.maximum(cells - 1, 1), 1e-9 * self.size)
        centres = np.stack(np.meshgrid(*(b0[a] + cell[a] * np.arange(cells[a]) for a in range(2)), indexing="ij"),
                           axis=-1).reshape(-1, 2)
        dist, _ = tree.query(centres, distance_upper_bound=margin + 0.5 * float(np.linalg.norm(cell)))
        sure = np.isinf(dist).reshape(cells)
        regions, count = label(sure)
        first = np.unique(regions.ravel(), return_index=True)[1][1:]  # each region's first cell
        _, i = tree.query(centres[first])
        side = np.einsum("pi,pi->p", centres[first] - tree.data[i], normals[i]) > 0
        return b0, cell, np.r_[False, side][regions], sure

    def _in_trim(self, f, uv):
        """(inside, sure) for parameters uv of trimmed face f: inside where uv lies on the inner
        side of its nearest boundary segment, sure where it lies farther from the sampled
        boundary than the margin (_trim); isInside decides the others. Looked up first in a
        raster of the face's parameter rectangle (cells of about the margin's size), whose
        cells no boundary crosses (their centres farther than the margin and half the cell's
        diagonal from it) hold their side."""
        trim = self._trims.get(f)
        if trim is None:
            return np.zeros(len(uv), dtype=bool), np.zeros(len(uv), dtype=bool)
        tree, normals, margin, raster = trim
        inside, sure = np.zeros(len(uv), dtype=bool), np.zeros(len(uv), dtype=bool)
        if raster is not None:
            origin, cell, ins, known = raster
            k = np.floor((uv - origin) / cell + 0.5).astype(int)
            on = np.all((k >= 0) & (k < np.array(ins.shape)), axis=1)
            inside[on], sure[on] = ins[k[on, 0], k[on, 1]], known[k[on, 0], k[on, 1]]
            sure[~on] = True  # outside the parameter rectangle: outside the face
        rest = np.flatnonzero(~sure)
        if rest.size:
            dist, i = tree.query(uv[rest])
            inside[rest] = np.einsum("pi,pi->p", uv[rest] - tree.data[i], normals[i]) > 0
            sure[rest] = dist > margin
        return inside, sure
