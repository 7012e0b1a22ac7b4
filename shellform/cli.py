"""The shellform command.

    shellform run SCENE.toml -o DIR       solve a scene into DIR (summary.json, tables, fields,
                                          pictures); --set KEY=VALUE changes a key of the scene,
                                          --resume continues a tool scene from DIR's last
                                          converged state, --threads N caps the element loops'
                                          threads, --trace logs every contact iterate
    shellform check SCENE.toml            check the scene as a run would, print it with every key
                                          resolved and what its mesh will cost; run nothing
    shellform study NAME -o DIR           run a study (shellform study --help lists them)

Each command takes -q (the closing line, warnings and errors only) or -v (every increment's
line, also on a terminal, where the default rewrites one line in place). The library logs
through Python's logging (shellform.results.log) and prints nothing itself: the command shows its log.

Exit status: 0 done, 2 input error, 3 stopped early (a full disk included), 128 + the signal
when Ctrl-C or SIGTERM stopped it. Scenes: docs/scenes.md; results: docs/results.md; studies:
docs/checked.md.
"""

import argparse
import os
import signal
import sys
import threading
from pathlib import Path

from shellform import __version__  # the package first: the DOLFINx runtime before any solver module
from shellform.errors import InputError

# name -> what it shows (docs/checked.md gives each one's run time)
STUDIES = {
    "plate": "Kirchhoff plate: convergence, error against time (with C0 interior penalty P2, P3)",
    "shell": "the paper's shallow-shell block, Figs. 1-2",
    "levy": "Levy's clamped plate in large deflection, error against time",
    "rollup": "a strip rolled into a full circle by an end moment",
    "plastic": "limit load and springback of an elastic-plastic cantilever",
    "strip": "finite-strain plasticity: a strip pulled to a stretch of 1.5 against closed forms",
    "ironing": "a strip squeezed between faces and drawn through a gap against plane-strain closed forms",
    "binder-wrap": "a strip wrapped onto a cylindrical binder, its springback against the closed form of a bend",
    "curved-binder": "a channel and a square cup over cylindrical binders: the binder wrap, then the draw; friction "
                     "per tool",
    "assembly": "assembly benchmark",
    "newton": "one Newton iteration of the plastic sheet, benchmark",
    "cup-hard": "the square cup's five hard cases",
    "cup-mesh": "the square cup on three meshes, error against time",
    "cup-strain": "the square cup before and after finite strains",
    "cup-paper": "the paper's Figs. 5 to 8 (after cup-mesh and cup-hard)",
    "numisheet": "the NUMISHEET'93 cups to 40 mm",
    "numisheet-cost": "the aluminium cup: mesh, step, thickness points, rtol against the converged answers and CPU time",
    "cup-benchmark": "the aluminium cup at 900 to 10,000 cells on 1 and 2 ranks: speed",
    "outlines": "circle and triangle plates, error against time",
    "locking": "membrane locking: thin roll-ups and a curved roof",
    "cup-convergence": "the aluminium and the square cup on a sequence of meshes: observed orders, Richardson estimates",
    "pinch-edge": "the holder's edge load resolved below the thickness: a plane-strain strip",
    "nakajima": "the Nakajima test: specimens of eleven widths stretched to the forming limit, their strain paths",
    "yld2000-fit": "Yld2000-2d and Poly6 fitted by least squares to the ESAFORM 2021 AA6016-T4 data: "
                   "errors per angle",
    "esaform-cup": "the ESAFORM 2021 cup drawn through, Yld2000-2d and Hill 1948: the height profile against the measured one",
    "sensitivity": "sensitivities from one run against closed forms and finite differences of two runs",
    "sensitivity-cup": "the aluminium cup's sensitivities (holder force, friction, K, n, r0) against differences of "
                       "whole runs, and their cost",
}

SCENE_HELP = "the scene's TOML file (docs/scenes.md)"
OUT_HELP = ("the output folder, created if missing; a run without --resume clears it of an older run's files of "
            "the same scene, and refuses it if it holds another scene's run")
SET_HELP = ("change a key of the scene, as mesh.n=24, tools.stroke=20, process.report=[0.25, 0.5], "
            "output.png=false (a TOML value; repeat for several); checked as the scene file is")
