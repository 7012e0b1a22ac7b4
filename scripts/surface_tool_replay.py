"""The CAD tools' calls of a cup run replayed: their cost per call and per contact pass against
the analytic tools' on the same calls (docs/tools.md, "Cost").

    python scripts/surface_tool_replay.py N STROKE [MODULE.py ...]

Draws demos/numisheet93_aluminium_cad.toml with mesh.n = N by STROKE mm, recording every call
of its punch's and die's gap and shape (the points, the offset, dz). Then replays the calls on
fresh tools, in the order of the run: the analytic tools of demos/numisheet93_aluminium.toml,
the STEP tools of shellform.tools.surface_tool and of each MODULE.py given (another version
of surface_tool.py, e.g. `git show REV:shellform/tools/surface_tool.py > old.py`). Prints
for each the CPU seconds of all gap and of all shape calls, per call in ms and per Newton
iteration of the run, and the largest differences of gap, normal and H from the first STEP
tools' (ties: points whose gap is the same and whose normal is another closest point's, at
the same distance: the medial axis, e.g. the diagonal x = y inside the die's opening; counted,
and left out of |dn|).
"""

import importlib.util
import sys
import time
from pathlib import Path

import numpy as np

import shellform  # noqa: F401  (before dolfinx)
from shellform import scene
from shellform.tools import surface_tool
from shellform.contact.problem import DrawingProblem
from shellform.tools.square import square_cup_tools

n, stroke = int(sys.argv[1]), float(sys.argv[2])
modules = [("STEP", surface_tool)]
for path in sys.argv[3:]:
    spec = importlib.util.spec_from_file_location(Path(path).stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    modules.append((f"STEP {path}", module))

s = scene.load("demos/numisheet93_aluminium_cad.toml").changed({"mesh.n": n})
p = DrawingProblem.from_scene(s, verbose=False)
calls = []  # (tool name, method, x, offset, dz)


def recorder(name, tool, method):
    original = getattr(tool, method)

    def call(x, offset=0.0, dz=0.0):
        calls.append((name, method, np.array(x, dtype=float), np.array(offset, dtype=float), float(dz)))
        return original(x, offset, dz)

    return call


for name, (tool, _, _) in p.tool_placements().items():
    if name in ("punch", "die"):
        for method in ("gap", "shape"):
            setattr(tool, method, recorder(name, tool, method))
t0 = time.perf_counter()
p.driver.run(stroke / s.tools.stroke)
iterations = sum(h.iterations for h in p.driver.history)
print(f"run: n {n}, {stroke:g} mm, {len(p.driver.history)} increments, {iterations} iterations, "
      f"{time.perf_counter() - t0:.1f} s; parts_s {p.driver.times['parts_s']:.2f}; calls: "
      + ", ".join(f"{k} {sum(1 for c in calls if c[1] == k)}" for k in ("gap", "shape"))
      + f", {np.mean([len(c[2]) for c in calls]):.0f} points a call", flush=True)

t = s.material.thickness
analytic_scene = scene.load("demos/numisheet93_aluminium.toml")
sets = [("analytic", square_cup_tools(analytic_scene.tools, t))]


def cup_tools(module):
    """The cup's tools of `module`: shellform.tools.surface_tool or another version of
    surface_tool.py (its SurfaceTool placed by cad_tools), or of cad_tools.py."""
    if hasattr(module, "cad_cup_tools"):
        return module.cad_cup_tools(s.tools, t)
    from shellform.tools import cad as cad_tools

    current = cad_tools.SurfaceTool
    cad_tools.SurfaceTool = module.SurfaceTool
    try:
        return cad_tools.cad_cup_tools(s.tools, t)
    finally:
        cad_tools.SurfaceTool = current


sets += [(label, cup_tools(module)) for label, module in modules]
answers = {}
print(f"{'tools':28} {'gap s':>7} {'shape s':>8} {'gap ms/call':>12} {'shape ms/call':>14} {'ms/iteration':>13} "
      f"{'|dgap| mm':>10} {'|dn|':>8} {'|dH|':>8}")
for label, tools in sets:
    spent = {"gap": 0.0, "shape": 0.0}
    out = []
    for name, method, x, offset, dz in calls:
        f = getattr(tools[name], method)
        t1 = time.process_time()
        r = f(x, offset, dz)
        spent[method] += time.process_time() - t1
        out.append(r)
    answers[label] = out
    count = {k: max(sum(1 for c in calls if c[1] == k), 1) for k in spent}
    line = (f"{label[:28]:28} {spent['gap']:7.2f} {spent['shape']:8.2f} {1e3 * spent['gap'] / count['gap']:12.3f} "
            f"{1e3 * spent['shape'] / count['shape']:14.3f} {1e3 * sum(spent.values()) / iterations:13.2f}")
    if label != "STEP" and "STEP" in answers and label != "analytic":
        dg = dn = dh = 0.0
        ties = 0
        for a, b, c in zip(out, answers["STEP"], calls):
            if c[1] == "shape":
                dh = max(dh, np.abs(a - b).max(initial=0.0))
                continue
            g, n = np.abs(a[0] - b[0]), np.abs(a[1] - b[1]).max(axis=1, initial=0.0)
            tie = (g < 1e-9) & (n > 1e-6) & (np.abs(b[0]) > 1e-6)  # another closest point as near
            ties += int(tie.sum())
            dg, dn = max(dg, g.max(initial=0.0)), max(dn, n[~tie].max(initial=0.0))
        line += f" {dg:10.1e} {dn:8.1e} {dh:8.1e}  ties {ties}"
    print(line, flush=True)
