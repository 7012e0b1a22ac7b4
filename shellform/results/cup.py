"""The drawn cup's results: draw-in, thickness lines, peak thinning, the VTX and VTU series, the
force-stroke plot and the picture of the cup (results/drawing.py's listeners call them).

The drawn sheet `p` is read through its public measurements only, the names that
shellform.contact.problem.DrawingProblem publishes for the results: comm, mesh, stroke,
symmetry, num_cells, tools_kind (its LINES and RIM), material; nodal_values(),
displacements(), cell_fields(), cell_centres(), input_order(), contact_nodes(),
tool_placements(), blank_bounds(), blank_size(), picture_depth(), rim(),
surface_strain_rates() (and, for
results/springback.py and results/drawing.py, initial_positions(), resultants(), the forces
and checks of the force-stroke table, membrane_stability(), cell_thickness_strain() and
volume_change()). Nothing here reaches into the sheet's model, driver or scene.

DX = draw-in of the blank edge on the axis y = 0 (initial x minus current x), DY the same on
x = 0, DD along the diagonal at the edge's node farthest along x + y (the square blank's corner;
initial minus current radius). A round cup's rim (the nodes of the blank's outer edge,
DrawingProblem.rim) gives its ear profile: per node its angle theta = atan2(Y, X) of its initial
position from the x axis, its radial draw-in R - r (initial minus current radius in plan) and its
height z (the mid-surface's, the flat blank at z = 0); rim_0deg, rim_45deg, rim_90deg are the
draw-in interpolated along the rim at those angles. An ear is where the rim is drawn in least
(a minimum of R - r: the flange's edge stays out, and once drawn off the holder that material
stands highest in the wall), a trough where it is drawn in most. A square cup's thickness lines
are the diagonal x = y and the transverse centre line y = 0; a round cup's the rolling (0 deg,
y = 0) and transverse (90 deg, x = 0) lines.
"""

from pathlib import Path

import numpy as np
from dolfinx import fem, io
from mpi4py import MPI

from shellform.assembly.sheet_element import BS
from shellform.results import fields
from shellform.results.fields import offscreen_backend
from shellform.results.sensitivity import at_extreme
from shellform.results.tables import write_figure, write_screenshot
from shellform.tools.protocol import surface_mesh


def _gather(comm, *arrays):
    return [np.concatenate(comm.allgather(a)) for a in arrays]


def _draw_in_nodes(p, X) -> tuple[int, int, int]:
    """The nodes (rows of the gathered initial positions X) where DX, DY and DD are measured:
    the blank's edge on the x and y axes, and its corner (x, y >= 0 quadrant)."""
    _, hx, _, hy = p.blank_bounds()
    at = lambda px, py: int(np.argmin(np.hypot(X[:, 0] - px, X[:, 1] - py)))  # noqa: E731
    return at(hx, 0.0), at(0.0, hy), int(np.argmax(X[:, 0] + X[:, 1]))


def draw_in(p) -> dict:
    """DX, DY, DD (mm) at the blank's edge on the axes and the diagonal (x, y >= 0 quadrant)."""
    X, x, _ = p.nodal_values()
    X, x = _gather(p.comm, X, x)
    i0, i1, corner = _draw_in_nodes(p, X)
    out = {"DX": float(X[i0, 0] - x[i0, 0]), "DY": float(X[i1, 1] - x[i1, 1]),
           "DD": float(np.hypot(*X[corner, :2]) - np.hypot(*x[corner, :2]))}
    if p.tools_kind.RIM:
        out.update(rim_draw_in(rim(p)))
    return out


def derivatives(p, sens, name: str) -> dict:
    """d/d(name) of the report's answers (state()) from the Sensitivity `sens`: DX, DY and DD
    at draw_in's nodes (-dx, -dy, and the corner's -x . dx / |x| in plan), the punch force (kN,
    its reactions' dR/dp) and min_thickness_strain at the node where it is least (the nodes'
    e33 = ln(2 h_i / t): h_i' / h_i)."""
    X, x, e33 = p.nodal_values()
    dx = sens.carrier(name).reshape(-1, BS)[: len(X), :3]
    de33 = p.nodal_thickness_strain_derivative(sens.thickness_strain(name))
    X, x, dx, e33, de33 = _gather(p.comm, X, x, dx, e33, de33)
    i0, i1, c = _draw_in_nodes(p, X)
    plan = x[c, :2]
    return {"DX": -float(dx[i0, 0]), "DY": -float(dx[i1, 1]), "DD": -float(plan @ dx[c, :2] / np.hypot(*plan)),
            "punch_force_kN": p.punch_force(residual=sens.residual(name)) / 1e3,
            "min_thickness_strain": float(de33[int(np.argmin(e33))])}


