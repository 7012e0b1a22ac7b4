"""Kirchhoff square plate under uniform pressure: convergence of the centre deflection.

Quarter plate [0, a/2]^2 with symmetry at x = 0 and y = 0; simply supported or clamped at
x = a/2 and y = a/2; a = 1, D = 1, q = 1, nu = 0.3, so w_center is the coefficient w D/(q a^4).
References: the project's validation notes, section 1 (docs/plate.md); the simply supported value from the
Navier double series summed here to round-off (0.0040623526607, within the table's 8 digits).

The plain DOLFINx route gives reference curves on the same error-against-time plot: the C0
interior-penalty plate with P2 and P3 Lagrange elements (shellform.studies.interior_penalty),
on the same quarter plate and meshes, timed the same way (mesh + assembly + solve, forms
compiled before), simply supported, up to 32,768 cells.
"""

import math
from pathlib import Path

import numpy as np

from shellform import linear
from shellform.scene import Scene, from_dict
from shellform.studies import interior_penalty
from shellform.studies.common import observed_rates, plot_error_time
from shellform.results.log import say
from shellform.results.tables import write_csv


def navier_centre(terms: int = 2001) -> float:
    """w D / (q a^4) at the centre of the simply supported square plate: the Navier series
    16 / pi^6 sum over odd m, n of (-1)^((m + n)/2 - 1) / (m n (m^2 + n^2)^2)."""
    m = np.arange(1, terms, 2.0)
    M, N = np.meshgrid(m, m)
    return float(16 / np.pi**6 * np.sum((-1.0) ** ((M + N) / 2 - 1) / (M * N * (M**2 + N**2) ** 2)))


REFERENCE = {"simply_supported": navier_centre(), "clamped": 0.00126532}
NU = 0.3
THICKNESS = (12 * (1 - NU**2)) ** (1 / 3)  # D = E t^3 / (12 (1 - nu^2)) = 1 with E = 1
BASE_N = 4  # elements along a quarter side of the coarsest mesh
LEVELS = (0, 1, 2, 3, 4)  # uniform refinements of it: nested meshes, 32 ... 8192 structured cells
QUICK_LEVELS = (0, 1, 2)
IP_LEVELS = (0, 1, 2, 3, 4, 5)  # the interior-penalty references, to 32,768 cells
IP_DEGREES = (2, 3)
COLUMNS = ["support", "mesh", "element", "cells", "dofs", "w_center", "rel_error", "abs_error_coeff",
           "rate", "compile_s", "assemble_s", "solve_s", "total_s"]


def scene(support="simply_supported", kind="structured", n=6, diagonal="right", mapped=True,
          refine=0) -> Scene:
    return from_dict({
        "title": f"square plate, {support}, {kind} n={n}, refined {refine}x",
        "effects": ["bending"],
        "geometry": {"lx": 1.0, "ly": 1.0, "region": "quarter"},
        "mesh": {"kind": kind, "n": n, "diagonal": diagonal, "refine": refine},
        "material": {"E": 1.0, "nu": NU, "thickness": THICKNESS},
        "supports": {"left": "symmetry", "bottom": "symmetry", "right": support, "top": support},
        "loads": {"pressure": 1.0},
        "solver": {"mapped": mapped},
    })


def solve_row(support, kind, n, diagonal="right", mapped=True, refine=0) -> dict:
    res = linear.solve(scene(support, kind, n, diagonal, mapped, refine))
    w = res.value("w", 0.0, 0.0)
    ref = REFERENCE[support]
    mesh = kind if kind == "unstructured" else f"structured-{diagonal}"
    return {"support": support, "mesh": mesh, "element": "mapped" if mapped else "unmapped",
            "n": n, "cells": res.num_cells, "dofs": res.num_dofs, "w_center": w,
            "rel_error": (w - ref) / ref, "abs_error_coeff": w - ref, **res.timings}


