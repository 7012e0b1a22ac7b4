"""The mixed semi-inverse contact driver (model.md section 4, the paper's eqs. 24-29).

The load factor lambda moves the punch by -lambda * stroke along z. In every increment the
nodes split into free ones and nodes on a tool. A node on a tool is seen in its nodal frame
(frames.py); its normal displacement is *known* (it follows the tool: the correction is
-gap, which closes the gap at the current iterate), its normal contact force is *unknown*:

    K11 dq1 = dp1 - K12 dq*      (27)  free increments, the known ones lifted to the right
    dp*     = K21 dq1 + K22 dq*  (28)  contact forces: the residual on the known rows

Assembled as one DOLFINx system with the known components as Dirichlet rows (the lift is
(27) exactly) and solved with PETSc; the contact forces are the residual's Dirichlet rows.

Friction (Coulomb, mu) acts on every node on a tool, in the tangent plane, against its slip s
relative to the tool in this increment:  f_t = -mu p_n s / max(|s|, eps),  so |f_t| <= mu p_n
always; a node slips (|f_t| = mu p_n) once |s| > eps and sticks, held elastically, below it
(eps = 1e-4 of the cell size by default: stick is resolved to a fraction of a micrometre).
The force and its rate in s enter the residual and tangent; p_n comes from the latest iterate
(the friction magnitude is a fixed point of the Newton iteration).

The contact set is settled within the increment: Newton converges on a fixed set, then nodes
that penetrate a tool by more than `penetration` join it and nodes whose normal force turned
tensile leave it; the increment is repeated from there until nothing changes. A node may switch
at most `max_toggles` times per increment (no chattering: it then stays where it is); a set
that does not settle in `max_passes` cuts the increment back.

The blank holder is force-controlled (holder.py): its height is the unknown that makes its
contact forces sum to the prescribed force at every iterate.
"""

import time
from dataclasses import dataclass

import numpy as np
from dolfinx import fem, la
from mpi4py import MPI

from shellform.assembly.sheet_element import BS
from shellform.contact.frames import from_frames, nodal_frames, rotate_cell_arrays
from shellform.contact.holder import ForceControlledHolder
from shellform.nonlinear.driver import Driver

FREE = -1


@dataclass
class ContactControls:
    penetration: float  # a free node may penetrate a tool by at most this much (length)
    max_passes: int = 12  # contact-set updates per increment
    max_toggles: int = 2  # switches of one node per increment before it is frozen
    gap_tol: float = 0.0  # |known corrections| at convergence (0: 1e-3 penetration)
    slip_regularization: float = 1e-4  # eps / cell size of the Coulomb force (see _coulomb)


class ContactState:
    """Per owned node: the tool it lies on (or FREE), its normal contact force, its switches in
    this increment."""

    def __init__(self, n: int):
        self.tool = np.full(n, FREE, dtype=np.int8)
        self.pressure = np.zeros(n)
        self.toggles = np.zeros(n, dtype=np.int32)

    def copy(self):
        c = ContactState(self.tool.size)
        for k, v in vars(self).items():
            setattr(c, k, v.copy())
        return c


