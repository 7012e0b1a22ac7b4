"""What one LU factorisation of the cup's tangent costs, per solver setting (docs/performance.md).

    .venv/bin/python scripts/factorisation_cost.py --n 35 -- -mat_mumps_icntl_35 1 -mat_mumps_cntl_7 1e-8

Draws the NUMISHEET'93 aluminium cup (shellform.studies.cup_benchmark, n x n quarter) 0.3 mm,
then factorises its last tangent once to set up and `--repeat` times more with the PETSc
options after `--` (defaults: MUMPS as the driver uses it), and prints the size, the factors'
entries and flops (MUMPS's INFOG(3), RINFOG(1)) and the fastest refactorisation and solve.
"""

import argparse
import time

import shellform  # noqa: F401  (the DOLFINx runtime first)
from petsc4py import PETSc

from shellform.contact.problem import DrawingProblem
from shellform.studies.cup_benchmark import scene_for

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--n", type=int, default=35, help="elements along a side of the quarter (35: 2,450 cells)")
parser.add_argument("--solver", default="mumps", help="PETSc factor package (mumps, petsc)")
parser.add_argument("--repeat", type=int, default=5)
parser.add_argument("options", nargs="*", help="PETSc options after --, e.g. -mat_mumps_icntl_35 1")
args = parser.parse_args()

p = DrawingProblem.from_scene(scene_for(args.n, 3.0), verbose=False)
p.driver.run(0.1)
A = p.driver.A
opts = PETSc.Options()
for key, value in zip(args.options[::2], args.options[1::2]):
    opts[key.lstrip("-")] = value
b = A.createVecLeft()
b.set(1.0)
x = b.duplicate()
ksp = PETSc.KSP().create(A.getComm())
ksp.setOperators(A)
ksp.setType("preonly")
ksp.getPC().setType("lu")
ksp.getPC().setFactorSolverType(args.solver)
ksp.setFromOptions()
ksp.solve(b, x)  # symbolic and first numeric factorisation
best = float("inf")
for _ in range(args.repeat):
    A.shift(0.0)  # a changed matrix state with the same pattern: a numeric refactorisation
    A.assemble()
    ksp.setOperators(A)
    t = time.perf_counter()
    ksp.solve(b, x)
    best = min(best, time.perf_counter() - t)
info = A.getInfo()
line = f"{A.getSize()[0]} unknowns, {int(info['nz_used']):,} nonzeros; {args.solver} {' '.join(args.options)}: "
if args.solver == "mumps":
    F = ksp.getPC().getFactorMatrix()
    line += f"{F.getMumpsInfog(3):,} factor entries, {F.getMumpsRinfog(1):.3g} flops; "
print(line + f"refactorisation + solve {1e3 * best:.0f} ms")
