"""The constitutive update's cost on the section states of a drawn cup (docs/performance.md,
"The constitutive update and the kernels").

    .venv/bin/python scripts/section_update_cost.py [--n 35] [--stroke 12] [--capture /tmp/section_states.pkl]

Draws the NUMISHEET'93 aluminium cup on n x n to --stroke mm, keeping the inputs of the section
updates of its last increments (strains, committed and last states of every layer), unless
--capture exists already; then times section_update on them, each layer warm-started from its
last state as in the driver, on 1 and 2 threads: the least of 5 sweeps, ms per evaluation. To
compare two commits, run it in a git worktree of each with the same --capture file.
"""

import argparse
import pickle
import time
from pathlib import Path

import shellform  # noqa: F401  (DOLFINx runtime first)

import numpy as np
from mpi4py import MPI

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--n", type=int, default=35)
parser.add_argument("--stroke", type=float, default=12.0)
parser.add_argument("--capture", type=Path, default=Path("/tmp/section_states.pkl"))
args = parser.parse_args()

KEYS = ("strain", "taper", "material", "thickness", "plastic", "finite", "zeta", "wz", "ep_n", "p_n", "ep", "p")

if not args.capture.exists():
    import shellform.nonlinear.model as model
    from shellform.contact.problem import DrawingProblem
    from shellform.studies.cup_benchmark import scene_for

    p = DrawingProblem.from_scene(scene_for(args.n, args.stroke), MPI.COMM_WORLD, verbose=False)
    update, records = model.section_update, []

    def keep(*a):
        if p.driver.lam > 0.93 and len(records) < 40:
            records.append({k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in zip(KEYS, a)})
        return update(*a)

    model.section_update = keep
    p.driver.run(1.0)
    args.capture.write_bytes(pickle.dumps(records))

from shellform.material.update import section_update  # noqa: E402

records = pickle.loads(args.capture.read_bytes())


def sweep(threads: int) -> float:
    total = 0.0
    for r in records:
        nc, nq = r["strain"].shape[:2]
        ep, p = r["ep"].copy(), r["p"].copy()  # the last state: the warm start
        out = np.ones((nc, nq)), np.zeros((nc, nq, 6)), np.zeros((nc, nq, 6, 6))
        t0 = time.perf_counter()
        section_update(*(r[k] for k in KEYS[:10]), ep, p, *out, threads=threads)
        total += time.perf_counter() - t0
    return 1e3 * total / len(records)


layers = sum(r["p_n"].size for r in records) / len(records)
for threads in (1, 2):
    sweep(threads)
    print(f"{len(records)} section updates of {layers:.0f} layers, {threads} thread(s): "
          f"{min(sweep(threads) for _ in range(5)):.1f} ms per evaluation")
