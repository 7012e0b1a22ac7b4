"""The ESAFORM 2021 cup's height profile (study esaform-cup): the height as the study defines it,
on sheets of known shape, the measured profile's answers, and a tiny run of the study."""

import csv
import json

import numpy as np
import pytest

from shellform.results import run_folder
from shellform.results.vtu import last_step, read_vtu
from shellform.studies import esaform_cup as ec


def polar_blank(radius, n_r, n_t, r_split=None):
    """A quarter disc's nodes on a polar grid (the centre once, r_split among the radii) and its
    triangles: (X (n, 3), triangles, radii, angles in degrees)."""
    radii = np.linspace(0.0, radius, n_r + 1)[1:]
    if r_split is not None:
        radii = np.unique(np.append(radii, r_split))
    angles = np.linspace(0.0, 90.0, n_t + 1)
    X = [np.zeros(3)]
    for r in radii:
        for a in np.radians(angles):
            X.append([r * np.cos(a), r * np.sin(a), 0.0])
    X = np.array(X)

    def node(i, j):  # ring i (0: the first radius), angle j
        return 1 + i * len(angles) + j

    tris = [(0, node(0, j), node(0, j + 1)) for j in range(n_t)]
    for i in range(len(radii) - 1):
        for j in range(n_t):
            a, b, c, d = node(i, j), node(i, j + 1), node(i + 1, j), node(i + 1, j + 1)
            tris += [(a, c, d), (a, d, b)]
    return X, np.array(tris), radii, angles


def test_height_of_a_drawn_through_cup_of_known_shape():
    """A flat bottom at z = -s and a vertical wall of radius r_p whose height carries ears,
    (R - r_p)(1 + b cos 4 theta): the rim's top is its mid-surface (a vertical wall), the
    bottom's outer face t0/2 below its mid-surface, so h = (R - r_p)(1 + b cos 4 theta) + t0/2,
    whatever the rim's thickness; mean (R - r_p) + t0/2, d0 = d90 = 2 b (R - r_p)."""
    R, rp, s, t0, b = 53.75, 30.6, 40.0, 1.0, 0.02
    X, tris, _, _ = polar_blank(R, 12, 36, r_split=rp)
    rho, theta = np.hypot(X[:, 0], X[:, 1]), np.arctan2(X[:, 1], X[:, 0])
    wall = rho > rp + 1e-9
    x = X.copy()
    x[:, 2] = -s
    x[wall, 0], x[wall, 1] = rp * np.cos(theta[wall]), rp * np.sin(theta[wall])
    x[wall, 2] = -s + (rho[wall] - rp) * (1.0 + b * np.cos(4.0 * theta[wall]))
    e33 = np.where(rho > R - 1e-9, np.log(1.5), 0.0)  # a thickened rim: its top is still its mid-surface
    rim, z_bottom = ec.rim_and_bottom(x, tris, x - X, e33, t0, R)
    assert len(rim) == 37 and z_bottom == pytest.approx(-s - t0 / 2, abs=1e-12)
    assert np.allclose(rim[:, 4], 0.0, atol=1e-12)  # |n_z| of a vertical wall
    assert np.allclose(rim[:, 3], 1.5 * t0)
    h = ec.heights(rim, z_bottom)
    for a in ec.ANGLES:
        want = (R - rp) * (1.0 + b * np.cos(np.radians(4.0 * a))) + t0 / 2
        assert h[f"h{a:g}"] == pytest.approx(want, abs=1e-9)
    assert h["mean"] == pytest.approx(R - rp + t0 / 2, abs=1e-9)  # the trapezoidal rule: exact for cos 4 theta
    assert h["d0"] == pytest.approx(2 * b * (R - rp), abs=1e-9)
    assert h["d90"] == pytest.approx(2 * b * (R - rp), abs=1e-9)


