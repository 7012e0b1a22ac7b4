"""Blanks of any outline: a circle, a polygon, or a gmsh geometry or mesh file, meshed by gmsh
into triangles whose boundary facets are tagged by named group.

Group names (the keys of [supports]):
    rectangle  left, right, bottom, top (shellform.mesh.rectangle)
    circle     rim; with region "half" (y >= 0) also bottom; "quarter" (x, y >= 0) left and bottom
    polygon    one name per edge (geometry.edges; default edge1, edge2, ...: edge i joins
               vertex i to vertex i + 1); edges that share a name form one group
    file       the file's named physical curves; a file without any: one group, boundary
Mesh size: h = (width of the region along x) / mesh.n, as for the unstructured rectangle; a .msh
file is read as it is, a .geo or CAD file is meshed with its own sizes capped at h.
"""

import functools
import math
from pathlib import Path

import numpy as np
from mpi4py import MPI

import dolfinx.mesh
from shellform.errors import InputError
from shellform.mesh.blank_mesh import BlankMesh
from shellform.mesh import gmsh_file, quality
from shellform.mesh.gmsh_model import OPTIONS, mesh_on_root
from shellform.mesh.rectangle import rectangle

SHAPES = ("rectangle", "circle", "polygon", "file")
CIRCLE_GROUPS = {"full": ("rim",), "half": ("rim", "bottom"), "quarter": ("rim", "left", "bottom")}
FILE_SUFFIXES = (".msh", ".geo", ".step", ".stp", ".brep")
TRIANGLE = 2  # gmsh's element type of the 3-node triangle


def polygon_edge_names(vertices, edges) -> list[str]:
    return list(edges) if edges else [f"edge{i + 1}" for i in range(len(vertices))]


def group_names(g) -> tuple[str, ...]:
    """The boundary groups of a [geometry] section, known before any mesh is built."""
    if g.shape == "rectangle":
        return ("left", "right", "bottom", "top")
    if g.shape == "circle":
        return CIRCLE_GROUPS[g.region]
    if g.shape == "polygon":
        return tuple(dict.fromkeys(polygon_edge_names(g.vertices, g.edges)))
    return _read_file(g.file, gmsh_file.check(g.file))[0]


# the mirror lines a quarter or half region is named by, x = 0 and y = 0: their planes' unit normals
MIRROR_NORMALS = {"left": (1.0, 0.0, 0.0), "bottom": (0.0, 1.0, 0.0)}


def symmetry_lines(g) -> tuple[str, ...]:
    """The groups of a [geometry] section on the mirror lines of a region that is part of the
    blank: x = 0 and y = 0 of a quarter (left, bottom), y = 0 of a half (bottom). None for a
    full region, a polygon or a file: their symmetry lines are the groups the scene declares."""
    if g.shape == "rectangle":
        return ("left", "bottom") if g.region == "quarter" else ()
    if g.shape == "circle":
        return {"full": (), "half": ("bottom",), "quarter": ("left", "bottom")}.get(g.region, ())
    return ()


def file_cells(g, n: int, refine: int) -> int:
    """Triangles a file blank makes: those of its mesh (a .msh), or a gmsh estimate from its
    bounding box at h = width / n or the file's own size where that is smaller (the median
    segment gmsh makes of its curves: a .geo or CAD file), times 4^refine."""
    from shellform.mesh.budget import gmsh_cells

    _, triangles, (width, height), segment = _read_file(g.file, gmsh_file.check(g.file))
    if triangles:
        return triangles * 4**refine
    return gmsh_cells(width * height, min(width / n, segment or math.inf), refine)


def file_own_size(g, n: int) -> float | None:
    """The size a file blank's own mesh sizes give where they, not mesh.n, set its cells (a .geo
    or CAD file whose curves gmsh meshes finer than width / n: their median segment); else None."""
    _, triangles, (width, _), segment = _read_file(g.file, gmsh_file.check(g.file))
    return segment if not triangles and segment is not None and segment < width / n else None


@functools.lru_cache(maxsize=8)
def _read_file(path, version) -> tuple[tuple[str, ...], int, tuple[float, float]]:
    """(boundary groups, triangles in its mesh (0: none yet), bounding box width and height,
    the median segment at the file's own sizes) of a gmsh file (gmsh_file.read_file), read once
    per version of the files gmsh reads for it (gmsh_file.check), in a child process with a time
    limit."""
    return gmsh_file.read_file(path, OPTIONS)


def _named_curves(gmsh) -> list[tuple[int, str]]:
    return [(tag, gmsh.model.getPhysicalName(1, tag) or f"group{tag}")
            for _, tag in gmsh.model.getPhysicalGroups(1)]


