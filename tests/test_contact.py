"""The mixed semi-inverse contact driver: nodal frames, equilibrium with a rigid punch, release
on unloading, the square cup drawn a few millimetres (balances, the pinch, penetration; hard
cases), its passes, tangent and fallback, the report of a stopped run, a resume, springback.
The parts have files of their own: test_friction.py, test_holder.py, test_drawbead.py,
test_tools.py; the cases they share are in contact_cases.py."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import logging

import numpy as np
import pytest
from mpi4py import MPI

from shellform import scene
from shellform.nonlinear.frames import from_frames, nodal_frames, rotate_cell_arrays
from shellform.contact.problem import DrawingProblem
from shellform.assembly.sheet_element import BS
from shellform.contact.semi_inverse import FREE, SemiInverseDriver
from shellform.nonlinear.driver import Controls

from contact_cases import ROOT, FlatTool, drawn_cup, plate, side_sum, square_cup, tangent_error


def test_nodal_frames_keep_symmetry_slots():
    rng = np.random.default_rng(0)
    n = rng.normal(size=(50, 3))
    n[:10, 0] = 0.0  # nodes on x = 0
    n[10:20, 1] = 0.0  # nodes on y = 0
    n[20:22, :2] = 0.0  # the flat faces, both signs
    n[21, 2] = -1.0
    n /= np.linalg.norm(n, axis=1)[:, None]
    F = nodal_frames(n)
    assert np.allclose(np.einsum("nij,nkj->nik", F, F), np.eye(3), atol=1e-14)
    assert np.allclose(np.linalg.det(F), 1.0)
    assert np.array_equal(F[:, 2], n)
    assert np.all(F[:10, 0] == [1.0, 0.0, 0.0])  # u stays one slot on x = 0
    assert np.all(np.abs(F[10:20, 1]) == [0.0, 1.0, 0.0])  # v stays one slot on y = 0
    assert np.all(F[20:22, 0] == [1.0, 0.0, 0.0])


def test_rotated_cell_arrays_are_t_k_tt():
    rng = np.random.default_rng(1)
    dofs = np.array([[0, 1, 2], [2, 3, 0]], dtype=np.int32)
    rotated = np.array([True, False, True, True])
    frames = nodal_frames(rng.normal(size=(4, 3)) / np.sqrt(3))
    frames = np.array([np.linalg.qr(f)[0] for f in frames])
    vec, mat = rng.normal(size=(2, 27)), rng.normal(size=(2, 27, 27))
    v2, m2 = vec.copy(), mat.copy()
    rotate_cell_arrays(dofs, rotated, frames, v2, m2, True)
    for c in range(2):
        T = np.eye(27)
        for a in range(3):
            if rotated[dofs[c, a]]:
                T[9 * a: 9 * a + 3, 9 * a: 9 * a + 3] = frames[dofs[c, a]]
        assert np.allclose(v2[c], T @ vec[c], atol=1e-13)
        assert np.allclose(m2[c], T @ mat[c] @ T.T, atol=1e-12)


def test_a_support_in_a_turned_frame_is_corrected_towards_its_value():
    """On y = 0 under a face whose normal points down, nodal_frames turns slot 1 to -e_y: the
    symmetry row's known correction must move v back to 0 (global: -v), not double it."""
    rect, model, bcs = plate()
    d = SemiInverseDriver(model, bcs, [FlatTool(0.5, 15.0, 15.0)], [-2.0], verbose=False)
    held = d.nodes.held
    bottom = np.flatnonzero(d.contact.on(0) & held[:, 1] & ~held[:, 0])
    assert bottom.size > 0
    q = d.q.x.array.reshape(-1, BS)
    q[bottom, 1] = 1e-3  # off the symmetry plane
    d.constrain(0.0)
    assert np.all(d.frames[bottom, 1] == [0.0, -1.0, 0.0])
    delta = d.correction()
    from_frames(delta, d.rotated, d.frames)  # the correction in x, y, z
    assert np.allclose(delta.reshape(-1, BS)[bottom, 1], -1e-3, rtol=1e-12)


