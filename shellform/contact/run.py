"""A deep-drawing scene from its TOML to results on disk: scene -> problem -> driver -> files.

The run only builds and drives: the problem (shellform.contact.problem), its listeners (the
cup's own, shellform.results.drawing, then the caller's: shellform.results.listeners), the
checkpoints, the stops and the springback. It tells the listeners of the start, every
increment, every report, every checkpoint, the stop and the end; they measure the drawn sheet
through its public measurements and write the files. summary.json gathers what they found.

Writes into the output folder (forces and draw-in for the whole blank, pictures included):
    summary.json             the friction coefficients the tools carried ("friction": punch, die,
                             holder; 0 without the effect); stroke_mm, draw_in_mm (DX, DY, DD)
                             and punch_force_kN at every reported stroke; min_thickness_strain and where; the sheet's
                             volume change (V - V0)/V0 (elastic only, with finite strains); increments,
                             Newton iterations, contact passes, element evaluations (run,
                             reused, and how many computed a tangent); wall_time_s and its split;
                             cpu_time_s, the CPU seconds of every thread of every rank
                             over_the_stroke: the worst penetration, z-balance, holder share
                             and count of free nodes under the closed holder
    reports.json             the reports so far (rewritten at each; a resumed run takes them over)
    force_stroke.csv, .png   per increment: punch force, holder force, height, lift, largest nodal
                             share and where it is (initial x y), the share of F that holds
                             pinched nodes down (the holder opens past 1), the tools' z-balance,
                             penetration, free nodes under the closed holder, iterations,
                             smallest line-search factor, contacts
    thickness_diagonal.csv   initial distance from the centre along x = y, thickness strain
    thickness_transverse.csv the same along the transverse centre line y = 0 (round tools:
                             thickness_0deg.csv along y = 0, thickness_90deg.csv along x = 0)
    thickness.png            the thickness strain along those lines against the initial distance
    rim.csv, rim.png         (round tools) the rim's ear profile: per node of the blank's outer
                             edge its initial angle from x, radial draw-in and height z;
                             summary.json: rim_0deg, rim_45deg, rim_90deg in draw_in_mm at each
                             report, and "rim": the least and most draw-in, their angles, the
                             spread of z (results/cup.py)
    cup.bp, cup_cells.bp     VTX time series at the reports: displacement and nodal thickness
                             strain; per cell the equivalent plastic strain and the major and
                             minor logarithmic surface strains
    cup.pvd, vtu/            ([output] vtu) the same and more as a series a stock ParaView and
                             pyvista open: the deformed sheet with its point and cell fields,
                             and punch.pvd, die.pvd, blank_holder.pvd, the tools' surfaces
                             (results/cup.py CupSeries, docs/results.md)
    cup.png                  the drawn cup coloured by thickness strain, white at zero (rank 0 draws it)
    fld.csv, fld.png         ([output] fld) the cells' major and minor true strains over the
                             Keeler-Brazier forming-limit curve, each cell's margin to it;
                             cup_margin.png the cup coloured by that margin (results/fld.py)
    strain_path.csv          ([output] fld) the major and minor true strains along the stroke
                             (every stroke/200 and at the reports) of the element whose margin is
                             smallest at the end: its strain path (the checkpoint carries it:
                             a resume continues it); summary.json "strain_path":
                             where it is and where it ends. With [process] stop_at_forming_limit
                             the stroke ends at the increment where the smallest margin reaches
                             0; summary.json "forming_limit_reached": the stroke interpolated to
                             margin 0 and the increment's (results/fld.py)
    (summary.json "neck")    where the sheet starts to neck (results/neck.py): the stroke where
                             a cell's membrane stability reaches 0 (interpolated within the
                             increment), the cell's initial x y and thickness strain there; null
                             without a neck. With [process] stop_at_neck the stroke ends at that
                             increment; without, the run goes on and only reports it
    sensitivities.csv, tornado.png   ([output] sensitivities; parts with derivatives) the answers'
                             derivatives at every report (results/drawing.py CupSensitivities;
                             summary.json "sensitivities" per report, "sensitivity_checks",
                             "uncertainty" with a scatter; docs/sensitivity.md)
    springback.csv, .png     ([process] springback) the profiles along y = 0 and x = y before and
                             after the tools withdraw (contact/springback.py releases them,
                             results/springback.py writes; the picture: after minus before);
                             summary.json: wall angle, flange edge, re-yield,
                             residual resultants; with [output] sensitivities their derivatives
                             (springback_sensitivities.csv, summary.json springback.sensitivities)
    checkpoint.npz           the last converged state (at every report, every output.checkpoint_every
                             seconds, at the end, at a stop: no convergence, Ctrl-C, SIGTERM),
                             any number of ranks, and the one before (checkpoint.previous.npz):
                             `shellform run SCENE --out DIR --resume` continues from it
    history.json             every increment so far (with the checkpoint)
    run.json                 the run: scene file and hash, title, code version, started, resumed

DX, DY, DD: shellform.results.cup.

A full disk (results/disk.py: DiskFull, from a write or from the room the driver keeps before
each checkpoint, report and the tables after the stroke) stops the run as a stop does: after
the increment under way, the last complete checkpoint kept as it is, nothing more written but
summary.json, its "stopped" saying "disk full at S mm: what could not be written and why" and
which checkpoint is kept.
"""

