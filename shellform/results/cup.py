"""The drawn cup's results: draw-in, thickness lines, peak thinning, the VTX series, the
force-stroke plot and the picture of the cup (used by shellform.contact.run).

DX = draw-in of the blank edge on the axis y = 0 (initial x minus current x), DY the same on
x = 0, DD along the diagonal at the edge's node farthest along x + y (the square blank's corner;
initial minus current radius). A square cup's thickness lines are the diagonal x = y and the
transverse centre line y = 0; a round cup's the rolling (0 deg, y = 0) and transverse (90 deg,
x = 0) lines.
"""

from pathlib import Path

import numpy as np
from dolfinx import fem, io
from mpi4py import MPI

from shellform.results.fields import offscreen_backend


def _gather(comm, *arrays):
    return [np.concatenate(comm.allgather(a)) for a in arrays]


def draw_in(p) -> dict:
    """DX, DY, DD (mm) at the blank's edge on the axes and the diagonal (x, y >= 0 quadrant)."""
    X, x, _ = p.nodal_values()
    X, x = _gather(p.model.mesh.comm, X, x)
    _, hx, _, hy = p.blank_bounds()

    def at(px, py):
        i = int(np.argmin(np.hypot(X[:, 0] - px, X[:, 1] - py)))
        return X[i], x[i]

    (X0, x0), (X1, x1) = at(hx, 0.0), at(0.0, hy)
    corner = int(np.argmax(X[:, 0] + X[:, 1]))
    return {"DX": float(X0[0] - x0[0]), "DY": float(X1[1] - x1[1]),
            "DD": float(np.hypot(*X[corner, :2]) - np.hypot(*x[corner, :2]))}


LINES = {  # the thickness lines of a cup by its tools' shape: name -> nodes on it
    "square": {"diagonal": lambda X, tol: np.abs(X[:, 0] - X[:, 1]) < tol,
               "transverse": lambda X, tol: np.abs(X[:, 1]) < tol},
    "round": {"0deg": lambda X, tol: np.abs(X[:, 1]) < tol, "90deg": lambda X, tol: np.abs(X[:, 0]) < tol},
}
LINES["cad"] = LINES["square"]  # a cup drawn by CAD tools: the square cup's lines


def thickness_lines(p) -> dict[str, list[dict]]:
    """Thickness strain at the nodes along the cup's lines (LINES), by initial distance."""
    X, _, e33 = p.nodal_values()
    X, e33 = _gather(p.model.mesh.comm, X, e33)
    tol = 1e-6 * p.blank_size()
    lines = {}
    for name, line in LINES[p.scene.tools.shape].items():
        on = line(X, tol)
        r = np.hypot(X[on, 0], X[on, 1])
        lines[name] = [{"initial_position_mm": float(r[i]), "thickness_strain": float(e33[on][i])}
                       for i in np.argsort(r)]
    return lines


def peak_thinning(p) -> dict:
    X, x, e33 = p.nodal_values()
    X, x, e33 = _gather(p.model.mesh.comm, X, x, e33)
    i = int(np.argmin(e33))
    return {"max_thickness_strain": float(e33[i]), "where_initial_xy_mm": X[i].tolist(),
            "where_current_xyz_mm": x[i].tolist(), "max_thickening_strain": float(e33.max())}


def forming_limits(outdir: Path, p, title: str, png: bool) -> dict:
    """fld.csv (per cell: initial centre, major and minor true strains, margin), fld.png and
    cup_margin.png (the cup coloured by the margin); returns the smallest margin and where."""
    from shellform.results import fld
    from shellform.results.tables import write_csv

    mat = p.scene.material
    t, n = mat.thickness, fld.hardening_exponent(mat)
    curve = fld.keeler_brazier(t, n)
    f = p.model.cell_fields()
    margin = fld.margins(f["major_strain"], f["minor_strain"], curve)
    centre = p.model.cell_coords.reshape(-1, 3, 3).mean(axis=1)[:, :2]
    rows = [{"x0_mm": c[0], "y0_mm": c[1], "major": a, "minor": b, "margin": m}
            for c, a, b, m in zip(centre, f["major_strain"], f["minor_strain"], margin)]
    comm = p.model.mesh.comm
    rows = [r for part in comm.allgather(rows) for r in part]
    write_csv(outdir / "fld.csv", rows, ["x0_mm", "y0_mm", "major", "minor", "margin"])
    label = f"Keeler-Brazier, t {t:g} mm, n {n:.3g}: FLC0 {fld.flc0(t, n):.3f}"
    fld.plot(outdir / "fld.png", f["major_strain"], f["minor_strain"], curve,
             f"{title}: stroke {p.stroke:.1f} mm", label)
    if png:
        picture(outdir / "cup_margin.png", p, f"{title}: margin to the forming-limit curve",
                ("margin to the FLC", margin, (-0.1, 0.3), "RdYlGn"))
    worst = min(rows, key=lambda r: r["margin"])
    return {"forming_limit": label, "min_margin": float(worst["margin"]),
            "min_margin_at_initial_xy_mm": [float(worst["x0_mm"]), float(worst["y0_mm"])]}


