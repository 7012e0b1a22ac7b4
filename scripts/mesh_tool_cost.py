"""The cost of a mesh tool's gap and shape per call against the analytic tool's (docs/tools.md,
"Tools from surface meshes").

    python scripts/mesh_tool_cost.py PER_TURN [MODULE.py ...]

The NUMISHEET'93 aluminium cup's punch meshed by gmsh at PER_TURN triangles a turn
(scripts/cup_tools_stl.py) and read as MeshTool (of shellform.tools.mesh_tool and of each
MODULE.py given, another version of mesh_tool.py), at 2,000 random points within 3 mm of the
analytic punch, CPU ms:

    search    gap on points a tool has not seen (the first call of a new tool; best of 3 tools)
    moved     gap on the points of the last call each moved by 1e-3 mm (best of 5)
    moved 0.1 the same, moved by 0.1 mm (best of 5)
    again     gap on the points of the last call (best of 5)
    shape     shape on the points of the last gap call (best of 5)

and the analytic punch's gap and shape (best of 5).
"""

import importlib.util
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from shellform import scene
from shellform.tools import mesh_tool
from shellform.tools.square import square_cup_tools

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cup_tools_step import punch  # noqa: E402
from cup_tools_stl import write_stl  # noqa: E402

per_turn = float(sys.argv[1])
modules = [("mesh_tool", mesh_tool)]
for path in sys.argv[2:]:
    spec = importlib.util.spec_from_file_location(Path(path).stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    modules.append((path, module))
s = scene.load("demos/numisheet93_aluminium.toml")
t, thickness = s.tools, s.material.thickness
analytic = square_cup_tools(t, thickness)["punch"]
stl = Path(tempfile.mkdtemp()) / "punch.stl"
write_stl(punch, stl, per_turn, 10.0, t.punch_half_width, t.punch_corner_radius, t.punch_profile_radius)
rng = np.random.default_rng(0)
x = rng.uniform([-60.0, -60.0, -4.0], [60.0, 60.0, 40.0], (40000, 3))
g, _ = analytic.gap(x)
x = x[(g > -1.0) & (g < 3.0)][:2000]
steps = rng.normal(size=(5, *x.shape))
steps /= np.linalg.norm(steps, axis=2)[:, :, None]


def cpu(f, *args):
    t0 = time.process_time()
    f(*args)
    return 1e3 * (time.process_time() - t0)


print(f"{len(x)} points; analytic gap {min(cpu(analytic.gap, x) for _ in range(5)):.2f} ms, shape "
      f"{min(cpu(analytic.shape, x) for _ in range(5)):.2f} ms")
for label, module in modules:
    tools = [module.MeshTool.from_file(stl, (0.0, 0.0, thickness / 2)) for _ in range(3)]
    search = min(cpu(tool.gap, x) for tool in tools)
    tool = tools[0]
    row = {"search": search}
    for name, size in (("moved", 1e-3), ("moved 0.1", 0.1)):
        times = []
        for k in range(5):
            tool.gap(x)
            times.append(cpu(tool.gap, x + size * steps[k]))
        row[name] = min(times)
    tool.gap(x)
    row["again"] = min(cpu(tool.gap, x) for _ in range(5))
    row["shape"] = min(cpu(tool.shape, x) for _ in range(5))
    print(f"{label} ({len(tool.patches)} triangles): " + ", ".join(f"{k} {v:.1f} ms" for k, v in row.items())
          + f"; counts {tool.counts}")
