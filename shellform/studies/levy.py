"""Levy's clamped square plate in large deflection (docs/references.md section 2).

Quarter plate, a = 1, nu = 0.316, dead uniform pressure stepped through Levy's loads
P = p a^4 / (E h^4); error of w_c/h against his table at every load, for nested meshes.
Supports: Levy's own, "clamped_sliding" (edges clamped against rotation and normal
displacement, free to slide along the edge, NACA TR 740); the immovable edge ("clamped") is
reported too, for the difference. Scale-free: w_c/h depends on P and nu only (von Karman), so
the same table checks a very thin and a thick plate (tests/test_hard_cases.py).
"""

import time
from pathlib import Path

from mpi4py import MPI

from shellform.material import Hill79Material
from shellform.nonlinear.driver import Controls
from shellform.nonlinear.loads import SheetLoads
from shellform.nonlinear.problem import SheetProblem
from shellform.studies.common import plot_error_time
from shellform.results.log import say
from shellform.results.tables import write_csv

NU = 0.316
TABLE = {17.8: 0.237, 38.3: 0.471, 63.4: 0.695, 95.0: 0.912, 134.9: 1.121, 184.0: 1.323, 245.0: 1.521,
         318.0: 1.714, 402.0: 1.902}
LEVELS = (4, 8, 16, 24)
QUICK_LEVELS = (4, 8)
COLUMNS = ["support", "n", "cells", "dofs", "P", "w_over_h", "levy", "rel_error", "increments",
           "iterations", "compile_s", "element_s", "constitutive_s", "assembly_s", "solve_s", "total_s"]


def problem(n, support="clamped_sliding", h=0.01, controls=None, effects=("bending", "membrane",
            "geometric_nonlinearity"), material=None, thickness_points=5, comm=MPI.COMM_WORLD):
    pmax = max(TABLE) * h**4  # E = 1, a = 1
    mat = material or Hill79Material(E=1.0, nu=NU)
    return SheetProblem.on_rectangle(
        comm, 1.0, 1.0, n, mat, h, effects, region="quarter",
        supports={"left": "symmetry", "bottom": "symmetry", "right": support, "top": support},
        loads=SheetLoads(pressure=pmax), controls=controls or Controls(initial_step=0.02, max_step=0.1),
        thickness_points=thickness_points)


def solve(n, support="clamped_sliding", h=0.01, loads=TABLE, **kw) -> list[dict]:
    """One row per Levy load: w_c/h and its error, with the cumulative times."""
    t0 = time.perf_counter()
    p = problem(n, support, h, **kw)
    compile_s = time.perf_counter() - t0
    rows = []
    pmax = max(TABLE)
    for P in loads:
        p.driver.run(P / pmax)
        w = p.value("w", 0.0, 0.0) / h
        d = p.driver
        rows.append({"support": support, "n": n, "cells": p.model.mesh.topology.index_map(2).size_global,
                     "dofs": p.model.V.dofmap.index_map.size_global * 9, "P": P, "w_over_h": w,
                     "levy": TABLE[P], "rel_error": (w - TABLE[P]) / TABLE[P],
                     "increments": len(d.history), "iterations": sum(i.iterations for i in d.history),
                     "compile_s": compile_s, **d.times, "total_s": time.perf_counter() - t0})
    return rows


SHOWN_LOADS = (17.8, 95.0, 184.0, 318.0, 402.0)


def markdown(rows: list[dict], loads=SHOWN_LOADS, support="clamped_sliding") -> str:
    """The table docs/levy.md includes (levy.md): w_c/h's error against Levy's table at five of
    his loads, a column per mesh of `support` past the coarsest (n = 4 is in the CSV only)."""
    meshes = sorted({r["n"] for r in rows if r["support"] == support})[1:]
    cells = {r["n"]: r["cells"] for r in rows}
    error = {(r["n"], float(r["P"])): r["rel_error"] for r in rows if r["support"] == support}
    out = ("| P | Levy | " + " | ".join(f"n = {n} ({cells[n]}{' cells' if i == 0 else ''})" for i, n in enumerate(meshes))
           + " |\n" + "|---" * (len(meshes) + 2) + "|\n")
    for P in loads:
        out += (f"| {P:.1f} | {TABLE[P]:.3f} | " + " | ".join(f"{100 * error[(n, P)]:.2f} %" for n in meshes) + " |\n")
    return out


def run(outdir: Path, levels=LEVELS) -> list[dict]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    rows, series = [], {}
    say(f"{'support':16s} {'n':>3s} {'cells':>6s} {'P':>6s} {'w/h':>8s} {'Levy':>6s} {'error':>8s} {'time_s':>7s}")
    for support in ("clamped_sliding", "clamped"):
        for n in levels if support == "clamped_sliding" else levels[-1:]:
            part = solve(n, support)
            for r in part:
                say(f"{support:16s} {n:3d} {r['cells']:6d} {r['P']:6.1f} {r['w_over_h']:8.4f} {r['levy']:6.3f} "
                    f"{r['rel_error']:+8.2%} {r['total_s']:7.2f}")
            rows += part
            worst = max(part, key=lambda r: abs(r["rel_error"]))
            series.setdefault(support, []).append({**part[-1], "rel_error": abs(worst["rel_error"])})
    write_csv(outdir / "levy.csv", rows, COLUMNS)
    as_written = [{k: float(f"{v:.6g}") if isinstance(v, float) else v for k, v in r.items()} for r in rows]
    (outdir / "levy.md").write_text(markdown(as_written))  # the CSV's digits, as docs/levy.md includes it
    plot_error_time(outdir / "levy_error_time.png", series,
                    "Levy clamped plate: worst |error| of w_c/h over the table", error="rel_error",
                    ylabel="max over P of |w_c/h - Levy| / Levy")
    return rows
