"""Forming answers against the mesh (issue 32): do they settle as the mesh is refined?

    shellform study cup-convergence --out docs/results/cup_convergence

The NUMISHEET'93 aluminium cup (demos/numisheet93_aluminium.toml) to 40 mm on n x n quarter
meshes, n = 16, 24, 35, 50, 71, and the paper's square cup (demos/square_cup.toml) to 30 mm on
n = 16, 24, 35, 50. For each run: DX, DY, DD and the punch force at 15 mm and at the end, the
peak thinning and where it is, the stroke at which the holder opens (if it does), the largest
nodal share of the holder's force, the peak of what it holds down, the edge load's share of F
(holder.py, pinch_edge.py) at the start and its peak, the holding-down off the edge's band at the
first report and its peak, and the largest change of the punch force
between consecutive increments in the last 40 % of the stroke. For each answer, over the three finest finished meshes, the observed order of
convergence p and the Richardson estimate of the converged value with its uncertainty
(`richardson`). Writes cup_convergence.csv (one row per run), cup_convergence_estimates.csv
(one row per case and answer) and cup_convergence.png (each answer against the cell size).
A case's run that stops early is kept in the table with its stop; its answers at the end are
left out of the estimates.
"""

import csv
import json
from pathlib import Path

import numpy as np

from shellform.contact.run import run as run_cup
from shellform.results.log import say
from shellform.results.tables import write_csv
from shellform.studies.cup_hard import folder, variant

CASES = {  # name: (scene file, levels, reports in mm)
    "aluminium": ("numisheet93_aluminium.toml", (16, 24, 35, 50, 71), (15.0, 40.0)),
    "square": ("square_cup.toml", (16, 24, 35, 50), (15.0, 30.0)),
}
QUICK_LEVELS = (6, 8, 10)  # with QUICK_STROKE: the plumbing, in a minute
QUICK_STROKE = 2.0
ANSWERS = ("DX", "DY", "DD", "force")


def richardson(h, q) -> dict:
    """The observed order p and the Richardson estimate from three meshes of sizes h0 > h1 > h2
    with answers q0, q1, q2, for q(h) = q* + C h^p. With the ratios r1 = h0/h1, r2 = h1/h2 (any),
    p solves  (q0 - q1) / (q1 - q2) = (r1^p - 1) r2^p / (r2^p - 1)  (bisection on p in [0.05, 8]),
    and q* = q2 + (q2 - q1) / (r2^p - 1). Its uncertainty: |q* - q2| times 1.25 (Roache's safety
    factor for three meshes). Where the differences change sign (no monotone convergence) or no
    p in the range fits, p and q* are nan and the uncertainty is the spread of the three."""
    h0, h1, h2 = map(float, h)
    q0, q1, q2 = map(float, q)
    r1, r2 = h0 / h1, h1 / h2
    d1, d2 = q0 - q1, q1 - q2
    spread = {"p": np.nan, "estimate": np.nan, "uncertainty": float(np.ptp([q0, q1, q2]))}
    if d2 == 0.0:
        return {"p": np.inf, "estimate": q2, "uncertainty": 0.0} if d1 == 0.0 else spread
    ratio = d1 / d2
    if ratio <= 0:
        return spread

    def f(p):
        return (r1**p - 1) * r2**p / (r2**p - 1) - ratio

    lo, hi = 0.05, 8.0
    if f(lo) * f(hi) > 0:
        return spread
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(lo) * f(mid) > 0 else (lo, mid)
    p = 0.5 * (lo + hi)
    estimate = q2 + (q2 - q1) / (r2**p - 1)
    return {"p": p, "estimate": estimate, "uncertainty": 1.25 * abs(estimate - q2)}


def scene_of(case: str, n: int, stroke: float | None = None):
    name, _, reports = CASES[case]
    end = stroke or reports[-1]
    marks = [r / end for r in reports[:-1] if r < end]
    return variant(n, name, tools__stroke=end, process__report=marks, output__png=False, output__fld=False)


def run_name(case: str, n: int) -> str:
    return f"{case} n {n}"


