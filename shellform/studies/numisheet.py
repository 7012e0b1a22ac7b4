"""The NUMISHEET'93 square cups, aluminium and mild steel, drawn to 40 mm.

    shellform study numisheet --out docs/results/numisheet93

demos/numisheet93_aluminium.toml and demos/numisheet93_steel.toml as they are (16 x 16
quarter mesh; every input and choice is stated in the scene files). Writes numisheet.csv (and
numisheet.md, its table in docs/contact.md): at 15 and 40 mm the draw-in DX, DY and DD, the punch force, the peak thinning and where it is, the
smallest margin to the forming-limit curve (at 40 mm); with increments, Newton iterations, cut-backs and
wall time. Each run's folder holds its thickness strain along the diagonal and the transverse
centre line (thickness_diagonal.csv, thickness_transverse.csv), force_stroke.csv/.png, cup.png
and the forming-limit view.
"""

import json
from pathlib import Path

from shellform.results.log import say
from shellform.results.tables import write_csv
from shellform.studies.cup_hard import draw, folder, variant

CUPS = {"aluminium": "numisheet93_aluminium.toml", "mild steel": "numisheet93_steel.toml"}
COLUMNS = ["cup", "stroke_mm", "DX", "DY", "DD", "punch_force_kN", "min_thickness_strain",
           "where_initial_xy_mm", "where_current_xyz_mm", "min_margin", "increments", "newton_iterations",
           "cutbacks", "wall_s", "stopped"]


def run(out: Path, n: int = 16) -> list[dict]:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    for name, scene_file in CUPS.items():
        say(f"numisheet: {name}")
        draw(name, variant(n, scene_file), out)
    return table(out)


def table(out: Path) -> list[dict]:
    rows = []
    for name in CUPS:
        s = json.loads((folder(out, name) / "summary.json").read_text())
        for r in s["reports"]:
            rows.append({"cup": name, "stroke_mm": r["stroke_mm"], **r["draw_in_mm"],
                         "punch_force_kN": r["punch_force_kN"], "min_thickness_strain": r["min_thickness_strain"],
                         "where_initial_xy_mm": " ".join(f"{v:.1f}" for v in r["where_initial_xy_mm"]),
                         "where_current_xyz_mm": " ".join(f"{v:.1f}" for v in r["where_current_xyz_mm"]),
                         "min_margin": s.get("min_margin", "") if r is s["reports"][-1] else "",
                         "increments": s["increments"],
                         "newton_iterations": s["newton_iterations"], "cutbacks": s["cutbacks"],
                         "wall_s": s["wall_time_s"]["total"], "stopped": s["stopped"] or ""})
    write_csv(out / "numisheet.csv", rows, COLUMNS)
    as_written = [{k: float(f"{v:.6g}") if isinstance(v, float) else v for k, v in r.items()} for r in rows]
    (out / "numisheet.md").write_text(markdown(as_written))  # the CSV's digits, as docs/contact.md includes it
    return rows


def markdown(rows: list[dict]) -> str:
    """The table docs/contact.md includes (numisheet.md): a row per cup, its answers at each report."""
    cups = list(dict.fromkeys(r["cup"] for r in rows))
    strokes = list(dict.fromkeys(r["stroke_mm"] for r in rows))
    out = ("| cup | " + " | ".join(f"at {float(s):g} mm: DX, DD, punch force, peak thinning" for s in strokes)
           + " | increments, iterations, cut-backs, wall |\n" + "|---" * (len(strokes) + 2) + "|\n")
    for cup in cups:
        at = {r["stroke_mm"]: r for r in rows if r["cup"] == cup}
        last = at[strokes[-1]]
        out += (f"| {cup} | " + " | ".join(
            f"{at[s]['DX']:.2f} (DY {at[s]['DY']:.2f}), {at[s]['DD']:.2f} mm, {at[s]['punch_force_kN']:.1f} kN, "
            f"{at[s]['min_thickness_strain']:.3f}" for s in strokes)
            + f" | {last['increments']}, {last['newton_iterations']}, {last['cutbacks']}, {last['wall_s']:.0f} s |\n")
    return out
