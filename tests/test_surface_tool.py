"""Tools from CAD surfaces (shellform/tools/surface_tool.py): the NUMISHEET'93 aluminium cup's
punch and die built in gmsh (OpenCASCADE) from the dimensions of demos/numisheet93_aluminium.toml,
written to STEP and read back, against the analytic tools of the same scene (tools.py): gap,
normal and shape operator at random points near every region of their surfaces, and on the
seams between a fillet and the face it meets. The accuracy asked: 1e-6 mm in the gap, 1e-6 in
the normal, 1e-5 of the largest curvature in H (measured: 3e-8 mm, 1e-7 and 2e-6 on the punch's
nose corner, in STEP a surface of revolution of a B-spline that approximates the nose's circle;
1e-14 on the die's planes, cylinders and tori)."""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from shellform import scene
from shellform.tools.surface_tool import SurfaceTool
from shellform.tools.square import square_cup_tools
from shellform.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
SCENE = scene.load(ROOT / "demos" / "numisheet93_aluminium.toml")
T = SCENE.material.thickness
SPEC = SCENE.tools
ANALYTIC = square_cup_tools(SPEC, T)
GAP, NORMAL, CURVATURE = 1e-6, 1e-6, 1e-5  # mm; -; times the largest |H| of the points
RNG = np.random.default_rng(35)