def late_jump(curve: list[dict], late: float = 0.6) -> float:
    """The largest relative change of the punch force between consecutive increments beyond
    `late` of the stroke."""
    stroke = [float(r["stroke_mm"]) for r in curve]
    force = [float(r["punch_force_kN"]) for r in curve]
    jumps = [abs(force[i] - force[i - 1]) / abs(force[i]) for i in range(1, len(curve))
             if stroke[i] > late * stroke[-1] and force[i] != 0.0]
    return max(jumps, default=0.0)


def row(case: str, n: int, out: Path) -> dict:
    """A run's row from its summary.json and force_stroke.csv."""
    d = folder(out, run_name(case, n))
    s = json.loads((d / "summary.json").read_text())
    with open(d / "force_stroke.csv") as f:
        curve = list(csv.DictReader(f))
    opened = next((float(r["stroke_mm"]) for r in curve if float(r["holder_lift_mm"]) > 0
                   or int(r["nodes_on_holder"]) > 0), None)
    r = {"case": case, "n": n, "cells": s["cells"], "stroke_mm": s["stroke_mm"],
         "finished": s["stopped"] is None, "increments": s["increments"], "newton_iterations": s["newton_iterations"],
         "cutbacks": s["cutbacks"], "wall_s": s["wall_time_s"]["total"], "holder_opens_mm": opened,
         "largest_share": max(float(x["holder_largest_share"]) for x in curve),
         "held_down_peak": max(float(x["holder_held_down"]) for x in curve),
         "edge_load_start": float(curve[0]["holder_edge_load"]),
         "edge_load_peak": max(float(x["holder_edge_load"]) for x in curve),
         "off_band_first": float(min(curve, key=lambda x: abs(float(x["stroke_mm"]) - s["reports"][0]["stroke_mm"]))
                                 ["holder_off_band"]),
         "off_band_peak": max(float(x["holder_off_band"]) for x in curve),
         "late_force_jump": late_jump(curve),
         "min_thickness_strain": s["min_thickness_strain"], "where_x_mm": s["where_initial_xy_mm"][0],
         "where_y_mm": s["where_initial_xy_mm"][1], "stopped": s["stopped"] or ""}
    for rep in s["reports"]:
        at = f"{rep['stroke_mm']:g}"
        r.update({f"{k}_{at}": rep["draw_in_mm"][k] for k in ("DX", "DY", "DD")})
        r[f"force_{at}"] = rep["punch_force_kN"]
    for k in ANSWERS:  # at the last report, whatever its stroke (the plot's)
        r[f"{k}_end"] = r[f"{k}_{s['reports'][-1]['stroke_mm']:g}"]
    return r


def estimates(rows: list[dict], reports) -> list[dict]:
    """Per answer, the successive differences and the Richardson estimate over the three finest
    finished meshes (cell size h ~ cells^-1/2)."""
    done = [r for r in rows if r["finished"]]
    out = []
    keys = [f"{a}_{rep:g}" for rep in reports for a in ANSWERS] + ["min_thickness_strain"]
    for key in keys:
        have = [r for r in done if r.get(key) is not None]
        e = {"case": rows[0]["case"], "answer": key, "values": " ".join(f"{r[key]:.6g}" for r in have),
             "differences": " ".join(f"{b[key] - a[key]:+.3g}" for a, b in zip(have, have[1:])),
             "p": np.nan, "estimate": np.nan, "uncertainty": np.nan}
        if len(have) >= 3:
            last = have[-3:]
            e.update(richardson([r["cells"] ** -0.5 for r in last], [r[key] for r in last]))
        out.append(e)
    return out


def _num(x, digits=3) -> str:
    return "" if x is None or (isinstance(x, float) and np.isnan(x)) else f"{float(x):.{digits}f}"


