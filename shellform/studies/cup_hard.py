"""Hard cases of the square cup (issue 9): each draws to the end or stops cleanly with its cause.

    shellform study cup-hard --out docs/results/cup_hard

The paper's cup (demos/square_cup.toml) with one thing made hard at a time:
- mu 0.3: three times the friction;
- t 0.5 mm: a thinner sheet (clearance and holder unchanged);
- die radius 2 mm: a sharp die shoulder, under half a cell of the 16 x 16 mesh;
- BHF 4 t with die radius 20 mm: the paper's Fig. 8 case (39.2 kN);
- 10x increment: every increment ten times the scene's largest (2.4 mm of stroke), which the
  driver must cut back on its own.
Writes hard_cases.csv: stroke reached, the stop message (empty when it finished), increments,
Newton iterations, cut-backs, wall time, the peak punch force and thinning of the last
converged state; and hard_cases.md, its table in docs/contact.md.
"""

from pathlib import Path

from shellform import demos, scene
from shellform.contact.run import run as run_cup
from shellform.results.log import say
from shellform.results.tables import write_csv

COLUMNS = ["case", "n", "stroke_mm", "target_mm", "finished", "increments", "newton_iterations", "cutbacks",
           "wall_s", "peak_punch_force_kN", "min_thickness_strain", "stopped"]


def variant(n: int, name: str = "square_cup.toml", **changes) -> scene.Scene:
    """A demo scene on an n x n quarter mesh with changes section__key=value or effects=[...]
    (no VTX output, no springback: the studies compare the drawn state), checked as a scene
    file is (Scene.changed)."""
    return scene.load(demos.path(name)).changed({
        "mesh.n": n, "output.vtx": False, "process.springback": False,
        **{key.replace("__", "."): value for key, value in changes.items()}})


def draw(name: str, s: scene.Scene, out: Path) -> dict:
    """Run one cup scene into out/NAME; its row: stroke, stop, counts, time, force, thinning,
    draw-in at the end and the punch force at every report."""
    run_cup(s, folder(out, name))
    return row(name, s, out)


def folder(out: Path, name: str) -> Path:
    return Path(out) / name.replace(" ", "_").replace(",", "")


def row(name: str, s: scene.Scene, out: Path) -> dict:
    """A finished or stopped run's row from its summary.json and force_stroke.csv."""
    import csv
    import json

    d = folder(out, name)
    summary = json.loads((d / "summary.json").read_text())
    with open(d / "force_stroke.csv") as f:
        curve = [float(r["punch_force_kN"]) for r in csv.DictReader(f)]
    return {"case": name, "n": s.mesh.n, "stroke_mm": summary["stroke_mm"], "target_mm": s.tools.stroke,
            "finished": summary["stopped"] is None, "increments": summary["increments"],
            "newton_iterations": summary["newton_iterations"], "cutbacks": summary["cutbacks"],
            "wall_s": summary["wall_time_s"]["total"], "peak_punch_force_kN": max(curve, default=0.0),
            **summary["draw_in_mm"][-1], "min_thickness_strain": summary["min_thickness_strain"],
            "stopped": summary["stopped"] or ""}


def cases(n: int = 16) -> dict:
    """The hard variants of the paper's cup scene on an n x n quarter mesh."""
    big = 10 * scene.load(demos.path("square_cup.toml")).process.max_step_mm
    variant_n = lambda **changes: variant(n, **changes)  # noqa: E731
    return {
        "mu 0.3": variant_n(tools__friction=0.3),
        "t 0.5 mm": variant_n(material__thickness=0.5),
        "die radius 2 mm": variant_n(tools__die_profile_radius=2.0),
        "BHF 4t, die radius 20 mm": variant_n(tools__blank_holder_force=39200.0, tools__die_profile_radius=20.0),
        "10x increment": variant_n(process__initial_step_mm=big, process__max_step_mm=big),
    }


def run(out: Path, n: int = 16, only=None) -> list[dict]:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for name, s in cases(n).items():
        if only and name not in only:
            continue
        say(f"cup-hard: {name}")
        rows.append(draw(name, s, out))
        _write(out, rows)
    return rows


def _write(out: Path, rows: list[dict]) -> None:
    """hard_cases.csv and its table hard_cases.md (the CSV's digits, as docs/contact.md includes it)."""
    write_csv(Path(out) / "hard_cases.csv", rows, COLUMNS)
    as_written = [{k: float(f"{v:.6g}") if isinstance(v, float) else v for k, v in r.items()} for r in rows]
    (Path(out) / "hard_cases.md").write_text(markdown(as_written))


def markdown(rows: list[dict]) -> str:
    """The table docs/contact.md includes (hard_cases.md): a row per case."""
    return ("| case | stroke | increments, iterations, cut-backs | wall | peak punch force | peak thinning |\n"
            + "|---" * 6 + "|\n"
            + "".join(f"| {r['case']} | {float(r['stroke_mm']):g} mm | {r['increments']}, {r['newton_iterations']}, "
                      f"{r['cutbacks']} | {r['wall_s']:.0f} s | {r['peak_punch_force_kN']:.1f} kN | "
                      f"{r['min_thickness_strain']:.3f} |\n" for r in rows))


def tabulate(out: Path, n: int = 16) -> list[dict]:
    """hard_cases.csv again from the runs on disk (no computation)."""
    rows = [row(name, s, out) for name, s in cases(n).items() if (folder(out, name) / "summary.json").exists()]
    _write(out, rows)
    return rows
