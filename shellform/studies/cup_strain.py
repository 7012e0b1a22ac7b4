"""The paper's square cup before and after finite-strain plasticity (issue 10).

    shellform study cup-strain --out docs/results/cup_strain

demos/square_cup.toml as it is (effect finite_strain: logarithmic strains, a thinning lever
arm) and without finite_strain (issue 3's small-strain layers on the Green-Lagrange strain).
Writes cup_strain.csv: at 15 and 30 mm the punch force, draw-in DX and DD, peak thinning and
thickening and the sheet's volume change, with counts and wall time; cup_strain.png: punch force
against stroke and the thickness strain along the diagonal at 30 mm, both runs.
"""

import csv
import json
from pathlib import Path

from shellform.results.log import say
from shellform.results.tables import write_csv
from shellform.studies.cup_hard import draw, folder, variant

COLUMNS = ["case", "stroke_mm", "punch_force_kN", "DX", "DY", "DD", "min_thickness_strain",
           "max_thickening_strain", "volume_change", "increments", "newton_iterations", "wall_s", "stopped"]


def runs(n: int = 16) -> list:
    demo = variant(n)
    small = demo.changed({"effects": [e for e in demo.effects if e != "finite_strain"]})
    return [("finite strain", demo), ("small strain", small)]


def run(out: Path, n: int = 16) -> list[dict]:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    for name, s in runs(n):
        say(f"cup-strain: {name}")
        draw(name, s, out)
    return table(out, n)


def table(out: Path, n: int = 16) -> list[dict]:
    rows = []
    for name, _ in runs(n):
        summary = json.loads((folder(out, name) / "summary.json").read_text())
        for r in summary["reports"]:
            rows.append({"case": name, "stroke_mm": r["stroke_mm"], "punch_force_kN": r["punch_force_kN"],
                         **r["draw_in_mm"], "min_thickness_strain": r["min_thickness_strain"],
                         "max_thickening_strain": r["max_thickening_strain"], "volume_change": r["volume_change"],
                         "increments": summary["increments"], "newton_iterations": summary["newton_iterations"],
                         "wall_s": summary["wall_time_s"]["total"], "stopped": summary["stopped"] or ""})
    write_csv(out / "cup_strain.csv", rows, COLUMNS)
    as_written = [{k: float(f"{v:.6g}") if isinstance(v, float) else v for k, v in r.items()} for r in rows]
    (out / "cup_strain.md").write_text(markdown(as_written))  # the CSV's digits, as docs/material.md includes it
    _plot(out, [name for name, _ in runs(n)])
    return rows


def markdown(rows: list[dict]) -> str:
    """The table docs/material.md includes (cup_strain.md): a column per case (the first the
    demo's finite strains, the second the small strains before), a row per answer at the two
    reports."""
    cases = list(dict.fromkeys(r["case"] for r in rows))
    at = {(r["case"], float(r["stroke_mm"])): r for r in rows}
    first, last = sorted({float(r["stroke_mm"]) for r in rows})

    def thinning(r):  # the committed runs' CSV carries the key's name before its rename
        return r["min_thickness_strain"] if "min_thickness_strain" in r else r["max_thickness_strain"]

    def line(label, cell):
        return f"| {label} | " + " | ".join(cell(c) for c in cases) + " |\n"

    names = {"finite strain": "finite strain (now the demo)", "small strain": "small strain (before)"}
    return ("| | " + " | ".join(names.get(c, c) for c in cases) + " |\n" + "|---" * (len(cases) + 1) + "|\n"
            + line(f"punch force at {first:g} / {last:g} mm",
                   lambda c: f"{at[c, first]['punch_force_kN']:.1f} / {at[c, last]['punch_force_kN']:.1f} kN")
            + "".join(line(f"draw-in DX, DD at {s:g} mm", lambda c, s=s: f"{at[c, s]['DX']:.2f}, {at[c, s]['DD']:.2f} mm")
                      for s in (first, last))
            + line(f"peak thinning at {last:g} mm (at the punch corner, initially (28.1, 28.1) mm)",
                   lambda c: f"{thinning(at[c, last]):.3f}")
            + line(f"peak thickening at {last:g} mm (the flange edge at the middle of a side)",
                   lambda c: f"{at[c, last]['max_thickening_strain']:+.3f}")
            + line(f"the sheet's volume change (V - V0)/V0 at {first:g} / {last:g} mm",
                   lambda c: f"{100 * at[c, first]['volume_change']:+.2g} % / {100 * at[c, last]['volume_change']:+.2g} %")
            + line("increments, Newton iterations, wall (one after the other, nothing else on the machine)",
                   lambda c: f"{at[c, last]['increments']}, {at[c, last]['newton_iterations']}, {at[c, last]['wall_s']:.0f} s"))


def _plot(out: Path, names) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    for name in names:
        with open(folder(out, name) / "force_stroke.csv") as f:
            curve = list(csv.DictReader(f))
        a.plot([float(r["stroke_mm"]) for r in curve], [float(r["punch_force_kN"]) for r in curve], label=name)
        with open(folder(out, name) / "thickness_diagonal.csv") as f:
            line = list(csv.DictReader(f))
        b.plot([float(r["initial_position_mm"]) for r in line], [float(r["thickness_strain"]) for r in line],
               "o-", ms=3, label=name)
    a.set_xlabel("punch stroke (mm)")
    a.set_ylabel("punch force, whole cup (kN)")
    b.set_xlabel("initial distance from the centre along the diagonal (mm)")
    b.set_ylabel("thickness strain at 30 mm")
    for ax in (a, b):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Square cup (BHF 19.6 kN, mu 0.1, r 1.5, die radius 5 mm), 16 x 16 quarter mesh", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "cup_strain.png", dpi=120)
    plt.close(fig)
