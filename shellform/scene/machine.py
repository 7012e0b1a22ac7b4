"""The checks of a scene that depend on the machine it is read on: its blank's file exists
(``check_file``) and its mesh fits this machine's memory (``check_size``, by the estimates of
shellform/mesh/budget.py). They raise shellform.errors.InputError naming the field.
"""

from pathlib import Path

from shellform.errors import InputError
from shellform.mesh import outline


def require(cond, name, message):
    """Raise InputError(name, message) unless cond."""
    if not cond:
        raise InputError(name, message)


def check_file(s) -> None:
    """A file blank's file exists (its name and suffix are checked with the geometry)."""
    require(Path(s.geometry.file).is_file(), "geometry.file", f"no such file: {s.geometry.file}")


def check_tool_files(s) -> None:
    """What a run checks in the tools' files before computing (shellform.tools.cad.check_files:
    a CAD file read by a child process, a surface mesh read whole), for `shellform check`; run
    makes the same checks as it reads them. Not part of every scene's reading (a child process per file)."""
    if s.tools is not None and s.tools.shape == "cad":
        from shellform.tools import cad

        cad.check_files(s.tools)


def estimate(s) -> dict:
    """What the scene's mesh will cost on this machine, before it is built (the estimates of
    shellform/mesh/budget.py): {"cells", "layers" (points through a plastic section's
    thickness, 0 if elastic), "bytes" (peak memory, one rank), "available_bytes"}."""
    from shellform.mesh import budget

    g, m = s.geometry, s.mesh
    if g.shape == "file":
        cells = outline.file_cells(g, m.n, m.refine)
    elif g.shape == "rectangle":
        cells = budget.estimated_cells(g.lx, g.ly, g.region, m.kind, m.n, m.refine)
    else:
        x0, x1, _, _ = outline.region_bounds(g)
        cells = budget.gmsh_cells(outline.region_area(g), (x1 - x0) / m.n, m.refine)
    nonlinear = s.nonlinear or s.tools is not None
    layers = s.process.thickness_points if "plasticity" in s.effects else 0  # a plastic section's points
    return {"cells": cells, "layers": layers, "nonlinear": nonlinear,
            "bytes": budget.estimated_bytes(cells, nonlinear, layers=layers),
            "available_bytes": budget.available_bytes()}


def check_size(s) -> None:
    """A mesh whose estimated memory exceeds what the machine allows is refused before it is built."""
    from shellform.mesh import budget
    from shellform.scene.schema import Process

    e = estimate(s)
    cells, layers, need, have = e["cells"], e["layers"], e["bytes"], e["available_bytes"]
    m = s.mesh
    usual = min(layers, Process().thickness_points)
    require(need <= have or budget.estimated_bytes(cells, e["nonlinear"], layers=usual) > have,
            "process.thickness_points",
            f"{layers:,} points through the thickness on {cells:,} cells need about {need / 1e9:.3g} GB; "
            f"this machine allows {have / 1e9:.3g} GB (shellform/mesh/budget.py)")
    own = outline.file_own_size(s.geometry, m.n) if need > have and s.geometry.shape == "file" else None
    unrefined = outline.file_cells(s.geometry, m.n, 0) if own is not None else 0
    if own is not None and budget.estimated_bytes(unrefined, e["nonlinear"], layers=layers) > have:  # not mesh.refine's
        raise InputError("geometry.file", f"its own mesh sizes (gmsh meshes its curves at a median {own:.3g} mm) "
                         f"make about {unrefined:,} cells, which need about "
                         f"{budget.estimated_bytes(unrefined, e['nonlinear'], layers=layers) / 1e9:.3g} GB; "
                         f"this machine allows {have / 1e9:.3g} GB (shellform/mesh/budget.py)")
    require(need <= have, "mesh.n", f"n = {m.n} (refine {m.refine}) makes about {cells:,} cells, which need about "
            f"{need / 1e9:.3g} GB; this machine allows {have / 1e9:.3g} GB (shellform/mesh/budget.py)")