def _script():
    spec = importlib.util.spec_from_file_location("cup_tools_step", ROOT / "scripts" / "cup_tools_step.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def cad(tmp_path_factory):
    """The punch and the die written as STEP and read back, placed as the analytic ones."""
    steps = _script()
    folder = tmp_path_factory.mktemp("cad")
    steps.write_step(steps.punch, folder / "punch.step", SPEC.punch_half_width, SPEC.punch_corner_radius,
                     SPEC.punch_profile_radius)
    steps.write_step(steps.die, folder / "die.step", SPEC.die_half_width, SPEC.die_corner_radius,
                     SPEC.die_profile_radius)
    return {"punch": SurfaceTool.from_file(folder / "punch.step", (0.0, 0.0, T / 2 + SPEC.punch_gap)),
            "die": SurfaceTool.from_file(folder / "die.step", (0.0, 0.0, -T / 2)), "folder": folder}


def _box(lo, hi, n=300):
    return RNG.uniform(lo, hi, (n, 3))


# regions of the punch (face at z = t/2; nose 8, plan corner 10, half-width 35) and the die (top at
# -t/2, shoulder 8, opening 37 with plan corner 12): boxes of points around each, x, y >= 0 and < 0
PUNCH_REGIONS = {
    "flat face": ([-24.0, -24.0, -3.0], [24.0, 24.0, 0.4]),
    "nose, straight": ([28.0, -20.0, -3.0], [40.0, 20.0, 8.0]),
    "nose, plan corner": ([26.0, 26.0, -3.0], [38.0, 38.0, 8.0]),
    "wall": ([35.5, -20.0, 10.0], [38.0, 20.0, 40.0]),
    "wall, plan corner": ([-35.0, 28.0, 10.0], [-28.0, 35.0, 40.0]),
}
DIE_REGIONS = {
    "flat top": ([46.0, -60.0, -0.4], [70.0, 60.0, 3.0]),
    "shoulder, straight": ([35.0, -20.0, -8.0], [47.0, 20.0, 3.0]),
    "shoulder, plan corner": ([-46.0, -46.0, -8.0], [-30.0, -30.0, 3.0]),
    "wall": ([33.0, -20.0, -40.0], [36.8, 20.0, -10.0]),
    "wall, plan corner": ([27.0, 27.0, -40.0], [34.0, 34.0, -10.0]),
}


def _near(tool, x, dz):
    """The points within 3 mm of the analytic tool's surface, outside or at most 2 mm inside."""
    g, _ = tool.gap(x, 0.0, dz)
    return x[(g < 3.0) & (g > -2.0)]


@pytest.mark.parametrize("name, regions, dz", [("punch", PUNCH_REGIONS, 0.0), ("punch", PUNCH_REGIONS, -12.5),
                                                ("die", DIE_REGIONS, 0.0)])
def test_gap_normal_shape_match_the_analytic_tools(cad, name, regions, dz):
    """At random points near every region (the punch also moved down by 12.5 mm), within 1e-6 mm
    in the gap, 1e-6 in the normal and 1e-5 of the largest curvature in H; an offset subtracts."""
    analytic, tool = ANALYTIC[name], cad[name]
    for region, (lo, hi) in regions.items():
        lo, hi = np.add(lo, [0, 0, dz]), np.add(hi, [0, 0, dz])
        x = _near(analytic, _box(lo, hi), dz)
        assert len(x) > 50, region
        g0, n0 = analytic.gap(x, 0.4, dz)
        g1, n1 = tool.gap(x, 0.4, dz)
        assert np.abs(g1 - g0).max() < GAP, region
        assert np.abs(n1 - n0).max() < NORMAL, region
        H0, H1 = analytic.shape(x, 0.4, dz), tool.shape(x, 0.4, dz)
        assert np.abs(H1 - H0).max() < CURVATURE * max(np.abs(H0).max(), 1.0 / 8.0), region
        assert np.allclose(H1, H1.transpose(0, 2, 1), atol=1e-12)
        assert np.abs(np.einsum("pij,pj->pi", H1, n1)).max() < 1e-9  # H n = 0


@pytest.mark.parametrize("name, regions, travel", [("punch", PUNCH_REGIONS, -0.2), ("die", DIE_REGIONS, 0.0)])
def test_moved_points_are_answered_without_a_search(cad, name, regions, travel):
    """The contact set's calls: the points of the last call moved a little (0.05 mm each way,
    the punch 0.2 mm down a call), then given again (shape after gap). The moved points are
    answered by the faces' closed forms (nearly all: counts; the cup's tools have no face gmsh
    alone evaluates), the points given again take their last answer; every answer the analytic
    tool's within the accuracy asked, and the last call's those of a new tool, to round-off."""
    analytic, tool = ANALYTIC[name], cad[name]
    x = np.vstack([_near(analytic, _box(lo, hi, 120), 0.0) for lo, hi in regions.values()])
    tool.gap(x, 0.4, 0.0)
    for step in range(1, 4):
        x = x + RNG.normal(0.0, 0.05, x.shape)
        dz = step * travel
        before = dict(tool.counts)
        g1, n1 = tool.gap(x, 0.4, dz)
        H1 = tool.shape(x, 0.4, dz)
        assert tool.counts["exact"] - before["exact"] >= 0.9 * len(x)
        assert tool.counts["repeated"] - before["repeated"] == len(x)
        g0, n0 = analytic.gap(x, 0.4, dz)
        H0 = analytic.shape(x, 0.4, dz)
        assert np.abs(g1 - g0).max() < GAP and np.abs(n1 - n0).max() < NORMAL
        assert np.abs(H1 - H0).max() < CURVATURE * max(np.abs(H0).max(), 1.0 / 8.0)
    fresh = SurfaceTool.from_file(cad["folder"] / f"{name}.step", tool.translation)
    g2, n2 = fresh.gap(x, 0.4, dz)
    assert fresh.counts["repeated"] == fresh.counts["warm"] == 0
    assert fresh.counts["exact"] + fresh.counts["searched"] == len(x) and fresh.counts["exact"] >= 0.9 * len(x)
    assert np.abs(g2 - g1).max() < 1e-10 and np.abs(n2 - n1).max() < 1e-10
    assert np.abs(fresh.shape(x, 0.4, dz) - H1).max() < 1e-9


def _cone(gmsh):
    """A truncated cone on z = 0 (radius 20, 8 at z = 15): its side a cone, which no closed
    form here evaluates (gmsh does), its ends two discs."""
    gmsh.model.occ.addCone(0.0, 0.0, 0.0, 0.0, 0.0, 15.0, 20.0, 8.0)


def _cone_gap(x):
    """The distance to _cone's side (a segment in every half-plane through the axis), signed
    outward, and its normal, where that segment holds the nearest point."""
    rho, z = np.hypot(x[:, 0], x[:, 1]), x[:, 2]
    a, b = np.array([20.0, 0.0]), np.array([8.0, 15.0])
    t = b - a
    length = np.linalg.norm(t)
    t /= length
    out = np.array([t[1], -t[0]])  # outward in the half-plane
    q = np.c_[rho, z] - a
    s = q @ t
    g = q @ out
    radial = x[:, :2] / rho[:, None]
    n = np.c_[out[0] * radial, np.full(len(x), out[1])]
    return g, n, (s > 0.0) & (s < length)


def test_moved_points_on_a_face_gmsh_evaluates_start_warm():
    """A face no closed form evaluates (a cone's side): points moved a little (0.05 mm) start
    from their last closest points (the warm start: nearly all, counts); the answers the
    cone's exact distance and normal, and a new tool's, to round-off."""
    tool = SurfaceTool.from_builder(_cone)
    rng = np.random.default_rng(7)
    r, z = rng.uniform(9.0, 21.0, 600), rng.uniform(3.5, 11.5, 600)  # the side nearer than the ends
    phi = rng.uniform(0.0, 2 * np.pi, 600)
    x = np.c_[r * np.cos(phi), r * np.sin(phi), z]
    g0, _, held = _cone_gap(x)
    x = x[held & (np.abs(g0) < 2.0) & (np.abs(g0) > 0.05)]
    tool.gap(x)
    for _ in range(3):
        x = x + rng.normal(0.0, 0.05, x.shape)
        before = dict(tool.counts)
        g1, n1 = tool.gap(x)
        assert tool.counts["warm"] - before["warm"] >= 0.9 * len(x)
        g0, n0, held = _cone_gap(x)
        assert held.all()
        assert np.abs(g1 - g0).max() < 1e-9 and np.abs(n1 - n0).max() < 1e-9
    fresh = SurfaceTool.from_builder(_cone)
    g2, n2 = fresh.gap(x)
    assert fresh.counts["searched"] == len(x)
    assert np.abs(g2 - g1).max() < 1e-10 and np.abs(n2 - n1).max() < 1e-10


def _projection(tool, x, face):
    """gmsh's projection of points x (in the tool's frame: untranslated) onto a face of the
    tool's model (OCC's, onto its untrimmed surface): points, parameters, and whether these
    lie inside the face's parameter bounds."""
    import gmsh

    previous = gmsh.model.getCurrent()
    gmsh.model.setCurrent(tool.model)
    try:
        c, p = gmsh.model.getClosestPoint(2, face, x.ravel())
        b0, b1 = gmsh.model.getParametrizationBounds(2, face)
    finally:
        gmsh.model.setCurrent(previous)
    p = np.asarray(p).reshape(-1, 2)
    return np.asarray(c).reshape(-1, 3), p, np.all((p > np.add(b0, 1e-6)) & (p < np.subtract(b1, 1e-6)), axis=1)


@pytest.mark.parametrize("build, lo, hi", [
    (lambda gmsh: gmsh.model.occ.addTorus(1.0, -2.0, 3.0, 12.0, 4.0, zAxis=[0.3, 0.2, 1.0]), -20.0, 20.0),
    (lambda gmsh: gmsh.model.occ.addSphere(1.0, 2.0, -1.0, 6.0), -12.0, 12.0),
    (lambda gmsh: gmsh.model.occ.addCylinder(0.0, 0.0, 0.0, 2.0, 1.0, 9.0, 5.0, angle=4.0), -7.0, 12.0),
])
def test_closed_forms_are_gmsh_s_projection(build, lo, hi):
    """A torus (tilted), a sphere and a cylinder (an arc of 4 rad, with its flat sides), their
    faces evaluated in closed form (faces.py): at random points whose projection by OCC onto a
    curved face lies inside it and is their closest point, the closest point, its distance and
    parameters are OCC's to round-off, and the closed forms answered them (counts of a new
    tool)."""
    tool = SurfaceTool.from_builder(build)
    x = np.random.default_rng(11).uniform(lo, hi, (400, 3))
    c, d, n, ent, par = tool.closest(x)
    import gmsh

    previous = gmsh.model.getCurrent()
    gmsh.model.setCurrent(tool.model)
    curved = [t for _, t in gmsh.model.getEntities(2) if gmsh.model.getType(2, t) != "Plane"]
    gmsh.model.setCurrent(previous)
    checked = 0
    for face in curved:
        c0, p0, inside = _projection(tool, x, face)
        mine = inside & (np.linalg.norm(c - c0, axis=1) < 1e-6)  # the points whose closest point is on it
        assert np.abs(np.abs(d[mine]) - np.linalg.norm(x[mine] - c0[mine], axis=1)).max(initial=0.0) < 1e-10
        assert np.abs(c[mine] - c0[mine]).max(initial=0.0) < 1e-9
        turn = np.mod(par[mine] - p0[mine] + np.pi, 2 * np.pi) - np.pi  # parameters: angles modulo 2 pi
        assert np.abs(turn).max(initial=0.0) < 1e-9
        checked += mine.sum()
        fresh = SurfaceTool.from_builder(build)
        fresh.closest(x[mine])
        assert fresh.counts["exact"] == mine.sum()
    assert checked > 100


def test_the_punch_s_nose_corner_is_gmsh_s_projection(cad):
    """The STEP punch's nose corners are surfaces of revolution of a B-spline (the circle of the
    nose approximated to 1e-8 mm): turned in closed form, Newton along the meridian (faces.py,
    CurveRevolutions). At points around a corner whose projection by OCC lies inside it, near
    and far (the sheet's flange, 40 mm off), the closest point is OCC's."""
    import gmsh

    tool = cad["punch"]
    previous = gmsh.model.getCurrent()
    gmsh.model.setCurrent(tool.model)
    corners = [t for _, t in gmsh.model.getEntities(2) if gmsh.model.getType(2, t) == "Surface of Revolution"]
    gmsh.model.setCurrent(previous)
    assert len(corners) == 4
    rng = np.random.default_rng(5)
    x = np.vstack([rng.uniform([26.0, 26.0, -3.0], [36.0, 36.0, 9.0], (300, 3)),
                   rng.uniform([40.0, 40.0, -1.0], [60.0, 60.0, 1.0], (100, 3))]) + tool.translation
    before = dict(tool.counts)
    c, d, n, ent, par = tool.closest(x)
    assert tool.counts["exact"] - before["exact"] >= 0.9 * len(x)
    y, cy = x - tool.translation, c - tool.translation
    checked = 0
    for face in corners:
        c0, p0, inside = _projection(tool, y, face)
        mine = inside & (np.linalg.norm(cy - c0, axis=1) < 1e-5)
        assert np.abs(np.abs(d[mine]) - np.linalg.norm(y[mine] - c0[mine], axis=1)).max(initial=0.0) < 1e-10
        assert np.abs(cy[mine] - c0[mine]).max(initial=0.0) < 1e-7
        checked += mine.sum()
    assert checked > 150


@pytest.mark.parametrize("x0, spread, z", [
    ((0.012, 0.012), 0.004, (-30.0, -15.0)),  # in the opening: the walls x = +-37 (planes), 0.024 mm apart
    ((0.012, 0.012), 0.004, (3.0, 6.0)),  # above it: the shoulders along x = +-37 (cylinders), 0.02 mm apart
])
def test_a_moved_point_whose_nearest_face_jumps_is_found(cad, x0, spread, z):
    """Points beside the die's middle plane x = 0, nearer its side x = 37 than the sides y =
    +-37, moved to the other side of that plane: the nearest face jumps to the side x = -37
    across the opening (a face that does not meet the last one). The warm start's bounds refuse
    the last face; the answers are the analytic tool's."""
    analytic, tool = ANALYTIC["die"], cad["die"]
    x = np.c_[RNG.uniform(*x0, 100), RNG.uniform(-spread, spread, 100), RNG.uniform(*z, 100)]
    normals = []
    for y in (x, x * [-1.0, 1.0, 1.0]):
        g1, n1 = tool.gap(y, 0.4)
        g0, n0 = analytic.gap(y, 0.4)
        assert np.abs(g1 - g0).max() < GAP and np.abs(n1 - n0).max() < NORMAL
        normals.append(n1)
    assert np.all(normals[0][:, 0] < -0.2) and np.all(normals[1][:, 0] > 0.2)  # the face across


def _one_sided(tool, x, step, dz=0.0):
    """H just beside x on both sides of a seam (x -/+ step)."""
    return tool.shape(x - step, 0.0, dz), tool.shape(x + step, 0.0, dz)


@pytest.mark.parametrize("name, seam, across", [
    ("punch", lambda y, d: np.c_[np.full_like(y, 27.0), y, T / 2 - d], [1.0, 0.0, 0.0]),  # flat face | nose
    ("punch", lambda z, d: np.c_[np.full_like(z, 35.0) + d, np.zeros_like(z), T / 2 + 8.0 + 0 * z],
     [0.0, 0.0, 1.0]),  # nose | wall, on y = 0 at the nose's top
    ("die", lambda y, d: np.c_[np.full_like(y, 45.0), y, -T / 2 + d], [1.0, 0.0, 0.0]),  # shoulder | flat top
])
def test_seams_take_one_side(cad, name, seam, across):
    """Points whose closest point lies on a fillet's seam (the tangent edge between the fillet
    and the face it meets): gap and normal are continuous there and match the analytic tool; H
    is one of its two one-sided values (the face's or the fillet's)."""
    analytic, tool = ANALYTIC[name], cad[name]
    d = RNG.uniform(0.05, 2.0, 40)
    x = seam(RNG.uniform(-15.0, 15.0, 40), d)
    g0, n0 = analytic.gap(x, 0.0)
    g1, n1 = tool.gap(x, 0.0)
    assert np.abs(g1 - g0).max() < GAP and np.abs(n1 - n0).max() < NORMAL
    a, b = _one_sided(analytic, x, 1e-7 * np.asarray(across))
    assert np.abs(a - b).max() > 0.05  # a true jump: the two sides differ
    H = tool.shape(x, 0.0)
    side = np.minimum(np.abs(H - a).max(axis=(1, 2)), np.abs(H - b).max(axis=(1, 2)))
    assert side.max() < 1e-5


def test_a_model_built_in_this_process_equals_its_step_file(cad):
    """The punch built by a Python function with gmsh, not written: the same gap as the STEP
    file read back, within the accuracy of OCC's projection onto the nose's tori (STEP keeps the
    exact surfaces: 0 on the planes and cylinders, 3e-8 mm on the tori)."""
    steps = _script()
    built = SurfaceTool.from_builder(lambda gmsh: steps.punch(gmsh, SPEC.punch_half_width, SPEC.punch_corner_radius,
                                                              SPEC.punch_profile_radius),
                                     (0.0, 0.0, T / 2))
    x = _box([-40.0, -40.0, -3.0], [40.0, 40.0, 10.0], 200)
    assert np.abs(built.gap(x)[0] - cad["punch"].gap(x)[0]).max() < GAP


def test_inward_normals_turn_gap_and_normal(cad, tmp_path):
    """normals = "inward" turns the faces: the gap and the normal change sign, H too."""
    turned = SurfaceTool.from_file(cad["folder"] / "die.step", (0.0, 0.0, -T / 2), normals="inward")
    x = _near(ANALYTIC["die"], _box(*DIE_REGIONS["shoulder, straight"]), 0.0)
    g, n = cad["die"].gap(x)
    gt, nt = turned.gap(x)
    assert np.abs(gt + g).max() < 1e-12 and np.abs(nt + n).max() < 1e-12
    assert np.abs(turned.shape(x) + cad["die"].shape(x)).max() < 1e-9


def test_a_sphere_s_poles_do_not_stop_the_search():
    """A sphere's OCC face has a degenerated edge, a point with no curve, at each pole; the tool
    leaves those out (the face holds the points), so points near and around the poles get the
    sphere's exact distance and normal (they raised 'curve is null in projection' before)."""
    tool = SurfaceTool.from_builder(lambda gmsh: gmsh.model.occ.addSphere(0.0, 0.0, 0.0, 10.0))
    rng = np.random.default_rng(3)
    x = np.vstack([[[0.0, 0.0, 10.3], [0.0, 0.0, -9.6], [0.01, -0.02, 11.0], [0.0, 0.0, 0.5]],
                   rng.normal(size=(200, 3)) * 8.0])
    g, n = tool.gap(x, 0.0, 0.0)
    r = np.linalg.norm(x, axis=1)
    np.testing.assert_allclose(g, r - 10.0, atol=1e-9)
    np.testing.assert_allclose(n, x / r[:, None], atol=1e-9)  # the outward normal, inside too


PLATE = dict(half=25.0, corner=10.0, outer=60.0, height=10.0)  # a plate with a rounded-square hole


def _plate(gmsh):
    """A plate |x|, |y| <= outer, 0 <= z <= height, through it a hole of half-width `half` and
    plan corner radius `corner`: its rims are sharp edges, four straight and four arcs at top
    and bottom (the arcs' parameter ranges quarter turns, not all of them holding 0)."""
    occ, a, h, out = gmsh.model.occ, PLATE["half"], PLATE["height"], PLATE["outer"]
    plate = occ.addBox(-out, -out, 0.0, 2 * out, 2 * out, h)
    hole = occ.addBox(-a, -a, -1.0, 2 * a, 2 * a, h + 2.0)
    occ.synchronize()
    boxes = {t: np.reshape(gmsh.model.getBoundingBox(1, t), (2, 3)) for _, t in gmsh.model.getEntities(1)}
    vertical = [t for t, (lo, hi) in boxes.items() if np.all(hi[:2] - lo[:2] < 1e-6) and abs(abs(lo[0]) - a) < 1e-6]
    occ.fillet([hole], vertical, [PLATE["corner"]])
    occ.synchronize()
    (_, hole), = [e for e in gmsh.model.getEntities(3) if e[1] != plate]
    occ.cut([(3, plate)], [(3, hole)])
    occ.synchronize()


def _plate_distance(x):
    """The plate's signed distance (> 0 outside), its gradient (the outward normal) and the hole's
    plan tangent at the nearest rim point, in closed form, for points nearer the hole than the
    plate's outer sides: the hole's rounded square's plan distance s (> 0 in the hole), the plate
    its extrusion over 0 <= z <= height."""
    a, r, h = PLATE["half"], PLATE["corner"], PLATE["height"]
    q = np.abs(x[:, :2]) - (a - r)
    corner = np.all(q > 0, axis=1)
    side = np.argmax(q, axis=1)
    qq = np.maximum(q, 0)
    g2 = np.where(corner[:, None], qq / np.maximum(np.linalg.norm(qq, axis=1), 1e-300)[:, None],
                  np.eye(2)[side]) * np.sign(x[:, :2])  # the gradient of the hole's plan distance, outward
    s = -(np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0) - r)  # > 0 in the hole
    wz = np.abs(x[:, 2] - h / 2) - h / 2
    out = np.hypot(np.maximum(s, 0), np.maximum(wz, 0))
    d = np.where((s > 0) | (wz > 0), out, np.maximum(s, wz))
    grad = np.zeros_like(x)
    rim = (s > 0) & (wz > 0)  # nearest a sharp rim edge
    grad[:, :2] = -g2 * np.where(rim, s / np.maximum(out, 1e-300), (s >= wz))[:, None]
    grad[:, 2] = np.sign(x[:, 2] - h / 2) * np.where(rim, wz / np.maximum(out, 1e-300), (wz > s))
    tangent = np.c_[-g2[:, 1], g2[:, 0], np.zeros(len(x))]
    return d, grad, tangent, rim, corner