def test_a_node_frozen_off_a_tool_inside_it_joins_it_when_the_set_would_settle():
    """A node whose switches are spent and that lies inside a tool when nothing else in the set
    changes joins the tool (a last switch), so that no increment is accepted with a node inside
    a tool; while other nodes still switch it waits (their passes may move it out). It cannot
    leave again in the increment."""
    rect, model, bcs = plate()
    d = SemiInverseDriver(model, bcs, [FlatTool(0.5, 15.0, 15.0)], [-2.0], verbose=False)
    cs = d.contact
    on = np.flatnonzero(cs.on(0))  # under the punch, which touches the plate at the start
    node, other = on[0], on[-1]
    q = d.q.x.array.reshape(-1, BS)
    for i in (node, other):
        cs.assign(i, FREE)
        q[i, 2] += cs.gaps(d.positions(), 0.0)[0][0][i] + 5.0 * cs.controls.penetration  # 5 tolerances inside
    cs.toggles[node] = cs.controls.max_toggles
    change = cs.update(0.0, 0)  # `other` may still switch: it joins, `node` waits
    assert change.changes == 1 and cs.on(0)[other] and not cs.on(0)[node] and "frozen" not in change.line
    change = cs.update(0.0, 0)  # nothing else changes: the frozen node joins
    assert (change.changes, change.back) == (1, 1) and cs.on(0)[node]
    assert "1 nodes frozen off a tool join it from 0.005 inside" in change.line
    assert cs.toggles[node] == cs.controls.max_toggles + 1


def test_flat_punch_on_a_plate_balances_the_supports_and_releases_on_unloading():
    """A flat rigid punch pushes a simply supported plate 2 mm down and goes back: the punch's
    contact force equals the support reactions (to 1e-8), no node penetrates, the contact set
    settles in every increment, and when the punch is lifted every node leaves it."""
    t = 1.0
    rect, model, bcs = plate(t=t)
    punch = FlatTool(t / 2, 15.0, 15.0)
    d = SemiInverseDriver(model, bcs, [punch], [-2.0], controls=Controls(initial_step=0.25, rtol=1e-10),
                          verbose=False)
    forces = []

    def check(dr):
        r = dr.reactions()
        on = dr.contact.on(0)
        # z of the punch's force on the sheet: F^T r on the punch nodes
        fz = np.einsum("nk,nk->n", dr.frames[: dr.n_owned][on][:, :, 2], r[on])
        punch_z = MPI.COMM_WORLD.allreduce(float(fz.sum()), op=MPI.SUM)
        support = side_sum(dr, rect, ("right", "top"), 2)
        forces.append(punch_z)
        peak = max(abs(f) for f in forces)
        assert abs(punch_z + support) <= 1e-8 * peak, (punch_z, support)
        gap, _ = punch.gap(dr.positions(), 0.5 * t, dr.lam * -2.0)
        assert -gap.min() <= dr.contact.controls.penetration
        assert dr.history[-1].contact["passes"] < dr.controls.max_passes

    d.run(1.0, on_increment=check)
    assert forces[-1] < 0 and abs(forces[-1]) > 10.0  # the punch pushes down with a real force
    assert MPI.COMM_WORLD.allreduce(int(d.contact.on(0).sum()), op=MPI.SUM) > 0
    d.run(-0.1, on_increment=check)  # unload and lift the punch 0.2 mm: the plate springs back off it
    assert MPI.COMM_WORLD.allreduce(int(d.contact.on(0).sum()), op=MPI.SUM) == 0
    assert abs(forces[-1]) < 1e-6 * max(abs(f) for f in forces)


