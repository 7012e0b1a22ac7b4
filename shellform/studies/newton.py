"""Benchmark: the cost of one Newton iteration of the elastic-plastic sheet (not a test).

Levy's clamped quarter plate, exact kinematics, Hill 1979 with Swift hardening and 5 Gauss
points through the thickness, n x n x 2 cells. The plate is loaded in a few increments until
its layers yield; the iterations of the last load step are timed, split into the element loop
(strains, FFCx kernels, maps), the constitutive update, DOLFINx assembly and the MUMPS solve.
Each time is per linear solve, i.e. per Newton iteration, counting those of an attempt that
was cut back (the csv says how many increments and cut-backs the step took).
Target (issue 3): <= 0.5 s per iteration at 10k cells on this 2-core machine.
"""

import time
from pathlib import Path

from mpi4py import MPI

from shellform.material import Hill79Material
from shellform.nonlinear.driver import Controls
from shellform.studies import levy
from shellform.results.log import say
from shellform.results.tables import write_csv

LEVELS = (16, 36, 71)  # 512, 2592, 10082 cells
QUICK_LEVELS = (16,)
COLUMNS = ["ranks", "n", "cells", "dofs", "plastic_layers", "increments", "cutbacks", "iterations", "element_s",
           "constitutive_s", "assembly_s", "solve_s", "iteration_s"]
MATERIAL = Hill79Material(E=1.0, nu=levy.NU, r=1.5, m=2.0, hardening="swift", K=1e-3, eps0=1e-3, n=0.2)


def measure(n) -> dict:
    effects = ("bending", "membrane", "geometric_nonlinearity", "plasticity", "anisotropy")
    p = levy.problem(n, effects=effects, material=MATERIAL, thickness_points=5,
                     controls=Controls(initial_step=0.08, max_step=0.08))
    d = p.driver
    d.run(0.16)  # two increments: compile, and yield the plate
    before, solves, increments = dict(d.times), d.solves, len(d.history)
    t0 = time.perf_counter()
    d.run(0.24)
    wall = time.perf_counter() - t0
    timed = d.history[increments:]
    iterations = max(d.solves - solves, 1)
    split = {k: (d.times[k] - before[k]) / iterations for k in before}
    return {"ranks": MPI.COMM_WORLD.size, "n": n, "cells": p.model.mesh.topology.index_map(2).size_global,
            "dofs": p.model.V.dofmap.index_map.size_global * 9, "plastic_layers": timed[-1].plastic_layers,
            "increments": len(timed), "cutbacks": sum(i.cutbacks for i in timed), "iterations": iterations, **split,
            "iteration_s": wall / iterations}


def run(outdir: Path, levels=LEVELS) -> list[dict]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    rows = []
    say(f"{'ranks':>5s} {'cells':>6s} {'plastic':>8s} {'element_s':>9s} {'constit_s':>9s} {'assembly_s':>10s} "
        f"{'solve_s':>8s} {'per iteration':>13s}")
    for n in levels:
        r = measure(n)
        say(f"{r['ranks']:5d} {r['cells']:6d} {r['plastic_layers']:8d} {r['element_s']:9.3f} "
            f"{r['constitutive_s']:9.3f} {r['assembly_s']:10.3f} {r['solve_s']:8.3f} {r['iteration_s']:13.3f}")
        rows.append(r)
    write_csv(outdir / f"newton_ranks{MPI.COMM_WORLD.size}.csv", rows, COLUMNS)
    return rows