import time
from pathlib import Path

from mpi4py import MPI

from shellform.contact import springback
from shellform.contact.problem import DrawingProblem
from shellform.errors import InputError
from shellform.mesh import budget
from shellform.nonlinear import checkpoint
from shellform.nonlinear.driver import ConvergenceFailure
from shellform.nonlinear.interrupt import Interrupted
from shellform.nonlinear.sensitivity import Sensitivity, scene_parameters
from shellform.results import run_folder
from shellform.results import springback as sprung_back
from shellform.results.disk import DiskFull
from shellform.results.drawing import CupListeners
from shellform.results.listeners import EndOfStroke, Run
from shellform.results.log import Progress, say
from shellform.results.summary import DrawingSummary
from shellform.scene import Scene

# a resume that changes one of these starts its steps afresh (not as the checkpoint had them)
STEPPING = {"process.initial_step_mm", "process.min_step_mm", "process.max_step_mm", "process.max_iterations",
            "process.rtol"}


def _stroke_of(lam, travel) -> float:
    """The punch's stroke (mm) of a checkpoint's load factor and the tools' travel."""
    return float(lam) * abs(float(travel[0]))


def _resume(p: DrawingProblem, s: Scene, outdir: Path, comm) -> dict:
    """Restore the last complete checkpoint in outdir (checkpoint.read: the previous one where
    the last is damaged), refused where what defines the state differs (run_folder.fingerprint)
    or where it lies past this scene's stroke; returns what the summary records of the resume
    (the listeners take over their rows up to it: results/drawing.py)."""
    cells = p.model.mesh.topology.index_map(2).size_global
    saved = checkpoint.read(outdir, comm, budget.state_bytes(cells, s.process.thickness_points))
    if not p.driver.fingerprint:
        p.driver.fingerprint = run_folder.fingerprint(s, checkpoint.mesh_hash(p.model.V))
    differ, changed = run_folder.compare(saved.meta.get("fingerprint") or {}, p.driver.fingerprint)
    if differ:
        raise InputError("resume", f"the checkpoint {saved.path} was written for another scene, mesh or code: "
                                   f"{', '.join(differ)} differ")
    try:
        at = _stroke_of(saved.arrays["global.lam"], saved.arrays["global.contact_travel"])
    except (KeyError, IndexError, TypeError, ValueError) as err:
        raise InputError("resume", f"the checkpoint {saved.path} is damaged ({type(err).__name__}: {err})") from None
    if at > s.tools.stroke * (1 + 1e-12) + 1e-12:
        raise InputError("tools.stroke", f"{s.tools.stroke:g} mm is shorter than the stroke of the checkpoint "
                                         f"{saved.path}, {at:.6g} mm: resume with a stroke of at least that")
    run_folder.check_process(changed, at, saved.path)
    for line in saved.damaged:
        p.driver.progress.note(f"shellform: resume: {line}; using {saved.path}")
    try:
        p.driver.resume(saved)
    except InputError:
        raise
    except (KeyError, IndexError, TypeError, ValueError) as err:  # arrays of the wrong kind or length
        raise InputError("resume", f"the checkpoint {saved.path} is damaged ({type(err).__name__}: {err})") from None
    if set(changed) & STEPPING:  # other steps asked for: they start afresh
        p.driver.forget_steps()
    return {"from_stroke_mm": p.stroke, "checkpoint": saved.path.name, "damaged": saved.damaged,
            "increments_before": len(p.driver.history), "changed": changed}


