"""Plates of other outlines against closed forms, error against wall time: the circular plate
(a curved rim, simply supported or clamped; Timoshenko & Woinowsky-Krieger section 15) and
the simply supported equilateral triangle (oblique edges; section 35).

D = 1, q = 1, nu = 0.3. Circle of radius 1, a quarter with symmetry on x = 0 and y = 0, nested
gmsh meshes (BASE_N elements along the radius, refined): w_0 = q a^4/(64 D) clamped,
(5 + nu)/(1 + nu) q a^4/(64 D) simply supported. Triangle of height 1 from its centroid:
w_0 = q a^4/(972 D), on gmsh meshes of n elements across (not nested: its corners stay
corners). Wall time: mesh + compile + assembly + solve of each run, as shellform.linear times it.
The nonlinear sheet on the clamped disc (its curved rim held in the rim's frames), t = 0.01,
q = P 64 D t / a^4 (P = 1: the linear w0 = t), P = 1.488 and 4.904 on 8, 16 and 32 elements
along the radius: outlines_nonlinear.csv (no closed form; the mesh sequence shows convergence).

    shellform study outlines --out docs/results/outlines
"""

import math
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from shellform import linear
from shellform.scene import Scene, from_dict
from shellform.studies.common import observed_rates, plot_error_time
from shellform.results.log import say
from shellform.results.tables import write_csv

NU = 0.3
MATERIAL = {"E": 12 * (1 - NU**2), "nu": NU, "thickness": 1.0}  # D = 1
REFERENCE = {"clamped": 1 / 64, "simply_supported": (5 + NU) / (1 + NU) / 64, "triangle": 1 / 972}
BASE_N = 4
LEVELS = (0, 1, 2, 3, 4)
QUICK_LEVELS = (0, 1, 2)
TRIANGLE_N = (8, 16, 32, 64, 128)
TRIANGLE = [[-1 / 3, -1 / math.sqrt(3)], [2 / 3, 0.0], [-1 / 3, 1 / math.sqrt(3)]]
COLUMNS = ["case", "n", "refine", "cells", "w_center", "rel_error", "rate", "total_s", "compile_s"]


def disc_scene(support: str, n: int = BASE_N, refine: int = 0) -> Scene:
    """The quarter of the unit disc under q = 1, its rim `support`, D = 1."""
    return from_dict({
        "effects": ["bending"], "material": MATERIAL, "loads": {"pressure": 1.0},
        "geometry": {"shape": "circle", "radius": 1.0, "region": "quarter"},
        "mesh": {"kind": "unstructured", "n": n, "refine": refine},
        "supports": {"rim": support, "left": "symmetry", "bottom": "symmetry"}})


def triangle_scene(n: int) -> Scene:
    """The simply supported equilateral triangle of height 1 (centroid at the origin), q = 1, D = 1."""
    return from_dict({
        "effects": ["bending"], "material": MATERIAL, "loads": {"pressure": 1.0},
        "geometry": {"shape": "polygon", "vertices": TRIANGLE, "edges": ["edge"] * 3},
        "mesh": {"kind": "unstructured", "n": n}, "supports": {"edge": "simply_supported"}})


SHEET = ("bending", "membrane", "geometric_nonlinearity")
SHEET_T = 0.01
DISC_LOADS = (1.488, 4.904)
DISC_N = (8, 16, 32)


def clamped_disc(region: str, n: int, P: float, theta: float = 0.0, rim: str = "clamped"):
    """The nonlinear sheet on the unit disc (mesh turned by theta), its rim clamped (or `rim`),
    under q = P 64 D t / a^4 (E = 1, t = SHEET_T); returns (w0 / t, the SheetProblem)."""
    from shellform.material import Hill79Material
    from shellform.mesh import outline
    from shellform.nonlinear.driver import Controls
    from shellform.nonlinear.loads import SheetLoads
    from shellform.nonlinear.problem import SheetProblem

    blank = outline.circle(MPI.COMM_WORLD, 1.0, region, n)
    c, sn = math.cos(theta), math.sin(theta)
    x = blank.mesh.geometry.x
    x[:, :2] = x[:, :2] @ np.array([[c, -sn], [sn, c]]).T
    supports = {"rim": rim, **({"left": "symmetry", "bottom": "symmetry"} if region == "quarter" else {})}
    D = SHEET_T**3 / (12 * (1 - NU**2))
    p = SheetProblem.on_blank(blank, Hill79Material(E=1.0, nu=NU), SHEET_T, SHEET, supports,
                              SheetLoads(pressure=P * 64 * D * SHEET_T),
                              controls=Controls(initial_step=0.25, max_step=0.25))
    p.driver.run(1.0)
    return p.value("w", 0.0, 0.0) / SHEET_T, p


