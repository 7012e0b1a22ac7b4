"""A rigid tool whose surface is a CAD model, evaluated by gmsh's OpenCASCADE kernel.

The tool is the set of faces of an OCC model (a STEP, IGES or BREP file, or a model a Python
function builds with gmsh.model.occ), placed by a translation and moved by dz along z. It gives
what the analytic tools give (tools.py): for points x,

    gap(x, offset, dz)    the signed distance to the surface minus offset (> 0 clear), and the
                          unit normal pointing from the tool towards the point;
    shape(x, offset, dz)  H = dn/dx (n, 3, 3), the Hessian of the signed distance.

The surface is evaluated, not meshed (docs/tools.md). Most faces of a tool are elementary
surfaces evaluated from their parameters without gmsh (faces.py: planes, cylinders, surfaces of
revolution of a circle in compiled loops; of a curve, Newton along its meridian with gmsh),
fitted from gmsh's evaluations and verified against them when the tool is built. For a point
x the closest surface point c is found

    exact       on those faces, all at once: each one's nearest point whose bounding box lies
                within an upper bound of the distance (the last answer of the point's
                remembered neighbour plus the distance to it; a sample's), in closed form (a
                curve meridian: its turn in closed form, Newton along it), a trimmed plane's
                foot point where its trim holds it (a raster of its sides, the sampled boundary
                near it, isInside within the sampling's margin). The nearest of these is the
                closest point where it lies inside its face (not on an edge) and no entity they
                do not answer for (a face of another kind, an edge no filled one bounds) lies
                nearer by its bounding box;

and where not, in two steps with gmsh:

    local       Newton on the face of the nearest of points sampled on every face and edge (a
                k-d tree; both faces of a sample on an edge), from the sample's parameters; a
                point it finds inside its face is the face's nearest, and sure where no other
                entity's bounding box lies nearer (the face's own edges are settled by it);
    candidates  for the other points, the nearest of the projections onto every entity whose
                bounding box lies within the best distance found so far: a face's orthogonal
                projection onto its underlying surface (getClosestPoint, OCC's global one), kept
                where it lies inside the trimmed face (its parametric bounds for a face that
                fills them; for a trimmed one the inner side of its sampled boundary, isInside
                within the sampling's margin); an edge's projection with its parameter clamped
                to its range (the nearest point of a face whose projection falls outside it
                lies on its boundary).

A second, non-global minimum of the distance inside one face is not found by the gmsh steps
(the closed forms are global on their face).

Every point also gets lower bounds of its distance to every face and edge (the bounding
boxes', raised by the projections computed on the way, the closed forms' distances). The tool
remembers its last call's points with their closest points, the face's derivatives there and
these bounds (_Projections; the bounds of points the exact pass answered computed where asked).
A point given again takes its last answer (shape on the points of the last gap call: H from
the derivatives its face gave); a point the exact pass leaves, at distance delta from the
nearest remembered one whose closest point lay on a face,

    warm        Newton on that face from the remembered (u, v); a point it finds inside the
                face is sure where every other entity's bound less delta (the distance is
                1-Lipschitz) lies farther (a face in closed form: its exact distance); where
                not, the candidates are the entities whose bounds allow them nearer, the face's
                point the seed.

The other points are searched as above. `counts` counts the points answered each way
(repeated, exact, warm, searched).

Signed distance and normal. The faces' normals (getNormal, oriented by OCC's face orientation:
outward for the faces of a solid) point to the side of the sheet; ``normals = "inward"`` turns
them all. With the closest point c on a face of normal n_c at c, the signed distance is
d = (x - c) . n_c (x - c is parallel to n_c there) and the normal n = n_c. On an edge, d =
+/-|x - c| with the sign of (x - c) . (n_a + n_b), n_a, n_b the normals of the edge's faces at
c, and n = (x - c) / d (the faces' mean normal where x lies on the edge).

Shape operator. On a face, with X_u, X_v, X_uu, X_uv, X_vv the parametrisation's derivatives at
c, J = [X_u X_v], G = J^T J and B_ij = -n . X_ij (B/G > 0 where the tool is convex), the surface's
shape operator is H0 = J G^-1 B G^-1 J^T (tangential, symmetric), and the distance's Hessian at
distance d from it is H = H0 (I + d H0)^-1: each principal curvature k becomes k / (1 + k d),
the level surface's. On an edge between two faces that meet at an angle (a sharp edge), H =
(I - n n^T - e e^T) / d, e the edge's tangent: the Hessian of the distance to a straight line
(the edge's own curvature is left out).

Seams. Between two faces that meet tangentially (a fillet's seam, G1) the normal is
continuous, so gap and normal are smooth across the seam; H jumps there (a fillet's curvature
is not that of the face it meets). A point whose closest point lies on the seam takes the face
whose projection is nearest (within round-off, the one gmsh's isInside accepts; ties go to
the lower face tag); reached through the edge (neither face accepts it), it takes the edge's
first face that meets it tangentially. Either is one of the two one-sided values, as the
analytic tools take one side of a region boundary.

gmsh runs in this process, initialised once per process (every MPI rank evaluates its own
points); each tool is a gmsh model of its own, made current while it is evaluated. A file is
read first by a child process (cad_files.py: importing gmsh only, no MPI) stopped after READ_SECONDS (a file
that stalls or crashes OCC's reader does not stall or crash the run), then imported here with
gmsh.model.occ.importShapes, which reads the shapes only (gmsh's open/merge would also merge a
FILE.opt script beside it).
Lengths are in mm: OCC converts the file's unit to mm (Geometry.OCCTargetUnit).
"""