def markdown(rows: list[dict], ests: list[dict]) -> str:
    """The runs' table and the estimates' table of each case, as docs/cup-convergence.md shows
    them: draw-ins and force at the first and last report, peak thinning, the holder (opening,
    largest share, edge load, holding-down off the band), the late force jump, iterations, cut-backs, wall time."""
    text = []
    for case in dict.fromkeys(r["case"] for r in rows):
        part = [r for r in rows if r["case"] == case]
        first, last = (f"{x:g}" for x in (CASES[case][2][0], part[0]["stroke_mm"]))
        text += [f"### {case}", "",
                 f"| n (cells) | DX {first} | DD {first} | force {first} (kN) | DX {last} | DD {last} | force {last} (kN) "
                 "| min thickness strain | holder opens at | largest share of F | edge load / F (start, peak) "
                 f"| off the band / F ({first}, peak) | late force jump | iterations, cut-backs | wall (s) |",
                 "|" + "---|" * 15]
        for r in part:
            opens = f"{r['holder_opens_mm']:.1f} mm" if r["holder_opens_mm"] is not None else "never"
            stopped = "" if r["finished"] else f" (stopped at {r['stroke_mm']:.1f} mm)"
            text.append(f"| {r['n']} ({r['cells']:,}){stopped} | {_num(r.get('DX_' + first))} | {_num(r.get('DD_' + first))} "
                        f"| {_num(r.get('force_' + first), 2)} | {_num(r.get('DX_' + last), 2)} | {_num(r.get('DD_' + last), 2)} "
                        f"| {_num(r.get('force_' + last), 2)} | {_num(r['min_thickness_strain'])} | {opens} "
                        f"| {_num(r['largest_share'])} | {_num(r['edge_load_start'])}, {_num(r['edge_load_peak'])} "
                        f"| {_num(r['off_band_first'], 4)}, {_num(r['off_band_peak'], 4)} "
                        f"| {100 * r['late_force_jump']:.1f} % | {r['newton_iterations']}, {r['cutbacks']} | {r['wall_s']:.0f} |")
        text += ["", "| answer | values | successive differences | p | estimate +- uncertainty |", "|---|---|---|---|---|"]
        for e in ests:
            if e["case"] == case:
                text.append(f"| {e['answer']} | {e['values']} | {e['differences']} | {_num(e['p'], 2) or 'none'} "
                            f"| {_num(e['estimate'], 4) or 'none'} +- {_num(e['uncertainty'])} |")
        text.append("")
    return "\n".join(text)


def plot(path: Path, rows: list[dict]) -> None:
    """DX, DD and the punch force at each case's end, and the edge load's share of F at the
    start, against the cell size."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = ["DX_end", "DD_end", "force_end", "edge_load_start"]
    fig, axes = plt.subplots(1, len(keys), figsize=(4 * len(keys), 3.2))
    for ax, key in zip(axes, keys):
        for case in sorted({r["case"] for r in rows}):
            part = [r for r in rows if r["case"] == case and r.get(key) is not None]
            ax.plot([r["cells"] ** -0.5 for r in part], [r[key] for r in part], "o-", label=case)
        ax.set_xlabel("cells^-1/2 (cell size)")
        ax.set_title(key, fontsize=9)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run(out: Path, levels=None, cases=tuple(CASES), stroke=None) -> list[dict]:
    """Draw every case on its levels (or `levels`) into out, then the tables and the plot."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    quick = levels == QUICK_LEVELS
    stroke = stroke or (QUICK_STROKE if quick else None)
    for case in cases:
        for n in levels or CASES[case][1]:
            say(f"cup-convergence: {run_name(case, n)}")
            run_cup(scene_of(case, n, stroke), folder(out, run_name(case, n)))
    return tables(out, {case: levels or CASES[case][1] for case in cases}, stroke)


def tables(out: Path, levels: dict, stroke=None) -> list[dict]:
    """The tables (cup_convergence.csv, cup_convergence_estimates.csv, and both as markdown in
    cup_convergence.md) and the plot of the runs in out: levels, per case its mesh levels."""
    out = Path(out)
    rows, ests = [], []
    for case, ns in levels.items():
        reports = tuple(r for r in CASES[case][2] if stroke is None or r < stroke) + ((stroke,) if stroke else ())
        part = [row(case, n, out) for n in ns]
        rows += part
        ests += estimates(part, reports)
    write_csv(out / "cup_convergence.csv", rows, list(dict.fromkeys(k for r in rows for k in r)))
    write_csv(out / "cup_convergence_estimates.csv", ests,
              ["case", "answer", "values", "differences", "p", "estimate", "uncertainty"])
    plot(out / "cup_convergence.png", rows)
    (out / "cup_convergence.md").write_text(markdown(rows, ests))
    return rows