def test_height_of_a_flat_flange_counts_half_its_thickness():
    """A flat sheet pushed down by s in its middle with a flat flange: the flange's top is
    t/2 above its mid-surface (|n_z| = 1), the bottom's face t0/2 below: h = s + t_rim/2 + t0/2."""
    R, s, t0 = 50.0, 3.0, 1.0
    X, tris, _, _ = polar_blank(R, 10, 18)
    rho = np.hypot(X[:, 0], X[:, 1])
    x = X.copy()
    x[rho < 20.0, 2] = -s
    e33 = np.where(rho > R - 1e-9, np.log(1.2), 0.0)
    rim, z_bottom = ec.rim_and_bottom(x, tris, x - X, e33, t0, R)
    assert np.allclose(rim[:, 4], 1.0)
    h = ec.heights(rim, z_bottom)
    assert h["mean"] == pytest.approx(s + 0.6 + 0.5, abs=1e-12)
    assert h["d0"] == pytest.approx(0.0, abs=1e-12) and h["d90"] == pytest.approx(0.0, abs=1e-12)


def test_the_measured_profile():
    """docs/references.md section 6: 34.515 at 0.48 degrees, 33.131 at 45.03, 34.914 at 89.96;
    the whole circle's mean 34.13 mm (34.15 with the repeated row)."""
    m = ec.measured()
    assert m["mean"] == pytest.approx(34.13, abs=0.005)
    assert ec.MEASURED[:, 1].mean() == pytest.approx(34.15, abs=0.005)
    assert m["first"]["h45"] == pytest.approx(33.131, abs=0.002)
    assert m["first"]["h90"] == pytest.approx(34.914, abs=0.002)
    assert m["first"]["h0"] == pytest.approx(34.515, abs=0.02)  # interpolated to 0 from 0.48 and 344.8 degrees
    assert m["first"]["d0"] == pytest.approx(m["first"]["h0"] - m["first"]["h45"])
    # folded: the four quadrants' mean; at 0 degrees the rows at 0.48 and 180.2 degrees
    assert m["folded"]["h0"] == pytest.approx(0.5 * (34.498 + 35.25), abs=0.01)


def test_the_peers_profiles(tmp_path):
    """A quadrant mirrored onto the circle repeats it at 180 - a, 180 + a and 360 - a; the peers'
    Poly6 profiles (PolyN at 4c62d0af): PolyN's Abaqus run h(0) 34.208, h(90) 34.525 and the
    45-degree trough 31.00 mm read off its file's points (d0 3.21, d90 3.52), the paper's Fig. 103
    d0 1.87, d90 1.80; written to peers.csv."""
    q = np.array([(0.0, 1.0), (30.0, 2.0), (90.0, 3.0)])
    c = ec.circle(q)
    assert c[0].tolist() == [0.0, 1.0] and c[-1].tolist() == [360.0, 1.0]
    got = ec.measured_at([0.0, 30.0, 150.0, 210.0, 330.0, 90.0, 270.0], c)
    np.testing.assert_allclose(got, [1.0, 2.0, 2.0, 2.0, 2.0, 3.0, 3.0], atol=1e-12)
    rows = {r["peer"]: r for r in ec.peers(tmp_path)}
    abaqus = rows["PolyN's Abaqus run of its Poly6"]
    assert abaqus["h0"] == pytest.approx(34.2081) and abaqus["h90"] == pytest.approx(34.5245)
    assert abaqus["h45"] == pytest.approx(31.00, abs=0.01)
    assert abaqus["d0"] == pytest.approx(3.21, abs=0.01) and abaqus["d90"] == pytest.approx(3.52, abs=0.01)
    fig103 = rows["the benchmark's Poly6 participant (Fig. 103)"]
    assert fig103["d0"] == pytest.approx(1.87, abs=0.01) and fig103["d90"] == pytest.approx(1.80, abs=0.01)
    assert (tmp_path / "peers.csv").exists()