def margin_derivative(p, dq: np.ndarray, value: float, step: float, curve_of) -> float:
    """d/dp of the smallest margin to the forming-limit curve (results/fld.py: FLC(minor) - major
    per cell) at the cell where it is least, over all ranks, p at `value`: central differences
    with `step` of the margin along the major and minor strains' derivatives
    (p.surface_strain_rates along the carrier's derivative dq) and the curve's own, curve_of(p)
    (the curve at a parameter's value: Keeler-Brazier's moves with n). Where two cells' margins
    cross, the place jumps and so does the derivative, as the peak thinning's does."""
    from shellform.results import fld

    f = p.cell_fields()
    major, minor = f["major_strain"], f["minor_strain"]
    dmajor, dminor = p.surface_strain_rates(dq, step)
    ends = [fld.margins(major + s * step * dmajor, minor + s * step * dminor, curve_of(value + s * step))
            for s in (1.0, -1.0)]
    return at_extreme(p.comm, -fld.margins(major, minor, curve_of(value)), (ends[0] - ends[1]) / (2.0 * step))


RIM_ANGLES = (0.0, 45.0, 90.0)  # the round cup's draw-in in summary.json: rim_0deg, rim_45deg, rim_90deg


def rim(p) -> np.ndarray:
    """The rim's ear profile, rows (angle_deg, draw_in_mm, z_mm) by angle, gathered on every
    rank: theta = atan2(Y, X) of the node's initial position (degrees from the x axis), the
    radial draw-in hypot(X, Y) - hypot(x, y) and the current height z of the rim's nodes."""
    X, x, _ = p.nodal_values()
    on = p.rim()
    X, x = X[on], x[on]
    rows = np.column_stack([np.degrees(np.arctan2(X[:, 1], X[:, 0])),
                            np.hypot(X[:, 0], X[:, 1]) - np.hypot(x[:, 0], x[:, 1]), x[:, 2]])
    rows, = _gather(p.comm, rows)
    return rows[np.argsort(rows[:, 0], kind="stable")]


def rim_draw_in(rows: np.ndarray, angles=RIM_ANGLES, tol: float = 1e-6) -> dict:
    """The rim's draw-in at the given angles (degrees), linear between its nodes along the
    angle: {"rim_0deg": ..., ...}; nan at an angle the rim does not reach, beyond its first or
    last node by more than tol degrees (a node on a symmetry line lies at 0 or 90 degrees to
    round-off only: its angle is computed from tabulated coordinates)."""
    lo, hi = rows[0, 0], rows[-1, 0]
    return {f"rim_{a:g}deg": float(np.interp(min(max(a, lo), hi), rows[:, 0], rows[:, 1]))
            if lo - tol <= a <= hi + tol else float("nan") for a in angles}


def write_rim(outdir: Path, p, title: str) -> dict:
    """rim.csv (angle_deg, draw_in_mm, z_mm per rim node, by angle) and rim.png (the draw-in and
    the height against the angle); returns the profile's extremes for summary.json: the least and
    the most draw-in (the highest ear and the deepest trough) and their angles, and the spread
    of z."""
    from shellform.results.tables import write_csv

    rows = rim(p)
    write_csv(outdir / "rim.csv", [{"angle_deg": a, "draw_in_mm": d, "z_mm": z} for a, d, z in rows],
              ["angle_deg", "draw_in_mm", "z_mm"])
    lo, hi = int(np.argmin(rows[:, 1])), int(np.argmax(rows[:, 1]))
    out = {"least_draw_in_mm": float(rows[lo, 1]), "least_at_deg": float(rows[lo, 0]),
           "most_draw_in_mm": float(rows[hi, 1]), "most_at_deg": float(rows[hi, 0]),
           "z_spread_mm": float(np.ptp(rows[:, 2]))}
    if p.comm.rank == 0:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (ax, az) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
        ax.plot(rows[:, 0], rows[:, 1], "o-", ms=3)
        ax.set_ylabel("radial draw-in R - r (mm)\n(least: an ear)")
        mean, spread = float(rows[:, 1].mean()), float(np.ptp(rows[:, 1]))
        half = max(spread, 0.05 * abs(mean)) * 0.6  # at least +-3 % of the mean: mesh noise stays flat
        middle = 0.5 * float(rows[:, 1].min() + rows[:, 1].max())  # not the mean: every node within the axis
        ax.set_ylim(middle - half, middle + half)
        ax.text(0.01, 0.03, f"spread {spread:.3f} mm = {100 * spread / abs(mean):.2f} % of the mean {mean:.2f} mm"
                if mean else f"spread {spread:.3f} mm", transform=ax.transAxes, fontsize=8)
        az.plot(rows[:, 0], rows[:, 2], "o-", ms=3)
        az.set_ylabel("rim height z (mm)")
        az.set_xlabel("angle from the x axis, initial (degrees)")
        for a in (ax, az):
            a.grid(alpha=0.3)
        ax.set_title(f"{title}: the rim at stroke {p.stroke:.1f} mm", fontsize=10, parse_math=False)
        fig.tight_layout()
        write_figure(outdir / "rim.png", fig, dpi=120)
        plt.close(fig)
    return out


