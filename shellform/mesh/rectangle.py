"""Triangle meshes of the rectangular blank, and the distorted patch-test mesh.

The blank is centred at the origin. The square plate and shell-block examples of the paper mesh
one quarter of it (region "quarter", symmetry on x = 0 and y = 0); region "full" meshes all of it.
Exterior facets are tagged by side (SIDE_TAG) for boundary conditions.
"""

from contextlib import contextmanager
from dataclasses import dataclass
from numbers import Integral, Real

import numpy as np

import dolfinx.mesh
from shellform.errors import InputError
from shellform.mesh.budget import structured_ny

SIDES = ("left", "right", "bottom", "top")  # x = x_min, x = x_max, y = y_min, y = y_max
SIDE_TAG = {"left": 1, "right": 2, "bottom": 3, "top": 4}
REGIONS = ("full", "quarter")
KINDS = ("structured", "unstructured")
DIAGONALS = {
    "right": dolfinx.mesh.DiagonalType.right,
    "left": dolfinx.mesh.DiagonalType.left,
    "crossed": dolfinx.mesh.DiagonalType.crossed,
    "right/left": dolfinx.mesh.DiagonalType.right_left,
    "left/right": dolfinx.mesh.DiagonalType.left_right,
}


@dataclass
class RectangleMesh:
    """A mesh of the blank (or its quarter) with its boundary facets tagged by side."""

    mesh: dolfinx.mesh.Mesh
    facet_tags: dolfinx.mesh.MeshTags
    bounds: tuple[float, float, float, float]  # x_min, x_max, y_min, y_max


def _partitioner():
    return dolfinx.mesh.create_cell_partitioner(dolfinx.mesh.GhostMode.shared_facet, 2)


def _positive(field, value):
    bad = isinstance(value, bool) or not isinstance(value, Real)
    if bad or not np.isfinite(value) or value <= 0:
        raise InputError(field, f"must be a positive number, got {value!r}")
    return float(value)


def _check_points(points, bounds, tol):
    x0, x1, y0, y1 = bounds
    out = []
    for p in points:
        try:
            x, y = (float(c) for c in p)
        except (TypeError, ValueError):
            raise InputError("loads.points", f"a point must be a pair (x, y), got {p!r}") from None
        if not (x0 - tol <= x <= x1 + tol and y0 - tol <= y <= y1 + tol):
            raise InputError("loads.points", f"point ({x}, {y}) lies outside the region {bounds}")
        out.append((min(max(x, x0), x1), min(max(y, y0), y1)))
    return out


def rectangle(comm, lx, ly, region="full", kind="structured", n=8, diagonal="right", points=(), refine=0):
    """Mesh the lx x ly blank centred at the origin, or its quarter x, y >= 0, with triangles.

    kind "structured": n divisions along x and max(1, round(n ly/lx)) along y (for region "full"
    with even n the y count is made even too, so the centre (0, 0) is a vertex).
    kind "unstructured": gmsh Frontal-Delaunay triangles of size (region width)/n with the centre
    and every load point in `points` as mesh vertices. `points` must lie in the region.
    refine: uniform refinements (each triangle into four) after meshing: nested sequences of
    meshes, on which observed convergence rates are not blurred by mesh-to-mesh noise.
    """
    lx = _positive("geometry.lx", lx)
    ly = _positive("geometry.ly", ly)
    if region not in REGIONS:
        raise InputError("geometry.region", f"must be one of {REGIONS}, got {region!r}")
    if kind not in KINDS:
        raise InputError("mesh.kind", f"must be one of {KINDS}, got {kind!r}")
    if isinstance(n, bool) or not isinstance(n, Integral) or n < 1:
        raise InputError("mesh.n", f"must be an integer >= 1, got {n!r}")
    if not isinstance(diagonal, str) or diagonal not in DIAGONALS:
        raise InputError("mesh.diagonal", f"must be one of {tuple(DIAGONALS)}, got {diagonal!r}")
    if isinstance(refine, bool) or not isinstance(refine, Integral) or refine < 0:
        raise InputError("mesh.refine", f"must be an integer >= 0, got {refine!r}")
    n = int(n)
    if region == "full":
        bounds = (-lx / 2, lx / 2, -ly / 2, ly / 2)
    else:
        bounds = (0.0, lx / 2, 0.0, ly / 2)
    tol = 1e-10 * max(lx, ly)
    pts = _check_points(points, bounds, tol)

    if kind == "structured":
        ny = structured_ny(lx, ly, region, n)
        msh = dolfinx.mesh.create_rectangle(
            comm,
            [np.array(bounds[0::2]), np.array(bounds[1::2])],
            [n * 2**refine, ny * 2**refine],
            dolfinx.mesh.CellType.triangle,
            diagonal=DIAGONALS[diagonal],
        )
    else:
        msh = _gmsh_rectangle(comm, bounds, (bounds[1] - bounds[0]) / n, [(0.0, 0.0)] + pts, refine)
    return RectangleMesh(msh, _tag_sides(msh, bounds, tol), bounds)


