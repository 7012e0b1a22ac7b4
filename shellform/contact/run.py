"""A deep-drawing scene from its TOML to results on disk: scene -> problem -> driver -> files.

Writes into the output folder (forces and draw-in for the whole blank):
    summary.json             stroke_mm, draw_in_mm (DX, DY, DD) and punch_force_kN at every
                             reported stroke; max_thickness_strain and where; the sheet's
                             volume change (V - V0)/V0 (elastic only, with finite strains); increments,
                             Newton iterations, contact passes; wall_time_s and its split;
                             over_the_stroke: the worst penetration, z-balance, holder share
                             and count of free nodes under the closed holder
    force_stroke.csv, .png   per increment: punch force, holder force, height and largest nodal
                             share, the tools' z-balance, penetration, free nodes under the
                             closed holder, iterations, smallest line-search factor, contacts
    thickness_diagonal.csv   initial distance from the centre along x = y, thickness strain
    thickness_transverse.csv the same along the transverse centre line y = 0
    cup.bp, cup_cells.bp     VTX time series at the reports: displacement and nodal thickness
                             strain; per cell the equivalent plastic strain and the major and
                             minor logarithmic surface strains
    cup.png                  the drawn cup coloured by thickness strain (serial runs)
    last_converged.*         only if the run stops: the last converged state

DX = draw-in of the blank edge at the middle of the side x = L/2 (initial x minus current x),
DY the same on y = L/2, DD along the diagonal at the corner (initial minus current radius).
"""

import time
from pathlib import Path

import numpy as np
from dolfinx import fem, io
from mpi4py import MPI

from shellform import output
from shellform.assembly.sheet_element import BS
from shellform.contact.problem import DrawingProblem
from shellform.nonlinear.driver import ConvergenceFailure
from shellform.scene import Scene
from shellform.studies.common import say, write_csv


# worst values over all increments, in summary.json: the balances and the pinch
CHECKS = ("max_penetration_mm", "force_balance", "holder_largest_share", "free_under_closed_holder")


def _gather(comm, *arrays):
    return [np.concatenate(comm.allgather(a)) for a in arrays]


def draw_in(p: DrawingProblem) -> dict:
    """DX, DY, DD (mm) at the blank's edge midpoints and corner (x, y >= 0 quadrant)."""
    X, x, _ = p.nodal_values()
    X, x = _gather(p.model.mesh.comm, X, x)
    hx, hy = p.scene.geometry.lx / 2, p.scene.geometry.ly / 2

    def at(px, py):
        i = int(np.argmin(np.hypot(X[:, 0] - px, X[:, 1] - py)))
        return x[i]

    corner = at(hx, hy)
    return {"DX": float(hx - at(hx, 0.0)[0]), "DY": float(hy - at(0.0, hy)[1]),
            "DD": float(np.hypot(hx, hy) - np.hypot(corner[0], corner[1]))}


def thickness_lines(p: DrawingProblem) -> tuple[list[dict], list[dict]]:
    """Thickness strain at the nodes along the diagonal and along y = 0, by initial distance."""
    X, _, e33 = p.nodal_values()
    X, e33 = _gather(p.model.mesh.comm, X, e33)
    tol = 1e-6 * p.scene.geometry.lx
    lines = []
    for on in (np.abs(X[:, 0] - X[:, 1]) < tol, np.abs(X[:, 1]) < tol):
        r = np.hypot(X[on, 0], X[on, 1])
        order = np.argsort(r)
        lines.append([{"initial_position_mm": float(r[i]), "thickness_strain": float(e33[on][i])} for i in order])
    return lines[0], lines[1]


def _peak_thinning(p: DrawingProblem) -> dict:
    X, x, e33 = p.nodal_values()
    X, x, e33 = _gather(p.model.mesh.comm, X, x, e33)
    i = int(np.argmin(e33))
    return {"max_thickness_strain": float(e33[i]), "where_initial_xy_mm": X[i].tolist(),
            "where_current_xyz_mm": x[i].tolist(), "max_thickening_strain": float(e33.max())}


class _Series:
    """VTX time series: cup.bp the displacement and the nodal thickness strain, cup_cells.bp the
    cells' equivalent plastic strain and major and minor (logarithmic) surface strains."""

    CELL_FIELDS = ("equivalent_plastic_strain", "major_strain", "minor_strain")

    def __init__(self, p: DrawingProblem, path: Path):
        mesh = p.model.mesh
        self.p = p
        self.disp = fem.Function(fem.functionspace(mesh, ("Lagrange", 1, (3,))), name="displacement")
        self.e33 = fem.Function(fem.functionspace(mesh, ("Lagrange", 1)), name="thickness_strain")
        dg0 = fem.functionspace(mesh, ("DG", 0))
        self.cells = [fem.Function(dg0, name=name) for name in self.CELL_FIELDS]
        self.writers = [io.VTXWriter(mesh.comm, path, [self.disp, self.e33], engine="BP4"),
                        io.VTXWriter(mesh.comm, path.with_name(path.stem + "_cells.bp"), self.cells, engine="BP4")]

    def write(self, stroke):
        d = self.p.driver
        n = d.n_owned
        self.disp.x.array.reshape(-1, 3)[:n] = d.q.x.array.reshape(-1, BS)[:n, :3]
        self.e33.x.array[:n] = self.p.nodal_values()[2]
        fields = self.p.model.cell_fields()
        for f in self.cells:
            f.x.array[: self.p.model.num_cells] = fields[f.name]
        for f in (self.disp, self.e33, *self.cells):
            f.x.scatter_forward()
        for w in self.writers:
            w.write(stroke)

    def close(self):
        for w in self.writers:
            w.close()


