"""The paper's square cup on three meshes: what the demo's resolution costs and misses.

    shellform study cup-mesh --out docs/results/cup_mesh

demos/square_cup.toml (BHF 19.6 kN, mu 0.1, r 1.5, die radius 5 mm, 30 mm) on n x n quarter
meshes (n = 12, 16, 24; the demo uses 16), and with half the demo's largest increment on the
demo's mesh. Writes cup_mesh.csv: the stroke each run reached (and why it stopped), its wall
time, increments, Newton iterations and peak punch force, and at 15 mm (which every run
reaches) and at 30 mm the punch force, the draw-in DX and DD and the peak thinning, each with
its difference from the finest run (n = 24); cup_mesh.md (its table in docs/contact.md);
cup_mesh_picks.csv (the cheapest run within 1, 5 and 10 % of it) and cup_mesh_error_time.png.
"""

from pathlib import Path

from shellform.results.log import say
from shellform.studies import cup_accuracy
from shellform.studies.cup_hard import draw, variant

LEVELS = (12, 16, 24)
REPORTS = ("15", "30")  # the scene's reports: 15 mm and the end, 30 mm
MEASURES = ("force", "DX", "DD", "thinning")  # DY = DX on the square cup


def runs(levels=LEVELS) -> list:
    """(name, scene) of the study's runs."""
    demo = variant(16)
    return [(f"n {n}", variant(n)) for n in levels] + [
        ("n 16, half step", variant(16, process__max_step_mm=demo.process.max_step_mm / 2,
                                    process__initial_step_mm=demo.process.initial_step_mm / 2))]


def run(out: Path, levels=LEVELS) -> list[dict]:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    runs_ = runs(levels)
    for name, s in runs_:
        say(f"cup-mesh: {name}")
        draw(name, s, out)
    return table(out, runs_, f"n {max(levels)}")


def table(out: Path, runs, finest: str) -> list[dict]:
    """cup_mesh.csv, cup_mesh_picks.csv and cup_mesh_error_time.png from the runs on disk."""
    rows, _ = cup_accuracy.write(out, "cup_mesh", runs, finest, REPORTS,
                                 "Square cup (paper's case) at 15 and 30 mm: accuracy against the time of the whole run",
                                 MEASURES)
    as_written = [{k: float(f"{v:.6g}") if isinstance(v, float) else v for k, v in r.items()} for r in rows]
    (Path(out) / "cup_mesh.md").write_text(markdown(as_written))  # the CSV's digits, as docs/contact.md includes it
    return rows


def markdown(rows: list[dict]) -> str:
    """The table docs/contact.md includes (cup_mesh.md): a row per run, the demo's mesh in bold."""
    def at(r, mm):
        return (f"{r[f'force_{mm}']:.1f} kN, {r[f'DX_{mm}']:.2f}, {r[f'DD_{mm}']:.2f} mm, "
                f"{r[f'thinning_{mm}']:.3f}")

    out = ("| run | stroke | increments, iterations, cut-backs | wall | at 15 mm: punch force, DX, DD, peak thinning "
           "| at 30 mm: force, DX, DD, peak thinning |\n" + "|---" * 6 + "|\n")
    for r in rows:
        name = "**n 16 (demo)**" if r["case"] == "n 16" else r["case"]
        out += (f"| {name} | {float(r['stroke_mm']):g} mm | {r['increments']}, {r['newton_iterations']}, {r['cutbacks']} | "
                f"{r['wall_s']:.0f} s | {at(r, 15)} | {at(r, 30)} |\n")
    return out
