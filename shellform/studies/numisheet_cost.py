"""What accuracy costs: the NUMISHEET'93 aluminium cup against its converged answers.

    shellform study numisheet-cost --out docs/results/numisheet_cost

demos/numisheet93_aluminium.toml (every input stated there), drawn 40 mm by runs that differ in
one choice each:
- the mesh: n x n quarter meshes, n = 8, 12, 16, 24 and 35 (`--levels` for others, 50 say), and
  the graded mesh of demos/numisheet93_aluminium_graded.toml;
- on n = 16 and 24 (VARIED): twice the scene's increments (and half on n = 16), 3, 7 and 9
  thickness points (the scene's 5; 9 on n = 16 only), Newton's rtol 1e-5 (and 1e-4 on n = 16;
  the scene's 1e-6).

The reference is the converged answer, not the finest run: per answer the Richardson estimate
q* with its uncertainty u over the three finest meshes of the cup-convergence study
(cup_convergence_estimates.csv in the folder cup_convergence beside --out: the clone keeps it
in docs/results/cup_convergence, docs/cup-convergence.md); where
that study found no order (differences that change sign), the finest mesh's value with the
spread of the three as u. A run's error in an answer is e = (q - q*) / |q*|; it is *within* a
tolerance tol where |e| + u / |q*| <= tol, so that no run is credited with more accuracy than
the reference can vouch for, and a tolerance below u / |q*| is *not decidable*.

The cost is CPU seconds (summary.json cpu_time_s): every run has one thread, so its CPU time is
its wall time alone on one core, whatever else runs on the machine beside it; a short draw
first compiles the kernels, so that no run's cost holds a compile.

Writes numisheet_cost.csv (per run: counts, CPU and wall seconds, every answer and its error),
numisheet_cost_picks.csv (per answer and for all at once, and per tolerance 1, 2 and 5 %: the
cheapest run within it, or why none is), numisheet_cost_reference.csv, numisheet_cost.md (the
three as the tables docs/cost.md shows) and numisheet_cost_error_time.png (each answer's |e|
against CPU seconds, and the worst |e| of each run with the cheapest-for-its-accuracy runs, the
Pareto front, joined).
"""

import csv
import json
import math
import os
import shutil
from pathlib import Path

from shellform import demos, scene
from shellform.errors import InputError
from shellform.results.log import say
from shellform.results.tables import write_csv
from shellform.studies.cup_hard import draw, folder, variant

SCENE = "numisheet93_aluminium.toml"
GRADED = "numisheet93_aluminium_graded.toml"
LEVELS = (8, 12, 16, 24, 35)
VARIED = (16, 24)  # the meshes on which the step, the thickness points and rtol are varied
ESTIMATES = Path("cup_convergence") / "cup_convergence_estimates.csv"  # the cup-convergence study's, beside --out
MEASURES = ("DX", "DY", "DD", "force")
TOLERANCES = (0.01, 0.02, 0.05)


def answers(at=("15", "40")) -> tuple[str, ...]:
    """The answers: the draw-ins and the punch force at each report (mm), and the peak thinning."""
    return tuple(f"{q}_{mm}" for mm in at for q in MEASURES) + ("min_thickness_strain",)


def reference(path: Path, case: str = "aluminium") -> dict:
    """{answer: (q*, u, source)} from the cup-convergence study's estimates (the file `path`):
    the Richardson estimate where it has one, else the finest mesh's value with the spread as u."""
    out = {}
    if not Path(path).is_file():
        raise InputError("--out", f"no {path}: the reference is the cup-convergence study's estimates; run "
                                  f"`shellform study cup-convergence --out {Path(path).parent}` first")
    with open(path) as f:
        for r in csv.DictReader(f):
            if r["case"] != case:
                continue
            estimate, u = float(r["estimate"]), float(r["uncertainty"])
            if math.isfinite(estimate):
                out[r["answer"]] = (estimate, u, f"Richardson (p {float(r['p']):.2g})")
            else:
                out[r["answer"]] = (float(r["values"].split()[-1]), u, "finest mesh, no order")
    return out


def runs(levels=LEVELS, varied=VARIED, graded: bool = True, stroke=None) -> list:
    """(name, scene) of the study's runs; stroke: draw only this far (mm; tests)."""
    short = {"tools__stroke": stroke} if stroke is not None else {}
    out = [(f"n {n}", variant(n, SCENE, **short)) for n in levels]
    if graded:
        s = scene.load(demos.path(GRADED)).changed({"output.vtx": False, "process.springback": False,
                                                          **{k.replace("__", "."): v for k, v in short.items()}})
        out.append(("graded", s))
    for n in varied:
        s = variant(n, SCENE, **short)
        p = s.process
        steps = (2.0, 0.5) if n == varied[0] else (2.0,)
        for k in steps:
            out.append((f"n {n}, {'2x' if k == 2 else 'half'} step",
                        s.changed({"process.max_step_mm": p.max_step_mm * k,
                                   "process.initial_step_mm": p.initial_step_mm * k})))
        for points in ((3, 7, 9) if n == varied[0] else (3, 7)):
            out.append((f"n {n}, {points} points", s.changed({"process.thickness_points": points})))
        for rtol in ((1e-5, 1e-4) if n == varied[0] else (1e-5,)):
            out.append((f"n {n}, rtol {rtol:g}", s.changed({"process.rtol": rtol})))
    return out


