"""Newton's convergence on the aluminium cup with tools from surface meshes: Nagata patches
against flat facets against the analytic tools (docs/tools.md, "Tools from surface meshes").

    python scripts/mesh_tool_newton.py N STROKE PER_TURN [PER_TURN ...]

demos/numisheet93_aluminium.toml with mesh.n = N drawn STROKE mm by its analytic tools, then for
each PER_TURN by its punch and die meshed by gmsh (scripts/cup_tools_stl.py: PER_TURN triangles
along a full turn of a curved face, at most 10 mm; the holder's edge at HOLDER) and read as
MeshTool: once as Nagata patches (the tool a scene gets), once as flat facets (the same
triangles, c = 0: facet normals). For each run: increments, Newton iterations, cut-backs, punch
force, draw-in, peak thinning, wall time and the driver's parts_s (the contact passes, tools
included); the residual's decay: the median over the iterates with |R| below 0.1 of the
increment's first of the observed order log|R_k+1| / log|R_k| (2: quadratic), and the increments' iterations.

The flat facets are for this comparison only: a scene's .stl tool is always Nagata's.
"""

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import shellform  # noqa: F401  (before dolfinx)
from shellform import scene
from shellform.contact import problem as drawing
from shellform.tools import cad as cad_kind
from shellform.tools.mesh_tool import MeshTool, read_surface_mesh
from shellform.errors import InputError
from shellform.results.cup import draw_in, peak_thinning

# the holder's inner edge where the CAD scene has it: on the die's shoulder seam
HOLDER = (45.0, 20.0)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cup_tools_step import die, punch  # noqa: E402
from cup_tools_stl import write_stl  # noqa: E402


def flat_facets(path, normals, field):
    """The triangles of a mesh file as flat patches: X = x_0 + (x_1 - x_0) u + (x_2 - x_0) v."""
    vertices, triangles = read_surface_mesh(path, field)
    x = vertices[triangles]
    patches = np.zeros((len(triangles), 6, 3))
    patches[:, 0], patches[:, 1], patches[:, 2] = x[:, 0], x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
    return MeshTool(patches, normals=normals)


def run(s, label):
    try:
        p = drawing.DrawingProblem.from_scene(s, verbose=False)
    except InputError as exc:
        print(f"{label}: refused: {exc}", flush=True)
        return
    t0 = time.perf_counter()
    p.driver.run(stroke / s.tools.stroke)
    wall = time.perf_counter() - t0
    h = p.driver.history
    orders = []
    for inc in h:
        r = np.asarray(inc.residuals, dtype=float) / inc.residuals[0]
        for a, b in zip(r[:-1], r[1:]):
            if 0 < b < a < 1e-1:
                orders.append(np.log(b) / np.log(a))
    d = draw_in(p)
    its = [x.iterations for x in h]
    print(f"{label}: increments {len(h)}, iterations {sum(its)} (largest {max(its)}), cut-backs "
          f"{sum(x.cutbacks for x in h)}, force {p.punch_force():.6g} N, DX {d['DX']:.6g}, DD {d['DD']:.6g}, "
          f"thinning {peak_thinning(p)['min_thickness_strain']:.6g}, order {np.median(orders) if orders else 0:.2f} "
          f"({len(orders)} steps), run {wall:.2f} s, parts_s {p.driver.times['parts_s']:.2f} s", flush=True)
    print(f"  iterations per increment: {its}", flush=True)


n, stroke, turns = int(sys.argv[1]), float(sys.argv[2]), [float(a) for a in sys.argv[3:]]
base = scene.load("demos/numisheet93_aluminium.toml").changed({"mesh.n": n})
run(base, f"analytic, n {n}, {stroke} mm")
cad = scene.load("demos/numisheet93_aluminium_cad.toml").changed({"mesh.n": n})
t = base.tools
with tempfile.TemporaryDirectory() as folder:
    for per_turn in turns:
        files = Path(folder) / f"{per_turn:g}"
        files.mkdir()
        write_stl(punch, files / "punch.stl", per_turn, 10.0, t.punch_half_width, t.punch_corner_radius,
                  t.punch_profile_radius)
        write_stl(die, files / "die.stl", per_turn, 10.0, t.die_half_width, t.die_corner_radius, t.die_profile_radius)
        s = cad.changed({"tools.punch_file": str(files / "punch.stl"), "tools.die_file": str(files / "die.stl"),
                         "tools.holder_half_width": HOLDER[0], "tools.holder_corner_radius": HOLDER[1]})
        sizes = [len(read_surface_mesh(files / f"{k}.stl")[1]) for k in ("punch", "die")]
        run(s, f"Nagata, {per_turn:g} a turn ({sizes[0]} + {sizes[1]} triangles)")
        nagata = cad_kind.tools

        def faceted(spec, thickness):
            tools = nagata(spec, thickness)
            # the placed tools (placement.Placed) keep their rotation, translation and axis
            tools["punch"].tool = flat_facets(spec.punch_file, spec.punch_normals, "tools.punch_file")
            tools["die"].tool = flat_facets(spec.die_file, spec.die_normals, "tools.die_file")
            return tools

        cad_kind.tools = faceted
        try:
            run(s, f"faceted, {per_turn:g} a turn")
        finally:
            cad_kind.tools = nagata