def test_short_square_cup_draw():
    """The square-cup scene on a coarse quarter blank, 3 mm of stroke: at every increment the
    holder's nodal forces sum to 19.6 kN and no node takes more than 10 % of it, the tools' forces
    balance (to 1e-6 of the punch force), no flange node under the closed holder is free, no node
    penetrates a tool by more than 1 % of the thickness and the contact settles; the punch force
    grows."""
    s = square_cup()
    p = DrawingProblem.from_scene(s, verbose=False)
    forces = []

    def check(d):
        assert abs(p.holder_force() - s.tools.blank_holder_force) <= 1e-9 * s.tools.blank_holder_force
        assert p.holder_share() <= 0.1
        held, edge, off_band = p.holder_held_down()
        assert 0.0 <= off_band <= held <= 1.0 and edge >= 0.0  # the closed holder: what it holds down is at most F
        x, y = p.holder_largest_at()
        assert 0 <= x <= s.geometry.lx / 2 and 0 <= y <= s.geometry.ly / 2
        assert p.force_balance() <= 1e-6
        assert p.free_under_holder() == 0 and d.holder.closed
        assert p.max_penetration() <= 0.01 * s.material.thickness
        assert d.history[-1].contact["passes"] < d.controls.max_passes
        forces.append(p.punch_force())

    p.driver.run(3.0 / s.tools.stroke, on_increment=check)
    assert forces[-1] > forces[0] > 0
    assert np.all(np.diff(forces) > 0)
    c = p.in_contact()
    assert c["punch"] > 0 and c["pinched"] > 0 and c["free"] > 0


@pytest.mark.parametrize("case", ["mu 0.3", "10x increment", "die radius 2 mm"])
def test_hard_cup_cases_draw(case):
    """Hard cases of the cup (the full-stroke table: shellform study cup-hard) on the coarse mesh
    for 3 mm: three times the friction; increments of ten times the scene's largest (2.4 mm), cut
    back by the driver where they fail; a die shoulder of 2 mm, a quarter of a cell. Each reaches
    3 mm with the tools in balance, the flange pinched and no penetration."""
    s = square_cup()
    big = 10 * s.process.max_step_mm
    changes = {"mu 0.3": ("tools", "friction", 0.3), "die radius 2 mm": ("tools", "die_profile_radius", 2.0),
               "10x increment": ("process", "max_step_mm", big)}[case]
    setattr(getattr(s, changes[0]), changes[1], changes[2])
    if case == "10x increment":
        s.process.initial_step_mm = big
    p = DrawingProblem.from_scene(s, verbose=False)
    p.driver.run(3.0 / s.tools.stroke)
    assert p.stroke == pytest.approx(3.0)
    assert p.force_balance() <= 1e-6 and p.free_under_holder() == 0
    assert p.max_penetration() <= 0.01 * s.material.thickness
    assert p.punch_force() > 0
    if case == "10x increment":  # it took the big steps (cut back where it had to)
        assert len(p.driver.history) <= 2 + sum(h.cutbacks for h in p.driver.history)


def test_a_shorter_stroke_takes_fewer_increments_of_the_same_travel():
    """A tool scene's steps are mm of the punch's travel (process.*_step_mm): the cup drawn 0.6
    and 1.8 mm with the same steps takes the same first increments, in mm, and three times the
    stroke takes about three times the increments (the first ones grow from initial_step_mm)."""
    travel = {}
    for stroke in (0.6, 1.8):
        s = square_cup(n=4, stroke=stroke, changes={"process.initial_step_mm": 0.05, "process.max_step_mm": 0.15})
        p = DrawingProblem.from_scene(s, verbose=False)
        p.driver.run(1.0)
        assert p.stroke == pytest.approx(stroke) and sum(h.cutbacks for h in p.driver.history) == 0
        travel[stroke] = [h.dlam * stroke for h in p.driver.history]
    short, long = travel[0.6], travel[1.8]
    assert short[0] == pytest.approx(0.05, rel=1e-12) and max(long) == pytest.approx(0.15, rel=1e-12)
    assert np.allclose(long[: len(short) - 1], short[:-1], rtol=1e-12)  # the short one's last is what is left
    assert sum(short) == pytest.approx(0.6) and sum(long) == pytest.approx(1.8)
    assert 2.0 * len(short) < len(long) <= 3 * len(short)


def test_the_iterations_of_a_try_cut_back_are_counted(monkeypatch):
    """An increment's iterations are its linear solves, those of a try that was cut back included:
    the second increment's first try is refused (after its Newton ran), cut back and tried again;
    the history's iterations add up to the solves made."""
    s = square_cup(n=4, stroke=0.3, changes={"process.initial_step_mm": 0.1, "process.max_step_mm": 0.1})
    p = DrawingProblem.from_scene(s, verbose=False)
    d = p.driver
    real, tries = SemiInverseDriver.newton, []

    def second_refused(self, lam, reversal=False):
        ok, its, res, ev = real(self, lam, reversal)
        tries.append(its)
        if len(tries) == 2:
            self.cause = "refused by the test"
            return False, its, res, ev
        return ok, its, res, ev

    monkeypatch.setattr(SemiInverseDriver, "newton", second_refused)
    d.run(1.0)
    h = d.history
    assert h[1].cutbacks == 1 and tries[1] > 0
    assert h[1].iterations == tries[1] + tries[2]
    assert sum(x.iterations for x in h) == sum(tries) == d.solves


