"""The mesh tools' calls of a cup run replayed: their cost per call and per contact pass against
the analytic tools' on the same calls (docs/tools.md, "Tools from surface meshes").

    python scripts/mesh_tool_replay.py N STROKE PER_TURN [MODULE.py ...]

Draws demos/numisheet93_aluminium_cad.toml with mesh.n = N by STROKE mm with its punch and die
meshed by gmsh at PER_TURN triangles a turn (scripts/cup_tools_stl.py, as
scripts/mesh_tool_newton.py does) and read as MeshTool, recording every call of their gap and
shape (the points, the offset, dz). Then replays the calls on fresh tools, in the order of the
run: the analytic tools of demos/numisheet93_aluminium.toml, the MeshTools of
shellform.tools.mesh_tool and of each MODULE.py given (another version of mesh_tool.py, e.g.
`git show REV:shellform/tools/mesh_tool.py > old.py`). Prints for each the CPU seconds of all
gap and of all shape calls, per call in ms and per Newton iteration of the run, the points
answered each way (MeshTool.counts) and the largest differences of gap, normal and H from the
first MeshTools' (ties: points whose gap is the same and whose normal is another closest
point's, at the same distance; counted, and left out of |dn|).
"""

import importlib.util
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import shellform  # noqa: F401  (before dolfinx)
from shellform import scene
from shellform.tools import mesh_tool
from shellform.tools.cad import cad_cup_tools
from shellform.contact.problem import DrawingProblem
from shellform.tools.square import square_cup_tools

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cup_tools_step import die, punch  # noqa: E402
from cup_tools_stl import write_stl  # noqa: E402

HOLDER = (45.0, 20.0)  # the holder's inner edge, as in scripts/mesh_tool_newton.py

n, stroke, per_turn = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
modules = [("mesh", mesh_tool)]
for path in sys.argv[4:]:
    spec = importlib.util.spec_from_file_location(Path(path).stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    modules.append((f"mesh {path}", module))

analytic_scene = scene.load("demos/numisheet93_aluminium.toml")
t = analytic_scene.tools
folder = Path(tempfile.mkdtemp())
write_stl(punch, folder / "punch.stl", per_turn, 10.0, t.punch_half_width, t.punch_corner_radius,
          t.punch_profile_radius)
write_stl(die, folder / "die.stl", per_turn, 10.0, t.die_half_width, t.die_corner_radius, t.die_profile_radius)
s = scene.load("demos/numisheet93_aluminium_cad.toml").changed(
    {"mesh.n": n, "tools.punch_file": str(folder / "punch.stl"), "tools.die_file": str(folder / "die.stl"),
     "tools.holder_half_width": HOLDER[0], "tools.holder_corner_radius": HOLDER[1]})
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
print(f"run: n {n}, {stroke:g} mm, {per_turn:g} a turn, {len(p.driver.history)} increments, {iterations} "
      f"iterations, {time.perf_counter() - t0:.1f} s; parts_s {p.driver.times['parts_s']:.2f}; calls: "
      + ", ".join(f"{k} {sum(1 for c in calls if c[1] == k)}" for k in ("gap", "shape"))
      + f", {np.mean([len(c[2]) for c in calls]):.0f} points a call", flush=True)

thickness = s.material.thickness
sets = [("analytic", square_cup_tools(analytic_scene.tools, thickness))]
for label, module in modules:
    tools = cad_cup_tools(s.tools, thickness)
    for name in ("punch", "die"):
        tools[name].tool = module.MeshTool.from_file(getattr(s.tools, f"{name}_file"),
                                                     normals=getattr(s.tools, f"{name}_normals"))
    sets.append((label, tools))
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
    if label != "mesh" and "mesh" in answers and label != "analytic":
        dg = dn = dh = 0.0
        ties = 0
        for a, b, c in zip(out, answers["mesh"], calls):
            if c[1] == "shape":
                dh = max(dh, np.abs(a - b).max(initial=0.0))
                continue
            g, nn = np.abs(a[0] - b[0]), np.abs(a[1] - b[1]).max(axis=1, initial=0.0)
            tie = (g < 1e-9) & (nn > 1e-6) & (np.abs(b[0]) > 1e-6)  # another closest point as near
            ties += int(tie.sum())
            dg, dn = max(dg, g.max(initial=0.0)), max(dn, nn[~tie].max(initial=0.0))
        line += f" {dg:10.1e} {dn:8.1e} {dh:8.1e}  ties {ties}"
    if label != "analytic":
        line += "  " + "; ".join(f"{name} {tools[name].tool.counts}" for name in ("punch", "die"))
    print(line, flush=True)
