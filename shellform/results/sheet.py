"""The nonlinear sheet's results as listeners (results/listeners.py): what a sheet scene's run
records and writes, each part owning its state and its files.

| listener | on_start | on_increment | on_report / save_report | on_end | summary.json |
|---|---|---|---|---|---|
| `SheetReports` | the probes checked | | the report: the load factor, u, v, w at the origin and the probes, the extremes, the peak strains | increments.csv, nodal.bp, cells.bp, deformed.png | reports |
| `SheetSeries` | | | the state in sheet.pvd (`[output] vtu`) | | |
| `neck.Necking` | the cells' centres | the neck watch (results/neck.py, the cup's too); at the neck with `stop_at_neck` the load path ends (run.end_with) and the steps shorten ahead of it | | | neck |
| `SheetSensitivities` | the sensitivities, a record of the driver (nonlinear/sensitivity.py) | | each report's derivatives (results/sensitivity.py) | sensitivities.csv, tornado.png | uncertainty, sensitivity_checks |

The run (shellform.nonlinear.run) tells them in that order, then a caller's own; `run.sheet` is
the SheetProblem (its model and driver), whose public measurements they read.
"""

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from shellform.errors import InputError
from shellform.results import fields, neck, sensitivity
from shellform.results.listeners import Listener, Listeners, Run
from shellform.results.tables import write_csv


def probe_values(p, probe, i: int) -> dict:
    """(u, v, w) at a probe's vertex; an input error naming output.probe[i] where none is there."""
    try:
        return {k: p.value(k, probe.x, probe.y) for k in ("u", "v", "w")}
    except InputError:
        raise InputError(f"output.probe[{i}]", f"no mesh vertex at ({probe.x}, {probe.y})") from None


def extremes(p) -> dict:
    """For u, v and w: the value of largest magnitude over the blank and the initial (x, y) of its
    vertex, all ranks."""
    comm = p.model.mesh.comm
    n = p.model.V.dofmap.index_map.size_local
    X = p.model.V.tabulate_dof_coordinates()[:n, :2]
    q = p.driver.q.x.array.reshape(-1, len(p.model.components))[:n]
    out = {}
    for name in ("u", "v", "w"):
        values = q[:, p.model.components.index(name)]
        i = int(np.argmax(np.abs(values))) if n else -1
        mine = (abs(float(values[i])), float(values[i]), X[i].tolist()) if i >= 0 else (-1.0, 0.0, [np.nan, np.nan])
        _, value, xy = max(comm.allgather(mine), key=lambda c: c[0])
        out[name] = {"value": value, "at_initial_xy": xy}
    return out


def cell_functions(p) -> dict:
    """Equivalent plastic strain and mid-surface thickness strain as DG0 functions."""
    W = fem.functionspace(p.model.mesh, ("DG", 0))
    out = {}
    for name, values in p.model.cell_fields().items():
        f = fem.Function(W, name=name)
        f.x.array[: values.size] = values
        f.x.scatter_forward()
        out[name] = f
    return out


class SheetReports(Listener):
    """The reports (summary.json "reports") and the tables and fields at the end."""

    def __init__(self):
        self.rows = []

    def on_start(self, run: Run) -> None:
        for i, probe in enumerate(run.scene.output.probe):  # each at a vertex: named before any step
            probe_values(run.sheet, probe, i)

    def on_report(self, run: Run) -> None:
        """A report: the load factor, (u, v, w) at the origin and at each probe, the extremes of
        u, v, w and where, the peak plastic strain and thinning."""
        p, comm = run.sheet, run.comm
        f = p.model.cell_fields()
        peq = comm.allreduce(float(f["equivalent_plastic_strain"].max(initial=0.0)), op=MPI.MAX)
        e33 = comm.allreduce(float(f["thickness_strain"].min(initial=0.0)), op=MPI.MIN)
        self.rows.append({
            "load_factor": p.driver.lam, **{k: p.value(k, 0.0, 0.0) for k in ("u", "v", "w")},
            "probes": {probe.name: probe_values(p, probe, i) for i, probe in enumerate(run.scene.output.probe)},
            "extremes": extremes(p), "max_equivalent_plastic_strain": peq, "min_thickness_strain": e33})

    def last(self, run: Run) -> None:
        """The state where the run stopped, in the summary only (a full disk), unless reported."""
        if not self.rows or self.rows[-1]["load_factor"] != run.driver.lam:
            self.on_report(run)

    def on_end(self, run: Run) -> None:
        d, s, p = run.driver, run.scene, run.sheet
        rows = [{"increment": h.number, "load_factor": h.lam, "step": h.dlam, "iterations": h.iterations,
                 "first_residual": h.residuals[0], "last_residual": h.residuals[-1],
                 "plastic_layers": h.plastic_layers, "cutbacks": h.cutbacks} for h in d.history]
        write_csv(run.outdir / "increments.csv", rows, list(rows[0]) if rows else ["increment"])
        if s.output.vtx:
            with d.room.write("the fields"):
                fields.write_vtx(run.outdir, d.q, p.model.components, cell_functions(p))
        if s.output.png:
            fields.write_png(run.outdir / "deformed.png", d.q, p.model.components, title=s.title)


class SheetSeries(Listener):
    """The states at the reports as sheet.pvd (results/fields.py SheetSeries)."""

    def __init__(self, run_sheet, outdir):
        self.series = fields.SheetSeries(run_sheet.model.V, run_sheet.model.num_cells, outdir)

    def save_report(self, run: Run) -> None:
        p = run.sheet
        self.series.write(run.driver.lam, run.driver.q, p.model.components, p.model.cell_fields())


class SheetSensitivities(Listener):
    """The answers' derivatives in `[output] sensitivities` (nonlinear/sensitivity.py), added to
    each report of `reports`."""

    def __init__(self, sensitivity_of, reports: SheetReports):
        self.make, self.reports, self.sens = sensitivity_of, reports, None

    def on_start(self, run: Run) -> None:
        self.sens = self.make(run.driver)
        run.driver.records.append(self.sens)

    def on_report(self, run: Run) -> None:
        row = self.reports.rows[-1]
        row["sensitivities"] = sensitivity.answers(run.sheet, self.sens, row, run.scene.output.probe)

    def on_end(self, run: Run) -> None:
        s = run.scene
        sensitivity.write(run.outdir, self.reports.rows, self.sens.parameters, s.output.scatter, s.title,
                          picture=s.output.png)

    def summary(self, run: Run) -> dict:
        """summary.json's "sensitivity_checks" and "uncertainty" (results/sensitivity.py)."""
        return sensitivity.summary(self.sens, self.reports.rows, run.scene.output.scatter)


class SheetListeners:
    """The sheet route's own listeners for a scene, and a caller's after them."""

    def __init__(self, s, sheet, outdir, comm, sensitivity_of=None, extra=()):
        self.reports = SheetReports()
        self.series = SheetSeries(sheet, outdir) if s.output.vtu else None
        self.necking = neck.Necking.load_factor(comm, s.process.stop_at_neck, s.largest_r()) if sheet.model.plastic else None
        self.sensitivities = SheetSensitivities(sensitivity_of, self.reports) if sensitivity_of else None
        self.extra = list(extra)

    def all(self) -> Listeners:
        return Listeners([x for x in (self.reports, self.series, self.necking, self.sensitivities) if x is not None]
                         + self.extra)
