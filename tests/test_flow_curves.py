"""Flow curves (issue 33): Voce, Swift-Voce and a tabulated curve from a CSV file with the
extrapolation beyond its last point chosen by the user, against closed forms; errors naming
the field."""

import math

import numpy as np
import pytest

from shellform import scene
from shellform.errors import InputError
from shellform.material import SheetMaterial, flow_stress, point
from shellform.material.flow_curve import FlowCurve, read_csv

E, NU = 206e3, 0.3
VOCE = dict(yield_stress=150.0, Q=120.0, beta=12.0)
SWIFT = dict(K=565.32, eps0=0.007117, n=0.2589)
STRAINS = [0.0, 1e-3, 0.02, 0.1, 0.25, 0.6, 1.5]


def swift(p):
    return SWIFT["K"] * (SWIFT["eps0"] + p) ** SWIFT["n"]


def voce(p):
    return VOCE["yield_stress"] + VOCE["Q"] * (1.0 - math.exp(-VOCE["beta"] * p))


def check_slope(mat, p):
    h = 1e-7
    fd = (flow_stress(p + h, mat)[0] - flow_stress(p - h, mat)[0]) / (2 * h)
    assert flow_stress(p, mat)[1] == pytest.approx(fd, rel=1e-6, abs=1e-5)  # FD rounding: ~1e-6 MPa


def test_voce_and_swift_voce_against_their_closed_forms():
    v = SheetMaterial(E, NU, hardening="voce", **VOCE).pack()
    sv = SheetMaterial(E, NU, hardening="swift_voce", **VOCE, **SWIFT, swift_weight=0.3).pack()
    for p in STRAINS:
        assert flow_stress(p, v)[0] == pytest.approx(voce(p), rel=1e-14)
        assert flow_stress(p, sv)[0] == pytest.approx(0.3 * swift(p) + 0.7 * voce(p), rel=1e-14)
        if p > 0:
            check_slope(v, p)
            check_slope(sv, p)


def test_voce_material_point_in_uniaxial_tension():
    """The strain-driven uniaxial stress follows the Voce curve at the point's plastic strain."""
    mat = SheetMaterial(E, NU, hardening="voce", **VOCE).pack()
    path = point.uniaxial(mat, 0.2, 20)
    for s, p in zip(path.stress[5:], path.p[5:]):
        assert s[0] == pytest.approx(voce(p), rel=1e-10)


def table(f, p_last=0.3, n=13):
    p = np.linspace(0.0, p_last, n)
    return np.column_stack([p, [f(x) for x in p]])


@pytest.mark.parametrize("extrapolation", ["constant", "linear", "swift", "voce"])
def test_table_is_linear_between_its_points_and_continuous_beyond(extrapolation):
    t = table(swift)
    mat = SheetMaterial(E, NU, hardening="table", flow_curve=t, extrapolation=extrapolation).pack()
    for (p0, s0), (p1, s1) in zip(t[:-1], t[1:]):
        assert flow_stress(p0, mat)[0] == s0
        pm = 0.3 * p0 + 0.7 * p1
        assert flow_stress(pm, mat) == pytest.approx((0.3 * s0 + 0.7 * s1, (s1 - s0) / (p1 - p0)), rel=1e-13)
    pN, sN = t[-1]
    assert flow_stress(pN, mat)[0] == pytest.approx(sN, rel=1e-14)
    beyond = flow_stress(pN + 0.2, mat)
    expected = {"constant": (sN, 0.0), "linear": (sN + 0.2 * (t[-1, 1] - t[-2, 1]) / (t[-1, 0] - t[-2, 0]), None),
                "swift": (swift(pN + 0.2), None), "voce": (None, None)}[extrapolation]
    if expected[0] is not None:
        assert beyond[0] == pytest.approx(expected[0], rel=1e-6)
    if expected[1] is not None:
        assert beyond[1] == expected[1]
    if extrapolation != "constant":
        check_slope(mat, pN + 0.2)


def test_the_tail_fits_recover_the_curve_the_table_was_sampled_from():
    """A table sampled from a Swift curve, extrapolated by Swift: K, eps0, n recovered to 1e-6;
    one sampled from Voce, extrapolated by Voce: its saturation stress and beta to 1e-6."""
    K, e0, n = FlowCurve.from_table(table(swift), "swift").parameters
    assert (K, e0, n) == pytest.approx((SWIFT["K"], SWIFT["eps0"], SWIFT["n"]), rel=1e-6)
    sinf, beta = FlowCurve.from_table(table(voce, 0.15), "voce").parameters
    assert (sinf, beta) == pytest.approx((VOCE["yield_stress"] + VOCE["Q"], VOCE["beta"]), rel=1e-6)
    text = FlowCurve.from_table(table(swift), "swift").extrapolation_text
    assert "Swift 565.32 (0.007117 + p)^0.2589" in text


@pytest.mark.parametrize("rows, extrapolation, field, words", [
    ([[0.0, 200.0], [0.1, 250.0], [0.2, 240.0]], "swift", "material.flow_curve", "decreases"),
    ([[0.0, 200.0], [0.1, 250.0], [0.1, 260.0]], "swift", "material.flow_curve", "must increase"),
    ([[0.01, 200.0], [0.1, 250.0]], "swift", "material.flow_curve", "start at plastic strain 0"),
    ([[0.0, 200.0]], "swift", "material.flow_curve", "two rows"),
    ([[0.0, 200.0], [0.1, 250.0]], "cubic", "material.extrapolation", "one of"),
    ([[0.0, 200.0], [0.1, 250.0]], None, "material.extrapolation", "one of"),
])
def test_table_errors_name_the_field(rows, extrapolation, field, words):
    with pytest.raises(InputError) as err:
        SheetMaterial(E, NU, hardening="table", flow_curve=rows, extrapolation=extrapolation)
    assert err.value.field == field and words in str(err.value)


