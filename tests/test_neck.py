"""The neck's onset (issue 44): the sections' membrane stability (shellform.material.stability)
reaches 0 at Considere's force maximum of a strip in tension, the watch (shellform.results.neck)
interpolates where, and [process] stop_at_neck ends a tool scene's stroke there."""

import json
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from shellform import scene
from shellform.contact import run as contact_run
from shellform.errors import InputError
from shellform.material.stability import membrane_stiffness, smallest_eigenvalue
from shellform.results.neck import NeckWatch
from shellform.studies import strip

DEMOS = Path(__file__).resolve().parents[1] / "demos"
MATERIALS = {"swift": strip.mild_steel, "power": strip.power_law}


def test_smallest_eigenvalue_in_closed_form():
    """The trigonometric solution against LAPACK on random symmetric matrices, with a nearly
    singular and a repeated case, to 1e-9 of the largest eigenvalue."""
    rng = np.random.default_rng(44)
    cases = [rng.normal(size=(3, 3)) * 10.0 ** rng.uniform(-2, 5) for _ in range(200)]
    cases += [np.diag([2e5, 1e5, 1e-3]), np.diag([7.0, 7.0, 7.0]), np.diag([3.0, 5.0, 5.0])]
    for a in cases:
        a = a + a.T
        exact = np.linalg.eigvalsh(a)
        got = smallest_eigenvalue(a[0, 0], a[0, 1], a[0, 2], a[1, 1], a[1, 2], a[2, 2])
        assert abs(got - exact[0]) <= 1e-9 * np.abs(exact).max()


def test_uniaxial_stiffness_is_the_slope_of_the_nominal_force():
    """A state of uniaxial stress N = (N1, 0, 0) at stretches (lambda, mu), with a diagonal
    tangent A: on the spin-free rates the stiffness along dE11 is A11 + N1 / lambda^2 (its
    geometric term), the shear's 2 (A22 + N1 / (4 mu^2)) in Mandel's components (dE12 = 1/2 in
    the Voigt shear's tensor, sqrt 2 dE12 its Mandel component)."""
    lam, mu, N1 = 1.3, 0.9, 250.0
    E = np.array([(lam**2 - 1) / 2, (mu**2 - 1) / 2, 0.0])
    A = np.diag([100.0, 2000.0, 800.0])
    M = np.zeros((3, 3))
    assert membrane_stiffness(E, np.array([N1, 0.0, 0.0]), A, M)
    assert M[0, 0] == pytest.approx(100.0 + N1 / lam**2, rel=1e-14)
    assert M[1, 1] == pytest.approx(2000.0, rel=1e-14)
    assert M[2, 2] == pytest.approx(2.0 * (800.0 + N1 / (4 * mu**2)), rel=1e-14)
    assert M[0, 1] == M[0, 2] == M[1, 2] == 0.0


def test_the_stiffness_is_the_nominal_force_tangent_on_spin_free_rates():
    """For a membrane N = A0 E + N0 (any symmetric A0, a prestress N0) at a sheared stretch F,
    dF : dP on dF = F^-T dE equals m^T M m, P = F N the nominal force and dP its central
    difference, for random dE (m: dE's Mandel components)."""
    rng = np.random.default_rng(7)
    A0 = rng.normal(size=(3, 3)) * 50.0
    A0 = A0 + A0.T + np.diag([900.0, 700.0, 300.0])
    N0 = np.array([120.0, -40.0, 30.0])
    F = np.array([[1.25, 0.2], [-0.1, 0.85]])

    def strain(F):
        E = 0.5 * (F.T @ F - np.eye(2))
        return np.array([E[0, 0], E[1, 1], 2.0 * E[0, 1]])

    def nominal(F):
        N = A0 @ strain(F) + N0
        return F @ np.array([[N[0], N[2]], [N[2], N[1]]])

    M = np.zeros((3, 3))
    assert membrane_stiffness(strain(F), A0 @ strain(F) + N0, A0, M)
    for _ in range(5):
        m = rng.normal(size=3)
        dE = np.array([[m[0], m[2] / np.sqrt(2)], [m[2] / np.sqrt(2), m[1]]])
        dF = np.linalg.inv(F).T @ dE
        h = 1e-6
        dP = (nominal(F + h * dF) - nominal(F - h * dF)) / (2 * h)
        assert np.sum(dF * dP) == pytest.approx(m @ M @ m, rel=1e-7)


