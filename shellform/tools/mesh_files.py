"""A tool's surface mesh read from its file: an STL file, or a gmsh .msh file's triangles.

Reading a file: STL (binary, or ASCII), or a gmsh .msh in its ASCII format (2.2 or 4.1: its
3-node triangles; the corners of 6-node ones), parsed here without gmsh, so no script (a FILE.opt
beside it) runs. At most MAX_MESH_BYTES. Vertices nearer than MERGE_TOLERANCE of the model's
size are one; triangles that collapse are dropped. Refused (InputError naming the field): a
missing file, another kind, a file with no triangles, an edge shared by more than two triangles
(non-manifold), two triangles whose orders disagree across their edge (inconsistent
orientation). An open surface is taken as it is (beside its boundary the distance is to the
boundary curve). Lengths are in the file's units, mm.
"""

import re
from pathlib import Path

import numpy as np

from shellform.errors import InputError

MESH_SUFFIXES = (".stl", ".msh")  # any case
MAX_MESH_BYTES = 200_000_000  # a tool's mesh file larger than this is refused
MERGE_TOLERANCE = 1e-8  # vertices nearer than this times the model's size are one


def read_surface_mesh(path, field: str = "tools.file"):
    """The vertices (V, 3) and triangles (T, 3) of an STL or ASCII gmsh .msh file, vertices
    merged, collapsed triangles dropped (module docstring). InputError naming `field`."""
    path = Path(path)
    if not path.is_file():
        raise InputError(field, f"no such file: {path}")
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise InputError(field, f"{path.name} is not a surface mesh: a tool's mesh file must end in .stl or .msh")
    size = path.stat().st_size
    if size > MAX_MESH_BYTES:
        raise InputError(field, f"{path} is larger than {MAX_MESH_BYTES:,} bytes")
    data = path.read_bytes()
    corners = _stl(data, path, field) if suffix == ".stl" else _msh(data, path, field)
    if len(corners) == 0:
        raise InputError(field, f"{path} holds no triangles")
    if not np.all(np.isfinite(corners)):
        raise InputError(field, f"{path} holds a vertex that is not a finite number")
    vertices, triangles = merge_vertices(corners.reshape(-1, 3))
    triangles = triangles.reshape(-1, 3)
    e1 = vertices[triangles[:, 1]] - vertices[triangles[:, 0]]
    e2 = vertices[triangles[:, 2]] - vertices[triangles[:, 0]]
    scale = float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))
    area = np.linalg.norm(np.cross(e1, e2), axis=1)
    keep = (triangles[:, 0] != triangles[:, 1]) & (triangles[:, 1] != triangles[:, 2]) \
        & (triangles[:, 0] != triangles[:, 2]) & (area > 1e-14 * scale ** 2)
    triangles = triangles[keep]
    if len(triangles) == 0:
        raise InputError(field, f"{path} holds no triangles of nonzero area")
    _check_topology(vertices, triangles, path, field)
    return vertices, triangles


def _stl(data: bytes, path, field):
    """The corners (T, 3, 3) of a binary or ASCII STL file."""
    if len(data) >= 84:
        count = int(np.frombuffer(data, dtype="<u4", count=1, offset=80)[0])
        if len(data) == 84 + 50 * count:  # binary: 80-byte header, count, 50 bytes a facet
            rows = np.frombuffer(data, dtype=np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)),
                                                        ("attribute", "<u2")]), count=count, offset=84)
            return rows["corners"].astype(float)
    if not data.lstrip()[:5].lower() == b"solid":
        raise InputError(field, f"{path} is neither a binary STL (its size does not match its facet count) nor an "
                         "ASCII one (it does not begin with 'solid')")
    text = data.decode("ascii", errors="replace")
    found = re.findall(r"\bvertex\s+(\S+)\s+(\S+)\s+(\S+)", text)
    try:
        corners = np.array(found, dtype=float).reshape(-1, 3)
    except ValueError:
        raise InputError(field, f"{path}: a vertex of its facets is not three numbers") from None
    if len(corners) % 3:
        raise InputError(field, f"{path}: its facets hold {len(corners)} vertices, not three each")
    return corners.reshape(-1, 3, 3)


