"""Tools from surface meshes (shellform/tools/mesh_tool.py): Nagata patches of a triangulated
sphere against the exact sphere at two mesh sizes (the errors fall at the patches' order), the
NUMISHEET'93 punch meshed by gmsh and written as STL against the analytic punch, the reading of
STL and .msh files and its errors, and the scene's dispatch of .stl files to a MeshTool."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from shellform import scene
from shellform.tools.cad import cad_cup_tools
from shellform.tools.mesh_tool import MeshTool, nagata_patches, read_surface_mesh
from shellform.tools.square import square_cup_tools
from shellform.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
SCENE = scene.load(ROOT / "demos" / "numisheet93_aluminium.toml")
T = SCENE.material.thickness
RNG = np.random.default_rng(36)
R = 10.0  # the sphere's radius, mm


def icosphere(level, radius=R):
    """An icosahedron's triangles subdivided `level` times, its vertices on the sphere (outward)."""
    p = (1 + 5 ** 0.5) / 2
    V = np.array([[-1, p, 0], [1, p, 0], [-1, -p, 0], [1, -p, 0], [0, -1, p], [0, 1, p], [0, -1, -p], [0, 1, -p],
                  [p, 0, -1], [p, 0, 1], [-p, 0, -1], [-p, 0, 1]], float)
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
                  [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
                  [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    V /= np.linalg.norm(V, axis=1)[:, None]
    for _ in range(level):
        edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        unique, inverse = np.unique(edges, axis=0, return_inverse=True)
        mid = V[unique].mean(axis=1)
        mid /= np.linalg.norm(mid, axis=1)[:, None]
        m = inverse.reshape(3, -1).T + len(V)
        V = np.vstack([V, mid])
        (a, b, c), (ab, bc, ca) = F.T, m.T
        F = np.vstack([np.c_[a, ab, ca], np.c_[b, bc, ab], np.c_[c, ca, bc], np.c_[ab, bc, ca]])
    return V * radius, F


def write_stl(path, vertices, triangles):
    """A binary STL of the triangles."""
    x = vertices[triangles].astype("<f4")
    rows = np.zeros(len(triangles), dtype=np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)),
                                                     ("attribute", "<u2")]))
    rows["corners"] = x
    with open(path, "wb") as f:
        f.write(b"shellform test".ljust(80, b" "))
        f.write(np.uint32(len(triangles)).tobytes())
        f.write(rows.tobytes())


def _sphere_errors(level, x):
    """The largest errors of gap, normal and H (H at the 95th percentile: beside an edge where the
    two patches' normals part, H is the edge curve's, 1/d across it) against the sphere."""
    V, F = icosphere(level)
    tool = MeshTool.from_triangles(V, F)
    g, n = tool.gap(x, 0.5)
    H = tool.shape(x, 0.5)
    r = np.linalg.norm(x, axis=1)
    n0 = x / r[:, None]
    H0 = (np.eye(3) - n0[:, :, None] * n0[:, None, :]) / r[:, None, None]
    h = float(np.linalg.norm(V[F[:, 1]] - V[F[:, 0]], axis=1).max())
    return h, np.abs(g - (r - R - 0.5)).max(), np.abs(n - n0).max(), np.percentile(np.abs(H - H0).max(axis=(1, 2)), 95)


def test_a_sphere_s_errors_fall_at_the_patches_order():
    """An icosphere of radius 10 mm at 1,280 and 5,120 triangles (largest edge 1.65 and 0.83 mm):
    at 2,000 random points from 2 mm inside to 4 mm outside, the gap's error falls as h^4 and the
    normal's as h^3 (the vertex normals, Max's weights, are exact on a sphere; measured: 5.3e-5 ->
    3.3e-6 mm, 3.3e-4 -> 4.4e-5) and H's (95th percentile) as h^2 or faster; the patches' normals
    across an edge part by an angle that falls as h^3."""
    x = RNG.normal(size=(2000, 3))
    x *= (R + RNG.uniform(-2.0, 4.0, 2000))[:, None] / np.linalg.norm(x, axis=1)[:, None]
    (h1, g1, n1, H1), (h2, g2, n2, H2) = _sphere_errors(3, x), _sphere_errors(4, x)
    order = np.log(h1 / h2)
    assert g2 < 1e-5 and n2 < 1e-4 and H2 < 1e-3
    assert 3.5 < np.log(g1 / g2) / order < 4.5
    assert 2.5 < np.log(n1 / n2) / order < 3.5
    assert np.log(H1 / H2) / order > 1.8
    jumps = [_edge_normal_jump(*icosphere(level)) for level in (3, 4)]
    assert jumps[1] < 2e-4 and 2.5 < np.log(jumps[0] / jumps[1]) / order < 3.5


