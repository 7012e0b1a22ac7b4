"""The square cup's punch and die as surface meshes (binary STL): the CAD solids of
scripts/cup_tools_step.py meshed by gmsh, for a scene's [tools] shape = "cad" with .stl files
(docs/tools.md, "Tools from surface meshes").

    python scripts/cup_tools_stl.py SCENE.toml OUT_FOLDER [PER_TURN] [LARGEST]

writes OUT_FOLDER/punch.stl and OUT_FOLDER/die.stl from the scene's square [tools]: triangles of
at most LARGEST mm (default 6), PER_TURN of them along a full turn of a curved face (default 48:
about 1 mm on the 8 mm nose and shoulder). As the STEP files: the punch's face and the die's top
at z = 0.

write_stl(build, path, per_turn, largest, *args) meshes any builder of cup_tools_step.py.
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cup_tools_step import die, punch, write_step  # noqa: E402


def write_stl(build, path, per_turn, largest, *args):
    """build(gmsh, *args) in a fresh gmsh model, its surface meshed (per_turn triangles along a
    full turn of a curved face, at most `largest` mm), written to path as binary STL."""

    def mesh(gmsh):
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", per_turn)
        gmsh.option.setNumber("Mesh.MeshSizeMax", largest)
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
        gmsh.model.mesh.generate(2)
        gmsh.option.setNumber("Mesh.Binary", 1)

    write_step(build, path, *args, prepare=mesh)

if __name__ == "__main__":
    from shellform import scene

    t = scene.load(sys.argv[1]).tools
    out = Path(sys.argv[2])
    per_turn = float(sys.argv[3]) if len(sys.argv) > 3 else 48.0
    largest = float(sys.argv[4]) if len(sys.argv) > 4 else 6.0
    out.mkdir(parents=True, exist_ok=True)
    write_stl(punch, out / "punch.stl", per_turn, largest, t.punch_half_width, t.punch_corner_radius,
              t.punch_profile_radius)
    write_stl(die, out / "die.stl", per_turn, largest, t.die_half_width, t.die_corner_radius, t.die_profile_radius)
    print(f"wrote {out / 'punch.stl'} and {out / 'die.stl'}")
