"""Benchmark: compile and assembly cost of the hybrid element (targets in docs/performance.md).

Re-assembly of the condensed, mapped stiffness on a ~10k-cell quarter plate, for the plate
(bending) and the shallow shell (membrane + bending + curvature), and the wall time of the
simply supported plate study. Times are the best of several repeats on this machine.
"""

import os
import platform
import time
from pathlib import Path

import dolfinx.fem.petsc as fem_petsc

from shellform import linear
from shellform.studies import plate, shell
from shellform.results.log import say
from shellform.results.tables import write_csv

COLUMNS = ["case", "cells", "dofs", "compile_s", "first_assembly_s", "reassembly_s", "us_per_cell", "solve_s"]


def _cpu() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def assembly_row(case: str, s, repeats: int = 5) -> dict:
    rect = linear.mesh(s)
    t0 = time.perf_counter()
    forms = linear.compile_forms(s, rect.mesh)
    t1 = time.perf_counter()
    A = fem_petsc.assemble_matrix(forms.stiffness)
    A.assemble()
    t2 = time.perf_counter()
    best = float("inf")
    for _ in range(repeats):
        A.zeroEntries()
        t = time.perf_counter()
        fem_petsc.assemble_matrix(A, forms.stiffness)
        A.assemble()
        best = min(best, time.perf_counter() - t)
    A.destroy()
    A, b = linear.assemble_system(forms, linear.boundary_conditions(s, rect, forms))
    t = time.perf_counter()
    linear.lu_solve(A, b, forms.V)
    solve_s = time.perf_counter() - t
    cells = len(forms.cells)
    return {"case": case, "cells": cells, "dofs": forms.num_dofs, "compile_s": t1 - t0,
            "first_assembly_s": t2 - t1, "reassembly_s": best, "us_per_cell": best / cells * 1e6,
            "solve_s": solve_s}


def run(outdir: Path) -> list[dict]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    say(f"machine: {os.cpu_count()} cores, {_cpu()}")
    rows = [
        assembly_row("plate (bending)", plate.scene("simply_supported", "structured", 70)),
        assembly_row("shallow shell (membrane + bending + curvature)", shell.scene(5.0, 70)),
    ]
    for r in rows:
        say(f"{r['case']:48s} {r['cells']:6d} cells: compile {r['compile_s']:.2f} s, first assembly "
            f"{r['first_assembly_s']:.3f} s, re-assembly {r['reassembly_s']:.4f} s = "
            f"{r['us_per_cell']:.2f} us/cell, solve {r['solve_s']:.3f} s")
    t = time.perf_counter()
    plate.run(outdir / "ss_study", supports=("simply_supported",), unmapped=False, references=False)
    study = time.perf_counter() - t
    rows.append({"case": "simply supported plate study, 10 solves up to 11264 cells (wall time)",
                 "reassembly_s": study})
    say(f"simply supported plate study (in a process that has compiled already): {study:.2f} s")
    write_csv(outdir / "assembly_benchmark.csv", rows, COLUMNS)
    return rows