def _edge_normal_jump(V, F):
    """The largest angle (rad) between the two patches' normals at points along their shared
    edges (the edges' quarter and middle points)."""
    A = nagata_patches(V, F)
    local = {(0, 1): (np.array([1.0, 0.0]), np.array([0.0, 0.0])),
             (1, 2): (np.array([-1.0, 1.0]), np.array([1.0, 0.0])),
             (0, 2): (np.array([0.0, 1.0]), np.array([0.0, 0.0]))}
    normals = {}
    for t, tri in enumerate(F):
        for (i, j), (direction, start) in local.items():
            a, b = tri[i], tri[j]
            for s in (0.25, 0.5, 0.75):
                u, v = start + direction * (s if a < b else 1 - s)
                Xu = A[t, 1] + 2 * A[t, 3] * u + A[t, 5] * v
                Xv = A[t, 2] + 2 * A[t, 4] * v + A[t, 5] * u
                n = np.cross(Xu, Xv)
                normals.setdefault((min(a, b), max(a, b), s), []).append(n / np.linalg.norm(n))
    pairs = np.array([v for v in normals.values() if len(v) == 2])
    return float(np.arccos(np.clip(np.einsum("pi,pi->p", pairs[:, 0], pairs[:, 1]), -1, 1)).max())


def _script(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def stl(tmp_path_factory):
    """The punch and the die meshed by gmsh (48 triangles a turn on the curved faces: about 1 mm
    on the nose and the shoulder, at most 10 mm) and written as STL."""
    stls, steps = _script("cup_tools_stl"), _script("cup_tools_step")
    folder = tmp_path_factory.mktemp("stl")
    t = SCENE.tools
    stls.write_stl(steps.punch, folder / "punch.stl", 48, 10.0, t.punch_half_width, t.punch_corner_radius,
                   t.punch_profile_radius)
    stls.write_stl(steps.die, folder / "die.stl", 48, 10.0, t.die_half_width, t.die_corner_radius,
                   t.die_profile_radius)
    return folder


@pytest.mark.parametrize("name, lo, hi, gap, normal", [
    ("punch", [-24.0, -24.0, -3.0], [24.0, 24.0, 0.4], 1e-12, 1e-12),  # the flat face: exact
    ("punch", [28.0, -20.0, -3.0], [40.0, 20.0, 8.0], 1.2e-2, 3e-2),  # the nose, straight
    ("punch", [26.0, 26.0, -3.0], [38.0, 38.0, 8.0], 1.2e-2, 3e-2),  # the nose's plan corner
    ("die", [46.0, -60.0, -0.4], [70.0, 60.0, 3.0], 1e-12, 1e-12),  # the flat top beyond the seam's row
    ("die", [35.0, -20.0, -8.0], [47.0, 20.0, 3.0], 1.2e-2, 6e-2),  # the shoulder
])
def test_the_punch_and_die_from_stl_match_the_analytic_tools(stl, name, lo, hi, gap, normal):
    """The STL tools against the analytic ones at random points from 1 mm inside to 3 mm outside:
    exact on the flat faces (their triangles' vertices have the plane's normal, those on the seams
    too); on the nose and the shoulder within 1.2e-2 mm and 3e-2 in the normal (measured: 3.5e-3
    mm and 5.5e-3 on the straight nose, 4.6e-3 and 1.9e-2 on its plan corner, 8.5e-3 and 5.3e-2 on the
    shoulder; the largest within a row of triangles of the seams, where the curvature jumps from
    1/8 mm to 0 and a vertex normal's error is of the order of h/r)."""
    analytic = square_cup_tools(SCENE.tools, T)[name]
    place = (0.0, 0.0, T / 2) if name == "punch" else (0.0, 0.0, -T / 2)
    tool = MeshTool.from_file(stl / f"{name}.stl", place)
    x = np.random.default_rng(int(abs(lo[0]) + 100 * abs(lo[2]))).uniform(lo, hi, (3000, 3))
    g0, _ = analytic.gap(x)
    x = x[(g0 < 3.0) & (g0 > -1.0)][:800]
    if name == "die" and lo[0] == 46.0:
        x = x[np.maximum(np.abs(x[:, 0]), np.abs(x[:, 1])) > 47.0]
    assert len(x) > 200
    g0, n0 = analytic.gap(x, 0.4)
    g1, n1 = tool.gap(x, 0.4)
    assert np.abs(g1 - g0).max() < gap
    assert np.abs(n1 - n0).max() < normal
    H = tool.shape(x, 0.4)
    assert np.allclose(H, H.transpose(0, 2, 1), atol=1e-9)
    assert np.abs(np.einsum("pij,pj->pi", H, n1)).max() < 1e-6  # H n = 0


def test_points_given_again_take_their_last_answers(stl):
    """The contact set's calls: gap, then shape on a subset, then gap at the same points: no
    search for the points given again, the same answers."""
    tool = MeshTool.from_file(stl / "punch.stl", (0.0, 0.0, T / 2))
    x = RNG.uniform([20.0, -20.0, -2.0], [40.0, 20.0, 8.0], (300, 3))
    g, n = tool.gap(x, 0.4, -1.0)
    H = tool.shape(x[::3], 0.4, -1.0)
    g2, n2 = tool.gap(x, 0.4, -1.0)
    assert tool.counts == {"repeated": 400, "warm": 0, "searched": 300}
    assert np.array_equal(g, g2) and np.array_equal(n, n2)
    fresh = MeshTool.from_file(stl / "punch.stl", (0.0, 0.0, T / 2))
    assert np.abs(fresh.shape(x[::3], 0.4, -1.0) - H).max() < 1e-12


def test_inward_normals_turn_gap_and_normal(stl):
    tool = MeshTool.from_file(stl / "die.stl", (0.0, 0.0, -T / 2))
    turned = MeshTool.from_file(stl / "die.stl", (0.0, 0.0, -T / 2), normals="inward")
    x = RNG.uniform([35.0, -20.0, -8.0], [47.0, 20.0, 3.0], (200, 3))
    (g, n), (gt, nt) = tool.gap(x), turned.gap(x)
    assert np.abs(gt + g).max() < 1e-12 and np.abs(nt + n).max() < 1e-12
    assert np.abs(turned.shape(x) + tool.shape(x)).max() < 1e-9


def test_ascii_stl_and_msh_read_as_the_binary_stl(tmp_path):
    """One mesh as binary STL, ASCII STL and gmsh .msh (ASCII, formats 4.1 and 2.2): the same
    vertices and triangles (the STL's corners merged)."""
    V, F = icosphere(1)
    write_stl(tmp_path / "s.stl", V, F)
    facets = "".join("facet normal 0 0 0\n outer loop\n" + "".join(f"  vertex {a:.17g} {b:.17g} {c:.17g}\n"
                                                                     for a, b, c in V[tri]) + " endloop\nendfacet\n"
                     for tri in F)
    (tmp_path / "a.stl").write_text(f"solid s\n{facets}endsolid s\n")
    nodes = "".join(f"{i + 1}\n" for i in range(len(V))) + "".join(f"{a:.17g} {b:.17g} {c:.17g}\n" for a, b, c in V)
    elements = "".join(f"{k + 1} {a + 1} {b + 1} {c + 1}\n" for k, (a, b, c) in enumerate(F))
    (tmp_path / "m4.msh").write_text(
        f"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 {len(V)} 1 {len(V)}\n2 1 0 {len(V)}\n{nodes}$EndNodes\n"
        f"$Elements\n1 {len(F)} 1 {len(F)}\n2 1 2 {len(F)}\n{elements}$EndElements\n")
    nodes2 = "".join(f"{i + 1} {a:.17g} {b:.17g} {c:.17g}\n" for i, (a, b, c) in enumerate(V))
    elements2 = "".join(f"{k + 1} 2 2 1 1 {a + 1} {b + 1} {c + 1}\n" for k, (a, b, c) in enumerate(F))
    (tmp_path / "m2.msh").write_text(f"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n{len(V)}\n{nodes2}$EndNodes\n"
                                     f"$Elements\n{len(F)}\n{elements2}$EndElements\n")
    for name, tol in (("s.stl", 1e-5), ("a.stl", 1e-14), ("m4.msh", 1e-14), ("m2.msh", 1e-14)):
        v, f = read_surface_mesh(tmp_path / name)
        assert len(v) == len(V) and len(f) == len(F), name
        assert np.abs(v[f] - V[F]).max() < tol, name


def _refused(path, words):
    with pytest.raises(InputError) as err:
        MeshTool.from_file(path, field="tools.punch_file")
    assert err.value.field == "tools.punch_file" and words in err.value.message


def test_bad_mesh_files_are_refused_naming_the_field(tmp_path):
    """Missing, empty, without triangles, not a mesh kind, a binary .msh, a non-manifold edge,
    facets whose orders disagree: InputError naming the field."""
    _refused(tmp_path / "none.stl", "no such file")
    (tmp_path / "empty.stl").write_bytes(b"")
    _refused(tmp_path / "empty.stl", "neither a binary STL")
    (tmp_path / "nothing.stl").write_text("solid nothing\nendsolid nothing\n")
    _refused(tmp_path / "nothing.stl", "holds no triangles")
    (tmp_path / "lines.msh").write_text("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1 2\n1 1 0 2\n1\n2\n"
                                        "0 0 0\n1 0 0\n$EndNodes\n$Elements\n1 1 1 1\n1 1 1 1\n1 1 2\n$EndElements\n")
    _refused(tmp_path / "lines.msh", "holds no triangles")
    (tmp_path / "binary.msh").write_text("$MeshFormat\n4.1 1 8\n$EndMeshFormat\n")
    _refused(tmp_path / "binary.msh", "not an ASCII gmsh mesh")
    (tmp_path / "tool.obj").write_text("v 0 0 0\n")
    _refused(tmp_path / "tool.obj", "not a surface mesh")
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0, -1, 0]], float)
    write_stl(tmp_path / "fin.stl", V, np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]]))
    _refused(tmp_path / "fin.stl", "non-manifold")
    write_stl(tmp_path / "turned.stl", V, np.array([[0, 1, 2], [0, 1, 4]]))
    _refused(tmp_path / "turned.stl", "orientation is inconsistent")


