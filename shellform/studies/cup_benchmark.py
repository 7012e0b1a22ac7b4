"""Benchmark: how fast the NUMISHEET'93 aluminium cup draws, and what it computes (issue 12).

    shellform study cup-benchmark --out docs/results/cup_benchmark

demos/numisheet93_aluminium.toml (every input stated there) at the scene's increments on
n x n quarter meshes, n = 21, 35 and 71: 882, 2,450 and 10,082 cells, about 900, 2,500 and
10,000 elements. The runs go one after the other, so that each wall time is the run's own; the
2,450 and 10,082-cell cups are drawn once more on 2 MPI ranks (mpiexec -n 2; each rank takes
half the cores for its threads), and the 10,082-cell cup once more on one core (one rank, one
thread: NUMBA_NUM_THREADS=1), the baseline against which the ranks' speed-up says how the MPI
engine scales (one rank alone already runs its element and material loops on every core). The
882 and 2,450-cell cups are drawn to 40 mm; the 10,082-cell cup to 5 mm only (STROKES), a run of hours to 40 mm on a 2-core machine: its row gives the cost of
an iteration at that size, not the time of the whole draw. The 2,450-cell cup is drawn again
with Newton's tolerance at 1e-4 and at 1e-3 (LOOSE) instead of the scene's 1e-6, on 1 and on 2
ranks (on 882 cells 1e-4 moves every reported quantity by under 1e-4 and 1e-3 by under 5e-4,
the mesh 1e-3 to 1e-2; docs/performance.md).

Writes cup_benchmark.csv, one row per run:
- ranks, threads per rank, Newton's rtol, cells, stroke, wall time, increments, Newton iterations, contact passes;
- one iteration's time in ms, split into the element loop, the constitutive update, the
  parts (frames, friction, set updates), DOLFINx assembly, the MUMPS solve and the rest
  (Python and other work between them), and the rest's share of the run;
- the punch force, draw-in DX and DD and the peak thinning at 15 and 40 mm (where reached),
  so that speed is always shown next to accuracy;
and cup_benchmark.png: the iteration's split against cells, and the wall time against cells.

Run one case alone (what the 2-rank line does under mpiexec):

    python -m shellform.studies.cup_benchmark --n 35 --out DIR [--stroke MM] [--rtol 1e-4] [--trace]
"""

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

from shellform.results.log import say
from shellform.results.tables import write_csv
from shellform.studies.common import mpiexec
from shellform.studies.cup_hard import variant

SCENE = "numisheet93_aluminium.toml"
LEVELS = (21, 35, 71)
QUICK_LEVELS = (6,)
STROKES = {71: 5.0}  # mm; the others to the scene's 40 mm
MPI_LEVELS = (35, 71)  # the levels drawn once more on 2 ranks (issue 12's 2-rank target: the 10,000-cell cup)
ONE_CORE = (71,)  # the levels drawn once more on one core (1 rank, 1 thread): the baseline of the ranks' speed-up
LOOSE = (35, (1e-4, 1e-3))  # the level drawn again with these Newton tolerances
PARTS = ("element", "constitutive", "parts", "assembly", "solve")
REPORTS = (15.0, 40.0)
COLUMNS = ["case", "ranks", "threads", "rtol", "n", "cells", "stroke_mm", "finished", "wall_s", "increments", "newton_iterations",
           "contact_passes", "iteration_ms", *(f"{p}_ms" for p in PARTS), "rest_ms", "rest_share",
           *(f"{q}_{mm:g}" for mm in REPORTS for q in ("force", "DX", "DD", "thinning")), "stopped"]


def scene_for(n: int, stroke: float | None = None, rtol: float | None = None):
    """The aluminium cup on an n x n quarter mesh, drawn `stroke` mm (None: the scene's 40) with
    the scene's increments in mm, and Newton's tolerance rtol (None: the scene's)."""
    s = variant(n, SCENE)
    changes = {"output.png": False, "output.fld": False}
    if rtol is not None:
        changes["process.rtol"] = rtol
    if stroke is not None and stroke != s.tools.stroke:
        scale = s.tools.stroke / stroke
        changes.update({"process.report": [f * scale for f in s.process.report if f * scale <= 1.0],
                        "tools.stroke": stroke})
    return s.changed(changes)


