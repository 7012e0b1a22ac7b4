"""Limit load of an elastic-perfectly plastic cantilever strip, and its springback.

Strip L x b clamped at x = -L/2, symmetry on the long sides (plane strain across the strip),
small-deflection kinematics, tip deflection prescribed (displacement control). Limit analysis:
the clamp section becomes a hinge at P_L = M_p b / L, with the plane-strain fully plastic
moment M_p = s_ps t^2 / 4, s_ps the plane-strain yield stress of Hill 1979 (docs/references.md 4).
Through the thickness the section sums layer stresses: its own fully plastic moment is
M_p (4 sum w |zeta|), the number the discrete model can reach.

Unloading from the largest deflection is elastic (|Delta M| = M_p < 2 M_y), so the tip must
come back along the initial elastic slope k: residual deflection d_max - P_max / k.
"""

import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from shellform.material import Hill79Material, section
from shellform.nonlinear.driver import Controls
from shellform.nonlinear.problem import SheetProblem
from shellform.studies.common import plot_error_time
from shellform.results.log import say
from shellform.results.tables import write_csv

L, T, E, NU, SY = 1.0, 0.02, 1000.0, 0.3, 1.0
COLUMNS = ["n", "thickness_points", "r", "m", "cells", "P_max_over_PL", "P_max_over_PL_discrete",
           "rel_error", "residual_deflection_error", "increments", "iterations", "compile_s", "element_s",
           "constitutive_s", "assembly_s", "solve_s", "total_s"]
LEVELS = ((8, 5), (16, 5), (32, 5), (16, 3), (16, 9), (16, 15))
QUICK_LEVELS = ((8, 5), (16, 5))


def plane_strain_yield(r=1.0, m=2.0):
    """s1 at plane-strain yield (eps2 = 0), from docs/references.md 4: s2/s1 = (t-1)/(t+1)."""
    t = (1 + 2 * r) ** (1 / (m - 1))
    k = (t - 1) / (t + 1)
    return SY * (2 * (1 + r) / (abs(1 + k) ** m + (1 + 2 * r) * abs(1 - k) ** m)) ** (1 / m)


def limit_load(b, r=1.0, m=2.0, thickness_points=None):
    """P_L = M_p b / L; with thickness_points, the section's own (discrete) plastic moment."""
    factor = 1.0
    if thickness_points:
        zeta, w = section.through_thickness_rule(thickness_points)
        factor = 4 * float(np.sum(w * np.abs(zeta)))
    return plane_strain_yield(r, m) * T**2 / 4 * factor * b / L


def problem(n, thickness_points=5, r=1.0, m=2.0, dmax=None, controls=None, comm=MPI.COMM_WORLD):
    b = L / n
    effects = ["bending", "membrane", "plasticity"] + (["anisotropy"] if (r, m) != (1.0, 2.0) else [])
    mat = Hill79Material(E=E, nu=NU, r=r, m=m, hardening="swift", K=SY, eps0=1.0, n=0.0)
    dy = 2 * SY * L**2 / (3 * E * T)  # tip deflection at first yield (uniaxial estimate)
    return SheetProblem.on_rectangle(
        comm, L, b, n, mat, T, effects, thickness_points=thickness_points,
        supports={"left": "clamped", "top": "symmetry", "bottom": "symmetry"},
        prescribed={("right", "w"): dmax or 20 * dy},
        controls=controls or Controls(initial_step=0.01, max_step=0.05))


def solve(n, thickness_points=5, r=1.0, m=2.0) -> dict:
    t0 = time.perf_counter()
    p = problem(n, thickness_points, r, m)
    compile_s = time.perf_counter() - t0
    d = p.driver
    path = []
    d.run(1.0, on_increment=lambda drv: path.append((drv.lam, p.reaction("right", "w"))))
    b = L / n
    lam, P = np.array(path).T
    dmax = p.model.mesh.comm.allreduce(float(p.driver.prescribed.x.array.max()), op=MPI.MAX)
    k = P[0] / (lam[0] * dmax)  # the elastic slope (first increment is elastic)
    residual_pred = dmax - P[-1] / k
    d.run(residual_pred / dmax)  # unload the tip to where the elastic slope says P = 0
    P_after = p.reaction("right", "w")
    PL, PLd = limit_load(b, r, m), limit_load(b, r, m, thickness_points)
    return {"n": n, "thickness_points": thickness_points, "r": r, "m": m,
            "cells": p.model.mesh.topology.index_map(2).size_global, "path": (lam * dmax, P),
            "P_max_over_PL": P.max() / PL, "P_max_over_PL_discrete": P.max() / PLd,
            "rel_error": P.max() / PL - 1.0, "residual_deflection_error": abs(P_after) / P.max(),
            "increments": len(d.history), "iterations": sum(i.iterations for i in d.history),
            "plastic_layers": max(i.plastic_layers for i in d.history),
            "compile_s": compile_s, **d.times, "total_s": time.perf_counter() - t0}


def markdown(rows: list[dict]) -> str:
    """The table docs/plastic.md includes (plastic.md): a row per run."""
    return ("| elements | layers | P_max / P_L | P_max / discrete P_L | tip force after elastic unloading / P_max |\n"
            + "|---" * 5 + "|\n"
            + "".join(f"| {r['n']} | {r['thickness_points']} | {r['P_max_over_PL']:.3f} | "
                      f"{r['P_max_over_PL_discrete']:.3f} | {r['residual_deflection_error']:.0e} |\n" for r in rows))


def run(outdir: Path, levels=LEVELS) -> list[dict]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    rows = []
    say(f"{'n':>3s} {'layers':>6s} {'P_max/P_L':>10s} {'P_max/P_L,discrete':>18s} {'|P| after unload':>16s} {'time_s':>7s}")
    for n, nz in levels:
        row = solve(n, nz)
        say(f"{n:3d} {nz:6d} {row['P_max_over_PL']:10.4f} {row['P_max_over_PL_discrete']:18.4f} "
            f"{row['residual_deflection_error']:16.2e} {row['total_s']:7.2f}")
        rows.append(row)
    write_csv(outdir / "plastic.csv", rows, COLUMNS)
    as_written = [{k: float(f"{v:.6g}") if isinstance(v, float) else v for k, v in r.items()} for r in rows]
    (outdir / "plastic.md").write_text(markdown(as_written))  # the CSV's digits, as docs/plastic.md includes it
    plot_error_time(outdir / "plastic_error_time.png",
                    {f"{nz} layers": [r for r in rows if r["thickness_points"] == nz] for nz in
                     sorted({r["thickness_points"] for r in rows})},
                    "Cantilever limit load: P_max against limit analysis", error="rel_error",
                    ylabel="|P_max / P_L - 1|")
    _plot_path(outdir / "plastic_load_deflection.png", rows)
    return rows


def _plot_path(path, rows):
    if MPI.COMM_WORLD.rank != 0:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    for r in rows:
        d, P = r["path"]
        ax.plot(d, P / limit_load(L / r["n"]), label=f"n={r['n']}, {r['thickness_points']} layers")
    ax.axhline(1.0, color="k", lw=0.8, ls="--", label="limit analysis")
    ax.set_xlabel("tip deflection")
    ax.set_ylabel("P / P_L")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
