"""The blank holder under force control: its height Z is an unknown fixed by its force.

The rigid holder rests on the flange over the die's flat top. Between two rigid tools the
sheet's only compliance is through its thickness, so a node whose top surface z_i + t_i/2 rises
above Z is squeezed by the through-thickness stiffness of its tributary area,

    p_i = k_i max(z_i + t_i/2 - Z, 0),   k_i = E A_i / t_i,

and Z solves  sum_i p_i(Z) = F  (the prescribed force): a piecewise-linear decreasing function
of Z, solved exactly by sorting the tops. The holder therefore bears on the thickest part of the
flange, as a rigid holder does. The squeeze is micrometres (E A/t ~ 1e6 N/mm per node), far
below the thickness change that redistributes it.
"""

import numpy as np
from mpi4py import MPI


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


class ForceControlledHolder:
    """Holder forces on the owned nodes whose plan position lies over the die's flat top.

    Z is a Newton unknown beside the carrier (the driver's bordered solve, Sherman-Morrison):
    the force balance  g(q, Z) = sum_i k_i max(top_i - Z, 0) - F = 0  is linearised as
    sum_active k_i dw_i - (sum_active k_i) dZ = -g.  ``balance`` re-solves Z exactly for given
    positions (at the start, and as a safeguard between contact passes).
    """

    def __init__(self, tool, force: float, stiffness: np.ndarray, comm, rtol: float = 1e-8):
        self.tool, self.force, self.k, self.comm = tool, float(force), np.asarray(stiffness), comm
        self.rtol = rtol
        self.Z = tool.z_face

    def _tops(self, x, half_thickness):
        gap, _ = self.tool.gap(x, half_thickness, 0.0)  # gap = z_face - top (inf off the holder)
        under = np.isfinite(gap)
        return under, self.tool.z_face - gap[under]

    def forces(self, x: np.ndarray, half_thickness: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Nodal forces along z on the sheet (<= 0) at the holder height Z, and their stiffness."""
        under, tops = self._tops(x, half_thickness)
        fz, kz = np.zeros(x.shape[0]), np.zeros(x.shape[0])
        idx = np.flatnonzero(under)
        squeeze = np.maximum(tops - self.Z, 0.0)
        fz[idx] = -self.k[idx] * squeeze
        kz[idx] = np.where(squeeze > 0, self.k[idx], 0.0)
        return fz, kz

    def linearisation(self, x, half_thickness):
        """(g, active node indices, their k): the force misfit and the nodes bearing the holder."""
        under, tops = self._tops(x, half_thickness)
        idx = np.flatnonzero(under)
        squeeze = tops - self.Z
        act = idx[squeeze > 0]
        total = self.comm.allreduce(float(np.sum(self.k[idx] * np.maximum(squeeze, 0.0))), op=MPI.SUM)
        return total - self.force, act, self.k[act]

    def balance(self, x: np.ndarray, half_thickness: np.ndarray) -> bool:
        """Move Z so that the forces at the positions x sum to F; False if they already did."""
        under, tops = self._tops(x, half_thickness)
        all_tops = np.concatenate(self.comm.allgather(tops))
        all_k = np.concatenate(self.comm.allgather(self.k[under]))
        if all_tops.size == 0:
            return False
        total = float(np.sum(all_k * np.maximum(all_tops - self.Z, 0.0)))
        if abs(total - self.force) <= self.rtol * max(self.force, 1e-300):
            return False
        self.Z = holder_height(all_tops, all_k, self.force) if self.force > 0 else float(all_tops.max())
        return True

    def total(self, fz: np.ndarray) -> float:
        return -self.comm.allreduce(float(fz.sum()), op=MPI.SUM)