def test_the_watch_interpolates_the_onset_and_keeps_it():
    """Least stabilities 30 and 10 at stretches 1.1 and 1.2, -10 at 1.3: the onset at 1.25, in
    the cell weakest at 1.3, whose thickness strain -0.10 -> -0.14 is -0.12 there; the first
    onset stays."""
    watch = NeckWatch(MPI.COMM_SELF, "stretch", "initial_xy")
    centres = np.array([[0.5, 0.5], [1.5, 0.5]])
    assert not watch.reached(1.1, np.array([40.0, 30.0]), np.array([-0.04, -0.05]), centres)
    assert not watch.reached(1.2, np.array([10.0, 20.0]), np.array([-0.10, -0.08]), centres)
    assert watch.onset is None
    assert watch.reached(1.3, np.array([-10.0, 5.0]), np.array([-0.14, -0.11]), centres)
    assert watch.onset["stretch"] == pytest.approx(1.25, rel=1e-14)
    assert watch.onset["increment_stretch"] == 1.3
    assert watch.onset["initial_xy"] == [0.5, 0.5]
    assert watch.onset["thickness_strain"] == pytest.approx(-0.12, rel=1e-13)
    assert watch.onset["stability"] == -10.0
    first = dict(watch.onset)
    assert watch.reached(1.4, np.array([-20.0, -30.0]), np.array([-0.2, -0.2]), centres)
    assert watch.onset == first


def test_a_thickening_cell_does_not_neck():
    """A cell compressed in the mean (thickness strain > 0) whose membrane tangent turns indefinite
    is not a neck: the watch sees only the cells that have thinned."""
    watch = NeckWatch(MPI.COMM_SELF, "stretch", "initial_xy")
    centres = np.array([[0.5, 0.5], [1.5, 0.5]])
    assert not watch.reached(1.1, np.array([40.0, 30.0]), np.array([0.04, -0.05]), centres)
    assert not watch.reached(1.2, np.array([-10.0, 20.0]), np.array([0.05, -0.08]), centres)
    assert watch.onset is None
    assert watch.reached(1.3, np.array([-10.0, -5.0]), np.array([0.06, -0.11]), centres)
    assert watch.onset["initial_xy"] == [1.5, 0.5] and watch.onset["stability"] == -5.0


def test_a_cell_drawn_more_than_stretched_does_not_neck():
    """Given the major strains, a thinned cell is watched only where its thinning is at least
    0.9 / (1 + r) of its major strain (uniaxial tension's share 1 / (1 + r), r = 1.5: 0.36): the
    square cup's drawn corner (major 0.32, thickness strain -0.026, share 0.08) passes its force
    maximum unreported; a cell stretched nearly uniaxially (share 0.38) is reported; the same
    drawn cell with an isotropic sheet's r = 1 (0.45) neither."""
    centres = np.array([[35.9, 34.4], [34.4, 31.25]])
    major = np.array([0.32, 0.21])
    thickness = np.array([-0.026, -0.079])
    watch = NeckWatch(MPI.COMM_SELF, r=1.5)
    assert not watch.reached(15.8, np.array([-30.0, 40.0]), thickness, centres, major)
    assert watch.onset is None
    assert watch.reached(20.1, np.array([-30.0, -12.0]), thickness, centres, major)
    assert watch.onset["initial_xy_mm"] == [34.4, 31.25] and watch.onset["stability"] == -12.0
    isotropic = NeckWatch(MPI.COMM_SELF, r=1.0)
    assert not isotropic.reached(20.1, np.array([-30.0, -12.0]), thickness, centres, major)
    assert isotropic.reached(20.1, np.array([-30.0, -12.0]), thickness, centres)  # without major strains: every thinned cell


