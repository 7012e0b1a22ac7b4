"""What one LU factorisation of the cup's tangent costs, per solver setting (docs/performance.md).

    .venv/bin/python scripts/factorisation_cost.py --n 35 -- -mat_mumps_icntl_35 1 -mat_mumps_cntl_7 1e-8
    .venv/bin/python scripts/factorisation_cost.py --n 35 --stroke 3 --free-rows

Draws the NUMISHEET'93 aluminium cup (shellform.studies.cup_benchmark, n x n quarter) `--stroke`
mm (0.3 by default), then factorises its last tangent once to set up and `--repeat` times more
with the PETSc options after `--` (defaults: MUMPS as the driver uses it), and prints the size,
the factors' entries and flops (MUMPS's INFOG(3), RINFOG(1)) and the fastest refactorisation and
solve. With --free-rows: the free rows only, as the driver factorises them
(shellform/nonlinear/free_rows.py; the copy into AIJ and the submatrix included in the time),
after the whole matrix for comparison.
"""

import argparse
import time

import shellform  # noqa: F401  (the DOLFINx runtime first)
from petsc4py import PETSc

from shellform.contact.problem import DrawingProblem
from shellform.nonlinear.free_rows import FreeRowsLU
from shellform.studies.cup_benchmark import scene_for

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--n", type=int, default=35, help="elements along a side of the quarter (35: 2,450 cells)")
parser.add_argument("--solver", default="mumps", help="PETSc factor package (mumps, petsc)")
parser.add_argument("--repeat", type=int, default=5)
parser.add_argument("--stroke", type=float, default=0.3, help="mm drawn before the tangent is taken")
parser.add_argument("--free-rows", action="store_true", help="also factorise the free rows only (as the driver does)")
parser.add_argument("options", nargs="*", help="PETSc options after --, e.g. -mat_mumps_icntl_35 1")
args = parser.parse_args()

p = DrawingProblem.from_scene(scene_for(args.n, 3.0), verbose=False)
p.driver.run(args.stroke / 3.0)
p.driver.residual(p.driver.lam, tangent=True)  # the converged state's tangent (Newton assembles it only to solve)
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

if args.free_rows:
    d = p.driver
    lu = FreeRowsLU(d.model.mesh.comm, d.free_lu.owned, d.free_lu.first)
    known = d.bc_dofs[d.bc_dofs < lu.owned]
    eliminable = d._eliminable()
    lu.solve(A, b, x, known, eliminable)  # symbolic and first numeric factorisation
    best = float("inf")
    for _ in range(args.repeat):
        A.shift(0.0)
        A.assemble()
        t = time.perf_counter()
        lu.solve(A, b, x, known, eliminable)
        best = min(best, time.perf_counter() - t)
    F = lu._ksp.getPC().getFactorMatrix()
    print(f"free rows: {lu._free.size} of {lu.owned} ({len(known)} known, {len(lu._eliminated)} taken out); "
          f"{F.getMumpsInfog(3):,} factor entries, {F.getMumpsRinfog(1):.3g} flops; "
          f"copy, submatrix, refactorisation + solve {1e3 * best:.0f} ms")
