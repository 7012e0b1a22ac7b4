"""Short versions of the square-cup studies (issue 11): what accuracy costs in time.

The numisheet-cost study's runs on a coarse mesh, 1.5 mm of stroke: every run finishes in
balance, each choice moves the answers by what it should, and the picks for 1, 2 and 5 % are
runs that really lie within them. Its reference and its picking on tables made by hand; the
cup-mesh study's picking (against its finest run) too.
"""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import csv
import json
import math
from pathlib import Path

import pytest

from shellform.errors import InputError
from shellform.results.tables import as_written
from shellform.studies import cup_accuracy, cup_paper, numisheet_cost
from shellform.studies.cup_hard import folder

ROOT = Path(__file__).resolve().parents[1]


def test_picks_take_the_cheapest_run_within_each_tolerance():
    rows = [{"case": "fine", "finished": True, "wall_s": 100.0, "rel_diff_DX": 0.0, "worst_rel_diff": 0.0},
            {"case": "a", "finished": True, "wall_s": 10.0, "rel_diff_DX": -0.08, "worst_rel_diff": 0.2},
            {"case": "b", "finished": True, "wall_s": 30.0, "rel_diff_DX": 0.03, "worst_rel_diff": 0.03},
            {"case": "c", "finished": False, "wall_s": 5.0, "rel_diff_DX": 0.001, "worst_rel_diff": 0.001},  # stopped
            {"case": "d", "finished": True, "wall_s": 40.0, "rel_diff_DX": -0.004, "worst_rel_diff": 0.004}]
    chosen = {(p["quantity"], p["tolerance"]): p["case"] for p in cup_accuracy.picks(rows, "fine", ("DX",))}
    assert chosen == {("DX", 0.01): "d", ("DX", 0.05): "b", ("DX", 0.10): "a",
                      ("all", 0.01): "d", ("all", 0.05): "b", ("all", 0.10): "b"}
    none = cup_accuracy.picks(rows, "fine", ("DX",), tolerances=(1e-4,))[0]
    assert none["case"] == "none coarser than fine" and none["wall_s"] == ""


def test_numisheet_cost_reference_is_the_converged_answer():
    """The reference of each answer: the cup-convergence study's Richardson estimate where it
    found an order, else its finest mesh's value, with the uncertainty it states."""
    ref = numisheet_cost.reference(ROOT / "docs" / "results" / numisheet_cost.ESTIMATES)
    assert set(ref) == set(numisheet_cost.answers())
    assert ref["DX_15"][0] == pytest.approx(5.15221) and ref["DX_15"][1] == pytest.approx(0.00416298)
    assert ref["DX_15"][2].startswith("Richardson")
    assert ref["DD_15"][0] == pytest.approx(2.89934) and ref["DD_15"][1] == pytest.approx(0.0124559)
    assert ref["DD_15"][2] == "finest mesh, no order"


def test_studies_of_other_studies_results_read_them_beside_out_before_any_run(tmp_path):
    """numisheet-cost's reference (cup-convergence's estimates) and cup-paper's runs (cup-mesh's,
    cup-hard's) lie in the folders beside --out, as docs/results/ holds them; where they are
    missing the study says which to run, before its first run."""
    with pytest.raises(InputError, match="study cup-convergence --out .*cup_convergence"):
        numisheet_cost.run(tmp_path / "numisheet_cost")
    with pytest.raises(InputError, match="study cup-mesh --out .*cup_mesh.* cup-hard --out .*cup_hard"):
        cup_paper.run(tmp_path / "cup_paper")
    assert not (tmp_path / "numisheet_cost").exists() and not (tmp_path / "cup_paper").exists()


def test_numisheet_cost_picks_credit_no_more_than_the_reference_vouches_for():
    ref = {"DX": (10.0, 0.05, "r"), "F": (50.0, 1.5, "r")}  # 0.5 % and 3 % uncertain
    rows = [{"case": "a", "finished": True, "cpu_s": 10.0, "error_DX": 0.012, "error_F": 0.001},
            {"case": "b", "finished": True, "cpu_s": 30.0, "error_DX": 0.004, "error_F": -0.01},
            {"case": "c", "finished": False, "cpu_s": 5.0, "error_DX": 0.0, "error_F": 0.0},  # stopped
            {"case": "d", "finished": True, "cpu_s": 40.0, "error_DX": 0.001, "error_F": 0.03}]
    chosen = {(p["answer"], p["tolerance"]): (p["case"], p["verdict"][:14])
              for p in numisheet_cost.picks(rows, ref)}
    assert chosen[("DX", 0.01)] == ("b", "within")  # a: 1.2 % + 0.5 % > 1 %
    assert chosen[("DX", 0.02)] == ("a", "within")  # 1.2 + 0.5 <= 2
    assert chosen[("F", 0.01)] == ("", "not decidable:") and chosen[("F", 0.02)] == ("", "not decidable:")
    assert chosen[("F", 0.05)] == ("a", "within")
    assert chosen[("all", 0.05)] == ("a", "within")
    rows[0]["error_F"] = 0.04  # 4 % + 3 % > 5 %
    assert {(p["answer"], p["tolerance"]): p["case"] for p in numisheet_cost.picks(rows, ref)}[("all", 0.05)] == "b"
    for r in rows:
        r["worst_error"] = max(abs(r["error_DX"]), abs(r["error_F"]))
    assert [r["case"] for r in numisheet_cost.pareto(rows)] == ["a", "b"]  # d costs more and is worse


