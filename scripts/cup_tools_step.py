"""The square cup's punch and die as CAD solids (gmsh, OpenCASCADE), written as STEP files: the
analytic tools of shellform/tools/analytic.py built from the same dimensions, for a scene's
[tools] shape = "cad" (docs/tools.md).

    python scripts/cup_tools_step.py SCENE.toml OUT_FOLDER

writes OUT_FOLDER/punch.step and OUT_FOLDER/die.step from the scene's square [tools]
(`holder` builds a flat holder's plate: tests/test_channel.py's flat binder from a file). The punch's
face lies at z = 0, the die's flat top at z = 0: the scene places them with punch_translation
[0, 0, t/2 + punch_gap] and die_translation [0, 0, -t/2] (the sheet's mid-surface is z = 0).

punch(gmsh, ...): a box with filleted edges: its vertical edges rounded with the plan corner
radius, then its bottom edge loop with the nose radius (cylinders along the sides, tori at the
corners); the analytic punch is this solid with its walls continued upwards.
die(gmsh, ...): a plate with a square opening whose vertical edges are rounded with the plan
corner radius, the opening's top edge loop rounded with the shoulder radius.
"""

import sys
from pathlib import Path


def _edges(gmsh, keep):
    """The model's edges whose bounding box (x0, y0, z0, x1, y1, z1) passes keep."""
    return [t for _, t in gmsh.model.getEntities(1) if keep(*gmsh.model.getBoundingBox(1, t))]


def _vertical(x0, y0, z0, x1, y1, z1):
    return abs(x1 - x0) < 1e-6 and abs(y1 - y0) < 1e-6


def punch(gmsh, half_width, corner_radius, profile_radius, z_face=0.0, height=60.0):
    """The punch in the current gmsh model: face at z_face, walls up to z_face + height."""
    occ, a = gmsh.model.occ, half_width
    box = occ.addBox(-a, -a, z_face, 2 * a, 2 * a, height)
    occ.synchronize()
    occ.fillet([box], _edges(gmsh, _vertical), [corner_radius])
    occ.synchronize()
    (_, vol), = gmsh.model.getEntities(3)
    bottom = _edges(gmsh, lambda x0, y0, z0, x1, y1, z1: z1 < z_face + 1e-6)
    occ.fillet([vol], bottom, [profile_radius])
    occ.synchronize()


def vertical_edges_of(gmsh, volume):
    """The vertical edges of one volume of the current model."""
    faces = gmsh.model.getBoundary([(3, volume)], oriented=False)
    edges = {abs(t) for _, t in gmsh.model.getBoundary(faces, combined=False, oriented=False)}
    return [t for t in edges if _vertical(*gmsh.model.getBoundingBox(1, t))]


def cut_opening(gmsh, solid, half_width, corner_radius, z0, z1):
    """Cut from the volume `solid` the rounded-square opening of half-width half_width (plan
    corner radius corner_radius > 0) between z0 and z1; returns the volume left."""
    occ, a = gmsh.model.occ, half_width
    hole = occ.addBox(-a, -a, z0, 2 * a, 2 * a, z1 - z0)
    occ.synchronize()
    occ.fillet([hole], vertical_edges_of(gmsh, hole), [corner_radius])
    occ.synchronize()
    (_, hole), = [e for e in gmsh.model.getEntities(3) if e[1] != solid]
    occ.cut([(3, solid)], [(3, hole)])
    occ.synchronize()
    (_, vol), = gmsh.model.getEntities(3)
    return vol


def die(gmsh, half_width, corner_radius, profile_radius, z_top=0.0, outer=100.0, depth=60.0):
    """The die in the current gmsh model: flat top at z_top over |x|, |y| <= outer, the opening
    of half-width half_width (plan corner radius corner_radius > 0) through its depth."""
    occ = gmsh.model.occ
    plate = occ.addBox(-outer, -outer, z_top - depth, 2 * outer, 2 * outer, depth)
    vol = cut_opening(gmsh, plate, half_width, corner_radius, z_top - depth - 1.0, z_top + 1.0)
    rim = _edges(gmsh, lambda x0, y0, z0, x1, y1, z1: z0 > z_top - 1e-6 and max(x1, y1) < outer - 1e-6)
    occ.fillet([vol], rim, [profile_radius])
    occ.synchronize()


def holder(gmsh, half_width, corner_radius, z_face=0.0, outer=100.0, height=20.0):
    """A flat blank holder in the current gmsh model: a plate whose face (its bottom) lies at
    z_face over |x|, |y| <= outer, with the opening of half-width half_width (plan corner radius
    corner_radius > 0) through it; its face's inner edge is sharp, as the analytic holder's
    (shellform/tools/analytic.py, BlankHolder) ends there."""
    plate = gmsh.model.occ.addBox(-outer, -outer, z_face, 2 * outer, 2 * outer, height)
    cut_opening(gmsh, plate, half_width, corner_radius, z_face - 1.0, z_face + height + 1.0)


def write_step(build, path, *args, prepare=None):
    """build(gmsh, *args) in a fresh gmsh model, written to path (STEP; or what path's suffix
    says, after prepare(gmsh): a surface mesh's, for example)."""
    import gmsh

    owner = not gmsh.isInitialized()
    if owner:
        gmsh.initialize(readConfigFiles=False, interruptible=False)
    gmsh.option.setNumber("General.Terminal", 0)
    previous = gmsh.model.getCurrent()
    gmsh.model.add(f"write_{Path(path).stem}")
    try:
        build(gmsh, *args)
        if prepare is not None:
            prepare(gmsh)
        gmsh.write(str(path))
    finally:
        gmsh.model.remove()
        if owner:
            gmsh.finalize()
        elif previous:
            gmsh.model.setCurrent(previous)


if __name__ == "__main__":
    from shellform import scene

    t = scene.load(sys.argv[1]).tools
    out = Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    write_step(punch, out / "punch.step", t.punch_half_width, t.punch_corner_radius, t.punch_profile_radius)
    write_step(die, out / "die.step", t.die_half_width, t.die_corner_radius, t.die_profile_radius)
    print(f"wrote {out / 'punch.step'} and {out / 'die.step'}")
