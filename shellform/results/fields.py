"""Fields on disk: VTX (ADIOS2) for ParaView and a PNG of the deformed shape.

The carrier holds physical nodal values, so output reads it directly: DOLFINx's interpolation
and plotting know nothing of the slope map and are not used for the element's fields.
"""

import os
from pathlib import Path

import numpy as np
from dolfinx import fem, io, plot


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
    pl.screenshot(str(path))
    pl.close()
    return Path(path)
