"""The aluminium cup's sensitivities from one run against central differences of whole runs.

The NUMISHEET'93 aluminium cup (demos/numisheet93_aluminium.toml: its force-controlled holder,
19.6 kN, friction 0.162, Hill 1948 with three r values, Swift hardening) is drawn to 40 mm with
reports at 15 and 40 mm, once with `[output] sensitivities` for the holder's force, the friction
coefficient, the Swift K and n and r0, and for each parameter twice more at p (1 +- h) for two
steps h = 1e-3 and 1e-4 (process.rtol 1e-10 in every run, so that Newton's tolerance does not
enter the differences). At each report, for DX, DD, the punch force and the peak thinning
(min_thickness_strain), a row gives the derivative from one run, the two central differences,
their difference as the differences' own error estimate, and whether the derivative lies within
2 % of the finer difference or within that estimate (issue 49's check). Where a difference jumps,
the two runs' contact sets part somewhere along the path: each row says, for each step, at how
many increments the plus and minus runs' counts of nodes on the punch, the die and under the
holder differ (the set-held derivative does not see such a change; equal counts do not prove
equal sets).

The run with the sensitivities and one without are timed alone, one thread each (the cost), after
a short run with the sensitivities that compiles the kernels (numba's cache), so that neither
timed run pays for compiling; the differences' runs then go two at a time (subprocesses).

    shellform study sensitivity-cup --out docs/results/sensitivity_cup     (about 45 minutes)

writes sensitivity_cup.csv, sensitivity_cup.md and cost.csv (docs/sensitivity.md).
"""

import csv
import json
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from shellform import demos
from shellform.results import run_folder
from shellform.results.log import say
from shellform.results.tables import markdown_table, write_csv

SCENE = "numisheet93_aluminium.toml"
LEVELS = (16, 24)
QUICK_LEVELS = (6,)
STROKE = 40.0
WARM_UP_MM = 1.0
REPORTS = (15.0, 40.0)
PARAMETERS = ("tools.blank_holder_force", "tools.friction", "material.K", "material.n", "material.r0")
STEPS = (1e-3, 1e-4)
ANSWERS = ("DX", "DD", "punch_force_kN", "min_thickness_strain")
WITHIN = 0.02
RTOL = 1e-10
COUNTS = ("nodes_on_punch", "nodes_on_die", "nodes_on_pinched")
COLUMNS = ["n", "stroke_mm", "answer", "parameter", "value", "one_run", "fd_coarse", "fd_fine", "fd_error",
           "rel_error", "within", "set_differs_coarse", "set_differs_fine"]
TIME_COLUMNS = ["n", "parameters", "with_s", "without_s", "extra"]


def settings(n: int, stroke: float = STROKE, changes: dict | None = None, sensitivities: bool = False) -> list[str]:
    """The `shellform run --set` arguments of one run."""
    out = {"mesh.n": n, "tools.stroke": stroke, "process.report": [r / stroke for r in REPORTS if r < stroke] + [1.0],
           "process.rtol": RTOL, "process.springback": False, "output.png": False, "output.vtx": False,
           "output.vtu": False, "output.fld": False, **(changes or {})}
    if sensitivities:
        out["output.sensitivities"] = list(PARAMETERS)
    return [f"--set={k}={json.dumps(v)}" for k, v in out.items()]


def _value(name: str) -> float:
    from shellform import scene

    s = scene.load(demos.path(SCENE))
    section, _, key = name.partition(".")
    return float(getattr(getattr(s, section), key))


def _run(folder: Path, args: list[str]) -> float:
    """One `shellform run` of the scene into folder (one thread); its wall time (summary.json's).
    A finished run of the same settings by the same code there is kept."""
    stamp = folder / "settings.json"
    key = {"settings": args, "code": run_folder.code_version()}
    if not ((folder / "summary.json").exists() and stamp.exists() and json.loads(stamp.read_text()) == key):
        cmd = [sys.executable, "-c", "from shellform.cli import main; main()", "run", str(demos.path(SCENE)),
               "-o", str(folder), "-q", "--threads", "1", *args]
        subprocess.run(cmd, check=True)
        stamp.write_text(json.dumps(key))
    return float(json.loads((folder / "summary.json").read_text())["wall_time_s"]["total"])


def _reports(folder: Path) -> list[dict]:
    return json.loads((folder / "summary.json").read_text())["reports"]


def _answer(report: dict, answer: str) -> float:
    return float(report["draw_in_mm"][answer]) if answer in ("DX", "DY", "DD") else float(report[answer])


def _counts(folder: Path) -> list[tuple]:
    with open(folder / "force_stroke.csv") as f:
        return [(float(r["stroke_mm"]), tuple(int(r[c]) for c in COUNTS)) for r in csv.DictReader(f)]


