"""The linear system of one Newton iterate: R and K assembled by DOLFINx, solved by MUMPS.

The problem is  R(q, lambda) = f_int(q) - lambda f_ext(q) - sum of the parts' forces = 0  with
known rows: the supports (q_D = lambda qbar_D, in the frames of clamped curved edges where the
scene has them) and the rows the parts make known at this iterate (parts.py), seen in nodal
frames F (rows t0, t1, n). The element arrays are turned into the frames before assembly,
f' = T f, K' = T K T^T with T = diag(F, 1, ...) on each turned node's block (frames.py); the
known rows are Dirichlet rows whose corrections are lifted, so that

    K11 dq1 = -R1 - K12 dq*,   dq* the known corrections

is one DOLFINx system, and the residual's known rows are the reactions (a tool's contact
force on its node's normal row). A support's row on a turned node is the frame's slot k,
F_k . d, which the frames keep on +-e_k (a symmetry plane keeps its meaning with the sign of
the frame): its correction is F_kk (g_k - q_k).

The element loops run once per iterate and their arrays are kept (element_arrays.py: an
iterate at the same q and material state, a pass's first after the set changed, turns the kept
arrays from their frames into today's, T = F F0^T), and a trial leaves its tangent for later:
the element tangents, K's assembly and the parts' stiffness are computed only when a solve
needs them. The solve factorises the free rows alone where that pays (free_rows.py).
"""

import time
from contextlib import contextmanager

import dolfinx.fem.petsc as fem_petsc
import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from shellform.assembly.sheet_element import BS
from shellform.nonlinear.element_arrays import ElementArrays
from shellform.nonlinear.frames import from_frames
from shellform.nonlinear.free_rows import FreeRowsLU, lu_solver
from shellform.nonlinear.parts import Constraints


