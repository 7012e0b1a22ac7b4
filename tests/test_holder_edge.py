"""The blank holder's inner edge (shellform/tools/holder_edge.py): a rounded square, or an
outline read from a die's flat top; tested apart from assembly, then read from CAD and STL dies."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
import pytest

from shellform.tools.holder_edge import OutlineEdge, RoundedSquareEdge, closed_loops

ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]
RNG = np.random.default_rng(3)


def _rounded_square(a, rc, spacing):
    """Points every `spacing` (or closer) around the rounded square, counter-clockwise: corner
    arc k about (+-(a - rc), +-(a - rc)) from the angle k pi/2 to (k + 1) pi/2, then the side to
    the next arc."""
    d = a - rc
    centres = np.array([[d, d], [-d, d], [-d, -d], [d, -d]])
    pts = []
    for k in range(4):
        angles = np.linspace(k * np.pi / 2, (k + 1) * np.pi / 2, max(int(np.ceil(np.pi / 2 * rc / spacing)), 2) + 1)
        arc = centres[k] + rc * np.c_[np.cos(angles), np.sin(angles)]
        nxt = centres[(k + 1) % 4] + rc * np.array([np.cos((k + 1) * np.pi / 2), np.sin((k + 1) * np.pi / 2)])
        side = np.linspace(arc[-1], nxt, max(int(np.ceil(2 * d / spacing)), 1) + 1)[1:-1]
        pts += [arc, side]
    return np.vstack(pts)


def test_an_outline_of_a_rounded_square_is_the_rounded_square():
    """A rounded square (45, 20) sampled every 0.25 mm: the signed distance within the chords'
    sagitta (0.25^2 / (8 x 20) = 4e-4 mm), the length and the reach to 1e-5, and j = 1/(1 + s/rc)
    beside the arcs' middles and 1 beside the sides' middles to 1e-3."""
    exact, outline = RoundedSquareEdge(45.0, 20.0), OutlineEdge(_rounded_square(45.0, 20.0, 0.25))
    xy = RNG.uniform(-75, 75, (4000, 2))
    assert np.abs(outline.distance(*xy.T) - exact.distance(*xy.T)).max() < 4.5e-4
    assert outline.length() == pytest.approx(exact.length(), rel=1e-5)
    assert outline.reach() == pytest.approx(45.0, abs=1e-9)
    s = np.linspace(-3.0, 6.0, 10)
    arc = np.c_[25 + (20 + s) * np.cos(np.pi / 4), 25 + (20 + s) * np.sin(np.pi / 4)]  # the arc's middle
    side = np.c_[45 + s, np.zeros_like(s)]  # a side's middle
    for pts in (arc, side):
        (s1, j1), (s0, j0) = outline.offset(*pts.T), exact.offset(*pts.T)
        assert s1 == pytest.approx(s0, abs=5e-4) and j1 == pytest.approx(j0, abs=1e-3)
    assert exact.offset(*arc.T)[1] == pytest.approx(20.0 / (20.0 + s))


def test_a_clockwise_outline_is_turned():
    pts = _rounded_square(10.0, 3.0, 0.2)
    a, b = OutlineEdge(pts), OutlineEdge(pts[::-1])
    xy = RNG.uniform(-20, 20, (500, 2))
    assert a.distance(*xy.T) == pytest.approx(b.distance(*xy.T), abs=1e-12)


def test_beyond_a_tips_radius_the_edge_weight_is_bounded():
    """An opening with a re-entrant corner: the flat top's tip, the plate's corner x, y >= 10
    rounded with 4 mm, points into it. On the holder's side of the tip the offset lines shorten
    as 1 - s/4, and j, their inverse, is held at 2 from s = 2 on (a band wider than the tip)."""
    angles = np.linspace(-np.pi / 2, -np.pi, 100)
    tip = np.array([14.0, 14.0]) + 4.0 * np.c_[np.cos(angles), np.sin(angles)]  # (14, 10) to (10, 14)
    opening = np.vstack([[[-30, -30], [30, -30], [30, 10]], tip, [[10, 30], [-30, 30]]])
    edge = OutlineEdge(opening)
    middle = np.array([14.0, 14.0]) - 4.0 / np.sqrt(2)
    inward = np.array([1.0, 1.0]) / np.sqrt(2)  # into the plate: the holder's side
    s = np.array([0.5, 1.0, 1.5, 3.0, 3.9])
    got, j = edge.offset(*(middle + s[:, None] * inward).T)
    assert got == pytest.approx(s, abs=2e-3)
    assert j == pytest.approx(1.0 / np.maximum(1.0 - s / 4.0, 0.5), rel=2e-2)
    assert edge.distance(np.array([0.0]), np.array([0.0]))[0] < 0  # the centre: over the opening


def test_pieces_chain_into_closed_loops_whatever_their_order_and_direction():
    square = [np.array([[0, 0, 0], [1, 0, 0.0]]), np.array([[1, 1, 0], [1, 0, 0.0]]),  # the second reversed
              np.array([[0, 1, 0], [0, 0, 0.0]]), np.array([[1, 1, 0], [0.5, 1, 0], [0, 1, 0.0]])]
    (loop,) = closed_loops(square, 1e-9)
    assert len(loop) == 5 and np.allclose(loop[0], [0, 0, 0])
    with pytest.raises(ValueError):
        closed_loops(square[:3], 1e-9)


@pytest.mark.parametrize("name", ["die.step", "die.stl"])
def test_the_numisheet_dies_flat_top_opening_is_its_rounded_square(name):
    """The NUMISHEET'93 die (STEP and STL): its flat top's inner loop is the rounded square
    (37 + 8, 12 + 8) where the holder begins: within 4e-4 mm (STEP, the sampling's sagitta) and
    0.03 mm (STL, 24 triangles a turn)."""
    from shellform.tools.mesh_tool import MeshTool
    from shellform.tools.surface_tool import SurfaceTool

    kind = MeshTool if name.endswith(".stl") else SurfaceTool
    die = kind.from_file(ROOT / "demos" / "meshes" / "numisheet93" / name)
    loops = die.flat_top_boundary()
    assert len(loops) == 2
    inner = OutlineEdge(min(loops, key=lambda p: np.ptp(p[:, 0]))[:, :2])
    xy = RNG.uniform(-75, 75, (3000, 2))
    error = np.abs(inner.distance(*xy.T) - RoundedSquareEdge(45.0, 20.0).distance(*xy.T)).max()
    assert error < (4e-4 if name.endswith("step") else 0.03)


def test_the_cross_dies_opening_is_read_for_the_holder():
    """The cross-shaped cup's die (scripts/cross_cup_step.py): the holder's edge reaches
    45 + 2 + 5 = 52 mm along an arm. Between the arms the die's opening has a re-entrant corner
    at (22, 22) rounded with 14 mm about (36, 36); the flat top begins 5 mm further, on the arc of
    radius 9 about (36, 36): on the diagonal at 36 - 9 / sqrt(2), the holder's edge."""
    from shellform import scene
    from shellform.tools.cad import cad_cup_tools

    s = scene.load(ROOT / "demos" / "cross_cup.toml")
    tools = cad_cup_tools(s.tools, s.material.thickness)
    edge = tools["holder"].edge
    assert edge.reach() == pytest.approx(52.0, abs=1e-6)
    apex = 36.0 - 9.0 / np.sqrt(2)
    d = edge.distance(np.array([apex - 1, apex + 1]), np.array([apex - 1, apex + 1]))
    assert d[0] < 0 < d[1]
    assert edge.distance(np.array([apex]), np.array([apex]))[0] == pytest.approx(0.0, abs=1e-3)


def test_the_cross_cup_draws_with_the_holder_on_the_dies_flat_top(tmp_path):
    """The cross-shaped cup on n = 8 to 5 mm: no cut-back, the holder closed and pinching over
    the die's flat top with every node's share under 10 % of its force, the z-balance to 1e-6."""
    from shellform import scene
    from shellform.contact import run as contact_run

    s = scene.load(ROOT / "demos" / "cross_cup.toml").changed({
        "mesh.n": 8, "tools.stroke": 5.0, "process.initial_step_mm": 0.1, "process.max_step_mm": 0.25,
        "process.report": [], "output.vtx": False, "output.vtu": False, "output.png": False, "output.fld": False})
    summary = contact_run.run(s, tmp_path / "cross")
    worst = summary["over_the_stroke"]
    assert summary["cutbacks"] == 0 and summary["stopped"] is None
    assert worst["force_balance"] < 1e-6
    assert 0.0 < worst["holder_largest_share"] < 0.1
    assert summary["punch_force_kN"][-1]["force"] > 10.0