def run(out: Path, levels=LEVELS, varied=VARIED, graded: bool = True, stroke=None, fresh: bool = True,
        threads: int = 1, estimates=None) -> list[dict]:
    """Draw every run (draw_all) and write the table against the converged answers: those of
    `estimates`, by default the cup-convergence study's beside out (out/../ESTIMATES), read
    before the first run."""
    ref = reference(Path(out).resolve().parent / ESTIMATES if estimates is None else estimates)
    runs_ = runs(levels, varied, graded, stroke)
    draw_all(out, runs_, fresh, threads)
    return table(out, runs_, ref)


def draw_all(out: Path, runs_, fresh: bool = True, threads: int = 1) -> None:
    """Draw the runs one after the other on `threads` threads each (fresh=False keeps those
    already on disk), after a short draw that compiles the kernels (a first run's compile time is
    not the cost of its accuracy; it is not kept)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    saved = os.environ.get("SHELLFORM_THREADS")
    os.environ["SHELLFORM_THREADS"] = str(threads)
    try:
        warm = out / "warm-up"
        draw("warm-up", variant(4, SCENE, tools__stroke=0.25), out)
        shutil.rmtree(warm)
        for name, s in runs_:
            if fresh or not (folder(out, name) / "summary.json").exists():
                say(f"numisheet-cost: {name}")
                draw(name, s, out)
    finally:
        if saved is None:
            os.environ.pop("SHELLFORM_THREADS")
        else:
            os.environ["SHELLFORM_THREADS"] = saved


def row(out: Path, name: str, s, ref: dict) -> dict:
    """A run's row from its summary.json: counts, seconds, answers and their errors e."""
    summary = json.loads((folder(out, name) / "summary.json").read_text())
    r = {"case": name, "cells": summary["cells"], "stroke_mm": summary["stroke_mm"],
         "finished": summary["stopped"] is None, "increments": summary["increments"],
         "newton_iterations": summary["newton_iterations"], "cutbacks": summary["cutbacks"],
         "cpu_s": summary["cpu_time_s"], "wall_s": summary["wall_time_s"]["total"], "stopped": summary["stopped"] or ""}
    for at in summary["reports"]:
        mm = f"{at['stroke_mm']:g}"
        r.update({f"{q}_{mm}": v for q, v in {**at["draw_in_mm"], "force": at["punch_force_kN"]}.items() if q in MEASURES})
    r["min_thickness_strain"] = summary["min_thickness_strain"]
    worst = 0.0
    for q, (value, u, _) in ref.items():
        if q not in r:
            worst = math.nan
            continue
        r[f"error_{q}"] = (r[q] - value) / abs(value)
        worst = max(worst, abs(r[f"error_{q}"]))
    r["worst_error"] = worst if r["finished"] else math.nan
    return r


def table(out: Path, runs_, ref: dict) -> list[dict]:
    """The table, its picks and plot from the runs on disk (no computation)."""
    rows = [row(out, name, s, ref) for name, s in runs_]
    qs = list(ref)
    write_csv(Path(out) / "numisheet_cost.csv", rows,
              ["case", "cells", "stroke_mm", "finished", "increments", "newton_iterations", "cutbacks", "cpu_s",
               "wall_s", *qs, *(f"error_{q}" for q in qs), "worst_error", "stopped"])
    write_csv(Path(out) / "numisheet_cost_reference.csv",
              [{"answer": q, "value": v, "uncertainty": u, "relative_uncertainty": u / abs(v), "source": how}
               for q, (v, u, how) in ref.items()], ["answer", "value", "uncertainty", "relative_uncertainty", "source"])
    chosen = picks(rows, ref)
    write_csv(Path(out) / "numisheet_cost_picks.csv", chosen, ["answer", "tolerance", "case", "cpu_s", "error", "verdict"])
    (Path(out) / "numisheet_cost.md").write_text(markdown(rows, ref, chosen))
    plot(Path(out) / "numisheet_cost_error_time.png", rows, ref)
    return rows


