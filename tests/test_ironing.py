"""Ironing (issue 45): the sheet's thickness bounded by the clearance between two tools
(shellform.material.ironing). The section's added resultants and tangents are checked against
the energy they derive from, apart from any assembly, and the element's tangent against its
forces; then a strip squeezed between faces and a strip drawn through a gap against the closed
forms of plane-strain flow (shellform.studies.ironing); then a cup's flange under a holder held
at a gap (shellform.contact.ironing)."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from shellform import scene
from shellform.contact import run as contact_run
from shellform.errors import InputError
from shellform.material.ironing import squeeze, through_thickness_modulus
from shellform.studies import ironing, strip

T0, M = 1.0, 1.0e5
WEIGHTS = np.array([0.4, 0.6])  # two points of a cell, weights summing to 1


def thickness(E):
    """t0 / J of the points' membrane strains (points, 3)."""
    return T0 / np.sqrt((1 + 2 * E[:, 0]) * (1 + 2 * E[:, 1]) - E[:, 2] ** 2)


def energy(E, gap):
    """phi(t_bar) = M / (2 t0) <t_bar - gap>^2 per unit initial area (the module docstring)."""
    return 0.5 * M / T0 * max(WEIGHTS @ thickness(E) - gap, 0.0) ** 2


def pressed(E, gap):
    e = np.zeros((1, len(WEIGHTS), 6))
    e[0, :, :3] = E
    S, D, p = np.zeros((1, 2, 6)), np.zeros((1, 2, 6, 6)), np.zeros((1, 2))
    d, ironed = np.zeros((1, 2, 3)), np.zeros((1, 11))
    count = squeeze(e, np.array([gap]), T0, M, WEIGHTS, S, D, p, d, ironed)
    return count, S[0], D[0], p[0], d[0], ironed[0, 0]


STRAINS = [[(0.02, -0.05, 0.03), (0.01, -0.04, 0.02)], [(-0.04, -0.03, 0.0), (-0.05, -0.02, 0.01)]]


@pytest.mark.parametrize("E", STRAINS)
def test_the_resultants_and_tangents_derive_from_the_cells_energy(E):
    """On a cell of two points, by central differences of A0 phi(t_bar) (Voigt E11, E22, 2 E12):
    w_g N_g = dphi/dE_g, and dN_g/dE_h = D_g (h = g) plus the rank-one phi'' w_h d_g d_h^T that the
    element loop adds, to 1e-6 of their size; N_g = -p_g J_g t_g C_g^-1 (the Cauchy membrane
    force -p t I pulled back), and no moment (the same pressure in every layer)."""
    E = np.array(E, dtype=float)
    gap = 0.9 * WEIGHTS @ thickness(E)  # 10 % thinner than the sheet
    count, S, D, p, d, k = pressed(E, gap)
    assert count == (2, 0) and k == M / T0
    h = 1e-6
    for g in range(2):
        dE = lambda i, sign: E + sign * h * np.outer(np.eye(2)[g], np.eye(3)[i])  # noqa: E731
        N_fd = np.array([(energy(dE(i, 1), gap) - energy(dE(i, -1), gap)) / (2 * h) for i in range(3)]) / WEIGHTS[g]
        assert np.allclose(S[g, :3], N_fd, rtol=0, atol=1e-6 * np.abs(N_fd).max())
        for other in range(2):
            D_fd = np.array([(pressed(E + h * np.outer(np.eye(2)[other], np.eye(3)[j]), gap)[1][g, :3]
                              - pressed(E - h * np.outer(np.eye(2)[other], np.eye(3)[j]), gap)[1][g, :3]) / (2 * h)
                             for j in range(3)]).T
            model = k * WEIGHTS[other] * np.outer(d[g], d[other]) + (D[g, :3, :3] if other == g else 0.0)
            assert np.allclose(model, D_fd, rtol=0, atol=1e-6 * np.abs(D_fd).max())
        C = np.array([[1 + 2 * E[g, 0], E[g, 2]], [E[g, 2], 1 + 2 * E[g, 1]]])
        B, J = np.linalg.inv(C), np.sqrt(np.linalg.det(C))
        assert np.allclose(S[g, :3], -p[g] * J * (T0 / J) * np.array([B[0, 0], B[1, 1], B[0, 1]]), rtol=1e-12, atol=0)
        assert np.allclose(D[g, :3, :3], D[g, :3, :3].T, rtol=0, atol=1e-9 * np.abs(D).max())
    assert not np.any(S[:, 3:]) and not np.any(D[:, 3:, :]) and not np.any(D[:, :, 3:])