def set_differs(plus: Path, minus: Path, stroke: float) -> int:
    """The increments up to `stroke` at which the two runs' counts of nodes on the punch, the die
    and under the holder differ (or their strokes do)."""
    a = [c for c in _counts(plus) if c[0] <= stroke + 1e-9]
    b = [c for c in _counts(minus) if c[0] <= stroke + 1e-9]
    return sum(x != y for x, y in zip(a, b)) + abs(len(a) - len(b))


def level(out: Path, n: int, stroke: float = STROKE) -> tuple[list[dict], dict]:
    """The rows of one mesh level and its cost row."""
    base = Path(out) / f"n_{n}"
    say(f"sensitivity-cup: n {n}, a short run that compiles the kernels, then the run with the sensitivities and "
        "the one without, alone")
    _run(base / "warm_up", settings(n, WARM_UP_MM, sensitivities=True))  # numba's cache, so that no timed run compiles
    with_s = _run(base / "one_run", settings(n, stroke, sensitivities=True))
    without = _run(base / "plain", settings(n, stroke))
    jobs, values = {}, {name: _value(name) for name in PARAMETERS}
    for name, value in values.items():
        for h in STEPS:
            for sign in (1, -1):
                jobs[(name, h, sign)] = (base / f"{name}_{h:g}_{'+' if sign > 0 else '-'}",
                                         settings(n, stroke, {name: value * (1 + sign * h)}))
    say(f"sensitivity-cup: n {n}, {len(jobs)} runs of the differences, two at a time")
    with ThreadPoolExecutor(2) as pool:
        list(pool.map(lambda job: _run(*job), jobs.values()))
    one = _reports(base / "one_run")
    rows = []
    for i, report in enumerate(one):
        at = float(report["stroke_mm"])
        for name, value in values.items():
            fd = {}
            for h in STEPS:
                plus, minus = (_reports(jobs[(name, h, s)][0])[i] for s in (1, -1))
                fd[h] = {a: (_answer(plus, a) - _answer(minus, a)) / (2 * h * value) for a in ANSWERS}
            differs = [set_differs(jobs[(name, h, 1)][0], jobs[(name, h, -1)][0], at) for h in STEPS]
            for a in ANSWERS:
                d, coarse, fine = float(report["sensitivities"][name][a]), fd[STEPS[0]][a], fd[STEPS[1]][a]
                error = abs(coarse - fine)
                rel = abs(d - fine) / abs(fine) if fine else float("inf")
                rows.append({"n": n, "stroke_mm": at, "answer": a, "parameter": name, "value": value,
                             "one_run": d, "fd_coarse": coarse, "fd_fine": fine, "fd_error": error,
                             "rel_error": rel, "within": bool(rel <= WITHIN or abs(d - fine) <= error),
                             "set_differs_coarse": differs[0], "set_differs_fine": differs[1]})
    cost = {"n": n, "parameters": len(PARAMETERS), "with_s": with_s, "without_s": without,
            "extra": with_s / without - 1}
    return rows, cost


def markdown(rows: list[dict]) -> str:
    head = ["n", "stroke (mm)", "answer", "parameter", "one run", "differences, h 1e-3 / 1e-4", "their spread",
            "error", "within", "contact counts part at, h 1e-3 / 1e-4 (increments)"]
    body = [[str(r["n"]), f"{r['stroke_mm']:g}", r["answer"], r["parameter"], f"{r['one_run']:.6g}",
             f"{r['fd_coarse']:.6g} / {r['fd_fine']:.6g}", f"{r['fd_error']:.2g}", f"{100 * r['rel_error']:.2f} %",
             "yes" if r["within"] else "**no**", f"{r['set_differs_coarse']} / {r['set_differs_fine']}"]
            for r in rows]
    return markdown_table(head, body)


def run(out: Path, levels=LEVELS) -> list[dict]:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stroke = 4.0 if tuple(levels) == QUICK_LEVELS else STROKE
    rows, costs = [], []
    for n in levels:
        r, c = level(out, n, stroke)
        rows += r
        costs.append(c)
    write_csv(out / "sensitivity_cup.csv", rows, COLUMNS)
    write_csv(out / "cost.csv", costs, TIME_COLUMNS)
    (out / "sensitivity_cup.md").write_text(markdown(rows))
    misses = [r for r in rows if not r["within"]]
    say(f"sensitivity-cup: {len(rows) - len(misses)} of {len(rows)} derivatives within 2 % or the differences' "
        f"spread; cost {', '.join(f'n {c['n']}: +{100 * c['extra']:.0f} %' for c in costs)}")
    return rows