def test_points_nearest_a_sharp_edge_get_its_distance(tmp_path):
    """A plate with a rounded-square hole, read from STEP: its rims are sharp edges, straight
    lines and quarter arcs. At points around the rims, outside the plate (the point nearest on
    an edge: the search's candidates) and inside it, from a new tool and moved a little on the
    same one: the gap and the normal are the closed form's, H on a rim (I - n n^T - e e^T)/d,
    and mirrored points get the same gap. Before, gmsh's parameter of an edge's projection (0
    wherever OCC's projection succeeds) was clamped to the edge's range: the foot point on the
    bottom rim y = 45 of a hole of half-width 45 (22.04, 44.14, -0.405) was answered 47.05 mm
    off, by the far end of the segment."""
    path = tmp_path / "plate.step"
    _script().write_step(_plate, path)
    a, h = PLATE["half"], PLATE["height"]
    rng = np.random.default_rng(4)
    x = rng.uniform([-a - 4, -a - 4, -3.0], [a + 4, a + 4, h + 3.0], (20000, 3))
    d, _, _, rim, _ = _plate_distance(x)
    near = (np.abs(d) < 3.0) & ((np.abs(x[:, 2]) < 3.0) | (np.abs(x[:, 2] - h) < 3.0))
    x = np.vstack([x[near & ~rim][:200], x[near & rim][:200]])  # inside and outside, beside the rims
    x = np.vstack([x, [[a - 3.0, a - 0.86, -0.405], [0.0, a - 0.86, -0.405], [a - 0.86, 0.0, h + 0.3]]])
    d, grad, tangent, rim, corner = _plate_distance(x)
    assert (rim & corner).sum() > 20 and (rim & ~corner).sum() > 20  # arcs and lines
    mirrored = []
    for y in (x, x * [-1.0, 1.0, 1.0], x * [1.0, -1.0, 1.0], x[:, [1, 0, 2]]):
        tool = SurfaceTool.from_file(path)
        g, n = tool.gap(y)
        dy, grad, tangent, rim, _ = _plate_distance(y)
        np.testing.assert_allclose(g, dy, atol=1e-9)
        np.testing.assert_allclose(n, grad, atol=1e-7)
        P = np.eye(3) - n[rim, :, None] * n[rim, None, :] - tangent[rim, :, None] * tangent[rim, None, :]
        np.testing.assert_allclose(tool.shape(y)[rim], P / g[rim, None, None], atol=1e-7)
        mirrored.append(g)
        moved = y + rng.normal(scale=0.05, size=y.shape)
        np.testing.assert_allclose(tool.gap(moved)[0], _plate_distance(moved)[0], atol=1e-9)
    assert np.abs(np.array(mirrored) - mirrored[0]).max() < 1e-12