def markdown(rows: list[dict], ref: dict, chosen: list[dict]) -> str:
    """The reference, the runs (errors in per cent of the reference) and the picks, as tables."""
    qs = list(ref)
    pct = lambda v: f"{100 * v:+.2f}"  # noqa: E731
    text = ["| answer | reference q* | uncertainty u | u / q* | source |", "|---|---|---|---|---|"]
    text += [f"| {q} | {v:.5g} | {u:.3g} | {100 * u / abs(v):.2f} % | {how} |" for q, (v, u, how) in ref.items()]
    text += ["", "| run | cells | increments, iterations, cut-backs | CPU s | " + " | ".join(qs) + " | worst |",
             "|---|---|---|---|" + "---|" * (len(qs) + 1)]
    for r in rows:
        errors = " | ".join(pct(r[f"error_{q}"]) if f"error_{q}" in r else "" for q in qs)
        worst = f"{100 * r['worst_error']:.2f}" if r["finished"] else f"stopped at {r['stroke_mm']:.1f} mm"
        text.append(f"| {r['case']} | {r['cells']:,} | {r['increments']}, {r['newton_iterations']}, {r['cutbacks']} "
                    f"| {r['cpu_s']:.0f} | {errors} | {worst} |")
    text += ["", "(errors in % of the reference; worst: the largest |error| of the run)", "",
             "| answer | within 1 % | within 2 % | within 5 % |", "|---|---|---|---|"]
    for q in (*qs, "all"):
        cells = []
        for p in (c for c in chosen if c["answer"] == q):
            cells.append(f"{p['case']} ({p['cpu_s']:.0f} s)" if p["verdict"] == "within" else p["verdict"])
        text.append(f"| {q} | " + " | ".join(cells) + " |")
    return "\n".join(text) + "\n"


def picks(rows: list[dict], ref: dict, tolerances=TOLERANCES) -> list[dict]:
    """Per answer (and "all") and tolerance: the cheapest finished run (CPU seconds) within it
    (module docstring), "not decidable" where the reference's own uncertainty exceeds it, or
    "none of the runs"."""
    done = [r for r in rows if r["finished"]]
    out = []
    for q in (*ref, "all"):
        qs = list(ref) if q == "all" else [q]
        u = max(ref[a][1] / abs(ref[a][0]) for a in qs)
        for tol in tolerances:
            pick = {"answer": q, "tolerance": tol, "case": "", "cpu_s": "", "error": "", "verdict": ""}
            if u > tol:
                pick["verdict"] = f"not decidable: the reference's uncertainty is {100 * u:.2g} %"
            else:
                within = [r for r in done if all(abs(r.get(f"error_{a}", math.inf)) + ref[a][1] / abs(ref[a][0]) <= tol
                                                 for a in qs)]
                best = min(within, key=lambda r: r["cpu_s"], default=None)
                if best is None:
                    pick["verdict"] = "none of the runs"
                else:
                    e = max((best[f"error_{a}"] for a in qs), key=abs)
                    pick.update({"case": best["case"], "cpu_s": best["cpu_s"], "error": e, "verdict": "within"})
            out.append(pick)
    return out


def pareto(rows: list[dict]) -> list[dict]:
    """The finished runs that no cheaper run beats in worst error, cheapest first."""
    front, best = [], math.inf
    for r in sorted((r for r in rows if r["finished"] and math.isfinite(r["worst_error"])), key=lambda r: r["cpu_s"]):
        if r["worst_error"] < best:
            front.append(r)
            best = r["worst_error"]
    return front


def plot(path: Path, rows: list[dict], ref: dict) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 5))
    done = [r for r in rows if r["finished"]]
    for i, q in enumerate(ref):
        have = [r for r in done if f"error_{q}" in r]
        left.loglog([r["cpu_s"] for r in have], [max(abs(r[f"error_{q}"]), 1e-5) for r in have],
                    "osv^Dp*h<"[i % 9], label=q, fillstyle="full" if i < 4 else "none")
    left.set_title("each answer's |error| against the converged answer", fontsize=10)
    front = pareto(rows)
    right.loglog([r["cpu_s"] for r in done], [r["worst_error"] for r in done], "o", color="grey")
    right.loglog([r["cpu_s"] for r in front], [r["worst_error"] for r in front], "-o", color="C3",
                 label="the cheapest run for its accuracy")
    for r in front:
        right.annotate(r["case"], (r["cpu_s"], r["worst_error"]), fontsize=7, xytext=(4, 4), textcoords="offset points")
    right.set_title("the worst |error| of a run (grey: a cheaper run is as accurate)", fontsize=10)
    right.legend(fontsize=8)
    for ax in (left, right):
        for tol in TOLERANCES:
            ax.axhline(tol, color="grey", lw=0.6, ls=":")
        ax.set_xlabel("CPU seconds of the whole run (one thread)")
        ax.set_ylabel("|(q - q*) / q*|")
        ax.grid(True, which="both", alpha=0.3)
    left.legend(fontsize=7, ncol=2)
    fig.suptitle("NUMISHEET'93 aluminium cup, 40 mm: accuracy against cost", fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
