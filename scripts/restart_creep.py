"""Newton's creep on the friction kink after a restart: the NUMISHEET'93 aluminium cup on n x n
(default 35: 2,450 cells) drawn to --at mm, then resumed for --more mm (docs/performance.md, "The
friction kink"; the variant that kept an overshooting step where slipping nodes stick, measured
there, is no longer in the code).

    .venv/bin/python scripts/restart_creep.py [--n 35] [--at 30] [--more 0.72] [--out /tmp/restart_creep]

A resumed run starts without the predictor's memory, as every run does after a report or a
cut-back: its first Newton steps shorten the slip of nodes on the punch's corner that were
slipping, the slip tangent has no stiffness along the slip, and the step overshoots by the
stick stiffness it meets. Prints the iterations of each resumed increment, their sum, the wall
time and the punch force and DX at the end.
"""

import argparse
import json
import shutil
from pathlib import Path

import shellform  # noqa: F401  (DOLFINx runtime first)

from mpi4py import MPI

from shellform.contact.problem import DrawingProblem
from shellform.contact.run import _resume, run
from shellform.results.cup import draw_in
from shellform.studies.cup_benchmark import scene_for

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--n", type=int, default=35, help="quarter mesh n x n x 2 triangles")
parser.add_argument("--at", type=float, default=30.0, help="stroke of the restart, mm")
parser.add_argument("--more", type=float, default=0.72, help="stroke drawn after the restart, mm")
parser.add_argument("--out", type=Path, default=Path("/tmp/restart_creep"))
args = parser.parse_args()

base = args.out / f"n_{args.n}_at_{args.at:g}"
if not (base / "summary.json").exists():
    run(scene_for(args.n, args.at), base)  # the scene's increments in mm
out = args.out / "resumed"
shutil.rmtree(out, ignore_errors=True)
shutil.copytree(base, out)
s = scene_for(args.n, args.at + args.more)
p = DrawingProblem.from_scene(s, MPI.COMM_WORLD, checkpoint_dir=out, verbose=False)
_resume(p, s, out, MPI.COMM_WORLD)
before = len(p.driver.history)
start = MPI.Wtime()
p.driver.run(1.0)
its = [h.iterations for h in p.driver.history[before:]]
print(json.dumps({"iterations": its, "total": sum(its), "wall_s": round(MPI.Wtime() - start, 1),
                  "punch_force_kN": p.punch_force() / 1e3, "DX_mm": draw_in(p)["DX"]}))