def test_bad_files_are_named(tmp_path):
    """A missing file, a file that is no CAD file by its name, a file OCC cannot read and a
    file with no surface: each an InputError naming the field given."""
    with pytest.raises(InputError, match="no such file") as err:
        SurfaceTool.from_file(tmp_path / "none.step", field="tools.punch_file")
    assert err.value.field == "tools.punch_file"
    (tmp_path / "punch.stl").write_text("solid x\nendsolid x\n")
    with pytest.raises(InputError, match="not a CAD file"):
        SurfaceTool.from_file(tmp_path / "punch.stl", field="tools.punch_file")
    (tmp_path / "junk.step").write_text("this is no STEP file\n")
    with pytest.raises(InputError) as err:
        SurfaceTool.from_file(tmp_path / "junk.step", field="tools.die_file")
    assert err.value.field == "tools.die_file"
    steps = _script()
    steps.write_step(lambda gmsh: (gmsh.model.occ.addPoint(0, 0, 0), gmsh.model.occ.synchronize()),
                     tmp_path / "point.step")
    with pytest.raises(InputError, match="no surface|cannot read") as err:
        SurfaceTool.from_file(tmp_path / "point.step", field="tools.die_file")
    assert err.value.field == "tools.die_file"


# -- the scene: [tools] shape = "cad" ------------------------------------------------------------
CAD_SCENE = ROOT / "demos" / "numisheet93_aluminium_cad.toml"


