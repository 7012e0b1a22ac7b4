"""The aluminium cup drawn by its STEP tools against the analytic run on the same blank mesh
(docs/tools.md, "The cup drawn by STEP tools").

    python scripts/cad_cup_compare.py N STROKE

demos/numisheet93_aluminium.toml and demos/numisheet93_aluminium_cad.toml with mesh.n = N, each
drawn STROKE mm: increments, iterations, punch force, draw-in, peak thickness strain, the run's
wall time and the driver's split of it (times; parts_s: the parts' share, the tools' included);
for the STEP tools, how many points each answered again, by a warm start and by a search
(SurfaceTool.counts).
"""

import sys
import time

import shellform  # noqa: F401  (before dolfinx)
from shellform import scene
from shellform.contact.problem import DrawingProblem
from shellform.results.cup import draw_in, peak_thinning

n, stroke = int(sys.argv[1]), float(sys.argv[2])
for name in ("numisheet93_aluminium", "numisheet93_aluminium_cad"):
    s = scene.load(f"demos/{name}.toml").changed({"mesh.n": n})
    p = DrawingProblem.from_scene(s, verbose=False)
    t0 = time.perf_counter()
    p.driver.run(stroke / s.tools.stroke)
    run = time.perf_counter() - t0
    h = p.driver.history
    d = draw_in(p)
    times = ", ".join(f"{k} {v:.2f}" for k, v in p.driver.times.items())
    print(f"{name}: increments {len(h)}, iterations {sum(x.iterations for x in h)}, force {p.punch_force():.6g} N, "
          f"DX {d['DX']:.10g}, DD {d['DD']:.10g}, thinning {peak_thinning(p)['min_thickness_strain']:.8g}, "
          f"run {run:.2f} s ({times})", flush=True)
    for tool_name, (tool, _, _) in p.tool_placements().items():
        if hasattr(tool, "counts"):
            print(f"  {tool_name}: points " + ", ".join(f"{k} {v}" for k, v in tool.counts.items()), flush=True)
