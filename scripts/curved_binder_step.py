"""A square cup's die and holder over a cylindrical binder as CAD solids (gmsh, OpenCASCADE),
written as STEP files, for a scene's [tools] shape = "cad" with the holder's face from a file
(holder_file) and binder_rise (docs/tools.md, "A cup over a curved binder from CAD files").

    python scripts/curved_binder_step.py OUT_FOLDER [RADIUS]

writes OUT_FOLDER/die.step and OUT_FOLDER/holder.step (RADIUS: the binder's, mm, default 500)
with the square cup's opening (half-width 37, plan corner radius 12, shoulder 5 mm; the punch
is scripts/cup_tools_step.py's, demos/meshes/numisheet93/punch.step).

die(gmsh, ...): a block whose top is the cylinder of radius R about the x axis through z = -R
(its crown z = 0 on y = 0), over |x|, |y| <= outer, with the rounded-square opening through it,
the opening's rim on the cylinder rounded with the shoulder radius.
holder(gmsh, ...): a plate whose face (its bottom) is the concentric cylinder of radius R + t
(the wrapped sheet's upper surface; crown z = t at y = 0, so that placed at the die's crown it
rests on a sheet of thickness t), with the opening of the die's top (half-width + shoulder
radius, plan corner radius + shoulder radius) through it, its rim sharp.
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cup_tools_step import _edges, _vertical, cut_opening, write_step  # noqa: E402


def _cylinder(gmsh, axis_depth, radius, outer):
    """The cylinder of `radius` about the x axis through z = -axis_depth, longer than the tools."""
    return gmsh.model.occ.addCylinder(-outer - 1.0, 0.0, -axis_depth, 2 * outer + 2.0, 0.0, 0.0, radius)


def die(gmsh, radius, half_width, corner_radius, profile_radius, outer=100.0, depth=60.0):
    """A block under the cylinder of `radius` (over |x|, |y| <= outer, from z = -depth), the
    opening cut through it, its rim on the cylinder rounded with profile_radius."""
    occ = gmsh.model.occ
    box = occ.addBox(-outer, -outer, -depth, 2 * outer, 2 * outer, depth + 10.0)
    (block,), _ = occ.intersect([(3, box)], [(3, _cylinder(gmsh, radius, radius, outer))])
    occ.synchronize()
    vol = cut_opening(gmsh, block[1], half_width, corner_radius, -depth - 1.0, 11.0)
    rim = _edges(gmsh, lambda x0, y0, z0, x1, y1, z1: z1 > -12.0 and z0 > -12.0 and max(x1, y1) < outer - 1e-6
                 and not _vertical(x0, y0, z0, x1, y1, z1))
    occ.fillet([vol], rim, [profile_radius])
    occ.synchronize()


def holder(gmsh, radius, thickness, half_width, corner_radius, outer=100.0, height=20.0):
    """A plate over the cylinder of radius + thickness (its face), the opening cut through it."""
    occ = gmsh.model.occ
    box = occ.addBox(-outer, -outer, -30.0, 2 * outer, 2 * outer, 30.0 + height)
    (plate,), _ = occ.cut([(3, box)], [(3, _cylinder(gmsh, radius, radius + thickness, outer))])
    occ.synchronize()
    cut_opening(gmsh, plate[1], half_width, corner_radius, -40.0, height + 2.0)


if __name__ == "__main__":
    out = Path(sys.argv[1])
    radius = float(sys.argv[2]) if len(sys.argv) > 2 else 500.0
    out.mkdir(parents=True, exist_ok=True)
    write_step(die, out / "die.step", radius, 37.0, 12.0, 5.0)
    write_step(holder, out / "holder.step", radius, 0.78, 42.0, 17.0)
    print(f"wrote {out / 'die.step'} and {out / 'holder.step'}")