@pytest.mark.parametrize("changes, r", [({}, 1.5), ({"material.yield_function": "hill48", "material.r0": 0.7,
                                                        "material.r45": 0.6, "material.r90": 2.1}, 2.1)])
def test_the_largest_r_of_a_scene(changes, r):
    from shellform import demos
    from shellform.scene import load

    s = load(demos.path("square_cup.toml"))
    if changes:
        s = s.changed({"material.r": 1.0, **changes})
    assert s.largest_r() == r


def test_a_resumed_watch_keeps_an_earlier_onset():
    """A resumed run at 12 mm keeps the onset found at 10 mm (from the summary before), and
    ignores one past its state (a run resumed from before it finds it again)."""
    earlier = {"stroke_mm": 10.0, "increment_stroke_mm": 10.5, "initial_xy_mm": [1.0, 2.0],
               "thickness_strain": -0.2, "stability": -1.0}
    watch = NeckWatch(MPI.COMM_SELF)
    watch.carry(earlier, 12.0)
    assert watch.onset == earlier
    assert watch.reached(13.0, np.array([5.0]), np.array([-0.1]), np.array([[0.0, 0.0]]))
    assert watch.onset == earlier
    later = NeckWatch(MPI.COMM_SELF)
    later.carry(earlier, 9.0)
    later.carry(None, 9.0)
    assert later.onset is None


@pytest.mark.parametrize("homogeneous", [True, False], ids=["homogeneous", "free"])
@pytest.mark.parametrize("material", ["swift", "power"])
def test_a_strip_pulled_past_considere_necks_at_the_force_maximum(material, homogeneous):
    """Pulled to a stretch of 1.35 in 20 increments (d eps = 0.0136 at the onset), held
    homogeneous or only its end pulled: the neck starts at the closed-form force maximum of
    tau(eps) / lambda (Swift 0.2532, its elastic part included; the power law 1/N = 0.25) within
    0.05 d eps. Why that tolerance: the stability is smooth in the stretch (as d tau / d eps - tau),
    and its linear interpolation between the increments misses its zero by at most
    d eps^2 / 8 |m''| / |m'|, about 3e-4 = 0.024 d eps here (measured 3.2e-4 and 2.4e-4); the
    rigid-plastic Considere strain n - eps0 = 0.2518 lies 1.4e-3 below the Swift maximum (the
    elastic strain), still within one d eps. The thickness strain there is the uniaxial one,
    -(eps - tau/E)/2 - nu tau/E, to 1e-4 (seen 1e-5)."""
    mat = MATERIALS[material]()
    steps, stretch = 20, 1.35
    watch = NeckWatch(MPI.COMM_WORLD, "stretch", "initial_xy")
    _, rows = strip.strip(mat, stretch, homogeneous=homogeneous, steps=steps, n=1 if homogeneous else 2, watch=watch)
    onset = watch.onset
    assert onset is not None
    eps = float(np.log(onset["stretch"]))
    d_eps = float(np.log(onset["increment_stretch"] / (onset["increment_stretch"] - (stretch - 1) / steps)))
    assert d_eps == pytest.approx(0.0136, abs=1e-4)
    assert abs(eps - strip.force_maximum_strain(mat)) < 0.05 * d_eps
    assert abs(eps - strip.considere_strain(mat)) < d_eps
    tau = strip.uniaxial_kirchhoff(mat, onset["stretch"])
    assert onset["thickness_strain"] == pytest.approx(-(eps - tau / mat.E) / 2 - mat.nu * tau / mat.E, abs=1e-4)
    stable, unstable = [r for r in rows if r["stability"] > 0], [r for r in rows if r["stability"] <= 0]
    assert stable[-1]["stretch"] < onset["stretch"] <= onset["increment_stretch"] == unstable[0]["stretch"]


