"""gmsh reads one blank file, in a child process of shellform.mesh.gmsh_file.read_file (which
checked the file first and stops this process after its time limit).

    python -P gmsh_reader.py FILE OPTIONS_JSON

prints one line, the marker and JSON: the file's named physical curves as boundary groups
(one group, boundary, where it has none), the triangles of its mesh (0: none yet) and the width
and height of its bounding box; or {"error": gmsh's message}, or {"empty": true} for a file that
holds no geometry and no mesh. Imports gmsh only, so that the
child starts in a fraction of a second.
"""

import json
import sys

MARK = "shellform-gmsh-read: "
TRIANGLE = 2  # gmsh's element type of the 3-node triangle


def summary(path: str, options: dict) -> dict:
    import gmsh

    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        for key, value in options.items():
            gmsh.option.setNumber(key, value)
        gmsh.model.add("shellform_blank")
        try:
            gmsh.open(path)
        except Exception as exc:  # noqa: BLE001  (gmsh raises plain Exceptions)
            return {"error": str(exc)}
        if not gmsh.model.getEntities():
            return {"empty": True}
        groups = [gmsh.model.getPhysicalName(1, tag) or f"group{tag}" for _, tag in gmsh.model.getPhysicalGroups(1)]
        types, tags = gmsh.model.mesh.getElements(2)[:2]
        triangles = sum(len(t) for kind, t in zip(types, tags) if kind == TRIANGLE)
        x0, y0, _, x1, y1, _ = gmsh.model.getBoundingBox(-1, -1)
        return {"groups": groups or ["boundary"], "triangles": int(triangles), "size": [x1 - x0, y1 - y0]}
    finally:
        gmsh.finalize()


if __name__ == "__main__":
    result = summary(sys.argv[1], json.loads(sys.argv[2]))
    print("\n" + MARK + json.dumps(result), flush=True)