def test_a_sheet_thinner_than_the_clearance_is_not_pressed():
    E = np.array([(0.05, 0.05, 0.0), (0.05, 0.05, 0.0)])  # t = t0 / 1.1
    count, S, D, p, d, k = pressed(E, 0.95 * T0)
    assert count == (0, 0) and not np.any(p) and not np.any(S) and not np.any(D) and k == 0.0
    assert pressed(E, np.inf)[0] == (0, 0)


def test_a_pressed_point_turned_inside_out_fails():
    """det C <= 0: no thickness; the driver cuts back (the strain guard's count)."""
    count = pressed(np.array([(-0.6, 0.0, 0.0), (0.0, 0.0, 0.0)]), 0.5)[0]
    assert count == (0, 1)


@pytest.mark.parametrize("effects, turning", [((), False), (("assumed_membrane",), False), ((), True)],
                         ids=["compatible", "assumed", "turning faces"])
def test_the_element_tangent_is_the_derivative_of_its_forces_when_pressed(effects, turning):
    """An elastic sheet at a random state, every cell pressed: clearance 0.97 t0 at the state,
    moving with the vertices along random gradients n_i (c = 0.97 t0 + sum_i n_i . (u_i - u_i0) / 3,
    as a tool's face moves the clearance), and with `turning` faces whose gradients turn with the
    vertices by random symmetric H_i (c_i gains (u_i - u_i0) . H_i (u_i - u_i0) / 2, n_i becomes
    n_i + H_i (u_i - u_i0): two curved tools). Each cell's tangent (its points' rank-one coupling,
    the faces' push on its vertices and that push's turn -phi' A0 / 3 H_i included) equals the
    central difference of its forces, the push included, along a random direction to 1e-7 (seen
    1e-10), with the compatible and the assumed membrane strain; without the turn's term the
    turning faces' tangent misses by 3e-3."""
    from dolfinx import fem
    from mpi4py import MPI

    from shellform.material import Hill79Material
    from shellform.mesh import rectangle
    from shellform.nonlinear.model import SheetModel

    rect = rectangle(MPI.COMM_SELF, 4.0, 2.0, region="quarter", n=2)
    m = SheetModel(rect.mesh, Hill79Material(E=70000.0, nu=0.3).pack(), 1.0,
                   ("bending", "membrane", "geometric_nonlinearity", "ironing") + effects)
    rng = np.random.default_rng(0)
    q = fem.Function(m.V)
    q.x.array[:] = 0.02 * rng.standard_normal(q.x.array.size)
    n = rng.standard_normal((m.num_cells, 3, 3))
    n /= np.linalg.norm(n, axis=2)[..., None]
    u0 = q.x.array[m.unrolled_dofs].reshape(m.num_cells, 3, 9)[:, :, :3].copy()
    H = rng.standard_normal((m.num_cells, 3, 3, 3)) * turning
    H = 0.5 * (H + H.transpose(0, 1, 3, 2))

    def evaluate(state):
        du = state.x.array[m.unrolled_dofs].reshape(m.num_cells, 3, 9)[:, :, :3] - u0
        turned = n + np.einsum("ciab,cib->cia", H, du)
        c = 0.97 + (np.einsum("cia,cia->c", n, du) + 0.5 * np.einsum("cia,ciab,cib->c", du, H, du)) / 3.0
        m.squeeze(c, turned, H)
        m.evaluate(state)

    evaluate(q)
    assert np.all(m.ironed[:, 0] > 0)
    K = m.forms.matrices.copy()
    dq, h = rng.standard_normal(q.x.array.size), 1e-6
    forces = []
    for sign in (1, -1):
        qs = fem.Function(m.V)
        qs.x.array[:] = q.x.array + sign * h * dq
        evaluate(qs)
        forces.append(m.forms.vectors.copy())
    fd = (forces[0] - forces[1]) / (2 * h)
    assert np.abs(fd - np.einsum("cij,cj->ci", K, dq[m.unrolled_dofs])).max() < 1e-7 * np.abs(fd).max()


def test_the_through_thickness_modulus_is_the_p_wave_modulus():
    mat = strip.mild_steel().pack()
    assert through_thickness_modulus(mat) == pytest.approx(206e3 * 0.7 / (1.3 * 0.4), rel=1e-14)