@pytest.mark.slow
def test_numisheet_cost_short(tmp_path):
    """The study's runs on a 4 x 4 mesh drawn 1.5 mm, measured against the scene's own run: each
    choice moves the answers by what it should, and the cost is one thread's CPU seconds."""
    runs = numisheet_cost.runs(levels=(4,), varied=(4,), graded=False, stroke=1.5)
    assert [name for name, _ in runs] == ["n 4", "n 4, 2x step", "n 4, half step", "n 4, 3 points", "n 4, 7 points",
                                          "n 4, 9 points", "n 4, rtol 1e-05", "n 4, rtol 0.0001"]
    numisheet_cost.draw_all(tmp_path, runs)
    own = json.loads((folder(tmp_path, "n 4") / "summary.json").read_text())
    at = own["reports"][-1]
    ref = {"DX_1.5": (at["draw_in_mm"]["DX"], 1e-3 * at["draw_in_mm"]["DX"], "n 4"),
           "force_1.5": (at["punch_force_kN"], 1e-3 * at["punch_force_kN"], "n 4"),
           "min_thickness_strain": (own["min_thickness_strain"], 1e-3 * abs(own["min_thickness_strain"]), "n 4")}
    rows = {r["case"]: r for r in numisheet_cost.table(tmp_path, runs, ref)}
    for name, s in runs:
        r, summary = rows[name], json.loads((folder(tmp_path, name) / "summary.json").read_text())
        assert r["finished"] and r["stroke_mm"] == pytest.approx(1.5) and summary["threads"] == 1
        assert 0 < r["cpu_s"] and summary["over_the_stroke"]["force_balance"] <= max(1e-6, s.process.rtol)
    assert all(rows["n 4"][f"error_{q}"] == 0.0 for q in ref)
    assert max(abs(rows["n 4, rtol 0.0001"][f"error_{q}"]) for q in ref) < 1e-3  # Newton's tolerance only
    assert max(abs(rows["n 4, 2x step"][f"error_{q}"]) for q in ref) < 0.05
    assert abs(rows["n 4, 9 points"]["error_force_1.5"]) < 0.02  # 5 points integrate the section well
    assert rows["n 4, half step"]["increments"] > rows["n 4"]["increments"] > rows["n 4, 2x step"]["increments"]
    with open(tmp_path / "numisheet_cost_picks.csv") as f:
        for p in csv.DictReader(f):
            assert p["verdict"] == "within", p  # every tolerance is decidable and n 4 itself is within
            assert abs(float(p["error"])) + 1e-3 <= float(p["tolerance"]) + 1e-12
            assert float(p["cpu_s"]) <= as_written([rows["n 4"]])[0]["cpu_s"]  # both as the CSVs write them
    assert (tmp_path / "numisheet_cost_error_time.png").stat().st_size > 0
    table = (tmp_path / "numisheet_cost.md").read_text()
    assert all(f"| {name} | " in table for name, _ in runs)
    every = next(line for line in table.splitlines() if line.startswith("| all | "))
    assert every.count(" s)") == 3  # a run within each tolerance, named with its CPU seconds


