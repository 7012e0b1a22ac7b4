"""Coulomb friction on the nodes that rub on a tool or under the holder: a part of the contact.

Integrated as a return mapping, like non-associated plasticity. With a node's slip increment ds
relative to its tool (the tangential part), its tangential force f_n of the last converged
increment (the history) and the stick stiffness k_t:

    trial  f* = f_n - k_t ds,   |f*| <= mu p: stick, f = f*,   df/ds = -k_t I
                               |f*| >  mu p: slip,  f = mu p f*/|f*|,
                                                    df/ds = -k_t (mu p/|f*|) (I - m m^T),  m = f*/|f*|

with k_t = STICK_STIFFNESS E A_i / h per node (A_i its tributary area, h the cell size), so that
the elastic slip before sliding, mu p / k_t, is a small fraction of a cell, yet long against
Newton's steps on a node nearly at rest (docs/contact.md: E A_i / h itself made such a node
reverse its force within every step). The
node's residual gets -f in its nodal frame, the tangent -df/ds in the frame's tangent slots.

Where Newton's iterates update the normal force p (the contact driver's refresh of p from the
reactions), the slipping force's dependence on it enters the tangent too:

    d(-f_i)/dq = -mu m_i (dp_i/dR0_i) K_(i,n),   dp/dR0 = 1 on a tool, sign(R0) on a pinched node

(K_(i,n) the node's normal row of the sheet's tangent, R0 its net normal force; non-symmetric),
on the free tangent rows of every slipping node, in the free columns.

The part owns its history (committed with an increment, forgotten where a node switches tools)
and the forces, stiffness and slip state of the current iterate; the contact driver tells it
which nodes rub, where they are and on what frames, and with which normal forces.
"""

import numpy as np

from shellform.assembly.sheet_element import BS
from shellform.contact.frames import add_tangent_slot_stiffness, subtract_nodal_forces


class CoulombFriction:
    """Coulomb friction with coefficient mu on n owned nodes (k_stick: their stick stiffness;
    held: (n, 2) tangent slots a symmetry plane holds, which get no stiffness)."""

    STICK_STIFFNESS = 0.01  # k_t per node over E A_i / h

    def __init__(self, mu: float, k_stick: np.ndarray, held: np.ndarray):
        n = len(k_stick)
        self.mu, self.k_stick, self.held = float(mu), k_stick, held
        self.history = np.zeros((n, 3))  # the tangential forces of the last converged increment (x, y, z)
        self.committed = self.history.copy()
        self.force = np.zeros((n, 3))  # of the current iterate (x, y, z)
        self.rate = np.zeros((n, 2, 2))  # -df/ds in the nodes' tangent slots
        self.slipping = np.zeros(n, dtype=bool)
        self.slip_rows = None  # (dp/dR0, g = f/p in the tangent slots) of the last normal-force tangent

    @property
    def active(self) -> bool:
        return self.mu > 0

    # -- the increment's history ----------------------------------------------------------------
    def start(self) -> None:
        """An increment (or a retry of it) starts from the committed history."""
        self.history = self.committed.copy()

    def forget(self, nodes: np.ndarray) -> None:
        """Nodes that switched tools start without history."""
        self.history[nodes] = 0.0

    def commit(self) -> None:
        """The increment converged: its forces are the next one's history."""
        self.committed = self.force.copy()
        self.history = self.committed.copy()

    def checkpoint(self) -> dict:
        return {"contact_friction": self.committed}

    def restore(self, nodes: dict) -> None:
        self.committed = nodes["contact_friction"].copy()
        self.history = self.committed.copy()

    # -- one iterate ---------------------------------------------------------------------------
    def update(self, idx, shift, x, x_n, F, normal) -> None:
        """The return mapping on the rubbing nodes idx at positions x (x_n: at the start of the
        increment; shift: their tool's z-travel in it; F: their frames, normal F[:, 2]) with the
        normal forces `normal` (all nodes); every other node carries no friction."""
        self.force[:] = 0.0
        self.rate[:] = 0.0
        self.slipping[:] = False
        if not self.active:
            return
        n = F[:, 2]
        ds = x[idx] - x_n[idx]
        ds[:, 2] -= shift
        ds -= np.sum(ds * n, axis=1)[:, None] * n  # tangential slip increment
        h = self.history[idx]
        f_old = h - np.sum(h * n, axis=1)[:, None] * n
        k = self.k_stick[idx]
        trial = f_old - k[:, None] * ds
        size = np.linalg.norm(trial, axis=1)
        limit = self.mu * normal[idx]
        slip = size > (1 - 1e-6) * limit  # on the cone (a node that slipped): keeps slipping, slip tangent
        ratio = np.where(slip, limit / np.maximum(size, 1e-300), 1.0)
        m2 = np.einsum("nij,nj->ni", F[:, :2], trial) / np.maximum(size, 1e-300)[:, None]
        rate = (k * ratio)[:, None, None] * (np.eye(2) - slip[:, None, None] * m2[:, :, None] * m2[:, None, :])
        held = self.held[idx]  # a symmetry plane holds that slot: no rate there
        rate[held[:, :, None] | held[:, None, :]] = 0.0
        self.force[idx] = ratio[:, None] * trial
        self.rate[idx] = rate
        self.slipping[idx] = slip

    def add_residual(self, R3: np.ndarray, frames: np.ndarray) -> None:
        """R -= f on the owned nodes' u, v, w rows (R3), in their nodal frames."""
        subtract_nodal_forces(R3, frames, self.force)

    def add_tangent(self, K) -> None:
        """K += -df/ds in the tangent slots of the rubbing nodes."""
        add_tangent_slot_stiffness(K, self.rate)

    def add_normal_force_tangent(self, K, model, coef, frames, normal, fixed, n_local) -> None:
        """K += the slipping force's dependence on its normal force (module docstring): coef,
        per owned node, dp/dR0 where the node slips on a tool with p > 0 and 0 elsewhere; frames
        (local nodes) and normal (owned) as update() had them; fixed: the known rows (local
        dofs), whose rows and columns get nothing. Keeps (coef, g) for the holder's lift."""
        n = len(coef)
        on = coef != 0
        g = np.zeros((n_local, 2))
        g[:n][on] = np.einsum("nij,nj->ni", frames[:n][on][:, :2], self.force[on]) / normal[on, None]
        self.slip_rows = (coef.copy(), np.where(self.held, 0.0, g[:n]))
        c = np.zeros(n_local)
        c[:n] = coef
        cells, local = np.nonzero(c[model.dofs] != 0)
        if cells.size == 0:
            return
        b = model.dofs[cells, local]
        rows = BS * b[:, None] + np.arange(2)  # (pairs, 2): the node's tangent slots in this cell
        g = np.where(fixed[rows], 0.0, g[b])  # none on a row held by symmetry
        row = model.forms.matrices[cells, BS * local + 2]  # (pairs, cell dofs): the normal row
        # not on the known columns, whose corrections vanish after a pass's first iterate
        row = np.where(fixed[model.unrolled_dofs[cells]], 0.0, row)
        values = -c[b][:, None, None] * g[:, :, None] * row[:, None, :]
        K.setValuesLocalRCV(rows.astype(np.int32), model.unrolled_dofs[cells].astype(np.int32),
                            values.reshape(len(b), -1), addv=True)