class SemiInverseDriver(Driver):
    """Punch displacement control with rigid tools, Coulomb friction and a force-controlled holder.

    tools: list of rigid tools with ``gap(x, offset, dz) -> (gap, normal)`` in contact order
    (e.g. punch, die); ``travel[k]`` is tool k's z-travel at lambda = 1 (punch: -stroke);
    holder: a BlankHolder tool (or None) with its force; friction: mu.
    """

    def __init__(self, model, bcs, tools, travel, friction=0.0, holder=None, holder_force=0.0,
                 prescribed=None, contact=None, controls=None, checkpoint_dir=None, verbose=True):
        super().__init__(model, bcs, prescribed=prescribed, controls=controls, checkpoint_dir=checkpoint_dir,
                         verbose=verbose)
        self.support_dofs = self.bc_dofs.copy()  # supports and symmetry (prescribed values: lam qbar)
        self.controls.predictor = False  # extrapolation would push nodes through the tools
        # an increment of a few contact passes is still an easy one
        self.controls.easy_iterations = max(self.controls.easy_iterations, 2 * self.controls.max_iterations // 3)
        V = model.V
        imap = V.dofmap.index_map
        self.n_owned, self.n_local = imap.size_local, imap.size_local + imap.num_ghosts
        self.tools, self.travel, self.mu = list(tools), np.asarray(travel, dtype=float), float(friction)
        self.contact = contact or ContactControls(penetration=1e-3 * model.thickness)
        if not self.contact.gap_tol:
            self.contact.gap_tol = 1e-3 * self.contact.penetration
        self.X = V.tabulate_dof_coordinates()[: self.n_local].copy()
        self.symmetry_bcs = list(bcs)
        sym = np.zeros(self.n_local * BS, dtype=bool)
        sym[self.bc_dofs] = True
        self.sym_fixed = sym.reshape(-1, BS)[: self.n_owned, :3]  # symmetry-fixed u, v, w (never w)
        # nodal fields shared with ghosts: frames (9 values = 3 x 3), known corrections, flags
        self._frame_fn, self._known_fn, self._flag_fn = fem.Function(V), fem.Function(V), fem.Function(V)
        self._z_fn = fem.Function(V)  # K^-1 b of the holder's bordered step
        self._b_holder = self._z_fn.x.petsc_vec.duplicate()  # its b
        self.frames = np.tile(np.eye(3), (self.n_local, 1, 1))
        self.rotated = np.zeros(self.n_local, dtype=bool)
        area, e33 = self._nodal_areas_and_thickness_strain()
        self.half_thickness = 0.5 * model.thickness * np.exp(e33)
        self.holder = None
        if holder is not None:
            k = model.material[0] * area / model.thickness  # E A / t: through-thickness stiffness
            self.holder = ForceControlledHolder(holder, holder_force, k, model.mesh.comm)
        self.state = ContactState(self.n_owned)
        self.committed = self.state.copy()
        self.x_n = self.X[: self.n_owned].copy()  # positions at the start of the increment
        self.lam_n = 0.0
        self._fz_holder = np.zeros(self.n_owned)
        self._kz_holder = np.zeros(self.n_owned)
        self._friction = np.zeros((self.n_owned, 3))
        self._slip_rate = np.zeros((self.n_owned, 2, 2))
        self._slipping = np.zeros(self.n_owned, dtype=bool)
        self._passes = self._changes = self._frozen = 0
        self.times["contact_s"] = 0.0
        self.nodal = self  # the contact forces enter the residual through Driver's nodal hook
        self.magnitude = 0.0
        self._initial_set()

    # -- geometry --------------------------------------------------------------------------
    def positions(self) -> np.ndarray:
        d = self.q.x.array.reshape(-1, BS)[: self.n_owned, :3]
        return self.X[: self.n_owned] + d

    def _gaps(self, x, lam):
        """Gap and normal of every owned node to every tool at load factor lam."""
        h = self.half_thickness
        return [tool.gap(x, h, lam * dz) for tool, dz in zip(self.tools, self.travel)]

    def _offset(self, k, lam):
        return np.array([0.0, 0.0, lam * self.travel[k]])

    def _initial_set(self):
        """Nodes touching a tool at the start (gap within the penetration tolerance)."""
        x = self.positions()
        s = self.state
        for k, (gap, _) in enumerate(self._gaps(x, 0.0)):
            touch = (gap <= self.contact.penetration) & (s.tool == FREE)
            s.tool[touch] = k
        self.committed = s.copy()
        if self.holder is not None:
            self.holder.balance(x, self.half_thickness)
        self.committed_Z = self.holder.Z if self.holder is not None else 0.0

    def _nodal_areas_and_thickness_strain(self):
        """Tributary areas (a third of each cell) and their area-weighted thickness strain."""
        m = self.model
        x = m.cell_coords.reshape(-1, 3, 3)
        a, b = x[:, 1, :2] - x[:, 0, :2], x[:, 2, :2] - x[:, 0, :2]
        cell_area = 0.5 * np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
        e33 = m.cell_fields()["thickness_strain"] if m.plastic else np.zeros(m.num_cells)
        f = fem.Function(m.V)
        arr = f.x.array.reshape(-1, BS)
        for col, values in ((0, cell_area / 3), (1, cell_area / 3 * e33)):
            np.add.at(arr[:, col], m.dofs.ravel(), np.repeat(values, 3))
        f.x.scatter_reverse(la.InsertMode.add)
        f.x.scatter_forward()
        area = arr[: self.n_owned, 0].copy()
        return area, arr[: self.n_owned, 1] / area

    # -- constraints of one iterate -----------------------------------------------------------
    def _constraints(self, lam):
        """Frames, known corrections and Dirichlet rows of the current contact set; friction and
        holder forces at the current iterate."""
        t0 = time.perf_counter()
        s, x = self.state, self.positions()
        gaps = self._gaps(x, lam)
        n_own = self.n_owned
        frames = np.tile(np.eye(3), (n_own, 1, 1))
        known = np.zeros((n_own, BS))
        flags = np.zeros((n_own, BS))
        self._friction[:] = 0.0
        self._slip_rate[:] = 0.0
        self._slipping[:] = False
        if self.holder is not None:
            self._fz_holder, self._kz_holder = self.holder.forces(x, self.half_thickness)
        for k in range(len(self.tools)):
            off = (s.tool == k) & ~np.isfinite(gaps[k][0])  # slid off the tool's extent
            s.tool[off], s.pressure[off] = FREE, 0.0
            on = np.flatnonzero(s.tool == k)
            if on.size == 0:
                continue
            gap, normal = gaps[k][0][on], gaps[k][1][on]
            frames[on] = nodal_frames(normal)
            known[on, 2] = -gap  # the normal correction that closes the gap
            flags[on, 2] = 1.0
            if self.mu > 0:
                shift = (lam - self.lam_n) * self.travel[k]  # the tool's travel in this increment
                self._friction[on] = self._coulomb(on, shift, x, frames[on])
        if self.mu > 0 and self.holder is not None:  # flange nodes the holder alone pinches
            only = np.flatnonzero((s.tool == FREE) & (self._fz_holder < 0))
            self._friction[only] = self._coulomb(only, 0.0, x, frames[only])
        flags[:, :3][self.sym_fixed] = 0.0  # already held by symmetry (a homogeneous condition)
        known[:, :3][self.sym_fixed] = 0.0
        # share with the ghosts
        for fn, values in ((self._frame_fn, frames.reshape(n_own, 9)), (self._known_fn, known),
                           (self._flag_fn, flags)):
            fn.x.array[: n_own * BS] = values.ravel()
            fn.x.scatter_forward()
        self.frames = self._frame_fn.x.array.reshape(-1, 3, 3).copy()
        flag = self._flag_fn.x.array.reshape(-1, BS)
        self.rotated = flag[:, :3].any(axis=1) | np.any(np.abs(self.frames - np.eye(3)) > 0, axis=(1, 2))
        self._set_bcs(flag)
        self.times["contact_s"] += time.perf_counter() - t0
        jump = self.model.mesh.comm.allreduce(float(np.abs(known).max(initial=0.0)), op=MPI.MAX)
        return max(jump, self._set_dirichlet(lam, self.support_dofs))  # supports: g = lam qbar

    def _coulomb(self, on, shift, x, F):
        """Coulomb forces on the nodes `on` of a tool that moved by `shift` along z in this
        increment: f = -mu (p_n + p_holder) s / max(|s|, eps),
        and their rate df/ds in the tangent slots, -mu p / |s| (I - s s^T / |s|^2) when
        slipping, -mu p / eps I when sticking (for fixed p)."""
        s = self.state
        n = F[:, 2]
        rel = x[on] - self.x_n[on]
        rel[:, 2] -= shift
        st = rel - np.sum(rel * n, axis=1)[:, None] * n  # slip in the tangent plane
        size = np.linalg.norm(st, axis=1)
        eps = self.contact.slip_regularization * self.model.cell_size
        slipping = size > eps
        p = np.maximum(s.pressure[on], 0.0) - self._fz_holder[on]  # both faces rub on the flange
        scale = self.mu * p / np.maximum(size, eps)
        s2 = np.einsum("nij,nj->ni", F[:, :2], st) / np.maximum(size, eps)[:, None]
        rate = scale[:, None, None] * (np.eye(2) - slipping[:, None, None] * s2[:, :, None] * s2[:, None, :])
        held = self.sym_fixed[on, :2]  # a symmetry plane holds that slot: no rate there
        rate[held[:, :, None] | held[:, None, :]] = 0.0
        self._slip_rate[on] = rate
        self._slipping[on] = slipping
        return -scale[:, None] * st

    def _set_bcs(self, flag):
        V = self.model.V
        bcs = list(self.symmetry_bcs)
        dofs = [self.symmetry_bcs[i].dof_indices()[0] for i in range(len(self.symmetry_bcs))]
        for slot in range(3):
            blocks = np.flatnonzero(flag[:, slot] > 0.5)
            if blocks.size:
                d = (BS * blocks + slot).astype(np.int32)
                bcs.append(fem.dirichletbc(np.float64(0), d, V.sub(slot)))
                dofs.append(d)
        self.bcs = bcs
        self.bc_dofs = np.unique(np.concatenate(dofs)).astype(np.int32) if dofs else np.zeros(0, np.int32)

    # -- Driver hooks -------------------------------------------------------------------------
    def _element_arrays(self, tangent):
        m = self.model
        rotate_cell_arrays(m.dofs, self.rotated, self.frames, m.forms.vectors, m.forms.matrices, tangent)

    def _correction(self):
        delta = self._known_fn.x.array.copy()
        d = self.support_dofs
        delta[d] = self.g[d] - self.q.x.array[d]
        return delta

    def add(self, lam, x, R, K=None):
        """Driver's nodal hook: R -= friction and holder forces (in the nodal frames); K += the
        holder's squeeze stiffness on free w rows and the slip rate of the friction force."""
        f = self._friction.copy()
        f[:, 2] += self._fz_holder
        f = np.einsum("nij,nj->ni", self.frames[: self.n_owned], f)  # identity off the tools
        R[: self.n_owned * BS].reshape(-1, BS)[:, :3] -= f
        if K is not None and self.holder is not None:
            free = np.flatnonzero((self._kz_holder > 0) & ~self.rotated[: self.n_owned])
            for b in free:
                K.setValuesLocal([BS * b + 2], [BS * b + 2], [[self._kz_holder[b]]], addv=True)
        if K is not None and self.mu > 0:
            for b in np.flatnonzero(np.abs(self._slip_rate).max(axis=(1, 2)) > 0):
                rows = [BS * b, BS * b + 1]
                K.setValuesLocal(rows, rows, self._slip_rate[b], addv=True)

    # -- one increment --------------------------------------------------------------------------
    def _newton(self, lam, reversal=False):
        """Newton on the fixed contact set, then settle the set; repeat until it holds."""
        self.state = self.committed.copy()
        if self.holder is not None:
            self.holder.Z = self.committed_Z
        self._lam_trial = lam
        self._passes = self._changes = 0
        iterations, residuals, ev = 0, [], None
        for _ in range(self.contact.max_passes):
            self._passes += 1
            ok, its, res, ev = self._newton_fixed_set(lam)
            iterations += its
            residuals += res
            if not ok:
                return False, iterations, residuals, ev
            changes = self._update_set(lam)
            self._changes += changes
            if changes == 0:
                return True, iterations, residuals, ev
        return False, iterations, residuals, ev

    def _newton_fixed_set(self, lam):
        c = self.controls
        residuals = []
        for it in range(c.max_iterations + 1):
            jump = self._constraints(lam)
            norm, scale, ev = self.residual(lam, tangent=True)
            residuals.append(norm)
            if not np.isfinite(norm) or ev.failures:
                return False, it, residuals, ev
            self._update_pressure()
            if norm <= c.rtol * scale and jump <= self.contact.gap_tol and self._holder_balanced():
                return True, it, residuals, ev
            if it == c.max_iterations:
                break
            if not self._solve(jump if jump > 0 else 0.0):
                return False, it, residuals, ev
            if self.holder is not None and self.holder.force > 0 and not self._holder_step():
                return False, it, residuals, ev
            from_frames(self.dq.x.array, self.rotated, self.frames)
            self.q.x.array[:] += self.dq.x.array
        return False, c.max_iterations, residuals, ev

    def _holder_balanced(self) -> bool:
        """The holder's forces sum to its force (to its rtol), or there is no holder force."""
        h = self.holder
        if h is None or h.force <= 0:
            return True
        g, _, _ = h.linearisation(self.positions(), self.half_thickness)
        return abs(g) <= h.rtol * h.force

    def _holder_step(self) -> bool:
        """The bordered Newton step for the holder height Z. With b = dR/d(-Z) (k_i on the w rows
        of the free nodes bearing the holder), y = the step just solved and z = K^-1 b:

            dq = y + z dZ,   dZ = (g + b.y + sum_pinched k_i dw_i) / (c - b.z),   c = sum k_i

        (the pinched nodes' dw_i are known: they lie on the die)."""
        h = self.holder
        g, act, k = h.linearisation(self.positions(), self.half_thickness)
        comm = self.model.mesh.comm
        c = comm.allreduce(float(k.sum()), op=MPI.SUM)
        if c == 0.0:  # the holder touches nothing: lower it onto the highest top
            h.balance(self.positions(), self.half_thickness)
            return True
        w = BS * act + 2
        pinned = self._flag_fn.x.array[w] > 0.5
        y = self.dq.x.array
        by = float(np.sum(k[~pinned] * y[w[~pinned]]))
        kp = float(np.sum(k[pinned] * self._known_fn.x.array[w[pinned]]))
        bvec = self._b_holder
        bvec.set(0.0)
        arr = bvec.getArray(readonly=False)
        arr[w[~pinned]] = k[~pinned]
        del arr
        t0 = time.perf_counter()
        self.ksp.solve(bvec, self._z_fn.x.petsc_vec)
        self.times["solve_s"] += time.perf_counter() - t0
        if self.ksp.getConvergedReason() < 0:
            return False
        self._z_fn.x.scatter_forward()
        z = self._z_fn.x.array
        bz = float(np.sum(k[~pinned] * z[w[~pinned]]))
        by, bz, kp = (comm.allreduce(v, op=MPI.SUM) for v in (by, bz, kp))
        dZ = (g + by + kp) / (c - bz)
        # a holder that lands on free flange nodes moves them by F / (sheet stiffness): go there
        # in steps of at most a tenth of the thickness (the die catches them on the way)
        limit = 0.1 * self.model.thickness
        dZ = float(np.clip(dZ, -limit, limit))
        self.dq.x.array[:] += dZ * z
        h.Z += dZ
        return bool(np.isfinite(dZ))

    def reactions(self) -> np.ndarray:
        """(n_owned, 3) residual on the u, v, w rows in the nodal frames (tool forces on constrained rows)."""
        return self.residual_full[: self.n_owned * BS].reshape(-1, BS)[:, :3]

    def _update_pressure(self):
        s = self.state
        on = s.tool != FREE
        s.pressure[on] = self.reactions()[on, 2]

    def _update_set(self, lam) -> int:
        """Join penetrating nodes, release tensile ones, rebalance the holder; returns the
        number of changes on all ranks."""
        t0 = time.perf_counter()
        s, x = self.state, self.positions()
        changes = 0
        scale = max(self.model.mesh.comm.allreduce(float(np.abs(s.pressure).max(initial=0.0)), op=MPI.MAX), 1e-300)
        can = s.toggles < self.contact.max_toggles
        # tensile contact force: release
        release = (s.tool != FREE) & (s.pressure < -1e-8 * scale) & can
        s.tool[release] = FREE
        s.pressure[release] = 0.0
        s.toggles[release] += 1
        changes += int(release.sum())
        # penetration of a free node: join the deepest tool
        gaps = self._gaps(x, lam)
        depth = np.stack([g for g, _ in gaps])  # (tools, nodes)
        k = np.argmin(depth, axis=0)
        join = (s.tool == FREE) & (depth.min(axis=0) < -self.contact.penetration) & can & ~release
        s.tool[join] = k[join]
        s.toggles[join] += 1
        changes += int(join.sum())
        if self.holder is not None and self.holder.balance(x, self.half_thickness):
            changes += 1  # the holder moved to carry its force again: one more pass
        self._frozen = int((s.toggles >= self.contact.max_toggles).sum())
        self.times["contact_s"] += time.perf_counter() - t0
        return self.model.mesh.comm.allreduce(changes, op=MPI.SUM)

    def _commit(self):
        super()._commit()
        s = self.state
        s.toggles[:] = 0
        x = self.positions()
        self.committed = s.copy()
        if self.holder is not None:
            self.committed_Z = self.holder.Z
        self.x_n = x
        self.lam_n = self._lam_trial
        if self.model.plastic:
            _, e33 = self._nodal_areas_and_thickness_strain()
            self.half_thickness = 0.5 * self.model.thickness * np.exp(e33)

    def _increment_info(self):
        return {"passes": self._passes, "set_changes": self._changes, "frozen": self._frozen,
                "in_contact": self.count_in_contact()}

    def count_in_contact(self) -> dict:
        """Nodes on each tool, all ranks: {"tool0": ..., "tool1": ...}."""
        comm = self.model.mesh.comm
        return {f"tool{k}": comm.allreduce(int((self.state.tool == k).sum()), op=MPI.SUM)
                for k in range(len(self.tools))}