def test_a_scene_s_stl_files_make_mesh_tools(stl, tmp_path):
    """[tools] shape = "cad" with .stl files: the punch and the die are MeshTools, placed by their
    translations (placement.Placed); a bad .stl file is refused naming its field."""
    cad = scene.load(ROOT / "demos" / "numisheet93_aluminium_cad.toml").tools
    spec = type(cad)(**{**cad.__dict__, "punch_file": str(stl / "punch.stl"), "die_file": str(stl / "die.stl")})
    tools = cad_cup_tools(spec, T)
    assert isinstance(tools["punch"].tool, MeshTool) and isinstance(tools["die"].tool, MeshTool)
    g, n = tools["punch"].gap(np.array([[0.0, 0.0, 0.0]]), T / 2)
    assert abs(g[0]) < 1e-12 and np.allclose(n, [[0, 0, -1]])
    (tmp_path / "die.stl").write_text("solid nothing\nendsolid nothing\n")
    spec = type(cad)(**{**spec.__dict__, "die_file": str(tmp_path / "die.stl")})
    with pytest.raises(InputError) as err:
        cad_cup_tools(spec, T)
    assert err.value.field == "tools.die_file"


def _same_answers(tool, x, offset=0.4, dz=-1.0):
    """tool's gap, normal and H at x against a fresh tool's (its search): the largest differences."""
    fresh = MeshTool(tool.patches, tool.translation, "outward" if tool.sign > 0 else "inward")
    g, n = tool.gap(x, offset, dz)
    H = tool.shape(x, offset, dz)
    g0, n0 = fresh.gap(x, offset, dz)
    H0 = fresh.shape(x, offset, dz)
    return np.abs(g - g0).max(), np.abs(n - n0).max(), np.abs(H - H0).max()


