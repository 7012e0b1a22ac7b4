"""Fields on disk: VTX (ADIOS2) for ParaView, a PVD series that a stock ParaView and pyvista
open, and a PNG of the deformed shape.

The carrier holds physical nodal values, so output reads it directly: DOLFINx's interpolation
and plotting know nothing of the slope map and are not used for the element's fields. The PVD
series (results/vtu.py) is written by rank 0, which gathers the sheet with its nodes and cells
in the mesh's input order (input_order, gather_in_input_order), so that the files do not depend
on the number of ranks.
"""

import os
from pathlib import Path

import numpy as np
from dolfinx import fem, io, plot

from shellform.results.tables import write_screenshot


def nodal_fields(q, components) -> list[fem.Function]:
    """The carrier split into named P1 functions: displacement (u, v, w) and slopes (w_x, w_y)."""
    mesh = q.function_space.mesh
    values = q.x.array.reshape(-1, len(components))
    V3 = fem.functionspace(mesh, ("Lagrange", 1, (3,)))
    disp = fem.Function(V3, name="displacement")
    d = disp.x.array.reshape(-1, 3)
    for k, name in enumerate(("u", "v", "w")):
        if name in components:
            d[:, k] = values[:, components.index(name)]
    out = [disp]
    if "w_x" in components:
        V2 = fem.functionspace(mesh, ("Lagrange", 1, (2,)))
        slopes = fem.Function(V2, name="slopes")
        i = components.index("w_x")
        slopes.x.array.reshape(-1, 2)[:] = values[:, i : i + 2]
        out.append(slopes)
    return out


def write_vtx(outdir: Path, q, components, cell_fields: dict) -> list[Path]:
    """nodal.bp (displacement, slopes) and cells.bp (strains, curvatures, resultants)."""
    outdir = Path(outdir)
    comm = q.function_space.mesh.comm
    paths = [outdir / "nodal.bp", outdir / "cells.bp"]
    for path, funcs in zip(paths, (nodal_fields(q, components), list(cell_fields.values()))):
        if funcs:
            with io.VTXWriter(comm, path, funcs, engine="BP4") as vtx:
                vtx.write(0.0)
    return paths


def input_order(V, num_cells: int):
    """Per owned node of the carrier space V its index in the mesh's input (the same on any
    number of ranks), per owned cell its input index, and each owned cell's nodes by that index."""
    mesh = V.mesh
    imap = V.dofmap.index_map
    dofs = V.dofmap.list
    node = np.full(imap.size_local + imap.num_ghosts, -1, dtype=np.int64)
    node[dofs.ravel()] = mesh.geometry.input_global_indices[mesh.geometry.dofmaps[0].ravel()]
    cells = np.asarray(mesh.topology.original_cell_index[:num_cells], dtype=np.int64)
    return node[: imap.size_local], cells, node[dofs[:num_cells]]


def node_positions(V) -> np.ndarray:
    """The initial position of every node of the carrier space V (owned, then ghosts)."""
    mesh = V.mesh
    imap = V.dofmap.index_map
    x = np.zeros((imap.size_local + imap.num_ghosts, 3))
    x[V.dofmap.list.ravel()] = mesh.geometry.x[mesh.geometry.dofmaps[0].ravel()]
    return x


def gather_in_input_order(comm, order, x, point_values: dict, cell_values: dict):
    """On rank 0, the whole sheet in the mesh's input order: (points, triangles, point_values,
    cell_values); None on the other ranks. order: input_order(...); x and point_values per owned
    node, cell_values per owned cell."""
    nodes, cells, triangles = order
    parts = comm.gather((nodes, x, point_values, cells, triangles, cell_values), root=0)
    if comm.rank != 0:
        return None
    node_ids = np.concatenate([q[0] for q in parts])
    by_node = np.argsort(node_ids)
    by_cell = np.argsort(np.concatenate([q[3] for q in parts]))

    def joined(i, key=None):
        values = [q[i] if key is None else q[i][key] for q in parts]
        return np.concatenate(values)[by_node if i < 3 else by_cell]

    connectivity = np.searchsorted(node_ids[by_node], joined(4))
    return (joined(1), connectivity, {k: joined(2, k) for k in point_values},
            {k: joined(5, k) for k in cell_values})


