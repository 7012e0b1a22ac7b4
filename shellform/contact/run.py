"""A deep-drawing scene from its TOML to results on disk: scene -> problem -> driver -> files.

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
    springback.csv, .png     ([process] springback) the profiles along y = 0 and x = y before and
                             after the tools withdraw (contact/springback.py; the picture: after
                             minus before); summary.json: wall angle, flange edge, re-yield,
                             residual resultants
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

import json
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
from shellform.results import cup, fld, neck, run_folder
from shellform.results.disk import DiskFull
from shellform.results.log import Progress, say
from shellform.results.summary import DrawingSummary
from shellform.results.tables import write_csv, write_json
from shellform.scene import Scene
from shellform.tools import kinds as tool_kinds


# a resume that changes one of these starts its steps afresh (not as the checkpoint had them)
STEPPING = {"process.initial_step_mm", "process.min_step_mm", "process.max_step_mm", "process.max_iterations",
            "process.rtol"}
# worst values over all increments, in summary.json: the balances and the pinch
CHECKS = ("max_penetration_mm", "force_balance", "holder_largest_share", "free_under_closed_holder")


class FormingLimitReached(Exception):
    """The stroke ends: an element's margin to the forming-limit curve reached 0."""


def _stroke_of(lam, travel) -> float:
    """The punch's stroke (mm) of a checkpoint's load factor and the tools' travel."""
    return float(lam) * abs(float(travel[0]))


def _resume(p: DrawingProblem, s: Scene, outdir: Path, comm) -> tuple[list, list, dict]:
    """Restore the last complete checkpoint in outdir (checkpoint.read: the previous one where
    the last is damaged), refused where what defines the state differs (run_folder.fingerprint)
    or where it lies past this scene's stroke; the force-stroke rows and reports up to it, and
    what the summary records of the resume."""
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
    curve, reports = _taken_over(outdir, p.stroke + 1e-9)
    info = {"from_stroke_mm": p.stroke, "checkpoint": saved.path.name, "damaged": saved.damaged,
            "increments_before": len(p.driver.history), "changed": changed}
    return curve, reports, info


def _taken_over(outdir: Path, upto: float) -> tuple[list, list]:
    """The force-stroke rows and the reports (force_stroke.csv, reports.json) up to the stroke
    `upto`, which a resume takes over; none where a file is missing. InputError("resume")
    naming the file where it is damaged (not the table a run writes)."""
    import csv

    curve, reports, path = [], [], outdir / "force_stroke.csv"
    try:
        if path.exists():
            with open(path, newline="") as f:
                rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
            curve = [r for r in rows if r["stroke_mm"] <= upto]
        path = outdir / "reports.json"
        if path.exists():
            reports = [r for r in json.loads(path.read_text()) if float(r["stroke_mm"]) <= upto]
            for r in reports:
                float(r["punch_force_kN"]), dict(r["draw_in_mm"])
    except (OSError, UnicodeDecodeError, csv.Error, KeyError, IndexError, TypeError, ValueError) as err:
        raise InputError("resume", f"{path} is damaged ({type(err).__name__}: {err}): the rows before the "
                                   "checkpoint cannot be taken over; run the scene afresh") from None
    return curve, reports


def _previous_neck(outdir: Path) -> dict | None:
    """The neck that the resumed run's summary.json reports (None without one or without it)."""
    try:
        return json.loads((outdir / "summary.json").read_text()).get("neck")
    except (OSError, ValueError, AttributeError):
        return None


