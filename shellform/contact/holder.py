"""The blank holder under force control: it pinches the flange onto the die's flat top.

Between the rigid die and the rigid holder, a flange node is *pinched*: its normal position is
known (it lies on the die) whatever the sign of its net normal force R0 (die minus holder). How
F is shared between the pinched nodes' two faces, the holding-down, the edge's band and the
squeeze a spread rule spreads, is the split (holder_split.py).

The band is the pinched nodes that carry the couple turning the sheet from the flange onto the
die's shoulder (within two cells of the holder's inner edge, or drawn past it in this
increment): e_i is their share of the edge load V_e per unit length of the holder's inner
edge (pinch_edge.py: the couple over the sheet's own through-thickness compliance, the same total
on every mesh), which replaces the discrete force the rigid pinch puts there (it grows as 1/h).
With E_in the holding-down off the band and E_e = sum e_i, the holder carries the edge in full
while E_in + E_e <= F; beyond, it *rides* on its edge. A holder riding on its edge is lifted by
micrometres (the couple's arm grows to take less force: EdgeLoad.riding_lift), so the flange
stays pinched while that lift is below the contact's tolerance (1 % of t); where it is not (a
light holder), the holder opens.

The holder *opens* when the flange off the band pushes it up harder than F holds it down
(E_in > F), or when riding on its edge would lift it by more than the tolerance: criteria on
forces per unit length and a physical lift, not on the mesh. Open, it
is still a rigid tool: a face whose lift is solved with the sheet (lifted_face.py). A node under
it touches it, the die, or neither, and leaves the face it touches when its force turns tensile.
The holder closes again when its lift falls to its closed position and it could ride there.
With F = 0 there is no holder.

The holder's faces hold the flange flat: under the closed holder the pinched nodes' w is known,
and their slopes where the faces hold the node's every cell (not on the pinch's boundary, where
a cell reaches beyond the faces and the sheet turns within it); under the open one the slopes of
every node beneath it but its boundary. The pinched set only
grows within an increment (a node drawn out from under the holder leaves at the next one), so
that a node at the holder's edge cannot switch from one pass to the next. The holder switches
(opens or closes) at most `max_toggles` times per increment. Its state machine runs in the
contact set's update (contact_set.py), whose tools its open face joins. The holder reads the set
through its view (contact_set.SetView: the nodes on the die, on its face, off the tools, their
net normal forces) and writes nothing there: it returns its decisions (the nodes that go onto
its face or back onto the die, the die's face forces under it) and the set applies them.
"""

import numpy as np
from mpi4py import MPI

from shellform.contact.holder_split import HolderSplit
from shellform.contact.lifted_face import LiftedFace
from shellform.contact.nodes import W_SLOPES
from shellform.contact.pinch_edge import edge_weights
from shellform.nonlinear.parts import Part
from shellform.results.log import say


