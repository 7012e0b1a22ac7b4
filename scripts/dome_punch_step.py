"""A hemispherical punch as a CAD solid (gmsh, OpenCASCADE), written as a STEP file: the punch
of demos/dome_cup.toml, a part no analytic tool of shellform/tools/analytic.py describes.

    python scripts/dome_punch_step.py OUT_FOLDER [RADIUS]

writes OUT_FOLDER/punch.step: a cylinder of radius R (default 35 mm) standing on a hemisphere of
the same radius, its tip at z = 0 (the scene places it with punch_translation [0, 0, t/2]). The
sphere is turned a quarter turn about x before the union, so that the poles of its
parametrisation lie on its equator at (0, +-R, R), where the sheet does not reach for strokes
below R: at a pole the surface's parameters degenerate and the closest-point Newton of
shellform/tools/surface_tool.py loses its footing.
"""

import math
import sys
from pathlib import Path

from cup_tools_step import write_step


def dome_punch(gmsh, radius, height=60.0):
    """The punch in the current gmsh model: tip at z = 0, a cylinder up to z = radius + height."""
    occ = gmsh.model.occ
    sphere = occ.addSphere(0.0, 0.0, radius, radius)
    occ.rotate([(3, sphere)], 0.0, 0.0, radius, 1.0, 0.0, 0.0, math.pi / 2)
    cylinder = occ.addCylinder(0.0, 0.0, radius, 0.0, 0.0, height, radius)
    occ.fuse([(3, cylinder)], [(3, sphere)])
    occ.synchronize()


if __name__ == "__main__":
    out = Path(sys.argv[1])
    radius = float(sys.argv[2]) if len(sys.argv) > 2 else 35.0
    out.mkdir(parents=True, exist_ok=True)
    write_step(dome_punch, out / "punch.step", radius)
    print(f"wrote {out / 'punch.step'}")
