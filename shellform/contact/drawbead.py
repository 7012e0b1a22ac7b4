"""Drawbeads: a part of the contact that restrains the flange's flow across a line.

The equivalent drawbead model (Stoughton 1988; Carleer, Meinders and Huetink 1996, "Equivalent
drawbead model in finite element simulations", Computers & Structures 58): the bead is not
meshed; a line on the flange (fixed in space, in the tools' plane) resists the sheet's motion
across it with a restraining force per unit length F_r, and pushes the binder open with an
uplift force per unit length F_u, both measured or computed for the bead's geometry, material
and friction once and given to the model.

On the sheet, a line load along the bead, spread to the nodes by the shell's own linear
interpolation: a node's share of the line is

    l_i = integral over the bead line of N_i dl

(the line clipped to each cell at the sheet's current positions; sum_i l_i is the length of
the line on the sheet, exactly). Across the line, in the sheet's plane, the bead's normal d_i
(the segments' normals weighted by l_i), the restraint is a rigid-plastic law integrated like
Coulomb friction, with the node's slip across the line ds = (x - x_n) . d_i in the increment,
its force of the last increment f_n and a stiffness k_i = E t l_i / h before the bead yields:

    trial  f* = f_n - k_i ds,   |f*| <= F_r l_i: f = f*,   df/ds = -k_i
                                |f*| >  F_r l_i: f = F_r l_i f*/|f*|,   df/ds = 0

acting along d_i; the uplift F_u l_i acts along +z on the sheet, which the holder takes. Sliding
across the line the restraint is F_r times the line's length to round-off. (The shares' change
with the positions is left out of the tangent: a node's share moves as it crosses the line.)

Sensitivities (nonlinear/sensitivity.py): the beads' forces depend on a parameter p at fixed q
through their history (the committed restraint), the committed positions (the slip is measured
from them), for the material's E the stiffness k_i, and for a bead's own restraint or uplift
(tools.drawbead[i].restraint, .uplift) that force; after the solve also through the
positions, along which the shares move. Both are central differences of the same return mapping
with the stick and slip states held as converged (forces_at); the shares' move, which the
tangent leaves out, is corrected for (tangent_misses). The beads' derivative enters dR itself,
as their forces enter R before the contact set reads the reactions, so that the holder's split
and friction see the uplift's.
"""

from dataclasses import dataclass

import numpy as np
from dolfinx import fem, la

from shellform.assembly.sheet_element import BS
from shellform.material.layout import E_
from shellform.nonlinear.frames import add_tangent_slot_stiffness, subtract_nodal_forces
from shellform.nonlinear.parts import Part


@dataclass(frozen=True)
class DrawbeadLine:
    """A drawbead: a polyline in the plane (x, y; at least two points), its restraining force
    and uplift force per unit length."""

    points: tuple
    restraint: float
    uplift: float = 0.0


