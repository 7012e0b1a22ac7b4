"""The paper's Figs. 1-2: a square shallow-shell block, simply supported, under uniform pressure.

Spherical reference surface z0 = -(x^2 + y^2)/(2R), side a = 1, thickness t = 0.01, E = 1,
nu = 0.3, pressure q = 1; quarter block with symmetry, shell diaphragm on the outer sides
(w = 0, w,s = 0, u_s = 0). The paper gives no shell data, so these are ours (docs/shell.md).
Centre deflection coefficient w D/(q a^4) against mesh density, errors against an overkill
solution of our own and against the Navier series of Donnell's shallow-shell equations (for a
spherical shell on diaphragm supports the shell acts as a plate on an elastic foundation
E t / R^2); and the flat-plate limit (0.00406235) as R grows.
"""

import math
from pathlib import Path

import numpy as np

from shellform import linear
from shellform.scene import Scene, from_dict
from shellform.studies.common import observed_rates, plot_error_time
from shellform.results.log import say
from shellform.results.tables import write_csv

A, T, NU, E = 1.0, 0.01, 0.3, 1.0
D = E * T**3 / (12 * (1 - NU**2))
PLATE = 0.00406235
BASE_N = 3  # elements along a quarter side of the coarsest mesh
LEVELS = (0, 1, 2, 3, 4)  # uniform refinements: nested meshes
QUICK_LEVELS = (0, 1, 2)
OVERKILL = 96  # structured quarter, 96 x 96 x 2
RADII = (2.0, 5.0, 10.0, 100.0, 1e3, 1e4, math.inf)
COLUMNS = ["R", "mesh", "cells", "dofs", "coefficient", "navier", "rel_error", "rate", "compile_s",
           "assemble_s", "solve_s", "total_s"]


def navier_coefficient(R: float, terms: int = 2000) -> float:
    """w D/(q a^4) at the centre: sum over odd m, n of 16 q / (pi^2 m n) / (D lambda^4 + E t / R^2)."""
    m = np.arange(1, 2 * terms, 2)[:, None]
    n = np.arange(1, 2 * terms, 2)[None, :]
    lam2 = (m**2 + n**2) * (np.pi / A) ** 2
    sign = np.sin(m * np.pi / 2) * np.sin(n * np.pi / 2)
    foundation = 0.0 if math.isinf(R) else E * T / R**2
    w = np.sum(16 / (np.pi**2 * m * n) * sign / (D * lam2**2 + foundation))
    return float(w * D / A**4)


def scene(R=5.0, n=12, kind="structured", refine=0) -> Scene:
    return from_dict({
        "title": f"shallow shell block R={R}, {kind} n={n}, refined {refine}x",
        "effects": ["bending", "membrane", "shallow_curvature"],
        "geometry": {"lx": A, "ly": A, "region": "quarter"},
        "surface": {"R1": R, "R2": R},
        "mesh": {"kind": kind, "n": n, "refine": refine},
        "material": {"E": E, "nu": NU, "thickness": T},
        "supports": {"left": "symmetry", "bottom": "symmetry",
                     "right": "simply_supported", "top": "simply_supported"},
        "loads": {"pressure": 1.0},
    })


def coefficient(R, n, kind="structured", refine=0) -> dict:
    res = linear.solve(scene(R, n, kind, refine))
    c = res.value("w") * D / A**4
    return {"R": R, "mesh": kind, "n": n, "cells": res.num_cells, "dofs": res.num_dofs,
            "coefficient": c, **res.timings}


def markdown(rows: list[dict]) -> str:
    """The two tables docs/shell.md includes (shell_convergence.md): the convergence against the
    overkill (the rows without a Navier value) and the flat-plate limit against Navier's."""
    def blank(v) -> bool:
        return v is None or v == "" or (isinstance(v, float) and math.isnan(v))

    mesh = [r for r in rows if blank(r.get("navier"))]
    limit = [r for r in rows if not blank(r.get("navier"))]
    n = round(math.sqrt(limit[0]["cells"] / 2)) if limit else 0
    return ("### convergence\n\n| mesh | cells | w D/(q a^4) | rel. error vs overkill | rate | total [s] |\n"
            + "|---" * 6 + "|\n"
            + "".join(f"| {r['mesh']} | {r['cells']} | {r['coefficient']:.8f} | {r['rel_error']:.2e} | "
                      f"{'' if blank(r['rate']) else format(r['rate'], '.2f')} | {r['total_s']:.3f} |\n" for r in mesh)
            + f"\n### flat_plate_limit\n\n| R | w D/(q a^4), {n} x {n} x 2 | Navier (Donnell) | rel. difference |\n"
            + "|---" * 4 + "|\n"
            + "".join(f"| {float(r['R']):g} | {r['coefficient']:.8f} | {r['navier']:.8f} | {r['rel_error']:.2e} |\n"
                      for r in limit))


def run(outdir: Path, R=5.0, levels=LEVELS, overkill=OVERKILL, radii=RADII) -> list[dict]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    ref = coefficient(R, overkill)["coefficient"]
    navier = navier_coefficient(R)
    say(f"R = {R}: overkill ({overkill} x {overkill} x 2 quarter) coefficient w D/(q a^4) = {ref:.8f}; "
        f"Navier (Donnell) series {navier:.8f}, relative difference {(ref - navier) / navier:.2e}")
    rows, series = [], {}
    for kind in ("structured", "unstructured"):
        part = []
        for k in levels:
            r = coefficient(R, BASE_N, kind, refine=k)
            r["rel_error"] = (r["coefficient"] - ref) / ref
            part.append(r)
            r["rate"] = observed_rates(part)[-1]
            say(f"R={R} {kind:12s} cells {r['cells']:6d} coefficient {r['coefficient']:.8f} "
                f"rel_error {r['rel_error']:9.2e} rate {r['rate']:5.2f} {r['total_s']:.2f} s")
        rows += part
        series[f"R = {R}, {kind}"] = part
    n_limit = BASE_N * 2 ** levels[-1]
    for radius in radii:
        r = coefficient(radius, n_limit)
        r["navier"] = navier_coefficient(radius)
        r["rel_error"] = (r["coefficient"] - r["navier"]) / r["navier"]
        r["rate"] = math.nan
        r["mesh"] = f"structured n={n_limit}, vs Navier"
        rows.append(r)
        say(f"R = {radius:8g}: coefficient {r['coefficient']:.8f}, Navier {r['navier']:.8f} "
            f"(relative difference {r['rel_error']:.2e}; flat plate {PLATE})")
    write_csv(outdir / "shell_convergence.csv", rows, COLUMNS)
    as_written = [{k: float(f"{v:.6g}") if isinstance(v, float) else v for k, v in r.items()} for r in rows]
    (outdir / "shell_convergence.md").write_text(markdown(as_written))  # the CSV's digits, as docs/shell.md includes it
    plot_error_time(outdir / "shell_error_time.png", series,
                    f"Shallow shell block (R = {R}): error against wall time (overkill reference)")
    return rows