def thickness_lines(p) -> dict[str, list[dict]]:
    """Thickness strain at the nodes along the cup's lines (its kind of tools' LINES:
    shellform.tools.kinds), by initial distance."""
    X, _, e33 = p.nodal_values()
    X, e33 = _gather(p.comm, X, e33)
    tol = 1e-6 * p.blank_size()
    lines = {}
    for name, line in p.tools_kind.LINES.items():
        on = line(X, tol)
        r = np.hypot(X[on, 0], X[on, 1])
        lines[name] = [{"initial_position_mm": float(r[i]), "thickness_strain": float(e33[on][i])}
                       for i in np.argsort(r)]
    return lines


def plot_thickness(path: Path, lines: dict[str, list[dict]], title: str) -> None:
    """The thickness strain along the cup's lines (thickness_lines: the diagonal and the
    transverse line, or 0 and 90 degrees) against the initial distance from the centre, the
    paper's own view of a drawn cup; rank 0."""
    if MPI.COMM_WORLD.rank != 0 or not any(lines.values()):
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for name, rows in lines.items():
        ax.plot([r["initial_position_mm"] for r in rows], [r["thickness_strain"] for r in rows], "o-", ms=2,
                label=name.replace("deg", " degrees"))
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("initial distance from the centre (mm)")
    ax.set_ylabel("thickness strain ln(t / t0)")
    ax.set_title(title, fontsize=10, parse_math=False)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    write_figure(path, fig, dpi=120)
    plt.close(fig)


def peak_thinning(p) -> dict:
    X, x, e33 = p.nodal_values()
    X, x, e33 = _gather(p.comm, X, x, e33)
    i = int(np.argmin(e33))
    return {"min_thickness_strain": float(e33[i]), "where_initial_xy_mm": X[i].tolist(),
            "where_current_xyz_mm": x[i].tolist(), "max_thickening_strain": float(e33.max())}


def forming_limits(outdir: Path, p, title: str, png: bool) -> dict:
    """fld.csv (per cell: initial centre, major and minor true strains, margin to the scene's
    forming-limit curve: the measured one where given, else Keeler-Brazier; fld.curves), fld.png
    and cup_margin.png (the cup coloured by the margin); returns the curve's label, the smallest
    margin and where."""
    from shellform.results import fld
    from shellform.results.tables import write_csv

    (curve, label), beside = fld.curves(p.material)
    f = p.cell_fields()
    margin = fld.margins(f["major_strain"], f["minor_strain"], curve)
    centre = p.cell_centres()
    rows = [{"x0_mm": c[0], "y0_mm": c[1], "major": a, "minor": b, "margin": m}
            for c, a, b, m in zip(centre, f["major_strain"], f["minor_strain"], margin)]
    comm = p.comm
    rows = [r for part in comm.allgather(rows) for r in part]
    write_csv(outdir / "fld.csv", rows, ["x0_mm", "y0_mm", "major", "minor", "margin"])
    fld.plot(outdir / "fld.png", f["major_strain"], f["minor_strain"], curve,
             f"{title}: stroke {p.stroke:.1f} mm", label, beside)
    if png:
        top = max(comm.allreduce(float(np.abs(margin).max(initial=0.0)), op=MPI.MAX), 1e-3)
        picture(outdir / "cup_margin.png", p, f"{title}: margin to the forming-limit curve (< 0: past it)",
                ("margin to the FLC", margin, (-top, top), "PuOr"), mark="least margin {:.3f}")
    worst = min(rows, key=lambda r: r["margin"])
    return {"forming_limit": label, "min_margin": float(worst["margin"]),
            "min_margin_at_initial_xy_mm": [float(worst["x0_mm"]), float(worst["y0_mm"])]}


