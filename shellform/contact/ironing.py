"""Ironing in a drawn part: where two tools face each other across the sheet closer than its
thickness, their faces bound it (shellform.material.ironing). A part of the contact.

A node on tool A (the contact set's: its normal row is known, the semi-inverse split) whose other
face lies within a quarter of the thickness of a tool B that faces A (their normals opposite
within 60 degrees) is *between faces*. There the clearance is the distance between the two
tools' surfaces through the node,

    c_i = 2 h_i + g_B,i            (h_i its half thickness, g_B,i the gap of its B-side face to B),

and a cell whose three nodes are between faces gets the mean of their clearances
(SheetModel.squeeze): its sections' thickness is bounded by it, and where the sheet is thicker
the faces press it with p. The bound is one-sided, so a cell whose sheet is thinner than its
clearance is in the set at no cost: the band keeps a cell that the faces have just pressed
thinner from leaving the set and thickening back into it in the next pass. The set is decided
after every converged pass from the pass's positions, as the contact set's is, and only grows
within an increment (a cell drawn out from between the faces leaves it at the next); its
changes count as the parts' changes, and the driver runs another pass on the new set. Within a
pass the set's clearances follow every iterate's positions, with their gradients dc_i/dx_i =
n_B (SheetModel.squeeze): the element's energy depends on the vertices' positions through them,
and its force and tangent carry that (shellform.material.ironing).

So B presses each node between faces with its share of the cells' face forces F_i (a third of
each cell's int p dA, SheetModel.face_forces) along B's normal, a force of the element on its
vertices. A, whose normal row is known, takes the balance in its reaction, so each tool's force
on the sheet includes its face's pressure (face_force). Where the faces are parallel (the punch's wall and the die's,
the holder at a gap over the die's top) the two forces cancel on the node and only the thickness
feels them; where B is inclined to A (the die's shoulder over the punch's wall) the push has a
component along the sheet that resists the draw. Friction on B's face is not modelled: the
friction part sees A's normal force (docs/contact.md, "Ironing").
"""

import numpy as np
from mpi4py import MPI

from shellform.contact.contact_set import FREE
from shellform.nonlinear.parts import Change, Part

FACING = -0.5  # A and B face each other where n_A . n_B is below this (60 degrees from opposite)
BAND = 0.25  # a node is between faces while its other face lies within this many thicknesses of B


