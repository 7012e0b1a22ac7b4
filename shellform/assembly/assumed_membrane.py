"""The sheet's assumed membrane strain: what keeps a thin bent sheet from locking.

A cubic displacement cannot bend without stretching: the Green-Lagrange strain E of a cubic
that follows a circle is a quartic that no choice of nodal values makes vanish, and its membrane
energy, E t times that residue squared, outweighs the bending energy E t^3 kappa^2 once t/h is
small (the roll-up of docs/locking.md locks at t/L = 1e-3). An assumed strain relaxes it: an
independent membrane strain eps^p, constant in each cell, tied to E on the element's boundary,
the string net:

    t_e . eps^p . t_e = (1/|e|) int_e t_e . E . t_e ds        on each edge e (unit tangent t_e)

three equations for the three components of eps^p. The edge stretch t.E.t depends only on the
displacement's trace on the edge, the cubic Hermite curve of its end values and end slopes, so
two neighbours tie their membrane strains to the same number on the edge they share: along a
bent strip one stretch condition per edge remains, which the nodal slopes can meet. For a
homogeneous E the tying returns E (the patch test).

Three strain parameters leave 12 of the cubic's 15 in-plane deformation modes of a cell without
stiffness; a fraction beta of the compatible strain keeps them:

    e^p = (1 - beta) eps^p + beta E,        beta^2 = t^2 / (t^2 + alpha h^2)

(h: the mean longest edge of the mesh's cells, one beta for the mesh: stabilisation), so that
the energy of what the tying removes is weighted by about t^2/h^2, the split Arnold and Brezzi
(Math. Comp. 66, 1997) gave a shell's membrane term: every mode keeps a stiffness of the order
of the bending stiffness at the mesh scale, and a thick sheet (t >> h) gets the compatible
strain back. alpha = 0.3: the roll-up's error at a fixed mesh is proportional to 1/alpha, the
stiffness left to the 12 modes to beta^2 (docs/locking.md).

With eps^p = sum_k A_k E_k (E_k: E at the edge Gauss points, A_k 3 x 3 per cell), the element's
internal work sum_i w_i S_i . e_i gives, with Sbar = sum_i w_i S^p_i (w_i: weights times |det J|)
and B_k = dE/dz at point k:

    force     beta (the usual kernel on S^p) + bending  +  (1 - beta) sum_k B_k^T A_k^T Sbar
    tangent   sum_i w_i Bt_i^T D_i Bt_i,   Bt_i = (1 - beta) sum_k A_k B_k + beta B_i (membrane rows)
              + initial stress: beta S^p and S^b in the usual kernel, and at the edge points
                (1 - beta) sigma_k . d2E_k with sigma_k = A_k^T Sbar, d2E = sym(dG^T DG).
"""

import numpy as np
from mpi4py import MPI

from shellform import _jit as jit
from shellform.assembly import slope_map
from shellform.elements import reduced_cubic

ALPHA = 0.3  # beta^2 = t^2 / (t^2 + ALPHA h^2)
MEMBRANE_ROWS = 3  # e = (E11, E22, 2 E12, K11, K22, 2 K12)
EDGES = ((0, 1), (1, 2), (2, 0))  # reference vertices (0, 0), (1, 0), (0, 1)
_VERTICES = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
_GAUSS = (0.5 - 0.5 * np.sqrt(0.6), 0.5, 0.5 + 0.5 * np.sqrt(0.6))  # Gauss-Legendre on [0, 1]
GAUSS_WEIGHTS = np.array([5.0, 8.0, 5.0]) / 18.0  # exact for the quartic edge stretch of a cubic


def edge_directions() -> np.ndarray:
    """(3, 2): the reference edge vectors, in EDGES order."""
    return np.array([_VERTICES[b] - _VERTICES[a] for a, b in EDGES])


def edge_points() -> np.ndarray:
    """(9, 2): the Gauss points of the three reference edges, edge by edge."""
    return np.array([_VERTICES[a] + s * (_VERTICES[b] - _VERTICES[a]) for a, b in EDGES for s in _GAUSS])


def cubic_gradients() -> np.ndarray:
    """(9 points, 9 dofs, 2): reference gradients of the reduced cubic's basis at the edge points."""
    tab = reduced_cubic.element().tabulate(1, edge_points())  # (derivative, point, dof)
    return np.ascontiguousarray(np.stack([tab[1], tab[2]], axis=-1))


def stabilisation(thickness: float, cell_coords: np.ndarray, comm, alpha: float = ALPHA) -> float:
    """beta from the thickness and h, the mean over the mesh's cells of their longest edge (on
    all ranks). One beta for the whole mesh: with a beta that changed from cell to cell, the
    beta part's edge terms would not cancel between neighbours and a constant stress would not
    be in equilibrium (the patch test)."""
    x = cell_coords.reshape(-1, 3, 3)[:, :, :2]
    longest = np.max(np.linalg.norm(x - np.roll(x, 1, axis=1), axis=2), axis=1)
    total, count = comm.allreduce(float(longest.sum()), op=MPI.SUM), comm.allreduce(longest.size, op=MPI.SUM)
    h = total / count
    return float(np.sqrt(thickness**2 / (thickness**2 + alpha * h**2)))


def tyings(cell_coords: np.ndarray) -> np.ndarray:
    """(cells, 3, 27): every cell's tying matrix A (geometry only: computed once per mesh)."""
    out = np.zeros((cell_coords.shape[0], 3, 27))
    _tyings(np.ascontiguousarray(cell_coords), edge_directions(), out)
    return out


