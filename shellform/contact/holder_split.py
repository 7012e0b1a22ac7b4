"""The closed holder's split: how its force F is shared between the faces of the pinched nodes.

Between the rigid die and the rigid holder, a pinched node's normal position is known, whatever
the sign of its net normal force R0 (die minus holder). The shell carries no through-thickness
strain, so the two faces' forces are known only through their difference R0 and the holder's
total F; their split is a modelling choice. The holder presses each pinched node with what holds
it down plus a *squeeze* s_i >= 0:

    off the edge's band   h_i = s_i + max(-R0_i, 0),   d_i = s_i + max(R0_i, 0)
    on the edge's band    h_i = s_i + f e_i,           d_i = h_i D / H,  D = max(H + sum R0_j, 0)
                          sum_i h_i = F,  friction pressure d_i + h_i

(H = sum h_j and the sums over the band): on the band the die presses with the band's
equilibrium total, shared as the holder presses, not node by node with the positive lobes of
the discrete couple the pinch carries there (their sum grows as 1/h, and friction saw it).
e_i is the node's share of the edge load (holder.py, pinch_edge.py). With E_in the holding-down
off the band and E_e = sum e_i, the holder carries the edge in full (f = 1) while
E_in + E_e <= F; beyond, it rides on its edge: f = (F - E_in) / E_e and no squeeze is left.

The squeeze left to spread is S = F - E_in - f E_e >= 0. A *spread rule* says how (SPREAD_RULES,
the scene's `tools.holder_spread`); each is a function (S, pinched, area, stiffness, tops, comm)
-> s over the owned nodes, so a new rule is one function and one registry line here (and its
name in shellform.scene.SPREADS):
- "area" (default): s_i = S A_i / sum A (tributary areas), the uniform flange pressure of a
  holder whose own compliance and the sheet's absorb the flange's thickness differences.
- "rigid": the rigid holder on the thickest rim: s_i = k_i max(top_i - Z, 0) with the
  through-thickness stiffness k_i = E A_i / t and Z fixed by sum s_i = S.
"""

import numpy as np
from mpi4py import MPI

from shellform.nonlinear.parts import copy_state, put_state


def holder_height(tops: np.ndarray, k: np.ndarray, force: float) -> float:
    """Z with sum k_i max(tops_i - Z, 0) = force (the highest top when force is 0)."""
    order = np.argsort(-tops)
    t, kk = tops[order], k[order]
    K = np.cumsum(kk)
    S = np.cumsum(kk * t)
    # with the first j + 1 tops touching: force = S_j - K_j Z  ->  Z_j = (S_j - force) / K_j
    Z = (S - force) / K
    below = np.append(t[1:], -np.inf)  # Z_j is the answer where it lies in [t_{j+1}, t_j]
    j = int(np.argmax(Z >= below))
    return float(Z[j])


def _sum(v, comm) -> float:
    return comm.allreduce(float(np.sum(v)), op=MPI.SUM)


def area_spread(S: float, pinched, area, stiffness, tops, comm) -> np.ndarray:
    """s_i = S A_i / sum A over the pinched nodes (all ranks)."""
    s = np.zeros(pinched.size)
    total = _sum(area[pinched], comm)
    if total > 0:
        s[pinched] = S * area[pinched] / total
    return s


def rigid_spread(S: float, pinched, area, stiffness, tops, comm) -> np.ndarray:
    """s_i = k_i max(top_i - Z, 0) with sum s_i = S over the pinched nodes (all ranks)."""
    s = np.zeros(pinched.size)
    all_tops = np.concatenate(comm.allgather(tops[pinched]))
    all_k = np.concatenate(comm.allgather(stiffness[pinched]))
    if all_tops.size:
        Z = holder_height(all_tops, all_k, S)
        s[pinched] = stiffness[pinched] * np.maximum(tops[pinched] - Z, 0.0)
    return s


SPREAD_RULES = {"area": area_spread, "rigid": rigid_spread}