from pathlib import Path

import numpy as np

from shellform.tools.cad_files import probe
from shellform.tools.faces import CurveRevolutions, Cylinders, Planes, Revolutions
from shellform.tools.faces import cross as faces_cross
from shellform.tools.faces import within as faces_within
from shellform.tools.holder_edge import closed_loops
from shellform.tools.surface_geometry import distance_hessian
from shellform.errors import InputError

LOCAL_ITERATIONS = 8  # Newton iterations of the local projection before the candidates' projections take over
SAMPLES = 24  # points per parametric direction sampled on a face (per edge: along it) for the upper bounds
BOUNDARY_SAMPLES = 4000  # a trimmed face's boundary sampled every 1/BOUNDARY_SAMPLES of the tool's size
SIDE_TESTS = 9  # segments of an edge of a trimmed face at which the face's side is asked
RASTER = 256  # at most as many cells along each parameter of a trimmed face's raster of its sides
NORMALS = ("outward", "inward")


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


def _keys(y):
    """Each point's coordinates as one opaque key (its bytes: equal exactly where the point is)."""
    return np.ascontiguousarray(y).view(np.dtype((np.void, y.dtype.itemsize * 3))).ravel()


class _Projections:
    """Points y (in a tool's model frame) with their closest points c, distances dist, signed
    distances d, normals n, entities (indices into the tool's entities) and parameters, lower
    bounds of their distances to every entity (points, entities), and where the closest point
    was found by Newton on a face (has), the face's derivatives there (J: X_u, X_v; S: X_uu,
    X_vv, X_uv)."""

    def __init__(self, y, c, dist, d, n, ent, par, bound, J, S, has):
        self.y, self.c, self.dist, self.d, self.n, self.ent, self.par, self.bound = y, c, dist, d, n, ent, par, bound
        self.J, self.S, self.has = J, S, has
        self.tree = self.order = None


    def nearest(self, y):
        """A remembered point near each of y (its index) and the distance to it: as many points
        as remembered are taken row by row (the contact set's nodes again, moved or not); in
        other calls a point given again is found by its coordinates' bytes (sorted), the others
        take the nearest remembered point (a k-d tree). 0 exactly where the point is given
        again."""
        if len(y) == len(self.y):
            r = y - self.y
            return np.arange(len(y)), np.sqrt(np.einsum("pi,pi->p", r, r))
        if self.order is None:
            self.keys = _keys(self.y)
            self.order = np.argsort(self.keys)
        keys = _keys(y)
        at = np.minimum(np.searchsorted(self.keys, keys, sorter=self.order), len(self.y) - 1)
        ref = self.order[at]
        delta = np.where(self.keys[ref] == keys, 0.0, np.inf)
        moved = np.flatnonzero(delta > 0.0)
        if moved.size:
            if self.tree is None:
                from scipy.spatial import cKDTree

                self.tree = cKDTree(self.y)
            delta[moved], ref[moved] = self.tree.query(y[moved])
        return ref, delta


