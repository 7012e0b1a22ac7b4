"""The incremental Newton driver: load factor stepping, cut-back, growth, checkpoints.

The problem is  R(q, lambda) = f_int(q) - lambda f_ext(q) = 0  with prescribed values
q_D = lambda qbar_D on the Dirichlet dofs (loads and prescribed displacements share lambda).
Each increment lambda_n -> lambda_n + dlambda:

    predictor   q = q_n + (dlambda / dlambda_prev) (q_n - q_n-1) (after a converged increment)
    Newton      K dq = -R (consistent tangent) with dq_D = lambda qbar_D - q_D in the first
                iteration (lifted, so a prescribed displacement spreads through the structure
                by the converged tangent), dq_D = 0 after; q += alpha dq
    line search on the energy slope s(alpha) = dq . R(q + alpha dq): alpha = 1 unless the step
                overshoots the energy minimum along dq (s(1) > |s(0)|), then secant steps
                towards s = 0; halved where the material update fails or |R| is not finite.
                Not in the lifted iteration (a prescribed jump): s(0) on the free rows is about
                zero there (a converged start) and is no energy slope of the whole move
    converged   |R_free| <= rtol max(|lambda f_ext|, |element forces|) or below the round-off
                floor 1e3 eps max(K_ii) h (a very thin sheet), or a correction at
                round-off level (|dq| <= stol |q|) with |R_free| <= 1e3 rtol max(...)

A failing increment (too many iterations, a non-finite value, a failed return mapping, no
descent) is restored and retried with dlambda / 4; an easy one (few iterations) lets the next
grow by 1.5. Below min_step the run stops with ConvergenceFailure, after writing the last
converged state to disk. Nothing non-finite is ever committed.
"""

import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import dolfinx.fem.petsc as fem_petsc
import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from shellform.errors import InputError
from shellform.nonlinear import checkpoint
from shellform.nonlinear.free_rows import FreeRowsLU, lu_solver
from shellform.nonlinear.interrupt import Interrupted, StopRequests
from shellform.results.log import Progress
from shellform.results.tables import write_json


class ConvergenceFailure(RuntimeError):
    """The driver could not continue; the last converged state is on disk (``checkpoint``)."""

    def __init__(self, message, checkpoint=None):
        super().__init__(message + (f" (last converged state: {checkpoint})" if checkpoint else ""))
        self.checkpoint = checkpoint


def shorten(alpha: float, s0: float, s1: float) -> float | None:
    """The line search on the energy slope s(alpha) = dq . R(q + alpha dq): None where alpha is
    kept (s1 <= |s0|, not past the energy minimum along dq by much, or no descent s0 >= 0), else
    a shorter alpha by a secant step towards s = 0, by a factor in [0.1, 0.5]."""
    if s1 <= abs(s0) or s0 >= 0:
        return None
    return alpha * max(0.1, min(0.5, s0 / (s0 - s1)))


@dataclass
class Controls:
    initial_step: float = 0.1  # first dlambda
    min_step: float = 1e-4
    max_step: float = 0.25
    max_iterations: int = 12
    rtol: float = 1e-9  # |R_free| <= rtol * max(|element forces|, |lambda f_ext|)
    stol: float = 1e-13  # or a Newton correction at round-off: |dq|_inf <= stol |q|_inf
    easy_iterations: int = 4  # converged in at most this many: grow the next step by `growth`
    growth: float = 1.5
    cut: float = 0.25
    line_search: int = 6  # halvings

    def check(self):
        for name in ("initial_step", "min_step", "max_step", "rtol"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"process.{name}", f"must be > 0, got {v}")
        if self.min_step > self.initial_step or self.initial_step > self.max_step:
            raise InputError("process.initial_step", "needs min_step <= initial_step <= max_step")
        if self.max_iterations < 1:
            raise InputError("process.max_iterations", f"must be >= 1, got {self.max_iterations}")


