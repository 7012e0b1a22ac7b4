"""The nonlinear sheet's element work per evaluation, with the compatible and with the assumed
membrane strain (docs/locking.md): strain loop, force-only and force-and-tangent passes.

    .venv/bin/python scripts/sheet_element_cost.py --n 35      # 2,450 cells (16: 512)

A quarter of a 100 mm square blank, t = 0.8 mm, elastic-plastic (Swift), at a random small
displacement; each figure is the mean of 5 evaluations after one warm-up. This machine's
timings spread by 30 % from run to run: compare the two lines of one run.
"""

import argparse
import time

import shellform  # noqa: F401  (DOLFINx runtime first)

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from shellform.material import Hill79Material
from shellform.mesh import rectangle
from shellform.nonlinear.model import SheetModel

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--n", type=int, default=35, help="elements along a side of the quarter")
parser.add_argument("--repeat", type=int, default=5)
args = parser.parse_args()

rect = rectangle(MPI.COMM_WORLD, 100.0, 100.0, region="quarter", n=args.n)
material = Hill79Material(E=70000.0, nu=0.33, hardening="swift", K=500.0, eps0=0.01, n=0.25).pack()
base = ("bending", "membrane", "geometric_nonlinearity", "plasticity")
for extra in ((), ("assumed_membrane",)):
    m = SheetModel(rect.mesh, material, 0.8, base + extra)
    q = fem.Function(m.V)
    q.x.array[:] = 1e-3 * np.random.default_rng(0).standard_normal(q.x.array.size)
    m.evaluate(q)  # compile and warm up
    k = m.kernels
    times = []
    for want_tangent in (None, False, True):
        t0 = time.perf_counter()
        for _ in range(args.repeat):
            if want_tangent is None:
                k.strain_loop(m.threads, m.cells, m.cell_coords, m.dofs, q.x.array, m.P, m.consts, m.beta, m.tying, m.z,
                              m.strain)
            else:
                k.tensor_loop(m.threads, m.cells, m.cell_coords, m.P, m.consts, m.beta, m.tying, m.z, m.resultants,
                              m.tangents, m.ironed_d, m.ironed, want_tangent, m.forms.vectors, m.forms.matrices)
        times.append((time.perf_counter() - t0) / args.repeat * 1e3)
    name = "assumed" if extra else "compatible"
    print(f"{name:10s} {m.num_cells} cells, {m.threads} threads: strain loop {times[0]:.1f} ms, force only "
          f"{times[1]:.1f} ms, force and tangent {times[2]:.1f} ms; element work per evaluation with the tangent "
          f"{times[0] + times[2]:.1f} ms")
