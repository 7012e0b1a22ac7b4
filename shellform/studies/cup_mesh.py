"""The paper's square cup on three meshes: what the demo's resolution costs and misses.

    shellform study cup-mesh --out docs/results/cup_mesh

demos/square_cup.toml (BHF 19.6 kN, mu 0.1, r 1.5, die radius 5 mm, 30 mm) on n x n quarter
meshes (n = 12, 16, 24; the demo uses 16), and with half the demo's largest increment on the
demo's mesh. Writes cup_mesh.csv: the stroke each run reached (and why it stopped), its wall
time, increments, Newton iterations and peak punch force, and at 15 mm (which every run
reaches) and at 30 mm the punch force, the draw-in DX and DD and the peak thinning, each with
its difference from the finest run (n = 24); and cup_mesh_error_time.png.
"""

from pathlib import Path

from shellform.results.log import say
from shellform.results.tables import write_csv
from shellform.studies.cup_hard import draw, folder, row, variant

LEVELS = (12, 16, 24)
REPORTS = {0: "15", 1: "30"}  # the scene's reports: 15 mm and the end, 30 mm
QUANTITIES = tuple(f"{q}_{mm}" for mm in REPORTS.values() for q in ("force", "DX", "DD", "thinning"))
COLUMNS = ["case", "n", "max_step", "stroke_mm", "finished", "increments", "newton_iterations", "cutbacks", "wall_s",
           "peak_punch_force_kN", *QUANTITIES, *(f"rel_diff_{q}" for q in QUANTITIES), "stopped"]


def runs(levels=LEVELS) -> list:
    """(name, scene) of the study's runs."""
    demo = variant(16)
    return [(f"n {n}", variant(n)) for n in levels] + [
        ("n 16, half step", variant(16, process__max_step=demo.process.max_step / 2,
                                    process__initial_step=demo.process.initial_step / 2))]


def run(out: Path, levels=LEVELS) -> list[dict]:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    runs_ = runs(levels)
    for name, s in runs_:
        say(f"cup-mesh: {name}")
        draw(name, s, out)
    return table(out, runs_, f"n {max(levels)}")


def table(out: Path, runs, finest: str) -> list[dict]:
    """From the runs on disk: the quantities at 15 mm of every run and their relative difference
    from the finest; cup_mesh.csv and the error-against-time plot."""
    import json

    rows = []
    for name, s in runs:
        r = {**row(name, s, out), "max_step": s.process.max_step}
        summary = json.loads((folder(out, name) / "summary.json").read_text())
        for i, mm in REPORTS.items():
            if i < len(summary["reports"]) and abs(summary["reports"][i]["stroke_mm"] - float(mm)) < 1e-6:
                at = summary["reports"][i]
                r.update({f"force_{mm}": at["punch_force_kN"], f"DX_{mm}": at["draw_in_mm"]["DX"],
                          f"DD_{mm}": at["draw_in_mm"]["DD"], f"thinning_{mm}": at["max_thickness_strain"]})
        rows.append(r)
    ref = next(r for r in rows if r["case"] == finest)
    for r in rows:
        for q in QUANTITIES:
            if q in r and q in ref:
                r[f"rel_diff_{q}"] = (r[q] - ref[q]) / abs(ref[q])
    write_csv(Path(out) / "cup_mesh.csv", rows, COLUMNS)
    _plot(Path(out) / "cup_mesh_error_time.png", [r for r in rows if r is not ref])
    return rows


def _plot(path: Path, rows: list[dict]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for q, marker in zip(QUANTITIES, "osv^osv^"):
        have = [r for r in rows if f"rel_diff_{q}" in r]
        ax.loglog([r["wall_s"] for r in have], [max(abs(r[f"rel_diff_{q}"]), 1e-5) for r in have], marker,
                  label=q, fillstyle="none" if q.endswith("30") else "full")
    for r in rows:
        ax.annotate(r["case"], (r["wall_s"], max(abs(r.get("rel_diff_DX_15", 1e-5)), 1e-5)), fontsize=7)
    ax.set_xlabel("wall time (s), 2-core machine")
    ax.set_ylabel("|relative difference| from n = 24")
    ax.set_title("Square cup (paper's case) at 15 and 30 mm: accuracy against the time of the whole run",
                 fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
