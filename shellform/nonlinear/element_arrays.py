"""The element arrays of one Newton iterate: the model's element loop run or reused, its
vectors and matrices turned into the solve's frames, and what is assembled from them.

The element loop (SheetModel.evaluate) writes one vector f and one matrix K per owned cell
into the model's cell-array forms (assemble.py), in x, y, z. Before DOLFINx assembles them they
are turned into the frames the system is solved in: a clamped curved edge's frames (the
edge frames, fixed for the run) and the parts' nodal frames F of the iterate (rows t0, t1, n),
f' = T f, K' = T K T^T with T = diag(F, 1, ...) on each turned node's block (frames.py).

The arrays are kept with the frames they were turned into: an iterate at the same q, the same
committed material state and the tangent asked for (a pass's first, after the parts' set
changed) turns the kept arrays from those frames F0 into today's, T = F F0^T (orthogonal, so
exact to round-off), instead of running the loop again; one whose tangent was left for later
computes the element tangents alone. The counts say how often each happened (summary.json
"element_evaluations").

They are assembled here, the vectors into R (with their norm, the residual's scale) and the
matrices into K (with the Dirichlet rows), before the parts add theirs. From the kept matrices
come the tangent's products K v (the lifted known rows, the parts'
bordered solves) without the matrix, and any element vectors in x, y, z (the sensitivities'
pseudo-loads) are turned and assembled the same way. The system (system.py) owns the carrier
and the frames and tells every call the iterate's (rotated, frames); this part owns the kept
arrays and their frames.
"""

import time
from dataclasses import replace

import dolfinx.fem.petsc as fem_petsc
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from shellform.nonlinear.frames import rotate_cell_arrays


