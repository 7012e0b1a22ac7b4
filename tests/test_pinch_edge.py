"""The pinch's edge load (shellform/contact/pinch_edge.py): the strip that resolves it below the
sheet's thickness converges where the rigid pinch grows as 1/h, the lumped band's kernel and
total do not depend on the mesh, and the riding holder's lift."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
import pytest

from shellform.assembly.sheet_element import BS
from shellform.contact.pinch_edge import C_EDGE, EdgeLoad, Strip, edge_weights
from shellform.contact.problem import DrawingProblem
from shellform.material import SheetMaterial
from shellform.studies.cup_convergence import scene_of
from shellform.studies.pinch_edge import STIFFER, aluminium_strip


def test_c_edge_is_the_winkler_plates_holder_lobes():
    """C_EDGE = beta t / M times the holder's lobes of the plate on the two-sided foundation,
    w = (2 beta^2 M / k) e^(-beta x)(cos beta x - sin beta x), integrated numerically."""
    t, M, Ep = 0.8, 30.0, 7e4
    k, D = 4 * Ep / t, Ep * t**3 / 12
    beta = (k / (4 * D)) ** 0.25
    x = np.linspace(0.0, 40.0 / beta, 400001)
    p = k * 2 * beta**2 * M / k * np.exp(-beta * x) * (np.cos(beta * x) - np.sin(beta * x))
    holder = np.trapezoid(np.maximum(-p, 0.0), x)  # where the plate pushes up: the holder's face
    assert holder * t / M == pytest.approx(C_EDGE, rel=1e-6)
    assert beta * t == pytest.approx(12**0.25)


def test_the_strip_converges_where_the_rigid_pinch_grows_as_one_over_h():
    """The aluminium strip: with the sheet's own compliance the holder's edge force settles as
    h falls below t/8 (successive differences shrink, the last under 0.5 %) at 1.5 % of
    C_EDGE M_0 / t; with faces 10^4 times stiffer it grows about as 1/h from 0.4 to 0.1 mm."""
    strip = aluminium_strip()
    k = 2 * strip.E_ps / strip.t
    V = [strip.solve(strip.t / n, k, 0.0)["Vh_N_per_mm"] for n in (8, 16, 32, 64)]
    d = np.abs(np.diff(V))
    assert d[1] < d[0] and d[2] < d[1] and d[2] < 5e-3 * V[-1]
    r = strip.solve(strip.t / 64, k, 0.0)
    assert r["Vh_t_over_M0"] == pytest.approx(C_EDGE, rel=0.015)
    rigid = [strip.solve(h, STIFFER * k, 0.0)["Vh_N_per_mm"] for h in (0.4, 0.1)]
    assert rigid[1] / rigid[0] > 3.5


def test_the_strips_section_is_the_plates_bending_stiffness_when_elastic():
    """An elastic sheet's tabulated moment is D kappa, D = E' t^3 / 12."""
    mat = SheetMaterial(E=7e4, nu=0.3).pack()
    strip = Strip(mat, 0.8, 8.0, 0.5)
    D = 7e4 / (1 - 0.09) * 0.8**3 / 12
    kap = np.array([0.01, 0.1, 1.0])
    assert strip.section(kap)[1] == pytest.approx(D * kap, rel=1e-4)


@pytest.mark.parametrize("offset", [0.0, 0.13, 0.5, 0.77, 0.999])
def test_the_band_kernel_sums_to_one_over_rows_for_any_offset(offset):
    """Rows of nodes h apart parallel to the edge, the first at offset h: h sum w = 1."""
    h = 1.7
    s = (offset + np.arange(5)) * h
    assert h * edge_weights(s, np.full(s.size, h)).sum() == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("n", [16, 35])
def test_the_edge_load_totals_v_e_times_the_edges_length_on_every_mesh(n):
    """On the aluminium quarter at the start, the band's shares sum to V_e times the length of the
    holder's inner edge (a rounded square's quarter) within 1.5 % (1.011 and 0.994 of it; 0.981
    to 1.011 on n = 12 to 71: where the edge turns from a side into the corner, the Cartesian
    mesh's rows are not parallel to it); no node takes more than V_e times two cells of it."""
    p = DrawingProblem.from_scene(scene_of("aluminium", n), verbose=False)
    h = p.driver.holder
    x = p.driver.nodes.positions()
    e, band = h.edge_shares(x, h.under(x))
    assert band[e > 0].all()
    length = h.tool.edge.length() / 4  # the quarter's
    total = p.model.mesh.comm.allreduce(e.sum())
    assert total == pytest.approx(h.edge_load * length, rel=1.5e-2)
    assert e.max() <= 2 * h.edge_load * p.driver.nodes.cell_size.max()


@pytest.mark.parametrize("stretch", [0.93, 1.12])
def test_the_edge_load_stays_v_e_per_unit_length_of_the_edge_however_the_flange_stretches(stretch):
    """The flange on n = 24 moved to x = stretch X in plan (its rows stretch apart or crowd
    together at the holder's edge, which stays put): the band's shares, taken with the current
    areas and the current rows' spacing, still sum to V_e times the edge's length within 0.5 %
    (with the reference ones they were off by 1 / stretch^2, and the kernel's rows would not
    sum to 1)."""
    p = DrawingProblem.from_scene(scene_of("aluminium", 24), verbose=False)
    d, h = p.driver, p.driver.holder
    q = d.q.x.array.reshape(-1, BS)
    q[:, :2] = (stretch - 1.0) * d.nodes.X[:, :2]
    x = d.nodes.positions()
    e, band = h.edge_shares(x, h.under(x))
    length = h.tool.edge.length() / 4  # the quarter's
    assert p.model.mesh.comm.allreduce(e.sum()) == pytest.approx(h.edge_load * length, rel=5e-3)
    assert band[e > 0].all()


def test_the_riding_lift_is_micrometres_at_full_share_and_grows_as_one_over_f_squared():
    e = EdgeLoad(line_load=45.0, moment=28.6, thickness=0.81, plate_stiffness=3400.0)
    assert 1e-4 < e.riding_lift(1.0) < 3e-3
    assert e.riding_lift(0.5) == pytest.approx(4 * e.riding_lift(1.0))


def test_an_edge_load_of_another_sheet_solves_its_strip_again():
    """EdgeLoad.at (a sensitivity's differences in the material): the same sheet gives the same
    edge bit for bit; K 1 % higher raises V_e by a little less than 1 % (the moment at the
    shoulder is the plastic section's, K times its shape, less the elastic core's share)."""
    from shellform.contact.pinch_edge import strip_edge
    from shellform.studies.cup_hard import variant

    s = variant(16, "numisheet93_aluminium.toml")
    mat = s.hill79().pack()
    e = strip_edge(mat, s.material.thickness, s.tools.die_profile_radius)
    assert e.at(mat) == e
    ratio = e.at(s.with_material("K", 1.01 * s.material.K).hill79().pack()).line_load / e.line_load
    assert 1.005 < ratio < 1.0101