def test_a_stopped_run_reports_its_last_converged_state(tmp_path, monkeypatch):
    """A run whose Newton breaks down (here: forced past 0.5 mm, leaving a wild iterate behind)
    stops with its cause, and summary.json reports the last converged state: the stroke, punch
    force and draw-in of the last line of force_stroke.csv, not of the failed iterate."""
    import csv
    import json

    from shellform.contact import run as contact_run

    original = SemiInverseDriver.settle

    def breaks_down(self, lam, reversal=False):
        if lam * 30.0 <= 0.5 + 1e-9:
            return original(self, lam, reversal)
        self.q.x.array[:] += 5.0  # a diverged iterate: its reactions must not be reported
        self.linearize(lam, tangent=False)
        self.cause = "forced by the test"
        return False, 1, [1e9], None

    monkeypatch.setattr(SemiInverseDriver, "settle", breaks_down)
    s = square_cup()
    s.process.initial_step_mm = s.process.max_step_mm = 0.25
    summary = contact_run.run(s, tmp_path)
    assert "forced by the test" in summary["stopped"]
    rows = list(csv.DictReader(open(tmp_path / "force_stroke.csv")))
    last = rows[-1]
    assert summary["stroke_mm"] == pytest.approx(0.5) == pytest.approx(float(last["stroke_mm"]))
    force = summary["punch_force_kN"][-1]
    assert force["stroke_mm"] == pytest.approx(0.5)
    assert force["force"] == pytest.approx(float(last["punch_force_kN"]), rel=1e-5) and force["force"] > 0
    assert abs(summary["draw_in_mm"][-1]["DD"]) < 0.1
    assert json.loads((tmp_path / "summary.json").read_text())["stopped"] == summary["stopped"]
    assert (tmp_path / "checkpoint.npz").exists()  # the last converged state, any rank count
    assert (tmp_path / "fld.csv").exists() and summary["min_margin"] > 0.3  # 0.5 mm: far from the curve
    worst = summary["over_the_stroke"]  # the checks of every converged increment
    assert worst["force_balance"] <= 1e-6 and worst["free_under_closed_holder"] == 0
    assert worst["holder_largest_share"] <= 0.1 and worst["max_penetration_mm"] <= 0.01 * s.material.thickness


@pytest.mark.parametrize("bad", [
    ("tools", "punch_gap", -0.1, "tools.punch_gap"),
    ("tools", "punch_half_width", 40.0, "tools.punch_half_width"),
    ("geometry", "lx", 80.0, "geometry.lx"),
])
def test_bad_tool_scenes_name_the_field(bad):
    import tomllib

    from shellform.errors import InputError

    section, key, value, field = bad
    data = tomllib.loads((ROOT / "demos" / "square_cup.toml").read_text())
    data[section][key] = value
    with pytest.raises(InputError, match=field.replace(".", r"\.")):
        scene.from_dict(data)


