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
from pathlib import Path

from shellform import __version__  # the package first: the DOLFINx runtime before any solver module
from shellform.errors import InputError


STUDIES = ["plate", "shell", "levy", "rollup", "plastic", "strip", "assembly", "newton", "cup-hard", "cup-mesh",
           "cup-strain", "cup-paper", "numisheet", "numisheet-cost", "cup-benchmark", "outlines", "locking",
           "cup-convergence"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="shellform", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"shellform {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    p_run = sub.add_parser("run", help="solve a scene file",
                           description="Solve a scene (docs/scenes.md) into --out: summary.json, tables, fields, "
                                       "pictures. Exit status 0 done, 2 input error, 3 stopped early, "
                                       "128 + the signal when Ctrl-C or SIGTERM stopped it (docs/reliability.md).")
    p_run.add_argument("scene", type=Path, help="the scene's TOML file")
    p_run.add_argument("--out", type=Path, required=True,
                       help="the output folder, created if missing; a run without --resume clears it of an older "
                            "run's files of the same scene, and refuses it if it holds another scene's run")
    p_run.add_argument("--resume", action="store_true",
                       help="a tool scene: continue from the last converged state in --out, on any number of ranks, "
                            "with this scene's stroke (not shorter), steps, friction and holder force; "
                            "refused where anything else differs (docs/reliability.md)")
    p_run.add_argument("--trace", action="store_true",
                       help="tool scenes: log every contact pass, Newton step and iterate (diagnosis)")
    p_study = sub.add_parser("study", help="run a convergence study")
    p_study.add_argument("name", choices=STUDIES, help="the study (see shellform --help)")
    p_study.add_argument("--out", type=Path, required=True, help="the folder for the study's tables and plots")
    p_study.add_argument("--quick", action="store_true", help="coarse levels only (for tests)")
    args = parser.parse_args(argv)

    from shellform.nonlinear.interrupt import Interrupted
    from shellform.results.log import say  # every line below once per run, on rank 0

    try:
        if args.command == "run":
            from shellform import run, scene

            summary = run.run(scene.load(args.scene), args.out, scene_path=args.scene, trace=args.trace,
                              resume=args.resume)
            say(summary.closing_line())
            if summary.stop_line():
                say(summary.stop_line(), file=sys.stderr)
            return summary.exit_status()
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