def _msh(data: bytes, path, field):
    """The triangles' corners (T, 3, 3) of an ASCII gmsh .msh file, format 2.2 or 4.1."""
    text = data.decode("ascii", errors="replace")

    def section(name):
        m = re.search(rf"^\${name}\s*$(.*?)^\$End{name}\s*$", text, re.M | re.S)
        if m is None:
            raise InputError(field, f"{path} has no ${name} section: not a gmsh mesh")
        return m.group(1).split()

    head = section("MeshFormat")
    if len(head) < 3 or head[1] != "0":
        raise InputError(field, f"{path} is not an ASCII gmsh mesh (write it with Mesh.Binary = 0)")
    version = head[0]
    try:
        if version.startswith("2"):
            nodes, elements = section("Nodes"), section("Elements")
            count = int(nodes[0])
            table = np.array(nodes[1:1 + 4 * count], dtype=float).reshape(count, 4)
            tags, xyz = table[:, 0].astype(np.int64), table[:, 1:]
            triangles, i = [], 1
            for _ in range(int(elements[0])):
                kind, ntags = int(elements[i + 1]), int(elements[i + 2])
                width = {2: 3, 9: 6}.get(kind, _MSH_NODES.get(kind, -1))
                if width < 0:
                    raise InputError(field, f"{path}: element type {kind} is not read (triangles, lines, points)")
                start = i + 3 + ntags
                if kind in (2, 9):
                    triangles.append([int(t) for t in elements[start:start + 3]])
                i = start + width
        elif version.startswith("4"):
            nodes, elements = section("Nodes"), section("Elements")
            blocks, i = int(nodes[0]), 4
            tag_list, xyz_list = [], []
            for _ in range(blocks):
                dim, parametric, count = int(nodes[i]), int(nodes[i + 2]), int(nodes[i + 3])
                i += 4
                tag_list.append(np.array(nodes[i:i + count], dtype=np.int64))
                i += count
                width = 3 + (dim if parametric else 0)
                xyz_list.append(np.array(nodes[i:i + width * count], dtype=float).reshape(count, width)[:, :3])
                i += width * count
            tags = np.concatenate(tag_list) if tag_list else np.zeros(0, dtype=np.int64)
            xyz = np.vstack(xyz_list) if xyz_list else np.zeros((0, 3))
            blocks, i = int(elements[0]), 4
            triangles = []
            for _ in range(blocks):
                kind, count = int(elements[i + 2]), int(elements[i + 3])
                i += 4
                width = {2: 3, 9: 6}.get(kind, _MSH_NODES.get(kind, -1))
                if width < 0:
                    raise InputError(field, f"{path}: element type {kind} is not read (triangles, lines, points)")
                rows = np.array(elements[i:i + (width + 1) * count], dtype=np.int64).reshape(count, width + 1)
                i += (width + 1) * count
                if kind in (2, 9):
                    triangles.extend(rows[:, 1:4].tolist())
        else:
            raise InputError(field, f"{path}: gmsh mesh format {version} is not read (2.2 or 4.1)")
    except (ValueError, IndexError):
        raise InputError(field, f"{path}: its $Nodes or $Elements section is not as gmsh writes it") from None
    triangles = np.array(triangles, dtype=np.int64).reshape(-1, 3)
    if len(triangles) == 0:
        return np.zeros((0, 3, 3))
    order = np.argsort(tags)
    at = np.searchsorted(tags[order], triangles)
    at = np.minimum(at, len(tags) - 1)
    if not np.all(tags[order][at] == triangles):
        raise InputError(field, f"{path}: a triangle names a node that is not in $Nodes")
    return xyz[order][at]


_MSH_NODES = {1: 2, 15: 1, 8: 3}  # the other element kinds skipped: lines, points, 3-node lines


def merge_vertices(points, tolerance: float = MERGE_TOLERANCE):
    """Points (N, 3) as unique vertices (V, 3) and each point's vertex (N): points nearer than
    `tolerance` times the points' bounding-box diagonal are one vertex (the first of them)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    points = np.asarray(points, dtype=float)
    scale = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))) or 1.0
    pairs = cKDTree(points).query_pairs(tolerance * scale, output_type="ndarray")
    n = len(points)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    first = np.full(label.max() + 1, n)
    np.minimum.at(first, label, np.arange(n))
    return points[first], label


def _edges(triangles):
    """The triangles' edges (T, 3, 2) in the patch's order (0-1, 1-2, 0-2), the unique edges'
    sorted vertex pairs (E, 2), each triangle edge's unique edge (T, 3) and how many triangles
    share each unique edge (E)."""
    local = np.array([[0, 1], [1, 2], [0, 2]])
    directed = triangles[:, local]  # (T, 3, 2)
    key = np.sort(directed, axis=2).reshape(-1, 2)
    unique, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return directed, unique, inverse.reshape(-1, 3), counts


def _check_topology(vertices, triangles, path, field):
    """Non-manifold edges and inconsistent orientation refused (InputError naming `field`)."""
    directed, unique, inverse, counts = _edges(triangles)
    if counts.max() > 2:
        e = unique[np.argmax(counts)]
        raise InputError(field, f"{path}: the edge between vertices at {np.round(vertices[e[0]], 6).tolist()} and "
                         f"{np.round(vertices[e[1]], 6).tolist()} is shared by {counts.max()} triangles "
                         "(a non-manifold surface)")
    # the triangles' own order of their edges: 0->1, 1->2, 2->0
    ring = triangles[:, [[0, 1], [1, 2], [2, 0]]].reshape(-1, 2)
    _, repeated = np.unique(ring, axis=0, return_counts=True)
    if repeated.max() > 1:
        raise InputError(field, f"{path}: two triangles run along a shared edge the same way (their vertices' "
                         "orders, which give their normals, disagree: the surface's orientation is inconsistent)")

