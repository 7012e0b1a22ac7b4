"""Ironing in a drawn part: where two tools face each other across the sheet closer than its
thickness, their faces bound it (shellform.material.ironing). A part of the contact.

A node whose two faces lie within a quarter of the thickness of two tools a and b that face each
other (their normals opposite within 60 degrees: the punch's wall and the die's, a holder at a
gap and the die's top), whether it is on one of them (the contact set's) or on neither, is
*between faces*. There the clearance is the distance between the two tools' surfaces through the
node,

    c_i = 2 h_i + g_a,i + g_b,i     (h_i its half thickness, g its faces' gaps to the tools),

and a cell whose three nodes are between faces gets the mean of their clearances
(SheetModel.squeeze): its sections' thickness is bounded by it, and where the sheet is thicker
the faces press it with p. The bound is one-sided, so a cell whose sheet is thinner than its
clearance is in the set at no cost: the band keeps a cell that the faces have just pressed
thinner from leaving the set and thickening back into it in the next pass. The set is decided
after every converged pass from the pass's positions, as the contact set's is; its changes
count as the parts' changes, and the driver runs another pass on the new set. Within a pass the
set's clearances follow every iterate's positions, with their gradients dc_i/dx_i = n_a + n_b
and those gradients' turn d^2 c_i/dx_i^2 = H_a + H_b (the two tools' shape operators dn/dx:
SheetModel.squeeze): the element's energy depends on the vertices' positions through them, and
its force and tangent carry that (shellform.material.ironing). A node of the set that leaves
the faces within a pass keeps its last clearance, with no gradient, until the pass ends.

So each face presses each node between faces with its share of the cells' face forces (a third
of each cell's int p dA, SheetModel.face_forces) along its normal, a force of the element on its
vertices: where the faces are parallel the two cancel on the node and only the thickness feels
them; where one is inclined to the other (the die's shoulder over the punch's wall) their sum
has a component along the sheet that resists the draw. Each tool's force on the sheet includes
its face's share (face_force). Friction on the faces' squeeze is not modelled: the friction part
sees the normal force of the tool a node is on (docs/contact.md, "Ironing").

The node itself lies on one face or on neither (the contact set's). Where the faces press, the
sheet's thickness exceeds the clearance (by the penalty's overclosure, and by the nodes'
recovered thickness against the cells' bounded mean), so the contact sees the faces of a node
between faces at the half clearance, min(h_i, c_i / 2) (half_thickness, ContactSet.bound_by): on
either face the node then lies in the clearance's middle and touches the other face, which
neither joins it nor moves the node when it switches.
"""

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from shellform.assembly.sheet_element import BS
from shellform.contact.contact_set import FREE
from shellform.nonlinear.parts import Change, Part

FACING = -0.5  # two tools face each other where n_a . n_b is below this (60 degrees from opposite)
BAND = 0.25  # a node is between faces while its other face lies within this many thicknesses of B


def between_faces(gaps, h: np.ndarray):
    """(c, pair, normals) of the nodes from the tools' gaps and normals `gaps` (ContactSet.gaps,
    at half thickness h): c_i the tightest clearance 2 h_i + g_a,i + g_b,i over the pairs of
    facing tools whose faces lie within BAND thicknesses of the node's faces (inf where none),
    the pair (a, b) (FREE, FREE where none) and their normals (nodes, 2, 3). Through the node,
    c_i is the distance between the two surfaces, whatever h_i."""
    clearance = np.full(h.shape[0], np.inf)
    pair = np.full((h.shape[0], 2), FREE, dtype=np.int8)
    normals = np.zeros((h.shape[0], 2, 3))
    for a, (ga, na) in enumerate(gaps):
        for b, (gb, nb) in enumerate(gaps[a + 1:], start=a + 1):
            near = np.isfinite(ga) & np.isfinite(gb) & (ga <= BAND * 2.0 * h) & (gb <= BAND * 2.0 * h)
            near &= np.einsum("ij,ij->i", na, nb) < FACING
            cab = 2.0 * h + ga + gb
            tighter = near & (cab < clearance)
            clearance[tighter] = cab[tighter]
            pair[tighter] = (a, b)
            normals[tighter, 0], normals[tighter, 1] = na[tighter], nb[tighter]
    return clearance, pair, normals


