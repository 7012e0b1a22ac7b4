"""Time series that a stock ParaView and ``pyvista.read`` open: one VTU file per step (VTK's XML
UnstructuredGrid, its arrays inline as base64 binary) and a PVD index listing the steps with
their times.

    <name>.pvd                 the index: <DataSet timestep="t" file="vtu/<name>_0003.vtu"/>
    vtu/<name>_0003.vtu        the step's points, triangles, point data and cell data

The writer is numpy only (no VTK needed to write); it runs on one process: the caller gathers
the mesh (shellform.results.cup gathers the sheet to rank 0). A series whose index exists
already (a resumed run) keeps the steps before the first time it writes. Each file is written
whole (tables.write_atomically), never through a link.
"""

import base64
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from shellform.results.tables import write_atomically

VTK_TRIANGLE = 5
_TYPES = {np.dtype(np.float64): "Float64", np.dtype(np.float32): "Float32", np.dtype(np.int64): "Int64",
          np.dtype(np.int32): "Int32", np.dtype(np.uint8): "UInt8", np.dtype(np.int8): "Int8"}


def _array(name: str, values) -> str:
    """A DataArray element: format "binary" is base64 of a UInt64 byte count and the raw
    little-endian values."""
    a = np.ascontiguousarray(values)
    if a.dtype not in _TYPES:
        a = a.astype(np.float64)
    a = a.astype(a.dtype.newbyteorder("<"), copy=False)
    components = 1 if a.ndim == 1 else a.shape[1]
    raw = a.tobytes()
    data = base64.b64encode(np.uint64(len(raw)).tobytes() + raw).decode("ascii")
    return (f'<DataArray type="{_TYPES[a.dtype.newbyteorder("=")]}" Name="{name}" '
            f'NumberOfComponents="{components}" format="binary">{data}</DataArray>')


def write_vtu(path: Path, points, triangles, point_data: dict | None = None, cell_data: dict | None = None) -> None:
    """One VTU file: points (n, 3), triangles (m, 3) of point indices, and named arrays per
    point (n,) or (n, k) and per cell (m,) or (m, k)."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    n, m = len(points), len(triangles)
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">',
             "<UnstructuredGrid>", f'<Piece NumberOfPoints="{n}" NumberOfCells="{m}">', "<PointData>"]
    for name, v in (point_data or {}).items():
        lines.append(_array(name, v))
    lines += ["</PointData>", "<CellData>"]
    for name, v in (cell_data or {}).items():
        lines.append(_array(name, v))
    lines += ["</CellData>", "<Points>", _array("Points", points), "</Points>", "<Cells>",
              _array("connectivity", triangles.ravel()), _array("offsets", 3 * np.arange(1, m + 1, dtype=np.int64)),
              _array("types", np.full(m, VTK_TRIANGLE, dtype=np.uint8)), "</Cells>",
              "</Piece>", "</UnstructuredGrid>", "</VTKFile>", ""]
    text = "\n".join(lines)
    write_atomically(Path(path), lambda f: f.write(text))


class PVDSeries:
    """A named series in `folder`: write(time, ...) adds the step's VTU file and rewrites the
    PVD index."""

    def __init__(self, folder: Path, name: str):
        self.folder, self.name = Path(folder), name
        self.index = self.folder / f"{name}.pvd"
        self.steps: list[tuple[float, str]] = []
        if self.index.exists():  # a resumed run: its earlier steps
            try:
                root = ET.parse(self.index).getroot()
                self.steps = [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]
            except (ET.ParseError, TypeError, ValueError):
                self.steps = []

    def write(self, time: float, points, triangles, point_data=None, cell_data=None) -> Path:
        self.steps = [(t, f) for t, f in self.steps if t < time - 1e-12]
        used = {f for _, f in self.steps}
        k = len(self.steps)
        while f"vtu/{self.name}_{k:04d}.vtu" in used:
            k += 1
        rel = f"vtu/{self.name}_{k:04d}.vtu"
        (self.folder / "vtu").mkdir(parents=True, exist_ok=True)
        write_vtu(self.folder / rel, points, triangles, point_data, cell_data)
        self.steps.append((float(time), rel))
        rows = "\n".join(f'    <DataSet timestep="{t!r}" group="" part="0" file="{f}"/>' for t, f in self.steps)
        text = ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
                f"{rows}\n  </Collection>\n</VTKFile>\n")
        write_atomically(self.index, lambda f: f.write(text))
        return self.folder / rel


_DTYPES = {name: np.dtype(dt).newbyteorder("<") for dt, name in _TYPES.items()}


def read_vtu(path: Path) -> tuple[np.ndarray, np.ndarray, dict, dict]:
    """The inverse of write_vtu for the files it writes (base64 binary arrays with a UInt64
    header, triangles only): (points (n, 3), triangles (m, 3), point_data, cell_data)."""

    def values(el):
        raw = base64.b64decode(el.text.strip())
        size = int(np.frombuffer(raw[:8], dtype="<u8")[0])
        a = np.frombuffer(raw[8:8 + size], dtype=_DTYPES[el.get("type")]).astype(_DTYPES[el.get("type")].newbyteorder("="))
        k = int(el.get("NumberOfComponents", "1"))
        return a.reshape(-1, k) if k > 1 else a

    piece = ET.parse(path).getroot().find("UnstructuredGrid/Piece")
    points = values(piece.find("Points/DataArray")).reshape(-1, 3)
    cells = {el.get("Name"): values(el) for el in piece.find("Cells")}
    triangles = cells["connectivity"].reshape(-1, 3)
    point_data = {el.get("Name"): values(el) for el in piece.find("PointData")}
    cell_data = {el.get("Name"): values(el) for el in piece.find("CellData")}
    return points, triangles, point_data, cell_data


def last_step(index: Path) -> tuple[float, Path]:
    """The time and the VTU file of a PVD index's last step."""
    root = ET.parse(index).getroot()
    steps = [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]
    time, rel = max(steps, key=lambda s: s[0])
    return time, Path(index).parent / rel