class Ironing(Part):
    """The faces' bound on the sheet's thickness between two tools (module docstring): model, the
    SheetModel it squeezes; nodes, its SheetNodes; contact, the ContactSet whose tools and
    nodes on them it reads."""

    def __init__(self, model, nodes, contact):
        self.model, self.nodes, self.contact = model, nodes, contact
        n = nodes.n_owned
        self.between = np.zeros(n, dtype=bool)  # the owned nodes between faces
        self.facing = np.full(n, FREE, dtype=np.int8)  # the tool B facing each of them
        self.normal = np.zeros((n, 3))  # B's normal there (towards the sheet)
        self.cells = np.zeros(model.num_cells, dtype=bool)  # the cells pressed
        self.committed = None

    def _nodal(self, lam: float) -> np.ndarray:
        """The owned nodes' clearances c_i at the current positions (inf where a node is not
        between faces); sets their facing tool and its normal."""
        c = self.contact
        x = self.nodes.positions()
        h = self.nodes.half_thickness
        gaps = c.gaps(x, lam)
        on = c.tool
        clearance = np.full(x.shape[0], np.inf)
        facing = np.full(x.shape[0], FREE, dtype=np.int8)
        normal = np.zeros((x.shape[0], 3))
        for a, (_, na) in enumerate(gaps):
            at = on == a
            if not at.any():
                continue
            for b, (gb, nb) in enumerate(gaps):
                if b == a:
                    continue
                near = at & np.isfinite(gb) & (gb <= BAND * 2.0 * h)
                near &= np.einsum("ij,ij->i", na, nb) < FACING
                cb = 2.0 * h + gb
                tighter = near & (cb < clearance)
                clearance[tighter], facing[tighter], normal[tighter] = cb[tighter], b, nb[tighter]
        self.between, self.facing, self.normal = np.isfinite(clearance), facing, normal
        return clearance

    def _squeeze(self, lam: float, decide: bool, grow: bool = False) -> int:
        """The cells' clearances at the current positions: the mean of their nodes' where all three
        are between faces. With `decide`, the set of cells is decided anew (with `grow` it keeps the
        cells it had); else the set stays and only its clearances follow the positions (a cell
        whose nodes are no longer all between faces keeps its last one). Returns the cells that
        changed (all ranks)."""
        at_cells = self.nodes.at_vertices(self._nodal(lam))
        normals = np.stack([self.nodes.at_vertices(self.normal[:, a]) for a in range(3)], axis=2)
        full = np.all(np.isfinite(at_cells), axis=1)
        values = np.where(full, np.where(full[:, None], at_cells, 0.0).mean(axis=1), np.inf)
        cells = (full | self.cells) if grow else full if decide else self.cells
        kept = cells & ~full  # in the set, a vertex no longer between faces: held where it was
        values = np.where(kept, self.model.clearance, values)
        values[~cells] = np.inf
        gradient = np.where((cells & full)[:, None, None], normals, 0.0)
        changed = int(np.sum(cells != self.cells))
        self.cells = cells
        self.model.squeeze(values, gradient)
        return int(self.model.mesh.comm.allreduce(changed, op=MPI.SUM))

    # -- the part's protocol -------------------------------------------------------------------
    def bind(self, driver) -> None:
        self._squeeze(0.0, decide=True)
        self.committed = self._copy()

    def _copy(self) -> dict:
        return {"between": self.between.copy(), "facing": self.facing.copy(), "normal": self.normal.copy(),
                "cells": self.cells.copy(), "clearance": self.model.clearance.copy()}

    def start(self, lam: float, predicting: bool) -> None:
        if self.committed is None:  # restored: decided at the restored positions
            self._squeeze(lam, decide=True)
            self.committed = self._copy()
        s = self.committed
        self.between, self.facing, self.normal = s["between"].copy(), s["facing"].copy(), s["normal"].copy()
        self.cells = s["cells"].copy()
        self.model.squeeze(s["clearance"])

    def constrain(self, c, lam: float) -> None:
        """No constraint: the set's clearances and their gradients follow this iterate's
        positions (the element's energy depends on them, and its tangent knows it)."""
        self._squeeze(lam, decide=False)

    def pushes(self) -> np.ndarray:
        """B's push on each owned node at the last evaluation (x, y, z; N): the elements' force on
        their vertices, a third of each pressed cell's face force along the clearance's gradient
        there (zero on a cell held in the set whose vertices are no longer all between faces)."""
        m = self.model
        share = m.face_forces()[:, None, None] / 3.0 * m.ironed[:, 2:].reshape(-1, 3, 3)
        return self.nodes.cell_sums(share[:, :, 0], share[:, :, 1], share[:, :, 2])

    def update(self, lam: float, changes: int) -> Change:
        n = self._squeeze(lam, decide=True, grow=True)
        return Change(changes=n, line=f"ironing: {n} cells between faces changed" if n else "")

    def commit(self, lam: float) -> None:
        self.committed = self._copy()

    def restore(self, state: dict, lam_scale: float) -> None:
        self.committed = None  # decided again from the restored positions at the first start

    def face_force(self, tool: int) -> np.ndarray:
        """The push of `tool`'s face on the nodes it presses between faces (x, y, z; N), all ranks."""
        on = self.between & (self.facing == tool)
        return self.model.mesh.comm.allreduce(self.pushes()[on].sum(axis=0), op=MPI.SUM)

    def report(self) -> dict:
        comm = self.model.mesh.comm
        pressed = comm.allreduce(int(self.cells.sum()), op=MPI.SUM)
        push = comm.allreduce(float(np.linalg.norm(self.pushes(), axis=1).sum()), op=MPI.SUM)
        return {"ironed_cells": pressed, "ironing_push": push}