@pytest.mark.parametrize("kwargs, field", [
    (dict(hardening="voce", yield_stress=150.0, Q=100.0), "material.beta"),
    (dict(hardening="voce", yield_stress=150.0, Q=-1.0, beta=3.0), "material.Q"),
    (dict(hardening="voce", Q=100.0, beta=3.0), "material.yield_stress"),
    (dict(hardening="swift_voce", **VOCE, **SWIFT), "material.swift_weight"),
    (dict(hardening="swift_voce", **VOCE, **SWIFT, swift_weight=1.0), "material.swift_weight"),
    (dict(hardening="table", extrapolation="swift"), "material.flow_curve"),
])
def test_curve_errors_name_the_field(kwargs, field):
    with pytest.raises(InputError) as err:
        SheetMaterial(E, NU, **kwargs)
    assert err.value.field == field


SHEET = ["bending", "membrane", "geometric_nonlinearity", "plasticity"]


def test_scene_reads_the_csv_next_to_it(tmp_path):
    (tmp_path / "curve.csv").write_text("plastic_strain,true_stress_MPa\n# from a tensile test\n"
                                        + "".join(f"{float(p)!r},{float(s)!r}\n" for p, s in table(swift)))
    (tmp_path / "sheet.toml").write_text(
        f'effects = {SHEET!r}\n[material]\nE = 206000.0\nthickness = 0.8\nhardening = "table"\n'
        'flow_curve = "curve.csv"\nextrapolation = "swift"\n'.replace("'", '"'))
    s = scene.load(tmp_path / "sheet.toml")
    mat = s.hill79().pack()
    for p in (0.0, 0.1, 0.5):
        assert flow_stress(p, mat)[0] == pytest.approx(swift(p), rel=2e-3 if p == 0.1 else 1e-6)
    np.testing.assert_array_equal(read_csv(tmp_path / "curve.csv"), table(swift))


@pytest.mark.parametrize("content, name, words", [
    (None, "missing.csv", "cannot read"),
    ("0.0, 200\n0.1, abc\n", "bad.csv", "row 2 is not two numbers"),
    ("0.0, 200, 1\n", "wide.csv", "3 columns"),
    ("0.0, 200\n", "curve.txt", "must be a .csv file"),
])
def test_a_csv_that_cannot_be_read_is_named(tmp_path, content, name, words):
    if content is not None:
        (tmp_path / name).write_text(content)
    with pytest.raises(InputError) as err:
        scene.from_dict({"effects": SHEET, "material": {"hardening": "table", "extrapolation": "constant",
                                                         "flow_curve": str(tmp_path / name)}})
    assert err.value.field == "material.flow_curve" and words in str(err.value)


def test_the_material_line_states_the_extrapolation():
    """SheetMaterial.describe (a run's log line) names the table's fitted extrapolation."""
    line = SheetMaterial(E, NU, hardening="table", flow_curve=table(swift), extrapolation="swift").describe()
    assert line.startswith("material: yield function hill79; r 1, m 2; hardening table; beyond p = 0.3")
    assert "Swift 565.32 (0.007117 + p)^0.2589 fitted to the last 7 points" in line


@pytest.mark.timeout(30)
@pytest.mark.parametrize("kind", ["/dev/zero", "a FIFO", "a folder", "too large"])
@pytest.mark.parametrize("key", ["flow_curve", "forming_limit_curve"])
def test_a_csv_that_is_no_regular_file_is_refused_within_seconds(tmp_path, capsys, kind, key):
    """A scene's CSV named curve.csv but a link to /dev/zero (endless: read whole, it took 24 GB
    before the OOM killer ended the run), a FIFO (no writer: the read waited forever), a folder
    or a file past the 1 MB limit: `shellform check` exits 2 within seconds, naming the field."""
    import os
    import time

    from shellform import cli

    good = "".join(f"{float(p)!r},{float(s)!r}\n" for p, s in table(swift))
    (tmp_path / "good.csv").write_text(good)
    bad = tmp_path / "curve.csv"
    if kind == "/dev/zero":
        bad.symlink_to("/dev/zero")
    elif kind == "a FIFO":
        os.mkfifo(bad)
    elif kind == "a folder":
        bad.mkdir()
    else:
        bad.write_text("#" * 1_100_000 + "\n" + good)
    curves = {"flow_curve": "good.csv", "forming_limit_curve": "good.csv", key: "curve.csv"}
    (tmp_path / "sheet.toml").write_text(
        f'effects = {SHEET!r}\n[material]\nE = 206000.0\nthickness = 0.8\nhardening = "table"\n'
        f'flow_curve = "{curves["flow_curve"]}"\nextrapolation = "swift"\n'
        f'forming_limit_curve = "{curves["forming_limit_curve"]}"\n'.replace("'", '"'))
    t0 = time.monotonic()
    rc = cli.main(["check", str(tmp_path / "sheet.toml")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and time.monotonic() - t0 < 10
    assert err[-1].startswith(f"shellform: input error: material.{key}: ") and "curve.csv" in err[-1], err


@pytest.mark.parametrize("row", [(0.1, 1e308), (1e300, 400.0), (0.2, 2e5)])
def test_a_flow_curve_past_its_range_names_the_row(row):
    """Stresses of 1e308 MPa (today: a scipy ValueError from the Swift fit), a plastic strain of
    1e300, or 200 GPa: InputError naming material.flow_curve and the row."""
    t = np.array([(0.0, 200.0), (0.05, 300.0), row])
    with pytest.raises(InputError) as err:
        FlowCurve.from_table(t, "swift")
    assert err.value.field == "material.flow_curve" and "row 3" in str(err.value)
