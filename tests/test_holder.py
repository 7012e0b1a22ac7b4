"""The pinching blank holder (shellform/contact/holder.py and the contact driver): a cup drawn
without a holder force, the open holder as a rigid face that carries its force, and its lift
step solved with the sheet as exact Newton."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
import pytest

from shellform.nonlinear.frames import from_frames
from shellform.contact.contact_set import FREE
from shellform.contact.problem import DIE, HOLDER, DrawingProblem
from shellform.assembly.sheet_element import BS

from contact_cases import square_cup


@pytest.mark.parametrize("force", [0.0, 4.0])
def test_cup_without_a_holder_force_draws(force):
    """BHF = 0 (no holder) and 4 N (a holder that the flange lifts): the cup draws its first
    millimetre, the holder open, with the tools in balance and no penetration."""
    s = square_cup(blank_holder_force=force)
    p = DrawingProblem.from_scene(s, verbose=False)
    p.driver.run(1.0 / s.tools.stroke)
    d = p.driver
    assert p.stroke == pytest.approx(1.0)
    assert not d.holder.closed and p.free_under_holder() == 0
    assert p.holder_force() == pytest.approx(force, abs=1e-9)
    assert p.force_balance() <= 1e-6
    assert p.max_penetration() <= 0.01 * s.material.thickness
    assert p.punch_force() > 0


def test_an_open_holder_stays_a_rigid_face_that_carries_its_force():
    """A light holder (400 N) cannot hold the pinch's edge: riding on it would lift it by more
    than the contact tolerance (pinch_edge.EdgeLoad.riding_lift, 1.7 mm), so it opens at the
    first increment and stays open to 4 mm, a rigid face at its own lift, solved with the sheet in
    each Newton iteration: the flange turning onto the shoulder tilts and lifts it (0.56 mm at
    4 mm), never by more than riding on the edge would; its nodes' forces sum to F (to Newton's
    tolerance), no node under it passes its face, the tools balance to Newton's tolerance, and
    Newton's last pass converges fast (each step at least 5 times smaller, from its second
    iterate) in at most 4 iterations."""
    s = square_cup(blank_holder_force=400.0)
    p = DrawingProblem.from_scene(s, verbose=False)
    F = s.tools.blank_holder_force
    tol = 0.01 * s.material.thickness
    h = p.driver.holder
    edge = h.edge_load * h.tool.edge.length()  # V_e times the edge's length
    assert h.edge_law.riding_lift(F / edge) > tol

    def check(d):
        assert not d.holder.closed
        # its force and the tools' balance to Newton's tolerance (rtol of the residual's scale, per
        # quarter; an iterate may converge on a round-off correction, module docstring of newton.py)
        assert abs(p.holder_force() - F) <= 4 * d.controls.rtol * d.scale
        assert p.force_balance() * p.punch_force() <= 4 * d.controls.rtol * d.scale
        assert p.max_penetration() <= tol  # the open face included
        assert -tol < p.holder_lift() <= h.edge_law.riding_lift(F / edge) and p.in_contact()["holder"] > 0
        last = d.pass_residuals[-1][1:]
        assert len(last) <= 5 and all(b <= a / 5 for a, b in zip(last, last[1:]))

    p.driver.run(4.0 / s.tools.stroke, on_increment=check)
    assert p.holder_lift() > 10 * tol  # lifted by the tilted flange, not held at micrometres
    assert p.stroke == pytest.approx(4.0)


def test_the_open_holders_lift_step_is_exact_newton():
    """The lift is solved with the sheet (a bordered system). From the open state at 1.25 mm
    (400 N holder, its nodes slipping) with F lowered by 1 %, at the first Newton iterate
    (its nodes still slipping), central differences of the residual along the next Newton
    direction (dq, dz_H) equal -R on the slipping holder nodes' tangential rows and on the
    holder's equation, to 1.2e-5 of |R| (h = 1e-4), against 0.68 without the slip forces' dp/dq
    on the known columns (Part.lift_known). Not at the converged state itself: its yielded
    layers sit on their yield surface and its slipping nodes on the friction cone, kinks that
    differences straddle (0.12 there; it read 1.2e-4 while the layers' lever lagged an increment
    and moved them off their surface)."""
    s = square_cup(blank_holder_force=400.0)
    p = DrawingProblem.from_scene(s, verbose=False)
    d = p.driver
    d.run(1.25 / s.tools.stroke)
    lam, slip = d.lam, np.flatnonzero(d.friction.slipping & d.contact.on(HOLDER))
    assert not d.holder.closed and slip.size > 0
    rows = (BS * slip[:, None] + np.arange(2)).ravel()
    d.holder.force *= 0.99
    q0, lift0, lifted = d.q.x.array.copy(), d.holder.lift, d.friction.lift_known

    def residual(h=0.0, dq=0.0, dz=0.0):
        d.q.x.array[:] = q0 + h * dq
        d.holder.lift = lift0 + h * dz
        d.linearize(lam)
        return np.append(d.b.getArray()[rows], d.holder.imbalance())

    def newton():
        R = residual()
        assert d.solve(0.0)
        dz = d.holder.border(d)
        dq = d.dq.x.array.copy()
        from_frames(dq, d.rotated, d.frames)
        return R, dq, dz

    _, dq, dz = newton()
    q0, lift0 = q0 + dq, lift0 + dz  # the first iterate
    assert np.all(d.friction.slipping[slip])
    errors = {}
    for exact in (True, False):
        d.friction.lift_known = lifted if exact else (lambda delta, b: None)
        R, dq, dz = newton()
        h = 1e-4
        change = (residual(h, dq, dz) - residual(-h, dq, dz)) / (2 * h)
        errors[exact] = np.abs(change + R).max() / np.abs(R).max()
    assert errors[True] <= 1e-3 and errors[False] >= 0.1, errors


def _open_at_one_mm():
    s = square_cup(blank_holder_force=400.0)
    p = DrawingProblem.from_scene(s, verbose=False)
    p.driver.run(1.0 / s.tools.stroke)
    d = p.driver
    assert not d.holder.closed and d.contact.on(HOLDER).sum() > 0
    d.holder.edge_law = None  # it rides on any edge: closing is the lift's decision alone
    return d


def test_the_holder_decides_and_the_set_moves_its_nodes_when_it_closes():
    """The holder reads the set through its view and returns its decisions; the set applies
    them (holder.py, contact_set.py). From the open state at 1 mm (400 N), a lift below its
    closed position closes it at the set's update: its face's nodes go back onto the die, pinched,
    with the die-minus-holder sign of their net normal forces (the set turns it)."""
    d = _open_at_one_mm()
    h, c = d.holder, d.contact
    face = c.on(HOLDER).copy()
    net = c.net_normal_forces()[face]
    h.lift = -0.1
    change = c.update(d.lam, 0)
    assert h.closed and change.changes >= 1
    assert c.on(DIE)[face].all() and h.pinched[face].all() and not c.on(HOLDER).any()
    # the split of the turned R0 (die minus holder = -net): its faces h - d = net on each node
    assert np.allclose(h.face[face] - c.pressure[face], net, rtol=0.0, atol=1e-9 * np.abs(net).max())


def test_an_open_holder_that_touches_nothing_comes_down_onto_the_nearest_node():
    """From the open state at 1 mm (400 N) with its face's nodes let go and the face 0.5 mm
    higher, the set's update lowers it by the gap to the nearest node under it, which joins its
    face; it stays open."""
    d = _open_at_one_mm()
    h, c = d.holder, d.contact
    c.assign(c.on(HOLDER), FREE)
    h.lift = h.lift + 0.5
    x = d.nodes.positions()
    gap = h.face_gap(x, d.nodes.half_thickness)[0][h.under(x)]
    lift = h.lift
    c.update(d.lam, 0)
    assert not h.closed
    assert h.lift == pytest.approx(lift - gap.min(), abs=1e-12)
    assert c.on(HOLDER).sum() >= 1


def test_the_pinch_holds_the_slopes_of_a_mid_surface_on_the_die():
    """The pinched nodes' known slopes are the gradient of their half thickness (the mid-surface
    a half thickness above the flat die), exact for a linear field on the mesh, zero on the
    virgin sheet; in the increment after a drawn millimetre the pinched nodes' slopes are those
    of the thickness at its start (the thickness is updated with each converged increment)."""
    s = square_cup()
    p = DrawingProblem.from_scene(s, verbose=False)
    n = p.driver.nodes
    X = n.X[: n.n_owned]
    assert np.abs(n.gradient(0.3 * X[:, 0] - 0.7 * X[:, 1] + 2.0) - [0.3, -0.7]).max() < 1e-12
    assert np.abs(n.surface_slopes).max() == 0.0
    p.driver.run(1.0 / s.tools.stroke)
    start = n.surface_slopes.copy()  # the thickness after the first millimetre: the next increment's targets
    assert np.abs(start).max() > 1e-8
    p.driver.run(1.2 / s.tools.stroke)
    pinched = p.driver.holder.pinched
    held = n.interior(pinched)
    edge = pinched & ~held  # the pinch's boundary: a cell reaches beyond the faces, the slopes are the sheet's
    assert held.sum() > 0 and edge.sum() > 0
    assert np.abs(n.slopes()[held] - start[held]).max() <= p.driver.contact.known_tolerance  # met as known values are
    assert np.abs(n.slopes()[edge] - start[edge]).max() > 1e-2  # turning onto the shoulder


def _plane_fits(cells, centroids, values, weights, X, n_nodes):
    """Per node, the value at the node of the plane fitted by weighted least squares to its cells'
    values at their centroids, or their weighted mean where they do not fix a plane: the
    recovery, written out."""
    out = np.empty(n_nodes)
    for i in range(n_nodes):
        c, k = np.nonzero(cells == i)
        w = weights[c, k]
        c, w = c[w > 0], w[w > 0]
        A = np.column_stack([np.ones(len(c)), centroids[c] - X[i]])
        if len(c) < 3 or np.linalg.matrix_rank(A, tol=1e-6 * np.abs(A).max()) < 3:
            out[i] = np.sum(w * values[c]) / np.sum(w)
        else:
            out[i] = np.linalg.lstsq(A * np.sqrt(w)[:, None], values[c] * np.sqrt(w), rcond=None)[0][0]
    return out


def test_the_nodes_recover_a_linear_cell_field_exactly_up_to_the_blank_s_edge():
    """SheetNodes.recover takes a per-cell field to the nodes exactly for a linear field, on the
    blank's edge too (but at a corner whose cells do not fix a plane, where it takes their mean);
    the cells' mean there lags by the gradient times a third of a cell."""
    p = DrawingProblem.from_scene(square_cup(), verbose=False)
    n, m = p.driver.nodes, p.driver.model
    X = n.X[: n.n_owned, :2]
    centroids = m.cell_centres()
    g = np.array([0.3, -0.7])
    recovered = n.recover(centroids @ g + 2.0)
    exact = X @ g + 2.0
    cells = m.dofs.reshape(-1, 3)
    count = np.bincount(cells.ravel(), minlength=n.n_owned)[: n.n_owned]
    rim = np.isclose(X.max(axis=1), X.max())
    assert np.abs(recovered - exact)[count >= 3].max() < 1e-12
    assert rim.sum() > 10 and (count[rim] >= 3).sum() >= 0.8 * rim.sum()
    area = np.repeat(m.cell_area[:, None], 3, axis=1)
    mean = np.bincount(cells.ravel(), (area * (centroids @ g + 2.0)[:, None]).ravel(), n.n_owned) / \
        np.bincount(cells.ravel(), area.ravel(), n.n_owned)
    assert np.abs(mean - exact)[rim & (count >= 3)].min() > 0.05 * np.abs(g).min() * n.cell_size.min()


