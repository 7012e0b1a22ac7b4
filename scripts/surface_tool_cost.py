"""The cost of a CAD tool's gap and shape against the analytic tool's (docs/tools.md).

    python scripts/surface_tool_cost.py [POINTS]

The NUMISHEET'93 aluminium cup's punch and die (demos/numisheet93_aluminium_cad.toml, its STEP
files) and the analytic ones of demos/numisheet93_aluminium.toml, at POINTS (2000) random points
within 3 mm of each surface (the sheet's nodes in a contact pass lie there or farther), in ms:

    search    gap on points a tool has not seen (the first call of a new tool; best of 3 tools)
    moved     gap on the points of the last call each moved by up to 1e-3 mm (best of 5)
    again     gap on the points of the last call (best of 5)
    shape     shape on the points of the last gap call (best of 5)

and the analytic tool's gap and shape (best of 5), and the largest differences of gap and
normal from the analytic tool's on the moved points.
"""

import sys
import time

import numpy as np

from shellform import scene
from shellform.tools.cad import cad_cup_tools
from shellform.tools.square import square_cup_tools

points = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
analytic_scene, cad_scene = (scene.load(f"demos/{name}.toml") for name in
                             ("numisheet93_aluminium", "numisheet93_aluminium_cad"))
t = analytic_scene.material.thickness
analytic = square_cup_tools(analytic_scene.tools, t)
fresh = [cad_cup_tools(cad_scene.tools, t) for _ in range(3)]
rng = np.random.default_rng(0)


def timed(f, *args):
    t0 = time.perf_counter()
    f(*args)
    return 1e3 * (time.perf_counter() - t0)


print(f"{'tool':6} {'search':>8} {'moved':>8} {'again':>8} {'shape':>8} {'analytic gap':>13} {'shape':>8} "
      f"{'|dgap| mm':>10} {'|dn|':>9}")
for name in ("punch", "die"):
    x = rng.uniform([-60.0, -60.0, -10.0], [60.0, 60.0, 10.0], (50 * points, 3))
    g, _ = analytic[name].gap(x, 0.0)
    x = x[np.abs(g) < 3.0][:points]
    search = min(timed(tools[name].gap, x, t / 2) for tools in fresh)
    cad = fresh[0][name]
    moved, again, shape, dg, dn = [], [], [], 0.0, 0.0
    for _ in range(5):
        y = x + rng.uniform(-1e-3, 1e-3, x.shape) / np.sqrt(3.0)
        moved.append(timed(cad.gap, y, t / 2))
        again.append(timed(cad.gap, y, t / 2))
        shape.append(timed(cad.shape, y, t / 2))
        g0, n0 = analytic[name].gap(y, t / 2)
        g1, n1 = cad.gap(y, t / 2)
        dg, dn = max(dg, np.abs(g1 - g0).max()), max(dn, np.abs(n1 - n0).max())
    a_gap = min(timed(analytic[name].gap, x, t / 2) for _ in range(5))
    a_shape = min(timed(analytic[name].shape, x, t / 2) for _ in range(5))
    print(f"{name:6} {search:8.2f} {min(moved):8.2f} {min(again):8.2f} {min(shape):8.2f} {a_gap:13.3f} "
          f"{a_shape:8.3f} {dg:10.1e} {dn:9.1e}")