def test_a_resumed_run_equals_an_uninterrupted_one(tmp_path):
    """A cup run killed right after its first report (only its checkpoint survives) and resumed
    with --resume ends where the uninterrupted run ends: punch force, draw-in, thinning, every
    report and the force-stroke curve to 1e-9. A checkpoint of another mesh is refused, naming
    what differs."""
    import csv

    from resume_cup import cup, killed_after_first_report

    from shellform.contact import run as contact_run
    from shellform.errors import InputError

    s = cup()
    whole = contact_run.run(s, tmp_path / "whole")
    killed_after_first_report(tmp_path / "pieces")
    pieces = contact_run.run(s, tmp_path / "pieces", resume=True)
    assert pieces["resumed_from_stroke_mm"] == pytest.approx(0.5)
    assert len(pieces["reports"]) == len(whole["reports"]) == 2
    for a, b in zip(whole["reports"], pieces["reports"]):
        assert b["punch_force_kN"] == pytest.approx(a["punch_force_kN"], rel=1e-9)
        for k in ("DX", "DD"):
            assert b["draw_in_mm"][k] == pytest.approx(a["draw_in_mm"][k], rel=1e-9, abs=1e-12)
        assert b["min_thickness_strain"] == pytest.approx(a["min_thickness_strain"], rel=1e-9)
    rows = [list(csv.DictReader(open(tmp_path / d / "force_stroke.csv"))) for d in ("whole", "pieces")]
    assert len(rows[0]) == len(rows[1])
    assert float(rows[1][-1]["punch_force_kN"]) == pytest.approx(float(rows[0][-1]["punch_force_kN"]), rel=1e-9)

    other = square_cup(n=4, stroke=1.0)
    with pytest.raises(InputError) as err:
        contact_run.run(other, tmp_path / "pieces", resume=True)
    assert err.value.field == "resume" and "mesh.n" in str(err.value)


def test_an_elastic_sheet_springs_back_flat():
    """An elastic sheet (no friction: nothing dissipates) pressed 1 mm by the punch and released
    (contact/springback.py) returns to its flat blank: u, v and the slopes to 1e-8 mm, w to a
    rigid lift of the held centre to 1e-8 mm."""
    from shellform.contact import springback

    s = square_cup(n=6, stroke=1.0, friction=0.0, changes={
        "effects": ["bending", "membrane", "geometric_nonlinearity", "contact"], "material.hardening": "none",
        "material.r": 1.0, "material.K": 0.0, "material.eps0": 0.0, "material.n": 0.0,
        "process.initial_step_mm": 0.1, "process.max_step_mm": 0.25})
    p = DrawingProblem.from_scene(s, verbose=False)
    p.driver.run(1.0)
    drawn = p.driver.q.x.array.reshape(-1, 9)
    assert np.abs(drawn[:, 2]).max() > 0.5  # pressed well into the die opening
    sb = springback.release(p.driver)
    q = sb.q.x.array.reshape(-1, 9)
    centre = q[np.argmin(np.hypot(*p.driver.nodes.X[:, :2].T)), 2]
    assert np.abs(q[:, [0, 1, 3, 4, 5, 6, 7, 8]]).max() < 1e-8
    assert np.abs(q[:, 2] - centre).max() < 1e-8
    assert sum(h.plastic_layers for h in sb.history) == 0


def test_drawn_cup_springback_outputs(tmp_path):
    """A plastic cup drawn 3 mm and released: the run reports the flange's and the wall's change,
    the residual resultants and the unloading's plastic layers, and writes the profiles."""
    from shellform.contact import run as contact_run

    s = square_cup(n=6, stroke=3.0)
    s.process.initial_step_mm, s.process.max_step_mm = 0.06, 0.15
    s.process.springback = True
    s.output.vtx = s.output.png = s.output.fld = False
    summary = contact_run.run(s, tmp_path)
    sb = summary["springback"]
    assert abs(sb["flange_edge_dz_mm"]["diagonal"]) > 1e-3  # it springs
    assert sb["residual_max_N_per_mm"] > 1.0 and sb["residual_max_M_N"] > 0.1  # residual stresses
    assert sb["unloading_increments"] >= 1 and sb["plastic_layers_on_unloading"] >= 0
    assert (tmp_path / "springback.csv").exists() and (tmp_path / "springback.png").exists()
    assert (tmp_path / "thickness.png").stat().st_size > 10_000  # the thickness along the cup's lines
    assert (tmp_path / "force_stroke.png").stat().st_size > 10_000


@pytest.mark.parametrize("name", ["numisheet93_aluminium.toml", "numisheet93_steel.toml",
                                  pytest.param("numisheet93_aluminium_graded.toml", marks=pytest.mark.slow)])
