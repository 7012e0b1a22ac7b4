"""The blank seen from its nodes, as the contact parts need it.

Reference positions X, the current positions x = X + (u, v, w) of the carrier, the positions
x_n at the start of the increment (slip is measured from them), each node's tributary area
A_i (a third of each cell around it), its local cell size h_i = sqrt(2 a_i) (a_i the
area-weighted mean area of the cells around it: a right triangle's legs, 0.93 of an equilateral
one's side) and half thickness h_i = t/2 exp(e33_i) (e33 recovered at the node from the thickness
strains of the cells around it, `recover`, updated with every converged increment: the sheet's
surface is h_i from its mid-surface) with its plan gradient grad h_i (the area-weighted
mean of the cells' gradients of its linear interpolant, in the reference plan: the slopes of a
mid-surface whose lower surface lies on a flat face), and the carrier slots a symmetry plane holds.
A part of its own: it commits and checkpoints x_n and h_i.

A node *held flat* between two faces (hold_flat: the holder's pinch) takes h_i and grad h_i from
the cells around it that lie wholly between the faces, the material the faces hold, where it has
any: at the pinch's edge the cells beyond it bend onto the die's shoulder and thin, and their
average would dip the held node's surface by micrometres over one cell, a curvature ~ dh / h^2
forced on the flat sheet that grows as the mesh is refined (docs/contact.md, "The flange's
thickness at the pinch's edge").

The cells whose every node the faces pinch, w and slopes held, carry the curvature of their
thickness's taper without a moment (SheetModel.follow_taper, at every commit, at the state where
the next increment holds them: on the thickness just updated): their mid-surface curves with h_i
while the material between the faces stays flat.

The recovery is exact for a linear field, at the blank's edge too: there a node's cells lie on
one side, and their mean is the field a third of a cell inside the edge, not at the node. Under the
pinch, whose faces make the mid-surface follow h_i, that lag was a kink of the held flange one
row inside the blank's edge, carried by forces ~ D grad e33 / h that grow as the mesh is refined.
"""

import numpy as np
from dolfinx import fem, la

from shellform.assembly.sheet_element import BS, COMPONENTS
from shellform.nonlinear.parts import Part


W = COMPONENTS.index("w")
W_SLOPES = slice(COMPONENTS.index("w_x"), COMPONENTS.index("w_y") + 1)


