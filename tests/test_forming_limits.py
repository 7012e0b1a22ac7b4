"""A measured forming-limit curve (issue 33): a CSV of (minor, major) true strains used by the
forming-limit view and the margin in place of Keeler-Brazier (drawn beside it); errors naming
material.forming_limit_curve."""

import csv
from types import SimpleNamespace

import numpy as np
import pytest
from mpi4py import MPI

from shellform import scene
from shellform.errors import InputError
from shellform.results import cup, fld

# an aluminium-like measured curve: (minor, major) true strains
FLC = [[-0.30, 0.52], [-0.15, 0.36], [0.0, 0.24], [0.10, 0.27], [0.25, 0.33]]
SHEET = ["bending", "membrane", "geometric_nonlinearity", "plasticity"]
SWIFT = {"E": 70000.0, "nu": 0.33, "thickness": 1.0, "hardening": "swift", "K": 500.0, "eps0": 0.01, "n": 0.25}
VOCE = {"E": 70000.0, "nu": 0.33, "thickness": 1.0, "hardening": "voce", "yield_stress": 150.0, "Q": 100.0,
        "beta": 10.0}


def write(path, rows, header="minor,major\n"):
    path.write_text(header + "".join(f"{a!r},{b!r}\n" for a, b in rows))
    return path


def test_measured_curve_is_linear_between_and_beyond_its_points():
    curve = fld.measured(FLC)
    for e2, e1 in FLC:
        assert curve(e2) == pytest.approx(e1, rel=1e-15)
    assert curve(0.05) == pytest.approx(0.255, rel=1e-14)
    assert curve(-0.4) == pytest.approx(0.52 + (0.36 - 0.52) / 0.15 * -0.1, rel=1e-14)  # first segment's slope
    assert curve(0.35) == pytest.approx(0.33 + 0.06 / 0.15 * 0.1, rel=1e-14)  # last segment's slope
    assert fld.margins(0.2, 0.0, curve) == pytest.approx(0.04, rel=1e-13)
    assert curve.range == (-0.30, 0.25)


@pytest.mark.parametrize("rows, words", [
    ([[0.0, 0.24]], "at least two rows"),
    ([[0.0, 0.24], [0.0, 0.3]], "minor strain must increase"),
    ([[0.1, 0.24], [0.0, 0.3]], "minor strain must increase"),
    ([[0.0, 0.24], [0.1, -0.3]], "major strain must be positive"),
    ([[0.0, 0.24], [0.1, float("nan")]], "not finite"),
])
def test_measured_curve_errors_name_the_field(rows, words):
    with pytest.raises(InputError) as err:
        fld.measured(rows)
    assert err.value.field == "material.forming_limit_curve" and words in str(err.value)


def test_scene_takes_the_csv_next_to_it_and_keeps_keeler_brazier_beside(tmp_path):
    write(tmp_path / "flc.csv", FLC)
    (tmp_path / "sheet.toml").write_text(
        'effects = ["bending", "membrane", "geometric_nonlinearity", "plasticity"]\n[material]\n'
        + "".join(f"{k} = {v!r}\n".replace("'", '"') for k, v in SWIFT.items())
        + 'forming_limit_curve = "flc.csv"\n')
    s = scene.load(tmp_path / "sheet.toml")
    (curve, label), (kb, kb_label) = fld.curves(s.material)
    assert curve(0.05) == pytest.approx(0.255, rel=1e-14)
    assert label.startswith("measured, flc.csv: FLC0 0.240")
    assert kb(0.0) == pytest.approx(fld.flc0(1.0, 0.25), rel=1e-14) and kb_label.startswith("Keeler-Brazier")
    (only, only_label), beside = fld.curves(scene.from_dict({"effects": SHEET, "material": SWIFT}).material)
    assert beside is None and only(0.0) == kb(0.0) and only_label == kb_label


def test_a_curve_without_n_needs_a_measured_flc(tmp_path):
    """Voce has no Hollomon n: a tool scene with the forming-limit view needs a measured curve
    (refused before any computation, naming the key); with one it is taken."""
    tools = {"effects": SHEET + ["contact"], "geometry": {"lx": 150.0, "ly": 150.0, "region": "quarter"},
             "supports": {"left": "symmetry", "bottom": "symmetry"}, "tools": {}}
    with pytest.raises(InputError) as err:
        scene.from_dict({**tools, "material": VOCE})
    assert err.value.field == "material.forming_limit_curve" and "measured curve" in str(err.value)
    scene.from_dict({**tools, "material": VOCE, "output": {"fld": False}})
    s = scene.from_dict({**tools, "material": {**VOCE, "forming_limit_curve": str(write(tmp_path / "f.csv", FLC))}})
    (curve, _), beside = fld.curves(s.material)
    assert beside is None and curve(0.0) == 0.24


@pytest.mark.parametrize("content, name, field_words", [
    (None, "missing.csv", "cannot read"),
    ("minor,major\n0.0,abc\n", "bad.csv", "row 2 is not two numbers"),
    ("0.0,0.24\n-0.1,0.3\n", "order.csv", "minor strain must increase"),
])
def test_a_flc_csv_that_cannot_be_used_is_named(tmp_path, content, name, field_words):
    if content is not None:
        (tmp_path / name).write_text(content)
    with pytest.raises(InputError) as err:
        scene.from_dict({"effects": SHEET, "material": {**SWIFT, "forming_limit_curve": str(tmp_path / name)}})
    assert err.value.field == "material.forming_limit_curve" and field_words in str(err.value)


def test_forming_limit_view_uses_the_measured_curve(tmp_path):
    """cup.forming_limits writes each cell's margin to the measured curve and returns the
    smallest; the label names the measured curve."""
    s = scene.from_dict({"effects": SHEET, "material": {**SWIFT, "forming_limit_curve":
                                                        str(write(tmp_path / "flc.csv", FLC))}})
    major, minor = np.array([0.1, 0.3, 0.2]), np.array([-0.2, 0.0, 0.2])
    coords = np.arange(27, dtype=float).reshape(3, 9)
    p = SimpleNamespace(material=s.material, comm=MPI.COMM_WORLD, stroke=10.0,  # the drawn sheet's published names
                        cell_fields=lambda: {"major_strain": major, "minor_strain": minor},
                        cell_centres=lambda: coords.reshape(-1, 3, 3).mean(axis=1)[:, :2])
    out = cup.forming_limits(tmp_path, p, "test", png=False)
    curve = fld.measured(FLC)
    expected = curve(minor) - major
    rows = list(csv.DictReader((tmp_path / "fld.csv").open()))
    np.testing.assert_allclose([float(r["margin"]) for r in rows], expected, atol=1e-6)  # the CSV keeps 6 digits
    assert out["min_margin"] == pytest.approx(expected.min(), rel=1e-12)
    assert out["forming_limit"].startswith("measured, flc.csv")
    assert (tmp_path / "fld.png").is_file()