def test_numisheet_scenes_draw_their_first_millimetres(name):
    """The NUMISHEET'93 scenes (the numisheet study's, on 6 x 6; the graded one on its gmsh mesh
    from demos/meshes/square_cup_graded.geo) draw 2 mm: the holder's forces sum to F, the tools
    balance, no free node under the closed holder, penetration within 1 % of t, and the punch
    force grows."""
    s = scene.load(ROOT / "demos" / name)
    if s.geometry.shape == "rectangle":
        s.mesh.n = 6
    p = DrawingProblem.from_scene(s, verbose=False)
    forces = []

    def check(d):
        assert abs(p.holder_force() - s.tools.blank_holder_force) <= 1e-9 * s.tools.blank_holder_force
        # the z-balance closes to Newton's tolerance, which scales with the element forces, not
        # the punch force: early in the stroke 2.4 rtol of it on the graded mesh, under 1 rtol on 6 x 6
        assert p.force_balance() <= 5 * s.process.rtol and p.free_under_holder() == 0
        assert p.max_penetration() <= 0.01 * s.material.thickness
        forces.append(p.punch_force())

    p.driver.run(2.0 / s.tools.stroke, on_increment=check)
    assert p.stroke == pytest.approx(2.0)
    assert forces[-1] > forces[0] > 0


@pytest.mark.parametrize("mu", [0.0, pytest.param(0.1, marks=pytest.mark.slow)])
def test_tangent_follows_the_frames_turning_on_curved_tools(mu):
    """A node moving along the punch's nose turns its frame: its tangential rows t_a . R change
    by -R0 W_ab dx_b (W the nose's shape operator). On the cup drawn 6 mm, for nodes on the nose,
    a step along their own tangents matches the tangent's columns to 1e-6 of the largest entry
    frictionless, 1e-5 with the scene's friction (whose projection on the turning tangent plane,
    of order mu times the term, is left out); without the term: 1e-4 (docs/contact.md)."""
    d, lam = drawn_cup(6.0)
    d.friction.mu = mu
    nose = np.flatnonzero(d.contact.on(0) & (np.abs(d.contact.curvature).max(axis=(1, 2)) > 0))[:3]
    assert nose.size > 0
    rows = (BS * nose[:, None] + np.arange(2)).ravel()
    columns = []
    for b in nose:
        for a in np.flatnonzero(~d.nodes.held[b, :2]):
            v = np.zeros(d.q.x.array.size)
            v[BS * b:BS * b + 3] = d.frames[b, a]
            columns.append((BS * b + a, v))
    error = tangent_error(d, lam, rows, columns)
    assert error <= (1e-5 if mu else 1e-6), error


def test_a_pass_starts_from_the_last_evaluation_turned_into_its_frames():
    """A contact pass starts where the one before ended: the same carrier and material state,
    another contact set and so other nodal frames. The last evaluation's element arrays, turned
    from its frames F0 into the new F (T = F F0^T), give the residual and tangent of a fresh
    evaluation to round-off, without running the element loops again."""
    d, lam = drawn_cup(2.0)
    d.constrain(lam)
    d.residual(lam, tangent=True)
    s, x = d.contact, d.positions()
    released = np.flatnonzero(s.on(0) & ~d.nodes.held[:, :3].any(axis=1))[:5]
    die_gap = s.gaps(x, lam)[s.die][0]
    joined = np.flatnonzero(s.on(FREE) & np.isfinite(die_gap))[:5]
    assert released.size == 5 and joined.size == 5
    s.assign(released, FREE)
    s.assign(joined, s.die)
    d.constrain(lam)
    reused = d.reused
    d.residual(lam, tangent=True)
    assert d.reused == reused + 1
    R, K = d.b.copy(), d.A.copy()
    d.forget_evaluation()  # a fresh evaluation
    d.residual(lam, tangent=True)
    assert d.reused == reused + 1
    assert (R - d.b).norm() <= 1e-12 * d.b.norm()
    K.axpy(-1.0, d.A)
    assert K.norm() <= 1e-12 * d.A.norm()


