"""What a cup run's answers cost: its quantities at each report against its wall time, each with
its relative difference from the finest run of the study, and the cheapest run within a
tolerance, for each quantity and for all at once.

Shared by the cup studies that vary the mesh and the increment (cup-mesh, numisheet-cost). A run
is a (name, scene) whose summary.json and force_stroke.csv lie in the study's folder
(cup_hard.folder); the table is rebuilt from those files without computing anything.
"""

import json
from pathlib import Path

from shellform.results.tables import write_csv
from shellform.studies.cup_hard import folder, row

MEASURES = ("force", "DX", "DY", "DD", "thinning")


def quantities(reports: tuple[str, ...], measures=MEASURES) -> tuple[str, ...]:
    """Column names: each measure at each report (mm), then the peak punch force of the stroke."""
    return tuple(f"{q}_{mm}" for mm in reports for q in measures) + ("peak_force",)


def table(out: Path, runs, finest: str, reports: tuple[str, ...], measures=MEASURES) -> list[dict]:
    """One row per run: stroke, counts, wall time, the quantities and their relative differences
    from the run named `finest`. A report the run did not reach is left empty."""
    qs = quantities(reports, measures)
    rows = []
    for name, s in runs:
        r = {**row(name, s, out), "max_step_mm": s.process.max_step_mm}
        r["peak_force"] = r["peak_punch_force_kN"]
        summary = json.loads((folder(out, name) / "summary.json").read_text())
        for at in summary["reports"]:
            mm = next((m for m in reports if abs(at["stroke_mm"] - float(m)) < 1e-6), None)
            if mm is not None:
                values = {"force": at["punch_force_kN"], **at["draw_in_mm"], "thinning": at["min_thickness_strain"]}
                r.update({f"{q}_{mm}": values[q] for q in measures})
        rows.append(r)
    ref = next(r for r in rows if r["case"] == finest)
    for r in rows:
        for q in qs:
            if q in r and q in ref:
                r[f"rel_diff_{q}"] = (r[q] - ref[q]) / abs(ref[q])
        diffs = [abs(r[f"rel_diff_{q}"]) for q in qs if f"rel_diff_{q}" in r]
        r["worst_rel_diff"] = max(diffs) if len(diffs) == len(qs) else float("nan")
    return rows


def columns(reports: tuple[str, ...], measures=MEASURES) -> list[str]:
    qs = quantities(reports, measures)
    return ["case", "n", "max_step_mm", "stroke_mm", "finished", "increments", "newton_iterations", "cutbacks",
            "wall_s", *qs, *(f"rel_diff_{q}" for q in qs), "worst_rel_diff", "stopped"]


def picks(rows: list[dict], finest: str, qs: tuple[str, ...], tolerances=(0.01, 0.05, 0.10)) -> list[dict]:
    """For each quantity (and for all of them at once) and each tolerance, the cheapest finished
    run other than the finest whose difference from the finest lies within it; "none" when no
    coarser run does."""
    out = []
    for q in (*qs, "all"):
        key = "worst_rel_diff" if q == "all" else f"rel_diff_{q}"
        for tol in tolerances:
            within = [r for r in rows if r["case"] != finest and r["finished"] and key in r and abs(r[key]) <= tol]
            best = min(within, key=lambda r: r["wall_s"], default=None)
            out.append({"quantity": q, "tolerance": tol, "case": best["case"] if best else f"none coarser than {finest}",
                        "wall_s": best["wall_s"] if best else "", "rel_diff": best[key] if best else ""})
    return out


def plot(path: Path, rows: list[dict], qs: tuple[str, ...], title: str, finest: str) -> None:
    """|relative difference from the finest run| of every quantity against the run's wall time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in rows if r["case"] != finest]
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    for i, q in enumerate(qs):
        have = [r for r in rows if f"rel_diff_{q}" in r]
        ax.loglog([r["wall_s"] for r in have], [max(abs(r[f"rel_diff_{q}"]), 1e-5) for r in have],
                  "osv^Dp*h"[i % 8], label=q, fillstyle="full" if i < len(qs) // 2 else "none")
    for r in rows:
        ax.annotate(r["case"], (r["wall_s"], max(r.get("worst_rel_diff", 1e-5), 1e-5)), fontsize=7)
    for tol in (0.01, 0.05, 0.10):
        ax.axhline(tol, color="grey", lw=0.6, ls=":")
    ax.set_xlabel("wall time of the whole run (s), 2-core machine")
    ax.set_ylabel(f"|relative difference| from {finest}")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def write(out: Path, stem: str, runs, finest: str, reports: tuple[str, ...], title: str, measures=MEASURES):
    """STEM.csv, STEM_picks.csv and STEM_error_time.png in out; returns (rows, picks)."""
    rows = table(out, runs, finest, reports, measures)
    write_csv(Path(out) / f"{stem}.csv", rows, columns(reports, measures))
    chosen = picks(rows, finest, quantities(reports, measures))
    write_csv(Path(out) / f"{stem}_picks.csv", chosen, ["quantity", "tolerance", "case", "wall_s", "rel_diff"])
    plot(Path(out) / f"{stem}_error_time.png", rows, quantities(reports, measures), title, finest)
    return rows, chosen
