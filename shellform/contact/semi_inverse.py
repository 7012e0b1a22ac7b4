"""The mixed semi-inverse contact driver (model.md section 4, the paper's eqs. 24-29).

The load factor lambda moves the punch by -lambda * stroke along z. In every increment the
nodes split into free ones and nodes on a tool. A node on a tool is seen in its nodal frame
(frames.py); its normal displacement is *known* (it follows the tool: the correction is
-gap, which closes the gap at the current iterate), its normal contact force is *unknown*:

    K11 dq1 = dp1 - K12 dq*      (27)  free increments, the known ones lifted to the right
    dp*     = K21 dq1 + K22 dq*  (28)  contact forces: the residual on the known rows

Assembled as one DOLFINx system with the known components as Dirichlet rows (the lift is
(27) exactly) and solved with PETSc; the contact forces are the residual's Dirichlet rows.

The blank holder pinches the flange onto the die (holder.py): a node under the closed holder
stays on the die whatever the sign of its net force; it leaves the pinch when it is drawn off
the die's flat top, or when the holder opens. The open holder is one more tool, whose lift z_H
is an unknown with its own equation, sum of its nodal forces p_i = F. Each Newton iteration
solves it with the sheet (a bordered system, one more solve with the same factors):

    dq = dq_a + dz_H dq_b,   dq_b the response to the holder's nodes lifted by 1,
    dz_H = (F - sum p_i - sum (K dq_a)_i) / sum (K dq_b)_i   (sums over the holder's normal rows)

Coulomb friction is a part of its own (friction.py: its return mapping, history and
contributions to R and K) on every node on a tool and under the holder. The normal force p of a
node (both faces of a pinched node) is taken from the reactions of every Newton iterate after
the first, and the slipping force's dependence on it enters the tangent (non-symmetric).
Newton then converges p with the displacements instead of one pass at a time. The first
iterate of a pass keeps the p of the pass before, relaxed with Aitken's factor. Passes remain
for the contact set: they repeat until it holds, and a pass ends as soon as the set will change
once Newton's steps are below `early_step` penetrations (EARLY_STEP; after a failure of such
passes 1, for the rest of the run). A node moving along a curved tool turns its frame; the
tangent carries that too (K_ab += -R0 W_ab, W the tool's shape operator). With the three,
Newton's tails are quadratic again where no layer or node crosses a kink (elastic-plastic,
stick-slip) along the step (docs/performance.md: what each saves). A pass starts from the
element arrays of the last iterate, turned into its new frames (the carrier has not moved).

Newton is globalised: each correction is first limited so that no node moves by more than
`trust` thicknesses, then a line search on the energy slope dq . R(q + alpha dq) shortens it
where it overshoots. The contact set is settled between passes: nodes that penetrate a tool by more than `penetration`
join it, nodes (not pinched) whose normal force turned tensile leave it;
a node may switch at most `max_toggles` times per increment (no chattering).
"""

import time
from dataclasses import dataclass

import numpy as np
from dolfinx import fem, la
from mpi4py import MPI

from shellform.assembly.sheet_element import BS, COMPONENTS
from shellform.errors import InputError
from shellform.contact.frames import from_frames, nodal_frames, rotate_cell_arrays
from shellform.contact.drawbead import Drawbeads
from shellform.contact.friction import CoulombFriction
from shellform.contact.holder import PinchingHolder
from shellform.nonlinear.driver import Driver, shorten
from shellform.results.log import say

FREE = -1
W_SLOPES = slice(COMPONENTS.index("w_x"), COMPONENTS.index("w_y") + 1)


@dataclass
class ContactControls:
    penetration: float  # a free node may penetrate a tool by at most this much (length)
    max_passes: int = 12  # contact passes per increment, not counting those that only move the contact front
    max_toggles: int = 2  # switches of one node (or of the holder) per increment before it is frozen
    friction_rtol: float = 1e-4  # passes end when |mu dp| <= friction_rtol |mu p| (2-norms)
    trust: float = 0.5  # the largest nodal update of one Newton iteration, in thicknesses
    holder_spread: str = "area"  # "area" or "rigid" (holder.py)
    trace: bool = False  # log every pass, step and iterate (the largest residuals) and each node that switches


class ContactState:
    """Per owned node: the tool it lies on (or FREE), the normal force of that tool's face and
    of the holder's face, the normal force friction uses (held fixed within a pass; the faces'
    sum, relaxed between passes), the node's switches in this increment; and whether the holder
    is closed and its lift. (Friction's history is the friction part's.)"""

    def __init__(self, n: int):
        self.tool = np.full(n, FREE, dtype=np.int8)
        self.pressure = np.zeros(n)
        self.holder_face = np.zeros(n)
        self.normal = np.zeros(n)  # the normal force friction uses in this pass (both faces)
        self.toggles = np.zeros(n, dtype=np.int32)
        self.closed = np.zeros(1, dtype=bool)
        self.lift = np.zeros(1)  # the open holder's face above its closed position
        self.holder_toggles = np.zeros(1, dtype=np.int32)

    def copy(self):
        c = ContactState(self.tool.size)
        for k, v in vars(self).items():
            setattr(c, k, v.copy())
        return c


