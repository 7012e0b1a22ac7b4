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
converged state.
"""

import time
from pathlib import Path

from shellform import scene
from shellform.contact.run import run as run_cup
from shellform.studies.common import say, write_csv

ROOT = Path(__file__).resolve().parents[2]
COLUMNS = ["case", "n", "stroke_mm", "target_mm", "finished", "increments", "newton_iterations", "cutbacks",
           "wall_s", "peak_punch_force_kN", "max_thickness_strain", "stopped"]


def variant(n: int, name: str = "square_cup.toml", **changes) -> scene.Scene:
    """A demo scene on an n x n quarter mesh with changes section__key=value (no VTX output)."""
    s = scene.load(ROOT / "demos" / name)
    s.mesh.n = n
    for key, value in changes.items():
        section, field = key.split("__")
        setattr(getattr(s, section), field, value)
    s.output.vtx = False
    return s


def draw(name: str, s: scene.Scene, out: Path) -> dict:
    """Run one cup scene into out/NAME; its row: stroke, stop, counts, time, force, thinning,
    draw-in at the end and the punch force at every report."""
    t0 = time.perf_counter()
    summary = run_cup(s, out / name.replace(" ", "_").replace(",", ""))
    forces = [f["force"] for f in summary["punch_force_kN"]]
    return {"case": name, "n": s.mesh.n, "stroke_mm": summary["stroke_mm"], "target_mm": s.tools.stroke,
            "finished": summary["stopped"] is None, "increments": summary["increments"],
            "newton_iterations": summary["newton_iterations"], "cutbacks": summary["cutbacks"],
            "wall_s": time.perf_counter() - t0, "peak_punch_force_kN": max(forces),
            "report_punch_force_kN": forces, **summary["draw_in_mm"][-1],
            "max_thickness_strain": summary["max_thickness_strain"], "stopped": summary["stopped"] or ""}


def cases(n: int = 16) -> dict:
    """The hard variants of the paper's cup scene on an n x n quarter mesh."""
    big = 10 * scene.load(ROOT / "demos" / "square_cup.toml").process.max_step
    variant_n = lambda **changes: variant(n, **changes)  # noqa: E731
    return {
        "mu 0.3": variant_n(tools__friction=0.3),
        "t 0.5 mm": variant_n(material__thickness=0.5),
        "die radius 2 mm": variant_n(tools__die_profile_radius=2.0),
        "BHF 4t, die radius 20 mm": variant_n(tools__blank_holder_force=39200.0, tools__die_profile_radius=20.0),
        "10x increment": variant_n(process__initial_step=big, process__max_step=big),
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
        write_csv(out / "hard_cases.csv", rows, COLUMNS)
    return rows