@pytest.mark.parametrize("material", ["swift", "power"])
def test_a_strip_pulled_short_of_considere_does_not_neck(material):
    """Pulled to a stretch of 1.25 (eps 0.223, below 0.25) in 16 increments: no neck, the
    stability falling at every increment and still positive at the last (19.4 MPa Swift, 36.0 the
    power law)."""
    mat = MATERIALS[material]()
    watch = NeckWatch(MPI.COMM_WORLD, "stretch", "initial_xy")
    _, rows = strip.strip(mat, 1.25, homogeneous=False, steps=16, n=2, watch=watch)
    assert watch.onset is None
    stability = [r["stability"] for r in rows]
    assert np.all(np.diff(stability) < 0) and stability[-1] > 15.0


def stretched_cup(stroke: float, stop: bool):
    """The paper's cup on 4 x 4 with a holder force of 300 kN, which holds the flange: the punch
    stretches the sheet over its corner until it necks (at about 19.4 mm), in steps of 1.5 mm."""
    return scene.load(DEMOS / "square_cup.toml").changed({
        "mesh.n": 4, "tools.stroke": stroke, "tools.blank_holder_force": 300000.0, "process.initial_step_mm": 1.5,
        "process.max_step_mm": 1.5, "process.stop_at_neck": stop, "process.springback": False, "output.vtx": False,
        "output.vtu": False, "output.png": False, "output.fld": False})


@pytest.fixture(scope="module")
def stretched(tmp_path_factory):
    out = tmp_path_factory.mktemp("neck")
    return {stop: contact_run.run(stretched_cup(30.0, stop), out / str(stop)) for stop in (True, False)}


def test_stop_at_neck_ends_the_stroke_at_the_neck(stretched):
    """With stop_at_neck the stroke ends, as a finished run, at the first increment whose least
    stability is <= 0 (19.69 mm); the onset lies within that increment (19.58 mm), at the punch's
    plan corner (initial (25, 31.25) mm, or its mirror (31.25, 25)), where the cell has thinned by
    0.11 (its most strained quadrature point, equivalent plastic strain 0.25, lost its stability
    first); summary.json and the closing line say so."""
    summary = stretched[True]
    neck = summary["neck"]
    assert summary["stopped"] is None and summary.exit_status() == 0
    assert summary["stroke_mm"] == pytest.approx(neck["increment_stroke_mm"])
    assert 19.0 < neck["stroke_mm"] <= neck["increment_stroke_mm"] < 20.0
    assert neck["stability"] <= 0.0
    # the punch's plan corner, (25, 31.25) mm or its mirror across the diagonal: the cup is symmetric
    # about it, and which of the two mirror cells loses its stability first is the round-off's choice
    assert sorted(neck["initial_xy_mm"]) == pytest.approx([25.0, 31.25])
    assert -0.12 < neck["thickness_strain"] < -0.09
    assert summary.closing_line().count(
        f"neck from stroke {neck['stroke_mm']:.4g} mm at initial ({neck['initial_xy_mm'][0]:.4g}, "
        f"{neck['initial_xy_mm'][1]:.4g}), thickness strain {neck['thickness_strain']:.4f}") == 1
    saved = json.loads((summary.outdir / "summary.json").read_text())
    assert saved["neck"] == neck


def test_the_steps_shorten_ahead_of_the_neck(stretched):
    """The scene's steps are 1.5 mm. Past 18 mm the stability's fall predicts the onset within
    the next step, and the steps shorten to half the distance to it, not below a quarter of the
    first one bounded (0.375 mm): the onset falls into an increment of 0.375 mm, not 1.5. It lies
    the nearer to where short steps put it: the same cup drawn in steps of 1.5, 0.375 and 0.1 mm
    throughout necks at 19.41, 19.64 and 19.79 mm (the stability's linear interpolation over a
    long increment, and the step's error in the plastic state, both put it early); with the
    shortened steps at 19.58 mm, five increments more than the 13 of the fixed 1.5 mm steps."""
    rows = [json.loads(json.dumps(r)) for r in _force_stroke(stretched[True])]
    strokes = np.array([float(r["stroke_mm"]) for r in rows])
    steps = np.diff(np.concatenate([[0.0], strokes]))
    neck = stretched[True]["neck"]
    before = strokes < 18.0 - 1e-9
    assert np.all(steps[before][2:] > 1.0)  # the scene's steps, once grown
    assert steps[-1] == pytest.approx(0.375, rel=1e-9) and strokes[-1] == pytest.approx(neck["increment_stroke_mm"])
    assert np.all(steps[strokes > 18.0 + 1e-9] <= 0.5625 + 1e-9)
    assert 19.5 < neck["stroke_mm"] < 19.79


