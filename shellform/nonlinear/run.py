"""A nonlinear scene from its TOML to results on disk: scene -> problem -> driver -> files.

Writes into the output folder:
    summary.json       per reported load factor, at the end of every stage of the path and at a stop:
                       the displacement at the origin and at each [[output.probe]], the largest
                       u, v, w and where, peak equivalent plastic strain and thickness strain;
                       increments, Newton iterations, time split
    increments.csv     every increment: load factor, step, iterations, residuals, plastic layers
    nodal.bp, cells.bp the final state for ParaView (displacement, slopes; plastic and thickness
                       strain per cell)
    sheet.pvd, vtu/    ([output] vtu) the states at the reports as a series a stock ParaView and
                       pyvista open: the deformed mid-surface with displacement and slopes per node,
                       the cell fields of cells.bp and the major and minor strains per cell
                       (results/fields.py SheetSeries)
    deformed.png       the final shape (serial runs)
    checkpoint.npz     only if the run stops (no convergence, a limit load, Ctrl-C or SIGTERM): the
                       last converged state (nonlinear/checkpoint.py;
                       `--resume` continues tool scenes only)
    run.json           the run: scene file and hash, title, code version, started

summary.json "neck" (plasticity): where the sheet starts to neck (results/neck.py), the load factor
where a cell's membrane stability reaches 0 (interpolated within the increment), the cell's
initial x y and thickness strain there; null without a neck. With [process] stop_at_neck the
load path ends at that increment (its state reported), as a finished run.

A full disk (results/disk.py: DiskFull, from a write or from the room the driver keeps before
each report's series and checkpoint and the fields after the path) stops the run after the
increment under way: nothing more is written but summary.json, its "stopped" saying
"disk full at load factor P: what could not be written and why" and which checkpoint is
kept.
"""

import time
from pathlib import Path

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from shellform.errors import InputError
from shellform.nonlinear import checkpoint
from shellform.nonlinear.driver import ConvergenceFailure
from shellform.nonlinear.interrupt import Interrupted
from shellform.nonlinear.problem import SheetProblem
from shellform.nonlinear.sensitivity import Sensitivity, scene_parameters
from shellform.scene import Scene
from shellform.results import fields, neck, run_folder, sensitivity
from shellform.results.disk import DiskFull
from shellform.results.log import Progress
from shellform.results.summary import SheetSummary
from shellform.results.tables import write_csv


def cell_functions(p: SheetProblem) -> dict:
    """Equivalent plastic strain and mid-surface thickness strain as DG0 functions."""
    W = fem.functionspace(p.model.mesh, ("DG", 0))
    out = {}
    for name, values in p.model.cell_fields().items():
        f = fem.Function(W, name=name)
        f.x.array[: values.size] = values
        f.x.scatter_forward()
        out[name] = f
    return out


def _record(p: SheetProblem, s: Scene) -> dict:
    """A report: the load factor, (u, v, w) at the origin and at each probe, the extremes of
    u, v, w and where, the peak plastic strain and thinning."""
    fields = p.model.cell_fields()
    comm = p.model.mesh.comm
    peq = comm.allreduce(float(fields["equivalent_plastic_strain"].max(initial=0.0)), op=MPI.MAX)
    e33 = comm.allreduce(float(fields["thickness_strain"].min(initial=0.0)), op=MPI.MIN)
    return {"load_factor": p.driver.lam, **{k: p.value(k, 0.0, 0.0) for k in ("u", "v", "w")},
            "probes": {probe.name: probe_values(p, probe, i) for i, probe in enumerate(s.output.probe)},
            "extremes": extremes(p), "max_equivalent_plastic_strain": peq, "min_thickness_strain": e33}


def probe_values(p: SheetProblem, probe, i: int) -> dict:
    """(u, v, w) at a probe's vertex; an input error naming output.probe[i] where none is there."""
    try:
        return {k: p.value(k, probe.x, probe.y) for k in ("u", "v", "w")}
    except InputError:
        raise InputError(f"output.probe[{i}]", f"no mesh vertex at ({probe.x}, {probe.y})") from None


def extremes(p: SheetProblem) -> dict:
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