def test_a_node_held_flat_takes_the_thickness_of_the_material_between_the_faces():
    """The pinched nodes' half thickness is recovered from the cells wholly under the pinch
    (where a node has one), not from the cells bent beyond its edge: computed here from the
    cells' thickness strains by the plane fit written out, it differs from the fit to all cells at
    the pinch's edge, where the bent cells thin, and nowhere inside."""
    s = square_cup()
    p = DrawingProblem.from_scene(s, verbose=False)
    d = p.driver
    d.run(4.0 / s.tools.stroke)
    n, m = d.nodes, d.model
    flat = d.holder.flat()
    assert flat.sum() > 0 and np.array_equal(flat, n.flat)
    cells = m.dofs.reshape(-1, 3)
    e33, area = m.thickness_strain(), np.repeat(m.cell_area[:, None], 3, axis=1)
    centroids = m.cell_centres()
    X = n.X[: n.n_owned, :2]
    between = flat[cells].all(axis=1)
    a_held = np.bincount(cells[between].ravel(), area[between].ravel(), n.n_owned)
    inside = flat & (a_held > 0)
    held_w = np.where(inside[cells] & ~between[:, None], 0.0, area)
    every = _plane_fits(cells, centroids, e33, area, X, n.n_owned)
    held = _plane_fits(cells, centroids, e33, held_w, X, n.n_owned)
    np.testing.assert_allclose(n.half_thickness, 0.5 * s.material.thickness * np.exp(held), rtol=0, atol=1e-12)
    edge = inside & (a_held < np.bincount(cells.ravel(), area.ravel(), n.n_owned))
    assert edge.sum() > 0
    assert (held[edge] - every[edge]).max() > 1e-3  # the bent cells are thinner
    assert np.abs(held[flat & ~edge] - every[flat & ~edge]).max() < 1e-12


