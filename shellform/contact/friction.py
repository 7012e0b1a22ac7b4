"""Coulomb friction on the nodes that rub on a tool or under the holder: a part of the contact.

Integrated as a return mapping, like non-associated plasticity. With a node's slip increment ds
relative to its tool (the tangential part), its tangential force f_n of the last converged
increment (the history) and the stick stiffness k_t:

    trial  f* = f_n - k_t ds,   |f*| <= mu p: stick, f = f*,   df/ds = -k_t I
                               |f*| >  mu p: slip,  f = mu p f*/|f*|,
                                                    df/ds = -k_t (mu p/|f*|) (I - m m^T),  m = f*/|f*|

with mu the node's coefficient mu_i (friction per tool, below) and k_t = STICK_STIFFNESS E A_i / h
per node (A_i its tributary area, h the cell size), so that the elastic slip before sliding,
mu p / k_t, is a small fraction of a cell, yet long against Newton's steps on a node nearly at
rest (docs/contact.md: E A_i / h itself made such a node reverse its force within every step).
The node's residual gets -f in its nodal frame, the tangent -df/ds in the frame's tangent slots.

Where Newton's iterates update the normal force p (the contact driver's refresh of p from the
reactions), the slipping force's dependence on it enters the tangent too:

    d(-f_i)/dq = -m_i (d(mu_i p_i)/dR0_i) K_(i,n),   dp/dR0 = 1 on a tool, sign(R0) on a pinched node

(K_(i,n) the node's normal row of the sheet's tangent, R0 its net normal force; non-symmetric),
on the free tangent rows of every slipping node: in K on the free columns, and on the known
columns through the solve's lift of the known corrections (lift_known), which K cannot carry. Those
corrections do not all vanish after a pass's first iterate: a node ironed between two faces
lies at half the clearance through it, which moves with the node.

The normal force p (both faces of a pinched node) is the part's too. Within a Newton pass it is
taken from the reactions of every iterate after the first (the contact set's faces), so that
Newton converges p with the displacements; the first iterate of a pass keeps the p of the pass
before. Between passes p is the fixed point p = p~(p) of the faces' new sum p~, relaxed with
Aitken's factor (Irons and Tuck), r = p~ - p,

    omega_k = -omega_k-1 r_k-1 . (r_k - r_k-1) / |r_k - r_k-1|^2   in [0.2, 1.5],

which damps a cycling p (a node whose faces swap) and speeds a slow one; the passes go on until
|mu r| <= friction_rtol |mu p~| (2-norms over the nodes, each node's term times its own mu_i).
With the driver's predictor, an increment's first p is extrapolated from the last two
increments, as the carrier is (nodes on the same tool in both).

Friction per tool. Each tool carries its own coefficient (a lubricated punch, a dry binder): mu is
one coefficient for every tool, or one per tool of the contact set in its order (punch, die, ...)
then the holder's, whose face is the last tool (the open holder's face, or a holder held at a
gap); the closed holder's face on a pinched node and a node off the tools carry the holder's too.
A node's coefficient follows the faces it lies between, with d_i the normal force of its tool's
face (the die's on a pinched node) and h_i the holder's face's:

    mu_i = mu_tool + (mu_holder - mu_tool) h_i / (d_i + h_i)   (mu_tool where d_i + h_i = 0)

so that its Coulomb limit mu_i p_i, with p_i = d_i + h_i, is mu_tool d_i + mu_holder h_i: a
pinched node slips on both faces at once (the die and the holder stand still, the node has one
slip), so the faces' limits add, each face's normal force times its own tool's coefficient. It is
read from the contact set's faces at every return mapping (each iterate, each refresh of p), so
that it follows the face forces as p does. The slipping force's normal-force tangent carries each
face's own slope,

    d(mu_i p_i)/dR0_i = mu_tool dd_i/dR0_i + mu_holder dh_i/dR0_i,

and the passes' test weighs each node's change of p by its coefficient (|mu_i r_i| against
|mu_i p~_i|). With every coefficient equal, mu_i = mu exactly and each expression reduces to the one
coefficient's, bit for bit.

Sensitivities (nonlinear/sensitivity.py) differentiate the return mapping with the stick and
slip states held (forces_at): at fixed q through the history, the committed positions, the
normal forces and the coefficients (pseudo_load), and along the solved derivative for the next
increment's history (carry). On several ranks the normal-force term of a node on a rank's
boundary gathers that node's cells on every rank (the owners' coefficients and directions sent
to the ghosts, a ghost's lift sent back to its owner).

The part owns its history (committed with an increment, forgotten where a node switches tools),
its coefficients, its normal forces and the forces, stiffness and slip state of the current
iterate; the contact set (contact_set.py) tells it which nodes rub on which tool and with which
face forces.
"""

