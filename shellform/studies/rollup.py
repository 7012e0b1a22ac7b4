"""A cantilever strip rolled up by an end moment into a full circle (docs/references.md section 3).

Strip L x b clamped at x = -L/2, nu = 0, end moment M = lambda 2 pi EI / L per unit width
at x = L/2 (the exact work M theta of the end fibre's rotation, shellform.nonlinear.loads).
Symmetry on the long sides makes it the cylindrical bending of a wide plate, so EI = D.
Exact: a circular arc of radius EI/M; tip at x = R sin(L/R), z = R (1 - cos(L/R)) from the
clamp. Error: the largest tip distance from it over lambda in (0, 1], in units of L.
"""

import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from shellform.material import Hill79Material
from shellform.nonlinear.driver import Controls
from shellform.nonlinear.loads import EdgeMoment, SheetLoads
from shellform.nonlinear.problem import SheetProblem
from shellform.studies.common import plot_error_time
from shellform.results.log import say
from shellform.results.tables import write_csv

L, T, E = 1.0, 0.01, 1.0
EI = E * T**3 / 12
LEVELS = (16, 32, 48, 64)
QUICK_LEVELS = (16, 32)
STATIONS = np.linspace(0.125, 1.0, 8)
COLUMNS = ["n", "cells", "dofs", "max_tip_error", "full_circle_error", "increments", "iterations",
           "compile_s", "element_s", "constitutive_s", "assembly_s", "solve_s", "total_s"]


def exact_tip(lam):
    """Tip displacement (u, w) from its initial position at load factor lam."""
    R = L / (2 * np.pi * lam)
    return R * np.sin(L / R) - L, R * (1 - np.cos(L / R))


def problem(n, step=0.05, thickness=T, comm=MPI.COMM_WORLD, assumed_membrane=False):
    b = L / n  # one element across: the strip is a slice of a wide plate
    ei = E * thickness**3 / 12
    loads = SheetLoads(moments=[EdgeMoment("right", 2 * np.pi * ei / L)])
    return SheetProblem.on_rectangle(
        comm, L, b, n, Hill79Material(E=E, nu=0.0), thickness,
        ("bending", "membrane", "geometric_nonlinearity") + (("assumed_membrane",) if assumed_membrane else ()),
        supports={"left": "clamped", "top": "symmetry", "bottom": "symmetry"}, loads=loads,
        controls=Controls(initial_step=step, max_step=step))


def solve(n, stations=STATIONS, step=0.05, thickness=T, assumed_membrane=False) -> dict:
    t0 = time.perf_counter()
    p = problem(n, step, thickness, assumed_membrane=assumed_membrane)
    compile_s = time.perf_counter() - t0
    errors = []
    for lam in stations:
        p.driver.run(lam)
        ue, we = exact_tip(lam)
        u, w = p.value("u", L / 2, 0.0), p.value("w", L / 2, 0.0)
        errors.append(np.hypot(u - ue, w - we) / L)
    d = p.driver
    return {"n": n, "cells": p.model.mesh.topology.index_map(2).size_global,
            "dofs": p.model.V.dofmap.index_map.size_global * 9, "errors": errors,
            "max_tip_error": max(errors), "full_circle_error": errors[-1], "increments": len(d.history),
            "iterations": sum(i.iterations for i in d.history), "compile_s": compile_s, **d.times,
            "total_s": time.perf_counter() - t0}


def markdown(rows: list[dict]) -> str:
    """The table docs/rollup.md includes (rollup.md): a row per mesh; the first run's wall time
    holds the kernels' compilation; errors as 8.9e-2."""
    def short(v: float) -> str:
        return f"{v:.1e}".replace("e-0", "e-").replace("e+0", "e+")

    return ("| elements along the strip | cells | max tip error / L over lambda in (0, 1] | at the full circle | wall time |\n"
            + "|---" * 5 + "|\n"
            + "".join(f"| {r['n']} | {r['cells']} | {short(r['max_tip_error'])} | {short(r['full_circle_error'])} | "
                      f"{r['total_s']:.1f} s{' (with compilation, numba cached)' if i == 0 else ''} |\n"
                      for i, r in enumerate(rows)))


def run(outdir: Path, levels=LEVELS) -> list[dict]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    rows = []
    say(f"{'n':>3s} {'cells':>6s} {'max tip error/L':>16s} {'at 2 pi':>10s} {'increments':>10s} {'time_s':>7s}")
    for n in levels:
        r = solve(n)
        say(f"{n:3d} {r['cells']:6d} {r['max_tip_error']:16.2e} {r['full_circle_error']:10.2e} "
            f"{r['increments']:10d} {r['total_s']:7.2f}")
        rows.append(r)
    write_csv(outdir / "rollup.csv", rows, COLUMNS)
    as_written = [{k: float(f"{v:.6g}") if isinstance(v, float) else v for k, v in r.items()} for r in rows]
    (outdir / "rollup.md").write_text(markdown(as_written))  # the CSV's digits, as docs/rollup.md includes it
    plot_error_time(outdir / "rollup_error_time.png", {"roll-up": rows},
                    "Strip rolled into a full circle: tip error", error="max_tip_error",
                    ylabel="max over the path of |tip - exact| / L")
    return rows