def test_the_die_presses_the_edge_s_band_with_its_equilibrium_not_the_pinch_s_couple():
    """On the edge's band the die's face force is the band's equilibrium total, the holder's
    force there plus the band's net normal force, max(sum (h_i + R0_i), 0), shared as the
    holder's (d_i / h_i the same on every band node): friction sees that, not the positive
    lobes of the discrete couple the pinch carries where the sheet turns onto the shoulder
    (docs/contact.md, "The die's force on the band")."""
    s = square_cup()
    p = DrawingProblem.from_scene(s, verbose=False)
    d = p.driver
    d.run(12.0 / s.tools.stroke)
    h = d.holder
    net = d.net_normal_forces()
    pressed, values = h.faces(d.nodes.positions(), net)  # the die's face forces under it
    die = np.zeros(net.size)
    die[pressed] = values
    band = h.band & h.pinched
    assert band.sum() > 4 and h.face[band].min() > 0.0
    die = die[band]
    total = float((h.face[band] + net[band]).sum())
    assert total > 0.0 and abs(die.sum() - total) <= 1e-9 * total
    ratio = die / h.face[band]
    assert np.ptp(ratio) <= 1e-12 * max(ratio.max(), 1.0)


def test_the_pinched_flange_s_taper_carries_no_moment():
    """The cells whose every node the faces pinch (w and slopes held) take the curvature of
    their mid-surface, a half thickness above the die, as their taper at every commit (where the
    next increment holds them): at the converged state they carry next to none of the moment that
    curvature would need as bending. Cells elsewhere keep
    what they had when they left the pinch (docs/contact.md, "The taper of the held flange")."""
    s = square_cup()
    p = DrawingProblem.from_scene(s, verbose=False)
    d = p.driver
    d.run(12.0 / s.tools.stroke)
    m, n = d.model, d.nodes
    tapered = n.interior(d.holder.pinched)[m.dofs.reshape(-1, 3)].all(axis=1)
    assert tapered.sum() > 10
    taper = np.abs(m.taper[tapered]).max()
    t = s.material.thickness
    D = s.material.E * t**3 / (12 * (1 - s.material.nu**2))
    assert taper > 1e-5  # the flange's thickness varies: its mid-surface curves
    # the taper is that of the next increment's start, on the thickness just updated
    assert np.abs(m.strain[tapered][..., 3:] - m.taper[tapered]).max() < 0.1 * taper
    assert np.abs(m.resultants[tapered][..., 3:]).max() < 0.01 * D * taper
    assert np.abs(m.resultants[~tapered][..., 3:]).max() > 10 * D * taper  # the wall and the shoulder bend


