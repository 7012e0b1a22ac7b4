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
    sensitivities.csv, tornado.png  ([output] sensitivities) the answers' derivatives at the
                       reports (results/sensitivity.py; summary.json "sensitivities" per report,
                       "uncertainty" with a scatter, "sensitivity_checks")

summary.json "neck" (plasticity): where the sheet starts to neck (results/neck.py), the load factor
where a cell's membrane stability reaches 0 (interpolated within the increment), the cell's
initial x y and thickness strain there; null without a neck. With [process] stop_at_neck the
load path ends at that increment (its state reported), as a finished run.

The reports, the series, the neck watch, the sensitivities and the tables at the end are
listeners of the run (results/sheet.py, results/listeners.py): this module builds the problem,
drives the load path and writes summary.json.

A full disk (results/disk.py: DiskFull, from a write or from the room the driver keeps before
each report's series and checkpoint and the fields after the path) stops the run after the
increment under way: nothing more is written but summary.json, its "stopped" saying
"disk full at load factor P: what could not be written and why" and which checkpoint is
kept.
"""

import time
from pathlib import Path

from mpi4py import MPI

from shellform.nonlinear import checkpoint
from shellform.nonlinear.driver import ConvergenceFailure
from shellform.nonlinear.interrupt import Interrupted
from shellform.nonlinear.problem import SheetProblem
from shellform.nonlinear.sensitivity import Sensitivity, scene_parameters
from shellform.scene import Scene
from shellform.results import run_folder
from shellform.results.disk import DiskFull
from shellform.results.listeners import EndOfStroke, Run
from shellform.results.log import Progress
from shellform.results.sheet import SheetListeners
from shellform.results.summary import SheetSummary


def run(s: Scene, outdir: Path, comm=MPI.COMM_WORLD, scene_path=None, listeners=()) -> SheetSummary:
    """Step the scene's load path into outdir, which is this run's alone (run_folder.start);
    scene_path: the scene's file, for run.json; listeners: the caller's
    (shellform.results.listeners.Listener), told of the run's events after the sheet's own
    (results/sheet.py)."""
    outdir = Path(outdir)
    run_folder.start(outdir, s, scene_path, comm=comm)
    t0 = time.perf_counter()
    p = SheetProblem.from_scene(s, comm, checkpoint_dir=outdir)
    d = p.driver
    d.fingerprint = run_folder.fingerprint(s, checkpoint.mesh_hash(p.model.V))
    parameters = scene_parameters(s) if s.output.sensitivities else None
    own = SheetListeners(s, p, outdir, comm, (lambda driver: Sensitivity(driver, parameters)) if parameters else None,
                         listeners)
    told = own.all()
    r = Run(p, d, s, outdir, comm)
    told.announce("on_start", r)
    setup_s = time.perf_counter() - t0
    signum = 0
    d.progress = Progress("load factor", max(abs(x) for x in s.process.path))
    targets = sorted(set(s.process.report))

    def on_increment(_):
        told.announce("on_increment", r)
        if r.ending is not None:
            raise r.ending


    def stop_for_full_disk(err: DiskFull, when: str) -> None:
        """A full disk stops the run: `stopped` (after a stop before it) says in one sentence
        where, why, and which checkpoint is kept."""
        found = comm.bcast(checkpoint.last_complete(outdir) if comm.rank == 0 else None, root=0)
        at = f" at load factor {float(found[1]['lam']):.6g}" if found and "lam" in found[1] else ""
        r.stopped = (f"{r.stopped}; " if r.stopped else "") + \
            f"disk full {when}: {err.strerror}; {checkpoint.kept_words(found, at)}"
        d.progress.note(f"shellform: stopped: {r.stopped}")

    full = None  # the DiskFull that stopped the run
    try:
        try:
            for target in s.process.path:
                # stop at every report point on the way to the target
                lo, hi = sorted((d.lam, target))
                stops = [x for x in targets if lo < x < hi]
                for x in (stops if target > d.lam else stops[::-1]) + [target]:
                    d.run(x, on_increment=on_increment)
                    told.report(r)
        except EndOfStroke as err:  # a listener ended the load path here (the neck)
            d.progress.note(f"shellform: {err}")
            told.report(r)
        except (ConvergenceFailure, Interrupted) as err:
            r.stopped = str(err)
            if isinstance(err, Interrupted):
                signum = err.signal
                r.stopped = f"{err} at load factor {d.lam:.6g}"
            d.progress.note(f"shellform: stopped: {r.stopped}")
            told.report(r)  # the last converged state, which the driver restored
    except DiskFull as err:  # after the increment under way; nothing more is written but the summary
        full = err
        stop_for_full_disk(err, f"at load factor {d.lam:.6g}")
        own.reports.last(r)  # in the summary only
    d.progress.close()
    told.announce("on_stop", r)
    if full is None:
        try:
            d.room.check("the tables and fields")
            told.announce("on_end", r)
        except DiskFull as err:
            stop_for_full_disk(err, f"writing the tables and fields at load factor {d.lam:.6g}")
    summary = SheetSummary({
        "title": s.title, "effects": list(s.effects), "ranks": comm.size, "threads": p.model.threads,
        "cells": p.model.mesh.topology.index_map(2).size_global,
        "dofs": p.model.V.dofmap.index_map.size_global * 9, "reports": own.reports.rows,
        "increments": len(d.history), "newton_iterations": sum(h.iterations for h in d.history),
        "cutbacks": sum(h.cutbacks for h in d.history), "stopped": r.stopped, "signal": signum,
        "neck": own.necking.onset if own.necking is not None else None,
        **(own.sensitivities.summary(r) if own.sensitivities is not None else {}),
        "wall_time_s": time.perf_counter() - t0, "setup_s": setup_s, **d.times,
    }, outdir)
    summary.write(comm)
    return summary
