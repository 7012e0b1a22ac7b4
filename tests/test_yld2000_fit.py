"""Yld2000-2d fitted by least squares (shellform.material.yld2000_fit): on eight data it is the
exact fit; data of a known alpha set at 7 angles give the set back; the ESAFORM 2021 AA6016-T4
fit's errors are docs/results/yld2000_fit/residuals.csv's; malformed data are refused naming the
field. And our Yld2000-2d against an independent implementation (PolyN's tables)."""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import csv
from pathlib import Path

import numpy as np
import pytest

from material_data import AA2090, AA2090_DATA, esaform_data
from shellform import scene
from shellform.errors import InputError
from shellform.material import PAR_, yld2000, yld2000_fit
from shellform.studies import yld2000_fit as study

ROOT = Path(__file__).resolve().parents[1]
TABLE = ROOT / "docs" / "results" / "yld2000_fit" / "residuals.csv"
ANGLES = [0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0]
SHEET = ["bending", "membrane", "geometric_nonlinearity", "plasticity", "anisotropy"]
VOCE = {"E": 70000.0, "nu": 0.33, "thickness": 1.0, "hardening": "voce", "yield_stress": 140.2, "Q": 190.0,
        "beta": 12.4}
# the ESAFORM 2021 AA6016-T4 data (TUAT, docs/references.md) as demos/esaform2021_cup.toml gives them
ESAFORM = {"yield_function": "yld2000", "a": 8.0, **esaform_data()}


def lists_of(data: dict) -> dict:
    """The eight classic data as the least-squares keys (angles 0, 45, 90)."""
    return {"fit_angles": [0.0, 45.0, 90.0], "fit_r": [data["r0"], data["r45"], data["r90"]],
            "fit_sigma": [data["sigma0"], data["sigma45"], data["sigma90"]],
            "sigma_b": data["sigma_b"], "r_b": data["r_b"]}


def test_least_squares_on_the_eight_classic_data_is_the_exact_fit():
    """Eight data for eight alphas: no misfit to share, so the least-squares alphas are those of
    yld2000.fit (which solves the eight equations) to 1e-8, and every error vanishes."""
    exact = yld2000.fit(AA2090_DATA, 8.0)
    fit = yld2000.least_squares(lists_of(AA2090_DATA), 8.0)
    np.testing.assert_allclose(fit.alpha, exact, atol=1e-8)
    assert max(abs(r["error"]) for r in fit.rows) < 1e-8


@pytest.mark.parametrize("with_r_b", [True, False])
def test_data_of_a_known_set_at_7_angles_are_fitted_back(with_r_b):
    """r and sigma/sigma0 of the AA2090-T3 alphas at 0, 15, ..., 90 degrees, sigma_b (and r_b):
    15 or 16 data the set meets exactly, fitted back to 1e-6. The fit normalises sigma_bar to
    the rolling direction's yield stress, so the set comes back scaled by its sigma0 (0.99996)."""
    sigma, r, sigma_b, r_b = yld2000.predicted(AA2090, 8.0, ANGLES)
    values = {"fit_angles": ANGLES, "fit_r": list(r), "fit_sigma": list(250.0 * sigma), "sigma_b": 250.0 * sigma_b}
    if with_r_b:
        values["r_b"] = r_b
    fit = yld2000.least_squares(values, 8.0)
    np.testing.assert_allclose(fit.alpha, sigma[0] * np.array(AA2090), atol=1e-6)
    assert max(abs(row["error"]) for row in fit.rows) < 1e-8
    assert len(fit.rows) == 2 * 7 + 1 + with_r_b


