"""The drawbead part (shellform/contact/drawbead.py): a line on the flange that restrains the
sheet's flow across it with F_r per unit length and pushes the binder open with F_u."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
import pytest
from mpi4py import MPI

from shellform.contact.drawbead import DrawbeadLine, _barycentric, _clip
from contact_cases import side_sum, strip


def test_a_line_is_shared_out_by_the_shape_functions_to_its_length():
    """A segment clipped to two triangles of the unit square: the pieces' lengths add up to the
    segment's length inside, a piece along a shared edge counts half in each triangle, and the
    shape functions at a point sum to 1."""
    tri = np.array([[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 1], [0, 1]]], dtype=float)
    t0, t1, edge = _clip(np.array([0.25, -1.0]), np.array([0.25, 2.0]), tri)
    inside = np.clip(t1 - t0, 0, None) * 3.0
    assert inside.sum() == pytest.approx(1.0, rel=1e-14) and not edge.any()
    t0, t1, edge = _clip(np.array([-1.0, -1.0]), np.array([2.0, 2.0]), tri)  # along the diagonal
    assert np.all(edge) and np.allclose(np.clip(t1 - t0, 0, None) * 3 * np.sqrt(2), np.sqrt(2))
    N = _barycentric(tri, np.array([[0.6, 0.3], [0.2, 0.7]]))
    assert np.allclose(N.sum(axis=1), 1.0) and np.all(N >= 0)


@pytest.mark.parametrize("mu, uplift", [(0.0, 0.0), (0.15, 20.0)])
def test_a_strip_pulled_across_a_drawbead_needs_its_restraining_force(mu, uplift):
    """The 100 x 20 strip pinched under a 1 kN holder and pulled 2 mm across a drawbead along
    x = 5 (F_r = 30 N/mm): once it slides, the pull is F_r times the line's length on the sheet
    (its width, narrowed by 3e-5 as the pulled strip contracts) plus the friction, mu times the
    normal forces on both faces (the holder's F and the die's F - F_u L, the uplift taking a
    share of the die's), to 1e-6; the holder's forces still sum to F."""
    F, Fr, width = 1000.0, 30.0, 20.0
    bead = DrawbeadLine(((5.0, -15.0), (5.0, 15.0)), restraint=Fr, uplift=uplift)
    rect, d = strip(mu, F, drawbeads=(bead,))
    d.run(1.0)
    comm = MPI.COMM_WORLD
    pull = side_sum(d, rect, ("right",), 0)
    L = comm.allreduce(float(d.drawbeads.length.sum()), op=MPI.SUM)
    assert L == pytest.approx(width, rel=1e-4) and L < width
    expected = Fr * L + mu * (2 * F - uplift * L)
    assert pull == pytest.approx(expected, rel=1e-6), (pull, expected)
    assert d.holder.total() == pytest.approx(F, rel=1e-9)
    assert d.drawbeads.total(comm)[2] == pytest.approx(uplift * L, rel=1e-12)


ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]
SIDES = [{"points": [[50.0, 0.0], [50.0, 75.0]], "restraint": 60.0, "uplift": 20.0},
         {"points": [[0.0, 50.0], [75.0, 50.0]], "restraint": 60.0, "uplift": 20.0}]


def _cup(beads=None, **changes):
    from shellform import scene

    s = scene.load(ROOT / "demos" / "square_cup.toml")
    more = {"effects": list(s.effects) + ["drawbeads"], "tools.drawbead": beads} if beads else {}
    return s.changed({"mesh.n": 6, "tools.stroke": 3.0, "process.initial_step_mm": 0.15, "process.max_step_mm": 0.3,
                      "process.report": [], "process.springback": False, "output.vtx": False, "output.png": False,
                      "output.fld": False, **more, **changes})


@pytest.mark.parametrize("bead, field", [
    ({"points": [[50.0, 0.0]], "restraint": 60.0}, "tools.drawbead[0].points"),
    ({"points": [[30.0, 0.0], [30.0, 75.0]], "restraint": 60.0}, "tools.drawbead[0].points"),  # in the opening
    ({"points": [[50.0, 0.0], [50.0, 75.0]], "restraint": -1.0}, "tools.drawbead[0].restraint"),
    ({"points": [[50.0, 0.0], [50.0, 75.0]]}, "tools.drawbead[0]"),  # no force
    ({"points": [[50.0, 0.0], [50.0, 75.0]], "restraint": 60.0, "depth": 3.0}, "tools.drawbead[0].depth"),
])
def test_bad_drawbeads_name_the_field(bead, field):
    from shellform.errors import InputError

    with pytest.raises(InputError) as err:
        _cup([bead])
    assert err.value.field == field


def test_a_drawbead_without_its_effect_names_the_key():
    from shellform.errors import InputError

    with pytest.raises(InputError) as err:
        _cup(**{"tools.drawbead": SIDES})
    assert err.value.field == "tools.drawbead"


def test_the_square_cup_with_a_drawbead_along_each_side_draws_in_less(tmp_path):
    """The paper's cup (6 x 6 quarter, 3 mm) with a bead along each side of the flange, 50 mm
    from the centre (F_r = 60 N/mm, F_u = 20 N/mm): the flange draws in less along the axes (half,
    here) and the punch pulls
    harder; at every increment the sheet's z-balance, the beads' uplift included, closes to 1e-6."""
    from shellform.contact import run as contact_run

    plain = contact_run.run(_cup(), tmp_path / "plain")
    beads = contact_run.run(_cup(SIDES), tmp_path / "beads")
    a, b = plain["reports"][-1], beads["reports"][-1]
    assert b["draw_in_mm"]["DX"] < 0.9 * a["draw_in_mm"]["DX"]
    assert b["punch_force_kN"] > a["punch_force_kN"]
    assert beads["over_the_stroke"]["force_balance"] <= 1e-6
