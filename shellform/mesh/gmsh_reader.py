"""gmsh reads one blank file, in a child process of shellform.mesh.gmsh_file.read_file (which
checked the file first and stops this process after its time limit).

    python -P gmsh_reader.py FILE OPTIONS_JSON

prints one line, the marker and JSON: the file's named physical curves as boundary groups
(one group, boundary, where it has none), the triangles of its mesh (0: none yet), the width
and height of its bounding box, and for a geometry without a mesh the median length of the
segments gmsh makes of its curves at the file's own sizes (its points', its fields', its Mesh
options'), no shorter than FLOOR times the box's diagonal, so that a file whose sizes would make
a mesh too large for the machine is known before it is meshed; or {"error": gmsh's message}, or
{"empty": true} for a file that holds no geometry and no mesh. Imports gmsh and numpy only, so
that the child starts in a fraction of a second.
"""

import json
import sys

MARK = "shellform-gmsh-read: "
TRIANGLE = 2  # gmsh's element type of the 3-node triangle
FLOOR = 1e-5  # the shortest segment measured, of the box's diagonal: at most about 1e5 per curve


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
        found = {"groups": groups or ["boundary"], "triangles": int(triangles), "size": [x1 - x0, y1 - y0]}
        if not triangles:
            found["segment"] = _segment(gmsh, FLOOR * ((x1 - x0) ** 2 + (y1 - y0) ** 2) ** 0.5)
        return found
    finally:
        gmsh.finalize()


def _segment(gmsh, floor: float) -> float | None:
    """The median length of the segments of the curves' mesh at the file's own sizes, no
    shorter than floor (None: no curve)."""
    import numpy as np

    gmsh.option.setNumber("Mesh.MeshSizeMin", max(gmsh.option.getNumber("Mesh.MeshSizeMin"), floor))
    gmsh.model.mesh.generate(1)
    tags, x, _ = gmsh.model.mesh.getNodes()
    types, _, nodes = gmsh.model.mesh.getElements(1)
    if not len(types) or not tags.size:
        return None
    where = np.zeros(int(tags.max()) + 1, dtype=np.int64)
    where[tags.astype(np.int64)] = np.arange(tags.size)
    x = x.reshape(-1, 3)
    ends = np.concatenate([n.reshape(-1, gmsh.model.mesh.getElementProperties(t)[3])[:, :2]
                           for t, n in zip(types, nodes)]).astype(np.int64)
    return float(np.median(np.linalg.norm(x[where[ends[:, 1]]] - x[where[ends[:, 0]]], axis=1)))


if __name__ == "__main__":
    result = summary(sys.argv[1], json.loads(sys.argv[2]))
    print("\n" + MARK + json.dumps(result), flush=True)
