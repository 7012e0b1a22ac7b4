"""The NUMISHEET'93 mild-steel cup with its three r values (Hill 1948) against the averaged r
(Hill 1979, the demo's) on the same mesh (docs/cup.md, "The NUMISHEET'93 steel with three r
values").

    python scripts/numisheet_three_r.py N STROKE [STROKE ...]

demos/numisheet93_steel.toml with mesh.n = N drawn to each STROKE (mm) in turn, three times: as
Hill 1979 (m = 2, r = 1.77 = (r0 + 2 r45 + r90)/4, the scene's model before it took the three
values), with Hill 1948 from r0 = r45 = r90 = 1.77 (the same material written as Hill 1948: a
control), and with Hill 1948 from r0 = 1.79, r45 = 1.51, r90 = 2.27 (the scene as it is); the
rolling direction along x, the flow curve the rolling
direction's. Per run and stroke: DX, DY, DD, DX - DY, the punch force, the peak thickness strain,
increments, iterations and the wall time so far.
"""

import sys
import time

import shellform  # noqa: F401  (before dolfinx)
from shellform import scene
from shellform.contact.problem import DrawingProblem
from shellform.results.cup import draw_in, peak_thinning


def hill48(r0, r45, r90):
    return {"material.r": 1.0, "material.yield_function": "hill48",
            "material.r0": r0, "material.r45": r45, "material.r90": r90}


n, strokes = int(sys.argv[1]), [float(a) for a in sys.argv[2:]]
base = scene.load("demos/numisheet93_steel.toml").changed({"mesh.n": n, "process.report": []})
runs = {"Hill 1979, r 1.77": {"material.yield_function": "hill79", "material.r": 1.77, "material.m": 2.0,
                               "material.r0": 0.0, "material.r45": 0.0, "material.r90": 0.0}, "Hill 1948, r 1.77 / 1.77 / 1.77": hill48(1.77, 1.77, 1.77),
        "Hill 1948, r 1.79 / 1.51 / 2.27": hill48(1.79, 1.51, 2.27)}
for name, changes in runs.items():
    p = DrawingProblem.from_scene(base.changed(changes), verbose=False)
    t0 = time.perf_counter()
    for stroke in strokes:
        p.driver.run(stroke / base.tools.stroke)
        wall = time.perf_counter() - t0
        h = p.driver.history
        d = draw_in(p)
        print(f"{name}: stroke {p.stroke:.3f} mm, DX {d['DX']:.4f}, DY {d['DY']:.4f}, DD {d['DD']:.4f} mm, "
              f"DX - DY {d['DX'] - d['DY']:+.4f} mm, punch force {p.punch_force() / 1e3:.3f} kN, "
              f"peak thickness strain {peak_thinning(p)['min_thickness_strain']:.4f}, {len(h)} increments, "
              f"{sum(x.iterations for x in h)} iterations, {wall:.1f} s", flush=True)