def _degenerate(gmsh, edge: int) -> bool:
    """Whether an edge of the model is a point with no curve: OCC's degenerated edge at a
    sphere's pole or a cone's apex (its bounding box is a point grown by OCC's tolerance). It
    has nothing to project onto, and the face around it holds that point, so the tool leaves it
    out."""
    box = np.array(gmsh.model.getBoundingBox(1, edge))
    extent = float(np.max(box[3:] - box[:3]))
    return gmsh.model.getType(1, edge) == "Unknown" and extent <= 1e-6 * (1.0 + float(np.abs(box).max()))


class SurfaceTool:
    """A rigid tool: the faces of the OCC model `model` (a gmsh model's name), placed by
    `translation` (mm), its faces' normals pointing to the sheet (`normals` "outward") or away
    from it ("inward": turned). Build it with from_file or from_builder."""

    _count = 0
    axis = np.array([0.0, 0.0, 1.0])  # its travel dz is along z (placement.py turns and moves it)

    def __init__(self, model: str, translation=(0.0, 0.0, 0.0), normals: str = "outward"):
        if normals not in NORMALS:
            raise ValueError(f"normals must be one of {NORMALS}, got {normals!r}")
        self.model, self.sign = model, 1.0 if normals == "outward" else -1.0
        self.translation = np.asarray(translation, dtype=float).reshape(3)
        with _Current(model) as gmsh:
            self.faces = [t for _, t in gmsh.model.getEntities(2)]
            self.edges = [t for _, t in gmsh.model.getEntities(1) if not _degenerate(gmsh, t)]
            if not self.faces:
                raise ValueError("the model holds no surface")
            self._face_adjacent = {e: sorted(set(int(f) for f in gmsh.model.getAdjacencies(1, e)[0]))
                                   for e in self.edges}
            self._setup(gmsh)
            self._last = None  # the last call's points and their closest points (_Projections)
            self.counts = {"repeated": 0, "exact": 0, "warm": 0, "searched": 0}  # points answered each way, all calls
            self._index = {de: k for k, de in enumerate(self._ents)}
            self._is_face = np.array([d == 2 for d, _ in self._ents])
            self._face_edges = {self._index[(2, f)]: np.array([self._index[(1, abs(int(e)))]
                                                               for e in gmsh.model.getAdjacencies(2, f)[1]
                                                               if (1, abs(int(e))) in self._index], dtype=int)
                                for f in self.faces}

    # -- construction ------------------------------------------------------------------------
    @classmethod
    def _new_model(cls):
        gmsh = _gmsh()
        cls._count += 1
        name = f"shellform_tool_{cls._count}"
        previous = gmsh.model.getCurrent()
        gmsh.model.add(name)
        return gmsh, name, previous

    @classmethod
    def from_builder(cls, build, translation=(0.0, 0.0, 0.0), normals: str = "outward") -> "SurfaceTool":
        """The tool that build(gmsh) makes with gmsh.model.occ in a fresh model (it need not
        synchronize)."""
        gmsh, name, previous = cls._new_model()
        try:
            build(gmsh)
            gmsh.model.occ.synchronize()
        finally:
            if previous:
                gmsh.model.setCurrent(previous)
        return cls(name, translation, normals)

    @classmethod
    def from_file(cls, path, translation=(0.0, 0.0, 0.0), normals: str = "outward",
                  field: str = "tools.file") -> "SurfaceTool":
        """The tool of a STEP, IGES or BREP file (a bad file: InputError naming `field`)."""
        path = Path(path)
        probe(path, field)
        gmsh, name, previous = cls._new_model()
        try:
            gmsh.option.setString("Geometry.OCCTargetUnit", "MM")
            gmsh.model.occ.importShapes(str(path))
            gmsh.model.occ.synchronize()
        except Exception as exc:  # noqa: BLE001  (gmsh raises plain Exceptions)
            raise InputError(field, f"gmsh cannot read {path}: {exc}") from None
        finally:
            if previous:
                gmsh.model.setCurrent(previous)
        try:
            return cls(name, translation, normals)
        except ValueError as exc:
            raise InputError(field, f"{path}: {exc}") from None

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
        self._bounds, self._filled, self._trims, self._flat, self._orient = {}, {}, {}, set(), {}
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
            points.append(xyz)
            owner.append(np.full(len(xyz), k))
            params.append(uv)
        from scipy.spatial import cKDTree

        self._tree = cKDTree(np.vstack(points))
        self._sample_entity, self._sample_param = np.concatenate(owner), np.vstack(params)
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

    # -- evaluation --------------------------------------------------------------------------
    def closest(self, x, dz: float = 0.0):
        """For points x (n, 3): the closest surface points c (placed), the signed distances d,
        the normals n, and per point the entity (dim, tag) it lies on with its parametric
        coordinates (a face: (u, v); an edge: (t, 0)).

        The last call's points are remembered with their closest points (_Projections): a point
        given again (in the model's frame: the same x and dz) takes its last answer; a point
        near a remembered one starts from that one's face and parameters (_warm); the others
        are searched (_search)."""
        return self._closest(x, dz)[:5]

    def _closest(self, x, dz):
        """closest's answers, and where the closest point was found by Newton on a face (has)
        the face's derivatives there (J, S: _Projections)."""
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        shift = self.translation + np.array([0.0, 0.0, dz])
        y = x - shift  # in the model's frame
        npts = len(y)
        last = self._last if npts else None
        if last is not None:
            ref, delta = last.nearest(y)
            if not delta.any():  # every point given again: the remembered points stay
                self.counts["repeated"] += npts
                return (last.c[ref] + shift, last.d[ref], last.n[ref], last.ent[ref], last.par[ref], last.J[ref],
                        last.S[ref], last.has[ref])
        c, dist, ent, par = np.zeros_like(y), np.full(npts, np.inf), np.full(npts, -1), np.zeros((npts, 2))
        d, n, bound = np.zeros(npts), np.zeros((npts, 3)), np.zeros((npts, len(self._ents)))
        J, S, has = np.zeros((npts, 2, 3)), np.zeros((npts, 3, 3)), np.zeros(npts, dtype=bool)
        todo = np.ones(npts, dtype=bool)
        if last is not None:
            same = np.flatnonzero(delta == 0.0)
            r = ref[same]
            c[same], dist[same], ent[same], par[same] = last.c[r], last.dist[r], last.ent[r], last.par[r]
            d[same], n[same], bound[same] = last.d[r], last.n[r], last.bound[r]
            J[same], S[same], has[same] = last.J[r], last.S[r], last.has[r]
            todo[same] = False
            self.counts["repeated"] += same.size
        with _Current(self.model) as gmsh:
            m = gmsh.model
            new = np.flatnonzero(todo)
            if new.size and self._exact_faces.any():
                upper = last.dist[ref[new]] + delta[new] if last is not None else self._tree.query(y[new])[0]
                out = self._exact(m, y[new], upper)
                found = out[-1]
                rows = new[found]
                c[rows], dist[rows], ent[rows], par[rows], J[rows], S[rows] = (v[found] for v in out[:6])
                has[rows], bound[rows] = True, np.nan  # their bounds computed where asked (_remembered_bounds)
                todo[rows] = False
                self.counts["exact"] += rows.size
            if last is not None:
                warm = np.flatnonzero(todo & self._is_face[np.maximum(last.ent[ref], 0)] & (last.ent[ref] >= 0))
                if warm.size:
                    sure = self._warm(m, y, warm, last, ref[warm], delta[warm], (c, dist, ent, par, bound, J, S, has))
                    todo[warm[sure]] = False
                    self.counts["warm"] += int(sure.sum())
            rest = np.flatnonzero(todo)
            self.counts["searched"] += rest.size
            if rest.size:
                c[rest], dist[rest], ent[rest], par[rest], bound[rest] = self._search(m, y[rest])
            d[new], n[new] = self._signed(gmsh, y[new], c[new], dist[new], ent[new], par[new], J[new], has[new])
        if npts:
            self._last = _Projections(y, c, dist, d, n, ent, par, bound, J, S, has)
        return c + shift, d.copy(), n.copy(), ent.copy(), par.copy(), J, S, has

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
        bound = last.bound[ref]
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

    def _search(self, m, y):
        """Closest points: first the local projection from the nearest sample (_local), where
        it is sure; the other points by the candidates' projections (_candidates). Also returns
        lower bounds of every point's distance to every entity (points, entities): the bounding
        boxes', raised to a face's projection distance onto its untrimmed surface (an edge's onto
        its curve) where one was computed, and to the distance found on its face (and its
        edges) where the local projection converged inside it."""
        upper, sample = self._tree.query(y)
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
        k0 = self._sample_entity[sample]
        on_face = self._is_face[k0]
        pts, ks, uvs = [np.flatnonzero(on_face)], [k0[on_face]], [self._sample_param[sample[on_face]]]
        for k in np.unique(k0[~on_face]):
            e = self._ents[k][1]
            i = np.flatnonzero(k0 == k)
            t = self._sample_param[sample[i], 0]
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
        ks = last.ent[ref]
        uvs = last.par[ref].copy()
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

    def _candidates(self, m, y, upper, lower, seed, bound):
        """The nearest of every entity's projection whose bounding box lies within `upper`, and
        of the seed (c, dist, entity, parameters: the local projection's point, entity -1 where
        there is none). Raises `bound` to each projection's distance (onto the untrimmed
        surface, the edge's curve unclamped, a straight edge's clamped: lower bounds of the
        distance to the entity), and a face's whose projection falls outside it to the least of
        its edges' bounds."""
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
            c, p = m.getClosestPoint(d, t, y[idx].ravel())
            c = np.asarray(c).reshape(-1, 3)
            bound[idx, k] = np.maximum(bound[idx, k], np.linalg.norm(y[idx] - c, axis=1))
            if d == 1:
                p = np.asarray(p, dtype=float)
                q = np.clip(p, b0[0], b1[0])
                moved = q != p
                if moved.any():
                    c[moved] = np.asarray(m.getValue(1, t, q[moved])).reshape(-1, 3)
                P[idx, k, 0] = q
                if (d, t) in self._flat:  # a segment's nearest point: the line's, clamped
                    bound[idx, k] = np.maximum(bound[idx, k], np.linalg.norm(y[idx] - c, axis=1))
            else:
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

    def _signed(self, gmsh, y, c, dist, ent, par, J, has):
        """Signed distances and normals (module docstring); on a face the normal X_u x X_v
        turned by the face's orientation where its derivatives J are at hand (has), else
        gmsh's."""
        m = gmsh.model
        n = np.zeros((len(y), 3))
        d = dist.copy()
        rows = np.flatnonzero(has)
        if rows.size:
            cross = faces_cross(J[rows, 0], J[rows, 1])
            n[rows] = (self.sign * self._orientation[ent[rows]] / np.linalg.norm(cross, axis=1))[:, None] * cross
            d[rows] = np.einsum("ij,ij->i", y[rows] - c[rows], n[rows])
        for k in np.unique(ent[~has]) if not has.all() else ():
            dim, t = self._ents[k]
            rows = np.flatnonzero((ent == k) & ~has)
            if dim == 2:
                nc = self.sign * np.asarray(m.getNormal(t, par[rows].ravel())).reshape(-1, 3)
                n[rows] = nc
                d[rows] = np.einsum("ij,ij->i", y[rows] - c[rows], nc)
            else:
                mean = self._edge_faces_normal(m, t, par[rows, 0])[0]
                v = y[rows] - c[rows]
                s = np.where(np.einsum("ij,ij->i", v, mean) < 0.0, -1.0, 1.0)
                d[rows] = s * dist[rows]
                far = dist[rows] > 1e-12 * self.size
                n[rows] = np.where(far[:, None], s[:, None] * v / np.where(far, dist[rows], 1.0)[:, None], mean)
        return d, n

    def _edge_faces_normal(self, m, e, t):
        """The mean of the (turned) normals of the faces meeting at edge e at its parameters t,
        normalised, and the faces' normals (faces, points, 3)."""
        normals = []
        for f in self._face_adjacent[e]:
            uv = np.asarray(m.reparametrizeOnSurface(1, e, t, f)).reshape(-1, 2)
            normals.append(self.sign * np.asarray(m.getNormal(f, uv.ravel())).reshape(-1, 3))
        normals = np.array(normals).reshape(-1, len(t), 3)
        mean = normals.sum(axis=0)
        mean /= np.maximum(np.linalg.norm(mean, axis=1), 1e-300)[:, None]
        return mean, normals

    def gap(self, x, offset=0.0, dz: float = 0.0):
        """Signed distance minus offset (> 0 clear) and unit normal from the tool towards x."""
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        _, d, n, _, _ = self.closest(x, dz)
        return d - np.broadcast_to(np.asarray(offset, dtype=float), d.shape), n + 0.0

    def shape(self, x, offset=0.0, dz: float = 0.0):
        """H = dn/dx (n, 3, 3) (module docstring): H0 (I + d H0)^-1 on a face, (I - n n^T -
        e e^T) / d beside a sharp edge."""
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        c, d, n, ent, par, J, S, has = self._closest(x, dz)
        H = np.zeros((len(x), 3, 3))
        if has.any():  # the derivatives of the Newton that found the point
            H[has] = distance_hessian(J[has], S[has], n[has], d[has])
        if has.all():
            return H + 0.0
        with _Current(self.model) as gmsh:
            m = gmsh.model
            for k in np.unique(ent[~has]):
                dim, t = self._ents[k]
                rows = np.flatnonzero((ent == k) & ~has)
                if dim == 2:
                    H[rows] = self._face_hessian(m, t, par[rows], n[rows], d[rows])
                    continue
                _, faces = self._edge_faces_normal(m, t, par[rows, 0])
                smooth = np.all(np.einsum("fpi,pi->fp", faces, faces[0]) > 1 - 1e-8, axis=0) if len(faces) else \
                    np.zeros(len(rows), dtype=bool)
                if smooth.any():  # a seam: the edge's first face
                    f = self._face_adjacent[t][0]
                    uv = np.asarray(m.reparametrizeOnSurface(1, t, par[rows[smooth], 0], f)).reshape(-1, 2)
                    H[rows[smooth]] = self._face_hessian(m, f, uv, n[rows[smooth]], d[rows[smooth]])
                sharp = rows[~smooth]
                if sharp.size:
                    e = np.asarray(m.getDerivative(1, t, par[sharp, 0])).reshape(-1, 3)
                    e /= np.linalg.norm(e, axis=1)[:, None]
                    dd = np.where(np.abs(d[sharp]) > 1e-12 * self.size, d[sharp], np.inf)
                    P = np.eye(3) - n[sharp, :, None] * n[sharp, None, :] - e[:, :, None] * e[:, None, :]
                    H[sharp] = P / dd[:, None, None]
        return H + 0.0

    def _face_hessian(self, m, f, uv, n, d):
        """H0 (I + d H0)^-1 at the face's parameters uv, n the (turned) normals, d the distances."""
        J = np.asarray(m.getDerivative(2, f, uv.ravel())).reshape(-1, 2, 3)  # rows X_u, X_v
        S = np.asarray(m.getSecondDerivative(2, f, uv.ravel())).reshape(-1, 3, 3)  # X_uu, X_vv, X_uv
        return distance_hessian(J, S, n, d)

    # -- the binder ----------------------------------------------------------------------------
    def flat_top_boundary(self, spacing: float = 0.25) -> list[np.ndarray]:
        """The boundary loops, in the model's frame ((m, 3) points every `spacing` mm or closer,
        each loop closed by its first point), of the highest planar face whose (turned) normal
        is +z: a die's flat top, on which the holder pinches the flange. Its loops bound the die's
        opening (the inner ones) and the die (the outer one)."""
        with _Current(self.model) as gmsh:
            m = gmsh.model
            top, height = None, -np.inf
            for f in self.faces:
                if m.getType(2, f) != "Plane":
                    continue
                b0, b1 = (np.asarray(v, dtype=float) for v in m.getParametrizationBounds(2, f))
                n = self.sign * np.asarray(m.getNormal(f, 0.5 * (b0 + b1)))
                z = m.getBoundingBox(2, f)[5]
                if n[2] > 1.0 - 1e-9 and z > height:
                    top, height = f, z
            if top is None:
                raise ValueError("the model has no flat face whose normal is +z (a die's flat top)")
            pieces = []
            for _, c in m.getBoundary([(2, top)], combined=False, oriented=False, recursive=False):
                c = abs(int(c))
                if _degenerate(gmsh, c):
                    continue
                t0, t1 = (float(np.ravel(v)[0]) for v in m.getParametrizationBounds(1, c))
                steps = max(int(np.ceil(_curve_length(m, c, t0, t1) / spacing)), 2)
                pieces.append(np.asarray(m.getValue(1, c, np.linspace(t0, t1, steps + 1))).reshape(-1, 3))
        return closed_loops(pieces, 1e-6 * self.size)


def _curve_length(m, c, t0, t1, n=64):
    x = np.asarray(m.getValue(1, c, np.linspace(t0, t1, n + 1))).reshape(-1, 3)
    return float(np.linalg.norm(np.diff(x, axis=0), axis=1).sum())
