"""The round cup's rim: its ear profile (angle, radial draw-in, height) and the ears of a planar
anisotropic sheet (Hill 1948) on demos/round_cup.toml's tools (docs/cup.md, "Ears")."""

import json
import re
from pathlib import Path

import numpy as np
import pytest

from shellform import cli, scene
from shellform.contact.problem import DrawingProblem
from shellform.results import cup

DEMOS = Path(__file__).resolve().parents[1] / "demos"


def round_cup(tmp_path, stroke: float, n: int, r0: float, r45: float, r90: float, name="cup") -> Path:
    """demos/round_cup.toml with Hill 1948 (r0, r45, r90; rolling direction along x), n elements
    along the radius, the given stroke, and no series or pictures; the scene's path."""
    text = (DEMOS / "round_cup.toml").read_text()
    hill48 = f'\nyield_function = "hill48"\nr0 = {r0}\nr45 = {r45}\nr90 = {r90}\n'
    for pattern, new in ((r"stroke = 45\.0", f"stroke = {stroke}"), (r"\nn = 12\n", f"\nn = {n}\n"),
                         (r"\nr = 0\.41\nm = 2\.0\n", hill48)):
        text, count = re.subn(pattern, new, text)
        assert count == 1, pattern
    text += "\n[output]\nvtx = false\nvtu = false\npng = false\nfld = false\n"
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return path


def test_rim_interpolates_the_draw_in_along_the_angle():
    rows = np.array([[0.0, 1.0, 0.0], [30.0, 2.0, 0.1], [60.0, 5.0, 0.2], [90.0, 3.0, 0.3]])
    d = cup.rim_draw_in(rows)
    assert d == {"rim_0deg": 1.0, "rim_45deg": pytest.approx(3.5, rel=1e-15), "rim_90deg": 3.0}
    assert np.isnan(cup.rim_draw_in(rows[1:], angles=(0.0,))["rim_0deg"])  # not on the rim: no value


