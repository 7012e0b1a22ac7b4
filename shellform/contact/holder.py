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
    """Holder forces on the owned nodes whose plan position lies over the die's flat top."""

    def __init__(self, tool, force: float, stiffness: np.ndarray, comm):
        self.tool, self.force, self.k, self.comm = tool, float(force), np.asarray(stiffness), comm
        self.Z = tool.z_face

    def forces(self, x: np.ndarray, half_thickness: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Nodal forces along z on the sheet (<= 0) and their stiffness k_i where in contact."""
        # tops relative to the holder's rest height: gap = Z0 - top (inf outside its plan region)
        gap, _ = self.tool.gap(x, half_thickness, 0.0)
        under = np.isfinite(gap)
        tops = self.tool.z_face - gap[under]
        all_tops = np.concatenate(self.comm.allgather(tops))
        all_k = np.concatenate(self.comm.allgather(self.k[under]))
        fz, kz = np.zeros(x.shape[0]), np.zeros(x.shape[0])
        if all_tops.size == 0 or self.force <= 0:
            self.Z = float(all_tops.max()) if all_tops.size else self.tool.z_face
            return fz, kz
        self.Z = holder_height(all_tops, all_k, self.force)
        squeeze = np.maximum(tops - self.Z, 0.0)
        idx = np.flatnonzero(under)
        fz[idx] = -self.k[idx] * squeeze
        kz[idx] = np.where(squeeze > 0, self.k[idx], 0.0)
        return fz, kz

    def total(self, fz: np.ndarray) -> float:
        return -self.comm.allreduce(float(fz.sum()), op=MPI.SUM)
