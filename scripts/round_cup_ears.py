"""Ears of the round cup with Hill 1948 (docs/cup.md, "Ears of the round cup").

    python scripts/round_cup_ears.py N STROKE [OUT]

demos/round_cup.toml's tools and blank with mesh.n = N, drawn STROKE mm, with Hill 1948 and the
rolling direction along x for three sheets: (a) r0 = r90 = 2, r45 = 1; (b) r0 = r90 = 1, r45 = 2;
(c) r0 = r45 = r90 = 1.5. Per sheet the rim's radial draw-in D at 0, 45 and 90 degrees
(results/cup.py rim: an ear is where the rim is drawn in least), (D0 + D90)/2 - D45 (< 0: ears at
0 and 90 degrees, troughs at 45), the rim's least and most draw-in and their angles, its spread,
the spread of its height z, and the run's wall time. Before the runs: the mesh's symmetry about
45 degrees (the largest distance from a node's mirror image in x = y to the nearest node). With
OUT: OUT/rim_a.csv ... (the rims: angle, draw-in, z) and OUT/ears.png.
"""

import sys
import time
from pathlib import Path

import numpy as np

import shellform  # noqa: F401  (before dolfinx)
from shellform import scene
from shellform.contact.problem import DrawingProblem
from shellform.results.cup import rim, rim_draw_in

SHEETS = {"a": (2.0, 1.0, 2.0), "b": (1.0, 2.0, 1.0), "c": (1.5, 1.5, 1.5)}


def sheet(n: int, stroke: float, r0: float, r45: float, r90: float):
    return scene.load("demos/round_cup.toml").changed({
        "mesh.n": n, "tools.stroke": stroke, "material.r": 1.0, "material.yield_function": "hill48",
        "material.r0": r0, "material.r45": r45, "material.r90": r90, "process.report": []})


def mirror_gap(p) -> float:
    """The largest distance from a node's mirror image in x = y to the mesh's nearest node (mm)."""
    X = p.nodal_values()[0]
    Y = X[:, ::-1]
    return float(max(np.hypot(*(X - y).T).min() for y in Y))


def main():
    n, stroke = int(sys.argv[1]), float(sys.argv[2])
    out = Path(sys.argv[3]) if len(sys.argv) > 3 else None
    rims = {}
    print(f"round cup, mesh.n = {n}, stroke {stroke:g} mm, Hill 1948, rolling direction along x")
    for name, r in SHEETS.items():
        p = DrawingProblem.from_scene(sheet(n, stroke, *r), verbose=False)
        if name == "a":
            print(f"cells {p.model.mesh.topology.index_map(2).size_global}, rim nodes {int(p.rim().sum())}, "
                  f"largest gap of a node's mirror image in x = y to a node: {mirror_gap(p):.3g} mm")
        t0 = time.perf_counter()
        p.driver.run(1.0)
        wall = time.perf_counter() - t0
        rows = rim(p)
        rims[name] = rows
        d = rim_draw_in(rows)
        d0, d45, d90 = d["rim_0deg"], d["rim_45deg"], d["rim_90deg"]
        lo, hi = int(np.argmin(rows[:, 1])), int(np.argmax(rows[:, 1]))
        print(f"({name}) r0 {r[0]:g} r45 {r[1]:g} r90 {r[2]:g}: stroke {p.stroke:.3f} mm, draw-in D0 {d0:.4f}, "
              f"D45 {d45:.4f}, D90 {d90:.4f} mm, (D0 + D90)/2 - D45 {(d0 + d90) / 2 - d45:+.4f} mm, least "
              f"{rows[lo, 1]:.4f} at {rows[lo, 0]:.1f} deg, most {rows[hi, 1]:.4f} at {rows[hi, 0]:.1f} deg, "
              f"spread {np.ptp(rows[:, 1]):.4f} mm ({np.ptp(rows[:, 1]) / rows[:, 1].mean():.2%} of the mean "
              f"{rows[:, 1].mean():.4f}), z spread {np.ptp(rows[:, 2]):.2e} mm, {len(p.driver.history)} increments, "
              f"{wall:.1f} s", flush=True)
    if out is not None:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        out.mkdir(parents=True, exist_ok=True)
        fig, ax = plt.subplots(figsize=(7, 4))
        for name, rows in rims.items():
            np.savetxt(out / f"rim_{name}.csv", rows, delimiter=",", header="angle_deg,draw_in_mm,z_mm",
                       comments="", fmt="%.6g")
            r0, r45, r90 = SHEETS[name]
            ax.plot(rows[:, 0], rows[:, 1], "o-", ms=3, label=f"({name}) r0 {r0:g}, r45 {r45:g}, r90 {r90:g}")
        ax.set_xlabel("angle from the rolling direction x, initial (degrees)")
        ax.set_ylabel("radial draw-in of the rim (mm)\nleast: an ear")
        ax.set_title(f"Round cup, Hill 1948, mesh.n = {n}, stroke {stroke:g} mm", fontsize=10)
        ax.set_xticks(range(0, 91, 15))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(out / "ears.png", dpi=110)


if __name__ == "__main__":
    main()