def test_cad_scene_reads_files_relative_to_its_folder():
    s = scene.load(CAD_SCENE)
    assert s.tools.shape == "cad"
    assert Path(s.tools.punch_file) == ROOT / "demos" / "meshes" / "numisheet93" / "punch.step"
    assert Path(s.tools.die_file).is_file()
    with pytest.raises(InputError) as err:
        s.changed({"tools.die_file": str(ROOT / "demos" / "meshes" / "none.step")})
    assert err.value.field == "tools.die_file"
    with pytest.raises(InputError) as err:
        s.changed({"tools.punch_normals": "up"})
    assert err.value.field == "tools.punch_normals"
    with pytest.raises(InputError) as err:
        s.changed({"tools.punch_translation": [0.0, 0.0]})
    assert err.value.field == "tools.punch_translation"
    with pytest.raises(InputError) as err:
        s.changed({"geometry.lx": 80.0})  # half of it, 40, does not reach the holder at 45
    assert err.value.field == "geometry.lx"


@pytest.mark.parametrize("changes, field", [
    ({"tools.die_normals": "inward"}, "tools.die_normals"),  # the die's normals point away from the sheet
    ({"tools.punch_translation": [0.0, 0.0, 0.0]}, "tools.punch_translation"),  # the punch cuts the blank
    ({"tools.die_translation": [0.0, 0.0, -0.6]}, "tools.die_translation"),  # the die's top below the sheet
    ({"tools.holder_half_width": 41.0}, "tools.holder_half_width"),  # the holder over the die's shoulder
])
def test_cad_tools_that_do_not_fit_the_blank_are_named(changes, field):
    """Before any computation: the tools checked against the blank's nodes (check_start)."""
    from shellform.contact.problem import DrawingProblem

    s = scene.load(CAD_SCENE).changed({"mesh.n": 4, **changes})
    with pytest.raises(InputError) as err:
        DrawingProblem.from_scene(s, verbose=False)
    assert err.value.field == field