class CupSeries:
    """VTX time series: cup.bp the displacement and the nodal thickness strain, cup_cells.bp the
    cells' equivalent plastic strain and major and minor (logarithmic) surface strains."""

    CELL_FIELDS = ("equivalent_plastic_strain", "major_strain", "minor_strain")

    def __init__(self, p, path: Path):
        mesh = p.model.mesh
        self.p = p
        self.disp = fem.Function(fem.functionspace(mesh, ("Lagrange", 1, (3,))), name="displacement")
        self.e33 = fem.Function(fem.functionspace(mesh, ("Lagrange", 1)), name="thickness_strain")
        dg0 = fem.functionspace(mesh, ("DG", 0))
        self.cells = [fem.Function(dg0, name=name) for name in self.CELL_FIELDS]
        self.writers = [io.VTXWriter(mesh.comm, path, [self.disp, self.e33], engine="BP4"),
                        io.VTXWriter(mesh.comm, path.with_name(path.stem + "_cells.bp"), self.cells, engine="BP4")]

    def write(self, stroke):
        e33 = self.p.nodal_values()[2]
        n = len(e33)  # the owned nodes
        self.disp.x.array.reshape(-1, 3)[:n] = self.p.displacements()[:n]
        self.e33.x.array[:n] = e33
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


def plot_force(path: Path, rows: list[dict], title: str) -> None:
    if MPI.COMM_WORLD.rank != 0 or not rows:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot([r["stroke_mm"] for r in rows], [r["punch_force_kN"] for r in rows], "-")
    ax.set_xlabel("punch stroke (mm)")
    ax.set_ylabel("punch force (kN)")
    ax.set_title(title, fontsize=10, parse_math=False)  # a scene's title is text, never TeX
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def picture(path: Path, p, title: str, cell_field: tuple | None = None) -> None:
    """The drawn cup (true scale, a quarter blank mirrored to the whole cup) seen from above at
    an angle, so that the flange, the wall and the bottom show, coloured by the nodal thickness
    strain or by cell_field = (name, values per cell, (min, max), colour map); serial runs only."""
    mesh = p.model.mesh
    if mesh.comm.size > 1:
        return
    offscreen_backend()
    import pyvista
    from dolfinx import plot

    topology, cell_types, x = plot.vtk_mesh(mesh)
    grid = pyvista.UnstructuredGrid(topology, cell_types, x + p.displacements()[: x.shape[0]])
    e33 = np.zeros(x.shape[0])
    owned = p.nodal_values()[2]
    e33[: len(owned)] = owned
    grid.point_data["thickness strain"] = e33
    name, clim, cmap = "thickness strain", None, "coolwarm"
    if cell_field is not None:
        name, values, clim, cmap = cell_field
        grid.cell_data[name] = values
    if p.symmetry == 4:  # the quarter and its mirror images in x = 0, y = 0 and both
        parts = [grid, grid.reflect((1, 0, 0), point=(0, 0, 0))]
        parts += [g.reflect((0, 1, 0), point=(0, 0, 0)) for g in parts]
        grid = parts[0].merge(parts[1:])
    pl = pyvista.Plotter(off_screen=True, window_size=(1000, 800))
    pl.add_mesh(grid, scalars=name, show_edges=True, cmap=cmap, clim=clim, edge_color="#555555",
                line_width=0.5, scalar_bar_args={"title": name})
    pl.add_text(title, font_size=10)
    L = 2 * p.blank_size() if p.symmetry == 4 else p.blank_size()
    pl.camera_position = [(1.1 * L, -1.5 * L, 0.9 * L), (0.0, 0.0, -0.15 * L), (0.0, 0.0, 1.0)]
    pl.screenshot(str(path))
    pl.close()