def _clip(P0, P1, tri):
    """The parameters [t0, t1] of the segment P0 -> P1 inside each triangle of tri (cells, 3,
    2), and whether the piece lies on one of its edges (shared with a neighbour). t0 >= t1:
    none."""
    d = P1 - P0
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    orient = np.sign((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    t0, t1 = np.zeros(len(tri)), np.ones(len(tri))
    on_edge = np.zeros(len(tri), dtype=bool)
    scale = np.abs(tri).max(initial=1.0) + np.abs(P0).max() + np.abs(P1).max()
    for p, q in ((a, b), (b, c), (c, a)):
        e = q - p
        n = orient[:, None] * np.stack([-e[:, 1], e[:, 0]], axis=1)  # inward normal
        f0 = np.einsum("ij,ij->i", n, P0 - p)  # n . (P0 + t d - p) >= 0
        slope = n @ d
        tol = 1e-12 * scale * np.linalg.norm(n, axis=1)
        along = np.abs(slope) <= tol  # parallel to this edge
        on_edge |= along & (np.abs(f0) <= tol * max(1.0, np.linalg.norm(d)))
        outside = along & (f0 < -tol)
        t0[outside], t1[outside] = 1.0, 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            t = -f0 / slope
        enter, leave = ~along & (slope > 0), ~along & (slope < 0)
        t0[enter] = np.maximum(t0[enter], t[enter])
        t1[leave] = np.minimum(t1[leave], t[leave])
    return t0, t1, on_edge


class Drawbeads(Part):
    """The drawbeads of a blank on n_owned nodes (V: the carrier's space, dofs: the owned
    cells' nodes, E and t: the sheet's modulus and thickness, h: its cell size, held: (n, 2)
    in-plane slots a symmetry plane holds)."""

    def __init__(self, lines, V, dofs, E: float, t: float, h: float, held: np.ndarray, nodes=None):
        self.lines, self.nodes = tuple(lines), nodes
        self.V, self.dofs, self.held = V, dofs, held
        n = held.shape[0]
        self.n = n
        self.k_per_length = E * t / h
        self._shares = fem.Function(V)  # l_i and l_i d_i per node (3 of the carrier's slots)
        self.length = np.zeros(n)  # l_i
        self.across = np.zeros((n, 2))  # d_i
        self.uplift = np.zeros(n)  # F_u l_i
        self.limit = np.zeros(n)  # F_r l_i
        self.committed = np.zeros(n)  # the restraint of the last converged increment (along d_i)
        self.history = np.zeros(n)
        self.force = np.zeros((n, 3))  # of the current iterate, on the sheet (x, y, z)
        self.rate = np.zeros((n, 2, 2))  # -df/dx in the nodes' tangent slots
        self.slipping = np.zeros(n, dtype=bool)  # of the current iterate
        self.E = E
        self.dhistory, self.drestraint = {}, {}  # per parameter: d/dp of the history, of this increment's restraint
        self._work = fem.Function(V)  # the owned nodes' position derivatives shared with the ghosts

    def shares(self, x_local: np.ndarray) -> None:
        """l_i, d_i, F_r l_i and F_u l_i at the current positions of the local nodes."""
        self.length, self.across, self.limit, self.uplift = self.shares_at(x_local)

    def shares_at(self, x_local: np.ndarray, lines=None) -> tuple:
        """(l_i, d_i, F_r l_i, F_u l_i) of the owned nodes at the positions x_local of the local
        nodes, of `lines` (default the part's; nothing of the part's state changes)."""
        arr = self._shares.x.array.reshape(-1, BS)
        arr[:] = 0.0
        tri = x_local[self.dofs][:, :, :2]  # (cells, 3, 2)
        lo, hi = tri.min(axis=1), tri.max(axis=1)  # the cells' boxes: a segment is clipped to those it meets
        for line in self.lines if lines is None else lines:
            pts = np.asarray(line.points, dtype=float)
            for P0, P1 in zip(pts[:-1], pts[1:]):
                d = P1 - P0
                length = float(np.hypot(*d))
                normal = np.array([-d[1], d[0]]) / length
                near = np.flatnonzero(np.all((lo <= np.maximum(P0, P1)) & (hi >= np.minimum(P0, P1)), axis=1))
                t0, t1, on_edge = _clip(P0, P1, tri[near])
                inside = np.flatnonzero(t1 > t0)
                if inside.size == 0:
                    continue
                t0, t1, on_edge, cells = t0[inside], t1[inside], on_edge[inside], near[inside]
                piece = (t1 - t0) * length * np.where(on_edge, 0.5, 1.0)
                mid = P0 + 0.5 * (t0 + t1)[:, None] * d
                N = _barycentric(tri[cells], mid)  # the shape functions at the piece's middle
                w = piece[:, None] * N  # (cells, 3): integral of N_i along the piece
                nodes = self.dofs[cells]
                for col, values in ((0, w), (1, w * normal[0]), (2, w * normal[1]),
                                    (3, w * line.restraint), (4, w * line.uplift)):
                    np.add.at(arr[:, col], nodes.ravel(), values.ravel())
        self._shares.x.scatter_reverse(la.InsertMode.add)
        own = arr[: self.n]
        size = np.hypot(own[:, 1], own[:, 2])
        across = np.where(size[:, None] > 0, own[:, 1:3] / np.maximum(size, 1e-300)[:, None], 0.0)
        return own[:, 0].copy(), across, own[:, 3].copy(), own[:, 4].copy()

    # -- the increment's history ----------------------------------------------------------------
    def start(self, lam: float = 0.0, predicting: bool = False) -> None:
        self.history = self.committed.copy()

    def commit(self, lam: float = 0.0) -> None:
        """The increment converged: its restraint is the next one's history (and its derivatives,
        where carry gave them, the next one's history derivatives)."""
        self.committed = np.einsum("ni,ni->n", self.force[:, :2], self.across)
        self.history = self.committed.copy()
        self.dhistory.update(self.drestraint)
        self.drestraint = {}

    def checkpoint(self) -> dict:
        return {"nodes": {"drawbead_restraint": self.committed}}

    def restore(self, state: dict, lam_scale: float = 1.0) -> None:
        self.committed = state["nodes"]["drawbead_restraint"].copy()
        self.history = self.committed.copy()

    # -- the part's protocol: one iterate --------------------------------------------------------
    def follow(self, frames: np.ndarray, lam: float) -> None:
        self.frames = frames[: self.n]
        self.slide(self.nodes.local_positions(), self.nodes.x_n, self.frames)

    def add_residual(self, R: np.ndarray) -> None:
        """R -= f on the owned nodes' u, v, w rows, in their nodal frames."""
        subtract_nodal_forces(R[: self.n * BS].reshape(-1, BS)[:, :3], self.frames, self.force)

    def add_tangent(self, K, R: np.ndarray, fixed: np.ndarray) -> None:
        add_tangent_slot_stiffness(K, self.rate)

    # -- the part's protocol: sensitivities ------------------------------------------------------
    def derivatives(self) -> str | None:
        """Differentiated with the stick and slip states held (pseudo_load, carry)."""
        return None

    def tangent_misses(self) -> bool:
        """The tangent leaves out the shares' move with the positions: corrected where a bead
        crosses the sheet."""
        return bool(np.any(self.length > 0))

    def pseudo_load(self, key: str, rhs: np.ndarray, dx_n: np.ndarray, eps: float, parameter=None) -> None:
        """rhs -= the beads' forces' derivative at fixed q, turned into the frames: through the
        history's derivative, the committed positions' and the stiffness's (E)."""
        x = self.nodes.local_positions()
        df, _ = self._differences(key, eps, x, np.zeros_like(x), dx_n, parameter)
        rhs[:, :3] -= np.einsum("nij,nj->ni", self.frames, df)

    def carry(self, key: str, dx: np.ndarray, dx_n: np.ndarray, dR: np.ndarray, lam: float, eps: float,
              parameter=None) -> None:
        """The beads' forces' total derivative along the positions' dx as well, subtracted from dR
        as the forces are from R (before the contact set and friction read it); the restraint's,
        the next increment's history derivative, kept for commit."""
        work = self._work.x.array.reshape(-1, BS)
        work[:] = 0.0
        work[: self.n, :3] = dx
        self._work.x.scatter_forward()
        df, self.drestraint[key] = self._differences(key, eps, self.nodes.local_positions(), work[:, :3].copy(),
                                                     dx_n, parameter)
        dR[:, :3] -= np.einsum("nij,nj->ni", self.frames, df)

    def derivative_state(self, key: str) -> dict:
        return {"drawbead_dhistory": self.dhistory.get(key, np.zeros_like(self.history))}

    def restore_derivative_state(self, key: str, state: dict) -> None:
        self.dhistory[key] = state["drawbead_dhistory"].copy()

    def _differences(self, key, eps, x, dx, dx_n, parameter) -> tuple[np.ndarray, np.ndarray]:
        """Central differences of forces_at along (dx: the local nodes' positions', dx_n, the
        history's derivative, the stiffness's): (d force, d restraint along d_i) per owned node."""
        dh = self.dhistory.get(key, np.zeros_like(self.history))
        k = [self.k_per_length * self._modulus(parameter, s * eps) / self.E for s in (1.0, -1.0)]
        lines = [parameter.beads(self.lines, parameter.value + s * eps) if parameter is not None else None
                 for s in (1.0, -1.0)]
        ends = [self.forces_at(x + s * eps * dx, self.nodes.x_n + s * eps * dx_n, self.history + s * eps * dh, kk, ll)
                for s, kk, ll in zip((1.0, -1.0), k, lines)]
        return (ends[0][0] - ends[1][0]) / (2 * eps), (ends[0][1] - ends[1][1]) / (2 * eps)

    def _modulus(self, parameter, step: float) -> float:
        """E at the parameter moved by step (the scene's E where the parameter is not the material's)."""
        material = parameter.respond(parameter.value + step).get("material") if parameter is not None else None
        return float(material[E_]) if material is not None else self.E

    def forces_at(self, x_local: np.ndarray, x_n: np.ndarray, history: np.ndarray, k_per_length: float, lines=None):
        """(force on the sheet (n, 3), restraint along d_i) of the owned nodes at the local nodes'
        positions x_local from x_n and the history, of `lines` (default the part's), with the
        current iterate's stick and slip states held (the sensitivities' differences)."""
        force, f, _, _ = self._restrained(x_local, x_n, history, k_per_length, self.shares_at(x_local, lines),
                                          self.slipping)
        return force, f

    def _restrained(self, x_local, x_n, history, k_per_length, shares, slipping=None):
        """The rigid-plastic return mapping of the owned nodes (module docstring) with their
        shares (l_i, d_i, F_r l_i, F_u l_i): (force on the sheet (n, 3), restraint along d_i,
        slipping, stick stiffness k_i), the slipping states decided here or, given, held."""
        length, d, limit, uplift = shares
        ds = np.einsum("ni,ni->n", x_local[: self.n, :2] - x_n[:, :2], d)
        k = k_per_length * length
        trial = history - k * ds
        slip = np.abs(trial) > limit if slipping is None else slipping
        f = np.where(slip, limit * np.sign(trial), trial)
        force = np.zeros((self.n, 3))
        force[:, :2] = f[:, None] * d
        force[:, 2] = uplift
        return force, f, slip, k

    # -- one iterate ---------------------------------------------------------------------------
    def slide(self, x_local: np.ndarray, x_n: np.ndarray, frames: np.ndarray) -> None:
        """The restraint and uplift at the current positions (x_local: every local node; x_n:
        the owned nodes' at the start of the increment; frames: the owned nodes' frames)."""
        self.shares(x_local)
        n = self.n
        d = self.across
        force, _, slip, k = self._restrained(x_local, x_n, self.history, self.k_per_length,
                                             (self.length, d, self.limit, self.uplift))
        self.force[:] = force
        self.slipping = slip
        d3 = np.zeros((n, 3))
        d3[:, :2] = d
        d2 = np.einsum("nij,nj->ni", frames[:n, :2], d3)  # d in the frames' tangent slots
        self.rate = np.where(slip, 0.0, k)[:, None, None] * d2[:, :, None] * d2[:, None, :]
        held = self.held
        self.rate[held[:, :, None] | held[:, None, :]] = 0.0

    def total(self, comm) -> np.ndarray:
        """The beads' force on the sheet (x, y, z), all ranks (of this model: not mirrored)."""
        from mpi4py import MPI

        return comm.allreduce(self.force.sum(axis=0), op=MPI.SUM)


def _barycentric(tri, p):
    """The linear shape functions of triangles tri (cells, 3, 2) at points p (cells, 2)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    l1 = ((p[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (p[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])) / det
    l2 = ((b[:, 0] - a[:, 0]) * (p[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (p[:, 0] - a[:, 0])) / det
    return np.stack([1.0 - l1 - l2, l1, l2], axis=1)