def test_a_file_with_no_surface_is_named(tmp_path):
    steps = _script()
    steps.write_step(lambda gmsh: (gmsh.model.occ.addPoint(0, 0, 0), gmsh.model.occ.synchronize()),
                     tmp_path / "point.step")
    from shellform.contact.problem import DrawingProblem

    s = scene.load(CAD_SCENE).changed({"mesh.n": 4, "tools.die_file": str(tmp_path / "point.step")})
    with pytest.raises(InputError) as err:
        DrawingProblem.from_scene(s, verbose=False)
    assert err.value.field == "tools.die_file"


def _drawn(path, n, stroke):
    from shellform.contact.problem import DrawingProblem
    from shellform.results.cup import draw_in, peak_thinning

    s = scene.load(path).changed({"mesh.n": n})
    p = DrawingProblem.from_scene(s, verbose=False)
    p.driver.run(stroke / s.tools.stroke)
    return {**draw_in(p), "force": p.punch_force(), "thinning": peak_thinning(p)["min_thickness_strain"],
            "iterations": sum(h.iterations for h in p.driver.history),
            "increments": len(p.driver.history), "balance": p.force_balance()}


def test_the_cup_drawn_by_step_tools_equals_the_analytic_run():
    """The aluminium cup on 8 x 8 x 2 triangles drawn 2 mm by the STEP punch and die and by the
    analytic ones: draw-in, punch force and peak thinning within 0.5 %, iterations within 20 % (the issue's
    check; measured: the same increments and iterations, the answers to 1e-8, docs/tools.md)."""
    analytic = _drawn(ROOT / "demos" / "numisheet93_aluminium.toml", 8, 2.0)
    cad = _drawn(CAD_SCENE, 8, 2.0)
    for key in ("DX", "DY", "DD", "force", "thinning"):
        assert abs(cad[key] - analytic[key]) <= 5e-3 * abs(analytic[key]), key
    assert abs(cad["iterations"] - analytic["iterations"]) <= 0.2 * analytic["iterations"]
    assert analytic["force"] > 1000.0 and analytic["DX"] > 0.01  # the punch has drawn the sheet
    assert cad["balance"] < 1e-6