def run(s: Scene, outdir: Path, comm=MPI.COMM_WORLD, scene_path=None) -> SheetSummary:
    """Step the scene's load path into outdir, which is this run's alone (run_folder.start);
    scene_path: the scene's file, for run.json."""
    outdir = Path(outdir)
    run_folder.start(outdir, s, scene_path, comm=comm)
    t0 = time.perf_counter()
    p = SheetProblem.from_scene(s, comm, checkpoint_dir=outdir)
    for i, probe in enumerate(s.output.probe):  # each at a vertex: named before any step
        probe_values(p, probe, i)
    p.driver.fingerprint = run_folder.fingerprint(s, checkpoint.mesh_hash(p.model.V))
    setup_s = time.perf_counter() - t0
    reports, stopped, signum = [], None, 0
    p.driver.progress = Progress("load factor", max(abs(x) for x in s.process.path))
    targets = sorted(set(s.process.report))
    necks = neck.NeckWatch(comm, "load_factor", "initial_xy", s.largest_r()) if p.model.plastic else None
    centres = p.model.cell_centres()
    series = fields.SheetSeries(p.model.V, p.model.num_cells, outdir) if s.output.vtu else None
    sens = None
    if s.output.sensitivities:  # the answers' derivatives along the path (nonlinear/sensitivity.py)
        sens = Sensitivity(p.driver, scene_parameters(s))
        p.driver.records.append(sens)

    def record():
        reports.append(_record(p, s))
        if sens is not None:
            reports[-1]["sensitivities"] = sensitivity.answers(p, sens, reports[-1], s.output.probe)
        if series is not None:
            with p.driver.room.write("the report"):
                series.write(p.driver.lam, p.driver.q, p.model.components, p.model.cell_fields())

    def stop_for_full_disk(err: DiskFull, when: str) -> None:
        """A full disk stops the run: `stopped` (after a stop before it) says in one sentence
        where, why, and which checkpoint is kept."""
        nonlocal stopped
        found = comm.bcast(checkpoint.last_complete(outdir) if comm.rank == 0 else None, root=0)
        at = f" at load factor {float(found[1]['lam']):.6g}" if found and "lam" in found[1] else ""
        stopped = (f"{stopped}; " if stopped else "") + \
            f"disk full {when}: {err.strerror}; {checkpoint.kept_words(found, at)}"
        p.driver.progress.note(f"shellform: stopped: {stopped}")

    def on_increment(d):
        if necks is None:
            return
        before = necks.onset
        f = p.model.cell_fields()
        if necks.reached(d.lam, p.model.membrane_stability(), f["thickness_strain"], centres, f["major_strain"]):
            if s.process.stop_at_neck:
                raise neck.NeckReached
            if before is None:
                p.driver.progress.note(f"shellform: the sheet starts to neck: "
                                       f"{neck.words(necks.onset, 'load_factor', 'initial_xy')}")
        if s.process.stop_at_neck and d.next_step is not None:  # shorter steps ahead of the run's end
            d.bound_next_step(necks.ahead(d.next_step))

    full = None  # the DiskFull that stopped the run
    try:
        try:
            for target in s.process.path:
                # stop at every report point on the way to the target
                lo, hi = sorted((p.driver.lam, target))
                stops = [r for r in targets if lo < r < hi]
                for r in (stops if target > p.driver.lam else stops[::-1]) + [target]:
                    p.driver.run(r, on_increment=on_increment)
                    record()
        except neck.NeckReached:  # the load path ends where the sheet starts to neck
            p.driver.progress.note(f"shellform: the load path ends: "
                                   f"{neck.words(necks.onset, 'load_factor', 'initial_xy')}")
            record()
        except (ConvergenceFailure, Interrupted) as err:
            stopped = str(err)
            if isinstance(err, Interrupted):
                signum = err.signal
                stopped = f"{err} at load factor {p.driver.lam:.6g}"
            p.driver.progress.note(f"shellform: stopped: {stopped}")
            record()  # the last converged state, which the driver restored
    except DiskFull as err:  # after the increment under way; nothing more is written but the summary
        full = err
        stop_for_full_disk(err, f"at load factor {p.driver.lam:.6g}")
        if not reports or reports[-1]["load_factor"] != p.driver.lam:
            reports.append(_record(p, s))  # in the summary only
    p.driver.progress.close()
    d = p.driver
    if full is None:
        try:
            d.room.check("the tables and fields")
            rows = [{"increment": h.number, "load_factor": h.lam, "step": h.dlam, "iterations": h.iterations,
                     "first_residual": h.residuals[0], "last_residual": h.residuals[-1],
                     "plastic_layers": h.plastic_layers, "cutbacks": h.cutbacks} for h in d.history]
            write_csv(outdir / "increments.csv", rows, list(rows[0]) if rows else ["increment"])
            if s.output.vtx:
                with d.room.write("the fields"):
                    fields.write_vtx(outdir, d.q, p.model.components, cell_functions(p))
            if s.output.png:
                fields.write_png(outdir / "deformed.png", d.q, p.model.components, title=s.title)
            if sens is not None:
                sensitivity.write(outdir, reports, sens.parameters, s.output.scatter, s.title, picture=s.output.png)
        except DiskFull as err:
            stop_for_full_disk(err, f"writing the tables and fields at load factor {d.lam:.6g}")
    uncertain = {}  # the answers' standard deviations at the last report, from the scatter
    if sens is not None and s.output.scatter and reports and "sensitivities" in reports[-1]:
        uncertain["uncertainty"] = sensitivity.uncertainty(reports[-1]["sensitivities"],
                                                           sensitivity.changes(sens.parameters, s.output.scatter))
    summary = SheetSummary({
        "title": s.title, "effects": list(s.effects), "ranks": comm.size, "threads": p.model.threads,
        "cells": p.model.mesh.topology.index_map(2).size_global,
        "dofs": p.model.V.dofmap.index_map.size_global * 9, "reports": reports,
        "increments": len(d.history), "newton_iterations": sum(h.iterations for h in d.history),
        "cutbacks": sum(h.cutbacks for h in d.history), "stopped": stopped, "signal": signum,
        "neck": necks.onset if necks is not None else None,
        **uncertain,
        **({"sensitivity_checks": {  # where the derivatives are one-sided means, and the free rows' check
            "increments_with_switching_layers": [i + 1 for i, k in enumerate(sens.switches) if k],
            "largest_free_residual": max(sens.free_residual, default=0.0)}} if sens is not None else {}),
        "wall_time_s": time.perf_counter() - t0, "setup_s": setup_s, **d.times,
    }, outdir)
    summary.write(comm)
    return summary
