"""A tool placed by a rotation and a translation and moved along any axis
(shellform/tools/placement.py): the mapping tested apart from assembly, then in the scene."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
import pytest
from mpi4py import MPI

from shellform.tools.placement import Placed, rotation
from shellform.tools.analytic import Punch

ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]


def test_the_rotation_turns_about_x_then_y_then_z():
    ex, ey, ez = np.eye(3)
    assert rotation([90, 0, 0]) @ ey == pytest.approx(ez, abs=1e-15)
    assert rotation([0, 90, 0]) @ ez == pytest.approx(ex, abs=1e-15)
    assert rotation([0, 0, 90]) @ ex == pytest.approx(ey, abs=1e-15)
    assert rotation([90, 90, 0]) @ ey == pytest.approx(ex, abs=1e-15)  # e_y -> e_z (about x) -> e_x (about y)
    R = rotation([17, -40, 123])
    assert R @ R.T == pytest.approx(np.eye(3), abs=1e-15) and np.linalg.det(R) == pytest.approx(1.0)


def test_a_reflection_is_no_placement():
    with pytest.raises(ValueError):
        Placed(Punch(35.0, 10.0, 8.0, 0.0), np.diag([1.0, 1.0, -1.0]))


def test_the_placed_normal_and_hessian_are_the_derivatives_of_the_placed_gap():
    """A punch turned by (10, -20, 35) degrees, moved by (1, 2, 3) and by 4 mm along the axis
    (0.2, -0.1, 1): at points near its nose corner, on its flat face and beside its wall, the
    gap is the unplaced punch's at the point taken back to its frame, and central differences
    of the gap and of the normal in the scene's frame give n and H (to 1e-7 and 1e-5 of the
    largest curvature): the rotation carries n and H as a vector and a tensor."""
    punch = Punch(35.0, 10.0, 8.0, 0.0)
    R = rotation([10, -20, 35])
    placed = Placed(punch, R, (1.0, 2.0, 3.0), (0.2, -0.1, 1.0))
    a = np.array([0.2, -0.1, 1.0]) / np.linalg.norm([0.2, -0.1, 1.0])
    s = 4.0
    rng = np.random.default_rng(7)
    y = np.concatenate([[31.0, 31.0, -1.0] + rng.uniform(-1, 1, (20, 3)),  # the nose's corner
                        [10.0, 5.0, -2.0] + rng.uniform(-1, 1, (20, 3)),  # below the flat face
                        [37.0, 0.0, 15.0] + rng.uniform(-1, 1, (20, 3))])  # beside the wall
    x = y @ R.T + np.array([1.0, 2.0, 3.0]) + s * a
    g, n = placed.gap(x, 0.1, s)
    g0, n0 = punch.gap(y, 0.1, 0.0)
    assert g == pytest.approx(g0, abs=1e-12)
    assert n == pytest.approx(n0 @ R.T, abs=1e-14)
    H = placed.shape(x, 0.1, s)
    step = 1e-5
    for i in range(3):
        e = np.zeros(3)
        e[i] = step
        (gp, np_), (gm, nm) = placed.gap(x + e, 0.1, s), placed.gap(x - e, 0.1, s)
        assert (gp - gm) / (2 * step) == pytest.approx(n[:, i], abs=1e-7)
        assert (np_ - nm) / (2 * step) == pytest.approx(H[:, :, i], abs=1e-5 / 8.0)


def _cad_cup(**changes):
    from shellform import scene

    s = scene.load(ROOT / "demos" / "numisheet93_aluminium_cad.toml")
    return s.changed({"mesh.n": 8, "tools.stroke": 2.0, "process.initial_step_mm": 0.1, "process.max_step_mm": 0.2,
                      "process.report": [], "output.vtx": False,
                      "output.vtu": False, "output.png": False, "output.fld": False, **changes})


def test_a_square_punch_turned_a_quarter_about_z_draws_the_same_cup(tmp_path):
    """The STEP punch is square: turned by 90 degrees about z it is the same tool, and the run is
    the same to solver tolerance, its increments and iterations too."""
    from shellform.contact import run as contact_run

    a = contact_run.run(_cad_cup(), tmp_path / "a")
    b = contact_run.run(_cad_cup(**{"tools.punch_rotation": [0.0, 0.0, 90.0]}), tmp_path / "b")
    assert b["newton_iterations"] == a["newton_iterations"]
    assert b["punch_force_kN"][-1]["force"] == pytest.approx(a["punch_force_kN"][-1]["force"], rel=1e-7)
    assert b["draw_in_mm"][-1]["DX"] == pytest.approx(a["draw_in_mm"][-1]["DX"], rel=1e-6)


def test_a_punch_travelling_aslant_drags_the_sheet_and_the_sheet_stays_in_equilibrium():
    """The whole blank (no symmetry), the punch travelling along (0.1, 0, -1), 2 mm: the punch
    pulls the sheet along +x (friction on its face; about a sixth of its force here), the flange
    on the -x side draws in more than on the +x side, and the forces of the punch and the die
    (with the pinch) on the sheet balance in x, y and z to 1e-6 of the punch's force."""
    from shellform.contact.problem import DrawingProblem

    s = _cad_cup(**{"geometry.region": "full", "tools.punch_direction": [0.1, 0.0, -1.0],
                    "supports": {"left": "free", "right": "free", "top": "free", "bottom": "free"}})
    p = DrawingProblem.from_scene(s, MPI.COMM_WORLD)
    p.driver.run(1.0)
    punch, die = p.tool_force(0), p.tool_force(1)
    F = p.punch_force()
    assert F > 500.0
    assert punch[0] > 0.1 * F
    assert np.abs(punch + die).max() < 1e-6 * F
    u, x0 = p.driver.displacements(), p.initial_positions()
    rim = [int(np.argmin(np.abs(x0[:, 0] - side * 75.0) + np.abs(x0[:, 1]))) for side in (1, -1)]
    draw_in_plus, draw_in_minus = -u[rim[0], 0], u[rim[1], 0]
    assert draw_in_minus > 1.1 * draw_in_plus > 0


@pytest.mark.parametrize("changes, message", [
    ({"tools.punch_direction": [0.0, 0.0, 1.0]}, "down"),
    ({"tools.punch_direction": [0.1, 0.0, -1.0]}, "left"),  # the quarter's x = 0 symmetry
    ({"tools.punch_direction": [0.0, 0.0, 0.0]}, "non-zero"),
    ({"tools.punch_rotation": [0.0, float("nan"), 0.0]}, "finite"),
])
def test_bad_placements_name_the_field(changes, message):
    from shellform.errors import InputError

    with pytest.raises(InputError) as err:
        _cad_cup(**changes)
    field = "tools." + next(iter(changes)).split(".")[1]
    assert err.value.field == field and message in str(err.value)
