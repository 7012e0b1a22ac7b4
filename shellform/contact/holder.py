"""The blank holder under force control: it pinches the flange onto the die's flat top.

Between the rigid die and the rigid holder, a flange node is *pinched*: its normal position is
known (it lies on the die) whatever the sign of its net normal force R0 (die minus holder).
The shell carries no through-thickness strain, so the two faces' forces are known only through
their difference R0 and the holder's total F; their split is a modelling choice, the *squeeze*
s_i >= 0 with  sum_i (s_i + max(-R0_i, 0)) = F :

    die face     d_i = s_i + max(R0_i, 0)
    holder face  h_i = s_i + max(-R0_i, 0)        sum_i h_i = F,  friction pressure d_i + h_i

The squeeze left to spread is S = F - sum_i max(-R0_i, 0). ``spread`` says how:
- "area" (default): s_i = S A_i / sum A (tributary areas), the uniform flange pressure of a
  holder whose own compliance and the sheet's absorb the flange's thickness differences. On a
  nodal mesh the rigid law below puts the whole force on 2 to 4 of the thickest nodes, which a
  real holder (elastic, on a sheet whose thickness varies by micrometres between nodes early in
  the stroke) does not do, and friction on those few nodes then drives the flange.
- "rigid": the rigid holder on the thickest rim: s_i = k_i max(top_i - Z, 0) with the
  through-thickness stiffness k_i = E A_i / t and Z fixed by sum s_i = S.

The holder *opens* when the flange pushes it up harder than F holds it down (S < 0). Open, it
is still a rigid tool: a face lifted by `lift` above its closed position, with one unknown
(the lift) and one equation (its nodal forces sum to F), solved with the sheet in each Newton
iteration (semi_inverse.py). A node under it touches it, the die, or neither, and leaves the
face it touches when its force turns tensile. With the "area" spread the lifted face conforms
to the flange's thickness as the closed holder's pressure does (over each node it lies `lift`
above the node's own top when the node is on the die); with "rigid" it is flat. The holder
closes again when its lift falls to that closed position. With F = 0 there is no holder.
"""

import numpy as np
from mpi4py import MPI

from shellform.scene import SPREADS


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


class PinchingHolder:
    """The holder's force F on the owned nodes under it (plan position over the die's flat top).

    area: tributary areas of the owned nodes; stiffness: their E A / t (the "rigid" spread).
    """

    def __init__(self, tool, force: float, area: np.ndarray, stiffness: np.ndarray, comm, spread: str = "area"):
        if spread not in SPREADS:
            raise ValueError(f"holder spread must be one of {SPREADS}, got {spread!r}")
        self.tool, self.force, self.comm, self.spread = tool, float(force), comm, spread
        self.area, self.k = np.asarray(area, dtype=float), np.asarray(stiffness, dtype=float)

    def under(self, x: np.ndarray) -> np.ndarray:
        """Nodes whose plan position lies under the holder's face."""
        return np.isfinite(self.tool.gap(x, 0.0, 0.0)[0])

    def _sum(self, v) -> float:
        return self.comm.allreduce(float(np.sum(v)), op=MPI.SUM)

    def squeeze_left(self, pinched: np.ndarray, net: np.ndarray) -> float:
        """S = F - sum over the pinched nodes of max(-R0, 0), all ranks (< 0: the holder lifts)."""
        return self.force - self._sum(np.maximum(-net[pinched], 0.0))

    def faces(self, pinched: np.ndarray, net: np.ndarray, tops: np.ndarray):
        """(die face d, holder face h) forces on the pinched nodes (zero elsewhere) of a closed
        holder, from their net normal forces R0 and their tops z + t/2 (the "rigid" spread)."""
        S = max(self.squeeze_left(pinched, net), 0.0)
        s = np.zeros(net.size)
        if self.spread == "area":
            total = self._sum(self.area[pinched])
            if total > 0:
                s[pinched] = S * self.area[pinched] / total
        else:
            all_tops = np.concatenate(self.comm.allgather(tops[pinched]))
            all_k = np.concatenate(self.comm.allgather(self.k[pinched]))
            if all_tops.size:
                Z = holder_height(all_tops, all_k, S)
                s[pinched] = self.k[pinched] * np.maximum(tops[pinched] - Z, 0.0)
        d = np.where(pinched, s + np.maximum(net, 0.0), 0.0)
        h = np.where(pinched, s + np.maximum(-net, 0.0), 0.0)
        return d, h

    def face_gap(self, x: np.ndarray, half: np.ndarray, thickness: float, lift: float):
        """Gap and normal of the lifted face to the nodes at x with half thicknesses `half`: the
        flat face z_face + lift ("rigid"), or over each node z_face + lift + (2 half - t0), which
        lies `lift` above the node's top when the node rests on the die ("area")."""
        offset = half if self.spread == "rigid" else thickness - half
        return self.tool.gap(x, offset, lift)

    def lift_floor(self, tops: np.ndarray) -> float:
        """The closed position of the lift: 0 for the conforming face, the highest top (all
        ranks, `tops` of the owned nodes on the die under it) above z_face for the flat one."""
        if self.spread != "rigid":
            return 0.0
        top = self.comm.allreduce(float(np.max(tops, initial=-np.inf)), op=MPI.MAX)
        return max(top - self.tool.z_face, 0.0)

    def total(self, h: np.ndarray) -> float:
        """The holder's force on the sheet, all ranks."""
        return self._sum(h)
