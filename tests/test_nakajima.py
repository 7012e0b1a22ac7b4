"""The Nakajima test (demos/nakajima.toml, study nakajima): a stroke that ends at the
forming-limit curve, and the strain paths that specimens of different widths take to it."""

import csv

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
import pytest
from mpi4py import MPI

from shellform.results import fld


def _line(e2):
    """A forming-limit curve for the unit tests: 0.3 + |minor|."""
    return 0.3 + np.abs(np.asarray(e2, dtype=float))


def test_the_watch_interpolates_the_stroke_where_the_margin_reaches_zero():
    """Margins 0.3 - major: 0.2 and 0.1 at 1 and 2 mm, -0.1 at 4 mm. The limit is where the
    margin, linear between the last increment above 0 and the first at or below it, is 0:
    3 mm; none before; the first crossing stays the limit."""
    watch = fld.FormingLimitWatch(_line, MPI.COMM_SELF)
    for stroke in (1.0, 2.0):
        assert not watch.reached(stroke, np.array([0.1 * stroke, 0.01]), np.zeros(2))
    assert watch.limit is None
    assert watch.reached(4.0, np.array([0.4, 0.0]), np.zeros(2))
    assert watch.limit["stroke_mm"] == pytest.approx(3.0, rel=1e-12)
    assert watch.limit["increment_stroke_mm"] == 4.0
    assert watch.limit["margin"] == pytest.approx(-0.1)
    first = watch.limit
    assert watch.reached(5.0, np.array([0.5]), np.zeros(1))
    assert watch.limit is first


def test_strain_paths_are_recorded_every_spacing_and_at_the_end():
    paths = fld.StrainPaths(_line, MPI.COMM_SELF, spacing=1.0)
    for stroke in np.arange(0.25, 3.01, 0.25):
        paths.record(stroke, np.array([0.1, 0.1 * stroke]), np.array([0.0, -0.02 * stroke]))
    paths.record(3.1, np.array([0.1, 0.31]), np.array([0.0, -0.062]), final=True)
    assert paths.strokes == [0.25, 1.25, 2.25, 3.1]
    crit = paths.critical(np.array([[1.0, 2.0], [3.0, 4.0]]))
    assert crit["initial_xy_mm"] == [3.0, 4.0]  # its margin at the end: 0.3 + 0.062 - 0.31 > 0, the other's 0.2
    assert crit["major"] == pytest.approx([0.025, 0.125, 0.225, 0.31], rel=1e-6)
    assert crit["margin"][-1] == pytest.approx(0.3 + 0.062 - 0.31, rel=1e-5)


@pytest.fixture(scope="module")
def specimens(tmp_path_factory):
    """A narrow waist (20 mm) and the whole disc on the coarse mesh n = 8, each drawn to the
    forming-limit curve."""
    from shellform.contact import run as contact_run
    from shellform.studies import nakajima

    out = tmp_path_factory.mktemp("nakajima")
    runs = {}
    for width in (20, 180):
        s = nakajima.scene_of(width, 8, out).changed({"output.png": False, "process.max_step_mm": 0.6})
        summary = contact_run.run(s, out / f"W{width}")
        with open(out / f"W{width}" / "strain_path.csv") as f:
            path = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
        runs[width] = summary, path
    return runs


@pytest.mark.parametrize("width", [20, 180])
def test_the_stroke_ends_where_the_forming_limit_is_reached(specimens, width):
    """The run ends as a finished run (exit status 0), at the first increment whose smallest
    margin is <= 0: the interpolated limit lies within that increment, the margin there is just
    below 0, and the strain path's last point is the worst element of the FLD."""
    summary, path = specimens[width]
    limit = summary["forming_limit_reached"]
    assert summary["stopped"] is None and summary.exit_status() == 0
    assert summary["stroke_mm"] < 60.0  # the scene's stroke: the limit ended it sooner
    assert limit["increment_stroke_mm"] == pytest.approx(summary["stroke_mm"])
    assert path[-2]["stroke_mm"] < limit["stroke_mm"] <= limit["increment_stroke_mm"]
    assert -0.03 < limit["margin"] <= 0.0
    assert path[-1]["margin"] == pytest.approx(summary["min_margin"], abs=1e-6)
    assert path[-2]["margin"] > 0.0
    assert summary["over_the_stroke"]["force_balance"] < 1e-5
    assert summary["cutbacks"] == 0


def test_a_narrow_waist_is_pulled_in_uniaxial_tension_the_whole_disc_equibiaxially(specimens):
    """The critical elements' strain ratios at the limit: the 20 mm waist near uniaxial tension
    (minor / major about -r / (1 + r), -0.64 for r0 = 1.79), the disc near equibiaxial
    stretching (1), the narrow waist's limit reached at a lower dome than the disc's; both
    paths proportional to within 0.15 in their ratio over the last half of the stroke."""
    (narrow, n_path), (disc, d_path) = specimens[20], specimens[180]
    ratio = lambda p: p["minor"] / p["major"]  # noqa: E731
    assert -0.7 < ratio(n_path[-1]) < -0.35
    assert 0.55 < ratio(d_path[-1]) <= 1.0
    assert narrow["forming_limit_reached"]["stroke_mm"] < disc["forming_limit_reached"]["stroke_mm"]
    for p in (n_path, d_path):
        late = [ratio(q) for q in p if q["stroke_mm"] > 0.5 * p[-1]["stroke_mm"]]
        assert np.ptp(late) < 0.15


def test_stopping_at_the_forming_limit_needs_a_tool_scene_with_plasticity():
    """A plate's scene (no tools, no plasticity) that asks to stop at the forming limit: an
    error naming the key, before anything is solved."""
    from shellform import demos, scene
    from shellform.errors import InputError

    with pytest.raises(InputError) as err:
        scene.load(demos.path("clamped_disc_large_deflection.toml")).changed(
            {"process.stop_at_forming_limit": True})
    assert err.value.field == "process.stop_at_forming_limit"