def draw_one(n: int, out: Path, stroke: float | None = None, rtol: float | None = None, trace: bool = False) -> None:
    """Draw one case into out (on however many ranks this process has); trace: log every contact
    pass, iterate and switching node."""
    from shellform.contact.run import run as run_cup

    run_cup(scene_for(n, stroke, rtol), Path(out), trace=trace)


def case_folder(out: Path, n: int, ranks: int, rtol: float | None = None, one_core: bool = False) -> Path:
    return Path(out) / (f"n_{n}" + (f"_ranks_{ranks}" if ranks > 1 else "") + (f"_rtol_{rtol:g}" if rtol else "")
                        + ("_one_core" if one_core else ""))


def row(out: Path, n: int, ranks: int, rtol: float | None = None, one_core: bool = False) -> dict:
    """A run's row from its summary.json."""
    s = json.loads((case_folder(out, n, ranks, rtol, one_core) / "summary.json").read_text())
    t, its = s["wall_time_s"], max(s["newton_iterations"], 1)
    parts = {p: t.get(f"{p}_s", 0.0) for p in PARTS}
    rest = t["total"] - t["setup"] - sum(parts.values())
    r = {"case": f"n {n}" + (f", {ranks} ranks" if ranks > 1 else "") + (f", rtol {rtol:g}" if rtol else "")
         + (", one core" if one_core else ""),
         "ranks": s["ranks"], "threads": s.get("threads", ""), "rtol": rtol or variant(n, SCENE).process.rtol, "n": n,
         "cells": s["cells"], "stroke_mm": s["stroke_mm"], "finished": s["stopped"] is None, "wall_s": t["total"],
         "increments": s["increments"], "newton_iterations": s["newton_iterations"],
         "contact_passes": s["contact_passes"], "iteration_ms": 1e3 * (t["total"] - t["setup"]) / its,
         **{f"{p}_ms": 1e3 * v / its for p, v in parts.items()}, "rest_ms": 1e3 * rest / its,
         "rest_share": rest / t["total"], "stopped": s["stopped"] or ""}
    for at in s["reports"]:
        mm = next((m for m in REPORTS if abs(at["stroke_mm"] - m) < 1e-6), None)
        if mm is not None:
            r.update({f"force_{mm:g}": at["punch_force_kN"], f"DX_{mm:g}": at["draw_in_mm"]["DX"],
                      f"DD_{mm:g}": at["draw_in_mm"]["DD"], f"thinning_{mm:g}": at["min_thickness_strain"]})
    return r


def warm_up() -> None:
    """Compile every kernel and loop, or load them from the caches, by drawing the coarsest cup
    1 mm, so that no row pays it (after an edit of the numba code, 30 to 40 s of the first row)."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        draw_one(QUICK_LEVELS[0], Path(tmp), 1.0)


def run(out: Path, levels=LEVELS, strokes=None, mpi_levels=MPI_LEVELS,
        loose: tuple[int, tuple[float, ...]] | None = LOOSE, one_core=ONE_CORE) -> list[dict]:
    """Draw every case one after the other, then the 2-rank cases, the level of `loose` (level,
    tolerances) at each of its tolerances on 1 and 2 ranks, and the `one_core` levels on one
    core, and write the table and plot."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    strokes = STROKES if strokes is None else strokes
    cases = [(n, 1, None, False) for n in levels]
    if mpiexec() is not None:
        cases += [(n, 2, None, False) for n in mpi_levels]
    if loose is not None:
        for rtol in loose[1]:
            cases.append((loose[0], 1, rtol, False))
            if mpiexec() is not None:
                cases.append((loose[0], 2, rtol, False))
    cases += [(n, 1, None, True) for n in one_core]
    warm_up()
    for n, ranks, rtol, alone in cases:
        say(f"cup-benchmark: n {n} on {ranks} rank(s)" + (f", rtol {rtol:g}" if rtol else "")
            + (", one core" if alone else ""))
        folder = case_folder(out, n, ranks, rtol, alone)
        if ranks == 1 and not alone:
            draw_one(n, folder, strokes.get(n), rtol)
            continue
        cmd = [sys.executable, "-m", "shellform.studies.cup_benchmark", "--n", str(n), "--out", str(folder)]
        if strokes.get(n) is not None:
            cmd += ["--stroke", str(strokes[n])]
        if rtol is not None:
            cmd += ["--rtol", str(rtol)]
        env = dict(os.environ, OMP_NUM_THREADS="1")
        if alone:
            env["NUMBA_NUM_THREADS"] = "1"  # one rank on one core: no threads over the cells
        subprocess.run([mpiexec(), "-n", str(ranks), *cmd] if ranks > 1 else cmd, check=True, env=env)
    rows = [row(out, n, ranks, rtol, alone) for n, ranks, rtol, alone in cases]
    write_csv(out / "cup_benchmark.csv", rows, COLUMNS)
    plot(out / "cup_benchmark.png", rows)
    for r in rows:
        say(f"{r['case']:>16s}: {r['cells']:6d} cells, {r['stroke_mm']:.0f} mm in {r['wall_s']:.0f} s, "
            f"{r['newton_iterations']} iterations of {r['iteration_ms']:.0f} ms (rest {r['rest_ms']:.0f} ms)")
    return rows