@pytest.mark.slow
@pytest.mark.mpi
def test_cup_benchmark_short(tmp_path):
    """cup-benchmark on a 6 x 6 quarter mesh, 1 mm, on 1 and 2 ranks, with Newton's tolerance at
    1e-6 and 1e-4, and on one core: the split of an iteration adds up to its time, the two ranks
    draw the same cup (draw-in and force to 1e-6), the looser tolerance within 1e-4 of it in fewer
    iterations, the one-core run (one thread) the same cup as the first row's to 1e-9."""
    from shellform.studies import cup_benchmark

    rows = cup_benchmark.run(tmp_path, levels=(6,), strokes={6: 1.0}, mpi_levels=(6,), loose=(6, (1e-4,)),
                             one_core=(6,))
    assert [(r["ranks"], r["cells"], r["rtol"]) for r in rows] == [(1, 72, 1e-6), (2, 72, 1e-6), (1, 72, 1e-4),
                                                                  (2, 72, 1e-4), (1, 72, 1e-6)]
    assert rows[4]["case"] == "n 6, one core" and rows[4]["threads"] == 1
    assert rows[4]["newton_iterations"] == rows[0]["newton_iterations"]
    assert rows[2]["newton_iterations"] < rows[0]["newton_iterations"]
    for r in rows:
        assert r["finished"] and r["stroke_mm"] == pytest.approx(1.0)
        parts = sum(r[f"{p}_ms"] for p in cup_benchmark.PARTS) + r["rest_ms"]
        assert parts == pytest.approx(r["iteration_ms"], rel=1e-9)
        assert all(r[f"{p}_ms"] > 0 for p in cup_benchmark.PARTS) and 0 <= r["rest_share"] < 1
    assert (tmp_path / "cup_benchmark.png").stat().st_size > 0
    with open(tmp_path / "cup_benchmark.csv") as f:
        assert len(list(csv.DictReader(f))) == 5
    for rtol in (None, 1e-4):
        one, two = (json.loads((cup_benchmark.case_folder(tmp_path, 6, k, rtol) / "summary.json").read_text())
                    for k in (1, 2))
        for a, b in zip(one["reports"], two["reports"]):
            assert b["punch_force_kN"] == pytest.approx(a["punch_force_kN"], rel=1e-6)
            for k in ("DX", "DY", "DD"):
                assert b["draw_in_mm"][k] == pytest.approx(a["draw_in_mm"][k], rel=1e-6)
    one = json.loads((cup_benchmark.case_folder(tmp_path, 6, 1) / "summary.json").read_text())
    alone = json.loads((cup_benchmark.case_folder(tmp_path, 6, 1, one_core=True) / "summary.json").read_text())
    for a, b in zip(one["reports"], alone["reports"], strict=True):
        assert b["punch_force_kN"] == pytest.approx(a["punch_force_kN"], rel=1e-9)
        assert b["draw_in_mm"]["DX"] == pytest.approx(a["draw_in_mm"]["DX"], rel=1e-9)
    loose = json.loads((cup_benchmark.case_folder(tmp_path, 6, 1, 1e-4) / "summary.json").read_text())
    for a, b in zip(one["reports"], loose["reports"]):
        assert b["punch_force_kN"] == pytest.approx(a["punch_force_kN"], rel=1e-4)
        assert b["draw_in_mm"]["DX"] == pytest.approx(a["draw_in_mm"]["DX"], rel=1e-4)


@pytest.mark.parametrize("h", [(1.0, 0.5, 0.25), (1.0, 0.6, 0.35), (0.2, 0.15, 0.07)])
def test_richardson_recovers_the_order_and_the_limit(h):
    """q(h) = q* + C h^p on three meshes of any ratios: the observed order p and q* come back
    (to 1e-9); differences that change sign give no order and their spread as the uncertainty."""
    from shellform.studies.cup_convergence import richardson

    for p, C in ((1.0, 3.0), (1.7, -0.4), (2.0, 5.0)):
        q = [2.5 + C * x**p for x in h]
        r = richardson(h, q)
        assert r["p"] == pytest.approx(p, rel=1e-9) and r["estimate"] == pytest.approx(2.5, rel=1e-9)
        assert r["uncertainty"] == pytest.approx(1.25 * abs(2.5 - q[-1]), rel=1e-6)
    r = richardson(h, [1.0, 1.2, 1.1])
    assert math.isnan(r["p"]) and math.isnan(r["estimate"]) and r["uncertainty"] == pytest.approx(0.2)


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_cup_convergence_quick(tmp_path):
    """cup-convergence's plumbing on three coarse meshes to 2 mm: a row per run with its answers,
    the holder's largest share and holding-down peak from force_stroke.csv, and an estimate per
    answer with the successive differences of the three meshes."""
    from shellform.studies import cup_convergence

    rows = cup_convergence.run(tmp_path, levels=cup_convergence.QUICK_LEVELS)
    assert [(r["case"], r["n"]) for r in rows] == [(c, n) for c in cup_convergence.CASES
                                                  for n in cup_convergence.QUICK_LEVELS]
    for r in rows:
        assert r["finished"] and r["stroke_mm"] == pytest.approx(2.0)
        assert 0 < r["largest_share"] < 1 and r["DX_2"] > 0 and r["force_2"] > 0
    est = list(csv.DictReader(open(tmp_path / "cup_convergence_estimates.csv")))
    dx = next(e for e in est if e["case"] == "aluminium" and e["answer"] == "DX_2")
    assert len(dx["values"].split()) == 3 and len(dx["differences"].split()) == 2
    assert (tmp_path / "cup_convergence.png").stat().st_size > 0
    md = (tmp_path / "cup_convergence.md").read_text()
    assert md.count("| n (cells) |") == 2 and md.count("| DX_2 |") == 2 and "| 8 (128) |" in md