def _force_stroke(summary) -> list[dict]:
    import csv

    with open(summary.outdir / "force_stroke.csv", newline="") as f:
        return list(csv.DictReader(f))


def test_the_watch_bounds_the_step_ahead_of_the_predicted_onset():
    """After an elastic first increment (least stability 5,000), 30 and 10 at 1.1 and 1.2 (below
    a hundredth of 5,000: the plastic scale) predict 0 at 1.25: a next step of 0.1 is bounded to
    half the distance, 0.025 (the first step bounded, whose quarter, 0.025, is the floor from
    then on), a step of 0.4 then to 0.025 too; a first bound of 0.4 to its quarter, 0.1; a step
    that does not reach 1.25 (0.04) is left as it is. The elastic-plastic transition (5,000,
    4,000, 1,000: a line through the last two reaches 0 at 1.233), a rising stability and a
    neck already found bound nothing."""
    centres = np.array([[0.5, 0.5]])

    def watched(values, at=(1.0, 1.1, 1.2)):
        watch = NeckWatch(MPI.COMM_SELF, "stretch", "initial_xy")
        for a, m in zip(at, values):
            watch.reached(a, np.array([m]), np.array([-0.05]), centres)
        return watch

    assert watched([30.0]).ahead(0.1) == 0.1  # one increment: nothing to extrapolate
    watch = watched([5000.0, 30.0, 10.0])
    assert watch.ahead(0.04) == 0.04
    assert watch.ahead(0.1) == pytest.approx(0.025, rel=1e-12)
    assert watch.ahead(0.4) == pytest.approx(0.025, rel=1e-12)
    assert watched([5000.0, 30.0, 10.0]).ahead(0.4) == pytest.approx(0.1, rel=1e-12)  # the floor, a quarter of 0.4
    assert watched([5000.0, 4000.0, 1000.0]).ahead(0.1) == 0.1
    assert watched([5000.0, 30.0, 35.0]).ahead(0.1) == 0.1
    necked = watched([5000.0, 30.0, 10.0, -1.0], at=(1.0, 1.1, 1.2, 1.3))
    assert necked.onset is not None and necked.ahead(0.1) == 0.1


def test_without_stop_at_neck_the_run_goes_on_and_reports_the_neck(stretched):
    """The stroke drawn to its end (30 mm), thinning past the onset, which it reports in the same
    cell. Its steps are the scene's throughout (only a run that stops at the neck shortens them):
    the onset lies between its increments at 18 and 19.5 mm, at 19.41 mm, earlier than the
    shortened steps put it (the step's error)."""
    on, off = stretched[True], stretched[False]
    assert off["stroke_mm"] == pytest.approx(30.0)
    assert off["neck"]["initial_xy_mm"] == on["neck"]["initial_xy_mm"]
    assert off["neck"]["increment_stroke_mm"] == pytest.approx(19.5)
    assert 18.0 < off["neck"]["stroke_mm"] < on["neck"]["stroke_mm"]
    assert off["min_thickness_strain"] < on["neck"]["thickness_strain"] - 0.05


def test_no_neck_is_null(tmp_path):
    """A plastic run that does not neck writes "neck": null (the cup above stopped at 15 mm)."""
    summary = contact_run.run(stretched_cup(15.0, True), tmp_path)
    assert summary["neck"] is None and summary["stroke_mm"] == pytest.approx(15.0)
    assert '"neck": null' in (tmp_path / "summary.json").read_text()
    assert "neck from" not in summary.closing_line()


def test_stop_at_neck_needs_a_nonlinear_scene_with_plasticity():
    """A linear plate's scene that asks to stop at the neck: an error naming the key."""
    with pytest.raises(InputError) as err:
        scene.load(DEMOS / "square_plate.toml").changed({"process.stop_at_neck": True})
    assert err.value.field == "process.stop_at_neck"
