"""The cross-shaped cup's punch and die as CAD solids (gmsh, OpenCASCADE), written as STEP files
for demos/cross_cup.toml (docs/tools.md, "A cross-shaped cup"). No analytic tool describes them:
the punch's plan is a cross whose arms' ends are rounded (convex corners) and whose re-entrant
corners between the arms are filleted (concave corners).

    python scripts/cross_cup_step.py demos/meshes/cross

writes punch.step and die.step there. The punch: two boxes fused into a cross (arms of half-width
ARM reaching REACH from the centre), its vertical edges rounded (CONVEX at the arms' ends,
CONCAVE between the arms), then its bottom edge loop rounded with the nose radius NOSE; its face
at z = 0. The die: a plate whose opening is the punch's plan offset by the clearance CLEARANCE
(the convex radii grow by it, the concave ones shrink), the opening's top edge loop rounded with
the shoulder radius SHOULDER; its flat top at z = 0. The scene places them on the sheet's
surfaces (+-t/2), and the blank holder covers the die's flat top outside the shoulder.
"""

import sys
from pathlib import Path

from cup_tools_step import write_step

ARM, REACH, CONVEX, CONCAVE, NOSE = 20.0, 45.0, 8.0, 16.0, 6.0  # mm: the punch
CLEARANCE, SHOULDER = 2.0, 5.0  # mm: the die (the flat top's tips between the arms: 16 - 2 - 5 = 9 mm)


def _edges(gmsh, keep):
    return [t for _, t in gmsh.model.getEntities(1) if keep(*gmsh.model.getBoundingBox(1, t))]


def _cross(gmsh, arm, reach, convex, concave, z0, height):
    """A cross prism from z0 up by height, its vertical edges rounded: `convex` at the arms'
    ends, `concave` at the re-entrant corners (|x| = |y| = arm). Returns its volume's tag."""
    occ = gmsh.model.occ
    a = occ.addBox(-reach, -arm, z0, 2 * reach, 2 * arm, height)
    b = occ.addBox(-arm, -reach, z0, 2 * arm, 2 * reach, height)
    (_, vol), = occ.fuse([(3, a)], [(3, b)])[0]
    occ.synchronize()

    def vertical_at(corner):
        def keep(x0, y0, z0_, x1, y1, z1):
            return abs(x1 - x0) < 1e-6 and abs(y1 - y0) < 1e-6 and corner(abs(x0), abs(y0))
        return keep

    ends = _edges(gmsh, vertical_at(lambda x, y: abs(max(x, y) - reach) < 1e-6))
    (_, vol), = occ.fillet([vol], ends, [convex])
    occ.synchronize()
    inner = _edges(gmsh, vertical_at(lambda x, y: abs(x - arm) < 1e-6 and abs(y - arm) < 1e-6))
    (_, vol), = occ.fillet([vol], inner, [concave])
    occ.synchronize()
    return vol


def punch(gmsh, z_face=0.0, height=60.0):
    vol = _cross(gmsh, ARM, REACH, CONVEX, CONCAVE, z_face, height)
    bottom = _edges(gmsh, lambda x0, y0, z0, x1, y1, z1: z1 < z_face + 1e-6)
    gmsh.model.occ.fillet([vol], bottom, [NOSE])
    gmsh.model.occ.synchronize()


def die(gmsh, z_top=0.0, outer=100.0, depth=60.0):
    occ, c = gmsh.model.occ, CLEARANCE
    plate = occ.addBox(-outer, -outer, z_top - depth, 2 * outer, 2 * outer, depth)
    occ.synchronize()
    hole = _cross(gmsh, ARM + c, REACH + c, CONVEX + c, CONCAVE - c, z_top - depth - 1.0, depth + 2.0)
    (_, vol), = occ.cut([(3, plate)], [(3, hole)])[0]
    occ.synchronize()
    rim = _edges(gmsh, lambda x0, y0, z0, x1, y1, z1: z0 > z_top - 1e-6 and max(x1, y1) < outer - 1e-6)
    occ.fillet([vol], rim, [SHOULDER])
    occ.synchronize()


if __name__ == "__main__":
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    write_step(punch, out / "punch.step")
    write_step(die, out / "die.step")
    print(f"wrote {out / 'punch.step'} and {out / 'die.step'}")