def run(s: Scene, outdir: Path, comm=MPI.COMM_WORLD, trace=False, resume=False, scene_path=None,
        listeners=()) -> DrawingSummary:
    """Draw the scene's cup; trace: log every contact pass, Newton step and iterate; resume:
    continue from the last converged state in outdir (written at every report, at the end and
    at a stop), with this scene's stroke and steps (the summary's "resumed" records what
    changed; another holder force or friction is another run: run_folder.check_process);
    without resume the folder is this run's alone
    (run_folder.start). scene_path: the scene's file, for run.json. listeners: the caller's
    (shellform.results.listeners.Listener), told of the run's events after the cup's own."""
    outdir = Path(outdir)
    run_folder.start(outdir, s, scene_path, resume, comm)
    t0, c0 = time.perf_counter(), time.process_time()
    p = DrawingProblem.from_scene(s, comm, checkpoint_dir=outdir, trace=trace)
    d = p.driver
    d.fingerprint = run_folder.fingerprint(s, checkpoint.mesh_hash(p.model.V))
    sens = Sensitivity(d, scene_parameters(s)) if s.output.sensitivities else None
    if sens is not None:
        d.records.append(sens)  # the derivatives carried along the stroke, in its checkpoints
    cup = CupListeners.of(s, p.model.plastic, outdir, comm, listeners, sens)
    if cup.limits is not None:
        d.records += cup.limits.records()  # what the run records along the stroke, in its checkpoints
    told = cup.all()
    r = Run(p, d, s, outdir, comm)
    signum = 0
    if resume:
        r.resumed = _resume(p, s, outdir, comm)
    told.announce("on_start", r)  # a resume's rows taken over (a damaged file refuses it)
    if resume:
        run_folder.resumed(outdir, s, scene_path, comm)
    setup_s = time.perf_counter() - t0
    d.progress = Progress("stroke", 1.0, " mm", s.tools.stroke)
    saved_at = [time.monotonic()]  # when the last checkpoint was written

    def checkpoint_now():
        """What a resume takes over up to the checkpoint, then the state it ends at."""
        told.announce("on_checkpoint", r)
        d.save_checkpoint()
        saved_at[0] = time.monotonic()

    def on_increment(_):
        told.announce("on_increment", r)
        every = s.output.checkpoint_every  # the increment, recorded, on disk at least this often
        if every and comm.allreduce(time.monotonic() - saved_at[0] >= every, op=MPI.LOR):
            checkpoint_now()
        if r.ending is not None:
            raise r.ending


    def stop_for_full_disk(err: DiskFull, when: str) -> None:
        """A full disk stops the run: `stopped` (after a stop before it) says in one sentence
        where, why, and which checkpoint is kept."""
        found = comm.bcast(checkpoint.last_complete(outdir) if comm.rank == 0 else None, root=0)
        g = found[1] if found else {}
        at = f" at {_stroke_of(g['lam'], g['contact_travel']):.4g} mm" if "lam" in g and "contact_travel" in g else ""
        resume = ": --resume continues from it once there is room" if found else ""
        r.stopped = (f"{r.stopped}; " if r.stopped else "") + \
            f"disk full {when}: {err.strerror}; {checkpoint.kept_words(found, at)}{resume}"
        d.progress.note(f"shellform: stopped: {r.stopped}")

    def after_the_stroke():
        """The drawn cup's tables and pictures (the listeners' on_end), then the springback:
        what springback changed, or None; an Interrupted springback sets stopped."""
        nonlocal signum
        if d.verbose:
            say("shellform: writing the tables and pictures" + (", then the springback" if s.process.springback else ""))
        told.announce("on_end", r)
        if not s.process.springback or r.stopped is not None:
            return None
        before = sprung_back.profiles(p.initial_positions(), d.displacements(), comm)
        if d.verbose:
            say("shellform: springback: the tools withdraw")
        try:
            released = springback.release(d, sensitivity=sens)
        except (ConvergenceFailure, Interrupted) as err:  # the drawn state is kept and reported
            if isinstance(err, Interrupted):
                r.stopped, signum = f"{err} during springback (the drawn cup is complete)", err.signal
            return {"stopped": str(err)}
        derivatives = None if sens is None else sprung_back.derivatives(
            p.initial_positions(), d.displacements(), released.displacements(), sens, released.sensitivity, comm)
        return sprung_back.write(outdir, p, s.title, before, released, derivatives)

    full = None  # the DiskFull that stopped the run
    try:
        try:
            for target in sorted(set(s.process.report) | {1.0}):
                if target <= d.lam + 1e-12:
                    continue  # reached before the resumed state
                d.run(target, on_increment=on_increment)
                told.report(r)
                checkpoint_now()
        except EndOfStroke as err:  # a listener ended the stroke here (the forming limit, the neck)
            d.progress.note(f"shellform: {err}")
            told.report(r)
            checkpoint_now()
        except ConvergenceFailure as err:  # the driver wrote the state
            r.stopped = str(err)
            d.progress.note(f"shellform: stopped: {err}")
            told.report(r)
            told.announce("on_checkpoint", r)
        except Interrupted as err:  # the driver wrote the state; the rows up to it, and no report
            r.stopped, signum = f"{err} at {p.stroke:.4g} mm; --resume continues from there", err.signal
            d.progress.note(f"shellform: {r.stopped}")
            told.announce("on_checkpoint", r)
            cup.reports.last(r)  # in the summary only: a resumed run reports where the scene says
    except DiskFull as err:  # after the increment under way; nothing more is written but the summary
        full = err
        stop_for_full_disk(err, f"at {p.stroke:.4g} mm")
        cup.reports.last(r, again=False)  # in the summary only, as at a signal
    d.progress.close()
    told.announce("on_stop", r)
    drawn, sprung = False, None  # as far as a full disk lets them come
    if full is None:
        try:
            d.room.check("the tables and pictures")
            sprung = after_the_stroke()
            drawn = True
        except DiskFull as err:
            stop_for_full_disk(err, f"writing the tables and pictures at {p.stroke:.4g} mm")
    rim = cup.drawn.rim if drawn else None
    summary = DrawingSummary({
        "title": s.title, "effects": list(s.effects), "ranks": comm.size, "threads": p.model.threads,
        "friction": {k: v if "friction" in s.effects else 0.0 for k, v in s.tools.friction_per_tool().items()},
        "cells": p.model.mesh.topology.index_map(2).size_global, "stroke_mm": p.stroke,
        **cup.reports.summary(), **(cup.limits.found if drawn and cup.limits is not None else {}),
        "neck": cup.necking.onset if cup.necking is not None else None,
        "springback": sprung, **({"rim": rim} if rim else {}),
        "increments": len(d.history), "newton_iterations": sum(h.iterations for h in d.history),
        "contact_passes": sum(h.contact["passes"] for h in d.history),
        "element_evaluations": {"run": d.evaluations, "reused": d.reused, "tangents": d.tangents},
        "cutbacks": sum(h.cutbacks for h in d.history), "stopped": r.stopped, "signal": signum,
        "resumed_from_stroke_mm": r.resumed["from_stroke_mm"] if r.resumed else None, "resumed": r.resumed,
        "wall_time_s": {"total": time.perf_counter() - t0, "setup": setup_s, **d.times},
        "cpu_time_s": comm.allreduce(time.process_time() - c0, op=MPI.SUM),
        "over_the_stroke": cup.table.over_the_stroke(),
        **(cup.sensitivities.summary(r) if cup.sensitivities is not None else {}),
    }, outdir)
    summary.write(comm)
    return summary
