"""What accuracy costs in time: the NUMISHEET'93 aluminium cup to 40 mm on four meshes and two
increment sizes.

    shellform study numisheet-cost --out docs/results/numisheet_cost

demos/numisheet93_aluminium.toml (every input stated there) on n x n quarter meshes, n = 8, 12,
16 (the scene's) and 24, each with the scene's increments (largest 0.24 mm of stroke) and with
twice them. The runs go one after the other, so that each wall time is the run's own on the
machine. Writes numisheet_cost.csv: for every run the stroke reached, increments, Newton
iterations, cut-backs, wall time, and at 15 and 40 mm the punch force, the draw-in DX, DY, DD
and the peak thinning, with the peak punch force of the stroke; each with its relative
difference from the finest run (n = 24, the scene's increments). numisheet_cost_picks.csv
names the cheapest run within 1, 5 and 10 % of the finest in every quantity, and
numisheet_cost_error_time.png plots the differences against wall time.
"""

from pathlib import Path

from shellform.results.log import say
from shellform.studies import cup_accuracy
from shellform.studies.cup_hard import draw, folder, variant

SCENE = "numisheet93_aluminium.toml"
LEVELS = (8, 12, 16, 24)
STEPS = (1, 2)  # the scene's increments times this


def runs(levels=LEVELS, steps=STEPS, stroke=None) -> list:
    """(name, scene) of the study's runs, finest last; stroke: draw only this far (mm; tests)."""
    out = []
    for k in steps[::-1]:
        for n in levels:
            s = variant(n, SCENE)
            changes = {"process.max_step_mm": s.process.max_step_mm * k,
                       "process.initial_step_mm": s.process.initial_step_mm * k}
            if stroke is not None:
                changes["tools.stroke"] = stroke
            s = s.changed(changes)
            out.append((f"n {n}" + (f", {k}x step" if k != 1 else ""), s))
    return out


def reports(s) -> tuple[str, ...]:
    """The strokes (mm) a scene reports at, as the table's labels: 15 and 40 for the scene's."""
    return tuple(f"{f * s.tools.stroke:g}" for f in sorted(set(s.process.report) | {1.0}))


def run(out: Path, levels=LEVELS, steps=STEPS, stroke=None, fresh: bool = True) -> list[dict]:
    """Draw every run (fresh=False keeps the runs already on disk) and write the table."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    runs_ = runs(levels, steps, stroke)
    for name, s in runs_:
        if fresh or not (folder(out, name) / "summary.json").exists():
            say(f"numisheet-cost: {name}")
            draw(name, s, out)
    return table(out, runs_)


def table(out: Path, runs_=None) -> list[dict]:
    """The table, its picks and plot from the runs on disk (no computation)."""
    runs_ = runs_ or runs()
    at = reports(runs_[-1][1])
    rows, _ = cup_accuracy.write(out, "numisheet_cost", runs_, runs_[-1][0], at,
                                 f"NUMISHEET'93 aluminium cup, {' and '.join(at)} mm: accuracy against the time "
                                 "of the whole run")
    return rows
