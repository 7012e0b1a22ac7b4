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
                within the sampling's margin); an edge's nearest point, the nearer of OCC's
                projection onto it and its two ends, its parameter that of the point, not
                gmsh's (which reads 0 where OCC's projection succeeds). The nearest point of a
                face whose projection falls outside it lies on its boundary: an edge's.

A second, non-global minimum of the distance inside one face is not found by the gmsh steps
(the closed forms are global on their face).

Every point also gets lower bounds of its distance to every face and edge (the bounding
boxes', raised by the projections computed on the way, the closed forms' distances). The tool
remembers its last call's points with their closest points, the face's derivatives there and
these bounds (closest_point.Remembered; the bounds of points the exact pass answered computed where asked).
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
from shellform.tools.cad_model import _Current, _curve_length, _degenerate, _gmsh
from shellform.tools.cad_projections import CadProjections
from shellform.tools.closest_point import ClosestPointTool, Points
from shellform.tools.faces import cross as faces_cross
from shellform.tools.holder_edge import closed_loops
from shellform.tools.surface_geometry import distance_hessian
from shellform.errors import InputError


class SurfaceTool(CadProjections, ClosestPointTool):
    """A rigid tool: the faces of the OCC model `model` (a gmsh model's name), placed by
    `translation` (mm), its faces' normals pointing to the sheet (`normals` "outward") or away
    from it ("inward": turned). Build it with from_file or from_builder. Its closest points: the
    closest-point engine's flow (closest_point.py) over the passes of CadProjections (gmsh),
    CadExact (the closed forms) and the model of CadModel."""

    _count = 0
    COUNTS = ("repeated", "exact", "warm", "searched")
    BY_BYTES = True  # a point given again among other points is found by its coordinates' bytes

    def __init__(self, model: str, translation=(0.0, 0.0, 0.0), normals: str = "outward"):
        ClosestPointTool.__init__(self, translation, normals)
        self.model = model
        with _Current(model) as gmsh:
            self.faces = [t for _, t in gmsh.model.getEntities(2)]
            self.edges = [t for _, t in gmsh.model.getEntities(1) if not _degenerate(gmsh, t)]
            if not self.faces:
                raise ValueError("the model holds no surface")
            self._face_adjacent = {e: sorted(set(int(f) for f in gmsh.model.getAdjacencies(1, e)[0]))
                                   for e in self.edges}
            self._setup(gmsh)
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

    check_file = staticmethod(probe)  # the file's checks before it is read (cad.read_tool_file)

    @classmethod
    def from_file(cls, path, translation=(0.0, 0.0, 0.0), normals: str = "outward",
                  field: str = "tools.file") -> "SurfaceTool":
        """The tool of a STEP, IGES or BREP file (a bad file: InputError naming `field`)."""
        path = Path(path)
        cls.check_file(path, field)
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


    # -- the closest-point engine's hooks (closest_point.py) -----------------------------------
    def closest(self, x, dz: float = 0.0):
        """For points x (n, 3): the closest surface points c (placed), the signed distances d,
        the normals n, and per point the entity (dim, tag) it lies on with its parametric
        coordinates (a face: (u, v); an edge: (t, 0)).

        The last call's points are remembered with their closest points (closest_point.py): a
        point given again (in the model's frame: the same x and dz) takes its last answer; the
        others are answered in closed form (_exact), from a remembered neighbour's face and
        parameters (_warm) or searched (_search_samples)."""
        return super().closest(x, dz)

    def _closest_extra(self, p) -> tuple:
        return p.ent.copy(), p.par.copy()

    def _evaluating(self):
        return _Current(self.model)

    def _blank(self, npts) -> Points:
        """A call's arrays: closest points c, distances dist, signed distances d, normals n,
        entities (indices into _ents) and parameters, lower bounds of the distances to every
        entity (points, entities), and where the closest point was found by Newton on a face
        (has), the face's derivatives there (J: X_u, X_v; S: X_uu, X_vv, X_uv)."""
        return Points(c=np.zeros((npts, 3)), dist=np.full(npts, np.inf), ent=np.full(npts, -1),
                      par=np.zeros((npts, 2)), d=np.zeros(npts), n=np.zeros((npts, 3)),
                      bound=np.zeros((npts, len(self._ents))), J=np.zeros((npts, 2, 3)), S=np.zeros((npts, 3, 3)),
                      has=np.zeros(npts, dtype=bool))

    def _steps(self):
        return (("exact", self._exact_step), ("warm", self._warm_step))

    def _exact_step(self, y, todo, last, ref, delta, p):
        """The points the faces' closed forms answer (_exact), their upper bound the remembered
        neighbour's distance plus delta (a sample's on a first call)."""
        new = np.flatnonzero(todo)
        if not (new.size and self._exact_faces.any()):
            return new[:0]
        upper = last.points.dist[ref[new]] + delta[new] if last is not None else self._samples.query(y[new])[0]
        out = self._exact(_gmsh().model, y[new], upper)
        found = out[-1]
        rows = new[found]
        p.c[rows], p.dist[rows], p.ent[rows], p.par[rows], p.J[rows], p.S[rows] = (v[found] for v in out[:6])
        p.has[rows], p.bound[rows] = True, np.nan  # their bounds computed where asked (_remembered_bounds)
        return rows

    def _warm_step(self, y, todo, last, ref, delta, p):
        """The points whose remembered neighbour's closest point lay on a face (_warm)."""
        if last is None:
            return np.zeros(0, dtype=int)
        ent = last.points.ent[ref]
        warm = np.flatnonzero(todo & self._is_face[np.maximum(ent, 0)] & (ent >= 0))
        if not warm.size:
            return warm
        sure = self._warm(_gmsh().model, y, warm, last, ref[warm], delta[warm],
                          (p.c, p.dist, p.ent, p.par, p.bound, p.J, p.S, p.has))
        return warm[sure]

    def _search(self, y, rows, p):
        p.c[rows], p.dist[rows], p.ent[rows], p.par[rows], p.bound[rows] = self._search_samples(_gmsh().model, y[rows])

    def _signed(self, y, rows, p):
        p.d[rows], p.n[rows] = self._signed_distances(_gmsh(), y[rows], p.c[rows], p.dist[rows], p.ent[rows],
                                                      p.par[rows], p.J[rows], p.has[rows])

    def _signed_distances(self, gmsh, y, c, dist, ent, par, J, has):
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

    def _hessian(self, p):
        """H = dn/dx (n, 3, 3) (module docstring): H0 (I + d H0)^-1 on a face, (I - n n^T -
        e e^T) / d beside a sharp edge."""
        d, n, ent, par, J, S, has = p.d, p.n, p.ent, p.par, p.J, p.S, p.has
        H = np.zeros((len(d), 3, 3))
        if has.any():  # the derivatives of the Newton that found the point
            H[has] = distance_hessian(J[has], S[has], n[has], d[has])
        if has.all():
            return H
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
        return H

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