def _plot_force(path: Path, rows: list[dict], title: str) -> None:
    if MPI.COMM_WORLD.rank != 0 or not rows:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot([r["stroke_mm"] for r in rows], [r["punch_force_kN"] for r in rows], "-")
    ax.set_xlabel("punch stroke (mm)")
    ax.set_ylabel("punch force (kN)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _png(path: Path, p: DrawingProblem, title: str) -> None:
    """The drawn cup (true scale, a quarter blank mirrored to the whole cup) seen from above at
    an angle, so that the flange, the wall and the bottom show, coloured by the nodal thickness
    strain; serial runs only."""
    mesh = p.model.mesh
    if mesh.comm.size > 1:
        return
    output._offscreen_backend()
    import pyvista
    from dolfinx import plot

    topology, cell_types, x = plot.vtk_mesh(mesh)
    d = p.driver
    grid = pyvista.UnstructuredGrid(topology, cell_types, x + d.q.x.array.reshape(-1, BS)[: x.shape[0], :3])
    e33 = np.zeros(x.shape[0])
    e33[: d.n_owned] = p.nodal_values()[2]
    grid.point_data["thickness strain"] = e33
    if p.symmetry == 4:  # the quarter and its mirror images in x = 0, y = 0 and both
        parts = [grid, grid.reflect((1, 0, 0), point=(0, 0, 0))]
        parts += [g.reflect((0, 1, 0), point=(0, 0, 0)) for g in parts]
        grid = parts[0].merge(parts[1:])
    pl = pyvista.Plotter(off_screen=True, window_size=(1000, 800))
    pl.add_mesh(grid, scalars="thickness strain", show_edges=True, cmap="coolwarm", edge_color="#555555",
                line_width=0.5, scalar_bar_args={"title": "thickness strain"})
    pl.add_text(title, font_size=10)
    L = max(p.scene.geometry.lx, p.scene.geometry.ly)
    pl.camera_position = [(1.1 * L, -1.5 * L, 0.9 * L), (0.0, 0.0, -0.15 * L), (0.0, 0.0, 1.0)]
    pl.screenshot(str(path))
    pl.close()


def run(s: Scene, outdir: Path, comm=MPI.COMM_WORLD, trace=False) -> dict:
    """Draw the scene's cup; trace: log every contact pass, Newton step and iterate."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    p = DrawingProblem.from_scene(s, comm, checkpoint_dir=outdir, trace=trace)
    setup_s = time.perf_counter() - t0
    series = _Series(p, outdir / "cup.bp") if s.output.vtx else None
    curve, reports, stopped = [], [], None

    def on_increment(d):
        h = d.history[-1]
        curve.append({"increment": h.number, "stroke_mm": p.stroke, "punch_force_kN": p.punch_force() / 1e3,
                      "holder_force_kN": p.holder_force() / 1e3, "holder_height_mm": p.holder_height(),
                      "max_penetration_mm": p.max_penetration(), "force_balance": p.force_balance(),
                      "holder_largest_share": p.holder_share(), "free_under_closed_holder": p.free_under_holder(),
                      "iterations": h.iterations, "min_line_search": h.contact["min_line_search"],
                      "contact_passes": h.contact["passes"], **{f"nodes_on_{k}": v for k, v in p.in_contact().items()}})

    def report():
        reports.append({"stroke_mm": p.stroke, "draw_in_mm": draw_in(p), "punch_force_kN": p.punch_force() / 1e3,
                        **_peak_thinning(p), "volume_change": p.model.volume_change()})
        if series is not None:
            series.write(p.stroke)

    try:
        for target in sorted(set(s.process.report) | {1.0}):
            p.driver.run(target, on_increment=on_increment)
            report()
    except ConvergenceFailure as err:
        stopped = str(err)
        say(f"shellform: stopped: {err}")
        report()
    if series is not None:
        series.close()
    d = p.driver
    diagonal, transverse = thickness_lines(p)
    write_csv(outdir / "thickness_diagonal.csv", diagonal, ["initial_position_mm", "thickness_strain"])
    write_csv(outdir / "thickness_transverse.csv", transverse, ["initial_position_mm", "thickness_strain"])
    write_csv(outdir / "force_stroke.csv", curve, list(curve[0]) if curve else ["increment"])
    _plot_force(outdir / "force_stroke.png", curve, s.title)
    if s.output.png:
        _png(outdir / "cup.png", p, f"{s.title}: stroke {p.stroke:.1f} mm")
    summary = {
        "title": s.title, "effects": list(s.effects), "ranks": comm.size,
        "cells": p.model.mesh.topology.index_map(2).size_global, "stroke_mm": p.stroke,
        "draw_in_mm": [{"stroke_mm": r["stroke_mm"], **r["draw_in_mm"]} for r in reports],
        "punch_force_kN": [{"stroke_mm": r["stroke_mm"], "force": r["punch_force_kN"]} for r in reports],
        **{k: v for k, v in reports[-1].items() if k not in ("stroke_mm", "draw_in_mm", "punch_force_kN")},
        "reports": reports,
        "increments": len(d.history), "newton_iterations": sum(h.iterations for h in d.history),
        "contact_passes": sum(h.contact["passes"] for h in d.history),
        "cutbacks": sum(h.cutbacks for h in d.history), "stopped": stopped,
        "wall_time_s": {"total": time.perf_counter() - t0, "setup": setup_s, **d.times},
        "over_the_stroke": {k: max((row[k] for row in curve), default=0.0) for k in CHECKS},
    }
    output.write_json(outdir / "summary.json", summary)
    return summary