MPI_SCRIPT = """
import json, shellform
from mpi4py import MPI
from shellform import scene
from shellform.contact.problem import DrawingProblem
from shellform.results.cup import draw_in
s = scene.load(SCENE).changed({"mesh.n": 8})
p = DrawingProblem.from_scene(s, verbose=False)
p.driver.run(2.0 / s.tools.stroke)
force, d = p.punch_force(), draw_in(p)
if MPI.COMM_WORLD.rank == 0:
    print("RESULT " + json.dumps({"force": force, "DX": d["DX"],
                                  "iterations": sum(h.iterations for h in p.driver.history)}))
"""


@pytest.mark.slow
@pytest.mark.mpi
def test_step_tools_on_two_ranks(tmp_path):
    """Every rank reads the files (its own child process first: one that imports gmsh only,
    not MPI) and evaluates its own nodes: the cup drawn 2 mm on n = 8 by two ranks gives the
    serial run's iterations, force and draw-in to 1e-6 (measured: 37 iterations, the force to
    1.4e-8; about 15 s)."""
    import json
    import os
    import subprocess
    import sys

    from shellform.studies.common import mpiexec

    if mpiexec() is None:
        pytest.skip("no mpiexec")
    script = tmp_path / "run.py"
    script.write_text(MPI_SCRIPT.replace("SCENE", repr(str(CAD_SCENE))))
    out = subprocess.run([mpiexec(), "-n", "2", sys.executable, str(script)], capture_output=True, text=True,
                         timeout=600, env=dict(os.environ, OMP_NUM_THREADS="1"))
    assert out.returncode == 0, out.stderr[-2000:]
    line = [ln for ln in out.stdout.splitlines() if ln.startswith("RESULT ")][-1]
    parallel = json.loads(line[len("RESULT "):])
    serial = _drawn(CAD_SCENE, 8, 2.0)
    assert parallel["iterations"] == serial["iterations"]
    assert parallel["force"] == pytest.approx(serial["force"], rel=1e-6)
    assert parallel["DX"] == pytest.approx(serial["DX"], rel=1e-6)