def run(s: Scene, outdir: Path, comm=MPI.COMM_WORLD, trace=False, resume=False, scene_path=None) -> DrawingSummary:
    """Draw the scene's cup; trace: log every contact pass, Newton step and iterate; resume:
    continue from the last converged state in outdir (written at every report, at the end and
    at a stop), with this scene's stroke and steps (the summary's "resumed" records what
    changed; another holder force or friction is another run: run_folder.check_process);
    without resume the folder is this run's alone
    (run_folder.start). scene_path: the scene's file, for run.json."""
    outdir = Path(outdir)
    run_folder.start(outdir, s, scene_path, resume, comm)
    t0, c0 = time.perf_counter(), time.process_time()
    p = DrawingProblem.from_scene(s, comm, checkpoint_dir=outdir, trace=trace)
    p.driver.fingerprint = run_folder.fingerprint(s, checkpoint.mesh_hash(p.model.V))
    curve, reports, stopped, resumed, signum = [], [], None, None, 0
    paths = watch = None  # what the run records along the stroke, in its checkpoints (driver.records)
    if p.model.plastic and (s.output.fld or s.process.stop_at_forming_limit):
        (curve_of_limits, _), _ = fld.curves(s.material)
        paths = fld.StrainPaths(curve_of_limits, comm, s.tools.stroke / 200) if s.output.fld else None
        watch = fld.FormingLimitWatch(curve_of_limits, comm) if s.process.stop_at_forming_limit else None
    p.driver.records += [r for r in (paths, watch) if r is not None]
    if resume:
        curve, reports, resumed = _resume(p, s, outdir, comm)
        run_folder.resumed(outdir, s, scene_path, comm)
    setup_s = time.perf_counter() - t0
    series = cup.CupSeries(p, outdir, vtx=s.output.vtx, vtu=s.output.vtu, fld_margin=s.output.fld and p.model.plastic) \
        if s.output.vtx or s.output.vtu else None
    p.driver.progress = Progress("stroke", 1.0, " mm", s.tools.stroke)
    saved_at = [time.monotonic()]  # when the last checkpoint was written
    necks = neck.NeckWatch(comm) if p.model.plastic else None
    if necks is not None and resumed:
        necks.carry(_previous_neck(outdir), p.stroke)
    centres = p.model.cell_centres()

    def on_increment(d):
        h = d.history[-1]
        hx, hy = p.holder_largest_at()
        held, edge, off_band = p.holder_held_down()
        curve.append({"increment": h.number, "stroke_mm": p.stroke, "punch_force_kN": p.punch_force() / 1e3,
                      "holder_force_kN": p.holder_force() / 1e3, "holder_height_mm": p.holder_height(),
                      "holder_lift_mm": p.holder_lift(),
                      "max_penetration_mm": p.max_penetration(), "force_balance": p.force_balance(),
                      "holder_largest_share": p.holder_share(), "holder_largest_x_mm": hx, "holder_largest_y_mm": hy,
                      "holder_held_down": held, "holder_edge_load": edge, "holder_off_band": off_band,
                      "free_under_closed_holder": p.free_under_holder(),
                      "iterations": h.iterations, "min_line_search": h.contact["min_line_search"],
                      "contact_passes": h.contact["passes"], **{f"nodes_on_{k}": v for k, v in p.in_contact().items()}})
        necked = limit = False
        if necks is not None:
            before = necks.onset
            necked = necks.reached(p.stroke, p.model.membrane_stability(), p.model.thickness_strain(), centres)
            if necked and before is None and not s.process.stop_at_neck:
                p.driver.progress.note(f"shellform: the sheet starts to neck: {neck.words(necks.onset)}")
            if s.process.stop_at_neck and d.next_step is not None:  # shorter steps ahead of the run's end
                d.bound_next_step(necks.ahead(d.next_step * s.tools.stroke) / s.tools.stroke)  # mm per load factor
        if paths is not None or watch is not None:
            f = p.model.cell_fields()
            if paths is not None:
                paths.record(p.stroke, f["major_strain"], f["minor_strain"])
            limit = watch is not None and watch.reached(p.stroke, f["major_strain"], f["minor_strain"])
        every = s.output.checkpoint_every  # the increment, recorded, on disk at least this often
        if every and comm.allreduce(time.monotonic() - saved_at[0] >= every, op=MPI.LOR):
            checkpoint_now()
        if limit:
            raise FormingLimitReached
        if necked and s.process.stop_at_neck:
            raise neck.NeckReached

    def write_curve():
        with p.driver.room.write("force_stroke.csv"):
            write_csv(outdir / "force_stroke.csv", curve, list(curve[0]) if curve else ["increment"])

    def checkpoint_now():
        """The curve so far, then the state it ends at: a resume takes the curve's rows up to the
        checkpoint's stroke."""
        write_curve()
        p.driver.save_checkpoint()
        saved_at[0] = time.monotonic()

    def state() -> dict:
        return {"stroke_mm": p.stroke, "draw_in_mm": cup.draw_in(p), "punch_force_kN": p.punch_force() / 1e3,
                **cup.peak_thinning(p), "volume_change": p.model.volume_change()}

    def report():
        reports.append(state())
        if paths is not None:
            f = p.model.cell_fields()
            paths.record(p.stroke, f["major_strain"], f["minor_strain"], final=True)
        with p.driver.room.write("the report"):  # rank 0's writes after the collective ones
            if series is not None:
                series.write(p.stroke)
            write_json(outdir / "reports.json", reports)  # what a resumed run takes over

    def stop_for_full_disk(err: DiskFull, when: str) -> None:
        """A full disk stops the run: `stopped` (after a stop before it) says in one sentence
        where, why, and which checkpoint is kept."""
        nonlocal stopped
        found = comm.bcast(checkpoint.last_complete(outdir) if comm.rank == 0 else None, root=0)
        g = found[1] if found else {}
        at = f" at {_stroke_of(g['lam'], g['contact_travel']):.4g} mm" if "lam" in g and "contact_travel" in g else ""
        resume = ": --resume continues from it once there is room" if found else ""
        stopped = (f"{stopped}; " if stopped else "") + \
            f"disk full {when}: {err.strerror}; {checkpoint.kept_words(found, at)}{resume}"
        p.driver.progress.note(f"shellform: stopped: {stopped}")

    def after_the_stroke():
        """The tables and pictures of the drawn cup, then the springback: (rim, limits, sprung);
        an Interrupted springback sets stopped and signum."""
        nonlocal stopped, signum
        if p.driver.verbose:
            say("shellform: writing the tables and pictures" + (", then the springback" if s.process.springback else ""))
        lines = cup.thickness_lines(p)
        for name, line in lines.items():
            write_csv(outdir / f"thickness_{name}.csv", line, ["initial_position_mm", "thickness_strain"])
        cup.plot_thickness(outdir / "thickness.png", lines, f"{s.title}: stroke {p.stroke:.1f} mm")
        rim = cup.write_rim(outdir, p, s.title) if tool_kinds.kind(s.tools.shape).RIM else None
        cup.plot_force(outdir / "force_stroke.png", curve, s.title, p.symmetry)
        if s.output.png:
            cup.picture(outdir / "cup.png", p, f"{s.title}: stroke {p.stroke:.1f} mm")
        limits = cup.forming_limits(outdir, p, s.title, s.output.png) if s.output.fld and p.model.plastic else {}
        if paths is not None:
            path = paths.critical(centres)
            if path:
                rows = [dict(zip(("stroke_mm", "major", "minor", "margin"), r))
                        for r in zip(path["stroke_mm"], path["major"], path["minor"], path["margin"])]
                write_csv(outdir / "strain_path.csv", rows, ["stroke_mm", "major", "minor", "margin"])
                limits["strain_path"] = {"initial_xy_mm": path["initial_xy_mm"], "points": len(rows),
                                         "end": {k: path[k][-1] for k in ("stroke_mm", "major", "minor", "margin")}}
        if watch is not None:
            limits["forming_limit_reached"] = watch.limit
        sprung = None
        if s.process.springback and stopped is None:
            before = cup.profiles(p.initial_positions(), p.driver.displacements(), comm)
            if p.driver.verbose:
                say("shellform: springback: the tools withdraw")
            try:
                released = springback.release(p.driver)
            except (ConvergenceFailure, Interrupted) as err:  # the drawn state is kept and reported
                sprung = {"stopped": str(err)}
                if isinstance(err, Interrupted):
                    stopped, signum = f"{err} during springback (the drawn cup is complete)", err.signal
            else:
                sprung = cup.springback(outdir, p, s.title, before, released)
        return rim, limits, sprung

    full = None  # the DiskFull that stopped the run
    try:
        try:
            for target in sorted(set(s.process.report) | {1.0}):
                if target <= p.driver.lam + 1e-12:
                    continue  # reached before the resumed state
                p.driver.run(target, on_increment=on_increment)
                report()
                checkpoint_now()
        except FormingLimitReached:  # the stroke ends here, drawn as far as the sheet can go
            p.driver.progress.note(f"shellform: the forming-limit curve is reached at {watch.limit['stroke_mm']:.4g} mm")
            report()
            checkpoint_now()
        except neck.NeckReached:  # the stroke ends where the sheet starts to neck
            p.driver.progress.note(f"shellform: the stroke ends: {neck.words(necks.onset)}")
            report()
            checkpoint_now()
        except ConvergenceFailure as err:
            stopped = str(err)
            p.driver.progress.note(f"shellform: stopped: {err}")
            report()
            write_curve()
        except Interrupted as err:  # the driver wrote the state; the curve up to it, and no report
            stopped, signum = f"{err} at {p.stroke:.4g} mm; --resume continues from there", err.signal
            p.driver.progress.note(f"shellform: {stopped}")
            write_curve()
            reports.append(state())  # in the summary only: a resumed run reports where the scene says
    except DiskFull as err:  # after the increment under way; nothing more is written but the summary
        full = err
        stop_for_full_disk(err, f"at {p.stroke:.4g} mm")
        if not reports or reports[-1]["stroke_mm"] != p.stroke:
            reports.append(state())  # in the summary only, as at a signal
    p.driver.progress.close()
    if series is not None:
        series.close()
    d = p.driver
    rim, limits, sprung = None, {}, None  # as far as a full disk lets them come
    if full is None:
        try:
            d.room.check("the tables and pictures")
            rim, limits, sprung = after_the_stroke()
        except DiskFull as err:
            stop_for_full_disk(err, f"writing the tables and pictures at {p.stroke:.4g} mm")
    summary = DrawingSummary({
        "title": s.title, "effects": list(s.effects), "ranks": comm.size, "threads": p.model.threads,
        "friction": {k: v if "friction" in s.effects else 0.0 for k, v in s.tools.friction_per_tool().items()},
        "cells": p.model.mesh.topology.index_map(2).size_global, "stroke_mm": p.stroke,
        "draw_in_mm": [{"stroke_mm": r["stroke_mm"], **r["draw_in_mm"]} for r in reports],
        "punch_force_kN": [{"stroke_mm": r["stroke_mm"], "force": r["punch_force_kN"]} for r in reports],
        **{k: v for k, v in reports[-1].items() if k not in ("stroke_mm", "draw_in_mm", "punch_force_kN")},
        "reports": reports, **limits, "neck": necks.onset if necks is not None else None,
        "springback": sprung, **({"rim": rim} if rim else {}),
        "increments": len(d.history), "newton_iterations": sum(h.iterations for h in d.history),
        "contact_passes": sum(h.contact["passes"] for h in d.history),
        "element_evaluations": {"run": d.evaluations, "reused": d.reused, "tangents": d.tangents},
        "cutbacks": sum(h.cutbacks for h in d.history), "stopped": stopped, "signal": signum,
        "resumed_from_stroke_mm": resumed["from_stroke_mm"] if resumed else None, "resumed": resumed,
        "wall_time_s": {"total": time.perf_counter() - t0, "setup": setup_s, **d.times},
        "cpu_time_s": comm.allreduce(time.process_time() - c0, op=MPI.SUM),
        "over_the_stroke": {k: max((row[k] for row in curve), default=0.0) for k in CHECKS},
    }, outdir)
    summary.write(comm)
    return summary