def test_round_cup_writes_its_rim(tmp_path):
    """A coarse round cup (74 cells) drawn 4 mm through `shellform run`: rim.csv holds every node
    of the blank's outer edge (those at the blank's radius, counted here from the mesh) from 0 to
    90 degrees, rim.png is drawn, and summary.json's draw-in at 0, 45 and 90 degrees are the
    rim's, equal to DX and DY (the same nodes, on the axes) and to DD (its node lies at 45 degrees
    on this mesh). Through the public API, the profile is hypot(X, Y) - hypot(x, y) and z of the
    nodes at the blank's radius."""
    path = round_cup(tmp_path, 4.0, 6, 2.0, 1.0, 2.0)
    out = tmp_path / "out"
    assert cli.main(["run", str(path), "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stopped"] is None and summary["stroke_mm"] == pytest.approx(4.0)
    rows = np.loadtxt(out / "rim.csv", delimiter=",", skiprows=1)
    assert (out / "rim.csv").read_text().splitlines()[0] == "angle_deg,draw_in_mm,z_mm"
    assert (out / "rim.png").stat().st_size > 10_000

    s = scene.load(path)
    p = DrawingProblem.from_scene(s, verbose=False)
    X, x, _ = p.nodal_values()
    R = s.geometry.radius
    at_radius = np.abs(np.hypot(X[:, 0], X[:, 1]) - R) < 1e-9 * R
    assert p.rim().sum() == at_radius.sum() == len(rows) > 8
    assert np.array_equal(p.rim(), at_radius)
    theta = np.degrees(np.arctan2(X[at_radius, 1], X[at_radius, 0]))
    assert np.allclose(rows[:, 0], np.sort(theta), atol=1e-5)  # the CSV's 6 digits
    assert rows[0, 0] == pytest.approx(0.0, abs=1e-9) and rows[-1, 0] == pytest.approx(90.0, abs=1e-9)
    assert np.all(np.diff(rows[:, 0]) > 0)

    for last in (summary["draw_in_mm"][-1], summary["reports"][-1]["draw_in_mm"]):
        assert last["rim_0deg"] == pytest.approx(last["DX"], rel=1e-12)
        assert last["rim_90deg"] == pytest.approx(last["DY"], rel=1e-12)
        assert last["rim_45deg"] == pytest.approx(last["DD"], rel=1e-9)
        assert last["rim_0deg"] == pytest.approx(rows[0, 1], rel=1e-5)
    rim = summary["rim"]
    assert rim["least_draw_in_mm"] == pytest.approx(rows[:, 1].min(), rel=1e-5)
    assert rim["most_draw_in_mm"] == pytest.approx(rows[:, 1].max(), rel=1e-5)
    assert rim["z_spread_mm"] == pytest.approx(np.ptp(rows[:, 2]), abs=1e-6)

    for target in (0.5, 1.0):  # the same draw, stopping at the scene's report, through the API
        p.driver.run(target)
    X, x, _ = p.nodal_values()
    order = np.argsort(theta)
    profile = cup.rim(p)
    expected = np.column_stack([theta, R - np.hypot(x[at_radius, 0], x[at_radius, 1]), x[at_radius, 2]])[order]
    assert np.allclose(profile, expected, rtol=0, atol=1e-12)
    assert np.allclose(profile[:, 1:], rows[:, 1:], rtol=1e-5, atol=1e-8)  # the CLI's run, to its CSV digits


def hill48_cup(n: int, stroke: float, r0: float, r45: float, r90: float):
    """demos/round_cup.toml's scene with Hill 1948 (rolling direction along x), mesh.n = n."""
    return scene.load(DEMOS / "round_cup.toml").changed({
        "mesh.n": n, "tools.stroke": stroke, "material.r": 1.0, "material.yield_function": "hill48",
        "material.r0": r0, "material.r45": r45, "material.r90": r90, "process.report": []})


@pytest.mark.slow
def test_hill48_round_cup_ears_follow_delta_r():
    """The round cup drawn its whole 30 mm (mesh.n = 12) with Hill 1948, rolling direction along
    x. (On mesh.n = 8, 127 cells of about 7 mm = 9 t, the pinch's free boundary slopes let the
    flange turn a whole cell inside the holder where gmsh's boundary is uneven: the planar
    isotropic rim varies by 4.3 mm there, against 0.18 mm with the slopes held; on n = 10, 12 and
    16 by 0.14, 0.07 and 0.018 mm: docs/contact.md, "Which nodes' slopes".) An ear is where the
    rim is drawn in least:
    the flange's edge stays out there, and the rim stands highest (z; here the rim at 45 degrees
    of sheet (a) has left the holder over the die's shoulder). The classic rule (the ESAFORM 2021
    AA6016-T4 cup, r45 below the mean, measured highest at 0 and 90 degrees and lowest at 45,
    docs/cup.md): ears at 0 and 90 degrees when r45 < (r0 + r90)/2, at 45 degrees when above.
    (a) r0 = r90 = 2, r45 = 1: the most draw-in (a trough) at the rim node next to 45 degrees,
    the least (ears) at 0 or 90; (b) r0 = r90 = 1, r45 = 2: the reverse; both with the earing
    D45 - (D0 + D90)/2 beyond ten times the resolution, which is the spread of draw-in of
    (c) r0 = r45 = r90 = 1.5, planar isotropic, whose rim varies only by the mesh (gmsh's
    quarter is not symmetric about 45 degrees: a node's mirror image in x = y lies up to 3.6 mm
    from the nearest node); that spread is below 2 % of its mean draw-in. The rim's z falls
    where its draw-in grows: ears stand high."""
    rims = {}
    for name, r in {"a": (2.0, 1.0, 2.0), "b": (1.0, 2.0, 1.0), "c": (1.5, 1.5, 1.5)}.items():
        p = DrawingProblem.from_scene(hill48_cup(12, 30.0, *r), verbose=False)
        p.driver.run(1.0)
        assert p.stroke == pytest.approx(30.0)
        rims[name] = cup.rim(p)
    rows = rims["c"]
    resolution = np.ptp(rows[:, 1])
    assert resolution < 0.02 * rows[:, 1].mean(), rows
    step = 90.0 / (len(rows) - 1)  # the rim nodes' spacing (degrees)
    for name, sign in (("a", 1.0), ("b", -1.0)):
        rows = rims[name]
        d = cup.rim_draw_in(rows)
        earing = d["rim_45deg"] - (d["rim_0deg"] + d["rim_90deg"]) / 2
        assert sign * earing > 10 * resolution, (name, d, resolution)
        ears, troughs = (np.argmin, np.argmax) if sign > 0 else (np.argmax, np.argmin)
        assert rows[ears(rows[:, 1]), 0] in (pytest.approx(0.0, abs=1e-9), pytest.approx(90.0)), (name, rows)
        assert abs(rows[troughs(rows[:, 1]), 0] - 45.0) < step, (name, rows)
        z45 = np.interp(45.0, rows[:, 0], rows[:, 2])
        assert sign * ((rows[0, 2] + rows[-1, 2]) / 2 - z45) > 10 * np.ptp(rims["c"][:, 2]), (name, rows)
        assert np.corrcoef(rows[:, 1], rows[:, 2])[0, 1] < -0.9, (name, rows)


@pytest.mark.slow
def test_numisheet_steel_with_three_r_values_draws_in_less_where_r_across_is_higher():
    """The NUMISHEET'93 mild steel (demos/numisheet93_steel.toml, mesh.n = 8) to 15 mm. With
    the averaged r (Hill 1979, r 1.77) the structured quarter mesh is symmetric about x = y
    and DX = DY to rounding; with Hill 1948 from r0 / r45 / r90 = 1.79 / 1.51 / 2.27 (rolling
    direction along x) the flange on the x axis, compressed along y where r90 is the highest r,
    extends radially more than it thickens, and is drawn in less than the flange on the y axis
    (compressed along x, r0 = 1.79): DX < DY by more than 1 % (DX - DY = -0.135 mm, 2.6 % of DY,
    here; -0.139 mm, 2.6 %, on the 16 x 16 demo mesh, docs/cup.md)."""
    base = scene.load(DEMOS / "numisheet93_steel.toml").changed({"mesh.n": 8, "process.report": []})
    out = {}
    for name, changes in {"hill79": {"material.yield_function": "hill79", "material.r": 1.77, "material.m": 2.0,
                                     "material.r0": 0.0, "material.r45": 0.0, "material.r90": 0.0},
                          "hill48": {}}.items():  # the scene is Hill 1948 with the three r values
        p = DrawingProblem.from_scene(base.changed(changes), verbose=False)
        p.driver.run(15.0 / base.tools.stroke)
        assert p.stroke == pytest.approx(15.0)
        out[name] = cup.draw_in(p)
    assert out["hill79"]["DX"] == pytest.approx(out["hill79"]["DY"], rel=1e-9)
    d = out["hill48"]
    assert d["DY"] - d["DX"] > 0.01 * d["DY"], out


def test_the_rim_reaches_its_ends_to_round_off():
    """A rim whose first node lies at 1e-14 degrees (its angle from tabulated coordinates) still
    gives the draw-in at 0 degrees, its first node's; an angle the rim does not reach is nan."""
    rows = np.array([[1e-14, 2.0, 0.0], [30.0, 3.0, 0.0], [60.0, 4.0, 0.0], [90.0 - 1e-13, 5.0, 0.0]])
    d = cup.rim_draw_in(rows)
    assert d == {"rim_0deg": 2.0, "rim_45deg": pytest.approx(3.5), "rim_90deg": 5.0}
    assert np.isnan(cup.rim_draw_in(rows[1:])["rim_0deg"])


def _refuse(constant):
    raise ValueError(f"{constant} is not JSON")


@pytest.mark.parametrize("n", [8, 10])
def test_a_round_cup_summary_is_strict_json_with_the_rims_draw_in(tmp_path, n):
    """The round cup at mesh.n 8 and 10 (their first rim node lies at about 1e-16 degrees, where
    the draw-in at 0 degrees came out NaN) drawn 1 mm through `shellform run`: summary.json
    parses as strict JSON, and rim_0deg, rim_45deg, rim_90deg are finite numbers, rim_0deg DX's."""
    path = round_cup(tmp_path, 1.0, n, 1.0, 1.0, 1.0)
    assert cli.main(["run", str(path), "--out", str(tmp_path / "out"), "--set", "process.springback=false"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text(), parse_constant=_refuse)
    last = summary["draw_in_mm"][-1]
    assert all(isinstance(last[f"rim_{a}deg"], float) and np.isfinite(last[f"rim_{a}deg"]) for a in (0, 45, 90))
    assert last["rim_0deg"] == pytest.approx(last["DX"], rel=1e-9)
