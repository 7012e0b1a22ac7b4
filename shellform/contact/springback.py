"""Springback: the tools withdraw and the drawn sheet springs back.

At the end of the stroke the sheet is in equilibrium with the tools' forces on it: contact,
friction and the holder's squeeze, together f = f_int(q) (the internal force of the drawn
state on every node that symmetry does not hold). Withdrawing the tools releases f. A plain
Newton driver without tools carries the sheet from f applied (load factor 1, equilibrium by
construction) to f = 0, the material unloading from its drawn state (the first iteration with
the elastic tangent, as after any load reversal). The quarter's symmetry planes hold it in x,
y and the rotations; the bottom's centre node keeps its height (w held), which removes the one
rigid motion left. The tools do not come back: a part that would touch them again as it springs
is outside this model.
"""

import numpy as np
from mpi4py import MPI

from shellform.assembly.sheet_element import BS, COMPONENTS
from shellform.nonlinear.driver import Controls, Driver

W = COMPONENTS.index("w")


class ReleasedForces:
    """The tools' forces f on the owned dofs as a nodal load of the driver: R -= lam f."""

    def __init__(self, f: np.ndarray, comm):
        self.f = f
        self.magnitude = float(np.sqrt(comm.allreduce(float(f @ f), op=MPI.SUM)))

    def add(self, lam, q, R, A):
        R[:] -= lam * self.f[: R.size]


class SpringbackDriver(Driver):
    """Newton from the drawn state q (load factor 1, the tools' forces f applied as a nodal
    load) to the released one (0). The supports keep the values they have: the symmetry
    planes (`symmetry`) 0, the others (`held`: the centre's w) their drawn values."""

    def __init__(self, model, symmetry, held, q, controls=None, verbose=False):
        super().__init__(model, list(symmetry) + list(held), controls=controls, verbose=verbose)
        self.q.x.array[:] = q
        self.held = q.copy()
        for bc in symmetry:
            self.held[bc.dof_indices()[0]] = 0.0
        self.continue_from(1.0)  # run(0) is a load reversal: elastic first tangent
        self.residual(0.0, tangent=False)
        n = model.V.dofmap.index_map.size_local * BS
        f = self.residual_full[:n].copy()  # f_int(q): the tools' forces
        f[self.bc_dofs[self.bc_dofs < n]] = 0.0
        self.nodal = ReleasedForces(f, model.mesh.comm)
        self.sensitivity = None  # release(..., sensitivity=): the derivatives carried through the springback

    def _set_dirichlet(self, lam, dofs=None):
        d = self.support_dofs if dofs is None else dofs
        self.g[d] = self.held[d]
        return self._largest(self.g[d] - self.q.x.array[d])


def release(contact_driver, controls: Controls | None = None, verbose=False, sensitivity=None) -> SpringbackDriver:
    """Spring the drawn sheet of `contact_driver` back; returns the springback driver, whose
    history counts the plastic layers of every unloading increment. With the drawing's
    `sensitivity` (nonlinear/sensitivity.py), the springback carries it on (Sensitivity.released):
    the driver's `sensitivity` then holds the sprung-back sheet's derivatives."""
    from dolfinx import fem

    cd = contact_driver
    model, V = cd.model, cd.model.V
    X = cd.nodes.X
    n_owned = cd.n_owned
    centre = np.flatnonzero(np.hypot(X[:n_owned, 0], X[:n_owned, 1]) < 1e-9 * max(np.abs(X[:, :2]).max(), 1.0))
    held = fem.dirichletbc(np.float64(0), (BS * centre + W).astype(np.int32), V.sub(W))
    sb = SpringbackDriver(model, cd.support_bcs, [held], cd.q.x.array, controls=controls or Controls(
        initial_step=0.25, max_step=0.5, min_step=1e-3), verbose=verbose)
    if sensitivity is not None:
        sb.sensitivity = sensitivity.released(sb)
        sb.records.append(sb.sensitivity)
    sb.run(0.0)
    return sb