def test_errors_and_goals():
    m = ec.measured()
    r = {f"h{a:g}": m["first"][f"h{a:g}"] for a in ec.ANGLES}
    r.update(mean=m["mean"] * 1.029, d0=m["first"]["d0"] * 0.76, d90=m["first"]["d90"] * 1.24)
    r = ec.with_errors(r, m)
    assert r["err_mean"] == pytest.approx(0.029) and r["err_d0"] == pytest.approx(-0.24)
    assert r["ears_right"] and r["goals_met"]
    r = ec.with_errors({**r, "d0": m["first"]["d0"] * 0.7}, m)
    assert not r["goals_met"]
    r = ec.with_errors({**r, "h45": 40.0, "d0": 1.0}, m)
    assert not r["ears_right"]


def test_the_study_reuses_a_run_of_this_scene_by_this_code_only(tmp_path, monkeypatch):
    """A run folder is reused, not drawn again, only where its run.json names this scene and this
    code version and its results are there; a run of other code (stopped or not) is drawn again."""
    drawn = []
    monkeypatch.setattr(ec, "run_cup", lambda s, d: drawn.append(d))
    monkeypatch.setattr(ec, "tables", lambda out, levels: [])
    s = ec.scene_of("yld2000", 6, ec.QUICK_STROKE)
    d = ec.folder(tmp_path, ec.run_name("yld2000", 6))
    d.mkdir(parents=True)
    for name in ("summary.json", "cup.pvd"):
        (d / name).write_text("{}")
    manifest = {"scene_hash": run_folder.scene_hash(s), "code_version": run_folder.code_version()}
    (d / run_folder.MANIFEST).write_text(json.dumps(manifest))
    ec.run(tmp_path, levels=(6,), models=("yld2000",), stroke=ec.QUICK_STROKE)
    assert drawn == []
    (d / run_folder.MANIFEST).write_text(json.dumps({**manifest, "code_version": "0+src.another"}))
    ec.run(tmp_path, levels=(6,), models=("yld2000",), stroke=ec.QUICK_STROKE)
    assert drawn == [d]


@pytest.mark.slow
def test_esaform_cup_tiny(tmp_path):
    """n = 6, 4 mm, Yld2000-2d: the study's table has a row per run with every column; the rim
    is still flat under the holder, so its top is the holder's face (the highest top under it),
    and the bottom's outer face is the lowest node's lower face, below the punch."""
    rows = ec.run(tmp_path, levels=ec.QUICK_LEVELS, models=("yld2000",))
    assert len(rows) == 1
    r = rows[0]
    assert r["finished"] and r["stroke_mm"] == pytest.approx(ec.QUICK_STROKE)
    for a in ec.ANGLES:
        assert f"h{a:g}" in r and f"err_h{a:g}" in r
    with open(tmp_path / "esaform_cup.csv") as f:
        table = list(csv.DictReader(f))
    assert len(table) == 1 and float(table[0]["mean"]) == pytest.approx(r["mean"])
    assert (tmp_path / "esaform_cup.png").stat().st_size > 0
    assert "measured, first quadrant" in (tmp_path / "esaform_cup.md").read_text()
    d = tmp_path / "yld2000_n_6"
    with open(d / "force_stroke.csv") as f:
        last = list(csv.DictReader(f))[-1]
    rim = np.loadtxt(d / "rim_height.csv", delimiter=",", skiprows=1)
    assert np.all(rim[:, 4] > 0.999)  # flat under the holder
    assert rim[:, 1].max() == pytest.approx(float(last["holder_height_mm"]), abs=1e-9)
    # the bottom's outer face: the lowest node's z - t/2 (the bottom is flat: |n_z| = 1 to 1e-3),
    # at least the bottom's thickness below the punch's face t0/2 - stroke (the punch pushes on
    # the sheet's upper face; the bottom may hang below it)
    _, vtu = last_step(d / "cup.pvd")
    points, _, data, _ = read_vtu(vtu)
    lower = points[:, 2] - 0.5 * np.exp(data["thickness_strain"])
    assert r["z_bottom_mm"] == pytest.approx(lower.min(), abs=1e-3)
    assert r["z_bottom_mm"] <= 0.5 - ec.QUICK_STROKE - np.exp(data["thickness_strain"]).min() \
        + float(last["max_penetration_mm"])
    assert r["h45"] == pytest.approx(rim[:, 1].max() - r["z_bottom_mm"], abs=0.1)