def test_the_dome_cup_stretches_the_sheet_over_the_hemispherical_punch(tmp_path):
    """demos/dome_cup.toml (a CAD hemisphere in the CAD square die) on 8 x 8 x 2 cells, 4 mm:
    no cut-back, no penetration, the tools' forces balanced, and the sheet thins most at the
    dome's tip, where it follows the punch down the stroke (docs/tools.md, "A dome cup")."""
    from shellform import cli

    scene_file = ROOT / "demos" / "dome_cup.toml"
    args = ["run", str(scene_file), "-o", str(tmp_path), "--set", "mesh.n=8", "--set", "tools.stroke=4.0",
            "--set", "process.initial_step_mm=0.08", "--set", "process.max_step_mm=0.2", "--set", "process.report=[]"]
    assert cli.main(args) == 0
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["stopped"] is None and s["cutbacks"] == 0
    worst = s["over_the_stroke"]
    assert worst["force_balance"] < 2e-6 and worst["max_penetration_mm"] < 0.01 * 0.81
    x, y, z = s["where_current_xyz_mm"]
    assert np.hypot(x, y) < 1e-6 and z == pytest.approx(-4.0, abs=0.02)
    assert s["min_thickness_strain"] < -0.005 and s["punch_force_kN"][-1]["force"] > 0.5


@pytest.mark.timeout(60)
def test_a_cad_tool_of_too_many_faces_is_refused_before_its_setup(tmp_path):
    """A STEP of 500 solids took 295 s to set up past the read check: a tool's file of more than
    MAX_CAD_FACES faces (here 84 boxes, 504 faces) is refused by the child that reads it, naming
    the field, before the tool samples its faces."""
    import subprocess
    import sys

    from shellform.tools.cad_files import MAX_CAD_FACES

    path = tmp_path / "boxes.step"
    boxes = MAX_CAD_FACES // 6 + 1
    write = ("import gmsh\ngmsh.initialize(readConfigFiles=False)\ngmsh.option.setNumber('General.Terminal', 0)\n"
             f"for i in range({boxes}):\n    gmsh.model.occ.addBox((i % 10) * 3.0, (i // 10) * 3.0, 0, 2, 2, 2)\n"
             f"gmsh.model.occ.synchronize()\ngmsh.write({str(path)!r})\ngmsh.finalize()\n")
    subprocess.run([sys.executable, "-c", write], check=True, capture_output=True)
    with pytest.raises(InputError) as err:
        SurfaceTool.from_file(path, field="tools.die_file")
    assert err.value.field == "tools.die_file"
    assert f"holds {6 * boxes:,} faces; a tool may have at most {MAX_CAD_FACES}" in err.value.message