def profile(X, u, comm, diagonal=False):
    """(initial distance, x or r, z) of the owned nodes (initial positions X, displacements u)
    on the line y = 0 (or x = y), by initial distance from the centre, gathered on every rank."""
    n = len(u)
    x = X[:n] + u
    on = LINES["square"]["diagonal" if diagonal else "transverse"](X[:n], 1e-6 * max(np.abs(X[:, :2]).max(), 1.0))
    r = np.hypot(x[on, 0], x[on, 1]) if diagonal else x[on, 0]
    rows, = _gather(comm, np.column_stack([np.hypot(X[:n, 0], X[:n, 1])[on], r, x[on, 2]]))
    return rows[np.argsort(rows[:, 0])]


def wall_angle(rows, depth: float) -> float:
    """The wall's angle from the horizontal (degrees, 90: vertical): a line x(z) fitted to the
    profile's points between 30 % and 70 % of the depth."""
    z = rows[:, 2]
    wall = (z < -0.3 * depth) & (z > -0.7 * depth)
    if wall.sum() < 2:
        return float("nan")
    dxdz = np.polyfit(rows[wall, 2], rows[wall, 1], 1)[0]
    return float(90.0 - np.degrees(np.arctan(abs(dxdz))))


SPRINGBACK_LINES = {"transverse": False, "diagonal": True}


def profiles(X, u, comm) -> dict:
    """The transverse and diagonal profiles of a state (before or after springback): X the
    owned nodes' initial positions, u their displacements."""
    return {k: profile(X, u, comm, diagonal=v) for k, v in SPRINGBACK_LINES.items()}


def springback(outdir: Path, p, title: str, before: dict, released) -> dict:
    """What springback changed (shellform.contact.springback released the tools' forces into
    `released`): wall angle and flange edge along the transverse line, the diagonal's corner,
    the unloading's plastic layers, the residual resultants; springback.csv and springback.png."""
    from shellform.results.tables import write_csv

    lines = SPRINGBACK_LINES
    after = profiles(p.initial_positions(), released.displacements(), p.model.mesh.comm)
    depth = float(-before["transverse"][:, 2].min())
    rows = [{"line": k, "initial_position_mm": b[0], "before_r_mm": b[1], "before_z_mm": b[2],
             "after_r_mm": a[1], "after_z_mm": a[2]} for k in lines for b, a in zip(before[k], after[k])]
    write_csv(outdir / "springback.csv", rows, list(rows[0]))
    m = p.model
    N, M = m.resultants[..., :3], m.resultants[..., 3:]
    comm = m.mesh.comm
    edge = {k: (before[k][-1], after[k][-1]) for k in lines}
    out = {
        "stopped": None,
        "wall_angle_deg": {"before": wall_angle(before["transverse"], depth),
                           "after": wall_angle(after["transverse"], depth)},
        "flange_edge_dz_mm": {k: float(a[2] - b[2]) for k, (b, a) in edge.items()},
        "flange_edge_dr_mm": {k: float(a[1] - b[1]) for k, (b, a) in edge.items()},
        "unloading_increments": len(released.history),
        "plastic_layers_on_unloading": int(sum(h.plastic_layers for h in released.history)),
        "residual_max_N_per_mm": comm.allreduce(float(np.abs(N[..., :2]).max(initial=0.0)), op=MPI.MAX),
        "residual_max_M_N": comm.allreduce(float(np.abs(M[..., :2]).max(initial=0.0)), op=MPI.MAX),
    }
    if comm.rank == 0:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(11, 4))
        for ax, k in zip(axes, lines):
            ax.plot(before[k][:, 1], before[k][:, 2], "k-", label="drawn (tools in place)")
            ax.plot(after[k][:, 1], after[k][:, 2], "r--", label="sprung back")
            ax.set_xlabel("distance from the centre (mm)")
            ax.set_ylabel("z (mm)")
            ax.set_aspect("equal")
            ax.set_title(f"{k} line", fontsize=9)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
        fig.suptitle(f"{title}: springback", fontsize=10)
        fig.tight_layout()
        fig.savefig(outdir / "springback.png", dpi=120)
        plt.close(fig)
    return out
