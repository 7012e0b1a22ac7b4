"""Plates of other outlines against closed forms, error against wall time: the circular plate
(a curved rim, simply supported or clamped; Timoshenko & Woinowsky-Krieger section 15) and
the simply supported equilateral triangle (oblique edges; section 35).

D = 1, q = 1, nu = 0.3. Circle of radius 1, a quarter with symmetry on x = 0 and y = 0, nested
gmsh meshes (BASE_N elements along the radius, refined): w_0 = q a^4/(64 D) clamped,
(5 + nu)/(1 + nu) q a^4/(64 D) simply supported. Triangle of height 1 from its centroid:
w_0 = q a^4/(972 D), on gmsh meshes of n elements across (not nested: its corners stay
corners). Wall time: mesh + compile + assembly + solve of each run, as shellform.linear times it.

    shellform study outlines --out docs/results/outlines
"""

import math
from pathlib import Path

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


def row(case: str, scene: Scene) -> dict:
    result = linear.solve(scene)
    w = result.value("w")
    return {"case": case, "n": scene.mesh.n, "refine": scene.mesh.refine, "cells": result.num_cells, "w_center": w,
            "rel_error": (w - REFERENCE[case]) / REFERENCE[case], "total_s": result.timings["total_s"],
            "compile_s": result.timings["compile_s"]}


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
    plot_error_time(outdir / "outlines_error_time.png", series,
                    "Plates of other outlines, centre deflection: error against wall time")
    return rows