def _tag_sides(msh, bounds, tol):
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    where = dict(zip(SIDES, [(0, bounds[0]), (0, bounds[1]), (1, bounds[2]), (1, bounds[3])]))
    facets, values = [], []
    for side in SIDES:
        axis, value = where[side]
        f = dolfinx.mesh.locate_entities_boundary(
            msh, tdim - 1, lambda x, a=axis, v=value: np.abs(x[a] - v) <= tol
        )
        facets.append(f)
        values.append(np.full(len(f), SIDE_TAG[side], dtype=np.int32))
    facets, values = np.concatenate(facets), np.concatenate(values)
    order = np.argsort(facets)
    return dolfinx.mesh.meshtags(msh, tdim - 1, facets[order].astype(np.int32), values[order])


_GMSH_OPTIONS = {
    "General.Terminal": 0,
    "General.Verbosity": 0,
    "General.NumThreads": 1,
    "Mesh.Algorithm": 6,  # Frontal-Delaunay
    "Mesh.RandomSeed": 1,
    "Mesh.ElementOrder": 1,
    "Mesh.RecombineAll": 0,
    "Mesh.MeshSizeFromCurvature": 0,
    "Mesh.MeshSizeExtendFromBoundary": 1,
    "Mesh.MeshSizeFromPoints": 1,
    "Mesh.MeshSizeMin": 0.0,
}


@contextmanager
def _gmsh_model():
    """A fresh gmsh model with shellform's options; restores gmsh's previous state afterwards."""
    import gmsh

    owner = not gmsh.isInitialized()
    if owner:
        gmsh.initialize(readConfigFiles=False, interruptible=False)
    saved = {k: gmsh.option.getNumber(k) for k in (*_GMSH_OPTIONS, "Mesh.MeshSizeMax")}
    previous = gmsh.model.getCurrent() if not owner else None
    try:
        for k, v in _GMSH_OPTIONS.items():
            gmsh.option.setNumber(k, v)
        gmsh.model.add("shellform_rectangle")
        yield gmsh
    finally:
        if owner:
            gmsh.finalize()
        else:
            gmsh.model.remove()
            if previous:
                gmsh.model.setCurrent(previous)
            for k, v in saved.items():
                gmsh.option.setNumber(k, v)


def _gmsh_rectangle(comm, bounds, h, points, refine=0):
    """Unstructured triangles of the rectangle `bounds`, size h, with `points` as vertices."""
    from dolfinx.io.gmsh import model_to_mesh

    x0, x1, y0, y1 = bounds
    root = 0
    session = _gmsh_model() if comm.rank == root else _nothing()
    with session as gmsh:
        error = None
        if comm.rank == root:
            try:
                occ = gmsh.model.occ
                surface = occ.addRectangle(x0, y0, 0.0, x1 - x0, y1 - y0)
                unique = sorted(set(points))
                occ.fragment([(2, surface)], [(0, occ.addPoint(x, y, 0.0)) for x, y in unique])
                occ.synchronize()
                surfaces = [tag for _, tag in gmsh.model.getEntities(2)]
                gmsh.model.addPhysicalGroup(2, surfaces, 1, name="blank")
                gmsh.option.setNumber("Mesh.MeshSizeMax", h)
                gmsh.model.mesh.setSize(gmsh.model.getEntities(0), h)
                gmsh.model.mesh.generate(2)
                for _ in range(refine):
                    gmsh.model.mesh.refine()
            except Exception as exc:  # noqa: BLE001  (re-raised on every rank below)
                error = f"gmsh failed to mesh the region {bounds}: {exc}"
        error = comm.bcast(error, root=root)
        if error:
            raise RuntimeError(error)
        model = gmsh.model if comm.rank == root else None
        data = model_to_mesh(model, comm, root, gdim=2, partitioner=_partitioner())
    return data.mesh


@contextmanager
def _nothing():
    yield None


_PATCH_VERTICES = np.array(
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0],
     [0.20, 0.24], [0.78, 0.15], [0.62, 0.77], [0.27, 0.63]]
)  # fmt: skip
_PATCH_CELLS = np.array(
    [[0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [2, 3, 6],
     [3, 7, 6], [3, 0, 7], [0, 4, 7], [4, 5, 7], [5, 6, 7]]
)  # fmt: skip


def distorted_patch(comm):
    """The patch-test mesh: 10 triangles on [0, 1]^2 with 4 irregular interior vertices.

    No two interior edges are parallel to each other or to a side, so a passed patch test is
    not an artefact of a regular mesh.
    """
    import basix.ufl
    import ufl

    domain = ufl.Mesh(basix.ufl.element("Lagrange", "triangle", 1, shape=(2,)))
    if comm.rank == 0:
        cells, x = _PATCH_CELLS.astype(np.int64), _PATCH_VERTICES.copy()
    else:
        cells, x = np.empty((0, 3), dtype=np.int64), np.empty((0, 2))
    partitioner = _partitioner() if comm.size > 1 else None
    return dolfinx.mesh.create_mesh(comm, cells, domain, x, partitioner)
