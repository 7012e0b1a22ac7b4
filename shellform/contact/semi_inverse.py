"""The mixed semi-inverse contact algorithm (the paper's eqs. 24-29): the
Newton driver composed with the contact's parts.

The load factor lambda moves the punch by -lambda * stroke along z. In every increment the
nodes split into free ones and nodes on a tool: a node on a tool has a known normal
displacement (it follows the tool) and an unknown normal force, the residual of that known row
(contact_set.py). The parts, in the order they add their forces:

    SheetNodes      positions, tributary areas, half thicknesses (nodes.py)
    Drawbeads       restraining and uplift forces along the beads' lines (drawbead.py)
    ContactSet      which node lies on which tool, its frame, the tools' curvature, the faces' forces
                    (contact_set.py; the holder reads it through a view)
    PinchingHolder  the pinch onto the die, the open holder's lift and its equation (holder.py)
    Ironing         the faces' bound on the thickness between two tools (ironing.py; with the
                    effect 'ironing')
    CoulombFriction the return mapping, its normal forces and their relaxation (friction.py)

The driver (nonlinear/driver.py) knows none of them: it runs passes of Newton on their fixed
constraints until no part changes. This module only composes them and offers the measurements
a run reports (reactions, net normal forces, the nodes in contact).
"""

import numpy as np

from shellform.assembly.sheet_element import BS
from shellform.contact.contact_set import FREE, ContactControls, ContactSet
from shellform.contact.drawbead import Drawbeads
from shellform.contact.friction import CoulombFriction
from shellform.contact.holder import PinchingHolder
from shellform.contact.ironing import Ironing
from shellform.contact.nodes import SheetNodes
from shellform.nonlinear.driver import Driver

__all__ = ["FREE", "ContactControls", "SemiInverseDriver"]


class SemiInverseDriver(Driver):
    """Punch displacement control with rigid tools, Coulomb friction, a pinching holder and
    drawbeads.

    tools: rigid tools with ``gap(x, offset, dz) -> (gap, normal)`` and ``shape(x, offset, dz)``
    in contact order (e.g. punch, die); ``travel[k]`` is tool k's travel along its axis at
    lambda = 1 (punch: -stroke), or its path (shellform.tools.travel); holder: a BlankHolder
    tool (or None) with its force, pinching the flange onto tool `die` (default: the last tool);
    friction: mu, one coefficient for every tool or one per tool in contact order then the
    holder's (friction.py: CoulombFriction); drawbeads: DrawbeadLine's (drawbead.py);
    holder_edge: the pinch's EdgeLoad (pinch_edge.py; None: the rigid pinch's own edge);
    ironing: the tools' faces bound the sheet's thickness where two face each other (ironing.py);
    pressure: a dead pressure along +z at lambda = 1 (Driver's).
    """

    def __init__(self, model, bcs, tools, travel, friction=0.0, holder=None, holder_force=0.0,
                 prescribed=None, contact=None, controls=None, checkpoint_dir=None, verbose=True, die=None,
                 drawbeads=(), holder_edge=None, ironing=False, pressure=0.0):
        c = contact or ContactControls(penetration=1e-3 * model.thickness)
        t, E, comm = model.thickness, model.material[0], model.mesh.comm
        self.nodes = nodes = SheetNodes(model, bcs)
        self.holder = None if holder is None else PinchingHolder(
            holder, holder_force, nodes, E * nodes.area / t, comm, c.holder_spread, t, c.max_toggles, c.trace,
            holder_edge)
        self.contact = ContactSet(nodes, tools, travel, c, t, die, self.holder)
        self.friction = CoulombFriction(friction, CoulombFriction.STICK_STIFFNESS * E * nodes.area / model.cell_size,
                                        nodes.held[:, :2], self.contact, nodes, c.friction_rtol, c.trace)
        self.drawbeads = Drawbeads(drawbeads, model.V, model.dofs, E, t, model.cell_size, nodes.held[:, :2],
                                   nodes) if drawbeads else None
        if self.holder is not None:
            self.holder.compose(self.contact.view())  # what the holder reads of the set
        self.ironing = Ironing(model, nodes, self.contact) if ironing else None
        if self.ironing is not None:
            self.contact.bound_by(self.ironing)  # between two tools the sheet's faces lie at the bounded thickness
        parts = [p for p in (nodes, self.drawbeads, self.contact, self.holder, self.ironing, self.friction)
                 if p is not None]
        super().__init__(model, bcs, prescribed=prescribed, pressure=pressure, controls=controls,
                         checkpoint_dir=checkpoint_dir, verbose=verbose, parts=parts, trace=c.trace)
        self.tools, self.travel, self.paths = self.contact.tools, self.contact.travel, self.contact.paths

    # -- measurements ----------------------------------------------------------------------------
    def positions(self) -> np.ndarray:
        """Current positions of the owned nodes."""
        return self.nodes.positions()

    def reactions(self) -> np.ndarray:
        """(n_owned, 3) residual on the u, v, w rows in the nodal frames (tool forces on constrained rows)."""
        return self.residual_full[: self.n_owned * BS].reshape(-1, BS)[:, :3]

    def net_normal_forces(self) -> np.ndarray:
        """Each owned node's net normal force R0 from its tool (die minus holder on a pinched
        node; 0 off the tools)."""
        return self.contact.net_normal_forces()

    def count_in_contact(self) -> dict:
        """Nodes on each tool (the open holder last) and pinched by the holder, all ranks."""
        return self.contact.count()

    def restore_state(self, state: dict, lam_scale: float | None = None) -> None:
        """As Driver's; the load factor is rescaled to this run's tool travel (a longer stroke
        continues from the same punch position)."""
        if lam_scale is None:
            lam_scale = float(state["global"]["contact_travel"][0] / self.travel[0])
        super().restore_state(state, lam_scale)
