"""The cost of a CAD tool's gap and shape against the analytic tool's (docs/tools.md).

    python scripts/surface_tool_cost.py [POINTS]

The NUMISHEET'93 aluminium cup's punch and die (demos/numisheet93_aluminium_cad.toml, its STEP
files) and the analytic ones of demos/numisheet93_aluminium.toml, at POINTS (2000) random points
within 3 mm of each surface (the sheet's nodes in a contact pass lie there or farther); the best
of five calls of each, in ms, and the largest differences of gap and normal.
"""

import sys
import time

import numpy as np

from shellform import scene
from shellform.contact.surface_tool import cad_cup_tools
from shellform.contact.tools import square_cup_tools

points = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
analytic_scene, cad_scene = (scene.load(f"demos/{name}.toml") for name in
                             ("numisheet93_aluminium", "numisheet93_aluminium_cad"))
t = analytic_scene.material.thickness
analytic, cad = square_cup_tools(analytic_scene.tools, t), cad_cup_tools(cad_scene.tools, t)
rng = np.random.default_rng(0)


def best(f, *args):
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        f(*args)
        times.append(time.perf_counter() - t0)
    return 1e3 * min(times)


print(f"{'tool':6} {'gap ms':>8} {'analytic':>9} {'shape ms':>9} {'analytic':>9} {'|dgap| mm':>10} {'|dn|':>9}")
for name in ("punch", "die"):
    x = rng.uniform([-60.0, -60.0, -10.0], [60.0, 60.0, 10.0], (50 * points, 3))
    g, _ = analytic[name].gap(x, 0.0)
    x = x[np.abs(g) < 3.0][:points]
    g0, n0 = analytic[name].gap(x, t / 2)
    g1, n1 = cad[name].gap(x, t / 2)
    print(f"{name:6} {best(cad[name].gap, x, t / 2):8.2f} {best(analytic[name].gap, x, t / 2):9.3f} "
          f"{best(cad[name].shape, x, t / 2):9.2f} {best(analytic[name].shape, x, t / 2):9.3f} "
          f"{np.abs(g1 - g0).max():10.1e} {np.abs(n1 - n0).max():9.1e}")