class System:
    """The carrier q, R, K and their solve, with the parts' constraints (Driver builds on it)."""

    def __init__(self, model, bcs, prescribed=None, pressure=0.0, nodal=None, frames=None, parts=()):
        self.model, self.nodal, self.edge_frames = model, nodal, frames
        self.parts = list(parts)
        V = model.V
        self.q = fem.Function(V, name="carrier")
        self.prescribed = prescribed  # Function with qbar on the Dirichlet dofs (or None: zero)
        self.support_bcs = list(bcs)
        self.support_dofs = np.unique(np.concatenate([bc.dof_indices()[0] for bc in bcs])).astype(np.int32) \
            if bcs else np.zeros(0, dtype=np.int32)
        self.bcs, self.bc_dofs = list(bcs), self.support_dofs.copy()  # the supports and the parts' known rows
        self.g = np.zeros_like(self.q.x.array)  # Dirichlet values at the current load factor
        imap = V.dofmap.index_map
        self.n_owned, self.n_local = imap.size_local, imap.size_local + imap.num_ghosts
        held = np.zeros(self.n_local * BS, dtype=bool)
        held[self.support_dofs] = True
        self.supported = held.reshape(-1, BS)[: self.n_owned]  # carrier slots the supports hold
        # the nodal frames of the parts' constraints, shared with the ghosts
        self.frames = np.tile(np.eye(3), (self.n_local, 1, 1))
        self.rotated = np.zeros(self.n_local, dtype=bool)
        self._shared = [fem.Function(V) for _ in range(3)]  # frames (9 values = 3 x 3), known, flags
        self._known = np.zeros_like(self.g)
        self.arrays = ElementArrays(model, self.edge_frames, bool(self.parts), self.rotated, self.frames)
        self.times = {"element_s": 0.0, "constitutive_s": 0.0, "assembly_s": 0.0, "solve_s": 0.0, "parts_s": 0.0}
        self.f_ext = fem_petsc.create_vector(V)  # external load at lambda = 1: dead pressure
        self.f_ext.set(0.0)
        if pressure:
            model.forms.vectors[:] = pressure * model.pressure_vectors
            fem_petsc.assemble_vector(self.f_ext, model.forms.vector)
            self.f_ext.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        self.A = fem_petsc.create_matrix(model.forms.matrix, kind="baij")
        self.b = fem_petsc.create_vector(V)
        self.dq = fem.Function(V)
        self.ksp = lu_solver(self.A)  # PETSc options (PETSC_OPTIONS, e.g. -mat_mumps_icntl_7 5) may refine it
        self.free_lu = FreeRowsLU(V.mesh.comm, imap.size_local * V.dofmap.index_map_bs,
                                  imap.local_range[0] * V.dofmap.index_map_bs)
        self._stable_rows = self._known_rows_of(self.support_dofs)  # the known rows that stay known
        self._floor = 0.0
        self._later = None  # (lam, elastic_tangent) of a trial whose tangent is not assembled yet (trial)
        self.solves = 0  # linear solves: Newton iterations, those of failed attempts included
        self.residual_full = np.zeros(self.n_owned * BS)

    def displacements(self) -> np.ndarray:
        """(n_owned, 3) the owned nodes' displacements (u, v, w) (a view of the carrier)."""
        return self.q.x.array.reshape(-1, BS)[: self.n_owned, :3]

    # -- constraints -----------------------------------------------------------------------------
    def _in_frames(self) -> np.ndarray:
        """The carrier in the basis the system is solved in (edge frames turned; else q itself)."""
        return self.edge_frames.to_frames(self.q.x.array) if self.edge_frames is not None else self.q.x.array

    def _set_dirichlet(self, lam, dofs=None):
        """g = lam qbar on the supports (or on `dofs`); returns the largest jump |g - q| there."""
        g, d = self.g, self.support_dofs if dofs is None else dofs
        g[d] = lam * self.prescribed.x.array[d] if self.prescribed else 0.0
        return self._largest(g[d] - self._in_frames()[d])

    def constrain(self, lam) -> float:
        """The parts' constraints at the current iterate: nodal frames, known rows and their
        corrections, Dirichlet conditions; then each part follows the frames. Returns the
        largest known correction (all ranks). Without parts the supports are all."""
        if not self.parts:
            return 0.0
        t0 = time.perf_counter()
        n = self.n_owned
        c = Constraints.none(n, BS)
        for part in self.parts:
            part.constrain(c, lam)
        stable = c.stable | self.supported
        self._stable_rows = np.flatnonzero(stable.ravel()).astype(np.int32)
        flags, known = c.flags.astype(float), c.known
        flags[self.supported] = 0.0  # already held by a support (a homogeneous condition)
        known[self.supported] = 0.0
        for fn, values in zip(self._shared, (c.frames.reshape(n, 9), known, flags)):
            fn.x.array[: n * BS] = values.ravel()
            fn.x.scatter_forward()
        self.frames = self._shared[0].x.array.reshape(-1, 3, 3).copy()
        self._known = self._shared[1].x.array
        flag = self._shared[2].x.array.reshape(-1, BS)
        self.rotated = flag[:, :3].any(axis=1) | np.any(np.abs(self.frames - np.eye(3)) > 0, axis=(1, 2))
        self._set_bcs(flag)
        for part in self.parts:
            part.follow(self.frames, lam)
        self.times["parts_s"] += time.perf_counter() - t0
        return self._largest(known)

    def _set_bcs(self, flag):
        V = self.model.V
        bcs = list(self.support_bcs)
        dofs = [bc.dof_indices()[0] for bc in self.support_bcs]
        for slot in range(BS):
            blocks = np.flatnonzero(flag[:, slot] > 0.5)
            if blocks.size:
                d = (BS * blocks + slot).astype(np.int32)
                bcs.append(fem.dirichletbc(np.float64(0), d, V.sub(slot)))
                dofs.append(d)
        self.bcs = bcs
        self.bc_dofs = np.unique(np.concatenate(dofs)).astype(np.int32) if dofs else np.zeros(0, np.int32)

    def correction(self) -> np.ndarray:
        """The known corrections in the solve's coordinates: the parts' (nodal frames) and the
        supports', F_kk (g_k - q_k) on a turned node's slot k (module docstring)."""
        delta = self._known.copy() if self.parts else np.zeros_like(self.q.x.array)
        d = self.support_dofs
        delta[d] = self.g[d] - self._in_frames()[d]
        block, slot = d // BS, d % BS
        turned = (slot < 3) & self.rotated[block]
        delta[d[turned]] *= self.frames[block[turned], slot[turned], slot[turned]]
        return delta

    def to_xyz(self, dq: np.ndarray) -> np.ndarray:
        """A correction in the solve's coordinates (nodal or edge frames) in x, y, z (a copy)."""
        out = self.edge_frames.from_frames(dq) if self.edge_frames is not None else dq.copy()
        from_frames(out, self.rotated, self.frames)
        return out

    # -- residual and tangent ----------------------------------------------------------------
    def residual(self, lam, tangent: bool, elastic_tangent: bool = False):
        """Assemble R (into self.b, Dirichlet rows zero) and optionally K; return (|R_free| with
        the parts' own equations, scale, ev)."""
        self._later = None
        self.q.x.scatter_forward()
        ev = self.arrays.evaluate(self.q, tangent, elastic_tangent, self.rotated, self.frames)
        t0 = time.perf_counter()
        f_int = self.arrays.assemble_vector(self.b)  # the residual's scale: the element forces' norm
        self.b.axpy(-lam, self.f_ext)
        R = self.b.getArray(readonly=False)
        if tangent:
            self.arrays.assemble_matrix(self.A, self.bcs)
        if self.nodal is not None:
            self.nodal.add(lam, self.q.x.array, R, self.A if tangent else None)
        for part in self.parts:
            part.add_residual(R)
        if tangent and self.parts:
            fixed = np.zeros(self.n_local * BS, dtype=bool)
            fixed[self.bc_dofs] = True
            for part in self.parts:
                part.add_tangent(self.A, R, fixed)
        if tangent:
            self.A.assemble()
        self.residual_full = R.copy()  # with the reactions on the Dirichlet rows
        R[self.bc_dofs[self.bc_dofs < R.size]] = 0.0
        del R
        self.times["element_s"] += ev.element_s
        self.times["constitutive_s"] += ev.constitutive_s
        self.times["assembly_s"] += time.perf_counter() - t0
        if tangent:
            self._floor = self.arrays.round_off_floor()
        ext = max([abs(lam) * self.f_ext.norm()] + [abs(lam) * p.magnitude for p in self.parts]
                  + ([abs(lam) * self.nodal.magnitude] if self.nodal is not None else []))
        norm = self.b.norm()
        for part in self.parts:
            norm = float(np.hypot(norm, part.imbalance()))
        return norm, max(f_int, ext, self._floor / self.controls.rtol), ev

    def trial(self, lam, elastic_tangent: bool = False):
        """residual(lam, tangent=True) for Newton's iterates and line-search trials, the tangent
        left for later (assemble_tangent), so that neither the iterate that converges nor a rejected
        trial pays for a K that is never factorised (docs/performance.md). The round-off floor
        of the scale is then the last assembled tangent's."""
        out = self.residual(lam, tangent=False, elastic_tangent=elastic_tangent)
        self._later = (lam, elastic_tangent)
        return out

    @property
    def tangent_pending(self) -> bool:
        """The last trial left its tangent for later."""
        return self._later is not None

    def forget_evaluation(self) -> None:
        """The next residual runs the element loops afresh (no kept arrays)."""
        self.arrays.forget()

    # the element loops run, their arrays reused (a pass's first), the element tangents computed
    evaluations = property(lambda self: self.arrays.evaluations)
    reused = property(lambda self: self.arrays.reused)
    tangents = property(lambda self: self.arrays.tangents)

    @contextmanager
    def linearized(self, lam):
        """linearize(lam) for an observer (the sensitivities): within the block R and K are those
        of the converged q as Newton's iterates see them; after it the parts' iterate state
        (Part.iterate_state) and the residual are as the last iterate left them, so that the run
        goes on as it would have without the observer."""
        held = [part.iterate_state() for part in self.parts]
        residual = self.residual_full.copy()
        try:
            self.linearize(lam)
            yield
        finally:
            for part, state in zip(self.parts, held):
                part.set_iterate_state(state)
            self.residual_full = residual

    def linearize(self, lam, tangent: bool = True) -> float:
        """R (and K) at the current q as Newton's iterates after a pass's first see them: the
        parts' constraints at q, their forces following q. Returns the largest known correction."""
        for part in self.parts:
            part.stepped(True)
        jump = self.constrain(lam)
        self.residual(lam, tangent=tangent)
        return jump

    def assemble_tangent(self) -> None:
        """Assemble the tangent that the last trial left for later (R comes out the same)."""
        if self._later is not None:
            lam, elastic = self._later
            self._later = None
            self.residual(lam, tangent=True, elastic_tangent=elastic)

    def free_tangent(self, lam: float):
        """The tangent at the current q on its free rows, K_ff (scipy CSR), and those rows (the
        unknowns of the nodes' frames: x, y, z and the slopes of a free node; a tool's normal and
        tangents of a node on it), as a Newton iterate at lam sees them: for studying the
        tangent's spectrum (scripts/tangent_modes.py). One rank."""
        import scipy.sparse as sp

        if self.model.mesh.comm.size > 1:
            raise RuntimeError("free_tangent gathers nothing: run it on one rank")
        self.linearize(lam)
        self.assemble_tangent()
        indptr, indices, values = self.A.getValuesCSR()
        K = sp.csr_matrix((values, indices, indptr), shape=self.A.getSize())
        free = np.setdiff1d(np.arange(K.shape[0]), self.bc_dofs)
        return K[free][:, free], free

    def apply_tangent(self, v: np.ndarray) -> np.ndarray:
        """K v on the owned rows with the element tangents as they are (no Dirichlet rows; v a
        local array with ghosts): the change of the residual, reactions included, along v."""
        self.assemble_tangent()
        return self.arrays.apply(v)

    def assembled(self, vectors: np.ndarray) -> np.ndarray:
        """Element vectors in x, y, z (cells, NDOF: SheetModel.respond's) turned into the solve's
        frames and assembled: the owned rows (the model's own arrays as they were)."""
        return self.arrays.assembled(vectors, self.rotated, self.frames)

    def energy_slope(self, dq_xyz: np.ndarray) -> float:
        """dq . R over all ranks, R (free rows, nodal frames) turned back to x, y, z, with the
        parts' own unknowns' shares."""
        R = self.b.getArray(readonly=True).copy()
        if self.edge_frames is not None:
            R = self.edge_frames.from_frames(R)
        from_frames(R, self.rotated, self.frames)
        return self.model.mesh.comm.allreduce(float(np.dot(dq_xyz[: R.size], R)), op=MPI.SUM) + \
            sum(part.slope() for part in self.parts)

    # -- solves ------------------------------------------------------------------------------
    def _lift(self, delta: np.ndarray) -> None:
        """b -= K_fD delta on the free rows, b = delta on the Dirichlet rows (the known jump):
        the element tangents' known columns and the parts' (Part.lift_known)."""
        arr = self.b.getArray(readonly=False)
        arr -= self.apply_tangent(delta)
        for part in self.parts:
            part.lift_known(delta, arr)
        owned = self.bc_dofs[self.bc_dofs < arr.size]
        arr[owned] = delta[owned]
        del arr

    def solve(self, jump) -> bool:
        """dq = -K^-1 R with dq_D = the known corrections (lifted) where jump > 0."""
        self.assemble_tangent()
        t0 = time.perf_counter()
        self.b.scale(-1.0)
        if jump > 0:
            self._lift(self.correction())
        return self._linear_solve(self.dq, t0)

    def solve_lifted(self, delta: np.ndarray, out, extra: np.ndarray | None = None) -> bool:
        """The free rows' response to a jump `delta` on the Dirichlet rows alone (no residual),
        with the factorised tangent: out = K^-1 (-K_fD delta + extra) with out_D = delta
        (`extra`, owned rows: what K_fD delta misses of the assembled tangent's columns)."""
        self.assemble_tangent()
        t0 = time.perf_counter()
        self.b.set(0.0)
        self._lift(delta)
        if extra is not None:
            arr = self.b.getArray(readonly=False)
            arr += extra
            del arr
        return self._linear_solve(out, t0)

    def _known_rows_of(self, dofs) -> np.ndarray:
        return dofs[dofs < self.free_lu.owned]

    def _linear_solve(self, out, t0) -> bool:
        known = self._known_rows_of(self.bc_dofs)
        eliminable = self._stable_rows if self.parts else known  # the known rows that stay known
        if self.free_lu.pays(eliminable):
            ok = self.free_lu.solve(self.A, self.b, out.x.petsc_vec, known, eliminable)
        else:
            self.ksp.solve(self.b, out.x.petsc_vec)
            ok = self.ksp.getConvergedReason() >= 0
        self.solves += 1
        self.times["solve_s"] += time.perf_counter() - t0
        if not self.model.mesh.comm.allreduce(ok, op=MPI.LAND):
            return False
        out.x.scatter_forward()
        return bool(self.model.mesh.comm.allreduce(bool(np.all(np.isfinite(out.x.array))), op=MPI.LAND))

    def _largest(self, x: np.ndarray) -> float:
        """max |x| over all ranks (a decision every rank must take alike)."""
        return self.model.mesh.comm.allreduce(float(np.abs(x).max(initial=0.0)), op=MPI.MAX)

    def _norm(self, x: np.ndarray) -> float:
        """The 2-norm of a carrier array over the owned dofs of all ranks."""
        owned = self.free_lu.owned
        return float(np.sqrt(self.model.mesh.comm.allreduce(float(np.dot(x[:owned], x[:owned])), op=MPI.SUM)))
