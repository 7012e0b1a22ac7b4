"""The contact set: which node lies on which rigid tool (the paper's eqs. 24-29).

A node on a tool is seen in the tool's normal frame (frames.py); its normal displacement is
*known* (it follows the tool: the correction -gap closes the gap at the current iterate), its
normal contact force R0 is *unknown*, the residual of that known row (the paper's split):

    K11 dq1 = dp1 - K12 dq*      (27)  free increments, the known ones lifted to the right
    dp*     = K21 dq1 + K22 dq*  (28)  contact forces: the residual on the known rows

The tools are given in contact order (punch, die); tool k moves by paths[k].at(lambda) along its
axis (tool.axis: +z for the analytic tools, any direction for a placed one, placement.py); its
travel is a number (a Linear path of that rate) or a path of shellform.tools.travel (a holder
that stops at its gap over a curved binder: Capped).
The open holder's face is one more tool (holder.py), the last. Each tool gives its gap,
normal and shape operator H = dn/dx (tools.py). A node moving along a curved tool turns its
frame; its tangential rows t_a . R, with R ~ R0 n, then change by R0 n . dt_a = -R0 W_ab dx_b,
W_ab = t_a . H t_b, so the tangent gets K_ab += -R0 W_ab (softening on a convex nose,
stiffening in a concave shoulder).

The set is settled between Newton passes (``update``): nodes that penetrate a tool by more than
`penetration` join it, nodes (not pinched) whose normal force turned tensile leave it, nodes
drawn under the closed holder join the die; a node may switch at most `max_toggles` times per
increment (no chattering). A node so frozen off the tools that still penetrates one beyond
`penetration` when the set would otherwise settle joins it, a last switch, and stays on it for the
rest of the increment: no increment is accepted with a node inside a tool. A pass
may end before it converges where the set will change anyway, once Newton's steps are below
`early_step` penetrations (a step that long judges the set on an iterate still moving; after such
passes fail, they end only near convergence, early_step 1).
Newton's steps are bounded by `trust` thicknesses of nodal move (largest_move).

A node's faces lie its half thickness h_i from its mid-surface. Where two tools face each other
across the sheet closer than its thickness, a part bounds the thickness there (bound_by: the
ironing, with the clearance c_i between the tools through the node); the contact sees the faces
at min(h_i, c_i / 2). The sheet thicker than the clearance is the bound's business (its penalty's
overclosure, the nodes' recovered thickness against the cells' bounded mean): seen at h_i, a node
on one face would penetrate the other by 2 h_i - c_i, join it when released, and lie on either
face a different mid-surface apart; at c_i / 2 it lies in the clearance's middle on either face.
"""

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from shellform.assembly.sheet_element import BS
from shellform.nonlinear.frames import nodal_frames
from shellform.nonlinear.parts import Change, Part
from shellform.results.log import say
from shellform.tools.travel import path as travel_path

FREE = -1


@dataclass
class ContactControls:
    penetration: float  # a free node may penetrate a tool by at most this much (length)
    max_toggles: int = 2  # switches of one node (or of the holder) per increment before it is frozen
    friction_rtol: float = 1e-4  # passes end when |mu dp| <= friction_rtol |mu p| (2-norms)
    trust: float = 0.5  # the largest nodal update of one Newton iteration, in thicknesses
    holder_spread: str = "area"  # a spread rule of holder_split.py
    trace: bool = False  # log every pass, step and iterate (the largest residuals) and each node that switches


@dataclass(frozen=True)
class SetView:
    """What another part reads of the contact set, and all it may: the owned nodes on the die
    (where the closed holder pinches), on the open holder's face and off every tool, each node's
    net normal force, and the set's two tolerances. Nothing writes through it: a part's decisions
    about the set (the holder's nodes onto its face or back onto the die, the die's face forces
    under it) return to the set, which applies them."""

    on_die: Callable[[], np.ndarray]
    on_face: Callable[[], np.ndarray]
    free: Callable[[], np.ndarray]
    net_normal_forces: Callable[[], np.ndarray]
    penetration: float  # how far a free node may penetrate a tool
    known_tolerance: float  # |known corrections| at convergence


