"""Nodal frames of the semi-inverse split: the displacement of a node on a tool, seen along the
tool's normal and two tangents.

A node in contact gets the orthonormal frame F (rows: slot 0, slot 1, slot 2 = n, the tool
normal); its displacement components (u, v, w) are replaced by (F d)_k, so that the normal
component becomes a single degree of freedom that can be prescribed. The element arrays rotate
as  f' = T f,  K' = T K T^T  with T = diag(F, 1, ..., 1) on the node's block (the slopes are not
rotated). The tangents are chosen so that a symmetry plane keeps its meaning: where n_x = 0
(a node on x = 0) slot 0 is e_x, where n_y = 0 (a node on y = 0) slot 1 is e_y; so a symmetry
condition u = 0 or v = 0 stays a condition on one rotated slot.
"""

import numpy as np

from shellform.assembly.sheet_element import BS
from shellform import _jit as jit


def nodal_frames(normals: np.ndarray) -> np.ndarray:
    """(N, 3, 3) frames, rows (t0, t1, n), for unit normals (N, 3)."""
    n = np.asarray(normals, dtype=np.float64)
    F = np.zeros((n.shape[0], 3, 3))
    F[:, 2] = n
    ey_side = np.abs(n[:, 1]) <= np.abs(n[:, 0])  # project e_y (slot 1), else e_x (slot 0)
    e = np.zeros_like(n)
    e[ey_side, 1] = 1.0
    e[~ey_side, 0] = 1.0
    t = e - np.sum(e * n, axis=1)[:, None] * n
    t /= np.linalg.norm(t, axis=1)[:, None]
    other = np.cross(t, n)  # with t = proj(e_y): slot 0 = t x n; with t = proj(e_x): slot 1 = -(t x n)
    F[ey_side, 1], F[ey_side, 0] = t[ey_side], other[ey_side]
    F[~ey_side, 0], F[~ey_side, 1] = t[~ey_side], -other[~ey_side]
    # a right-handed frame with slot 0 along +x where it can be
    flip = F[:, 0, 0] < 0
    F[flip, 0] *= -1.0
    F[flip, 1] *= -1.0
    return F


@jit.njit
def rotate_cell_arrays(dofs, rotated, frames, vectors, matrices, tangent):
    """In place, for every cell: f' = T f, K' = T K T^T on the blocks flagged in `rotated`."""
    ncells, nv = dofs.shape
    tmp = np.zeros(3)
    for c in range(ncells):
        for a in range(nv):
            b = dofs[c, a]
            if not rotated[b]:
                continue
            F = frames[b]
            r0 = BS * a
            for i in range(3):
                tmp[i] = F[i, 0] * vectors[c, r0] + F[i, 1] * vectors[c, r0 + 1] + F[i, 2] * vectors[c, r0 + 2]
            for i in range(3):
                vectors[c, r0 + i] = tmp[i]
            if not tangent:
                continue
            n = matrices.shape[1]
            for j in range(n):  # rows: F K[rows, :]
                for i in range(3):
                    tmp[i] = (F[i, 0] * matrices[c, r0, j] + F[i, 1] * matrices[c, r0 + 1, j]
                              + F[i, 2] * matrices[c, r0 + 2, j])
                for i in range(3):
                    matrices[c, r0 + i, j] = tmp[i]
            for j in range(n):  # columns: K[:, cols] F^T
                for i in range(3):
                    tmp[i] = (matrices[c, j, r0] * F[i, 0] + matrices[c, j, r0 + 1] * F[i, 1]
                              + matrices[c, j, r0 + 2] * F[i, 2])
                for i in range(3):
                    matrices[c, j, r0 + i] = tmp[i]


def from_frames(array: np.ndarray, rotated: np.ndarray, frames: np.ndarray) -> None:
    """In place: F (u, v, w) -> (u, v, w) = F^T (rotated values) on the rotated blocks."""
    d = array.reshape(-1, BS)
    idx = np.flatnonzero(rotated[: d.shape[0]])
    d[idx, :3] = np.einsum("nji,nj->ni", frames[idx], d[idx, :3])


def subtract_nodal_forces(R3: np.ndarray, frames: np.ndarray, force: np.ndarray) -> None:
    """R -= f on the owned nodes' u, v, w rows R3, f (x, y, z) seen in their frames: F f."""
    R3 -= np.einsum("nij,nj->ni", frames, force)


def add_tangent_slot_stiffness(K, rate: np.ndarray) -> None:
    """K += rate, (n, 2, 2) blocks on the owned nodes' tangent slots (0, 1), where non-zero."""
    b = np.flatnonzero(np.abs(rate).max(axis=(1, 2)) > 0)
    if b.size:
        rows = (BS * b[:, None] + np.arange(2)).astype(np.int32)
        K.setValuesLocalRCV(rows, rows, rate[b].reshape(b.size, 4), addv=True)