def test_a_trials_tangent_is_assembled_only_when_a_solve_asks_for_it():
    """Newton's trials assemble R at once and K only before a solve: the element tangents then
    come from the trial's stresses and section tangents without the element loops running
    again, and R and K equal an eager evaluation's to round-off (of the element forces' scale).
    Drawn, the coarse cup computes one tangent per solve, fewer than its evaluations."""
    d, lam = drawn_cup(2.0)
    evaluations, tangents = d.evaluations, d.tangents
    d.forget_evaluation()
    _, scale, _ = d.trial(lam)
    R = d.b.copy()
    assert d.tangent_pending and d.tangents == tangents and d.evaluations == evaluations + 1
    d.assemble_tangent()
    assert not d.tangent_pending and d.tangents == tangents + 1 and d.evaluations == evaluations + 1
    K = d.A.copy()
    assert (R - d.b).norm() <= 1e-15 * scale  # the same R (converged: small against the element forces)
    d.forget_evaluation()
    d.residual(lam, tangent=True)
    assert (R - d.b).norm() <= 1e-14 * scale
    K.axpy(-1.0, d.A)
    assert K.norm() <= 1e-12 * d.A.norm()

    s = square_cup()
    p = DrawingProblem.from_scene(s, verbose=False)
    p.driver.run(1.5 / s.tools.stroke)
    lazy = p.driver
    assert lazy.tangents == lazy.solves < lazy.evaluations


def test_failed_early_ending_passes_end_only_near_convergence_from_then_on():
    """Contact passes that fail while they end early on a set change (early_step 10) end only
    near convergence from then on (early_step 1), and the increment is tried again from the
    same start before it is cut back; its iterations count both tries. A failure at early_step
    1 is returned to the driver (which cuts back)."""
    s = square_cup()
    p = DrawingProblem.from_scene(s, verbose=False)
    d = p.driver
    d.run(1.0 / s.tools.stroke)
    assert d.contact.early_step == 10.0
    starts, real = [], d.settle

    def first_fails(lam, reversal=False):
        starts.append((d.contact.early_step, d.q.x.array.copy()))
        if len(starts) == 1:
            d.q.x.array[:] += 1e-3  # a failed try leaves its last iterate behind
            d.cause = "a failure for the test"
            return False, 7, [1.0], None
        return real(lam, reversal)

    d.settle = first_fails
    lam = d.lam + 0.2 / s.tools.stroke
    ok, its, _, _ = d.newton(lam)
    assert ok and [e for e, _ in starts] == [10.0, 1.0] and d.contact.early_step == 1.0
    assert np.array_equal(starts[0][1], starts[1][1])
    assert its > 7

    def fails(lam, reversal=False):
        starts.append((d.contact.early_step, None))
        return False, 3, [1.0], None

    d.settle = fails
    assert d.newton(lam)[:2] == (False, 3) and len(starts) == 3


def test_passes_that_only_move_the_contact_front_are_not_counted():
    """The aluminium cup's first increment: the blank meets the punch's face and peels off it
    one row of nodes per pass (on 10,082 cells it took 15 passes). Passes in which every set
    change is a node's first switch do not count against max_passes: with max_passes 2 the
    increment converges as with 12, to the same state."""
    s = scene.load(ROOT / "demos" / "numisheet93_aluminium.toml")
    s.mesh.n = 16
    states = []
    for max_passes in (12, 2):
        p = DrawingProblem.from_scene(s, verbose=False)
        p.driver.controls.max_passes = max_passes
        p.driver.run(p.driver.controls.initial_step)
        h = p.driver.history
        assert len(h) == 1 and h[0].cutbacks == 0
        states.append((h[0].contact["passes"], p.driver.q.x.array.copy(), p.punch_force()))
    (passes, q, force), (passes2, q2, force2) = states
    assert passes2 == passes > 2
    assert force2 == force and np.array_equal(q2, q)


def test_the_trace_names_every_node_that_switches(caplog):
    """The trace (shellform run --trace) logs each node that joins or leaves a tool, with its position and force:
    in the aluminium cup's first increment (the blank peeling off the punch's face, the holder
    closed throughout) one line per counted set change."""
    s = scene.load(ROOT / "demos" / "numisheet93_aluminium.toml")
    s.mesh.n = 16
    p = DrawingProblem.from_scene(s, verbose=False, trace=True)
    caplog.set_level(logging.INFO, logger="shellform")
    p.driver.run(p.driver.controls.initial_step)
    lines = caplog.messages
    switches = [ln for ln in lines if " joins tool " in ln or " leaves tool " in ln]
    h = p.driver.history[0].contact
    assert h["holder_closed"] and h["set_changes"] > 0
    assert len(switches) == h["set_changes"]
    assert all("net normal force" in ln for ln in switches if " leaves tool " in ln)