class HolderSplit:
    """The split of a closed holder's force `force` over the owned nodes (module docstring):
    area, their tributary areas; stiffness, their through-thickness E A / t; spread, the rule's
    name in SPREAD_RULES. It keeps the last split's band totals, which its face_slopes read."""

    def __init__(self, force: float, area: np.ndarray, stiffness: np.ndarray, comm, spread: str = "area"):
        if spread not in SPREAD_RULES:
            raise ValueError(f"holder spread must be one of {tuple(SPREAD_RULES)}, got {spread!r}")
        self.force, self.comm, self.spread = float(force), comm, spread
        self.area, self.k = np.asarray(area, dtype=float), np.asarray(stiffness, dtype=float)
        self.band_ratio, self.band_force = 0.0, 0.0  # the die's force on the band over the holder's, the holder's

    def iterate_state(self) -> dict:
        """The band's ratio and force of the last split, copied (Part.iterate_state)."""
        return copy_state(self)

    def set_iterate_state(self, state: dict) -> None:
        put_state(self, state)

    def _sum(self, v) -> float:
        return _sum(v, self.comm)

    def demands(self, pinched: np.ndarray, net: np.ndarray, edge: np.ndarray, band: np.ndarray) -> tuple[float, float]:
        """(E_in, E_e), all ranks: the holding-down the pinched nodes off the edge's band need
        (sum max(-R0, 0)) and the edge load on the band (sum e_i)."""
        inner = pinched & ~band
        both = self.comm.allreduce(np.array([np.maximum(-net[inner], 0.0).sum(), edge.sum()]), op=MPI.SUM)
        return float(both[0]), float(both[1])

    def edge_share(self, inner: float, total_edge: float, force: float | None = None) -> float:
        """f: the share of its edge load E_e the holder gives after the holding-down E_in (of a
        force F, default its own)."""
        left = max((self.force if force is None else force) - inner, 0.0)
        return 1.0 if total_edge <= left else left / total_edge

    def held_down(self, pinched: np.ndarray, net: np.ndarray, edge: np.ndarray, band: np.ndarray):
        """(E_in + f E_e, E_e, E_in) / F: the part of F that holds the flange down against its own
        lift, the edge load's demand (> 1: the holder rides on its edge) and the holding-down off
        the edge's band."""
        inner, total_edge = self.demands(pinched, net, edge, band)
        return (inner + self.edge_share(inner, total_edge) * total_edge) / self.force, total_edge / self.force, \
            inner / self.force

    def forces(self, pinched: np.ndarray, net: np.ndarray, tops: np.ndarray, edge: np.ndarray, band: np.ndarray):
        """(die face d, holder face h) forces on the pinched nodes (zero elsewhere), from their net
        normal forces R0, their tops z + t/2 (the "rigid" spread) and the edge load's shares e_i on
        its band (module docstring); the split's band totals are kept (face_slopes)."""
        d, h, self.band_ratio, self.band_force = self.split_of(self.force, pinched, net, tops, edge, band)
        return d, h

    def split_of(self, force: float, pinched: np.ndarray, net: np.ndarray, tops: np.ndarray, edge: np.ndarray,
              band: np.ndarray):
        """forces' split of a force F, nothing kept: (d, h, the die's force on the band over the
        holder's D / H, the holder's H) (a sensitivity's differences)."""
        inner, total_edge = self.demands(pinched, net, edge, band)
        f = self.edge_share(inner, total_edge, force)
        S = max(force - inner, 0.0) - f * total_edge
        s = SPREAD_RULES[self.spread](S, pinched, self.area, self.k, tops, self.comm)
        h = np.where(pinched, s + np.where(band, f * edge, np.maximum(-net, 0.0)), 0.0)
        on_band = pinched & band
        H, R = self._sum(h[on_band]), self._sum(net[on_band])
        ratio = max(H + R, 0.0) / H if H > 0 else 0.0
        d = np.where(pinched, np.where(band, ratio * h, s + np.maximum(net, 0.0)), 0.0)
        return d, h, ratio, H

    def face_slopes(self, net: np.ndarray, face: np.ndarray, band: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(dd_i/dR0_i, dh_i/dR0_i) of the pinched nodes at the last split, whose holder faces were
        `face` (F's spread held fixed): off the edge's band the die's 1 where R0 > 0 and the
        holder's -1 where R0 < 0 (sign(R0) together); on it the die's h_i / H (d_i = h_i D / H, D
        the band's equilibrium total) while the die presses the band, 0 where it is clear, and the
        holder's 0 (h_i = s_i + f e_i)."""
        own = face / self.band_force if self.band_force > 0 and self.band_ratio > 0 else np.zeros_like(face)
        return (np.where(band, own, (net > 0).astype(float)),
                np.where(band, 0.0, -(net < 0).astype(float)))