class CupSeries:
    """The cup's time series at the reports.

    vtx: cup.bp the displacement and the nodal thickness strain, cup_cells.bp the cells'
    equivalent plastic strain and major and minor (logarithmic) surface strains (VTX, on the
    undeformed mesh, each rank its part).

    vtu: cup.pvd, the sheet as a stock ParaView or ``pyvista.read`` opens it (results/vtu.py):
    the modelled region (a quarter or a half is not mirrored) on its deformed mid-surface, with
    the point fields displacement, thickness_strain, contact_state (DrawingProblem.CONTACT_STATES)
    and contact_pressure, and the cell fields equivalent_plastic_strain, major_strain,
    minor_strain and, where the forming-limit view is on, fld_margin; and punch.pvd, die.pvd,
    blank_holder.pvd, each tool's surface at its position at the report (protocol.surface_mesh
    over the blank's plan extent). Rank 0 gathers the sheet and writes it with its nodes and
    cells in the mesh's input order, so that the files do not depend on the number of ranks.
    """

    CELL_FIELDS = ("equivalent_plastic_strain", "major_strain", "minor_strain")
    TOOL_GRID = 96  # plan points per side of a tool's surface

    def __init__(self, p, outdir: Path, vtx: bool = True, vtu: bool = True, fld_margin: bool = False):
        mesh, comm = p.mesh, p.comm
        self.p, self.outdir, self.writers, self.series = p, Path(outdir), [], {}
        self.fld_curve = None
        if fld_margin:
            from shellform.results import fld

            mat = p.material
            self.fld_curve = fld.keeler_brazier(mat.thickness, fld.hardening_exponent(mat))
        if vtx:
            self.disp = fem.Function(fem.functionspace(mesh, ("Lagrange", 1, (3,))), name="displacement")
            self.e33 = fem.Function(fem.functionspace(mesh, ("Lagrange", 1)), name="thickness_strain")
            dg0 = fem.functionspace(mesh, ("DG", 0))
            self.cells = [fem.Function(dg0, name=name) for name in self.CELL_FIELDS]
            self.writers = [io.VTXWriter(mesh.comm, self.outdir / "cup.bp", [self.disp, self.e33], engine="BP4"),
                            io.VTXWriter(mesh.comm, self.outdir / "cup_cells.bp", self.cells, engine="BP4")]
        if vtu:
            from shellform.results.vtu import PVDSeries

            self.order = p.input_order()
            names = ("cup", *p.tool_placements())  # on every rank: the placements reduce over them
            if comm.rank == 0:
                self.series = {name: PVDSeries(self.outdir, name) for name in names}

    def write(self, stroke):
        p = self.p
        values = p.cell_fields()
        if self.writers:
            e33 = p.nodal_values()[2]
            n = len(e33)  # the owned nodes
            self.disp.x.array.reshape(-1, 3)[:n] = p.displacements()[:n]
            self.e33.x.array[:n] = e33
            for f in self.cells:
                f.x.array[: p.num_cells] = values[f.name]
            for f in (self.disp, self.e33, *self.cells):
                f.x.scatter_forward()
            for w in self.writers:
                w.write(stroke)
        if hasattr(self, "order"):
            self._write_vtu(stroke, values)

    def _write_vtu(self, stroke, values):
        p = self.p
        comm = p.comm
        _, x, e33 = p.nodal_values()
        state, pressure = p.contact_nodes()
        n = len(self.order[0])
        cell_values = {k: values[k] for k in self.CELL_FIELDS}
        if self.fld_curve is not None:
            from shellform.results import fld

            cell_values["fld_margin"] = fld.margins(values["major_strain"], values["minor_strain"], self.fld_curve)
        point_values = {"displacement": p.displacements()[:n], "thickness_strain": e33,
                        "contact_state": state, "contact_pressure": pressure}
        whole = fields.gather_in_input_order(comm, self.order, x, point_values, cell_values)
        placements = p.tool_placements()
        if whole is None:
            return
        self.series["cup"].write(stroke, *whole)
        x0, x1, y0, y1 = p.blank_bounds()
        span = p.picture_depth()  # the walls, as deep as the stroke
        for name, (tool, dz, above) in placements.items():
            z = dz * tool.axis[2]  # the height it has moved by
            z_range = (z - span, z + span)
            points, tris = surface_mesh(tool, dz, (x0, x1, y0, y1), z_range, above, self.TOOL_GRID)
            self.series[name].write(stroke, points, tris)

    def close(self):
        for w in self.writers:
            w.close()