class Ironing(Part):
    """The faces' bound on the sheet's thickness between two tools (module docstring): model, the
    SheetModel it squeezes; nodes, its SheetNodes; contact, the ContactSet whose tools and
    nodes on them it reads."""

    def __init__(self, model, nodes, contact):
        self.model, self.nodes, self.contact = model, nodes, contact
        n = nodes.n_owned
        self.between = np.zeros(n, dtype=bool)  # the owned nodes between faces
        self.pair = np.full((n, 2), FREE, dtype=np.int8)  # the two tools whose faces they lie between
        self.normals = np.zeros((n, 2, 3))  # the two faces' normals there (towards the sheet)
        self.turn = np.zeros((n, 3, 3))  # their sum's derivative d(n_a + n_b)/dx_i there
        self.last = np.full(n, np.inf)  # each node's last clearance
        self.cells = np.zeros(model.num_cells, dtype=bool)  # the cells pressed
        self.bounded = np.zeros(n, dtype=bool)  # the owned nodes whose faces the clearance bounds (half_thickness)
        self.committed = None

    def _nodal(self, lam: float) -> np.ndarray:
        """The owned nodes' clearances c_i at the current positions (inf where a node is not
        between faces); sets the two tools whose faces it lies between, their normals, the
        normals' turn and the nodes whose faces the clearance bounds."""
        x = self.nodes.positions()
        gaps = self.contact.gaps(x, lam, bounded=False)
        h = self.nodes.half_thickness
        clearance, self.pair, self.normals = between_faces(gaps, h)
        self.between = np.isfinite(clearance)
        self.bounded = 0.5 * clearance < h
        self.turn = np.zeros((h.size, 3, 3))
        for a, b in {tuple(pair) for pair in self.pair[self.between]}:
            on = np.flatnonzero(self.between & (self.pair[:, 0] == a) & (self.pair[:, 1] == b))
            self.turn[on] = self.contact.shape_of(a, x[on], lam) + self.contact.shape_of(b, x[on], lam)
        return clearance

    def half_thickness(self, gaps, h: np.ndarray) -> np.ndarray:
        """The half thickness at which the sheet's faces lie for the contact (ContactSet.
        bound_by): min(h_i, c_i / 2) at a node between faces, h_i elsewhere; `gaps` the tools'
        gaps at h (module docstring)."""
        return np.minimum(h, 0.5 * between_faces(gaps, h)[0])

    def _squeeze(self, lam: float, decide: bool) -> int:
        """The cells' clearances at the current positions, the mean of their vertices', and the
        gradients n_a + n_b at the vertices. With `decide` the set is the cells whose three
        vertices are between faces; else the set stays, and a vertex of it no longer between faces
        keeps its last clearance, with no gradient. Returns the cells that changed (all ranks)."""
        nodal = self._nodal(lam)
        held = ~self.between
        nodal[held] = self.last[held]
        self.last = nodal
        at_cells = self.nodes.at_vertices(nodal)
        full = np.all(np.isfinite(at_cells), axis=1)
        cells = full if decide else self.cells
        values = np.where(cells, np.where(cells[:, None], at_cells, 0.0).mean(axis=1), np.inf)
        g = self.normals.sum(axis=1)  # d c_i / d x_i
        gradient = np.stack([self.nodes.at_vertices(g[:, k]) for k in range(3)], axis=2)
        gradient = np.where(cells[:, None, None], gradient, 0.0)
        turn = self.turn.reshape(-1, 9)  # d^2 c_i / d x_i^2
        curvature = np.stack([self.nodes.at_vertices(turn[:, k]) for k in range(9)], axis=2)
        curvature = np.where(cells[:, None, None], curvature, 0.0)
        changed = int(np.sum(cells != self.cells))
        self.cells = cells
        self.model.squeeze(values, gradient, curvature)
        return int(self.model.mesh.comm.allreduce(changed, op=MPI.SUM))

    # -- the part's protocol -------------------------------------------------------------------
    def bind(self, driver) -> None:
        self._jump, self._response = fem.Function(self.model.V), fem.Function(self.model.V)  # border_derivative's
        self._squeeze(0.0, decide=True)
        self.committed = self._copy()

    def _copy(self) -> dict:
        return {"between": self.between.copy(), "pair": self.pair.copy(), "normals": self.normals.copy(),
                "cells": self.cells.copy(), "last": self.last.copy()}

    def start(self, lam: float, predicting: bool) -> None:
        if self.committed is None:  # restored: decided at the restored positions
            self._squeeze(lam, decide=True)
            self.committed = self._copy()
        s = self.committed
        self.between, self.pair, self.normals = s["between"].copy(), s["pair"].copy(), s["normals"].copy()
        self.cells, self.last = s["cells"].copy(), s["last"].copy()
        self._squeeze(lam, decide=False)

    def constrain(self, c, lam: float) -> None:
        """No constraint: the set's clearances and their gradients follow this iterate's
        positions (the element's energy depends on them, and its tangent knows it)."""
        self._squeeze(lam, decide=False)

    def _shares(self) -> np.ndarray:
        """Per owned node its share of the pressed cells' face forces at the last evaluation,
        a third of each (N)."""
        return self.nodes.cell_sums(self.model.face_forces() / 3.0)[:, 0]

    def bounds(self) -> np.ndarray:
        """The owned nodes whose faces lie at the half clearance, c_i / 2 < h_i (half_thickness),
        at the last iterate's positions."""
        return self.bounded

    def derivatives(self) -> str | None:
        """None: the faces' penalty is the element's (its material's modulus, the clearance and
        its gradient moved with the vertices: SheetModel.respond, moved_squeeze), and a node
        whose faces the clearance bounds has the known normal row c_i'/2 (border_derivative)."""
        return None

    def border_derivative(self, key: str, driver, out, dR: np.ndarray, parameter=None) -> bool:
        """A node on a tool whose faces lie at the half clearance has n . x' = c_i'/2 =
        (n_a + n_b) . x'_i / 2 on its known normal row (n its tool's normal), where the faces are
        not parallel a value of the solved x' itself: set from the derivative in `out` (the
        solve's frames), with the free rows' response to that jump (a lifted solve with the
        increment's factors) added. Whether it changed `out` (all ranks alike; the contact set
        gives these rows 0: ContactSet.known_derivatives)."""
        push = self.normals.sum(axis=1)  # d c_i / d x_i
        inclined = np.flatnonzero(self.bounded & self.contact.on_tools() & (np.abs(push).max(axis=1) > 0.0))
        if not self.model.mesh.comm.allreduce(inclined.size, op=MPI.SUM):
            return False
        dx = driver.to_xyz(out.x.array).reshape(-1, BS)[inclined, :3]
        rows = BS * inclined + 2
        jump = self._jump.x.array
        jump[:] = 0.0
        jump[rows] = 0.5 * np.einsum("ni,ni->n", push[inclined], dx) - out.x.array[rows]
        self._jump.x.scatter_forward()
        if not driver.solve_lifted(jump, self._response):
            raise RuntimeError("the ironed nodes' known rows failed in a sensitivity solve")
        out.x.array[:] += self._response.x.array
        return True

    def update(self, lam: float, changes: int) -> Change:
        n = self._squeeze(lam, decide=True)
        return Change(changes=n, line=f"ironing: {n} cells between faces changed" if n else "")

    def commit(self, lam: float) -> None:
        self.committed = self._copy()

    def restore(self, state: dict, lam_scale: float) -> None:
        self.committed = None  # decided again from the restored positions at the first start

    def face_force(self, tool: int) -> np.ndarray:
        """The push of `tool`'s face on the nodes it presses between faces (x, y, z; N), all ranks:
        each node's share along that face's normal (the elements' force on their vertices)."""
        share = np.where(self.between, self._shares(), 0.0)
        push = sum((np.where((self.pair[:, k] == tool)[:, None], share[:, None] * self.normals[:, k], 0.0)
                    for k in range(2)), np.zeros((share.size, 3)))
        return self.model.mesh.comm.allreduce(push.sum(axis=0), op=MPI.SUM)

    def report(self) -> dict:
        comm = self.model.mesh.comm
        pressed = comm.allreduce(int(self.cells.sum()), op=MPI.SUM)
        push = comm.allreduce(float(np.where(self.between, self._shares(), 0.0).sum()), op=MPI.SUM)
        return {"ironed_cells": pressed, "ironing_push": push}
