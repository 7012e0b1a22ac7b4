"""A tool's CAD file, checked before gmsh imports it in this process: it exists, is a CAD
file by its name, is not too large, and a child process (importing gmsh only, no MPI) stopped
after READ_SECONDS reads it and finds faces in it, at most MAX_CAD_FACES, so that a file that
stalls or crashes OCC's reader does not stall or crash the run, and one of thousands of faces
(500 solids) is refused before its setup takes minutes."""

import sys
from pathlib import Path

from shellform.errors import InputError
from shellform.mesh.gmsh_file import read_in_child

CAD_SUFFIXES = (".step", ".stp", ".STEP", ".STP", ".iges", ".igs", ".IGES", ".IGS", ".brep", ".BREP")
MAX_CAD_BYTES = 200_000_000  # a tool's CAD file larger than this is refused
READ_SECONDS = 60.0  # the longest the child may take to read a tool's file
# a tool's faces: its setup samples every face and edge (cad_model.py), a time that grows faster
# than the count (docs/reliability.md); the demos' tools have 3 to 54
MAX_CAD_FACES = 500
_MARK = "shellform-cad-read: "


def probe(path: Path, field: str) -> dict:
    """Check a tool's CAD file before it is imported here: it exists, is a CAD file by its
    name, is not too large, and a child process stopped after READ_SECONDS reads it and finds
    faces in it. Returns the child's summary (faces, bounding box). InputError naming `field`."""
    if not path.is_file():
        raise InputError(field, f"no such file: {path}")
    if path.suffix not in CAD_SUFFIXES:
        raise InputError(field, f"{path.name} is not a CAD file: a tool's file must end in one of "
                         f"{', '.join(CAD_SUFFIXES)}")
    if path.stat().st_size > MAX_CAD_BYTES:
        raise InputError(field, f"{path} is larger than {MAX_CAD_BYTES:,} bytes")
    result = read_in_child([sys.executable, "-P", "-c", _CHILD, str(path)], path, field, _MARK, READ_SECONDS)
    if result["faces"] == 0:
        raise InputError(field, f"{path} holds no surface (a tool is the faces of a CAD model)")
    if result["faces"] > MAX_CAD_FACES:
        raise InputError(field, f"{path} holds {result['faces']:,} faces; a tool may have at most {MAX_CAD_FACES} "
                                "(setting a tool up samples every face: the time grows faster than their count)")
    return result


# the child of probe: python -P -c _CHILD FILE. It imports gmsh only (not shellform, whose import
# would start MPI in a child of an MPI rank) and prints one line, _MARK and JSON: the file's
# faces and bounding box, or {"error": gmsh's message}.
_CHILD = """
import json, sys
import gmsh
gmsh.initialize(readConfigFiles=False, interruptible=False)
gmsh.option.setNumber("General.Terminal", 0)
gmsh.option.setString("Geometry.OCCTargetUnit", "MM")
gmsh.model.add("shellform_tool")
try:
    gmsh.model.occ.importShapes(sys.argv[1])
    gmsh.model.occ.synchronize()
    faces = gmsh.model.getEntities(2)
    result = {"faces": len(faces), "box": list(gmsh.model.getBoundingBox(-1, -1)) if faces else [0.0] * 6}
except Exception as exc:
    result = {"error": str(exc)}
gmsh.finalize()
print("\\n" + MARK + json.dumps(result), flush=True)
""".replace("MARK", repr(_MARK))
