"""Coulomb friction, a part of the contact (shellform/contact/friction.py): the clamping force
it carries between flat tools, a slip reversal without flips, the cup's punch force, the
slipping force's normal-force term in the tangent, and friction per tool (a coefficient per
punch, die and holder)."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
import pytest
from mpi4py import MPI

from functools import lru_cache

from shellform import scene
from shellform.contact.problem import DrawingProblem
from shellform.results import cup
from shellform.assembly.sheet_element import BS
from shellform.contact.semi_inverse import FREE

from contact_cases import ROOT, drawn_cup, side_sum, square_cup, strip, tangent_error


def test_strip_dragged_between_flat_tools_carries_mu_times_the_clamping_force():
    """A strip pinched between a flat die and a flat holder (F = 1 kN) is pulled 2 mm at one
    end: once it slides, the pull equals mu times the sum of the normal forces on both faces
    (to 1e-8) and 2 mu F (to 1e-4); the holder's nodal forces sum to F at every increment, every
    node under it stays pinched, and no tangential force exceeds mu times its normal force."""
    mu, F = 0.15, 1000.0
    rect, d = strip(mu, F)
    comm = MPI.COMM_WORLD

    def check(dr):
        assert abs(dr.holder.total() - F) <= 1e-9 * F
        under = dr.holder.under(dr.positions())
        assert np.array_equal(dr.holder.pinched, under)  # no free node under the closed holder
        p = dr.contact.face_forces()
        ft = np.linalg.norm(dr.friction.force, axis=1)
        assert np.all(ft <= mu * p * (1 + 1e-8) + 1e-9)
        assert np.all(dr.contact.pressure[under] >= 0)

    d.run(1.0, on_increment=check)
    pull = side_sum(d, rect, ("right",), 0)
    normal = comm.allreduce(float(d.contact.face_forces().sum()), op=MPI.SUM)
    assert abs(pull - mu * normal) <= 1e-8 * mu * normal
    assert abs(pull - 2 * mu * F) <= 1e-4 * 2 * mu * F
    assert np.all(d.friction.slipping[d.contact.on(0)])  # the whole strip slides on the die


def test_slip_reversal_converges_without_friction_flips():
    """The strip pulled 1 mm, then pushed back 0.5 mm. A node's friction force never jumps
    from one side of the Coulomb cone to the other between Newton iterates (both at >= half the
    limit mu p), except once, in the first correction of the increment where the slip reverses
    (the return mapping goes through stick; and from rest, in the first increment, in the first
    two corrections); every Newton pass ends superlinearly; after the
    reversal the whole strip slides the other way with the pull reversed."""
    mu, F = 0.15, 1000.0
    rect, d = strip(mu, F, initial_step=0.05, max_step=0.05)
    sides, log = [], []
    constraints = d.constrain

    def record(lam):
        jump = constraints(lam)
        limit = mu * d.contact.face_forces()
        f = d.friction.force[:, 0]
        sides.append(np.sign(f) * (np.abs(f) >= 0.5 * limit) * (limit > 0))
        return jump

    d.constrain = record

    def check(dr):
        s = np.array(sides)
        jumps = s[1:] * s[:-1] < 0  # (iterate pairs, nodes): the force crossed the cone
        log.append((int(jumps.sum(axis=0).max()), int(jumps[1:].sum()), [list(r) for r in dr.pass_residuals]))
        sides.clear()

    d.run(0.5, on_increment=check)
    pull_forward = side_sum(d, rect, ("right",), 0)
    n_forward = len(log)
    d.run(0.25, on_increment=check)
    pull_back = side_sum(d, rect, ("right",), 0)
    # from rest (the first increment) every node starts sticking with no force: one crossing
    # is allowed there in its first two corrections
    assert all(per_node <= 1 for per_node, _, _ in log) and log[0][1] <= 1, [e[:2] for e in log]
    assert all(late == 0 for _, late, _ in log[1:]), [e[:2] for e in log]
    assert log[n_forward][0] == 1  # the reversal: one crossing, in the first correction
    assert all(e[0] == 0 for i, e in enumerate(log) if i not in (0, n_forward))
    assert pull_forward == pytest.approx(2 * mu * F, rel=1e-4)
    assert pull_back == pytest.approx(-2 * mu * F, rel=1e-4)
    on = d.contact.on(0)
    assert np.all(d.friction.slipping[on]) and np.all(d.friction.force[on, 0] > 0)
    tol = d.controls.rtol * d.scale  # Newton's tolerance: below it, round-off
    for _, _, passes in log:  # superlinear tails: above the tolerance, the last reduction is the
        for r in passes:      # best of the pass and at least 1e-2
            above = np.array([v for v in r[int(np.argmax(r)):] if v > tol])
            ratios = above[1:] / above[:-1]
            assert ratios.size == 0 or ratios[-1] <= 1e-2, r
            assert ratios.size < 2 or ratios[-1] < ratios[-2], r


def test_friction_raises_the_punch_force():
    """The trend of Fig. 7's runs (cup-paper), short: with friction 0.2 the cup needs more punch
    force at 3 mm than without friction, and draws in less."""
    out = {}
    for mu in (0.0, 0.2):
        effects = [e for e in scene.load(ROOT / "demos" / "square_cup.toml").effects if e != "friction" or mu > 0]
        s = square_cup(n=6, friction=mu, changes={"effects": effects, "process.initial_step_mm": 0.6,
                                            "process.max_step_mm": 1.5})
        p = DrawingProblem.from_scene(s, verbose=False)
        p.driver.run(3.0 / s.tools.stroke)
        X, x, _ = p.nodal_values()
        out[mu] = (p.punch_force(), np.abs(x[:, :2] - X).max())
    assert out[0.2][0] > 1.05 * out[0.0][0]
    assert out[0.2][1] < out[0.0][1]


def test_slip_tangent_carries_the_normal_force_change():
    """Newton updates the friction's normal forces at every iterate, so the tangent carries the
    slipping force's dependence on them, d(mu p m)/dq = mu m K_(i,n): on the cup drawn 2 mm, in
    the next increment's converged state (nodes slipping on the punch), the tangent's columns of
    the free nodes next to them match central differences of the residual on their tangential
    rows to 1e-6 of the largest entry (without the term: 1e-3, docs/contact.md)."""
    d, lam = drawn_cup(2.0)
    m = d.model
    slip = np.flatnonzero(d.friction.slipping & d.contact.on(0) & ~d.holder.pinched)
    assert slip.size > 0
    near = np.unique(m.dofs[np.isin(m.dofs, slip).any(axis=1)])
    free = [b for b in near if b < d.n_owned and d.contact.tool[b] == FREE][:3]
    rows = (BS * slip[:, None] + np.arange(2)).ravel()
    columns = [(j, np.eye(d.q.x.array.size)[j]) for j in (BS * b + k for b in free for k in range(BS))
               if j not in d.bc_dofs]
    error = tangent_error(d, lam, rows, columns)
    assert error <= 1e-6, error


def test_slip_tangent_on_the_known_columns_reaches_the_solve_through_the_lift():
    """The slipping force's normal-force term on a *known* column (the normal row of a node on
    the punch, its own or a neighbour's), which the assembled tangent cannot hold, enters the
    solve through the lift of the known corrections (Friction.lift_known): the element tangents'
    column and that term together match central differences of the residual on the slipping
    nodes' tangential rows along that node's normal, to 1e-6 of the largest entry (without the
    term the error is 3 % of it here; a node ironed between two faces keeps such a correction in every iterate,
    and Newton converged only linearly there, docs/cup.md)."""
    d, lam = drawn_cup(2.0)
    m = d.model
    slip = np.flatnonzero(d.friction.slipping & d.contact.on(0) & ~d.holder.pinched)
    assert slip.size > 0
    near = np.unique(m.dofs[np.isin(m.dofs, slip[:4]).any(axis=1)])
    on_punch = [b for b in near if b < d.n_owned and d.contact.tool[b] == 0][:4]
    d.linearize(lam)
    d.assemble_tangent()
    rows = np.setdiff1d((BS * slip[:, None] + np.arange(2)).ravel(), d.bc_dofs)  # not those of a symmetry line
    R0 = d.b.getArray()[rows].copy()
    frames, h = d.frames.copy(), 1e-6
    worst = size = without = 0.0
    for b in on_punch:
        j = BS * b + 2
        e = np.zeros(d.q.x.array.size)
        e[j] = 1.0
        element = d.apply_tangent(e)[rows]
        lifted = np.zeros(d.n_owned * BS)
        d.friction.lift_known(e, lifted)
        column = element - lifted[rows]
        q0 = d.q.x.array.copy()
        v = np.zeros_like(q0)
        v[BS * b: BS * b + 3] = frames[b, 2]  # the node's normal, the known row's direction
        sides = []
        for sign in (1.0, -1.0):
            d.q.x.array[:] = q0 + sign * h * v
            d.linearize(lam, tangent=False)
            sides.append(d.b.getArray()[rows].copy())
        d.q.x.array[:] = q0
        fd = (sides[0] - sides[1]) / (2 * h)
        worst = max(worst, np.abs(fd - column).max())
        without = max(without, np.abs(fd - element).max())
        size = max(size, np.abs(column).max())
    d.linearize(lam)
    assert np.isfinite(R0).all() and size > 0
    assert worst <= 1e-6 * size, worst / size
    assert without >= 1e-2 * size, without / size


def test_strip_between_a_die_and_a_holder_of_other_frictions_carries_each_face_with_its_own():
    """Friction per tool on a pinched node: the strip between a die of mu 0.05 and a holder of mu
    0.25 (F = 1 kN), pulled 2 mm. Both faces slip together, each with its own coefficient: once
    it slides, the pull equals mu_die sum d_i + mu_holder sum h_i (to 1e-8) and (mu_die +
    mu_holder) F (to 1e-4), as with one coefficient 0.15; every pinched node's coefficient lies
    between the two, and no tangential force exceeds mu_die d_i + mu_holder h_i."""
    mu_die, mu_holder, F = 0.05, 0.25, 1000.0
    rect, d = strip((mu_die, mu_holder), F)
    comm = MPI.COMM_WORLD

    def check(dr):
        die, holder = dr.contact.faces()
        ft = np.linalg.norm(dr.friction.force, axis=1)
        assert np.all(ft <= (mu_die * die + mu_holder * holder) * (1 + 1e-8) + 1e-9)
        mu = dr.friction.coefficient[dr.holder.pinched]
        assert np.all((mu >= mu_die) & (mu <= mu_holder))

    d.run(1.0, on_increment=check)
    pull = side_sum(d, rect, ("right",), 0)
    die, holder = d.contact.faces()
    limit = comm.allreduce(float(mu_die * die.sum() + mu_holder * holder.sum()), op=MPI.SUM)
    assert abs(pull - limit) <= 1e-8 * limit
    assert abs(pull - (mu_die + mu_holder) * F) <= 1e-4 * (mu_die + mu_holder) * F
    assert np.all(d.friction.slipping[d.contact.on(0)])


@lru_cache(maxsize=None)
def _drawn_6mm(**tools) -> dict:
    """The paper's cup on 6 x 6 drawn 6 mm with the tools keys (friction 0.1 from the demo): its
    punch force, draw-in, thickness strains (the peak and the mean over the nodes that start on
    the punch's flat face, x, y < 27 mm), Newton iterations and contact passes."""
    s = square_cup(n=6, changes={"process.initial_step_mm": 0.6, "process.max_step_mm": 1.5,
                                 **{f"tools.{k}": v for k, v in tools.items()}})
    p = DrawingProblem.from_scene(s, verbose=False)
    p.driver.run(6.0 / s.tools.stroke)
    X, _, e33 = p.nodal_values()
    face = np.all(X < 27.0, axis=1)
    h = p.driver.history
    return {"force": p.punch_force(), **cup.draw_in(p), **cup.peak_thinning(p), "face": float(e33[face].mean()),
            "iterations": sum(r.iterations for r in h), "passes": sum(r.contact["passes"] for r in h)}


def test_friction_per_tool_all_equal_is_the_one_coefficient():
    """tools.punch_friction, die_friction and holder_friction all equal to tools.friction (0.1)
    draw the same cup as tools.friction alone: every node's mu_i is then that coefficient exactly
    and each expression of friction.py reduces to the one coefficient's, so the punch force,
    draw-in (DX, DD), thinning, iterations and passes agree (to 1e-9; bit for bit in fact)."""
    one = _drawn_6mm()
    each = _drawn_6mm(punch_friction=0.1, die_friction=0.1, holder_friction=0.1)
    for key in ("force", "DX", "DD", "min_thickness_strain", "face"):
        assert each[key] == pytest.approx(one[key], rel=1e-9, abs=0.0), key
    assert (each["iterations"], each["passes"]) == (one["iterations"], one["passes"])


def test_a_lubricated_punch_thins_the_cup_more():
    """A lubricated punch (punch_friction 0.02, the die and holder 0.1) against 0.1 on every
    tool, and a dry one (0.3): the punch's friction holds the sheet on its face and nose, so
    with less of it the bottom slides over the punch and stretches more, and less of the cup
    comes from the flange. Ordered by the punch's coefficient: the peak thinning (on the punch's
    face where its corner nose begins) and the mean thinning of the bottom grow as it falls, the draw-in (DX, DD) shrinks.
    The punch force is not asserted (docs/contact.md: its numbers)."""
    lub = _drawn_6mm(punch_friction=0.02)
    base = _drawn_6mm()
    dry = _drawn_6mm(punch_friction=0.3)
    for key in ("min_thickness_strain", "face"):
        assert lub[key] < base[key] < dry[key] < 0, (key, lub[key], base[key], dry[key])
    for key in ("DX", "DD"):
        assert 0 < lub[key] < base[key] < dry[key], (key, lub[key], base[key], dry[key])
    assert lub["where_initial_xy_mm"] == base["where_initial_xy_mm"]  # the same node, at the nose
