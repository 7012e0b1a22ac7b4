"""The open holder's face: a rigid tool whose one unknown, its lift, is solved with the sheet.

Open, the holder is still a rigid tool: a face lifted by z_H above its closed position, with
one unknown (z_H) and one equation (its nodes' normal forces p_i sum to its force F), solved
with the sheet in each Newton iteration as a bordered system, one more solve with the same
factors:

    dq = dq_a + dz_H dq_b,   dq_b the response to the face's nodes lifted by 1,
    dz_H = (F - sum p_i - sum (K dq_a)_i) / sum (K dq_b)_i   (sums over the face's normal rows)

F - sum p_i is the derivative of the energy with respect to the lift: it enters the residual's
norm and the line search's energy slope (dz_H (F - sum p)). Where friction slips on the face's
nodes, their slip forces depend on those nodes' normal forces, so the lifted columns carry
friction's dp/dq too (the solve's lift of known columns, Part.lift_known). The face is flat at z_face + z_H ("rigid" spread) or conforms to the
flange's thickness ("area": over each node z_face + z_H + (2 h - t0), z_H above the node's top
when the node rests on the die), as the closed holder's pressure does.
"""

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from shellform.assembly.sheet_element import BS
from shellform.nonlinear.parts import copy_state, put_state


class LiftedFace:
    """The face of a holder (tool: a BlankHolder) with force F over a sheet of thickness t,
    flat or conforming (spread), and its lift z_H (mm above its closed position)."""

    def __init__(self, tool, force: float, thickness: float, spread: str, comm):
        self.tool, self.force, self.thickness, self.spread, self.comm = tool, float(force), thickness, spread, comm
        self.lift, self._lift0, self._dlift = 0.0, 0.0, 0.0
        self._unit = self._response = None

    def bind(self, V) -> None:
        self._unit, self._response = fem.Function(V), fem.Function(V)  # the unit lift and its response

    def gap(self, x: np.ndarray, half: np.ndarray):
        """Gap and normal of the face to the nodes at x with half thicknesses `half`."""
        offset = half if self.spread == "rigid" else self.thickness - half
        return self.tool.gap(x, offset, self.lift)

    def floor(self, tops: np.ndarray) -> float:
        """The closed position of the lift: 0 for the conforming face, the highest top (all
        ranks, `tops` of the owned nodes on the die under it) above z_face for the flat one."""
        if self.spread != "rigid":
            return 0.0
        top = self.comm.allreduce(float(np.max(tops, initial=-np.inf)), op=MPI.MAX)
        return max(top - self.tool.z_face, 0.0)

    def hold(self) -> None:
        """No lift in this Newton iteration (the face is closed or touches nothing)."""
        self._lift0, self._dlift = self.lift, 0.0

    def border(self, driver, on: np.ndarray, imbalance: float) -> float:
        """dz_H in this Newton iteration for the owned nodes `on` the face and its imbalance
        F - sum p_i (module docstring): dq (frame coordinates, from the solve) becomes
        dq_a + dz_H dq_b. NaN where the lifted solve fails."""
        self.hold()
        rows = BS * np.flatnonzero(on) + 2  # their normal rows (the frame's normal points down)
        unit = self._unit.x.array
        unit[:] = 0.0
        unit[rows] = -1.0  # the face up by 1: each node 1 up, -1 along its normal
        self._unit.x.scatter_forward()
        if not driver.solve_lifted(unit, self._response):
            return np.nan
        dqa, dqb = driver.dq.x.array, self._response.x.array
        change = self.comm.allreduce(np.array([driver.apply_tangent(dqa)[rows].sum(),
                                               driver.apply_tangent(dqb)[rows].sum()]), op=MPI.SUM)
        dz = (imbalance - change[0]) / change[1]
        dqa += dz * dqb
        driver.dq.x.scatter_forward()
        self._dlift = float(dz)
        return self._dlift

    def border_derivative(self, driver, on: np.ndarray, dforce: float, dR: np.ndarray, out) -> float:
        """The lift's derivative z' in a sensitivity (nonlinear/sensitivity.py): with q' = q'_a +
        z' q'_b (q'_a the derivative in `out`, q'_b the response to the face lifted by 1), the
        face's equation F - sum p_i = 0 differentiated, sum dR_i + z' sum (K q'_b)_i = F' over
        the normal rows of the owned nodes `on` the face (dR: the residual's total along q'_a,
        owned rows, the frames; dforce: F'). Adds z' q'_b to out and returns z'."""
        rows = BS * np.flatnonzero(on) + 2
        unit = self._unit.x.array
        unit[:] = 0.0
        unit[rows] = -1.0  # the face up by 1, as in border
        self._unit.x.scatter_forward()
        if not driver.solve_lifted(unit, self._response):
            raise RuntimeError("the open holder's lift response failed in a sensitivity solve")
        response = self._response.x.array
        sums = self.comm.allreduce(np.array([driver.apply_tangent(response)[rows].sum(), dR[rows].sum()]),
                                   op=MPI.SUM)
        dz = (dforce - sums[1]) / sums[0]
        out.x.array[:] += dz * response
        return float(dz)

    def iterate_state(self) -> dict:
        """The lift and its step, copied (Part.iterate_state)."""
        return copy_state(self)

    def set_iterate_state(self, state: dict) -> None:
        put_state(self, state)

    def slope(self, imbalance: float) -> float:
        """The lift's share of the energy slope: dz_H (F - sum p)."""
        return self._dlift * imbalance

    def move(self, alpha: float) -> None:
        self.lift = self._lift0 + alpha * self._dlift