class SheetNodes(Part):
    PLANE_SPREAD = 1e-3  # the centroids fix a plane when their offsets' smallest variance passes this (cell sizes^2)

    def __init__(self, model, bcs):
        self.model = model
        V = model.V
        imap = V.dofmap.index_map
        self.n_owned, self.n_local = imap.size_local, imap.size_local + imap.num_ghosts
        self.X = V.tabulate_dof_coordinates()[: self.n_local].copy()
        held = np.zeros(self.n_local * BS, dtype=bool)
        for bc in bcs:
            held[bc.dof_indices()[0]] = True
        self.held = held.reshape(-1, BS)[: self.n_owned]  # carrier slots fixed by symmetry
        x = model.cell_coords.reshape(-1, 3, 3)[:, :, :2]
        self._edges = np.stack([x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]], axis=1)  # rows: the edges from vertex 0
        self._cell_area = 0.5 * np.abs(np.linalg.det(self._edges))
        sums = self.cell_sums(self._cell_area / 3, self._cell_area**2 / 3)
        self.area, self.cell_size = sums[:, 0], np.sqrt(2.0 * sums[:, 1] / sums[:, 0])
        # (cells, 3, 2): each cell's centroid from each of its vertices, in the vertex's cell sizes (recover)
        self._centroid_offsets = (x.mean(axis=1)[:, None, :] - x) / self.at_vertices(self.cell_size)[..., None]
        self.flat, self.pinched = np.zeros(self.n_owned, dtype=bool), np.zeros(self.n_owned, dtype=bool)
        self._set_thickness()
        self.q = None
        self.x_n = self.X[: self.n_owned].copy()

    def bind(self, driver) -> None:
        self.q = driver.q

    def positions(self) -> np.ndarray:
        """Current positions of the owned nodes."""
        d = self.q.x.array.reshape(-1, BS)[: self.n_owned, :3]
        return self.X[: self.n_owned] + d

    def local_positions(self) -> np.ndarray:
        """Current positions of the owned and ghost nodes."""
        return self.X + self.q.x.array.reshape(-1, BS)[: self.n_local, :3]

    def slopes(self) -> np.ndarray:
        """(n_owned, 2) the slopes (w_x, w_y) of the owned nodes."""
        return self.q.x.array.reshape(-1, BS)[: self.n_owned, W_SLOPES]

    def cell_sums(self, *values) -> np.ndarray:
        """(n_owned, len(values)): per node the sum over the cells around it of each array in
        `values`, per cell or per cell and vertex (cells, 3) (all ranks' cells)."""
        f = fem.Function(self.model.V)
        arr = f.x.array.reshape(-1, BS)
        for col, v in enumerate(values):
            v = np.asarray(v, dtype=float)
            np.add.at(arr[:, col], self.model.dofs.ravel(), (v if v.ndim == 2 else np.repeat(v[:, None], 3, axis=1)).ravel())
        f.x.scatter_reverse(la.InsertMode.add)
        return arr[: self.n_owned, : len(values)].copy()

    def at_vertices(self, values: np.ndarray) -> np.ndarray:
        """(cells, 3): the owned nodes' `values` at each cell's vertices (ghosts' from their owners)."""
        f = fem.Function(self.model.V)
        arr = f.x.array.reshape(-1, BS)
        arr[: self.n_owned, 0] = values
        f.x.scatter_forward()
        return arr[:, 0][self.model.dofs.reshape(-1, 3)]

    def hold_flat(self, held: np.ndarray, pinched: np.ndarray) -> None:
        """The owned nodes held flat between two faces (module docstring), and those of them whose
        w the faces hold too (`pinched`: their cells' taper is followed); their surface follows
        at the next commit."""
        self.flat = np.asarray(held, dtype=bool).copy()
        self.pinched = np.asarray(pinched, dtype=bool) & self.flat

    def current_area(self, positions: np.ndarray | None = None) -> np.ndarray:
        """(n_owned,): a third of the current plan area of each cell around each node (or of
        the plan area with the owned nodes at `positions`, the ghosts at their owners')."""
        if positions is None:
            x = self.local_positions()[:, :2][self.model.dofs.reshape(-1, 3)]
        else:
            x = np.stack([self.at_vertices(positions[:, 0]), self.at_vertices(positions[:, 1])], axis=-1)
        e1, e2 = x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]
        a = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        return self.cell_sums(a / 3)[:, 0]

    def spread(self, values: np.ndarray) -> np.ndarray:
        """(n_owned,): the area-weighted mean over the cells around each node of the spread
        (largest minus smallest) of the owned nodes' `values` over the cell's vertices: of a
        distance to a line, the spacing of the rows of nodes along it."""
        v = self.at_vertices(values)
        sums = self.cell_sums(self._cell_area * (v.max(axis=1) - v.min(axis=1)), self._cell_area)
        return sums[:, 0] / sums[:, 1]

    def _within(self, region: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """((cells, 3), (cells,)): which vertices of each cell are in `region` (a mask of the
        owned nodes), and which cells lie wholly in it."""
        inside = self.at_vertices(np.asarray(region, dtype=float)) > 0.5
        return inside, inside.all(axis=1)

    def interior(self, region: np.ndarray) -> np.ndarray:
        """The owned nodes of `region` (a mask) whose cells all lie wholly in it: the region less
        its boundary, the nodes with a cell that reaches outside."""
        inside, whole = self._within(region)
        reaches_out = inside & ~whole[:, None]
        return np.asarray(region, dtype=bool) & ~(self.cell_sums(reaches_out.astype(float))[:, 0] > 0.0)

    def _weights(self) -> np.ndarray:
        """(cells, 3): the area with which each cell counts at each of its vertices: its area,
        but 0 at a node held flat when the cell does not lie wholly between the faces and the
        node has a cell that does."""
        held, between = self._within(self.flat)
        a = np.repeat(self._cell_area[:, None], 3, axis=1)
        inner = self.cell_sums(np.where(between[:, None], a, 0.0))[:, 0] > 0.0
        keep = ~(held & ~between[:, None] & (self.at_vertices(inner.astype(float)) > 0.5))
        return np.where(keep, a, 0.0)

    def _set_thickness(self, half: np.ndarray | None = None) -> None:
        """The half thickness (given, or t/2 exp(e33) with e33 recovered from the thickness
        strains of the cells around each node, weighted by _weights) and the slopes of a
        mid-surface a half thickness above a flat face."""
        m, w = self.model, self._weights()
        if half is None and not m.plastic:
            half = np.full(self.n_owned, 0.5 * m.thickness)
        elif half is None:
            half = 0.5 * m.thickness * np.exp(self.recover(m.thickness_strain(), w))
        self.half_thickness = half
        self.surface_slopes = self.gradient(half, w)

    def derivatives(self) -> str | None:
        """The nodes' positions and thicknesses are read, not solved for: nothing to add (the
        parts that hold nodes on them give those rows' derivatives: known_derivatives)."""
        return None

    def half_thickness_derivative(self, de33: np.ndarray) -> np.ndarray:
        """(n_owned,): d/dp of the half thickness of the committed state, given de33 = d/dp of
        the cells' thickness strains: h = t/2 exp(recover(e33)) and recover is linear, so
        h' = h recover(e33') with the same weights (0 for an elastic sheet, whose h is t/2)."""
        if not self.model.plastic:
            return np.zeros(self.n_owned)
        return self.half_thickness * self.recover(de33, self._weights())

    def surface_slopes_derivative(self, de33: np.ndarray) -> np.ndarray:
        """(n_owned, 2): d/dp of surface_slopes of the committed state, the gradient of the half
        thickness's derivative (half_thickness_derivative) with the same weights."""
        return self.gradient(self.half_thickness_derivative(de33), self._weights())

    def recover(self, values: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
        """(n_owned,): a per-cell field at the nodes, exact for a linear field: at each node the
        value at the node of the plane fitted by weighted least squares to the cells' values at
        their centroids (weights: (cells, 3), default the cells' areas). Where the cells around a
        node do not fix a plane (their centroids nearly on a line), their weighted mean."""
        w = np.repeat(self._cell_area[:, None], 3, axis=1) if weights is None else weights
        d = self._centroid_offsets
        dx, dy, f = d[..., 0], d[..., 1], np.repeat(np.asarray(values, dtype=float)[:, None], 3, axis=1)
        s = self.cell_sums(w, w * dx, w * dy, w * dx * dx, w * dx * dy, w * dy * dy, w * f, w * f * dx, w * f * dy)
        mean = s[:, 6] / s[:, 0]
        M = np.stack([s[:, 0:3], s[:, [1, 3, 4]], s[:, [2, 4, 5]]], axis=1) / s[:, :1, None]
        cov = M[:, 1:, 1:] - M[:, 1:, :1] * M[:, :1, 1:]
        fixed = np.linalg.eigvalsh(cov)[:, 0] > self.PLANE_SPREAD
        out = mean.copy()
        if fixed.any():
            out[fixed] = np.linalg.solve(M[fixed], (s[fixed, 6:9] / s[fixed, :1])[..., None])[:, 0, 0]
        return out

    def gradient(self, values: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
        """(n_owned, 2): the mean over the cells around each node of the plan gradient of the
        linear interpolant of the owned nodes' `values`, weighted by the cells' areas (or by
        `weights`, (cells, 3))."""
        v = self.at_vertices(values)
        g = np.linalg.solve(self._edges, np.stack([v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]], axis=1)[..., None])[..., 0]
        w = np.repeat(self._cell_area[:, None], 3, axis=1) if weights is None else weights
        sums = self.cell_sums(w, w * g[:, 0:1], w * g[:, 1:2])
        return sums[:, 1:] / sums[:, :1]

    def commit(self, lam: float) -> None:
        self.x_n = self.positions()
        if self.model.plastic:
            half, slopes = self.half_thickness, self.surface_slopes
            self._set_thickness()
            held = self.interior(self.pinched)
            ahead = self.q.copy()  # the held nodes where the next increment puts them: on the new thickness
            rows = ahead.x.array.reshape(-1, BS)[: self.n_owned]
            rows[held, W] += (self.half_thickness - half)[held]
            rows[held, W_SLOPES] += (self.surface_slopes - slopes)[held]
            ahead.x.scatter_forward()
            self.model.follow_taper(self._within(held)[1], ahead)

    def checkpoint(self) -> dict:
        return {"nodes": {"contact_x_n": self.x_n, "contact_half_thickness": self.half_thickness,
                          "contact_flat": self.flat}}

    def restore(self, state: dict, lam_scale: float) -> None:
        nodes = state["nodes"]
        self.x_n = nodes["contact_x_n"].copy()
        self.flat = nodes["contact_flat"].astype(bool)
        self._set_thickness(nodes["contact_half_thickness"].copy())