class SheetSeries:
    """<name>.pvd: a sheet or shell scene's states as a series (results/vtu.py), one step per
    call of write: the modelled region (a quarter or a half is not mirrored) on its deformed
    mid-surface, with the point fields displacement (and slopes where the carrier has w_x, w_y)
    and the cell fields given."""

    def __init__(self, V, num_cells: int, outdir: Path, name: str = "sheet"):
        from shellform.results.vtu import PVDSeries

        self.V, self.num_cells = V, num_cells
        self.comm = V.mesh.comm
        self.order = input_order(V, num_cells)
        n = V.dofmap.index_map.size_local
        self.X = node_positions(V)[:n]
        self.series = PVDSeries(outdir, name) if self.comm.rank == 0 else None

    def write(self, time: float, q, components, cell_values: dict) -> None:
        """The state q (a carrier with these components) at `time`; cell_values: per owned
        cell an array (cells,) or (cells, k), or a DG0 Function."""
        n = len(self.X)
        values = q.x.array.reshape(-1, len(components))[:n]
        disp = np.zeros((n, 3))
        for k, name in enumerate(("u", "v", "w")):
            if name in components:
                disp[:, k] = values[:, components.index(name)]
        points = {"displacement": disp}
        if "w_x" in components:
            i = components.index("w_x")
            points["slopes"] = values[:, i : i + 2]
        cells = {}
        for name, v in cell_values.items():
            if isinstance(v, fem.Function):
                bs = v.function_space.dofmap.index_map_bs
                v = v.x.array.reshape(-1, bs)[: self.num_cells]
                v = v[:, 0] if bs == 1 else v
            cells[name] = np.asarray(v)[: self.num_cells]
        whole = gather_in_input_order(self.comm, self.order, self.X + disp, points, cells)
        if whole is not None:
            self.series.write(time, *whole)


def offscreen_backend() -> None:
    """Render without a display: OSMesa where installed, else EGL, else VTK's own fallback."""
    import ctypes.util

    if "VTK_DEFAULT_OPENGL_WINDOW" in os.environ:
        return
    if ctypes.util.find_library("OSMesa"):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkOSOpenGLRenderWindow"
    elif ctypes.util.find_library("EGL"):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"


def write_png(path: Path, q, components, title: str = "", scale: float | None = None) -> Path | None:
    """The deformed mid-surface coloured by w (rank 0 gathers nothing: serial runs only)."""
    if q.function_space.mesh.comm.size > 1:
        return None
    offscreen_backend()
    import pyvista

    mesh = q.function_space.mesh
    topology, cell_types, x = plot.vtk_mesh(mesh)
    grid = pyvista.UnstructuredGrid(topology, cell_types, x)
    values = q.x.array.reshape(-1, len(components))
    nv = x.shape[0]
    w = values[:nv, components.index("w")] if "w" in components else np.zeros(nv)
    disp = np.zeros((nv, 3))
    for k, name in enumerate(("u", "v", "w")):
        if name in components:
            disp[:, k] = values[:nv, components.index(name)]
    size = np.ptp(x[:, :2], axis=0).max()
    peak = np.abs(disp).max()
    if scale is None:
        scale = 0.2 * size / peak if peak > 0 else 1.0
    grid.point_data["w"] = w
    warped = grid.copy()
    warped.points = x + scale * disp
    pl = pyvista.Plotter(off_screen=True, window_size=(900, 700))
    pl.add_mesh(warped, scalars="w", show_edges=True, cmap="viridis", scalar_bar_args={"title": "w"})
    pl.add_text(f"{title}  (displacement x {scale:.3g})", font_size=10)
    pl.view_isometric()
    write_screenshot(path, pl)
    pl.close()
    return Path(path)
