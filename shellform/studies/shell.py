"""The paper's Figs. 1-2: a square shallow-shell block, simply supported, under uniform pressure.

Spherical reference surface z0 = -(x^2 + y^2)/(2R), side a = 1, thickness t = 0.01, E = 1,
nu = 0.3, pressure q = 1; quarter block with symmetry, shell diaphragm on the outer sides
(w = 0, w,s = 0, u_s = 0). The paper gives no shell data, so these are ours (docs/shell.md).
Centre deflection coefficient w D/(q a^4) against mesh density, errors against an overkill
solution of our own; and the flat-plate limit (0.00406235) as R grows.
"""

import math
from pathlib import Path

from shellform import linear
from shellform.scene import Scene, from_dict
from shellform.studies.common import observed_rates, plot_error_time, say, write_csv

A, T, NU, E = 1.0, 0.01, 0.3, 1.0
D = E * T**3 / (12 * (1 - NU**2))
PLATE = 0.00406235
LEVELS = (3, 6, 12, 24, 48)
QUICK_LEVELS = (3, 6, 12)
OVERKILL = 96
RADII = (2.0, 5.0, 10.0, 100.0, 1e3, 1e4, math.inf)
COLUMNS = ["R", "mesh", "cells", "dofs", "coefficient", "rel_error", "rate", "compile_s",
           "assemble_s", "solve_s", "total_s"]


def scene(R=5.0, n=12, kind="structured") -> Scene:
    return from_dict({
        "title": f"shallow shell block R={R}, {kind} n={n}",
        "effects": ["bending", "membrane", "shallow_curvature"],
        "geometry": {"lx": A, "ly": A, "region": "quarter"},
        "surface": {"R1": R, "R2": R},
        "mesh": {"kind": kind, "n": n},
        "material": {"E": E, "nu": NU, "thickness": T},
        "supports": {"left": "symmetry", "bottom": "symmetry",
                     "right": "simply_supported", "top": "simply_supported"},
        "loads": {"pressure": 1.0},
    })


def coefficient(R, n, kind="structured") -> dict:
    res = linear.solve(scene(R, n, kind))
    c = res.value("w") * D / A**4
    return {"R": R, "mesh": kind, "n": n, "cells": res.num_cells, "dofs": res.num_dofs,
            "coefficient": c, **res.timings}


def run(outdir: Path, R=5.0, levels=LEVELS, overkill=OVERKILL, radii=RADII) -> list[dict]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    ref = coefficient(R, overkill)["coefficient"]
    say(f"R = {R}: overkill ({overkill} x {overkill} x 2 quarter) coefficient w D/(q a^4) = {ref:.8f}")
    rows, series = [], {}
    for kind in ("structured", "unstructured"):
        part = []
        for n in levels:
            r = coefficient(R, n, kind)
            r["rel_error"] = (r["coefficient"] - ref) / ref
            part.append(r)
            r["rate"] = observed_rates(part)[-1]
            say(f"R={R} {kind:12s} cells {r['cells']:6d} coefficient {r['coefficient']:.8f} "
                f"rel_error {r['rel_error']:9.2e} rate {r['rate']:5.2f} {r['total_s']:.2f} s")
        rows += part
        series[f"R = {R}, {kind}"] = part
    n_limit = levels[-1]
    for radius in radii:
        r = coefficient(radius, n_limit)
        r["rel_error"] = (r["coefficient"] - PLATE) / PLATE
        r["rate"] = math.nan
        r["mesh"] = "flat-limit"
        rows.append(r)
        say(f"flat-plate limit: R = {radius:8g}: coefficient {r['coefficient']:.8f} "
            f"(plate {PLATE}; relative difference {r['rel_error']:.2e})")
    write_csv(outdir / "shell_convergence.csv", rows, COLUMNS)
    plot_error_time(outdir / "shell_error_time.png", series,
                    f"Shallow shell block (R = {R}): error against wall time (overkill reference)")
    return rows