class PinchingHolder(Part):
    """The holder (tool: a BlankHolder) with force F on the owned nodes under it (plan position
    over the die's flat top): a part. nodes: the SheetNodes (their tributary areas); stiffness:
    their E A / t; spread: the split's rule (holder_split.py); edge: the pinch's EdgeLoad
    (pinch_edge.py; None: no band, the rigid pinch's discrete couple)."""

    def __init__(self, tool, force: float, nodes, stiffness: np.ndarray, comm, spread: str = "area",
                 thickness: float = 0.0, max_toggles: int = 2, trace: bool = False, edge=None):
        self.split = HolderSplit(force, nodes.area, stiffness, comm, spread)
        self.tool, self.force, self.comm = tool, float(force), comm
        self.nodes, self.thickness, self.max_toggles, self.trace = nodes, thickness, max_toggles, trace
        n = nodes.n_owned
        self.closed, self.toggles = False, 0
        self.lifted_face = LiftedFace(tool, force, thickness, spread, comm)
        self.pinched = np.zeros(n, dtype=bool)
        self.pinched_n = self.pinched.copy()  # of the last converged increment
        self.under_now = np.zeros(n, dtype=bool)  # under the holder in this increment (pinch)
        self.face = np.zeros(n)  # the holder face's normal force on each node
        self.edge_law = edge
        self.edge = np.zeros(n)  # the edge load's shares e_i at the last split (0 off the band)
        self.band = np.zeros(n, dtype=bool)  # the edge's band at the last split
        self.sloped = np.zeros(n, dtype=bool)  # the nodes whose slopes the faces hold
        self.view = None  # what it reads of the contact set (compose)
        self.committed = None
        self._edge_rates = {}  # dV_e/dp per parameter (_edge_rate)

    def bind(self, driver) -> None:
        self.lifted_face.bind(driver.model.V)

    @property
    def lift(self) -> float:
        """The open holder's lift above its closed position (mm)."""
        return self.lifted_face.lift

    @lift.setter
    def lift(self, value: float) -> None:
        self.lifted_face.lift = float(value)

    def compose(self, view) -> None:
        """The view (contact_set.SetView) of the contact set whose die the holder pinches onto and
        whose tools its open face joins: what it reads there; it writes nothing there."""
        self.view = view

    @property
    def edge_load(self) -> float:
        """V_e (N/mm), 0 without an edge load."""
        return self.edge_law.line_load if self.edge_law is not None else 0.0

    @property
    def is_open(self) -> bool:
        """The holder is open and presses (a tool with its own lift)."""
        return not self.closed and self.force > 0

    def under(self, x: np.ndarray) -> np.ndarray:
        """Nodes whose plan position lies under the holder's face."""
        return np.isfinite(self.tool.gap(x, 0.0, 0.0)[0])

    def _sum(self, v) -> float:
        return self.comm.allreduce(float(np.sum(v)), op=MPI.SUM)

    def edge_shares(self, x: np.ndarray, pinched: np.ndarray, line_load: float | None = None,
                    area: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(e, band): e_i = V_e a_i j_i (2 / b_i) sin^2(pi s_i / b_i) on the pinched nodes at x
        within b_i = 2 r_i of the holder's inner edge, 0 elsewhere (pinch_edge.py): s_i their
        plan distance from it, j_i the edge's length per unit length of their offset line, and
        in the current plan a_i their area and r_i the spacing of their rows along s
        (SheetNodes.spread of s: the rows' spacing however the flange has stretched, so that
        the kernel sums to 1 over them and the band's total is V_e per unit length of the
        edge). The band, the pinched nodes with s_i < b_i, includes those drawn past the edge
        in this increment (s < 0, still pinched until the next). line_load: V_e (default the
        edge law's); area: the nodes' a_i (default the iterate's, SheetNodes.current_area)."""
        V = self.edge_load if line_load is None else line_load
        if self.edge_load <= 0.0:
            return np.zeros(pinched.size), np.zeros(pinched.size, dtype=bool)
        s, j = self.tool.edge_offset(x)
        rows = self.nodes.spread(s)
        band = pinched & (s < 2.0 * rows)
        area = self.nodes.current_area() if area is None else area
        return np.where(pinched, V * area * j * edge_weights(s, rows), 0.0), band

    def rides(self, share: float, tolerance: float) -> bool:
        """Whether giving its edge `share` of the edge load lifts the holder by at most
        `tolerance` (EdgeLoad.riding_lift; always without an edge load)."""
        return self.edge_law is None or share >= 1.0 or self.edge_law.riding_lift(share) <= tolerance

    def lifted(self, net: np.ndarray, edge: np.ndarray, band: np.ndarray, tolerance: float) -> bool:
        """The closed holder cannot hold the flange: its holding-down off the edge's band passes
        F, or riding on its edge would lift it by more than `tolerance` (all ranks agree)."""
        inner, total_edge = self.split.demands(self.pinched, net, edge, band)
        return inner > self.force or not self.rides(self.split.edge_share(inner, total_edge), tolerance)

    def may_ride(self, x: np.ndarray, under: np.ndarray) -> bool:
        """Whether the open holder, closed on the flange on the die under it, could carry at
        least the share of its edge load that keeps riding within the contact's tolerance."""
        total = self._sum(self.edge_shares(x, under & self.view.on_die())[0])
        return self.rides(self.split.edge_share(0.0, total), self.view.penetration)

    def held_down(self, net: np.ndarray) -> tuple[float, float, float]:
        """(E_in + f E_e, E_e, E_in) / F of the closed holder at its last split (HolderSplit.held_down)."""
        return self.split.held_down(self.pinched, net, self.edge, self.band)

    def face_slopes(self, net: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(dd_i/dR0_i, dh_i/dR0_i) of the pinched nodes at the last split (HolderSplit.face_slopes),
        whose sum is d(d_i + h_i)/dR0_i."""
        return self.split.face_slopes(net, self.face, self.band)

    def face_gap(self, x: np.ndarray, half: np.ndarray):
        """Gap and normal of the open holder's face to the nodes at x with half thicknesses
        `half`: the flat face z_face + lift ("rigid"), or over each node z_face + lift + (2 half
        - t0), which lies `lift` above the node's top when the node rests on the die ("area");
        an infinite gap when the holder is closed or has no force."""
        if not self.is_open:
            return np.full(len(x), np.inf), np.tile([0.0, 0.0, -1.0], (len(x), 1))
        return self.lifted_face.gap(x, half)

    def lift_floor(self, tops: np.ndarray) -> float:
        """The closed position of the lift (LiftedFace.floor)."""
        return self.lifted_face.floor(tops)

    def total(self, h: np.ndarray | None = None) -> float:
        """The holder's force on the sheet, all ranks (its face forces, or `h`)."""
        return self._sum(self.face if h is None else h)

    # -- the pinch and the faces ---------------------------------------------------------------
    def _tops(self, x):
        return x[:, 2] + self.nodes.half_thickness

    def pinch(self, under, grow: bool) -> None:
        """The pinched nodes: on the die, under the closed holder (mask `under`); with `grow`
        the set only grows within the increment (module docstring). The nodes under the open
        holder, whose slopes it holds flat, follow the same rule."""
        on_die = self.view.on_die()
        now = self.closed & under & on_die
        self.pinched = (self.pinched | now) if grow else now
        self.pinched &= self.closed & on_die
        self.under_now = (self.under_now | under) if grow else under.copy()
        flat = self.flat()
        self.nodes.hold_flat(flat, self.pinched)
        self.sloped = self.nodes.interior(flat)

    def flat(self) -> np.ndarray:
        """The nodes the faces hold flat: the pinched ones, and under the open holder every node
        beneath it."""
        return self.pinched | self.under_now if self.is_open else self.pinched.copy()

    def faces(self, x, net) -> tuple[np.ndarray, np.ndarray]:
        """The face forces of the holder from the nodes' net normal forces `net` (die minus
        holder on a pinched node), at positions x: the closed holder's split; the open holder's
        face takes the force of the nodes on it. Returns the die's face forces under it, (nodes,
        values), for the contact set to press: the split's on the pinched nodes, 0 on the open
        face's nodes (they do not touch the die)."""
        if self.closed:
            self.edge, self.band = self.edge_shares(x, self.pinched)
            d, self.face = self.split.forces(self.pinched, net, self._tops(x), self.edge, self.band)
            return self.pinched.copy(), d[self.pinched]
        self.edge, self.band = np.zeros(net.size), np.zeros(net.size, dtype=bool)
        on = self.view.on_face()
        self.face = np.where(on, np.maximum(net, 0.0), 0.0)
        return on, np.zeros(int(on.sum()))

    def close_on(self, x) -> tuple[np.ndarray, np.ndarray]:
        """At the start: the holder closes on the flange when it has a force. Returns the die's
        face forces under it (faces)."""
        self.closed = self.force > 0
        self.pinch(self.under(x), grow=False)
        pressed = self.faces(x, np.zeros(x.shape[0]))
        self.committed = self._copy()
        return pressed

    def _copy(self):
        return {"closed": self.closed, "lift": self.lift, "face": self.face.copy()}

    def _lift_floor_over(self, x, under) -> float:
        """The closed position of the lift over the nodes on the die under the holder."""
        on_die = under & self.view.on_die()
        return self.lift_floor(self._tops(x)[on_die])

    def on_face(self):
        """The owned nodes on the open holder's face, and their number on all ranks."""
        on = self.view.on_face()
        return on, self.comm.allreduce(int(on.sum()), op=MPI.SUM)

    def settle(self, x, under, net, lam) -> tuple[int, np.ndarray, np.ndarray]:
        """After a converged pass: open the holder if the flange lifts it (its holding-down off the
        edge's band, E_in, passes F): the pinched nodes it holds down (R0 < 0) go onto its face, the others stay on
        the die, the face at its closed position. Close it once its lift is below that position
        by more than the contact set's known tolerance (within a pass the lift may pass it),
        unless that would spend its last switch of the increment or its edge load would lift it
        again (may_ride); its face's nodes go back onto the die. Lower an open holder that
        touches nothing onto the nearest node, which goes onto its face. `net`: the nodes' net
        normal forces. Returns (changes, onto its face, back onto the die): the changes the same
        on all ranks, the nodes for the contact set to move (a node that changes faces then
        carries its new face's force: the set turns its R0's sign). The set then pinches and
        splits again (pinch, faces)."""
        changes = 0
        to_face, to_die = np.zeros(net.size, dtype=bool), np.zeros(net.size, dtype=bool)
        if self.toggles < self.max_toggles and self.force > 0:
            if self.closed and self.lifted(net, *self.edge_shares(x, self.pinched), self.view.penetration):
                self.closed = False
                self.lift = self.lift_floor(self._tops(x)[self.pinched])
                to_face = self.pinched & (net < 0)  # held down: onto its face
                changes = 1
            elif (not self.closed and self.toggles + 1 < self.max_toggles and self.may_ride(x, under)
                  and self.lift < self._lift_floor_over(x, under) - self.view.known_tolerance):
                # the face presses into the flange on the die: closed (if it may still open
                # again in this increment: closed with its switches spent, it could be left
                # holding more than F)
                self.closed = True
                to_die = self.view.on_face()  # then pinched (the face is at the sheet)
                changes = 1
            elif not self.closed and self.on_face()[1] == 0:
                gap = self.face_gap(x, self.nodes.half_thickness)[0]
                nearest = self.comm.allreduce(float(gap[under].min(initial=np.inf)), op=MPI.MIN)
                if np.isfinite(nearest) and self.lift - nearest <= self._lift_floor_over(x, under):
                    self.closed = True  # down to the sheet on the die: closed
                    changes = 1
                elif np.isfinite(nearest):
                    self.lift -= nearest  # the face comes down onto the nearest node
                    to_face = under & (gap <= nearest + self.view.penetration) & self.view.free()
                    changes = 1
            self.toggles += changes
            if self.trace and changes:
                face = (self.view.on_face() & ~to_die) | to_face
                say(f"    holder: {'closed' if self.closed else 'open'}, lift {self.lift:.3e} mm, "
                    f"{self.comm.allreduce(int(face.sum()), op=MPI.SUM)} nodes on its face")
        return changes, to_face, to_die

    # -- the part's protocol -------------------------------------------------------------------
    def start(self, lam: float, predicting: bool) -> None:
        c = self.committed
        self.closed, self.lift, self.face = c["closed"], c["lift"], c["face"].copy()
        self.toggles = 0
        self.pinch(self.under(self.nodes.x_n), grow=False)

    def constrain(self, c, lam: float) -> None:
        """The holder's flat faces hold the flange flat: the slopes of w are known on the nodes
        they hold flat (the pinched ones, every node under the open holder) but for the
        boundary of that region, where a cell reaches beyond the faces: the sheet turns within
        that cell, and held flat at its node it would turn a cell inside the edge, at a place that
        jumps by a cell each time a row of nodes is drawn out (a sawtooth in the punch force,
        docs/contact.md). They stay known (and the pinched nodes' w) within the increment. Flat is the lower
        surface: the mid-surface lies a half thickness above the die, so its slopes are the half
        thickness's gradient (SheetNodes.surface_slopes), not zero: zero slopes under a w that
        follows the thickness kink the sheet at every node, with curvatures ~ dh / h^2 that grow
        as the mesh is refined. The thickness of a node held flat is that of the material between
        the faces (SheetNodes.hold_flat), not of the cells bent beyond the pinch's edge."""
        flat = self.sloped
        c.known[flat, W_SLOPES] = (self.nodes.surface_slopes - self.nodes.slopes())[flat]
        c.flags[flat, W_SLOPES] = True
        c.stable[flat, W_SLOPES] = True
        c.stable[self.pinched, 2] = True

    def imbalance(self) -> float:
        """F - sum p_i over the open holder's nodes (all ranks), 0 when it has none: the
        derivative of the energy with respect to its lift."""
        if not self.is_open:
            return 0.0
        on, count = self.on_face()
        if count == 0:
            return 0.0
        return self.force - self._sum(self.view.net_normal_forces()[on])

    def border(self, driver) -> float:
        """The open holder's lift in this Newton iteration, solved with the sheet
        (LiftedFace.border); none while it is closed or touches nothing."""
        on, count = self.on_face() if self.is_open else (None, 0)
        if count == 0:
            self.lifted_face.hold()
            return 0.0
        return self.lifted_face.border(driver, on, self.imbalance())

    def slope(self) -> float:
        return self.lifted_face.slope(self.imbalance())

    def move(self, alpha: float) -> None:
        self.lifted_face.move(alpha)

    def commit(self, lam: float) -> None:
        self.toggles = 0
        self.committed = self._copy()
        self.pinched_n = self.pinched.copy()

    def checkpoint(self) -> dict:
        c = self.committed
        return {"nodes": {"contact_holder_face": c["face"], "contact_pinched": self.pinched_n},
                "global": {"contact_closed": np.array(c["closed"]), "contact_lift": np.array(c["lift"])}}

    def restore(self, state: dict, lam_scale: float) -> None:
        nodes, glob = state["nodes"], state["global"]
        self.committed = {"closed": bool(glob["contact_closed"]), "lift": float(glob["contact_lift"]),
                          "face": nodes["contact_holder_face"].copy()}
        self.closed, self.lift, self.face = self.committed["closed"], self.committed["lift"], self.committed["face"].copy()
        self.pinched = nodes["contact_pinched"].copy()
        self.pinched_n = self.pinched.copy()

    def report(self) -> dict:
        return {"holder_closed": bool(self.closed), "holder_lift": float(self.lift)}

    def iterate_state(self) -> dict:
        """Its own state, its face's lift and its split's band (Part.iterate_state)."""
        return {"own": super().iterate_state(), "face": self.lifted_face.iterate_state(),
                "split": self.split.iterate_state()}

    def set_iterate_state(self, state: dict) -> None:
        super().set_iterate_state(state["own"])
        self.lifted_face.set_iterate_state(state["face"])
        self.split.set_iterate_state(state["split"])

    # -- derivatives (nonlinear/sensitivity.py) ------------------------------------------------
    EDGE_STEP = 1e-3  # the edge load's central differences in a material parameter, relative to it

    def derivatives(self) -> str | None:
        """The closed holder's split is differentiated (face_derivatives), its pinched nodes'
        known slopes too (known_derivatives); the open holder's lift is solved with the
        derivative as it is with Newton's step (border_derivative)."""
        return None

    def known_derivatives(self, delta: np.ndarray, de33: np.ndarray) -> None:
        """The nodes the faces hold flat take the slopes of the surface a half thickness above
        the die (constrain): their slope rows' derivative is that surface's
        (SheetNodes.surface_slopes_derivative). A node on the die or under the flat ("rigid")
        open face lies its half thickness from it: the contact set's h_i'. Under the conforming
        ("area") open face, which lies 2 h_i - t0 above the flat one, the node lies t0 - h_i
        from it: -h_i' along the normal, so -2 h_i' here on the contact set's +h_i'. The
        lift's own derivative is border_derivative's."""
        if self.force > 0:  # every rank: the gradient gathers the cells of every rank
            delta[self.sloped, W_SLOPES] += self.nodes.surface_slopes_derivative(de33)[self.sloped]
        if self.is_open and self.lifted_face.spread != "rigid":
            on = self.on_face()[0]
            delta[on, 2] -= 2.0 * self.nodes.half_thickness_derivative(de33)[on]

    def border_derivative(self, key: str, driver, out, dR: np.ndarray, parameter=None) -> bool:
        """The open holder's lift z' (LiftedFace.border_derivative), its force's derivative F' 1
        where the parameter is the holder's force."""
        on, count = self.on_face() if self.is_open else (None, 0)
        if count == 0:
            return False
        dforce = self.force / parameter.value if parameter is not None and parameter.holder_force else 0.0
        self.lifted_face.border_derivative(driver, on, dforce, dR, out)
        return True

    def face_derivatives(self, parameter, net: np.ndarray, dnet: np.ndarray, x: np.ndarray, dx: np.ndarray,
                         eps: float) -> tuple[np.ndarray, np.ndarray]:
        """(dd, dh) per owned node: d/dp of the closed holder's split (d_i, h_i) on the pinched
        nodes, 0 elsewhere, along the net normal forces' derivative dnet, the positions' dx (the
        edge load's shares follow each node's distance from the edge, its rows' spacing and its
        area), the force's (the parameter's, where it is the holder's force) and
        the edge load's V_e (its strip's, where the parameter is the material's): central
        differences of HolderSplit.split_of with step eps, the pinched nodes and the edge's band
        held as converged."""
        zero = np.zeros(net.size)
        if not self.closed or self.force <= 0:
            return zero, zero.copy()
        dF = self.force / parameter.value if parameter is not None and parameter.holder_force else 0.0
        dV = self._edge_rate(parameter)
        ends = []
        for sign in (1.0, -1.0):
            y = x + sign * eps * dx
            e = self.edge_shares(y, self.pinched, self.edge_load + sign * eps * dV, self.nodes.current_area(y))[0]
            ends.append(self.split.split_of(self.force + sign * eps * dF, self.pinched, net + sign * eps * dnet,
                                            self._tops(y), e, self.band))
        return (ends[0][0] - ends[1][0]) / (2 * eps), (ends[0][1] - ends[1][1]) / (2 * eps)

    def _edge_rate(self, parameter) -> float:
        """dV_e/dp: central differences of the edge's strip (EdgeLoad.at) at p (1 +- EDGE_STEP)
        where the parameter is the material's, else 0; once per parameter."""
        if self.edge_law is None or parameter is None or "material" not in parameter.respond(parameter.value):
            return 0.0
        rates = self._edge_rates
        if parameter.name not in rates:
            step = self.EDGE_STEP * abs(parameter.value)
            ends = [self.edge_law.at(parameter.respond(parameter.value + sign * step)["material"]).line_load
                    for sign in (1.0, -1.0)]
            rates[parameter.name] = (ends[0] - ends[1]) / (2 * step)
        return rates[parameter.name]
