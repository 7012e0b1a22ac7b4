"""The paper's square cup on three meshes: what the demo's resolution costs and misses.

    shellform study cup-mesh --out docs/results/cup_mesh

demos/square_cup.toml (BHF 19.6 kN, mu 0.1, r 1.5, die radius 5 mm, 30 mm) on n x n quarter
meshes (n = 12, 16, 24; the demo uses 16), and with half the demo's largest increment on the
demo's mesh. Writes cup_mesh.csv: the punch force at 15 and 30 mm and its peak, the draw-in
DX, DY, DD and the peak thinning at 30 mm, each with its difference from the finest run (n = 24),
against wall time, increments and Newton iterations; and cup_mesh_error_time.png.
"""

from pathlib import Path

from shellform.studies.common import say, write_csv
from shellform.studies.cup_hard import draw, variant

LEVELS = (12, 16, 24)
QUANTITIES = ("force_15_kN", "force_30_kN", "peak_punch_force_kN", "DX", "DY", "DD", "max_thickness_strain")
COLUMNS = ["case", "n", "max_step", "stroke_mm", "finished", "increments", "newton_iterations", "cutbacks", "wall_s",
           *QUANTITIES, *(f"rel_diff_{q}" for q in QUANTITIES)]


def run(out: Path, levels=LEVELS) -> list[dict]:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    runs = [(f"n {n}", variant(n)) for n in levels]
    demo = variant(16)
    runs.append(("n 16, half step", variant(16, process__max_step=demo.process.max_step / 2,
                                            process__initial_step=demo.process.initial_step / 2)))
    rows = []
    for name, s in runs:
        say(f"cup-mesh: {name}")
        row = draw(name, s, out)
        row["max_step"] = s.process.max_step
        row["force_15_kN"], row["force_30_kN"] = row["report_punch_force_kN"][0], row["report_punch_force_kN"][-1]
        rows.append(row)
    finest = next(r for r in rows if r["case"] == f"n {max(levels)}")
    for r in rows:
        for q in QUANTITIES:
            r[f"rel_diff_{q}"] = (r[q] - finest[q]) / abs(finest[q]) if finest[q] else float("nan")
    write_csv(out / "cup_mesh.csv", rows, COLUMNS)
    _plot(out / "cup_mesh_error_time.png", [r for r in rows if r is not finest])
    return rows


def _plot(path: Path, rows: list[dict]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for q, marker in (("force_15_kN", "o"), ("peak_punch_force_kN", "s"), ("DD", "^"), ("max_thickness_strain", "v")):
        ax.loglog([r["wall_s"] for r in rows], [max(abs(r[f"rel_diff_{q}"]), 1e-5) for r in rows], marker,
                  label=q)
        for r in rows:
            ax.annotate(r["case"], (r["wall_s"], max(abs(r[f"rel_diff_{q}"]), 1e-5)), fontsize=7)
    ax.set_xlabel("wall time (s), 2-core machine")
    ax.set_ylabel("|relative difference| from n = 24")
    ax.set_title("Square cup (paper's case), 30 mm: accuracy against time", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