class SemiInverseDriver(Driver):
    """Punch displacement control with rigid tools, Coulomb friction and a pinching holder.

    tools: list of rigid tools with ``gap(x, offset, dz) -> (gap, normal)`` in contact order
    (e.g. punch, die); ``travel[k]`` is tool k's z-travel at lambda = 1 (punch: -stroke);
    holder: a BlankHolder tool (or None) with its force, pinching the flange onto tool `die`
    (default: the last tool); friction: mu; drawbeads: DrawbeadLine's (drawbead.py).
    """

    swap_line_search = False  # its Newton (_newton) has its own line search and contact passes
    MAX_FRONT_PASSES = 60  # all passes of an increment, front ones included (a front crosses a row of nodes per pass)
    EARLY_STEP = 10.0  # a pass ends once the set will change and the steps are below this many penetrations

    def __init__(self, model, bcs, tools, travel, friction=0.0, holder=None, holder_force=0.0,
                 prescribed=None, contact=None, controls=None, checkpoint_dir=None, verbose=True, die=None,
                 drawbeads=()):
        super().__init__(model, bcs, prescribed=prescribed, controls=controls, checkpoint_dir=checkpoint_dir,
                         verbose=verbose)
        self.support_dofs = self.bc_dofs.copy()  # supports and symmetry (prescribed values: lam qbar)
        # an increment of a few contact passes is still an easy one
        self.easy_iterations = max(self.easy_iterations, 2 * self.controls.max_iterations // 3)
        V = model.V
        imap = V.dofmap.index_map
        self.n_owned, self.n_local = imap.size_local, imap.size_local + imap.num_ghosts
        self.tools, self.travel = list(tools), np.asarray(travel, dtype=float)
        self.die = len(self.tools) - 1 if die is None else int(die)
        self.contact = contact or ContactControls(penetration=1e-3 * model.thickness)
        self.gap_tol = 1e-3 * self.contact.penetration  # |known corrections| at convergence
        self.early_step = self.EARLY_STEP  # 1 once passes that end early have failed (_newton)
        self.X = V.tabulate_dof_coordinates()[: self.n_local].copy()
        self.symmetry_bcs = list(bcs)
        sym = np.zeros(self.n_local * BS, dtype=bool)
        sym[self.bc_dofs] = True
        self.sym_all = sym.reshape(-1, BS)[: self.n_owned]  # carrier values fixed by symmetry
        self.sym_fixed = self.sym_all[:, :3]  # of u, v, w (never w)
        # nodal fields shared with ghosts: frames (9 values = 3 x 3), known corrections, flags
        self._frame_fn, self._known_fn, self._flag_fn = fem.Function(V), fem.Function(V), fem.Function(V)
        self.frames = np.tile(np.eye(3), (self.n_local, 1, 1))
        self.rotated = np.zeros(self.n_local, dtype=bool)
        self.area, e33 = self._nodal_areas_and_thickness_strain()
        self.half_thickness = 0.5 * model.thickness * np.exp(e33)
        E = model.material[0]
        self.friction = CoulombFriction(friction, CoulombFriction.STICK_STIFFNESS * E * self.area / model.cell_size,
                                        self.sym_fixed[:, :2])
        self.drawbeads = Drawbeads(drawbeads, V, model.dofs, E, model.thickness, model.cell_size,
                                   self.sym_fixed[:, :2]) if drawbeads else None
        # the parts with a history of their own: started, committed and checkpointed alike
        self.parts = [part for part in (self.friction, self.drawbeads) if part is not None]
        self.holder = None
        self.holder_tool = len(self.tools)  # the open holder's index in the contact set
        if holder is not None:
            self.holder = PinchingHolder(holder, holder_force, self.area, E * self.area / model.thickness,
                                         model.mesh.comm, self.contact.holder_spread)
        n = self.n_owned
        self.state = ContactState(n)
        self.x_n = self.X[:n].copy()  # positions at the start of the increment
        self.lam_n = 0.0
        self.pinched = np.zeros(n, dtype=bool)
        self.pinched_n = self.pinched.copy()  # of the last converged increment
        self._under = np.zeros(n, dtype=bool)  # under the holder in this increment (_pinch)
        self._previous = None  # the committed state before the last (the predictor's)
        self._r_prev, self._omega = None, 1.0
        self._passes = self._changes = self._frozen = 0
        self._scale = 0.0
        self._rub = (np.zeros(0, dtype=np.int64), np.zeros(0), self.X[:n].copy(), np.zeros((0, 3, 3)))
        self._refreshing = False  # normal forces from this iterate's reactions (all but a pass's first)
        self._curvature = np.zeros((n, 2, 2))  # W of each node's tool in its tangent slots
        self._net = np.zeros(n)  # the net normal forces of the last refreshed iterate
        self._early, self._step = False, np.inf  # a pass ended early; the last accepted step's largest move
        self._dlift = 0.0  # the open holder's lift in this Newton iteration
        self._stable_rows = np.zeros(0, dtype=np.int32)  # known rows the free-row solve takes out (_constraints)
        self._lift_fn = fem.Function(V)  # the unit lift of the open holder's nodes (known rows)
        self._lift_response = fem.Function(V)
        self.line_search_factors: list[float] = []  # alpha of every accepted Newton step (this increment)
        self.pass_residuals: list[list[float]] = []
        self.times["contact_s"] = 0.0
        self.nodal = self  # the contact forces enter the residual through Driver's nodal hook
        self.magnitude = 0.0
        self._initial_set()

    # -- geometry --------------------------------------------------------------------------
    def positions(self) -> np.ndarray:
        d = self.q.x.array.reshape(-1, BS)[: self.n_owned, :3]
        return self.X[: self.n_owned] + d

    def gaps(self, x, lam):
        """Gap and normal of every owned node to every tool at load factor lam, the open
        holder last (an infinite gap when it is closed or has no force)."""
        h = self.half_thickness
        gaps = [tool.gap(x, h, lam * dz) for tool, dz in zip(self.tools, self.travel)]
        if self.holder is not None:
            if self._holder_open():
                gaps.append(self.holder.face_gap(x, h, self.model.thickness, float(self.state.lift[0])))
            else:
                gaps.append((np.full(len(x), np.inf), np.tile([0.0, 0.0, -1.0], (len(x), 1))))
        return gaps

    def _holder_open(self) -> bool:
        """The holder is open and presses (a tool with its own lift)."""
        return self.holder is not None and not self.state.closed[0] and self.holder.force > 0

    def _on_holder(self):
        """The owned nodes on the open holder's face, and their number on all ranks."""
        on = self.state.tool == self.holder_tool
        return on, self.model.mesh.comm.allreduce(int(on.sum()), op=MPI.SUM)

    def _initial_set(self):
        """Nodes touching a tool at the start (gap within the penetration tolerance); the holder
        closes on the flange when it has a force."""
        x = self.positions()
        s = self.state
        for k, (gap, _) in enumerate(self.gaps(x, 0.0)):
            touch = (gap <= self.contact.penetration) & (s.tool == FREE)
            s.tool[touch] = k
        if self.holder is not None:
            s.closed[0] = self.holder.force > 0
            under = self.holder.under(x)
            self._pinch(under, grow=False)
            self._holder_faces(x, np.zeros(self.n_owned))
        s.normal = s.pressure + s.holder_face
        self.committed = s.copy()

    def _nodal_areas_and_thickness_strain(self):
        """Tributary areas (a third of each cell) and their area-weighted thickness strain."""
        m = self.model
        x = m.cell_coords.reshape(-1, 3, 3)
        a, b = x[:, 1, :2] - x[:, 0, :2], x[:, 2, :2] - x[:, 0, :2]
        cell_area = 0.5 * np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
        e33 = m.thickness_strain() if m.plastic else np.zeros(m.num_cells)
        f = fem.Function(m.V)
        arr = f.x.array.reshape(-1, BS)
        for col, values in ((0, cell_area / 3), (1, cell_area / 3 * e33)):
            np.add.at(arr[:, col], m.dofs.ravel(), np.repeat(values, 3))
        f.x.scatter_reverse(la.InsertMode.add)
        f.x.scatter_forward()
        area = arr[: self.n_owned, 0].copy()
        return area, arr[: self.n_owned, 1] / area

    # -- the holder ----------------------------------------------------------------------------
    def _pinch(self, under, grow: bool):
        """The pinched nodes: on the die, under the closed holder (mask `under`). Within an
        increment the set only grows (nodes drawn under the holder are pinched at once); a node
        drawn out from under it leaves at the next increment, so that a node at the holder's edge
        cannot switch between pinched and free from one pass to the next. The nodes under the
        open holder, whose slopes it holds flat, follow the same rule."""
        s = self.state
        now = s.closed[0] & under & (s.tool == self.die)
        self.pinched = (self.pinched | now) if grow else now
        self.pinched &= s.closed[0] & (s.tool == self.die)
        self._under = (self._under | under) if grow else under.copy()  # the same lag, for the open holder

    def _holder_faces(self, x, net):
        """The face forces of the holder (and of the die under it) from the nodes' net normal
        forces `net` (die minus holder on a pinched node), at positions x: the closed holder's
        split (holder.py); the open holder's face takes the force of the nodes on it."""
        s, h = self.state, self.holder
        if s.closed[0]:
            tops = x[:, 2] + self.half_thickness
            d, s.holder_face = h.faces(self.pinched, net, tops)
            s.pressure[self.pinched] = d[self.pinched]
        else:
            on = s.tool == self.holder_tool
            s.holder_face = np.where(on, np.maximum(net, 0.0), 0.0)
            s.pressure[on] = 0.0

    def _update_holder(self, x, under, net) -> int:
        """After a converged pass: open the holder if the flange lifts it (the squeeze left is
        negative): the pinched nodes it holds down (R0 < 0) go onto its face, the others stay on
        the die, the face at its closed position. Close it once its lift is below that position
        by more than `gap_tol` (within a pass the lift may pass it), unless that would spend its
        last switch of the increment; lower an open holder that touches nothing onto the
        nearest node. Then its face forces. `net`, the nodes' net normal forces, is updated
        where a node changes faces. Returns the changes (all ranks)."""
        s, h = self.state, self.holder
        comm = self.model.mesh.comm
        changes = 0
        if s.holder_toggles[0] < self.contact.max_toggles and h.force > 0:
            if s.closed[0] and h.squeeze_left(self.pinched, net) < 0:
                s.closed[0] = False
                tops = (x[:, 2] + self.half_thickness)[self.pinched]
                s.lift[0] = h.lift_floor(tops)
                held = self.pinched & (net < 0)
                s.tool[held] = self.holder_tool
                net[held] *= -1  # now the force of the face they lie on, along its normal
                changes = 1
            elif (not s.closed[0] and s.holder_toggles[0] + 1 < self.contact.max_toggles
                  and s.lift[0] < self._lift_floor(x, under) - self.gap_tol):
                # the face presses into the flange on the die: closed (if it may still open
                # again in this increment: closed with its switches spent, it could be left
                # holding more than F)
                s.closed[0] = True
                held = s.tool == self.holder_tool
                s.tool[held] = self.die  # then pinched (the face is at the sheet)
                net[held] *= -1  # die minus holder
                changes = 1
            elif not s.closed[0] and self._on_holder()[1] == 0:
                gap = self.gaps(x, self._lam_trial)[self.holder_tool][0]
                nearest = comm.allreduce(float(gap[under].min(initial=np.inf)), op=MPI.MIN)
                if np.isfinite(nearest) and s.lift[0] - nearest <= self._lift_floor(x, under):
                    s.closed[0] = True  # down to the sheet on the die: closed
                    changes = 1
                elif np.isfinite(nearest):
                    s.lift[0] -= nearest  # the face comes down onto the nearest node
                    s.tool[under & (gap <= nearest + self.contact.penetration) & (s.tool == FREE)] = self.holder_tool
                    changes = 1
            s.holder_toggles[0] += changes
            if self.contact.trace and changes:
                say(f"    holder: {'closed' if s.closed[0] else 'open'}, lift {s.lift[0]:.3e} mm, "
                    f"{self._on_holder()[1]} nodes on its face")
        self._pinch(under, grow=True)
        self._holder_faces(x, net)
        return changes

    def _lift_floor(self, x, under) -> float:
        """The open holder's closed position (holder.lift_floor) over the nodes on the die under it."""
        on_die = under & (self.state.tool == self.die)
        return self.holder.lift_floor((x[:, 2] + self.half_thickness)[on_die])

    # -- constraints of one iterate -----------------------------------------------------------
    def _constraints(self, lam):
        """Frames, known corrections and Dirichlet rows of the current contact set; friction
        forces at the current iterate."""
        t0 = time.perf_counter()
        s, x = self.state, self.positions()
        gaps = self.gaps(x, lam)
        n_own = self.n_owned
        frames = np.tile(np.eye(3), (n_own, 1, 1))
        known = np.zeros((n_own, BS))
        flags = np.zeros((n_own, BS))
        shift = np.zeros(n_own)  # z-travel of each node's tool in this increment
        self._curvature = np.zeros((n_own, 2, 2))
        for k in range(len(gaps)):
            off = (s.tool == k) & ~np.isfinite(gaps[k][0])  # slid off the tool's extent
            s.tool[off], s.pressure[off], s.normal[off] = FREE, 0.0, s.holder_face[off]
            on = np.flatnonzero(s.tool == k)
            if on.size == 0:
                continue
            gap, normal = gaps[k][0][on], gaps[k][1][on]
            frames[on] = nodal_frames(normal)
            known[on, 2] = -gap  # the normal correction that closes the gap
            flags[on, 2] = 1.0
            if k == self.holder_tool:
                continue  # flat, and still in plan
            self._curvature[on] = self._shape_operator(k, x[on], frames[on], normal, lam)
            shift[on] = (lam - self.lam_n) * self.travel[k]
        # the holder's flat faces hold the flange flat: the slopes of w are known too on the
        # pinched nodes, and on every node under the open holder (on a face or between them)
        flat = self.pinched.copy()
        if self._holder_open():
            flat |= self._under
        slopes = self.q.x.array.reshape(-1, BS)[:n_own, W_SLOPES]
        known[flat, W_SLOPES.start:W_SLOPES.stop] = -slopes[flat]
        flags[flat, W_SLOPES.start:W_SLOPES.stop] = 1.0
        # the rows the free-row solve takes out: the flat flange's (w too where pinched) and the
        # supports'; a node's normal on a punch or die switches too often (Driver._eliminable)
        stable = np.zeros((n_own, BS), dtype=bool)
        stable[flat, W_SLOPES] = True
        stable[self.pinched, 2] = True
        stable |= self.sym_all
        self._stable_rows = np.flatnonzero(stable.ravel()).astype(np.int32)
        rub = np.flatnonzero((s.tool != FREE) | (s.normal > 0))
        self._rub = (rub, shift[rub], x, frames[rub])
        self._friction_forces()
        flags[self.sym_all] = 0.0  # already held by symmetry (a homogeneous condition)
        known[self.sym_all] = 0.0
        # share with the ghosts
        for fn, values in ((self._frame_fn, frames.reshape(n_own, 9)), (self._known_fn, known),
                           (self._flag_fn, flags)):
            fn.x.array[: n_own * BS] = values.ravel()
            fn.x.scatter_forward()
        self.frames = self._frame_fn.x.array.reshape(-1, 3, 3).copy()
        flag = self._flag_fn.x.array.reshape(-1, BS)
        self.rotated = flag[:, :3].any(axis=1) | np.any(np.abs(self.frames - np.eye(3)) > 0, axis=(1, 2))
        self._set_bcs(flag)
        if self.drawbeads is not None:
            x_local = self.X + self.q.x.array.reshape(-1, BS)[: self.n_local, :3]
            self.drawbeads.update(x_local, self.x_n, self.frames[:n_own])
        self.times["contact_s"] += time.perf_counter() - t0
        return max(self._largest(known), self._set_dirichlet(lam, self.support_dofs))  # supports: g = lam qbar

    def _shape_operator(self, k, x, F, n, lam):
        """W_ab = t_a . (dn/dx) t_b of tool k's normal field n (the gradient of its distance) at
        the points x with tangents F[:, 0:2], by forward differences (h = 1e-4 thickness: an
        error of h / R^2 against 1 / R), symmetrised."""
        h = 1e-4 * self.model.thickness
        tool, dz = self.tools[k], lam * self.travel[k]
        W = np.zeros((len(x), 2, 2))
        for b in range(2):
            W[:, :, b] = np.einsum("nij,nj->ni", F[:, :2], (tool.gap(x + h * F[:, b], 0.0, dz)[1] - n) / h)
        return 0.5 * (W + W.transpose(0, 2, 1))

    def _friction_forces(self):
        """Friction on the rubbing nodes of this iterate (set by _constraints) with the current
        normal forces."""
        idx, shift, x, F = self._rub
        self.friction.update(idx, shift, x, self.x_n, F, self.state.normal)

    def _refresh_normal(self, R):
        """Within a pass: the friction's normal forces from this iterate's reactions (the rows of
        the known normal components of R, before friction), with the closed holder's faces, so
        that Newton converges the normal forces with the displacements instead of one pass at a
        time. The contact set stays fixed."""
        s = self.state
        net = self.net_normal_forces(R)
        self._net = net
        s.pressure = np.maximum(net, 0.0)
        if self.holder is not None:
            self._holder_faces(self._rub[2], net)
        s.normal = s.pressure + s.holder_face
        self._friction_forces()

    def _set_bcs(self, flag):
        V = self.model.V
        bcs = list(self.symmetry_bcs)
        dofs = [self.symmetry_bcs[i].dof_indices()[0] for i in range(len(self.symmetry_bcs))]
        for slot in range(BS):
            blocks = np.flatnonzero(flag[:, slot] > 0.5)
            if blocks.size:
                d = (BS * blocks + slot).astype(np.int32)
                bcs.append(fem.dirichletbc(np.float64(0), d, V.sub(slot)))
                dofs.append(d)
        self.bcs = bcs
        self.bc_dofs = np.unique(np.concatenate(dofs)).astype(np.int32) if dofs else np.zeros(0, np.int32)

    # -- Driver hooks -------------------------------------------------------------------------
    def _eliminable(self):
        """The known rows the free-row solve takes out: those that stay known (_constraints)."""
        return self._stable_rows

    def _element_arrays(self, tangent):
        m = self.model
        rotate_cell_arrays(m.dofs, self.rotated, self.frames, m.forms.vectors, m.forms.matrices, tangent)
        self._array_frames = (self.rotated.copy(), self.frames.copy())

    def _reframe_element_arrays(self, tangent):
        """From the frames F0 the arrays were turned into to the current F: T = F F0^T on every
        block turned in either (F0 = I on a block that was not turned; orthogonal, so exact to
        round-off)."""
        m = self.model
        rotated0, F0 = self._array_frames
        turn = rotated0 | self.rotated
        G = np.einsum("nij,nkj->nik", self.frames, F0)
        rotate_cell_arrays(m.dofs, turn, G, m.forms.vectors, m.forms.matrices, tangent)
        self._array_frames = (self.rotated.copy(), self.frames.copy())

    def _correction(self):
        """The known corrections in the solve's coordinates: the tools' (nodal frames) and the
        supports'. q and g hold global components, but on a node in a frame a support's row is
        the frame's slot k, F_k . d, which nodal_frames keeps on +-e_k (a symmetry plane keeps
        its meaning, with the sign of the frame: slot 1 is -e_y on y = 0 under the punch and
        the holder, whose normals point down): the slot's correction is F_kk (g_k - q_k).
        Without F_kk a slot along -e_k doubled q_k at every iteration instead of zeroing it."""
        delta = self._known_fn.x.array.copy()
        d = self.support_dofs
        delta[d] = self.g[d] - self.q.x.array[d]
        block, slot = d // BS, d % BS
        turned = (slot < 3) & self.rotated[block]
        delta[d[turned]] *= self.frames[block[turned], slot[turned], slot[turned]]
        return delta

    def residual(self, lam, tangent: bool, elastic_tangent: bool = False):
        """Driver's residual, its norm with the open holder's equation F - sum p_i."""
        norm, scale, ev = super().residual(lam, tangent, elastic_tangent)
        return float(np.hypot(norm, self._holder_imbalance())), scale, ev

    def _holder_imbalance(self) -> float:
        """F - sum p_i over the open holder's nodes (all ranks), 0 when it has none: the
        derivative of the energy with respect to its lift."""
        if not self._holder_open():
            return 0.0
        on, count = self._on_holder()
        if count == 0:
            return 0.0
        return self.holder.force - self.model.mesh.comm.allreduce(float(self.net_normal_forces()[on].sum()), op=MPI.SUM)

    def _lift_step(self) -> float:
        """The open holder's lift in this Newton iteration, solved with the sheet (module
        docstring): dq (frame coordinates, from the solve) becomes dq_a + dz_H dq_b."""
        if not self._holder_open():
            return 0.0
        comm = self.model.mesh.comm
        on, count = self._on_holder()
        if count == 0:
            return 0.0
        rows = BS * np.flatnonzero(on) + 2  # their normal rows (the frame's normal points down)
        unit = self._lift_fn.x.array
        unit[:] = 0.0
        unit[rows] = -1.0  # the face up by 1: each node 1 up, -1 along its normal
        self._lift_fn.x.scatter_forward()
        extra = None
        if self.friction.slip_rows is not None:  # the slip forces' dp/dq on these known columns
            coef, g = self.friction.slip_rows
            Ku = self.apply_tangent(unit)[: self.n_owned * BS].reshape(-1, BS)[:, 2]
            extra = np.zeros(self.n_owned * BS)
            extra.reshape(-1, BS)[:, :2] = (coef * Ku)[:, None] * g
        if not self.solve_lifted(unit, self._lift_response, extra):
            return np.nan
        dqa, dqb = self.dq.x.array, self._lift_response.x.array
        change = comm.allreduce(np.array([self.apply_tangent(dqa)[rows].sum(), self.apply_tangent(dqb)[rows].sum()]),
                                op=MPI.SUM)
        dz = (self._holder_imbalance() - change[0]) / change[1]
        dqa += dz * dqb
        self.dq.x.scatter_forward()
        return float(dz)

    def add(self, lam, x, R, K=None):
        """Driver's nodal hook: R -= the drawbeads' forces and friction forces (in the nodal
        frames), the friction's normal forces taken from R between the two where Newton's
        iterates update them; K += the beads' and the friction's stiffness in the tangent slots,
        the slip force's dp/dq and the frames' turning on curved tools."""
        n = self.n_owned
        F = self.frames[:n]  # identity off the tools
        R3 = R[: n * BS].reshape(-1, BS)[:, :3]
        if K is not None:
            self.friction.slip_rows = None
        if self.drawbeads is not None:  # before the reactions are read: the tools take what the beads do not
            self.drawbeads.add_residual(R3, F)
            if K is not None:
                self.drawbeads.add_tangent(K)
        if self._refreshing and self.friction.active:
            self._refresh_normal(R)  # the reactions before friction
        self.friction.add_residual(R3, F)
        if K is not None and self.friction.active:
            self.friction.add_tangent(K)
            if self._refreshing:
                self._add_slip_pressure_tangent(K)
        if K is not None:
            self._add_curvature_tangent(K, R3[:, 2])

    def _add_curvature_tangent(self, K, net):
        """The turning of a node's frame as it moves along a curved tool: its tangential rows
        t_a . R, with R ~ R0 n, change by R0 n . dt_a = -R0 t_a . dn = -R0 W_ab dx_b, so
        K_ab += -R0 W_ab (R0 the node's net normal force; softening on the punch's convex
        nose, stiffening in the die's concave shoulder)."""
        b = np.flatnonzero((self.state.tool != FREE) & (np.abs(self._curvature).max(axis=(1, 2)) > 0))
        if b.size == 0:
            return
        held = self.sym_fixed[b, :2]
        blocks = -net[b, None, None] * self._curvature[b]
        blocks[held[:, :, None] | held[:, None, :]] = 0.0
        rows = (BS * b[:, None] + np.arange(2)).astype(np.int32)
        K.setValuesLocalRCV(rows, rows, blocks.reshape(b.size, 4), addv=True)

    def _add_slip_pressure_tangent(self, K):
        """The slipping force's dependence on its normal force (friction.py), which Newton's
        iterates now update: dp/dR0 = 1 on a tool, sign(R0) on a pinched node
        (the closed holder's share of F through sum max(-R0, 0) is left out)."""
        s, n, net = self.state, self.n_owned, self._net
        coef = np.zeros(n)
        on = self.friction.slipping & (s.tool != FREE) & (s.normal > 0)
        coef[on] = np.where(self.pinched[on], np.sign(net[on]), (net[on] > 0).astype(float))
        fixed = np.zeros(self.n_local * BS, dtype=bool)
        fixed[self.bc_dofs] = True
        self.friction.add_normal_force_tangent(K, self.model, coef, self.frames, s.normal, fixed, self.n_local)

    # -- one increment --------------------------------------------------------------------------
    def _newton(self, lam, reversal=False):
        """The contact passes (_contact_passes); where they fail with passes that end early (early_step
        above 1), they end only near convergence from then on (early_step 1), and the increment
        is tried once more at the same step before the driver cuts it back. An early end judges
        the set on an iterate whose steps are still up to early_step penetrations long, which
        saves iterations where it holds and can fail where the set is delicate (docs/contact.md
        has both measured). The increment's iterations count both tries."""
        start = self.q.x.array.copy()
        ok, its, res, ev = self._contact_passes(lam, reversal)
        if ok or self.early_step <= 1.0:
            return ok, its, res, ev
        if self.verbose:
            self.progress.note(f"  the contact passes failed ({self._cause}); from now on they end only near "
                               f"convergence (early_step {self.early_step:g} -> 1), and the increment is tried again")
        self.early_step = 1.0
        self.q.x.array[:] = start
        ok, more, res, ev = self._contact_passes(lam, reversal)
        return ok, its + more, res, ev

    def _contact_passes(self, lam, reversal=False):
        """Contact passes: Newton on a fixed contact set (the normal forces follow the iterates),
        then the set's update; repeat until the set and the normal forces hold."""
        self.state = self.committed.copy()
        for part in self.parts:
            part.start()
        self._lam_trial = lam
        if self.holder is not None:
            self._pinch(self.holder.under(self.x_n), grow=False)
        self._extrapolate_normal_forces(lam)
        self._passes = self._changes = 0
        self._early = False
        self.line_search_factors = []
        self.pass_residuals = []  # |R| of every iterate, one list per pass (this increment)
        self._r_prev, self._omega = None, 1.0  # Aitken's memory of the normal-force updates
        iterations, residuals, ev = 0, [], None
        changes, dp, counted = 0, 0.0, 0
        while counted < self.contact.max_passes and self._passes < self.MAX_FRONT_PASSES:
            self._passes += 1
            ok, its, res, ev = self._newton_fixed_set(lam)
            iterations += its
            residuals += res
            self.pass_residuals.append(res)
            if not ok:
                return False, iterations, residuals, ev
            early, self._early = self._early, False
            changes, dp, pn, front = self._update_pass(lam)
            counted += not front
            if self.contact.trace:
                say(f"    pass {self._passes}: {its} iterations, |R| {res[0]:.3e} -> {res[-1]:.3e}, {changes} set "
                    f"changes, friction change |mu dp| {dp:.3e} of |mu p| {pn:.3e}")
            self._changes += changes
            if changes == 0 and dp <= self.contact.friction_rtol * pn and not early:
                return True, iterations, residuals, ev
        self._cause = (f"the contact did not settle in {self._passes} passes (last pass: {changes} "
                       f"set changes, friction change {dp:.3g} N)")
        return False, iterations, residuals, ev

    def _extrapolate_normal_forces(self, lam):
        """With the predictor: the friction's normal forces of the first pass extrapolated from
        the last two increments, as the carrier is (nodes on the same tool in both)."""
        prev = self._previous
        if not (self._dlam_prev and prev is not None):
            return
        s, ratio = self.state, (lam - self.lam_n) / (self.lam_n - prev["lam"])
        same = s.tool == prev["tool"]
        s.normal[same] = np.maximum(s.normal[same] + ratio * (s.normal[same] - prev["normal"][same]), 0.0)

    def _newton_fixed_set(self, lam):
        try:
            return self._newton_on_set(lam)
        finally:
            self._refreshing = False

    def _newton_on_set(self, lam):
        c = self.controls
        jump = self._constraints(lam)
        norm, scale, ev = self._trial(lam)
        residuals = [norm]
        for it in range(c.max_iterations + 1):
            if not np.isfinite(norm) or ev.failed:
                self._cause = ev.cause() or "the residual is not finite"
                return False, it, residuals, ev
            self._scale = scale
            if self.contact.trace:
                self._trace_iterate(norm, scale, jump)
            if norm <= c.rtol * scale and jump <= self.gap_tol:
                return True, it, residuals, ev
            if it == c.max_iterations:
                break
            R0 = self.b.copy()
            ok = self._solve(jump if jump > 0 else 0.0)
            self._dlift = self._lift_step() if ok else 0.0
            if not ok or not np.isfinite(self._dlift):
                R0.destroy()
                self._cause = "the linear solve failed (singular tangent or a non-finite correction)"
                return False, it, residuals, ev
            # dq . R(q) + dz_H (F - sum p) < 0: the energy slope (frame coordinates)
            s0 = self.dq.x.petsc_vec.dot(R0) + self._dlift * self._holder_imbalance()
            R0.destroy()
            from_frames(self.dq.x.array, self.rotated, self.frames)
            self._refreshing = True
            ok, norm, scale, ev, jump = self._line_search(lam, s0, jump)
            if not ok:
                return False, it + 1, residuals, ev
            residuals.append(norm)
            if (self._step <= self.early_step * self.contact.penetration
                    and self._set_will_change(lam)):
                self._early = True  # the set changes: end the pass here, not at convergence
                return True, it + 1, residuals, ev
        self._cause = f"no convergence in {c.max_iterations} iterations on a fixed contact set"
        return False, c.max_iterations, residuals, ev

    def _set_will_change(self, lam) -> bool:
        """Whether the contact set will change at the end of this pass, seen from this iterate:
        a free node penetrating a tool, a node drawn under the closed holder, or a node (not
        pinched) pulled off its tool by more than 1e-3 of the largest normal force."""
        x = self.positions()
        under = self.holder.under(x) if self.holder is not None else np.zeros(self.n_owned, dtype=bool)
        join, release, _ = self._set_changes(x, lam, under, self.net_normal_forces(), tensile=1e-3)
        return self.model.mesh.comm.allreduce(int(np.sum(join | release)), op=MPI.SUM) > 0

    def _set_changes(self, x, lam, under, net, tensile: float):
        """The nodes that join a tool (penetrating it by more than `penetration`, or drawn under
        the closed holder: onto the die) and those that leave theirs (not pinched, pulled off by
        more than `tensile` times the largest normal force), among the nodes that may still
        switch in this increment; with the tool each joining node joins."""
        s = self.state
        on, can = s.tool != FREE, s.toggles < self.contact.max_toggles
        scale = max(self._largest(net), 1e-300)
        release = on & ~self.pinched & (net < -tensile * scale) & can
        depth = np.stack([g for g, _ in self.gaps(x, lam)])  # (tools, nodes)
        deepest = np.argmin(depth, axis=0)
        enters = under & ~on & s.closed[0]  # the closed holder pinches what comes under it
        deepest[enters] = self.die
        allowed = np.full(len(x), self.contact.penetration)
        if self._holder_open():  # between the open holder's faces: as tight as the pinch it opened
            allowed[self._under] = self.gap_tol
        join = ~on & ((depth.min(axis=0) < -allowed) | enters) & can
        return join, release, deepest

    def _line_search(self, lam, s0, jump):
        """q += alpha dq, alpha first limited by the trust region (no node moves more than
        `trust` thicknesses), then shortened by secant steps where the energy slope
        dq . R(q + alpha dq) says the step overshoots (as the Driver's line search). A step
        that mostly moves nodes onto the tools (known corrections above 1 % of it) is a linear prediction of
        the free rows' response, R_free(q + alpha dq) ~ (1 - alpha) R_free(q): the slope says
        nothing of it, so it is only kept within the trust region and the material's reach."""
        c, comm = self.controls, self.model.mesh.comm
        n = self.n_owned
        dq = self.dq.x.array.copy()
        move = np.linalg.norm(dq.reshape(-1, BS)[:n, :3], axis=1).max(initial=0.0)
        move = comm.allreduce(float(move), op=MPI.MAX)
        alpha = min(1.0, self.contact.trust * self.model.thickness / max(move, 1e-300))
        if jump > max(self.gap_tol, 1e-2 * move):
            s0 = None  # the step mostly moves nodes onto the tools
        x0, lift0 = self.q.x.array.copy(), float(self.state.lift[0])
        norm = scale = ev = jump = None
        for _ in range(c.line_search + 1):
            self.q.x.array[:] = x0 + alpha * dq
            self.state.lift[0] = lift0 + alpha * self._dlift
            jump = self._constraints(lam)
            norm, scale, ev = self._trial(lam)
            if not np.isfinite(norm) or ev.failed:
                alpha *= 0.5  # outside the material's reach: shorten
                continue
            s1 = self._global_slope(dq) if s0 is not None else 0.0
            if self.contact.trace:
                say(f"      step: alpha {alpha:.3g} of a largest nodal move {move:.3g}, |R| {norm:.3e}, energy slope "
                    f"{s0 or 0:.3e} -> {s1:.3e}, known corrections {jump:.2e}")
            shorter = None if s0 is None else shorten(alpha, s0, s1)
            if shorter is None:
                self.line_search_factors.append(alpha)
                self._step = alpha * move
                return True, norm, scale, ev, jump
            alpha = shorter
        self._cause = f"the line search found no acceptable step ({ev.cause() or 'no energy descent'})"
        return False, norm, scale, ev, jump

    def _trace_iterate(self, norm, scale, jump):
        """The three owned nodes with the largest residual of this iterate, and what holds them."""
        R = self.b.getArray(readonly=True).reshape(-1, BS)
        r = np.linalg.norm(R, axis=1)
        x, s = self.positions(), self.state
        say(f"    iterate: |R| {norm:.3e} of {scale:.3e}, known corrections {jump:.2e}")
        for i in np.argsort(-r)[:3]:
            say(f"      node {i} at {self.X[i, :2].round(2)} -> {x[i].round(3)}: tool {s.tool[i]}, pinched {self.pinched[i]}, "
                f"normal {self.frames[i, 2].round(3)}, R (u, v, w) {R[i, :3].round(2)}, R (slopes) {R[i, 3:].round(1)}, "
                f"tool face {s.pressure[i]:.1f} N, holder face {s.holder_face[i]:.1f} N, friction normal "
                f"{s.normal[i]:.1f} N, friction "
                f"{self.friction.force[i].round(2)} ({'slip' if self.friction.slipping[i] else 'stick'})")

    def _global_slope(self, dq) -> float:
        """dq . R over all ranks, with R (free rows, nodal frames) rotated back to x, y, z, and
        the open holder's share dz_H (F - sum p)."""
        R = self.b.getArray(readonly=True).copy()
        from_frames(R, self.rotated, self.frames)
        return self.model.mesh.comm.allreduce(float(np.dot(dq[: R.size], R)), op=MPI.SUM) + \
            self._dlift * self._holder_imbalance()

    def reactions(self) -> np.ndarray:
        """(n_owned, 3) residual on the u, v, w rows in the nodal frames (tool forces on constrained rows)."""
        return self.residual_full[: self.n_owned * BS].reshape(-1, BS)[:, :3]

    def net_normal_forces(self, R=None) -> np.ndarray:
        """Each owned node's net normal force R0 from its tool (die minus holder on a pinched
        node; 0 off the tools), from the residual R (nodal frames; default: the last one)."""
        rows = self.reactions() if R is None else R[: self.n_owned * BS].reshape(-1, BS)
        return np.where(self.state.tool != FREE, rows[:, 2], 0.0)

    def _update_pass(self, lam):
        """After a converged pass: normal forces from the reactions, the holder's faces, release
        of tensile nodes (not pinched), join of penetrating ones. Returns (set changes on all
        ranks, |mu dp|, |mu p|, front): front where the set changed and every change was a
        node's first switch in this increment, the holder unchanged. Such a pass moves the
        contact front on (a sheet peeling off the punch's face releases one row of nodes per
        pass: 15 passes on 10,082 cells in the aluminium cup's first increment) and does
        not count against max_passes; a node switching back does."""
        t0 = time.perf_counter()
        s, x = self.state, self.positions()
        comm = self.model.mesh.comm
        net = self.net_normal_forces()
        s.pressure = np.maximum(net, 0.0)
        changes = 0
        under = self.holder.under(x) if self.holder is not None else np.zeros(self.n_owned, dtype=bool)
        if self.holder is not None:
            self._pinch(under, grow=True)
            changes = self._update_holder(x, under, net)
        holder_changes = changes
        join, release, deepest = self._set_changes(x, lam, under, net, tensile=1e-8)
        if self.contact.trace:
            for i in np.flatnonzero(release | join):
                say(f"      node {i} at {self.X[i, :2].round(2)} -> {x[i].round(3)}: "
                    + (f"leaves tool {s.tool[i]} (net normal force {net[i]:.3g} N)" if release[i] else
                       f"joins tool {deepest[i]}") + f", switch {s.toggles[i] + 1}")
        s.tool[release] = FREE
        s.tool[join] = deepest[join]
        if self.holder is not None:
            self._pinch(under, grow=True)  # the nodes drawn under the closed holder
        switched = release | join
        s.pressure[switched] = 0.0
        self.friction.forget(switched)  # a new contact starts without friction history
        s.toggles[switched] += 1
        changes += int(switched.sum())
        self._frozen = int((s.toggles >= self.contact.max_toggles).sum())
        changes, back = comm.allreduce(np.array([changes, holder_changes + int((s.toggles[switched] > 1).sum())]),
                                       op=MPI.SUM)
        changes = int(changes)
        dp, pn = self._relax_normal(changes)
        self.times["contact_s"] += time.perf_counter() - t0
        mu = self.friction.mu
        return changes, mu * dp, mu * pn, bool(changes > 0 and back == 0)

    def _relax_normal(self, changes):
        """The friction's normal force for the next pass from the faces' new sum p~: the fixed
        point p = p~(p) relaxed with Aitken's factor (Irons and Tuck), r = p~ - p,
        omega_k = -omega_k-1 r_k-1 . (r_k - r_k-1) / |r_k - r_k-1|^2 in [0.2, 1.5]: it damps a
        cycling p (a node whose faces swap) and speeds a slow one. Returns (|r|, |p~|)."""
        s, comm = self.state, self.model.mesh.comm
        target = s.pressure + s.holder_face
        r = target - s.normal
        dot = lambda a, b: comm.allreduce(float(np.dot(a, b)), op=MPI.SUM)  # noqa: E731
        omega = 1.0
        if changes == 0 and self._r_prev is not None:
            dr = r - self._r_prev
            dd = dot(dr, dr)
            if dd > 0:
                omega = float(np.clip(-self._omega * dot(self._r_prev, dr) / dd, 0.2, 1.5))
        if self.contact.trace and r.size:
            i = int(np.argmax(np.abs(r)))
            say(f"    normal force: omega {omega:.3g}; largest change at node {i} ({self.X[i, :2].round(2)}, tool "
                f"{s.tool[i]}, pinched {self.pinched[i]}): {s.normal[i]:.1f} -> {target[i]:.1f} N")
        self._r_prev, self._omega = (r, omega) if changes == 0 else (None, 1.0)
        s.normal = np.maximum(s.normal + omega * r, 0.0)
        s.normal[s.tool == FREE] = s.holder_face[s.tool == FREE]  # off the tools: the holder's load only
        return np.sqrt(dot(r, r)), np.sqrt(dot(target, target))

    def _commit(self):
        super()._commit()
        s = self.state
        s.toggles[:] = 0
        s.holder_toggles[:] = 0
        for part in self.parts:
            part.commit()
        c = self.committed
        self._previous = {"lam": self.lam_n, "tool": c.tool, "normal": c.normal}
        self.committed = s.copy()
        self.x_n = self.positions()
        self.pinched_n = self.pinched.copy()
        self.lam_n = self._lam_trial
        if self.model.plastic:
            _, e33 = self._nodal_areas_and_thickness_strain()
            self.half_thickness = 0.5 * self.model.thickness * np.exp(e33)

    # -- checkpoints -------------------------------------------------------------------------
    NODES = ("tool", "pressure", "holder_face", "normal")  # ContactState, per owned node
    GLOBAL = ("closed", "lift")  # ContactState, the holder's (the same on every rank)

    def checkpoint_state(self) -> dict:
        """The sheet's state and the contact's, as of the last converged increment: per owned
        node the committed contact set, forces and friction history, the pinched nodes, the
        positions and half thicknesses; the holder's state, the load factor and the tools'
        travel (shellform.nonlinear.checkpoint numbers the nodes globally)."""
        c, own = self.committed, super().checkpoint_state()
        own["nodes"].update({f"contact_{k}": getattr(c, k) for k in self.NODES})
        for part in self.parts:
            own["nodes"].update(part.checkpoint())
        own["nodes"].update({"contact_pinched": self.pinched_n, "contact_x_n": self.x_n,
                             "contact_half_thickness": self.half_thickness})
        own["global"].update({f"contact_{k}": getattr(c, k) for k in self.GLOBAL})
        own["global"].update({"contact_lam_n": np.array(self.lam_n), "contact_travel": self.travel,
                              "contact_early_step": np.array(self.early_step)})  # the fallback's
        if self._previous is not None:  # the predictor's: the committed set before the last
            own["nodes"].update({"contact_previous_tool": self._previous["tool"],
                                 "contact_previous_normal": self._previous["normal"]})
            own["global"]["contact_previous_lam"] = np.array(self._previous["lam"])
        return own

    def restore_state(self, state: dict, lam_scale: float | None = None) -> None:
        """As Driver's; the load factor is rescaled to this run's tool travel (a longer stroke
        continues from the same punch position)."""
        nodes, glob = state["nodes"], state["global"]
        if lam_scale is None:
            lam_scale = float(glob["contact_travel"][0] / self.travel[0])
        super().restore_state(state, lam_scale)
        if nodes["contact_tool"].shape != self.state.tool.shape:
            raise InputError("resume", "the checkpoint's contact state does not fit this model")
        c = ContactState(self.n_owned)
        for k in self.NODES:
            getattr(c, k)[...] = nodes[f"contact_{k}"]
        for k in self.GLOBAL:
            getattr(c, k)[...] = glob[f"contact_{k}"]
        self.committed, self.state = c, c.copy()
        for part in self.parts:
            part.restore(nodes)
        self.pinched = nodes["contact_pinched"].copy()
        self.pinched_n = self.pinched.copy()
        self.x_n = nodes["contact_x_n"].copy()
        self.lam_n = float(glob["contact_lam_n"]) * lam_scale
        self.half_thickness = nodes["contact_half_thickness"].copy()
        if "contact_early_step" in glob:
            self.early_step = float(glob["contact_early_step"])
        self._previous = None
        if "contact_previous_lam" in glob:
            self._previous = {"lam": float(glob["contact_previous_lam"]) * lam_scale,
                              "tool": nodes["contact_previous_tool"].copy(),
                              "normal": nodes["contact_previous_normal"].copy()}

    def _restore_converged(self):
        """The committed contact state and its forces (a stop reports the last converged state)."""
        self.state = self.committed.copy()
        for part in self.parts:
            part.start()
        self._lam_trial = self.lam_n
        self.model.converged_lever()
        if self.holder is not None:
            self._pinch(self.holder.under(self.x_n), grow=False)
        self._constraints(self.lam)
        self.residual(self.lam, tangent=False)

    def _increment_info(self):
        alphas = self.line_search_factors
        return {"passes": self._passes, "set_changes": self._changes, "frozen": self._frozen,
                "in_contact": self.count_in_contact(), "min_line_search": min(alphas) if alphas else 1.0,
                "holder_closed": bool(self.state.closed[0]), "holder_lift": float(self.state.lift[0])}

    def count_in_contact(self) -> dict:
        """Nodes on each tool (the open holder last) and pinched by the holder, all ranks:
        {"tool0": ..., "pinched": ...}."""
        comm = self.model.mesh.comm
        counts = {f"tool{k}": comm.allreduce(int((self.state.tool == k).sum()), op=MPI.SUM)
                  for k in range(len(self.tools) + (self.holder is not None))}
        counts["pinched"] = comm.allreduce(int(self.pinched.sum()), op=MPI.SUM)
        return counts