@dataclass
class Increment:
    number: int
    lam: float
    dlam: float
    iterations: int
    residuals: list[float]
    plastic_layers: int
    cutbacks: int
    seconds: dict = field(default_factory=dict)
    contact: dict = field(default_factory=dict)  # contact passes, set changes (contact driver)
    change: float = 0.0  # |q_n+1 - q_n|, 2-norm over all ranks (the path's stiffness: |dlam| / change)


class Driver:
    """Newton on the sheet model with DOLFINx assembly and a MUMPS LU solve."""

    def __init__(self, model, bcs, prescribed=None, pressure=0.0, nodal=None, controls=None,
                 checkpoint_dir=None, verbose=True, frames=None):
        """bcs: Dirichlet conditions of the carrier (values = the prescribed values at lambda = 1,
        held in the `prescribed` Function, or homogeneous); pressure: dead pressure at lambda = 1;
        nodal: shellform.nonlinear.loads.NodalLoads; frames: shellform.edge_frames.SheetEdgeFrames
        of clamped curved edges (the system is solved in their frames, the state kept in x, y)."""
        self.model, self.bcs, self.nodal, self.edge_frames = model, bcs, nodal, frames
        self.controls = controls or Controls()
        self.controls.check()
        self.easy_iterations = self.controls.easy_iterations  # an increment this easy lets the next grow
        self.checkpoint_dir = Path(checkpoint_dir) if checkpoint_dir else None
        self.verbose = verbose
        self.progress = Progress()  # a run sets its own (label, total, unit)
        self.stops = StopRequests(model.mesh.comm)  # Ctrl-C and SIGTERM while it steps (interrupt.py)
        self.fingerprint = {}  # what defines the run, written into its checkpoints (set by a run)
        self._numbering = None  # the checkpoints' global numbers of nodes and cells (numbering())
        V = model.V
        self.q = fem.Function(V, name="carrier")
        self.q_n = self.q.x.array.copy()  # the carrier of the last converged increment
        self.prescribed = prescribed  # Function with qbar on the Dirichlet dofs (or None: zero)
        self.bc_dofs = np.unique(np.concatenate([bc.dof_indices()[0] for bc in bcs])).astype(np.int32) \
            if bcs else np.zeros(0, dtype=np.int32)
        self.g = np.zeros_like(self.q.x.array)  # Dirichlet values at the current load factor
        self.lam = 0.0
        self.history: list[Increment] = []
        self.times = {"element_s": 0.0, "constitutive_s": 0.0, "assembly_s": 0.0, "solve_s": 0.0}
        # external load at lambda = 1: dead pressure (element vectors assembled once)
        self.f_ext = fem_petsc.create_vector(V)
        self.f_ext.set(0.0)
        if pressure:
            model.forms.vectors[:] = pressure * model.pressure_vectors
            fem_petsc.assemble_vector(self.f_ext, model.forms.vector)
            self.f_ext.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        self.A = fem_petsc.create_matrix(model.forms.matrix, kind="baij")
        self.b = fem_petsc.create_vector(V)
        self.dq = fem.Function(V)
        self.ksp = lu_solver(self.A)  # PETSc options (PETSC_OPTIONS, e.g. -mat_mumps_icntl_7 5) may refine it
        imap = V.dofmap.index_map
        self.free_lu = FreeRowsLU(V.mesh.comm, imap.size_local * V.dofmap.index_map_bs,
                                  imap.local_range[0] * V.dofmap.index_map_bs)
        self._dlam_prev = None
        self._direction = None
        self._steps = None  # between two increments of run(): (the next dlam, the last one, q before it)
        self._resumed_steps = None  # (dlam, dlam_prev, q_prev) a checkpoint gave the next run() to step on with
        self._floor = 0.0
        self._cause = ""  # why the last Newton attempt failed, in words
        self.searching = True  # the energy line search on; an increment that fails swaps it once
        self._memo = None  # the last evaluation (_evaluate)
        self._later = None  # (lam, elastic_tangent) of a trial whose tangent is not assembled yet (_trial)
        self.evaluations = self.reused = 0  # of the element loops: run, and reused (a contact pass's first)
        self.tangents = 0  # element tangents computed (at most one per evaluation)
        self.solves = 0  # linear solves: Newton iterations, those of failed attempts included

    # -- residual and tangent ----------------------------------------------------------------
    def _in_frames(self) -> np.ndarray:
        """The carrier in the basis the system is solved in (edge frames turned; else q itself)."""
        return self.edge_frames.to_frames(self.q.x.array) if self.edge_frames is not None else self.q.x.array

    def _set_dirichlet(self, lam, dofs=None):
        """g = lam qbar on the Dirichlet dofs (or on `dofs`); returns the largest jump |g - q| there."""
        g, d = self.g, self.bc_dofs if dofs is None else dofs
        g[d] = lam * self.prescribed.x.array[d] if self.prescribed else 0.0
        return self._largest(g[d] - self._in_frames()[d])

    def residual(self, lam, tangent: bool, elastic_tangent: bool = False):
        """Assemble R (into self.b, Dirichlet rows zero) and optionally K; return (|R_free|, scale, ev)."""
        m = self.model
        self._later = None
        self.q.x.scatter_forward()
        ev = self._evaluate(tangent, elastic_tangent)
        t0 = time.perf_counter()
        with self.b.localForm() as bl:
            bl.set(0.0)
        fem_petsc.assemble_vector(self.b, m.forms.vector, constants=m.forms.constants, coeffs=m.forms.vector_coeffs)
        self.b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        # scale of the residual: the element forces before they cancel in the sum (round-off)
        f_int = np.sqrt(m.mesh.comm.allreduce(float(np.sum(m.forms.vectors**2)), op=MPI.SUM))
        self.b.axpy(-lam, self.f_ext)
        R = self.b.getArray(readonly=False)
        if tangent:
            self.A.zeroEntries()
            fem_petsc.assemble_matrix(self.A, m.forms.matrix, bcs=self.bcs, constants=m.forms.constants,
                                      coeffs=m.forms.matrix_coeffs)
            self.A.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)
            self.A.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)
        if self.nodal is not None:
            self.nodal.add(lam, self.q.x.array, R, self.A if tangent else None)
        if tangent:
            self.A.assemble()
        self.residual_full = R.copy()  # with the reactions on the Dirichlet rows
        R[self.bc_dofs[self.bc_dofs < R.size]] = 0.0
        del R
        self.times["element_s"] += ev.element_s
        self.times["constitutive_s"] += ev.constitutive_s
        self.times["assembly_s"] += time.perf_counter() - t0
        if tangent:  # the residual's round-off floor: eps times stiffness times a cell size
            kmax = float(np.abs(np.einsum("cii->ci", m.forms.matrices)).max()) if m.num_cells else 0.0
            self._floor = 1e3 * np.finfo(float).eps * m.mesh.comm.allreduce(kmax, op=MPI.MAX) * m.cell_size
        ext = abs(lam) * self.f_ext.norm()
        if self.nodal is not None:
            ext = max(ext, abs(lam) * self.nodal.magnitude)
        return self.b.norm(), max(f_int, ext, self._floor / self.controls.rtol), ev

    def _evaluate(self, tangent: bool, elastic_tangent: bool):
        """The element loops at q, turned into the solve's frames (_element_arrays); or the last
        evaluation's arrays, turned from its frames into today's, where q, the committed material
        state and the tangent asked for are those of the last evaluation (a contact pass starts
        where the one before ended: only its set and frames changed). Returns the Evaluation."""
        m, memo, q = self.model, self._memo, self.q.x.array
        same = (memo is not None and memo["version"] == m.state_version and np.array_equal(memo["q"], q)
                and (not tangent or memo["elastic"] == elastic_tangent))
        if same and (memo["tangent"] or not tangent):
            self._reframe_element_arrays(memo["tangent"])
            self.reused += 1
            return replace(memo["ev"], element_s=0.0, constitutive_s=0.0)
        if same:  # the state's tangent, left for later (_trial): the element tangents alone
            t0 = time.perf_counter()
            m.tensor_arrays(tangent=True)
            seconds = time.perf_counter() - t0
            self.tangents += 1
            self._element_arrays(True)
            memo["tangent"] = True
            return replace(memo["ev"], element_s=seconds, constitutive_s=0.0)
        ev = m.evaluate(self.q, tangent=tangent, elastic_tangent=elastic_tangent)
        self.tangents += tangent
        if m.mesh.comm.size > 1:  # every rank takes the same branch on a failed update: global counts
            counts = m.mesh.comm.allreduce(np.array([ev.plastic_layers, ev.failures, ev.guard]), op=MPI.SUM)
            ev = replace(ev, plastic_layers=int(counts[0]), failures=int(counts[1]), guard=int(counts[2]))
        self.evaluations += 1
        self._element_arrays(tangent)
        self._memo = {"version": m.state_version, "tangent": tangent, "elastic": elastic_tangent, "q": q.copy(),
                      "ev": ev}
        return ev

    def _trial(self, lam, elastic_tangent: bool = False):
        """residual(lam, tangent=True) for Newton's iterates and line-search trials, the tangent
        left for later: the element tangents, K's assembly and its nodal terms are computed only
        when a solve needs them (_tangent_now), so that neither the iterate that converges nor a
        rejected trial pays for a K that is never factorised (docs/performance.md). The round-off
        floor of the scale is then the last assembled tangent's."""
        out = self.residual(lam, tangent=False, elastic_tangent=elastic_tangent)
        self._later = (lam, elastic_tangent)
        return out

    def _tangent_now(self) -> None:
        """Assemble the tangent that the last _trial left for later: the element tangents from
        that evaluation's stresses and section tangents, then residual and K as residual() does
        (R comes out the same)."""
        if self._later is not None:
            lam, elastic = self._later
            self._later = None
            self.residual(lam, tangent=True, elastic_tangent=elastic)

    def _reframe_element_arrays(self, tangent: bool) -> None:
        """Hook: turn the element arrays of the last evaluation from the frames they were turned
        into to the current ones (the edge frames never change: nothing to do)."""

    def _element_arrays(self, tangent: bool) -> None:
        """Hook between the element loop and assembly: the edge frames turn the arrays here (the
        contact driver rotates its nodal frames instead)."""
        if self.edge_frames is not None:
            m = self.model
            self.edge_frames.turn_cell_arrays(m.dofs, m.forms.vectors, m.forms.matrices, tangent)

    def _correction(self) -> np.ndarray:
        """The known correction dq_D on the Dirichlet dofs (zero elsewhere)."""
        delta = np.zeros_like(self.q.x.array)
        delta[self.bc_dofs] = self.g[self.bc_dofs] - self._in_frames()[self.bc_dofs]
        return delta

    def _increment_info(self) -> dict:
        return {}

    def _commit(self) -> None:
        """Accept the increment's state."""
        self.model.commit()

    def _restore_converged(self) -> None:
        """Before a stop: make every derived quantity (residual, reactions) that of the last
        converged state, which q already holds, so that what is reported is that state."""
        self.model.converged_lever()
        self._set_dirichlet(self.lam)
        self.residual(self.lam, tangent=False)

    def apply_tangent(self, v: np.ndarray) -> np.ndarray:
        """K v on the owned rows with the element tangents as they are (no Dirichlet rows; v a
        local array with ghosts): the change of the residual, reactions included, along v."""
        self._tangent_now()
        m = self.model
        self._memo = None  # the element vectors are overwritten here
        m.forms.vectors[:] = np.einsum("cij,cj->ci", m.forms.matrices, v[m.unrolled_dofs])
        Kv = fem_petsc.assemble_vector(m.forms.vector, constants=m.forms.constants, coeffs=m.forms.vector_coeffs)
        Kv.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        out = Kv.getArray(readonly=True).copy()
        Kv.destroy()
        return out

    def _lift(self, delta: np.ndarray) -> None:
        """b -= K_fD delta on the free rows, b = delta on the Dirichlet rows (the known jump)."""
        arr = self.b.getArray(readonly=False)
        arr -= self.apply_tangent(delta)
        owned = self.bc_dofs[self.bc_dofs < arr.size]
        arr[owned] = delta[owned]
        del arr

    def _solve(self, jump):
        """dq = -K^-1 R with dq_D = g - q_D (lifted: the free rows see -K_fD (g - q_D))."""
        self._tangent_now()
        t0 = time.perf_counter()
        self.b.scale(-1.0)
        if jump > 0:
            self._lift(self._correction())
        return self._linear_solve(self.dq, t0)

    def solve_lifted(self, delta: np.ndarray, out, extra: np.ndarray | None = None) -> bool:
        """The free rows' response to a jump `delta` on the Dirichlet rows alone (no residual),
        with the factorised tangent: out = K^-1 (-K_fD delta + extra) with out_D = delta
        (`extra`, owned rows: what K_fD delta misses of the assembled tangent's columns)."""
        self._tangent_now()
        t0 = time.perf_counter()
        self.b.set(0.0)
        self._lift(delta)
        if extra is not None:
            arr = self.b.getArray(readonly=False)
            arr += extra
            del arr
        return self._linear_solve(out, t0)

    def _known_rows(self) -> np.ndarray:
        """The owned known (Dirichlet) rows, local indices."""
        return self.bc_dofs[self.bc_dofs < self.free_lu.owned]

    def _eliminable(self) -> np.ndarray:
        """The known owned rows the free-row solve may take out (here: all of them)."""
        return self._known_rows()

    def _linear_solve(self, out, t0) -> bool:
        eliminable = self._eliminable()
        if self.free_lu.pays(eliminable):
            ok = self.free_lu.solve(self.A, self.b, out.x.petsc_vec, self._known_rows(), eliminable)
        else:
            self.ksp.solve(self.b, out.x.petsc_vec)
            ok = self.ksp.getConvergedReason() >= 0
        self.solves += 1
        self.times["solve_s"] += time.perf_counter() - t0
        if not self.model.mesh.comm.allreduce(ok, op=MPI.LAND):
            return False
        out.x.scatter_forward()
        return bool(self.model.mesh.comm.allreduce(bool(np.all(np.isfinite(out.x.array))), op=MPI.LAND))

    # -- one increment -------------------------------------------------------------------------
    def _newton(self, lam, reversal=False):
        """Newton at load factor lam from the current q; returns (converged, iterations, residuals, ev).
        After a load reversal the first tangent is the elastic one (elastic unloading)."""
        c = self.controls
        jump = self._set_dirichlet(lam)
        norm, scale, ev = self._trial(lam, elastic_tangent=reversal)
        residuals, step = [norm], np.inf
        for it in range(1, c.max_iterations + 1):
            if not np.isfinite(norm) or ev.failed:
                self._cause = ev.cause() or "the residual is not finite"
                return False, it, residuals, ev
            if norm <= c.rtol * scale and jump == 0:
                return True, it - 1, residuals, ev
            if step <= c.stol * self._largest(self.q.x.array) and norm <= 1e3 * c.rtol * scale:
                return True, it - 1, residuals, ev
            R0 = self.b.copy()
            ok = self._solve(jump)
            if not ok:
                R0.destroy()
                self._cause = "the linear solve failed (singular tangent or a non-finite correction)"
                return False, it, residuals, ev
            x0 = self.q.x.array.copy()
            s0 = self.dq.x.petsc_vec.dot(R0)  # dq . R(q) = -dq . K dq < 0: the energy slope
            alpha, accepted = 1.0, False
            step_xy = (self.edge_frames.from_frames(self.dq.x.array) if self.edge_frames is not None
                       else self.dq.x.array)
            for _ in range(c.line_search + 1):
                self.q.x.array[:] = x0 + alpha * step_xy
                trial, scale, ev = self._trial(lam)
                if not np.isfinite(trial) or ev.failed:
                    alpha *= 0.5  # outside the material's reach: shorten
                    continue
                # The lifted iteration moves the prescribed dofs: its slope on the free rows
                # (about zero at a converged start) says nothing of the energy: full step.
                searching = self.searching and jump == 0
                shorter = shorten(alpha, s0, self.dq.x.petsc_vec.dot(self.b)) if searching else None
                if shorter is None:
                    accepted = True
                    break
                alpha = shorter
            R0.destroy()
            if not accepted:
                self._cause = f"the line search found no acceptable step ({ev.cause() or 'no energy descent'})"
                return False, it, residuals, ev
            if alpha < 1.0 and jump > 0:
                held = self._in_frames()
                held[self.bc_dofs] = self.g[self.bc_dofs]  # the prescribed values
                self.q.x.array[:] = self.edge_frames.from_frames(held) if self.edge_frames is not None else held
                trial, scale, ev = self._trial(lam)
            jump = 0.0
            norm = trial
            step = alpha * self._largest(self.dq.x.array)
            residuals.append(norm)
        converged = np.isfinite(norm) and norm <= c.rtol * scale
        if not converged:
            self._cause = f"no convergence in {c.max_iterations} iterations"
        return converged, c.max_iterations, residuals, ev

    def limit_point(self, failed: float, softening: float = 0.05) -> str | None:
        """Why stepping stopped, where the load cannot grow further: a limit point of the path
        (a collapse load, a snap-through). Along the path the stiffness k_n = |dlambda_n| / |dq_n|
        of the converged increments has fallen below `softening` times the first one's; the limit
        load factor is estimated where k, extrapolated linearly in lambda from the last two
        increments, reaches zero, within [the last converged lambda, the failed one]. None where
        the stiffness held up (a failure of another kind)."""
        path = [h for h in self.history if h.change > 0]
        if len(path) < 2:
            return None
        k = [abs(h.dlam) / h.change for h in path]
        if k[-1] > softening * k[0]:
            return None
        lam_c, lam_b = path[-1].lam, path[-2].lam
        slope = (k[-1] - k[-2]) / (lam_c - lam_b)  # dk / dlambda
        estimate = lam_c - k[-1] / slope if slope * (failed - lam_c) < 0 else failed
        lo, hi = sorted((lam_c, failed))
        estimate = min(max(estimate, lo), hi)
        return (f"the structure reached its limit load at about load factor {estimate:.4g} (last converged "
                f"{lam_c:.6g}; no equilibrium found at {failed:.6g}): along the path its stiffness "
                f"|dlambda|/|dq| fell to {k[-1] / k[0]:.2g} times the first increment's")

    def _norm(self, x: np.ndarray) -> float:
        """The 2-norm of a carrier array over the owned dofs of all ranks."""
        owned = self.free_lu.owned
        return float(np.sqrt(self.model.mesh.comm.allreduce(float(np.dot(x[:owned], x[:owned])), op=MPI.SUM)))

    def _largest(self, x: np.ndarray) -> float:
        """max |x| over all ranks (a decision every rank must take alike)."""
        return self.model.mesh.comm.allreduce(float(np.abs(x).max(initial=0.0)), op=MPI.MAX)

    def _predict(self, dlam, x_n, x_prev):
        if self._dlam_prev:
            self.q.x.array[:] = x_n + (dlam / self._dlam_prev) * (x_n - x_prev)
        else:
            self.q.x.array[:] = x_n

    swap_line_search = True  # the contact driver has a line search of its own

    def _other_line_search(self, lam, reversal, dlam, x_n, x_prev, its):
        """Retry a failed increment with the energy line search swapped (off if it was on), and
        keep the swap while it converges. A thin sheet needs it off: Newton's first step bends it
        with the membrane unbalanced, past the energy minimum along that step, and converges from
        there in a few iterations, where a line search would creep (docs/locking.md)."""
        cause = self._cause
        self.searching = not self.searching
        self._predict(dlam, x_n, x_prev)
        ok, its2, res, ev = self._newton(lam, reversal)
        if not ok:
            self.searching = not self.searching
            self._cause = f"{cause}; with the line search {'on' if self.searching else 'off'}: {self._cause}"
        return ok, its + its2, res, ev

    def continue_from(self, lam: float) -> None:
        """q holds a converged state at load factor lam, reached from 0 (another driver's, or a
        state set by hand): the next run() steps on from there, a load reversal where it goes
        back towards 0 (its first tangent the elastic one)."""
        self.lam = float(lam)
        self._direction = float(np.sign(lam)) or None
        self._dlam_prev = None

    def forget_steps(self) -> None:
        """The next run() starts its steps afresh (initial_step, no predictor), not as a checkpoint
        written between two increments had them (a resume with other steps)."""
        self._resumed_steps = None

    def run(self, target: float = 1.0, on_increment=None):
        """Step lambda from its current value to `target` (up or down). A SIGINT or SIGTERM
        meanwhile stops it after the increment under way: the last converged state is written
        (save_checkpoint) and Interrupted raised."""
        with self.stops:
            return self._run(target, on_increment)

    def _stop_if_requested(self) -> None:
        """After an attempt at an increment: where a stop was requested, write the last
        converged state (q holds it) and raise Interrupted."""
        signum = self.stops.requested()
        if signum:
            self._restore_converged()
            raise Interrupted(signum, self.save_checkpoint())

    def _run(self, target, on_increment):
        c = self.controls
        direction = 1.0 if target >= self.lam else -1.0
        reversal = self._direction is not None and direction != self._direction
        self._direction = direction
        resumed, self._resumed_steps = self._resumed_steps, None
        if resumed is not None:  # a checkpoint written between two increments: step on as it would have
            dlam, self._dlam_prev, x_prev = resumed
        else:
            dlam = min(c.initial_step, abs(target - self.lam))
            x_prev = self.q.x.array.copy()
            self._dlam_prev = None  # nothing to extrapolate from at a new target
        while abs(target - self.lam) > 1e-14:
            dlam = min(dlam, abs(target - self.lam))
            x_n = self.q.x.array.copy()
            cutbacks = 0
            while True:
                lam = self.lam + direction * dlam
                self._predict(dlam, x_n, x_prev)
                t0 = time.perf_counter()
                ok, its, res, ev = self._newton(lam, reversal)
                if not ok and self.swap_line_search:
                    ok, its, res, ev = self._other_line_search(lam, reversal, dlam, x_n, x_prev, its)
                if ok:
                    break
                self.q.x.array[:] = x_n
                self._stop_if_requested()
                cutbacks += 1
                dlam *= c.cut
                if self.verbose:
                    self.progress.note(f"  cut back: lambda {lam:.6g} failed after {its} iterations "
                                       f"(|R| {res[-1]:.3e}: {self._cause}); retry with dlambda {dlam:.3g}")
                if dlam < c.min_step:
                    self._restore_converged()
                    path = self.save_checkpoint()
                    raise ConvergenceFailure(self.limit_point(lam) or (
                        f"increment at lambda {self.lam:.6g} -> {lam:.6g} did not converge ({self._cause}) and "
                        f"the step fell below min_step {c.min_step:g}"), path)
                self._dlam_prev = None  # no extrapolation after a failure
            self._commit()
            self.q_n = self.q.x.array.copy()
            reversal = False
            x_prev = x_n
            self.lam = lam
            self._dlam_prev = dlam
            inc = Increment(len(self.history) + 1, lam, dlam, its, res, ev.plastic_layers, cutbacks,
                            {"wall_s": time.perf_counter() - t0}, self._increment_info(), self._norm(self.q.x.array - x_n))
            self.history.append(inc)
            if self.verbose:
                self.progress.increment(
                    lam, inc.number, sum(h.iterations for h in self.history),
                    f"increment {inc.number:3d}  lambda {lam:.6g}  dlambda {dlam:.3g}  iterations {its}  "
                    f"|R| {res[0]:.2e} -> {res[-1]:.2e}  plastic layers {ev.plastic_layers}")
            if its <= self.easy_iterations and cutbacks == 0:
                dlam = min(dlam * c.growth, c.max_step)
            self._steps = (dlam, self._dlam_prev, x_n)  # the next step; this one and the state before it (the predictor's)
            if on_increment is not None:
                on_increment(self)
            self._stop_if_requested()
        self._steps = None  # the next target starts its steps afresh
        return self.history

    # -- disk ----------------------------------------------------------------------------------
    def checkpoint_state(self) -> dict:
        """Everything the next increment starts from, as of the last converged increment, in the
        groups of shellform.nonlinear.checkpoint: per owned node the carrier, per owned cell the
        material state, and the load factor."""
        state = {"nodes": {"q": self._owned_nodes(self.q_n)}, "cells": dict(self.model.checkpoint()),
                 "global": {"lam": np.array(self.lam), "searching": np.array(self.searching)}}
        if self._steps is not None:  # between two increments of a target: how the next one starts
            dlam, dlam_prev, q_prev = self._steps
            state["nodes"]["q_prev"] = self._owned_nodes(q_prev)
            state["global"].update({"next_dlam": np.array(dlam), "dlam_prev": np.array(dlam_prev)})
        return state

    def _owned_nodes(self, values: np.ndarray) -> np.ndarray:
        """A carrier array as rows of its owned nodes (a view)."""
        imap = self.q.function_space.dofmap.index_map
        return values.reshape(imap.size_local + imap.num_ghosts, -1)[: imap.size_local]

    def restore_state(self, state: dict, lam_scale: float = 1.0) -> None:
        """Continue from a checkpoint_state (this rank's rows; lam_scale: its load factor in this
        run's units)."""
        q = self._owned_nodes(self.q.x.array)
        if "q" not in state["nodes"] or state["nodes"]["q"].shape != q.shape:
            raise InputError("resume", "the checkpoint's carrier does not fit this model (another mesh)")
        self.model.restore(state["cells"])
        q[...] = state["nodes"]["q"]
        self.q.x.scatter_forward()
        self.q_n = self.q.x.array.copy()
        glob = state["global"]
        self.lam = float(glob["lam"]) * lam_scale
        self._direction = 1.0 if self.lam > 0 else None
        self._dlam_prev = None
        self.searching = bool(glob.get("searching", True))
        if "q_prev" in state["nodes"]:  # written between two increments: the next run() steps on from there
            q[...] = state["nodes"]["q_prev"]
            self.q.x.scatter_forward()
            q_prev = self.q.x.array.copy()
            self.q.x.array[:] = self.q_n
            self._resumed_steps = (float(glob["next_dlam"]) * lam_scale, float(glob["dlam_prev"]) * lam_scale, q_prev)

    def numbering(self) -> checkpoint.Numbering:
        """The global numbers of this rank's nodes and cells in a checkpoint (made once)."""
        if self._numbering is None:
            self._numbering = checkpoint.Numbering(self.model.V, self.model.num_cells)
        return self._numbering

    def save_checkpoint(self):
        """Write the last converged state (checkpoint_state, gathered into one rank-independent
        file by rank 0, with the run's fingerprint and the history of every increment so far) as
        checkpoint_dir/checkpoint.npz, keeping the one before (shellform.nonlinear.checkpoint);
        and the history as history.json. Collective; safe at any time of a run (it writes the
        state of the last converged increment, not a Newton iterate). Returns the path (None
        without a checkpoint_dir)."""
        if self.checkpoint_dir is None:
            return None
        history = [asdict(h) for h in self.history]
        path = checkpoint.save(self.checkpoint_dir, self.numbering(), self.checkpoint_state(),
                               {"fingerprint": self.fingerprint, "history": history})
        write_json(self.checkpoint_dir / "history.json", history)
        return path

    def resume(self, saved: checkpoint.Checkpoint, lam_scale: float | None = None) -> None:
        """Continue from a checkpoint read by shellform.nonlinear.checkpoint.read (written on any
        number of ranks): its state (restore_state) and its history, so that the increments,
        iterations and cut-backs counted afterwards are the whole run's."""
        state = saved.local(self.numbering())
        if lam_scale is None:
            self.restore_state(state)
        else:
            self.restore_state(state, lam_scale)
        self.history = [Increment(**h) for h in saved.meta.get("history", [])]