def test_squeezed_plane_strain_meets_the_clearance_with_the_flow_stress():
    """The strip squeezed to 0.8 t0 in 10 increments between frictionless faces: its thickness
    strain is ln 0.8 to 0.005 (seen 0.0039: the penalty's overclosure phi' / M, 0.2 %, and the
    layers' elastic thickness strain, which knows nothing of sigma33), and the faces press with the plane-strain
    flow stress (2 / sqrt 3) sigma_f((2 / sqrt 3) ln 1.25) to 1 % (its plastic strain falls short
    of the total by the elastic strain, sigma / E, 0.2 %: the model lies 0.5 % below)."""
    mat = strip.mild_steel()
    _, e33, pressure = ironing.squeezed(mat, 0.8)
    assert e33 == pytest.approx(np.log(0.8), abs=5e-3)
    closed = ironing.plane_strain_stress(mat, np.log(1.25))
    assert pressure == pytest.approx(closed, rel=1e-2)
    assert pressure < closed


def test_a_clearance_needs_the_effect_and_one_value_per_cell():
    p, _, _ = ironing.squeezed(strip.mild_steel(), 0.99, steps=1, n=1)
    m = p.model
    with pytest.raises(InputError, match="clearance"):
        m.squeeze(np.full(m.num_cells + 1, 0.9))
    with pytest.raises(InputError, match="clearance"):
        m.squeeze(np.full(m.num_cells, -0.9))
    plain = strip.strip(strip.mild_steel(), 1.01, steps=1)[0].model
    with pytest.raises(InputError, match="effects"):
        plain.squeeze(np.full(plain.num_cells, 0.9))


@pytest.mark.slow
def test_a_strip_drawn_through_a_gap_comes_out_at_the_gap_with_the_ideal_force():
    """The strip (0.25 mm cells) drawn 5 mm through a die narrowing from t0 to 0.9 t0 over 2 mm
    with a 2 mm land, frictionless: the cells drawn through come out at ln 0.9 to 0.005 (0.3 % of
    the thickness), and the pull over the steady window (from 2.5 mm on, after the die has
    closed and filled) averages the ideal work's t1 sigma_d within 2 % (seen -1.6 %). The force
    varies by about 7 % around it as the cells enter the die one by one."""
    mat = strip.mild_steel()
    _, rows = ironing.drawn(mat, 0.9, 5.0, cells=80)
    assert rows[-1]["cells_past_exit"] >= 2
    assert rows[-1]["exit_thickness_strain"] == pytest.approx(np.log(0.9), abs=5e-3)
    u = np.array([r["pull"] for r in rows])
    F = np.array([r["force_per_width"] for r in rows])
    steady = u >= 2.5
    mean = np.trapezoid(F[steady], u[steady]) / (u[steady][-1] - u[steady][0])
    assert mean == pytest.approx(0.9 * ironing.drawing_stress(mat, 0.9), rel=2e-2)


# -- the sheet's faces between two tools, as the contact sees them -------------------------------
class Plane:
    """A flat rigid face at height z0 whose normal (towards the sheet) is +e_z (up) or -e_z."""

    axis = (0.0, 0.0, 1.0)

    def __init__(self, z0, up):
        self.z0, self.up = z0, up

    def gap(self, x, offset, dz=0.0):
        d = (x[:, 2] - self.z0) if self.up else (self.z0 - x[:, 2])
        return d - offset, np.tile((0.0, 0.0, 1.0 if self.up else -1.0), (len(x), 1))


def test_between_two_faces_the_contact_sees_the_sheet_at_the_bounded_thickness():
    """Two parallel faces 1.2 apart (z = 0 up, z = 1.2 down). A node 1.3 thick lying on the lower
    face penetrates the upper one by 0.1, the ironing's overclosure (the faces' bound is the
    ironing's, on the cells' mean thickness): bounded, its faces lie at c / 2 = 0.6 from its
    mid-surface, the gaps to both faces sum to 0 and neither holds an overclosure, so that on
    either face the node lies in the clearance's middle. A node thinner than the clearance and a
    node whose other face is beyond the band keep their thickness (ContactSet.bound_by,
    Ironing.half_thickness)."""
    from types import SimpleNamespace

    from shellform.contact.contact_set import ContactControls, ContactSet
    from shellform.contact.ironing import Ironing

    x = np.array([[0.0, 0.0, 0.65], [0.0, 0.0, 0.55], [0.0, 0.0, 0.0]])
    nodes = SimpleNamespace(n_owned=3, half_thickness=np.array([0.65, 0.55, 0.5]))
    contact = ContactSet(nodes, [Plane(0.0, True), Plane(1.2, False)], [0.0, 0.0], ContactControls(1e-3), 1.0)
    raw = contact.gaps(x, 0.0)
    contact.bound_by(Ironing(SimpleNamespace(num_cells=0), nodes, contact))
    bounded = contact.gaps(x, 0.0)
    assert np.allclose(raw[0][0], [0.0, 0.0, -0.5]) and np.allclose(raw[1][0], [-0.1, 0.1, 0.7])
    assert np.allclose(bounded[0][0], [0.05, 0.0, -0.5]) and np.allclose(bounded[1][0], [-0.05, 0.1, 0.7])
    assert bounded[0][0][0] + bounded[1][0][0] == pytest.approx(0.0, abs=1e-14)  # the middle: both gaps 0 there
    assert np.allclose(contact.gaps(x, 0.0, bounded=False)[1][0], raw[1][0])