def region_bounds(g) -> tuple[float, float, float, float]:
    """x_min, x_max, y_min, y_max of the meshed region of a circle or polygon."""
    if g.shape == "circle":
        R = g.radius
        return {"full": (-R, R, -R, R), "half": (-R, R, 0.0, R), "quarter": (0.0, R, 0.0, R)}[g.region]
    v = np.asarray(g.vertices, dtype=float)
    return (v[:, 0].min(), v[:, 0].max(), v[:, 1].min(), v[:, 1].max())


def region_area(g) -> float:
    if g.shape == "circle":
        return math.pi * g.radius**2 / {"full": 1, "half": 2, "quarter": 4}[g.region]
    return _shoelace(np.asarray(g.vertices, dtype=float))


def polygon_problem(vertices) -> str | None:
    """Why these vertices make no simple polygon (None: they do)."""
    v = np.asarray(vertices, dtype=float)
    n = len(v)
    if n < 3:
        return f"needs at least 3 vertices, got {n}"
    scale = np.ptp(v, axis=0).max()
    if _shoelace(v) <= 1e-12 * scale**2:
        return "the polygon has no area"
    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    for i in range(n):
        a, b = v[i], v[(i + 1) % n]
        if np.hypot(*(b - a)) <= 1e-12 * scale:
            return f"vertices {i} and {(i + 1) % n} coincide"
        for j in range(i + 2, n):
            if (j + 1) % n == i:
                continue
            c, d = v[j], v[(j + 1) % n]
            if (cross(a, b, c) * cross(a, b, d) < 0) and (cross(c, d, a) * cross(c, d, b) < 0):
                return f"edge {i + 1} crosses edge {j + 1}: the outline must not intersect itself"
    for k in range(n):  # a vertex on an edge it does not end: the outline touches itself
        for i in range(n):
            if k in (i, (i + 1) % n):
                continue
            a, b = v[i], v[(i + 1) % n]
            t = np.clip(np.dot(v[k] - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
            if np.hypot(*(a + t * (b - a) - v[k])) <= 1e-9 * scale:
                return (f"vertex {k} {tuple(map(float, v[k]))} lies on edge {i + 1} (vertices {i} to {(i + 1) % n}): "
                        "the outline must not touch itself")
    return None


def _shoelace(v) -> float:
    return 0.5 * abs(np.dot(v[:, 0], np.roll(v[:, 1], -1)) - np.dot(v[:, 1], np.roll(v[:, 0], -1)))


# -- meshing ---------------------------------------------------------------------------------
def circle(comm, radius, region="full", n=8, points=(), refine=0) -> BlankMesh:
    """The disc of that radius centred at the origin, or its half y >= 0 or quarter x, y >= 0."""
    R = float(radius)
    h = (R if region == "quarter" else 2 * R) / n
    names = CIRCLE_GROUPS[region]

    def build(gmsh):
        geo = gmsh.model.geo
        p = lambda x, y: geo.addPoint(x, y, 0.0, h)  # noqa: E731
        c = p(0.0, 0.0)
        ends = {"full": [(R, 0), (0, R), (-R, 0), (0, -R), (R, 0)], "half": [(R, 0), (0, R), (-R, 0)],
                "quarter": [(R, 0), (0, R)]}[region]
        tags = [p(*ends[0])]
        for e in ends[1:]:
            tags.append(tags[0] if e == ends[0] else p(*e))
        rim = [geo.addCircleArc(a, c, b) for a, b in zip(tags[:-1], tags[1:])]
        lines = {}
        if region == "half":
            lines["bottom"] = [geo.addLine(tags[-1], c), geo.addLine(c, tags[0])]
        elif region == "quarter":
            lines["left"], lines["bottom"] = [geo.addLine(tags[-1], c)], [geo.addLine(c, tags[0])]
        loop = rim + lines.get("left", []) + lines.get("bottom", [])
        surface = geo.addPlaneSurface([geo.addCurveLoop(loop)])
        inside = [(x, y) for x, y in points if math.hypot(x, y) < R * (1 - 1e-9) and
                  (region == "full" or y > 1e-9 * R) and (region != "quarter" or x > 1e-9 * R)]
        embedded = [p(x, y) for x, y in sorted(set(inside))]
        geo.synchronize()
        if region == "full":
            embedded.append(c)
        if embedded:
            gmsh.model.mesh.embed(0, embedded, 2, surface)
        gmsh.model.addPhysicalGroup(2, [surface], 100, name="blank")
        groups = {"rim": rim, **lines}
        for tag, name in enumerate(names, start=1):
            gmsh.model.addPhysicalGroup(1, groups[name], tag, name=name)
        _generate(gmsh, h, refine)

    data = mesh_on_root(comm, build, f"the circle of radius {R} ({region})")
    unit = lambda x, y: (x / np.hypot(x, y), y / np.hypot(x, y))  # noqa: E731
    return _blank(data, names, normals={"rim": unit})


def polygon(comm, vertices, edges=(), n=8, points=(), refine=0) -> BlankMesh:
    """The polygon with these vertices (in order around it); edge i joins vertex i to i + 1."""
    v = [tuple(map(float, p)) for p in vertices]
    names = polygon_edge_names(v, edges)
    unique = list(dict.fromkeys(names))
    h = (max(x for x, _ in v) - min(x for x, _ in v)) / n
    ring = np.asarray(v)

    def build(gmsh):
        geo = gmsh.model.geo
        pts = [geo.addPoint(x, y, 0.0, h) for x, y in v]
        lines = [geo.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
        surface = geo.addPlaneSurface([geo.addCurveLoop(lines)])
        inside = [q for q in sorted(set([(0.0, 0.0), *points])) if _strictly_inside(q, ring, h)]
        embedded = [geo.addPoint(x, y, 0.0, h) for x, y in inside]
        geo.synchronize()
        if embedded:
            gmsh.model.mesh.embed(0, embedded, 2, surface)
        gmsh.model.addPhysicalGroup(2, [surface], 100, name="blank")
        for tag, name in enumerate(unique, start=1):
            gmsh.model.addPhysicalGroup(1, [lines[i] for i, m in enumerate(names) if m == name], tag, name=name)
        _generate(gmsh, h, refine)

    return _blank(mesh_on_root(comm, build, f"the polygon {v}"), unique)


def _strictly_inside(q, ring, h) -> bool:
    """Point q inside the polygon ring, farther than h/100 from its edges."""
    x, y = q
    a, b = ring, np.roll(ring, -1, axis=0)
    t = np.clip(((x - a[:, 0]) * (b[:, 0] - a[:, 0]) + (y - a[:, 1]) * (b[:, 1] - a[:, 1]))
                / np.sum((b - a) ** 2, axis=1), 0, 1)
    dist = np.hypot(a[:, 0] + t * (b[:, 0] - a[:, 0]) - x, a[:, 1] + t * (b[:, 1] - a[:, 1]) - y).min()
    crossings = ((a[:, 1] > y) != (b[:, 1] > y)) & (
        x < a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / np.where(b[:, 1] != a[:, 1], b[:, 1] - a[:, 1], 1))
    return bool(np.count_nonzero(crossings) % 2) and dist > h / 100


def from_file(comm, path, n=8, refine=0) -> BlankMesh:
    """The blank of a gmsh file: a .msh mesh read as it is, or a .geo / CAD geometry meshed here.
    Its triangles must lie in the plane z = 0; its named physical curves are the groups."""
    path = Path(path)
    state = {}

    def build(gmsh):
        gmsh_file.check(path)  # what the file may do, again just before gmsh reads it
        gmsh.open(str(path))
        if not gmsh.model.mesh.getNodes(2, includeBoundary=True)[0].size:
            xmin, _, _, xmax, _, _ = gmsh.model.getBoundingBox(-1, -1)
            _generate(gmsh, (xmax - xmin) / n, 0)
        kinds = set()
        for dim, tag in gmsh.model.getEntities(2):
            kinds.update(int(t) for t in gmsh.model.mesh.getElementTypes(dim, tag))
        if not kinds:
            raise InputError("geometry.file", f"{path} holds no surface mesh (2D triangles)")
        if kinds != {TRIANGLE}:
            other = ", ".join(gmsh.model.mesh.getElementProperties(k)[0] for k in sorted(kinds - {TRIANGLE}))
            raise InputError("geometry.file", f"{path} holds {other}: shellform needs linear triangles only")
        _check_triangles(gmsh, path)
        z = gmsh.model.mesh.getNodes()[1].reshape(-1, 3)[:, 2]
        if np.abs(z).max(initial=0.0) > 1e-9:
            raise InputError("geometry.file", f"{path}: the blank must lie in the plane z = 0 "
                             f"(a node has z = {z[np.argmax(np.abs(z))]:.3g})")
        for _ in range(refine):
            gmsh.model.mesh.refine()
        if not gmsh.model.getPhysicalGroups(2):
            gmsh.model.addPhysicalGroup(2, [t for _, t in gmsh.model.getEntities(2)], name="blank")
        state["curves"] = _named_curves(gmsh)

    data = mesh_on_root(comm, build, str(path))
    curves = comm.bcast(state.get("curves"), root=0)
    if not curves:  # no named curves: the whole boundary is one group
        return _whole_boundary(data.mesh)
    return _blank(data, [name for _, name in curves], tags={name: tag for tag, name in curves})


def _check_triangles(gmsh, path):
    """shellform.mesh.quality.check of the triangles DOLFINx gets: those of the file's physical
    surfaces, or of all its surfaces where it names none."""
    named = [e for _, g in gmsh.model.getPhysicalGroups(2) for e in gmsh.model.getEntitiesForPhysicalGroup(2, g)]
    entities = sorted(set(named)) if named else [t for _, t in gmsh.model.getEntities(2)]
    blocks = [gmsh.model.mesh.getElementsByType(TRIANGLE, e) for e in entities]
    cells = np.concatenate([np.zeros(0, dtype=np.uint64)] + [c for c, _ in blocks])
    nodes = np.concatenate([np.zeros(0, dtype=np.uint64)] + [v for _, v in blocks])
    tags, x, _ = gmsh.model.mesh.getNodes()
    order = np.argsort(tags)
    index = order[np.searchsorted(tags, nodes, sorter=order)] if nodes.size else nodes
    quality.check(x.reshape(-1, 3), index.reshape(-1, 3), cells, tags, source=str(path))


def _generate(gmsh, h, refine):
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    gmsh.model.mesh.generate(2)
    for _ in range(refine):
        gmsh.model.mesh.refine()


def _bounds(msh):
    x = msh.geometry.x
    lo, hi = x[:, :2].min(axis=0, initial=np.inf), x[:, :2].max(axis=0, initial=-np.inf)
    msh.comm.Allreduce(MPI.IN_PLACE, lo, op=MPI.MIN)
    msh.comm.Allreduce(MPI.IN_PLACE, hi, op=MPI.MAX)
    return (float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]))


def _blank(data, names, normals=None, tags=None) -> BlankMesh:
    groups = {name: (tags[name] if tags else i) for i, name in enumerate(names, start=1)}
    return BlankMesh(data.mesh, data.facet_tags, _bounds(data.mesh), groups, normals or {})


def _whole_boundary(msh) -> BlankMesh:
    msh.topology.create_connectivity(1, 2)
    facets = dolfinx.mesh.exterior_facet_indices(msh.topology)
    tags = dolfinx.mesh.meshtags(msh, 1, facets.astype(np.int32), np.full(len(facets), 1, dtype=np.int32))
    return BlankMesh(msh, tags, _bounds(msh), {"boundary": 1})


def blank(comm, scene, points=()) -> BlankMesh:
    """The mesh of a scene's blank (its [geometry] and [mesh]), with `points` as vertices where
    the outline allows; symmetry lines are checked to be straight, with the blank on one side."""
    from shellform.edge_frames import check_symmetry_lines  # PETSc: not at the scene's import

    g, m = scene.geometry, scene.mesh
    if g.shape == "rectangle":
        out = rectangle(comm, g.lx, g.ly, region=g.region, kind=m.kind, n=m.n, diagonal=m.diagonal,
                        points=points, refine=m.refine)
    elif g.shape == "circle":
        out = circle(comm, g.radius, g.region, m.n, points, m.refine)
    elif g.shape == "polygon":
        out = polygon(comm, g.vertices, g.edges, m.n, points, m.refine)
    else:
        out = from_file(comm, g.file, m.n, m.refine)
    check_symmetry_lines(out, scene.supports)
    _check_fields_finite(out.mesh, scene)
    return out


def _check_fields_finite(msh, scene) -> None:
    """The scene's fields given as text are finite on its mesh, before any form takes them: z0 of
    a curved scene with its first and second derivatives (sqrt(x) on a blank with x < 0 would fail
    in the linear solve), and the pressure's shape."""
    from shellform.forms.plan_field import PlanField
    from shellform.forms.reference_surface import ReferenceSurface

    fields, surface = [], scene.curvature()
    if isinstance(surface, ReferenceSurface):
        fields.append((surface, "surface.z0"))
    if scene.loads.pressure_shape:
        fields.append((PlanField(scene.loads.pressure_shape), "loads.pressure_shape"))
    for field, key in fields:
        bad = field.nonfinite_point(msh)
        if bad is not None:
            what, (x, y) = bad
            raise InputError(key, f"{field.quoted()}: {what} not finite at ({x:.6g}, {y:.6g}) of the blank's mesh")