def force_label(copies: int, what: str = "punch force") -> str:
    """The force axis's label: the whole cup's force, and how it was made from the modelled part."""
    region = {4: "quarter", 2: "half"}.get(copies)
    return f"{what} on the whole cup (kN)" + (f"\n(the modelled {region}'s x {copies})" if region else "")


def thickness_colours(e33) -> tuple[tuple[float, float], str, str]:
    """(limits, colour map, label) of a thickness-strain picture: a diverging map on limits
    symmetric about zero (+- the largest magnitude), white at an unchanged thickness."""
    top = float(np.abs(e33).max(initial=0.0)) or 1.0
    return (-top, top), "coolwarm", "thickness strain (white 0, symmetric limits)"


def plot_force(path: Path, rows: list[dict], title: str, copies: int = 1) -> None:
    """The punch force, and the blank holder's where the rows have it, against the stroke. The
    forces are the whole cup's (DrawingProblem's forces are the modelled region's times its
    `copies`, 4 for a quarter), and the axis says so."""
    if MPI.COMM_WORLD.rank != 0 or not rows:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    stroke = [r["stroke_mm"] for r in rows]
    ax.plot(stroke, [r["punch_force_kN"] for r in rows], "-", label="punch")
    if "holder_force_kN" in rows[0]:
        ax.plot(stroke, [r["holder_force_kN"] for r in rows], "--", label="blank holder")
        ax.legend(fontsize=8)
    ax.set_xlabel("punch stroke (mm)")
    ax.set_ylabel(force_label(copies, "force"))
    ax.set_title(title, fontsize=10, parse_math=False)  # a scene's title is text, never TeX
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    write_figure(path, fig, dpi=120)
    plt.close(fig)


def picture(path: Path, p, title: str, cell_field: tuple | None = None, mark: str | None = None) -> None:
    """The drawn cup (true scale, a quarter blank mirrored to the whole cup) seen from above at
    an angle, so that the flange, the wall and the bottom show, coloured by the nodal thickness
    strain or by cell_field = (name, values per owned cell, (min, max), colour map). The
    thickness strain takes a diverging map on limits symmetric about zero (+-its largest
    magnitude), so that white is an unchanged thickness, red thickening and blue thinning.
    mark: a label format ("least {:.3f}") put on the cell where cell_field is least. On several
    ranks rank 0 gathers the sheet (fields.gather_in_input_order) and draws it: collective."""
    _, x, e33 = p.nodal_values()
    cells = {} if cell_field is None else {"field": np.asarray(cell_field[1])[: p.num_cells]}
    whole = fields.gather_in_input_order(p.comm, p.input_order(), x, {"e33": e33}, cells)
    if whole is None:
        return
    points, triangles, point_values, cell_values = whole
    offscreen_backend()
    import pyvista

    grid = pyvista.PolyData(points, faces=np.column_stack([np.full(len(triangles), 3), triangles]).ravel())
    clim, cmap, name = thickness_colours(point_values["e33"])
    grid.point_data[name] = point_values["e33"]
    labels = None
    if cell_field is not None:
        name, _, clim, cmap = cell_field
        values = cell_values["field"]
        grid.cell_data[name] = values
        if mark is not None and len(values):
            i = int(np.argmin(values))
            labels = (grid.cell_centers().points[i : i + 1], [mark.format(float(values[i]))])
    if p.symmetry == 4:  # the quarter and its mirror images in x = 0, y = 0 and both
        parts = [grid, grid.reflect((1, 0, 0), point=(0, 0, 0))]
        parts += [g.reflect((0, 1, 0), point=(0, 0, 0)) for g in parts]
        grid = parts[0].merge(parts[1:])
    pl = pyvista.Plotter(off_screen=True, window_size=(1000, 800))
    pl.add_mesh(grid, scalars=name, show_edges=True, cmap=cmap, clim=clim, edge_color="#555555",
                line_width=0.5, scalar_bar_args={"title": name})
    pl.add_text(title, font_size=10)
    if labels is not None:
        pl.add_point_labels(labels[0], labels[1], point_size=12, point_color="black", font_size=14,
                            always_visible=True, shape_opacity=0.7)
    L = 2 * p.blank_size() if p.symmetry == 4 else p.blank_size()
    pl.camera_position = [(1.1 * L, -1.5 * L, 0.9 * L), (0.0, 0.0, -0.15 * L), (0.0, 0.0, 1.0)]
    write_screenshot(path, pl)
    pl.close()
