"""The ``shellform`` command.

    shellform run SCENE.toml --out DIR      solve a scene; write summary.json, VTX fields, a PNG
                                            (--trace: a tool scene logs every contact iterate;
                                            --resume: a tool scene continues from DIR's last
                                            converged state; without it DIR is cleared of an
                                            older run's files, or refused if another scene's)
    shellform study NAME --out DIR          run a study: plate, shell, levy, rollup, plastic (accuracy
                                            against time), strip (finite-strain plasticity against
                                            closed forms), assembly, newton (benchmarks), cup-hard
                                            (the square cup's hard cases), cup-mesh (its meshes),
                                            cup-strain (before and after finite strains),
                                            cup-paper (the paper's Figs. 5 to 8), numisheet
                                            (the NUMISHEET'93 cups to 40 mm), numisheet-cost
                                            (the aluminium cup's accuracy against time),
                                            cup-benchmark (its speed at 900 to 10,000 cells),
                                            outlines (blanks of any outline), locking (thin
                                            roll-ups and a curved roof, membrane locking)
"""

import argparse
import signal
import sys
import time
from pathlib import Path

from shellform.errors import InputError


def _extremes(res) -> dict:
    """Per displacement component (u, v, w) the vertex value largest in magnitude, over all
    ranks, and where it is."""
    from mpi4py import MPI

    V = res.q.function_space
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
        _, value, at = max(MPI.COMM_WORLD.allgather(mine))
        out[name] = {"value": value, "at": at}
    return out


def _centre_w(res):
    """w at the origin, or None where the blank has no vertex there (or no w)."""
    if "w" not in res.components:
        return None
    try:
        return res.value("w")
    except InputError:
        return None


def run_scene(path: Path, outdir: Path, trace: bool = False, resume: bool = False) -> dict:
    from mpi4py import MPI

    from shellform import linear, scene
    from shellform.results import fields, run_folder
    from shellform.results.tables import write_json

    s = scene.load(path)
    run_folder.check_writable(outdir)  # before any computation: InputError("--out")
    if s.tools is not None:
        from shellform.contact import run as contact_run

        return contact_run.run(s, outdir, trace=trace, resume=resume, scene_path=path)
    if resume:
        raise InputError("resume", "only tool scenes (a [tools] section) resume from a checkpoint")
    if s.nonlinear:
        from shellform.nonlinear import run as nonlinear_run

        return nonlinear_run.run(s, outdir, scene_path=path)
    run_folder.start(outdir, s, path)
    t0 = time.perf_counter()
    res = linear.solve(s)
    cells = res.cell_fields()
    summary = {
        "title": s.title, "effects": list(s.effects), "cells": res.num_cells, "dofs": res.num_dofs,
        "ranks": MPI.COMM_WORLD.size, "w_center": _centre_w(res), "extremes": _extremes(res),
        "wall_time_s": time.perf_counter() - t0, **res.timings,
    }
    if s.output.vtx:
        fields.write_vtx(outdir, res.q, res.components, cells)
    if s.output.png and "w" in res.components:
        fields.write_png(outdir / "deformed.png", res.q, res.components, title=s.title)
    write_json(outdir / "summary.json", summary)
    return summary


STUDIES = ["plate", "shell", "levy", "rollup", "plastic", "strip", "assembly", "newton", "cup-hard", "cup-mesh",
           "cup-strain", "cup-paper", "numisheet", "numisheet-cost", "cup-benchmark", "outlines", "locking"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="shellform", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    p_run = sub.add_parser("run", help="solve a scene file")
    p_run.add_argument("scene", type=Path)
    p_run.add_argument("--out", type=Path, required=True)
    p_run.add_argument("--resume", action="store_true",
                       help="a tool scene: continue from the last converged state in --out, on any number of ranks, "
                            "with this scene's stroke (not shorter), steps, friction and holder force; "
                            "refused where anything else differs (docs/reliability.md)")
    p_run.add_argument("--trace", action="store_true",
                       help="tool scenes: log every contact pass, Newton step and iterate (diagnosis)")
    p_study = sub.add_parser("study", help="run a convergence study")
    p_study.add_argument("name", choices=STUDIES)
    p_study.add_argument("--out", type=Path, required=True)
    p_study.add_argument("--quick", action="store_true", help="coarse levels only (for tests)")
    args = parser.parse_args(argv)

    import shellform  # noqa: F401  (DOLFINx runtime first)
    from shellform.nonlinear.interrupt import Interrupted
    from shellform.results.log import say  # every line below once per run, on rank 0

    try:
        if args.command == "run":
            summary = run_scene(args.scene, args.out, trace=args.trace, resume=args.resume)
            if "draw_in_mm" in summary:
                last = summary["draw_in_mm"][-1] if summary["draw_in_mm"] else {}
                say(f"shellform: {summary['title']}: {summary['cells']} cells, stroke {summary['stroke_mm']:.2f} mm, "
                    f"draw-in {last}, max thickness strain {summary['max_thickness_strain']:.4f}, "
                    f"{summary['wall_time_s']['total']:.1f} s; results in {args.out}")
            elif "reports" in summary:
                last = summary["reports"][-1] if summary["reports"] else {}
                say(f"shellform: {summary['title']}: {summary['cells']} cells, {summary['increments']} "
                    f"increments, load factor {last.get('load_factor')}, w = {last.get('w')}, "
                    f"{summary['wall_time_s']:.2f} s; results in {args.out}")
            else:
                say(f"shellform: {summary['title']}: {summary['cells']} cells, w_center = "
                    f"{summary['w_center']}, {summary['wall_time_s']:.2f} s; results in {args.out}")
            if summary.get("stopped"):
                say(f"shellform: the run stopped early: {summary['stopped']}", file=sys.stderr)
                return 128 + summary["signal"] if summary.get("signal") else 3
        else:
            import importlib

            study = importlib.import_module(f"shellform.studies.{args.name.replace('-', '_')}")
            kwargs = {"levels": study.QUICK_LEVELS} if args.quick and hasattr(study, "QUICK_LEVELS") else {}
            study.run(args.out, **kwargs)
    except InputError as err:
        say(f"shellform: input error: {err}", file=sys.stderr)
        return 2
    except Interrupted as err:  # outside a run's own handling (a study): its state is on disk
        say(f"shellform: {err}" + (f"; the last converged state: {err.checkpoint}" if err.checkpoint else ""),
            file=sys.stderr)
        return 128 + err.signal
    except KeyboardInterrupt:  # before any increment converged, or a second Ctrl-C
        say("shellform: interrupted; nothing newer than the last checkpoint was kept", file=sys.stderr)
        return 128 + signal.SIGINT
    return 0


if __name__ == "__main__":
    sys.exit(main())