import numpy as np
from dolfinx import fem, la
from mpi4py import MPI

from shellform.assembly.sheet_element import BS
from shellform.nonlinear.frames import add_tangent_slot_stiffness, subtract_nodal_forces
from shellform.nonlinear.parts import Change, Part
from shellform.results.log import say


class CoulombFriction(Part):
    """Coulomb friction on n owned nodes with mu: one coefficient for every tool, or one per tool
    of the contact set in its order, then the holder's (module docstring; k_stick: their stick
    stiffness; held: (n, 2) tangent slots a symmetry plane holds, which get no stiffness);
    contact: the ContactSet whose nodes rub; rtol: friction_rtol."""

    STICK_STIFFNESS = 0.01  # k_t per node over E A_i / h

    def __init__(self, mu, k_stick: np.ndarray, held: np.ndarray, contact=None, nodes=None,
                 rtol: float = 1e-4, trace: bool = False):
        n = len(k_stick)
        self.mu, self.k_stick, self.held = mu, k_stick, held
        self.coefficient = np.zeros(n)  # mu_i of each node at the last return mapping
        self.table = None  # mu per tool of the contact set, the holder's last (bind)
        self.contact, self.nodes, self.rtol, self.trace = contact, nodes, rtol, trace
        self.normal = np.zeros(n)  # p, the normal force friction uses (both faces)
        self.committed_normal = self.normal.copy()
        self.previous = None  # (lam, tool, p) of the increment before the last converged one
        self.last = None  # (lam, tool, p) of the last converged one
        self.refreshing = False
        self._r_prev, self._omega = None, 1.0
        self.frames = None
        self.history = np.zeros((n, 3))  # the tangential forces of the last converged increment (x, y, z)
        self.committed = self.history.copy()
        self.force = np.zeros((n, 3))  # of the current iterate (x, y, z)
        self.rate = np.zeros((n, 2, 2))  # -df/ds in the nodes' tangent slots
        self.slipping = np.zeros(n, dtype=bool)
        self.forgotten = np.zeros(n, dtype=bool)
        self.dhistory, self.dforce = {}, {}  # per parameter: d/dp of the history, of this increment's forces
        self._ghosts = None  # a work function: the ghosts' values of the normal-force tangent
        self.known_columns = None  # that tangent's terms on the known columns (lift_known)

    @property
    def active(self) -> bool:
        return float(np.max(self.mu)) > 0

    def derivatives(self) -> str | None:
        """Friction is differentiated with the stick and slip states held (pseudo_load, carry);
        on a pinched node through the holder's split (normal_rates)."""
        return None

    def tangent_misses(self) -> bool:
        """Its tangent holds the pinched nodes' split of the holder's force fixed but for each
        node's own R0, and leaves out the turn of a curved tool's normal towards the friction
        force (carry): a sensitivity's solve is corrected."""
        return self.active

    def per_tool(self) -> np.ndarray:
        """mu per tool of the contact set (its order, the holder's last): the scene's one
        coefficient for each, or its own."""
        tools = len(self.contact.tools) + (self.contact.holder is not None)
        mu = np.asarray(self.mu, dtype=float)
        if mu.ndim == 0:
            return np.full(tools, float(mu))
        if mu.shape != (tools,):
            raise ValueError(f"friction: one coefficient, or one per tool and the holder's ({tools}), got {self.mu!r}")
        return mu

    def coefficients(self) -> np.ndarray:
        """mu_i per owned node from the contact set's faces now (module docstring): its tool's
        (FREE: the holder's), moved towards the holder's by the holder face's share of its normal
        forces."""
        c, table = self.contact, self.table
        tool_mu = table[c.tool]  # FREE (-1): the last, the holder's
        d, h = c.faces()
        total = d + h
        share = np.divide(h, total, out=np.zeros_like(total), where=total > 0)
        return tool_mu + (table[-1] - tool_mu) * share

    def bind(self, driver) -> None:
        self.table = self.per_tool()  # mu per tool, the holder's last (checked here, once)
        self.comm = driver.model.mesh.comm
        self.normal = self.contact.face_forces()
        self.committed_normal = self.normal.copy()
        self.last = (0.0, self.contact.tool.copy(), self.committed_normal)

    # -- the increment's history ----------------------------------------------------------------
    def start(self, lam: float = 0.0, predicting: bool = False) -> None:
        """An increment (or a retry of it) starts from the committed history and normal forces,
        extrapolated where the driver predicts."""
        self.history = self.committed.copy()
        self.forgotten = np.zeros(self.history.shape[0], dtype=bool)  # nodes whose history this increment forgot
        self.normal = self.committed_normal.copy()
        self._r_prev, self._omega = None, 1.0  # Aitken's memory of the normal-force updates
        prev = self.previous
        if not (predicting and prev is not None):
            return
        lam_n = self.last[0]
        ratio = (lam - lam_n) / (lam_n - prev[0])
        same = self.contact.tool == prev[1]
        p = self.normal
        p[same] = np.maximum(p[same] + ratio * (p[same] - prev[2][same]), 0.0)

    def begin_pass(self) -> None:
        self.refreshing = False

    def stepped(self, yes: bool) -> None:
        self.refreshing = yes

    def forget(self, nodes: np.ndarray) -> None:
        """Nodes that switched tools start without history."""
        self.history[nodes] = 0.0
        self.forgotten[nodes] = True

    def commit(self, lam: float = 0.0) -> None:
        """The increment converged: its forces are the next one's history (and their
        derivatives, where carry gave them, the next one's history derivatives)."""
        self.dhistory.update(self.dforce)
        self.dforce = {}
        self.committed = self.force.copy()
        self.history = self.committed.copy()
        self.previous = self.last
        self.committed_normal = self.normal.copy()
        self.last = (lam, self.contact.tool.copy(), self.committed_normal) if self.contact is not None else None

    def checkpoint(self) -> dict:
        nodes = {"contact_friction": self.committed, "contact_normal": self.committed_normal}
        glob = {}
        if self.previous is not None:
            nodes.update({"contact_previous_tool": self.previous[1], "contact_previous_normal": self.previous[2]})
            glob["contact_previous_lam"] = np.array(self.previous[0])
        return {"nodes": nodes, "global": glob}

    def restore(self, state: dict, lam_scale: float = 1.0) -> None:
        nodes, glob = state["nodes"], state.get("global", {})
        self.committed = nodes["contact_friction"].copy()
        self.history = self.committed.copy()
        if "contact_normal" in nodes:
            self.committed_normal = nodes["contact_normal"].copy()
            self.normal = self.committed_normal.copy()
        if self.contact is not None and "contact_lam_n" in glob:
            self.last = (float(glob["contact_lam_n"]) * lam_scale, self.contact.tool.copy(), self.committed_normal)
        self.previous = None
        if "contact_previous_lam" in glob:
            self.previous = (float(glob["contact_previous_lam"]) * lam_scale, nodes["contact_previous_tool"].copy(),
                             nodes["contact_previous_normal"].copy())

    # -- the part's protocol: one iterate --------------------------------------------------------
    def follow(self, frames: np.ndarray, lam: float) -> None:
        """The return mapping at the iterate, on every node on a tool or pressed (by the holder)."""
        c, n = self.contact, self.nodes.n_owned
        self.normal[c.slid_off] = c.face_forces()[c.slid_off]
        self.frames = frames
        rub = np.flatnonzero(c.on_tools() | (self.normal > 0))
        self._rub = (rub, c.shift[rub], self.nodes.positions(), frames[:n][rub])
        self._map()

    def _map(self):
        """The return mapping on the rubbing nodes of this iterate with the current p and the
        coefficients of the current faces."""
        idx, shift, x, F = self._rub
        if self.active:
            self.coefficient = self.coefficients()
        self.slip(idx, shift, x, self.nodes.x_n, F, self.normal)

    def add_residual(self, R: np.ndarray) -> None:
        """R -= f; on the iterates after a pass's first, p from this iterate's faces first (the
        contact set's, which follow the reactions there), the return mapping again with it."""
        n = self.nodes.n_owned
        if not self.active:
            return
        if self.refreshing:
            self.normal = self.contact.face_forces()
            self._map()
        subtract_nodal_forces(R[: n * BS].reshape(-1, BS)[:, :3], self.frames[:n], self.force)

    def add_tangent(self, K, R: np.ndarray, fixed: np.ndarray) -> None:
        """K += -df/ds; on the iterates after a pass's first, the slip force's dp/dq too."""
        self.known_columns = None
        if not self.active:
            return
        add_tangent_slot_stiffness(K, self.rate)
        if self.refreshing:
            on = self.slipping & self.contact.on_tools() & (self.normal > 0)
            coef = np.where(on, self.limit_slopes(), 0.0)
            self.add_normal_force_tangent(K, self.contact.nodes.model, coef, self.frames, self.normal, fixed,
                                          self.nodes.n_local)

    def limit_slopes(self) -> np.ndarray:
        """d(mu_i p_i)/dR0_i / mu_i per owned node (0 where mu_i = 0): each face's slope
        (ContactSet.face_slopes) times its own coefficient over the node's (module docstring);
        the faces' dp/dR0 where the coefficients are equal."""
        table = self.table
        tool_mu = table[self.contact.tool]
        mu = self.coefficient
        on = mu > 0
        d_slope, h_slope = self.contact.face_slopes()
        own = np.divide(tool_mu, mu, out=np.zeros_like(mu), where=on)
        holder = np.divide(np.full_like(mu, table[-1]), mu, out=np.zeros_like(mu), where=on)
        return d_slope * own + h_slope * holder

    def update_normal(self, changes: int, weight=1.0):
        """Between passes: p relaxed towards the faces' new sum (module docstring). Returns
        (|weight r|, |weight p~|) (weight: per node, or one for all)."""
        c = self.contact
        target = c.face_forces()
        r = target - self.normal
        dot = lambda a, b: self.comm.allreduce(float(np.dot(a, b)), op=MPI.SUM)  # noqa: E731
        omega = 1.0
        if changes == 0 and self._r_prev is not None:
            dr = r - self._r_prev
            dd = dot(dr, dr)
            if dd > 0:
                omega = float(np.clip(-self._omega * dot(self._r_prev, dr) / dd, 0.2, 1.5))
        if self.trace and r.size:
            i = int(np.argmax(np.abs(r)))
            say(f"    normal force: omega {omega:.3g}; largest change at node {i}: {self.normal[i]:.1f} -> "
                f"{target[i]:.1f} N")
        self._r_prev, self._omega = (r, omega) if changes == 0 else (None, 1.0)
        self.normal = np.maximum(self.normal + omega * r, 0.0)
        free = ~c.on_tools()
        self.normal[free] = target[free]  # off the tools: the holder's load only
        wr, wt = weight * r, weight * target
        return np.sqrt(dot(wr, wr)), np.sqrt(dot(wt, wt))

    def update(self, lam: float, changes: int) -> Change:
        """After a converged pass: forget the history of the nodes that switched, relax p; the
        passes converge once |mu_i r_i| <= rtol |mu_i p~_i| (the coefficients of the new faces,
        over the largest mu: a weight of 1 where they are all equal)."""
        self.forget(self.contact.switched)
        mu = float(np.max(self.table))
        weight = self.coefficients() / mu if mu > 0 else 1.0
        dp, pn = self.update_normal(changes, weight)
        return Change(0, 0, bool(mu * dp <= self.rtol * mu * pn),
                      f"friction change |mu dp| {mu * dp:.3e} of |mu p| {mu * pn:.3e}")

    # -- derivatives (nonlinear/sensitivity.py) --------------------------------------------------
    def forces_at(self, x, x_n, normals, history, normal, coefficient) -> np.ndarray:
        """(n_owned, 3): the return mapping's forces on this iterate's rubbing nodes with every
        input given (positions x, x_n, their tools' normals, the history, the normal forces and
        coefficients) and the stick and slip states held as they are (slip's formulas): the map
        a sensitivity differentiates."""
        idx, shift = self._rub[0], self._rub[1]
        trial, size = self._trial(idx, shift, x, x_n, normals[idx], history)
        limit = coefficient[idx] * normal[idx]
        ratio = np.where(self.slipping[idx], limit / np.maximum(size, 1e-300), 1.0)
        out = np.zeros_like(self.force)
        out[idx] = ratio[:, None] * trial
        return out

    def _differences(self, key, eps, x, dx, dx_n, normals, dnormal, dmu):
        """(f(+eps) - f(-eps)) / 2 eps of forces_at along (dx, dx_n, the history's derivative,
        dnormal, the coefficients' dmu); normals: a function of the positions."""
        dh = self.dhistory.get(key, np.zeros_like(self.history))
        dh = np.where(self.forgotten[:, None], 0.0, dh)
        ends = [self.forces_at(x + s * eps * dx, self.nodes.x_n + s * eps * dx_n, normals(x + s * eps * dx),
                               self.history + s * eps * dh, self.normal + s * eps * dnormal,
                               self.coefficient + s * eps * dmu) for s in (1.0, -1.0)]
        return (ends[0] - ends[1]) / (2 * eps)

    def normal_rates(self, parameter, dnet: np.ndarray, x: np.ndarray, dx: np.ndarray, eps: float):
        """(dp, dmu) per owned node: d/dp of the normal forces and the coefficients friction
        presses with, given the net normal forces' derivative dnet and the positions' dx. On a
        tool dp = dR0/dp where it presses and dmu the parameter's rate for that tool; on a node
        the closed holder pinches, the derivative of its split (ContactSet.face_derivatives):
        dp = dd + dh, and mu_i = mu_tool + (mu_holder - mu_tool) h / (d + h) moves with both
        the rates and the holder face's share."""
        c = self.contact
        rates = getattr(parameter, "rates", None)
        dnormal = np.where(c.on_tools() & (self.normal > 0), dnet, 0.0)
        dmu = np.asarray(rates, dtype=float)[c.tool] if rates is not None else np.zeros(dnet.size)
        split = c.face_derivatives(parameter, dnet, x, dx, eps)
        if split is not None:
            (dd, dh), pinched = split
            d, h = c.faces()
            p = d + h
            share = np.divide(h, p, out=np.zeros_like(p), where=p > 0)
            dshare = np.divide(dh * d - h * dd, p * p, out=np.zeros_like(p), where=p > 0)
            table = self.table
            rate_h = float(rates[-1]) if rates is not None else 0.0
            mu = dmu + (rate_h - dmu) * share + (table[-1] - table[c.tool]) * dshare
            dnormal = np.where(pinched, dd + dh, dnormal)
            dmu = np.where(pinched, mu, dmu)
        return dnormal, dmu

    def pseudo_load(self, key: str, rhs: np.ndarray, dx_n: np.ndarray, eps: float, parameter=None) -> None:
        """rhs ((n_owned, BS), the nodes' frames: dR/dp at fixed q, the sheet's) -= the friction
        forces' derivative at fixed q, turned into the frames: through the history's derivative,
        the committed positions' (dx_n), the normal forces' (normal_rates along dR0/dp, the
        normal rows of rhs: where the tool presses, and the holder's split) and the
        coefficients' (the parameter's rates per tool)."""
        if not self.active:
            return
        n = self.nodes.n_owned
        x = self.nodes.positions()
        fixed = self.frames[:n, 2]
        dnormal, dmu = self.normal_rates(parameter, rhs[:, 2], x, np.zeros_like(x), eps)
        df = self._differences(key, eps, x, np.zeros_like(x), dx_n, lambda _: fixed, dnormal, dmu)
        rhs[:, :3] -= np.einsum("nij,nj->ni", self.frames[:n], df)

    def carry(self, key: str, dx: np.ndarray, dx_n: np.ndarray, dR: np.ndarray, lam: float, eps: float,
              parameter=None) -> None:
        """The converged forces' derivative (the next increment's history derivative, at commit):
        forces_at along the positions' derivative dx (their tools' normals following them), the
        committed positions' dx_n, the normal forces' total derivative (normal_rates along dR's
        normal rows and dx)."""
        if not self.active:
            return
        x = self.nodes.positions()
        normals = lambda y: self.contact.normals_at(y, lam)  # noqa: E731
        # R0 = n . R_sheet and R_sheet = R0 n + f on a node on a tool: as the node moves on a
        # curved tool its normal turns towards the friction force, R0' = n . R_sheet' + n' . f
        # (dR's normal row is n . R_sheet', the frames held)
        turn = np.einsum("ni,ni->n", (normals(x + eps * dx) - normals(x - eps * dx)) / (2 * eps), self.force)
        dnormal, dmu = self.normal_rates(parameter, dR[:, 2] + turn, x, dx, eps)
        self.dforce[key] = self._differences(key, eps, x, dx, dx_n, normals, dnormal, dmu)

    def total_derivative(self, key: str, dR: np.ndarray) -> None:
        if key in self.dforce:
            n = self.nodes.n_owned
            dR[:, :3] -= np.einsum("nij,nj->ni", self.frames[:n], self.dforce[key])

    def derivative_state(self, key: str) -> dict:
        return {"friction_dhistory": self.dhistory.get(key, np.zeros_like(self.history))}

    def restore_derivative_state(self, key: str, state: dict) -> None:
        self.dhistory[key] = state["friction_dhistory"].copy()

    # -- one iterate ---------------------------------------------------------------------------
    def _trial(self, idx, shift, x, x_n, n, history):
        """The elastic trial force f_n - k_t ds of the rubbing nodes idx (normals n) and its size:
        the history f_n and the slip increment ds = x - x_n - shift, both turned into the tangent
        plane."""
        ds = x[idx] - x_n[idx]
        ds -= shift
        ds -= np.sum(ds * n, axis=1)[:, None] * n  # tangential slip increment
        h = history[idx]
        f_old = h - np.sum(h * n, axis=1)[:, None] * n
        trial = f_old - self.k_stick[idx][:, None] * ds
        return trial, np.linalg.norm(trial, axis=1)

    def slip(self, idx, shift, x, x_n, F, normal) -> None:
        """The return mapping on the rubbing nodes idx at positions x (x_n: at the start of the
        increment; shift: their tool's travel in it, (m, 3); F: their frames, normal F[:, 2]) with the
        normal forces `normal` and the coefficients self.coefficient (all nodes); every other node
        carries no friction."""
        self.force[:] = 0.0
        self.rate[:] = 0.0
        self.slipping[:] = False
        if not self.active:
            return
        k = self.k_stick[idx]
        trial, size = self._trial(idx, shift, x, x_n, F[:, 2], self.history)
        limit = self.coefficient[idx] * normal[idx]
        slip = size > (1 - 1e-6) * limit  # on the cone (a node that slipped): keeps slipping, slip tangent
        ratio = np.where(slip, limit / np.maximum(size, 1e-300), 1.0)
        m2 = np.einsum("nij,nj->ni", F[:, :2], trial) / np.maximum(size, 1e-300)[:, None]
        rate = (k * ratio)[:, None, None] * (np.eye(2) - slip[:, None, None] * m2[:, :, None] * m2[:, None, :])
        held = self.held[idx]  # a symmetry plane holds that slot: no rate there
        rate[held[:, :, None] | held[:, None, :]] = 0.0
        self.force[idx] = ratio[:, None] * trial
        self.rate[idx] = rate
        self.slipping[idx] = slip

    def add_normal_force_tangent(self, K, model, coef, frames, normal, fixed, n_local) -> None:
        """K += the slipping force's dependence on its normal force (module docstring): coef,
        per owned node, dp/dR0 where the node slips on a tool with p > 0 and 0 elsewhere; frames
        (local nodes) and normal (owned) as update() had them; fixed: the known rows (local
        dofs), whose rows get nothing; on their columns the term goes to the lift (lift_known)."""
        n = len(coef)
        on = coef != 0
        g = np.zeros((n_local, 2))
        g[:n][on] = np.einsum("nij,nj->ni", frames[:n][on][:, :2], self.force[on]) / normal[on, None]
        c = np.zeros(n_local)
        c[:n] = coef
        if self.comm.size > 1:  # a node's normal row gathers the cells of every rank: ghosts get the owners' c, g
            c, g = self._to_ghosts(model, c, g)
        cells, local = np.nonzero(c[model.dofs] != 0)
        if cells.size == 0:
            if self.comm.size > 1:  # nothing here, but lift_known's exchange is every rank's
                self.known_columns = (np.zeros((0, 2), dtype=np.int64), np.zeros((0, 2)), np.zeros((0, 1)),
                                      np.zeros((0, 1), dtype=np.int64))
            return
        b = model.dofs[cells, local]
        rows = BS * b[:, None] + np.arange(2)  # (pairs, 2): the node's tangent slots in this cell
        g = np.where(fixed[rows], 0.0, g[b])  # none on a row held by symmetry
        row = model.forms.matrices[cells, BS * local + 2]  # (pairs, cell dofs): the normal row
        columns = model.unrolled_dofs[cells]
        known = fixed[columns]
        # on the free columns into K; on the known ones (a node on a tool whose face moves with
        # it, ironed between two faces, keeps a known correction after a pass's first iterate)
        # into the lift (lift_known)
        self.known_columns = (rows, -c[b][:, None] * g, np.where(known, row, 0.0), columns)
        values = -c[b][:, None, None] * g[:, :, None] * np.where(known, 0.0, row)[:, None, :]
        K.setValuesLocalRCV(rows.astype(np.int32), columns.astype(np.int32),
                            values.reshape(len(b), -1), addv=True)

    def _to_ghosts(self, model, c: np.ndarray, g: np.ndarray):
        """(c, g) with the ghost nodes' values their owners' (the owned ones as given)."""
        if self._ghosts is None:
            self._ghosts = fem.Function(model.V)
        arr = self._ghosts.x.array.reshape(-1, BS)
        arr[:] = 0.0
        arr[:, 0], arr[:, 1:3] = c, g
        self._ghosts.x.scatter_forward()
        return arr[:, 0].copy(), arr[:, 1:3].copy()

    def lift_known(self, delta: np.ndarray, b: np.ndarray) -> None:
        """b -= the slipping force's normal-force tangent on the known columns times their
        corrections (Part.lift_known): a known correction of a node's neighbours (or of its own normal
        row) changes its normal force, and with it the slip force mu p. A ghost node's rows (its
        cells on this rank) go to its owner."""
        if self.known_columns is None:
            return
        rows, scale, row, columns = self.known_columns
        values = scale * np.einsum("pj,pj->p", row, delta[columns])[:, None]
        mine = rows[:, 0] < b.size
        np.subtract.at(b, rows[mine], values[mine])
        if self.comm.size > 1:  # collective: every rank sends its ghosts' rows, if any
            work = self._ghosts
            work.x.array[:] = 0.0
            np.add.at(work.x.array, rows[~mine], values[~mine])
            work.x.scatter_reverse(la.InsertMode.add)
            b -= work.x.array[: b.size]