class ElementArrays:
    """The model's element arrays between its element loop and assembly (module docstring).
    edge_frames: the clamped curved edges' frames (or None); nodal: whether the parts turn
    nodes into frames; rotated, frames: the nodal frames the arrays start in (none turned)."""

    def __init__(self, model, edge_frames, nodal: bool, rotated: np.ndarray, frames: np.ndarray):
        self.model, self.edge_frames, self.nodal = model, edge_frames, nodal
        self.turned = (rotated.copy(), frames.copy())  # the nodal frames the kept arrays are in
        self.memo = None  # the last evaluation (evaluate)
        self.evaluations = self.reused = 0  # of the element loops: run, and reused (a pass's first)
        self.tangents = 0  # element tangents computed (at most one per evaluation)

    def evaluate(self, q, tangent: bool, elastic_tangent: bool, rotated: np.ndarray, frames: np.ndarray):
        """The element loops at q (a Function), turned into the solve's frames; or the last
        evaluation's arrays, turned from its frames into today's, where q, the committed
        material state and the tangent asked for are those of the last evaluation (a pass starts
        where the one before ended: only its set and frames changed). Returns the Evaluation."""
        m, memo, x = self.model, self.memo, q.x.array
        same = (memo is not None and memo["version"] == m.state_version and np.array_equal(memo["q"], x)
                and (not tangent or memo["elastic"] == elastic_tangent))
        if same and (memo["tangent"] or not tangent):
            self._reframe(memo["tangent"], rotated, frames)
            self.reused += 1
            return replace(memo["ev"], element_s=0.0, constitutive_s=0.0)
        if same:  # the state's tangent, left for later (trial): the element tangents alone
            t0 = time.perf_counter()
            m.tensor_arrays(tangent=True)
            seconds = time.perf_counter() - t0
            self.tangents += 1
            self._turn(True, rotated, frames)
            memo["tangent"] = True
            return replace(memo["ev"], element_s=seconds, constitutive_s=0.0)
        ev = m.evaluate(q, tangent=tangent, elastic_tangent=elastic_tangent)
        self.tangents += tangent
        if m.mesh.comm.size > 1:  # every rank takes the same branch on a failed update: global counts
            counts = m.mesh.comm.allreduce(np.array([ev.plastic_layers, ev.failures, ev.guard]), op=MPI.SUM)
            ev = replace(ev, plastic_layers=int(counts[0]), failures=int(counts[1]), guard=int(counts[2]))
        self.evaluations += 1
        self._turn(tangent, rotated, frames)
        self.memo = {"version": m.state_version, "tangent": tangent, "elastic": elastic_tangent, "q": x.copy(),
                     "ev": ev}
        return ev

    def forget(self) -> None:
        """The next evaluation runs the element loops afresh (no kept arrays)."""
        self.memo = None

    def _turn(self, tangent: bool, rotated: np.ndarray, frames: np.ndarray) -> None:
        """Between the element loop and assembly: the arrays into the solve's frames, which
        the kept arrays are in from now on."""
        self._into_frames(tangent, rotated, frames)
        if self.nodal:
            self.turned = (rotated.copy(), frames.copy())

    def _into_frames(self, tangent: bool, rotated: np.ndarray, frames: np.ndarray) -> None:
        """The model's element vectors (and matrices, with `tangent`) from x, y, z into the edge
        frames and the nodal frames."""
        m = self.model
        if self.edge_frames is not None:
            self.edge_frames.turn_cell_arrays(m.dofs, m.forms.vectors, m.forms.matrices, tangent)
        if self.nodal:
            rotate_cell_arrays(m.dofs, rotated, frames, m.forms.vectors, m.forms.matrices, tangent)

    def _reframe(self, tangent: bool, rotated: np.ndarray, frames: np.ndarray) -> None:
        """The kept arrays from the frames F0 they were turned into to the current F: T = F F0^T
        on every block turned in either (F0 = I on a block that was not turned). The edge
        frames never change."""
        if not self.nodal:
            return
        m = self.model
        rotated0, F0 = self.turned
        turn = rotated0 | rotated
        G = np.einsum("nij,nkj->nik", frames, F0)
        rotate_cell_arrays(m.dofs, turn, G, m.forms.vectors, m.forms.matrices, tangent)
        self.turned = (rotated.copy(), frames.copy())

    def assemble_vector(self, b) -> float:
        """b = the element vectors assembled (a PETSc vector, ghosts added to their owners);
        returns the 2-norm of the element vectors over all ranks: the residual's scale, the
        element forces before they cancel in the sum (round-off)."""
        m = self.model
        with b.localForm() as bl:
            bl.set(0.0)
        fem_petsc.assemble_vector(b, m.forms.vector, constants=m.forms.constants, coeffs=m.forms.vector_coeffs)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        return np.sqrt(m.mesh.comm.allreduce(float(np.sum(m.forms.vectors**2)), op=MPI.SUM))

    def assemble_matrix(self, A, bcs) -> None:
        """A = the element matrices assembled with the Dirichlet conditions bcs (flushed: the
        parts add to it before the final assembly)."""
        m = self.model
        A.zeroEntries()
        fem_petsc.assemble_matrix(A, m.forms.matrix, bcs=bcs, constants=m.forms.constants, coeffs=m.forms.matrix_coeffs)
        A.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)
        A.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)

    def round_off_floor(self) -> float:
        """The residual's round-off floor: 1e3 eps times the largest diagonal entry of the
        element matrices (all ranks) times a cell size."""
        m = self.model
        kmax = float(np.abs(np.einsum("cii->ci", m.forms.matrices)).max()) if m.num_cells else 0.0
        return 1e3 * np.finfo(float).eps * m.mesh.comm.allreduce(kmax, op=MPI.MAX) * m.cell_size

    def apply(self, v: np.ndarray) -> np.ndarray:
        """K v on the owned rows with the element tangents as they are (no Dirichlet rows; v a
        local array with ghosts). The element vectors are overwritten: the next evaluation
        runs the loops afresh."""
        m = self.model
        self.memo = None
        m.forms.vectors[:] = np.einsum("cij,cj->ci", m.forms.matrices, v[m.unrolled_dofs])
        return self._assemble_vectors()

    def assembled(self, vectors: np.ndarray, rotated: np.ndarray, frames: np.ndarray) -> np.ndarray:
        """Element vectors in x, y, z (cells, NDOF: SheetModel.respond's) turned into the solve's
        frames and assembled: the owned rows (the model's own arrays as they were)."""
        m = self.model
        kept = m.forms.vectors.copy()
        m.forms.vectors[:] = vectors
        self._into_frames(False, rotated, frames)
        out = self._assemble_vectors()
        m.forms.vectors[:] = kept
        return out

    def _assemble_vectors(self) -> np.ndarray:
        """The element vectors as they are, assembled: the local array (a copy)."""
        m = self.model
        vec = fem_petsc.assemble_vector(m.forms.vector, constants=m.forms.constants, coeffs=m.forms.vector_coeffs)
        vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        out = vec.getArray(readonly=True).copy()
        vec.destroy()
        return out
