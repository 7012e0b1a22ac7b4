"""Triangle meshes of the rectangular blank, and the distorted patch-test mesh.

The blank is centred at the origin. The square plate and shell-block examples of the paper mesh
one quarter of it (region "quarter", symmetry on x = 0 and y = 0); region "full" meshes all of it.
Exterior facets are tagged by side (SIDE_TAG) for boundary conditions.
"""

from numbers import Integral, Real

import numpy as np

import dolfinx.mesh
from shellform.errors import InputError
from shellform.mesh.blank_mesh import BlankMesh
from shellform.mesh.budget import structured_ny
from shellform.mesh.gmsh_model import mesh_on_root, partitioner

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
    return BlankMesh(msh, _tag_sides(msh, bounds, tol), bounds, dict(SIDE_TAG))


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


def _gmsh_rectangle(comm, bounds, h, points, refine=0):
    """Unstructured triangles of the rectangle `bounds`, size h, with `points` as vertices."""
    x0, x1, y0, y1 = bounds

    def build(gmsh):
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

    return mesh_on_root(comm, build, f"the region {bounds}").mesh


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
    return dolfinx.mesh.create_mesh(comm, cells, domain, x, partitioner() if comm.size > 1 else None)