THREADS_HELP = ("at most this many threads for the element and material loops of each rank (sets "
                "SHELLFORM_THREADS; default: the cores this process may use, shared by the ranks on a node, at "
                "most NUMBA_NUM_THREADS)")


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="shellform", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"shellform {__version__}")
    talk = argparse.ArgumentParser(add_help=False)
    how = talk.add_mutually_exclusive_group()
    how.add_argument("-q", "--quiet", action="store_true", help="print only the closing line, warnings and errors")
    how.add_argument("-v", "--verbose", action="store_true",
                     help="print every increment's line (also on a terminal, where one line is rewritten in place)")
    sub = parser.add_subparsers(dest="command", required=True)
    p_run = sub.add_parser("run", help="solve a scene file", parents=[talk],
                           description="Solve a scene (docs/scenes.md) into --out: summary.json, tables, fields, "
                                       "pictures. Exit status 0 done, 2 input error, 3 stopped early, "
                                       "128 + the signal when Ctrl-C or SIGTERM stopped it (docs/reliability.md).")
    p_run.add_argument("scene", type=Path, help=SCENE_HELP)
    p_run.add_argument("-o", "--out", type=Path, required=True, help=OUT_HELP)
    p_run.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="settings", help=SET_HELP)
    p_run.add_argument("--resume", action="store_true",
                       help="a tool scene: continue from the last converged state in --out, on any number of ranks, "
                            "with this scene's stroke (not shorter) and steps; "
                            "refused where anything else differs (docs/reliability.md)")
    p_run.add_argument("--threads", type=int, metavar="N", help=THREADS_HELP)
    p_run.add_argument("--trace", action="store_true",
                       help="tool scenes: log every contact pass, Newton step and iterate (diagnosis)")
    p_check = sub.add_parser("check", help="check a scene and print it resolved, without running it", parents=[talk],
                             description="Check a scene as `shellform run` does (every key, the files it reads, "
                                         "the memory its mesh needs), then print it with every key resolved (a "
                                         "TOML document that `shellform run` accepts) and its estimated cells "
                                         "and memory. Nothing is solved. Exit status 0 valid, 2 input error.")
    p_check.add_argument("scene", type=Path, help=SCENE_HELP)
    p_check.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", dest="settings", help=SET_HELP)
    width = max(map(len, STUDIES))
    p_study = sub.add_parser("study", help="run a study (convergence, accuracy against time, benchmarks)", parents=[talk],
                             formatter_class=argparse.RawDescriptionHelpFormatter,
                             description="Run a study into --out: its tables, plots and log (docs/checked.md gives "
                                         "each one's run time).\n\nstudies:\n"
                                         + "\n".join(f"  {k:<{width}}  {v}" for k, v in STUDIES.items()))
    p_study.add_argument("name", choices=list(STUDIES), metavar="NAME", help="the study (listed above)")
    p_study.add_argument("-o", "--out", type=Path, required=True, help="the folder for the study's tables and plots")
    p_study.add_argument("--threads", type=int, metavar="N", help=THREADS_HELP)
    p_study.add_argument("--quick", action="store_true", help="coarse levels only (for tests)")
    p_study.add_argument("--levels", type=int, nargs="+", metavar="N",
                         help="the mesh levels (n of an n x n quarter) of a study that has levels, instead of its own")
    return parser


def limit_threads(n: int | None) -> None:
    """Cap the element and material loops' threads: shellform.nonlinear.model.use_cores reads
    SHELLFORM_THREADS when a model is built. (Not NUMBA_NUM_THREADS: numba reads it once, when
    it is imported.)"""
    if n is None:
        return
    if n < 1:
        raise InputError("--threads", f"must be at least 1, got {n}")
    os.environ["SHELLFORM_THREADS"] = str(n)


def _scene(args):
    from shellform import scene

    s = scene.load(args.scene)
    return s.changed(scene.settings(args.settings)) if args.settings else s


def check(s) -> str:
    """The scene resolved (TOML) and what its mesh costs, as `shellform check` prints them."""
    from shellform import scene
    from shellform.scene import machine

    machine.check_tool_files(s)  # the checks a run makes of the tools' files before computing
    if s.geometry.file:  # absolute: the printed scene reads the same file from any folder
        s = s.changed({"geometry.file": str(Path(s.geometry.file).resolve())})
    e = machine.estimate(s)
    plastic = f", {e['layers']} points through the thickness" if e["layers"] else ""
    return (scene.to_toml(s) + f"\n# valid: the {s.route} route, about {e['cells']:,} cells{plastic}; "
            f"about {e['bytes'] / 1e9:.2g} GB of memory on one rank (this machine allows "
            f"{e['available_bytes'] / 1e9:.3g} GB)\n")


def main(argv=None) -> int:
    args = _parser().parse_args(argv)

    import logging

    from shellform.nonlinear.interrupt import Interrupted, stop_now
    from shellform.results.disk import DiskFull
    from shellform.results.log import RESULT, console, quiet, say  # every line below once per run, on rank 0

    main_thread = threading.current_thread() is threading.main_thread()
    saved = signal.signal(signal.SIGTERM, stop_now) if main_thread else None  # as Ctrl-C: one line, exit 143
    shown = console(RESULT if args.quiet else logging.DEBUG if args.verbose else logging.INFO)
    try:
        limit_threads(getattr(args, "threads", None))
        if args.command == "run":
            from shellform import run

            summary = run.run(_scene(args), args.out, scene_path=args.scene, trace=args.trace, resume=args.resume)
            say(summary.closing_line(), level=RESULT)
            if summary.stop_line():
                say(summary.stop_line(), file=sys.stderr)
            return summary.exit_status()
        elif args.command == "check":
            say(check(_scene(args)).rstrip("\n"), level=RESULT)
        else:
            import importlib

            study = importlib.import_module(f"shellform.studies.{args.name.replace('-', '_')}")
            kwargs = {"levels": study.QUICK_LEVELS} if args.quick and hasattr(study, "QUICK_LEVELS") else {}
            if args.levels:
                import inspect

                if "levels" not in inspect.signature(study.run).parameters:
                    raise InputError("--levels", f"the study {args.name} has no mesh levels")
                kwargs["levels"] = tuple(args.levels)
            study.run(args.out, **kwargs)
    except InputError as err:
        say(f"shellform: input error: {err}", file=sys.stderr)
        return 2
    except DiskFull as err:  # outside a run's own handling (before stepping: run.json; a study)
        say(f"shellform: disk full: {err}", file=sys.stderr)
        return 3
    except Interrupted as err:  # outside a run's own handling (a study): its state is on disk
        say(f"shellform: {err}" + (f"; the last converged state: {err.checkpoint}" if err.checkpoint else ""),
            file=sys.stderr)
        return 128 + err.signal
    except KeyboardInterrupt as err:  # before any increment converged, or a second Ctrl-C or SIGTERM
        signum = getattr(err, "signal", signal.SIGINT)
        say(f"shellform: interrupted ({signal.Signals(signum).name}); nothing newer than the last checkpoint was kept",
            file=sys.stderr)
        return 128 + signum
    finally:
        quiet(shown)
        if main_thread:
            signal.signal(signal.SIGTERM, saved)
    return 0


if __name__ == "__main__":
    sys.exit(main())