def _power(x: float) -> str:
    """1e-4 rather than 0.0001."""
    return f"{x:.0e}".replace("e-0", "e-")


def plot(path: Path, rows: list[dict]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(13, 4.8))
    tight = min(r["rtol"] for r in rows)
    labels = [f"{r['cells']:,}\n{r['ranks']} rank" + ("s" if r["ranks"] > 1 else "")
              + ("\n1 core" if r["case"].endswith("one core") else "")
              + (f"\nrtol {_power(r['rtol'])}" if r["rtol"] > tight else "") for r in rows]
    bottom = [0.0] * len(rows)
    for p in (*PARTS, "rest"):
        h = [r[f"{p}_ms"] for r in rows]
        a.bar(labels, h, bottom=bottom, label=p)
        bottom = [x + y for x, y in zip(bottom, h)]
    a.set_ylabel("ms per Newton iteration (stacked)")
    a.set_title("one iteration, split")
    a.tick_params(axis="x", labelsize=7)
    a.legend(fontsize=8)
    full = max(r["stroke_mm"] for r in rows)
    for ranks, stroke, loose, marker, label in ((1, True, False, "o-", "1 rank"), (2, True, False, "s", "2 ranks"),
                                                (1, False, False, "x", "1 rank, shorter stroke"),
                                                (2, False, False, "+", "2 ranks, shorter stroke"),
                                                (1, True, True, "^", "1 rank, looser Newton tolerance"),
                                                (2, True, True, "v", "2 ranks, looser Newton tolerance")):
        sel = [r for r in rows if r["ranks"] == ranks and (r["stroke_mm"] >= full) == stroke
               and (r["rtol"] > tight) == loose and not r["case"].endswith("one core")]
        if sel:
            b.plot([r["cells"] for r in sel], [r["wall_s"] for r in sel], marker, label=label)
        for r in sel:  # 2 ranks labelled on the left, 1 rank on the right
            b.annotate(f"{r['stroke_mm']:.0f} mm" + (f", rtol {_power(r['rtol'])}" if loose else ""),
                       (r["cells"], r["wall_s"]), xytext=(-6 if ranks > 1 else 6, 0), textcoords="offset points",
                       ha="right" if ranks > 1 else "left", va="center", fontsize=8)
    b.axhline(120.0, color="gray", ls="--", lw=0.8, label="issue 12: 2,500 cells in 120 s")
    b.set_xscale("log")
    b.set_yscale("log")
    b.set_xlabel("cells (quarter blank)")
    b.set_ylabel("wall time of the run [s]")
    b.set_title("NUMISHEET'93 aluminium cup")
    b.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> None:
    import shellform  # noqa: F401  (the DOLFINx runtime first)

    parser = argparse.ArgumentParser(description="draw one cup-benchmark case (on the ranks of mpiexec)")
    parser.add_argument("--n", type=int, required=True)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--stroke", type=float, default=None)
    parser.add_argument("--rtol", type=float, default=None, help="Newton's tolerance (default: the scene's)")
    parser.add_argument("--trace", action="store_true", help="log every contact pass, iterate and switching node")
    args = parser.parse_args(argv)
    draw_one(args.n, args.out, args.stroke, args.rtol, args.trace)


if __name__ == "__main__":
    main()