def interior_penalty_rows(degree: int, levels) -> list[dict]:
    """The simply supported plate by C0 interior penalty with P(degree) on the study's meshes."""
    ref = REFERENCE["simply_supported"]
    interior_penalty.solve(BASE_N, degree, NU)  # compile the forms once
    part = []
    for k in levels:
        r = interior_penalty.solve(BASE_N * 2**k, degree, NU)
        part.append({"support": "simply_supported", "mesh": "structured-right", "element": f"C0-IP P{degree}",
                     "n": BASE_N * 2**k, **r, "rel_error": (r["w_center"] - ref) / ref,
                     "abs_error_coeff": r["w_center"] - ref})
        part[-1]["rate"] = observed_rates(part)[-1]
        log_row(part[-1])
    return part


def log_row(r: dict) -> None:
    say(f"{r['support']:17s} {r['mesh']:18s} {r['element']:8s} {r['cells']:6d} {r['w_center']:12.8f} "
        f"{r['rel_error']:10.2e} {r['rate']:5.2f} {r['total_s']:7.3f}")


def markdown(rows: list[dict]) -> str:
    """The table docs/plate.md includes (plate_convergence.md): a row per plate, the time that of
    assembly and solve (no compilation), no rate for a series' first mesh."""
    head = ("| support | mesh | element | cells | dofs | w D/(q a^4) | rel. error | abs. error | rate "
            "| assemble + solve [s] |\n" + "|---" * 10 + "|\n")
    return head + "".join(
        f"| {r['support']} | {r['mesh']} | {r['element']} | {r['cells']} | {r['dofs']} | {r['w_center']:.8f} | "
        f"{r['rel_error']:.2e} | {r['abs_error_coeff']:.2e} | {'' if math.isnan(r['rate']) else format(r['rate'], '.2f')} | "
        f"{r['assemble_s'] + r['solve_s']:.3f} |\n" for r in rows)


def run(outdir: Path, supports=("simply_supported", "clamped"), kinds=("structured", "unstructured"),
        levels=LEVELS, unmapped=True, references=True) -> list[dict]:
    """The convergence study; references: also the C0 interior-penalty plates (plain DOLFINx)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    variants = [(s, k, True) for s in supports for k in kinds]
    if unmapped:
        variants += [(s, k, False) for s in supports[:1] for k in kinds]
    rows, series = [], {}
    say(f"{'support':17s} {'mesh':18s} {'element':8s} {'cells':>6s} {'w_center':>12s} "
        f"{'rel_error':>10s} {'rate':>5s} {'total_s':>7s}")
    for support, kind, mapped in variants:
        part = []
        for k in levels:
            part.append(solve_row(support, kind, BASE_N, mapped=mapped, refine=k))
            part[-1]["rate"] = observed_rates(part)[-1]
            log_row(part[-1])
        rows += part
        series[f"{support}, {part[0]['mesh']}, {part[0]['element']}"] = part
    if references and "simply_supported" in supports:
        for degree in IP_DEGREES:
            part = interior_penalty_rows(degree, [k for k in IP_LEVELS if k <= max(levels) + 1])
            rows += part
            series[f"simply_supported, {part[0]['mesh']}, {part[0]['element']} (plain DOLFINx)"] = part
    # the paper's figure: 72 elements on the quarter plate, both diagonal directions
    for diagonal in ("right", "left"):
        r = solve_row("simply_supported", "structured", 6, diagonal=diagonal)
        r["rate"] = math.nan
        rows.append(r)
        say(f"72 elements, diagonal {diagonal}: |w D/(q a^4) error| = {abs(r['abs_error_coeff']):.2e} "
            "(paper: 7.2e-5)")
    write_csv(outdir / "plate_convergence.csv", rows, COLUMNS)
    as_written = [{k: float(f"{v:.6g}") if isinstance(v, float) else v for k, v in r.items()} for r in rows]
    (outdir / "plate_convergence.md").write_text(markdown(as_written))  # the CSV's digits, as docs/plate.md includes it
    plot_error_time(outdir / "plate_error_time.png", series,
                    "Square plate, centre deflection: error against wall time")
    return rows