class ContactSet(Part):
    """The nodes on the tools: per owned node its tool (or FREE), its tool face's normal force
    and its switches in this increment; the die index, where the closed holder pinches."""

    EARLY_STEP = 10.0  # a pass ends once the set will change and the steps are below this many penetrations

    def __init__(self, nodes, tools, travel, controls: ContactControls, thickness: float, die=None, holder=None):
        self.nodes, self.tools = nodes, list(tools)
        self.paths = [travel_path(t) for t in travel]
        self.travel = np.array([p.rate for p in self.paths])  # the rates (the checkpoint's)
        self.axes = np.array([tool.axis for tool in self.tools], dtype=float).reshape(-1, 3)
        self.controls, self.thickness = controls, thickness
        self.die = len(self.tools) - 1 if die is None else int(die)
        self.holder = holder
        self.holder_tool = len(self.tools)  # the open holder's index
        self.bound = None  # a part that bounds the sheet's thickness between two tools (bound_by)
        n = nodes.n_owned
        self.tool = np.full(n, FREE, dtype=np.int8)
        self.pressure = np.zeros(n)  # the tool face's normal force (the die's on a pinched node)
        self.toggles = np.zeros(n, dtype=np.int32)
        self.known_tolerance = 1e-3 * controls.penetration  # |known corrections| at convergence
        self.early_step = self.EARLY_STEP
        self.lam_n = 0.0
        self.curvature = np.zeros((n, 2, 2))  # W of each node's tool in its tangent slots
        self.shift = np.zeros((n, 3))  # the travel of each node's tool in this increment
        self.slid_off = np.zeros(n, dtype=bool)  # nodes that slid off their tool's extent (this iterate)
        self.switched = np.zeros(n, dtype=bool)  # nodes that switched in the last update
        self.net = np.zeros(n)  # the net normal forces of the last refresh
        self.frames = None  # the iterate's nodal frames (follow)
        self._turn = {}  # per parameter: the frames' turn along the solved derivative (carry)
        self.following = False  # the faces follow the reactions (the iterates after a pass's first)
        self.frozen = 0
        self.residual = None  # the driver's residual with its reactions (bind)
        self.comm = None
        self.committed = None

    def view(self) -> SetView:
        """The set as another part may read it (SetView)."""
        return SetView(lambda: self.tool == self.die, lambda: self.tool == self.holder_tool,
                       lambda: self.tool == FREE, self.net_normal_forces, self.controls.penetration,
                       self.known_tolerance)

    def bind(self, driver) -> None:
        self.residual = lambda: driver.residual_full
        self.comm = driver.model.mesh.comm
        self._initial_set()

    def bound_by(self, part) -> None:
        """Where two tools face each other across the sheet closer than its thickness, `part`
        (the ironing) bounds the thickness: its ``half_thickness(gaps, h)`` is the half thickness
        the sheet's faces lie at there (module docstring), its ``bounds()`` the owned nodes whose
        faces lie at the bound (their known rows' derivatives are the part's)."""
        self.bound = part

    # -- geometry ------------------------------------------------------------------------------
    def gaps(self, x, lam, bounded: bool = True):
        """Gap and normal of every owned node to every tool at load factor lam, the open holder
        last (an infinite gap when it is closed or has no force). The sheet's faces lie a half
        thickness h_i from the mid-surface; with `bounded`, where a part bounds the thickness
        between two tools (bound_by), at the bounded one."""
        h = self.nodes.half_thickness
        gaps = self._gaps(x, h, lam)
        if bounded and self.bound is not None:
            hb = self.bound.half_thickness(gaps, h)
            if np.any(hb < h):
                gaps = self._gaps(x, hb, lam)
        return gaps

    def _gaps(self, x, h, lam):
        gaps = [tool.gap(x, h, p.at(lam)) for tool, p in zip(self.tools, self.paths)]
        if self.holder is not None:
            gaps.append(self.holder.face_gap(x, h))
        return gaps

    def shape_of(self, k: int, x, lam) -> np.ndarray:
        """(len(x), 3, 3): dn/dx of tool k's surface at positions x, load factor lam (the open
        holder's flat face: 0)."""
        if k == self.holder_tool:
            return np.zeros((len(x), 3, 3))
        return self.tools[k].shape(x, 0.0, self.paths[k].at(lam))

    def normals_at(self, x, lam) -> np.ndarray:
        """(n_owned, 3): each node's tool's normal at positions x (+z off the tools)."""
        out = np.tile([0.0, 0.0, 1.0], (x.shape[0], 1))
        h = self.nodes.half_thickness
        for k, (tool, path) in enumerate(zip(self.tools, self.paths)):
            on = self.tool == k
            if on.any():
                out[on] = tool.gap(x[on], h[on], path.at(lam))[1]
        return out

    def on(self, k: int) -> np.ndarray:
        """The owned nodes on tool k (the open holder: holder_tool)."""
        return self.tool == k

    def on_tools(self) -> np.ndarray:
        return self.tool != FREE

    def assign(self, nodes: np.ndarray, k: int) -> None:
        """Put `nodes` (a mask or indices) on tool k (FREE: off every tool)."""
        self.tool[nodes] = k

    def _initial_set(self):
        """Nodes touching a tool at the start (gap within the penetration tolerance); the holder
        closes on the flange when it has a force."""
        x = self.nodes.positions()
        for k, (gap, _) in enumerate(self.gaps(x, 0.0)):
            touch = (gap <= self.controls.penetration) & (self.tool == FREE)
            self.tool[touch] = k
        if self.holder is not None:
            self._press(*self.holder.close_on(x))
        self.committed = self._copy()

    def _copy(self):
        return {"tool": self.tool.copy(), "pressure": self.pressure.copy()}

    # -- forces ------------------------------------------------------------------------------
    def net_normal_forces(self, R=None) -> np.ndarray:
        """Each owned node's net normal force R0 from its tool (die minus holder on a pinched
        node; 0 off the tools), from the residual R (nodal frames; default: the driver's last)."""
        R = self.residual() if R is None else R
        rows = R[: self.nodes.n_owned * BS].reshape(-1, BS)
        return np.where(self.tool != FREE, rows[:, 2], 0.0)

    def refresh(self, R) -> np.ndarray:
        """The faces' normal forces from the reactions of this iterate (R: the sheet's and the
        drawbeads' forces, before friction): the tool's face max(R0, 0), the holder's faces split
        from R0. Returns R0."""
        net = self.net_normal_forces(R)
        self.net = net
        self.pressure = np.maximum(net, 0.0)
        if self.holder is not None:
            self._press(*self.holder.faces(self._x, net))
        return net

    def _press(self, nodes, values) -> None:
        """Set the tool face's normal force of `nodes` (the holder's split on the die under it)."""
        self.pressure[nodes] = values

    def face_forces(self) -> np.ndarray:
        """The sum of both faces' normal forces on each node (what friction presses with)."""
        return self.pressure + (self.holder.face if self.holder is not None else 0.0)

    def faces(self) -> tuple[np.ndarray, np.ndarray]:
        """Each node's two faces' normal forces (d, h): its tool's face (the die's on a pinched
        node; 0 on the open holder's face) and the holder's (the closed holder's on a pinched
        node, the open one's on its face; 0 elsewhere). face_forces is d + h; friction gives
        each its own tool's coefficient."""
        return self.pressure, (self.holder.face if self.holder is not None else np.zeros_like(self.pressure))

    def face_slopes(self) -> tuple[np.ndarray, np.ndarray]:
        """(dd/dR0, dh/dR0) per node, the faces of ``faces``: on a tool 1 where it presses (to
        its tool's face), on a pinched node the closed holder's split (its face_slopes: F's
        spread held fixed), 0 off the tools."""
        on = self.tool != FREE
        tool, holder = (self.net > 0).astype(float), np.zeros(self.net.size)
        if self.holder is not None:
            die, top = self.holder.face_slopes(self.net)
            tool = np.where(self.holder.pinched, die, tool)
            holder = np.where(self.holder.pinched, top, holder)
        return np.where(on, tool, 0.0), np.where(on, holder, 0.0)

    # -- the part's protocol -------------------------------------------------------------------
    def stepped(self, yes: bool) -> None:
        """On the iterates after a pass's first the faces follow the reactions (add_residual); on
        a pass's first they keep the update's."""
        self.following = yes

    def add_residual(self, R) -> None:
        """The faces' normal forces from this iterate's reactions (refresh), where they follow
        them: friction presses with them (the parts before the set add the drawbeads' forces,
        the set adds none)."""
        if self.following:
            self.refresh(R)

    def start(self, lam: float, predicting: bool) -> None:
        c = self.committed
        self.tool, self.pressure = c["tool"].copy(), c["pressure"].copy()
        self.toggles = np.zeros_like(self.toggles)

    def constrain(self, c, lam: float) -> None:
        """Frames and known normal rows of the nodes on the tools, at the current iterate."""
        x = self.nodes.positions()
        self._x = x
        gaps = self.gaps(x, lam)
        self.curvature = np.zeros((x.shape[0], 2, 2))
        self.shift = np.zeros((x.shape[0], 3))
        self.slid_off = np.zeros(x.shape[0], dtype=bool)
        for k in range(len(gaps)):
            off = (self.tool == k) & ~np.isfinite(gaps[k][0])  # slid off the tool's extent
            self.tool[off], self.pressure[off] = FREE, 0.0
            self.slid_off |= off
            on = np.flatnonzero(self.tool == k)
            if on.size == 0:
                continue
            gap, normal = gaps[k][0][on], gaps[k][1][on]
            c.frames[on] = nodal_frames(normal)
            c.known[on, 2] = -gap  # the normal correction that closes the gap
            c.flags[on, 2] = True
            if k == self.holder_tool:
                continue  # flat, and still in plan
            H = self.tools[k].shape(x[on], 0.0, self.paths[k].at(lam))  # dn/dx
            t = c.frames[on][:, :2]
            self.curvature[on] = np.einsum("nai,nij,nbj->nab", t, H, t)  # W_ab = t_a . H t_b
            self.shift[on] = self.paths[k].between(self.lam_n, lam) * self.axes[k]

    def follow(self, frames: np.ndarray, lam: float) -> None:
        """The iterate's nodal frames (owned and ghost nodes), which carry reads."""
        self.frames = frames

    def add_tangent(self, K, R, fixed) -> None:
        """K_ab += -R0 W_ab on the tangent slots of the nodes on curved tools (module
        docstring; R0 the node's net normal force with every part's forces)."""
        b = np.flatnonzero((self.tool != FREE) & (np.abs(self.curvature).max(axis=(1, 2)) > 0))
        if b.size == 0:
            return
        net = R[: self.nodes.n_owned * BS].reshape(-1, BS)[:, 2]
        held = self.nodes.held[b, :2]
        blocks = -net[b, None, None] * self.curvature[b]
        blocks[held[:, :, None] | held[:, None, :]] = 0.0
        rows = (BS * b[:, None] + np.arange(2)).astype(np.int32)
        K.setValuesLocalRCV(rows, rows, blocks.reshape(b.size, 4), addv=True)

    def largest_move(self) -> float:
        return self.controls.trust * self.thickness

    def ends_pass(self, move: float, lam: float) -> bool:
        """Once the steps are short (early_step penetrations), whether the set will change at the
        end of this pass, seen from this iterate: a free node penetrating a tool, a node drawn
        under the closed holder, or a node (not pinched) pulled off its tool by more than 1e-3
        of the largest normal force."""
        if move > self.early_step * self.controls.penetration:
            return False
        x = self.nodes.positions()
        under = self._under(x)
        join, release, _, _ = self._changes(x, lam, under, self.net_normal_forces(), tensile=1e-3)
        return self.comm.allreduce(int(np.sum(join | release)), op=MPI.SUM) > 0

    def retry(self) -> str | None:
        """Where passes that end early failed: from now on they end only near convergence."""
        if self.early_step <= 1.0:
            return None
        self.early_step, before = 1.0, self.early_step
        return f"from now on the contact passes end only near convergence (early_step {before:g} -> 1)"

    def easy_iterations(self, max_iterations: int) -> int:
        return 2 * max_iterations // 3  # an increment of a few contact passes is still an easy one

    def _under(self, x):
        return self.holder.under(x) if self.holder is not None else np.zeros(x.shape[0], dtype=bool)

    def _changes(self, x, lam, under, net, tensile: float):
        """The nodes that join a tool (penetrating it by more than `penetration`, or drawn under
        the closed holder: onto the die) and those that leave theirs (not pinched, pulled off by
        more than `tensile` times the largest normal force), among the nodes that may still
        switch in this increment; with the tool each joining node joins, and the nodes frozen
        off the tools that penetrate one (sunk: their switches are spent, update decides)."""
        on, can = self.tool != FREE, self.toggles < self.controls.max_toggles
        scale = max(self.comm.allreduce(float(np.abs(net).max(initial=0.0)), op=MPI.MAX), 1e-300)
        pinched = self.holder.pinched if self.holder is not None else np.zeros_like(on)
        release = on & ~pinched & (net < -tensile * scale) & can
        depth = np.stack([g for g, _ in self.gaps(x, lam)])  # (tools, nodes)
        deepest = np.argmin(depth, axis=0)
        enters = under & ~on & (self.holder is not None and self.holder.closed)  # the closed holder pinches
        deepest[enters] = self.die
        allowed = np.full(len(x), self.controls.penetration)
        if self.holder is not None and self.holder.is_open:  # between its faces: as tight as the pinch it opened
            allowed[self.holder.under_now] = self.known_tolerance
        penetrating = ~on & ((depth.min(axis=0) < -allowed) | enters)
        return penetrating & can, release, deepest, penetrating & ~can

    def update(self, lam: float, changes: int) -> Change:
        """After a converged pass: normal forces from the reactions, the holder's state and
        faces (holder.py), release of tensile nodes (not pinched), join of penetrating ones.
        Counts the switches back (a node's second switch, or the holder's): a pass whose changes
        are all first switches moves the contact front on (a sheet peeling off the punch's face
        releases one row of nodes per pass) and is not counted against the driver's passes."""
        x = self.nodes.positions()
        net = self.net_normal_forces()
        self.pressure = np.maximum(net, 0.0)
        under = self._under(x)
        holder_changes = 0
        if self.holder is not None:
            holder_changes = self._settle_holder(x, under, net, lam)
        join, release, deepest, sunk = self._changes(x, lam, under, net, tensile=1e-8)
        pending, sunk_count = self.comm.allreduce(
            np.array([holder_changes + int((join | release).sum()), int(sunk.sum())]), op=MPI.SUM)
        line = ""
        if sunk_count and not pending:  # the set would settle with nodes frozen inside a tool: they join it
            depth = self.comm.allreduce(-min(g[sunk].min(initial=0.0) for g, _ in self.gaps(x, lam)), op=MPI.MAX)
            line = f", {int(sunk_count)} nodes frozen off a tool join it from {depth:.3g} inside"
            join = sunk
        if self.controls.trace:
            X = self.nodes.X
            for i in np.flatnonzero(release | join):
                say(f"      node {i} at {X[i, :2].round(2)} -> {x[i].round(3)}: "
                    + (f"leaves tool {self.tool[i]} (net normal force {net[i]:.3g} N)" if release[i] else
                       f"joins tool {deepest[i]}") + f", switch {self.toggles[i] + 1}")
        self.tool[release] = FREE
        self.tool[join] = deepest[join]
        if self.holder is not None:
            self.holder.pinch(under, grow=True)  # the nodes drawn under the closed holder
        switched = release | join
        self.switched = switched
        self.pressure[switched] = 0.0
        self.toggles[switched] += 1
        self.frozen = int((self.toggles >= self.controls.max_toggles).sum())
        count, back = self.comm.allreduce(
            np.array([holder_changes + int(switched.sum()), holder_changes + int((self.toggles[switched] > 1).sum())]),
            op=MPI.SUM)
        return Change(int(count), int(back), True, f"{int(count)} set changes" + line)

    def _settle_holder(self, x, under, net, lam) -> int:
        """The holder's state after a converged pass (PinchingHolder.settle): its nodes moved onto
        its face or back onto the die, where a node that changes faces carries its new face's
        force (`net` turns its sign there), then its pinch and faces again. Returns its changes."""
        self.holder.pinch(under, grow=True)
        changes, to_face, to_die = self.holder.settle(x, under, net, lam)
        moved = to_face | to_die
        net[moved & (self.tool != FREE)] *= -1  # die minus holder <-> the face's own normal force
        self.tool[to_face] = self.holder_tool
        self.tool[to_die] = self.die
        self.holder.pinch(under, grow=True)
        self._press(*self.holder.faces(x, net))
        return changes

    def commit(self, lam: float) -> None:
        self.toggles[:] = 0
        self.committed = self._copy()
        self.lam_n = lam

    def checkpoint(self) -> dict:
        c = self.committed
        return {"nodes": {"contact_tool": c["tool"], "contact_pressure": c["pressure"]},
                "global": {"contact_lam_n": np.array(self.lam_n), "contact_travel": self.travel,
                           "contact_early_step": np.array(self.early_step)}}

    def restore(self, state: dict, lam_scale: float) -> None:
        nodes, glob = state["nodes"], state["global"]
        if nodes["contact_tool"].shape != self.tool.shape:
            from shellform.errors import InputError

            raise InputError("resume", "the checkpoint's contact state does not fit this model")
        self.committed = {"tool": nodes["contact_tool"].astype(np.int8).copy(),
                          "pressure": nodes["contact_pressure"].copy()}
        self.tool, self.pressure = self.committed["tool"].copy(), self.committed["pressure"].copy()
        self.lam_n = float(glob["contact_lam_n"]) * lam_scale
        if "contact_early_step" in glob:
            self.early_step = float(glob["contact_early_step"])

    def count(self) -> dict:
        """Nodes on each tool (the open holder last) and pinched by the holder, all ranks."""
        counts = {f"tool{k}": self.comm.allreduce(int((self.tool == k).sum()), op=MPI.SUM)
                  for k in range(len(self.tools) + (self.holder is not None))}
        pinched = self.holder.pinched if self.holder is not None else np.zeros(0, dtype=bool)
        counts["pinched"] = self.comm.allreduce(int(pinched.sum()), op=MPI.SUM)
        return counts

    def report(self) -> dict:
        return {"frozen": self.frozen, "in_contact": self.count()}

    def derivatives(self) -> str | None:
        """The set held, a node on a tool has a known normal row and no force on its free rows
        beyond the sheet's (the tools' curvature term is in K); the ironing's bound is refused
        by its own part. None."""
        return None

    def face_derivatives(self, parameter, dnet: np.ndarray, x: np.ndarray, dx: np.ndarray, eps: float):
        """((dd, dh), pinched): d/dp of faces() on the nodes the closed holder pinches, its split's
        (PinchingHolder.face_derivatives) along the net normal forces' derivative dnet and the
        positions' dx; None where no holder presses."""
        if self.holder is None or self.holder.force <= 0:
            return None
        return self.holder.face_derivatives(parameter, self.net, dnet, x, dx, eps), self.holder.pinched

    def carry(self, key: str, dx: np.ndarray, dx_n: np.ndarray, dR: np.ndarray, lam: float, eps: float,
              parameter=None) -> None:
        """The turn of the frames of the nodes on curved tools along the positions' derivative
        dx, for total_derivative: a tangent row t_a . R picks up (dt_a/dp) . n R0 =
        -R0 W_ab (t_b . dx), the curvature term of the tangent (add_tangent) along dx."""
        b = np.flatnonzero((self.tool != FREE) & (np.abs(self.curvature).max(axis=(1, 2)) > 0))
        turn = np.zeros((self.tool.size, 2))
        if b.size:
            t = np.einsum("nai,ni->na", self.frames[b][:, :2], dx[b])
            turn[b] = -self.net_normal_forces()[b, None] * np.einsum("nab,nb->na", self.curvature[b], t)
            turn[self.nodes.held[:, :2]] = 0.0
        self._turn[key] = turn

    def total_derivative(self, key: str, dR: np.ndarray) -> None:
        """dR's tangent rows += the frames' turn (carry): what the element forces' differences,
        taken in the frames held, leave out."""
        if key in self._turn:
            dR[:, :2] += self._turn.pop(key)

    def known_derivatives(self, delta: np.ndarray, de33: np.ndarray) -> None:
        """A node on a tool lies its half thickness h_i from the tool's surface along the normal
        (its frame's third row): d(d(x))/dp = h_i' on that known row (SheetNodes'
        half_thickness_derivative), the tool not moving with p; where a part bounds the
        thickness (bound_by) and the node's faces lie at its bound, 0 here and the bound's
        derivative from that part (Ironing.border_derivative)."""
        on = np.flatnonzero(self.tool != FREE)
        if on.size:
            dh = self.nodes.half_thickness_derivative(de33)
            if self.bound is not None:  # there the clearance's half: the bounding part's (Part.border_derivative)
                dh = np.where(self.bound.bounds(), 0.0, dh)
            delta[on, 2] += dh[on]