def read_table(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_the_esaform_fit_has_the_documented_errors():
    """The demo's least-squares fit (7 angles, sigma_b, r_b = 1): per datum, the measured,
    fitted and error of docs/results/yld2000_fit/residuals.csv (written by `shellform study
    yld2000-fit` with 6 significant digits) to their 6 digits; the largest errors as docs/material.md
    states them; the scene's material packs the fitted alphas."""
    fit = study.fit_of()
    table = read_table(TABLE)
    assert [(row["quantity"], row["angle_deg"]) for row in table] == [
        (r["quantity"], f"{r['angle_deg']:g}" if r["angle_deg"] != "" else "") for r in fit.rows]
    for row, got in zip(table, fit.rows):
        for k in ("measured", "fitted", "error"):
            assert float(row[k]) == pytest.approx(got[k], rel=6e-6, abs=1e-9), (row, got)
    assert fit.worst("r") == pytest.approx(0.0333, abs=5e-5)
    assert fit.worst("sigma/sigma0") == pytest.approx(0.0281, abs=5e-5)
    s = scene.from_dict({"effects": SHEET, "material": {**VOCE, **ESAFORM}})
    np.testing.assert_allclose(s.hill79().pack()[PAR_:PAR_ + 11], yld2000.pack(fit.alpha, 8.0), rtol=1e-12)
    assert study.fit_of().alpha == fit.alpha
    table = study.markdown(fit, "Yld2000-2d").splitlines()  # docs/material.md includes the study's table
    assert len(table) == 2 + 7 + 1 and table[4] == "| 30 | 0.301 | 0.2677 | -0.0333 | 0.913 | 0.9124 | -0.0006 |"
    assert table[-1].startswith("| biaxial | r_b 1 | 1.0010 | +0.0010 | sigma_b/sigma0 1 | 0.9991 |")


def test_our_yld2000_gives_polyns_table_for_the_siegen_alphas():
    """An independent implementation: the Yld2000-2d alphas of the Siegen team for AA6016-T4
    (a = 8; stefanSCS/PolyN symb_AA6016T4_Yld2000_Postech.txt) and PolyN's predictions of them
    (CM_Data/AA6016_Parameters/AA6016T4_Yld2000_Siegen_deg8_Err_and_Coeff.txt, 4 digits): sigma
    and r at 0, 15, ..., 90 degrees, sigma_b, and PolyN's generalised biaxial r = -r_b/(1 + r_b)."""
    siegen = [0.9238, 0.9967, 0.9365, 1.0227, 1.0303, 1.0075, 0.8385, 1.3761]
    sigma, r, sigma_b, r_b = yld2000.predicted(siegen, 8.0, ANGLES)
    np.testing.assert_allclose(sigma, [1.0000, 0.9800, 0.9336, 0.9080, 0.9264, 0.9662, 0.9831], atol=6e-5)
    np.testing.assert_allclose(r, [0.5261, 0.3643, 0.2521, 0.2530, 0.2791, 0.4215, 0.6013], atol=6e-5)
    assert sigma_b == pytest.approx(0.9910, abs=6e-5)
    assert -r_b / (1.0 + r_b) == pytest.approx(-0.4606, abs=6e-5)


def changed(**keys) -> dict:
    material = {**VOCE, **ESAFORM, **keys}
    return {k: v for k, v in material.items() if v is not None}


@pytest.mark.parametrize("material, field", [
    (changed(fit_r=[0.526, 0.344, 0.301, 0.253, 0.294, 0.393]), "material.fit_r"),
    (changed(fit_sigma=[1.0, 0.944, 0.913, 0.908, 0.898, 0.928, 0.983, 0.9]), "material.fit_sigma"),
    (changed(fit_angles=[0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 120.0]), "material.fit_angles"),
    (changed(fit_angles=[0.0, 15.0, 30.0, 45.0, 60.0, 75.0, -90.0]), "material.fit_angles"),
    (changed(fit_angles=[0.0, 15.0, 30.0, 45.0, 45.0, 75.0, 90.0]), "material.fit_angles"),
    (changed(fit_angles=[5.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0]), "material.fit_angles"),
    (changed(fit_r=[0.526, 0.344, -0.301, 0.253, 0.294, 0.393, 0.601]), "material.fit_r"),
    (changed(fit_r=[0.526, 0.344, 0.301, 0.0, 0.294, 0.393, 0.601]), "material.fit_r"),
    (changed(fit_sigma=[1.0, 0.944, 0.913, 0.908, -0.898, 0.928, 0.983]), "material.fit_sigma"),
    (changed(fit_r=None), "material.fit_r"),
    (changed(fit_angles=None), "material.fit_angles"),
    (changed(sigma_b=None), "material.sigma_b"),
    (changed(r45=0.253), "material.r45"),
    (changed(alpha=AA2090), "material.fit_angles"),
    (changed(fit_angles=[0.0, 90.0], fit_r=[0.526, 0.601], fit_sigma=[1.0, 0.983]), "material.fit_angles"),
])
def test_bad_least_squares_data_are_refused_naming_the_field(material, field):
    """Lists of other lengths, an angle outside [0, 90], one twice, no 0 (the stresses' reference),
    a non-positive r or stress, a list or sigma_b missing, r0 .. sigma90 or alpha beside the
    lists, and fewer than 8 data (2 angles: 2 x 2 + sigma_b + r_b = 6)."""
    with pytest.raises(InputError) as err:
        scene.from_dict({"effects": SHEET, "material": material})
    assert err.value.field == field