@jit.njit
def _tyings(cell_coords, directions, out):
    for c in range(cell_coords.shape[0]):
        tying(slope_map.jacobian(cell_coords[c]), directions, out[c])


@jit.njit
def tying(J, directions, A):
    """A (3 x 27): eps^p = sum_k A[:, 3k:3k+3] E_k over the 9 edge points (Voigt E11, E22, 2 E12)."""
    M = np.empty((3, 3))
    tau = np.empty((3, 3))
    for e in range(3):
        t0 = J[0, 0] * directions[e, 0] + J[0, 1] * directions[e, 1]
        t1 = J[1, 0] * directions[e, 0] + J[1, 1] * directions[e, 1]
        n2 = t0 * t0 + t1 * t1
        tau[e, 0], tau[e, 1], tau[e, 2] = t0 * t0 / n2, t1 * t1 / n2, t0 * t1 / n2
        M[e, :] = tau[e, :]
    Minv = np.linalg.inv(M)
    A[:, :] = 0.0
    for e in range(3):
        for g in range(3):
            k = 3 * e + g
            for a in range(3):
                for b in range(3):
                    A[a, 3 * k + b] = GAUSS_WEIGHTS[g] * Minv[a, e] * tau[e, b]


@jit.njit
def assumed_strain(E_edge, A, beta, e):
    """e (points x 6): membrane rows (1 - beta) eps^p + beta E, eps^p = sum_k A_k E_edge[k]."""
    eps = np.zeros(MEMBRANE_ROWS)
    for k in range(9):
        for a in range(MEMBRANE_ROWS):
            for b in range(MEMBRANE_ROWS):
                eps[a] += A[a, 3 * k + b] * E_edge[k, b]
    for i in range(e.shape[0]):
        for r in range(MEMBRANE_ROWS):
            e[i, r] = (1.0 - beta) * eps[r] + beta * e[i, r]


@jit.njit
def tied_stress(S, wdet, A, sigma):
    """Sbar = sum_i wdet_i S^p_i and sigma (9 x 3): sigma_k = A_k^T Sbar."""
    nqp = S.shape[0]
    Sbar = np.zeros(MEMBRANE_ROWS)
    for i in range(nqp):
        for r in range(MEMBRANE_ROWS):
            Sbar[r] += wdet[i] * S[i, r]
    for k in range(9):
        for b in range(MEMBRANE_ROWS):
            s = 0.0
            for a in range(MEMBRANE_ROWS):
                s += A[a, 3 * k + b] * Sbar[a]
            sigma[k, b] = s


@jit.njit
def tied_force(Bm, sigma, scale, rz):
    """rz += scale sum_k Bm_k^T sigma_k (Bm: the 9 edge points x 3 membrane rows x nz)."""
    nz = rz.size
    for k in range(9):
        for j in range(nz):
            s = 0.0
            for b in range(MEMBRANE_ROWS):
                s += Bm[k, b, j] * sigma[k, b]
            rz[j] += scale * s


@jit.njit
def material_tangent(B, Bm, A, beta, D, wdet, Kz, Bt, DB):
    """Kz += sum_i wdet_i Bt_i^T D_i Bt_i (B: area points x 6 x nz, Bm: edge points x 3 x nz,
    D: points x 36), as one product Bt^T (blockdiag(wdet_i D_i) Bt) of the stacked rows
    (scratch Bt, DB: 6 points x nz)."""
    nqp, nz = B.shape[0], B.shape[2]
    Beps = np.zeros((MEMBRANE_ROWS, nz))
    for k in range(9):
        for a in range(MEMBRANE_ROWS):
            for b in range(MEMBRANE_ROWS):
                c = A[a, 3 * k + b]
                if c != 0.0:
                    for j in range(nz):
                        Beps[a, j] += c * Bm[k, b, j]
    for i in range(nqp):
        for j in range(nz):
            for r in range(MEMBRANE_ROWS):
                Bt[6 * i + r, j] = (1.0 - beta) * Beps[r, j] + beta * B[i, r, j]
            for r in range(MEMBRANE_ROWS, 6):
                Bt[6 * i + r, j] = B[i, r, j]
        for a in range(6):
            for j in range(nz):
                DB[6 * i + a, j] = 0.0
            for b in range(6):
                d = wdet[i] * D[i, 6 * a + b]
                for j in range(nz):
                    DB[6 * i + a, j] += d * Bt[6 * i + b, j]
    Kz += Bt.T @ DB


@jit.njit
def tied_initial_stress(J, grads, sigma, scale, Kz):
    """Kz += scale sum_k sigma_k . d2E_k over the edge points: for the cubic dofs j, m of one
    displacement component c (z rows 3 j + c), with g = J^-T grad phi,
    sigma11 g_j1 g_m1 + sigma22 g_j2 g_m2 + sigma12 (g_j1 g_m2 + g_j2 g_m1)."""
    det = slope_map.determinant(J)
    g = np.empty((9, 2))
    for k in range(9):
        for j in range(9):  # J^-T grad_X
            gx, gy = grads[k, j, 0], grads[k, j, 1]
            g[j, 0] = (J[1, 1] * gx - J[1, 0] * gy) / det
            g[j, 1] = (-J[0, 1] * gx + J[0, 0] * gy) / det
        s11, s22, s12 = scale * sigma[k, 0], scale * sigma[k, 1], scale * sigma[k, 2]
        for j in range(9):
            for m in range(9):
                v = (s11 * g[j, 0] * g[m, 0] + s22 * g[j, 1] * g[m, 1]
                     + s12 * (g[j, 0] * g[m, 1] + g[j, 1] * g[m, 0]))
                for c in range(3):
                    Kz[3 * j + c, 3 * m + c] += v