# -- the tools' clearance in a drawn cup: a holder at a gap ---------------------------------------
ROUND = Path(__file__).resolve().parents[1] / "demos" / "round_cup.toml"
IRONING = ["bending", "membrane", "geometric_nonlinearity", "plasticity", "anisotropy", "finite_strain", "contact",
           "friction", "ironing"]


def gap_scene(**changes):
    return scene.changed(scene.load(ROUND), {"effects": IRONING, "tools.holder": "gap", "tools.holder_gap": 1.04,
                                              **changes})


@pytest.mark.parametrize("changes, field", [
    ({"effects": IRONING[:-1]}, "tools.holder"),
    ({"tools.holder_gap": 0.9}, "tools.holder_gap"),
    ({"tools.holder": "clamp"}, "tools.holder"),
    ({"tools.holder": "force"}, "tools.holder_gap"),
])
def test_a_holder_at_a_gap_is_checked_naming_the_field(changes, field):
    with pytest.raises(InputError, match=field.replace(".", r"\.")):
        gap_scene(**changes)


def test_a_holder_at_a_gap_irons_the_flange_to_the_gap(tmp_path):
    """The round cup's flange held at a 1.0 mm gap (the sheet's thickness) drawn 6 mm on 8 cells
    along the radius: the flange thickens into the gap and the faces iron it, so no cell is
    thicker than the gap by more than 1 % (seen 0.52 %: the penalty's overclosure phi' / M at the
    faces' pressure, which a face at the sheet's own thickness drives to about a GPa, and the
    layers' elastic thickness strain), the holder's force is a result (the faces' pressure), and
    the tools' z-forces balance."""
    s = gap_scene(**{"tools.holder_gap": 1.0, "mesh.n": 8, "tools.stroke": 6.0, "output.png": False,
                     "output.vtx": False, "output.fld": False, "process.springback": False, "process.report": []})
    contact_run.run(s, tmp_path)
    rows = list(csv.DictReader(open(tmp_path / "force_stroke.csv")))
    holder = np.array([float(r["holder_force_kN"]) for r in rows])
    assert holder[-1] > 1.0  # kN: the flange presses the holder's face
    assert max(float(r["force_balance"]) for r in rows) < 1e-5
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["stopped"] is None
    assert summary["max_thickening_strain"] < np.log(1.01)


@pytest.mark.slow
def test_the_round_cup_with_ironing_is_drawn_through(tmp_path):
    """demos/round_cup.toml with the effect 'ironing', drawn 45 mm on its 279 cells (2 min): the
    rim, thickened to about 1.4 mm, is ironed into the 1.2 mm clearance and passes the die's
    shoulder (without 'ironing' the run stops at 36 mm): the run does not stop, the punch force
    falls from its peak (36.7 kN) below a tenth of it once the rim is through (1.6 kN seen), the
    rim lies below the shoulder's foot, 10.5 mm under the die's top (12.5 seen), and the tools'
    z-forces balance to 3e-6 of the peak punch force over the whole stroke: the z-sum of the
    residual Newton leaves at rtol 1e-6 (2.3e-6, 0.083 N, seen; 31 times less at rtol 1e-7:
    docs/contact.md, "The z-balance is the residual Newton leaves"; relative to the punch force
    of the moment, 1.4e-5 where the rim slides in the clearance at 1.6 kN)."""
    s = scene.changed(scene.load(ROUND), {"effects": IRONING, "tools.stroke": 45.0, "output.png": False,
                                          "output.vtx": False, "output.fld": False, "process.springback": False})
    contact_run.run(s, tmp_path)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["stopped"] is None
    rows = list(csv.DictReader(open(tmp_path / "force_stroke.csv")))
    force = np.array([float(r["punch_force_kN"]) for r in rows])
    assert force[-1] < 0.1 * force.max()
    assert max(float(r["force_balance"]) * abs(f) for r, f in zip(rows, force)) < 3e-6 * force.max()
    rim = list(csv.DictReader(open(tmp_path / "rim.csv")))
    assert max(float(r["z_mm"]) for r in rim) < -10.5