def test_the_holder_s_pressure_is_its_face_force_over_the_node_s_area_against_the_flow_stress():
    """DrawingProblem.holder_pressure: the largest h_i / a_i (a_i a third of the current plan area
    of the cells around node i), and the largest ratio to the flow stress at the node, which lies
    between the pressure over the largest flow stress in the sheet and over the initial yield
    stress (the flow curve rises); on the paper's cup at 4 mm the flange is pressed at a few
    times F over its area (the holding-down and the edge's band on the spread), far below yielding
    it through its thickness."""
    from shellform.material import hardening

    s = square_cup()
    p = DrawingProblem.from_scene(s, verbose=False)
    d = p.driver
    d.run(4.0 / s.tools.stroke)
    pressure, ratio = p.holder_pressure()
    h, area = d.holder, d.nodes.current_area()
    assert pressure == pytest.approx(float(np.max(h.face / area)), rel=1e-14)
    mean = h.force / float(area[h.pinched].sum())
    assert mean < pressure < 20 * mean
    m = d.model
    highest = hardening.flow_stress(float(m.cell_fields()["equivalent_plastic_strain"].max()), m.material)[0]
    assert pressure / highest <= ratio <= pressure / hardening.flow_stress(0.0, m.material)[0]
    assert 0.0 < ratio < 0.1
