"""The linear shell's results (shellform.linear.solve): summary.json, the fields, the picture.

Writes into the output folder:
    summary.json       title, effects, cells, dofs, ranks; w_center (w at the origin, null where
                       the blank has no vertex there); extremes: per displacement component
                       (u, v, w) the vertex value largest in magnitude over all ranks and its
                       (x, y); wall_time_s and the solve's time split (compile, assembly, solve)
    nodal.bp, cells.bp the solution for ParaView ([output] vtx)
    sheet.pvd, vtu/    ([output] vtu) the solution as a one-step series a stock ParaView and pyvista
                       open: the deformed mid-surface, displacement and slopes per node, the
                       strains and resultants per cell (results/fields.py SheetSeries)
    deformed.png       the deformed blank ([output] png, where w is a component)
"""

from pathlib import Path

from shellform.errors import InputError
from shellform.results import fields
from shellform.results.summary import ShellSummary
from shellform.results.tables import write_json


def extremes(res) -> dict:
    """Per displacement component (u, v, w) the vertex value largest in magnitude, over all
    ranks, and where it is."""
    V = res.q.function_space
    comm = V.mesh.comm
    owned = V.dofmap.index_map.size_local
    values = res.q.x.array.reshape(-1, len(res.components))[:owned]
    xy = V.tabulate_dof_coordinates()[:owned, :2]
    out = {}
    for name in ("u", "v", "w"):
        if name not in res.components:
            continue
        a = values[:, res.components.index(name)]
        k = int(abs(a).argmax()) if owned else -1
        mine = (abs(float(a[k])), float(a[k]), xy[k].tolist()) if owned else (-1.0, 0.0, [0.0, 0.0])
        _, value, at = max(comm.allgather(mine))
        out[name] = {"value": value, "at": at}
    return out


def centre_w(res):
    """w at the origin, or None where the blank has no vertex there (or no w)."""
    if "w" not in res.components:
        return None
    try:
        return res.value("w")
    except InputError:
        return None


def write(outdir: Path, s, res, wall_time_s: float) -> ShellSummary:
    """The result `res` of the scene `s` into outdir; its summary."""
    summary = ShellSummary({
        "title": s.title, "effects": list(s.effects), "cells": res.num_cells, "dofs": res.num_dofs,
        "ranks": res.q.function_space.mesh.comm.size, "w_center": centre_w(res), "extremes": extremes(res),
        "wall_time_s": wall_time_s, **res.timings,
    }, outdir)
    if s.output.vtx or s.output.vtu:
        cells = res.cell_fields()
        if s.output.vtx:
            fields.write_vtx(outdir, res.q, res.components, cells)
        if s.output.vtu:
            V = res.q.function_space
            fields.SheetSeries(V, V.mesh.topology.index_map(2).size_local, outdir).write(
                1.0, res.q, res.components, cells)
    if s.output.png and "w" in res.components:
        fields.write_png(outdir / "deformed.png", res.q, res.components, title=s.title)
    write_json(outdir / "summary.json", summary)
    return summary