def nonlinear_rows(disc_n=DISC_N) -> list[dict]:
    rows = []
    for P in DISC_LOADS:
        for n in disc_n:
            t0 = time.perf_counter()
            w, p = clamped_disc("quarter", n, P)
            rows.append({"P": P, "n": n, "cells": p.model.mesh.topology.index_map(2).size_global,
                         "w0_over_t": w, "newton_iterations": sum(h.iterations for h in p.driver.history),
                         "total_s": time.perf_counter() - t0})
            say(f"clamped disc, nonlinear sheet: P {P:5.3f}  n {n:3d}  cells {rows[-1]['cells']:5d}  "
                f"w0/t {w:.5f}  {rows[-1]['total_s']:.2f} s")
    return rows


def row(case: str, scene: Scene) -> dict:
    result = linear.solve(scene)
    w = result.value("w")
    return {"case": case, "n": scene.mesh.n, "refine": scene.mesh.refine, "cells": result.num_cells, "w_center": w,
            "rel_error": (w - REFERENCE[case]) / REFERENCE[case], "total_s": result.timings["total_s"],
            "compile_s": result.timings["compile_s"]}


LABELS = {"simply_supported": "disc, simply supported", "clamped": "disc, clamped",
          "triangle": "triangle, simply supported"}


def markdown(rows: list[dict]) -> str:
    """The table docs/outlines.md includes (outlines.md): a row per mesh, each case named on its
    first row, w_center to the CSV's six digits."""
    out = "| case | cells | w_center | rel. error | rate | time (s) |\n" + "|---" * 6 + "|\n"
    for i, r in enumerate(rows):
        first = i == 0 or rows[i - 1]["case"] != r["case"]
        rate = "-" if math.isnan(r["rate"]) else f"{r['rate']:.2f}"
        out += (f"| {LABELS.get(r['case'], r['case']) if first else ''} | {r['cells']:,} | {r['w_center']:#.6g} | "
                f"{r['rel_error']:.2e} | {rate} | {r['total_s']:.3f} |\n")
    return out


def run(outdir: Path, levels=LEVELS) -> list[dict]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    linear.solve(disc_scene("clamped"))  # compile the kernels once, outside the timings
    cases = {"simply_supported": [disc_scene("simply_supported", BASE_N, k) for k in levels],
             "clamped": [disc_scene("clamped", BASE_N, k) for k in levels],
             "triangle": [triangle_scene(n) for n in TRIANGLE_N[: len(levels)]]}
    rows, series = [], {}
    say(f"{'case':17s} {'cells':>6s} {'w_center':>13s} {'rel_error':>10s} {'rate':>5s} {'total_s':>7s}")
    for case, scenes in cases.items():
        part = []
        for s in scenes:
            part.append(row(case, s))
            part[-1]["rate"] = observed_rates(part)[-1]
            r = part[-1]
            say(f"{case:17s} {r['cells']:6d} {r['w_center']:13.10f} {r['rel_error']:10.2e} {r['rate']:5.2f} "
                f"{r['total_s']:7.3f}")
        rows += part
        series[{"triangle": "triangle, simply supported (oblique edges)"}.get(case, f"disc, {case} rim")] = part
    write_csv(outdir / "outlines.csv", rows, COLUMNS)
    as_written = [{k: float(f"{v:.6g}") if isinstance(v, float) else v for k, v in r.items()} for r in rows]
    (outdir / "outlines.md").write_text(markdown(as_written))  # the CSV's digits, as docs/outlines.md includes it
    plot_error_time(outdir / "outlines_error_time.png", series,
                    "Plates of other outlines, centre deflection: error against wall time")
    sheet = nonlinear_rows(DISC_N[: max(1, len(levels) - 2)])
    write_csv(outdir / "outlines_nonlinear.csv", sheet, list(sheet[0]))
    return rows