@pytest.mark.parametrize("move, warm", [(1e-3, 0.9), (0.5, 0.5)])
def test_moved_points_start_warm_with_the_search_s_answers(stl, move, warm):
    """Points near the punch's flat face, nose and wall, and farther off, moved by 1e-3 and 0.5
    mm in random directions after a first call: gap, normal and H equal a fresh tool's search
    to 1e-10 mm; at least 90 % (1e-3 mm) and half (0.5 mm) of the moved points are answered
    warm, from their remembered neighbour lists (measured: all 600 of both)."""
    tool = MeshTool.from_file(stl / "punch.stl", (0.0, 0.0, T / 2))
    rng = np.random.default_rng(7)
    x = rng.uniform([-5.0, -45.0, -3.0], [45.0, 45.0, 20.0], (600, 3))
    tool.gap(x, 0.4, -1.0)
    step = rng.normal(size=x.shape)
    y = x + move * step / np.linalg.norm(step, axis=1)[:, None]
    dg, dn, dH = _same_answers(tool, y)
    assert dg < 1e-10 and dn < 1e-10 and dH < 1e-10
    assert tool.counts["warm"] >= warm * len(x) and tool.counts["searched"] + tool.counts["warm"] == 2 * len(x)


def test_a_moved_point_whose_nearest_patch_jumps_is_found(stl):
    """Points moved 0.5 mm across the seam between the punch's flat face and its nose, and
    points moved through a slab 0.2 mm thick (its nearest face jumps from the top to the
    bottom): the same answers as a fresh tool's."""
    tool = MeshTool.from_file(stl / "punch.stl", (0.0, 0.0, T / 2))
    edge = SCENE.tools.punch_half_width - SCENE.tools.punch_profile_radius
    x = np.c_[np.full(50, edge - 0.25), np.linspace(-20.0, 20.0, 50), np.full(50, -0.6)]
    tool.gap(x, 0.4, -1.0)
    dg, dn, dH = _same_answers(tool, x + [0.5, 0.0, 0.0])
    assert dg < 1e-10 and dn < 1e-10 and dH < 1e-10
    from scipy.spatial import ConvexHull

    corners = np.array([[a, b, c] for a in (-5.0, 5.0) for b in (-5.0, 5.0) for c in (-0.1, 0.1)])
    faces = ConvexHull(corners).simplices
    normal = np.cross(corners[faces[:, 1]] - corners[faces[:, 0]], corners[faces[:, 2]] - corners[faces[:, 0]])
    faces = np.where((np.einsum("ij,ij->i", normal, corners[faces].mean(axis=1)) < 0)[:, None], faces[:, ::-1], faces)
    slab = MeshTool.from_triangles(corners, faces)
    x = np.c_[RNG.uniform(-3.0, 3.0, (40, 2)), np.full(40, 0.15)]
    g, n = slab.gap(x)
    assert np.allclose(g, 0.05) and np.allclose(n, [0.0, 0.0, 1.0])
    for z, gap, nz in ((-0.15, 0.05, -1.0), (-0.02, -0.08, -1.0)):
        y = x * [1.0, 1.0, 0.0] + [0.0, 0.0, z]
        dg, dn, dH = _same_answers(slab, y, 0.0, 0.0)
        assert dg < 1e-10 and dn < 1e-10 and dH < 1e-10
        g, n = slab.gap(y)
        assert np.allclose(g, gap) and np.allclose(n[:, 2], nz)
        x = y
    assert slab.counts["warm"] > 0


def test_a_tool_meshed_without_the_blanks_symmetry_is_named():
    """The demo's STL tools are triangulated without the quarter's mirror symmetry: their
    distances at mirror points of the blank differ by micrometres, and a ToolSymmetryWarning
    names each file; the STEP tools are symmetric to OCC's round-off and pass silently."""
    import warnings

    from mpi4py import MPI

    from shellform.tools.cad import ToolSymmetryWarning, check_mirrors
    from shellform.mesh import blank

    planes = np.eye(3)[:2]  # x = 0 and y = 0
    for name, asymmetric in (("numisheet93_aluminium_stl.toml", True), ("numisheet93_aluminium_cad.toml", False)):
        s = scene.load(ROOT / "demos" / name).changed({"mesh.n": 8})
        x = blank(MPI.COMM_WORLD, s).mesh.geometry.x
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            worst = check_mirrors(cad_cup_tools(s.tools, T), x, planes, MPI.COMM_WORLD)
        named = {str(w.message).split(":")[0] for w in caught if issubclass(w.category, ToolSymmetryWarning)}
        if asymmetric:
            assert min(worst.values()) > 1e-4 and named == {"tools.punch_file", "tools.die_file"}
        else:
            assert max(worst.values()) < 1e-9 and not named
