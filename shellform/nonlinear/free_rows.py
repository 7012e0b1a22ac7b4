"""The Newton system solved on its free rows only.

DOLFINx assembles the tangent with the known (Dirichlet) rows and columns replaced by the
identity, the known corrections lifted to the right-hand side:

    [ K_ff  0 ] [dq_f]   [b_f]
    [ 0     I ] [dq_k] = [b_k]        so  dq_k = b_k,  K_ff dq_f = b_f.

MUMPS factorises the pattern it is given, and the assembled pattern still couples every known
row to its neighbours (with explicit zeros). In the cup a quarter of the unknowns are known
(the pinched flange's w and slopes, the nodes on the tools' normals, symmetry): factorising
K_ff alone takes half the flops of the whole matrix (1.08e9 -> 5.1e8 on the 2,450-cell
aluminium cup, docs/performance.md). K_ff is taken from the assembled matrix (a copy into AIJ,
whose rows and columns can be picked one by one, then the submatrix). The driver says which
known rows may be taken out (the contact driver: those that stay known); the others stay in
K_ff as identity rows, which solve to their known values. The symbolic factorisation is kept
until a row taken out turns free, and where the rows to take out are too few to pay for the
copies (MIN_SHARE) the whole matrix is factorised instead. The numeric factors are reused for
every solve with the same assembled matrix (the open holder's lift after Newton's step, the
sensitivities' right-hand sides: nonlinear/sensitivity.py).
"""

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc


def lu_solver(A: PETSc.Mat) -> PETSc.KSP:
    """A direct solve with MUMPS; PETSc options (PETSC_OPTIONS) may refine it."""
    ksp = PETSc.KSP().create(A.getComm())
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    ksp.setFromOptions()
    return ksp


class FreeRowsLU:
    """dq = K^-1 b for a tangent K whose known rows and columns are the identity.

    owned: the number of owned scalar unknowns; first: the global index of the first one."""

    GROWTH = 1.1  # known rows beyond the eliminated ones (a fraction of them) before they are eliminated too
    MIN_SHARE = 0.12  # below this share of the rows to take out, the whole matrix is factorised

    def __init__(self, comm, owned: int, first: int):
        self.comm, self.owned, self.first = comm, owned, first
        self._eliminated = None  # the owned known rows taken out of the factorised matrix
        self._factored = None  # (id, state) of the matrix whose factors the solver holds: reused while it is unchanged
        self._free = np.zeros(0, dtype=np.int32)
        self._aij = self._sub = self._ksp = self._is = None
        self._b = self._x = None
        self.symbolic = 0  # symbolic factorisations (each change of the eliminated rows)

    def pays(self, eliminable: np.ndarray) -> bool:
        """Whether taking these rows out pays for the copy, the submatrix and the symbolic
        factorisations it costs: at least MIN_SHARE of all rows. Measured on the aluminium cup's
        2,450 cells on 2 ranks, every known row taken out: once the holder had opened late in
        the stroke, the free rows cost 33 to 49 ms more per iteration than the whole matrix (the
        rows changed at every pass; only the flange's slopes, about 9 % of the rows, stay known
        there); with the pinched flange (15 to 24 % of the rows) they saved 2 to 10 ms."""
        counts = self.comm.allreduce(np.array([eliminable.size, self.owned]), op=MPI.SUM)
        return counts[0] >= self.MIN_SHARE * counts[1]

    def _rows(self, eliminated: np.ndarray) -> None:
        """New rows taken out: a new submatrix and a new symbolic factorisation."""
        for obj in (self._sub, self._ksp, self._is, self._b, self._x):
            if obj is not None:
                obj.destroy()
        mask = np.ones(self.owned, dtype=bool)
        mask[eliminated] = False
        self._eliminated = eliminated.copy()
        self._free = np.flatnonzero(mask).astype(np.int32)
        self._is = PETSc.IS().createGeneral(self._free + np.int32(self.first), comm=self.comm)
        self._sub = self._ksp = None
        self.symbolic += 1

    def _stale(self, known: np.ndarray, eliminable: np.ndarray) -> bool:
        """Whether the rows eliminated so far no longer fit: one of them is free now, or the
        rows that may be eliminated have grown by more than GROWTH of them. Rows that became
        known since stay in K_ff, identity rows that solve to their known value, and the
        symbolic factorisation stays valid."""
        if self._eliminated is None:
            return True
        if eliminable.size > self.GROWTH * max(self._eliminated.size, 1):
            return True
        mask = np.zeros(self.owned, dtype=bool)
        mask[known] = True
        return not mask[self._eliminated].all()

    def solve(self, A: PETSc.Mat, b: PETSc.Vec, x: PETSc.Vec, known: np.ndarray,
              eliminable: np.ndarray | None = None) -> bool:
        """x = A^-1 b with A assembled (its `known` owned rows, local indices, the identity);
        False where the factorisation failed. `eliminable`: the known rows that may be taken out
        (default: all; rows that switch often are better left in, so that the symbolic
        factorisation lasts)."""
        eliminable = known if eliminable is None else np.intersect1d(eliminable, known)
        stale = self._stale(known, eliminable)
        if self.comm.allreduce(stale, op=MPI.LOR):  # every rank takes the new rows
            self._rows(np.sort(eliminable))
            self._factored = None
        same = self._factored == (id(A), A.stateGet())  # A unchanged since its factors were made
        if not self.comm.allreduce(same, op=MPI.LAND):
            self._aij = A.convert("aij", self._aij if self._aij is not None else PETSc.Mat())
            self._sub = self._aij.createSubMatrix(self._is, self._is, self._sub)
            if self._ksp is None:
                self._ksp = lu_solver(self._sub)
                self._x, self._b = self._sub.createVecs()
            else:
                self._ksp.setOperators(self._sub)
            self._factored = (id(A), A.stateGet())
        rhs = b.getArray(readonly=True)
        self._b.getArray()[:] = rhs[self._free]
        self._ksp.solve(self._b, self._x)
        out = x.getArray()
        out[self._free] = self._x.getArray(readonly=True)
        out[known] = rhs[known]
        return self._ksp.getConvergedReason() >= 0
