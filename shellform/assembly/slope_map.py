"""Per-cell map between the physical carrier values and the reference degrees of freedom.

A vertex slope in the carrier is physical, (w_x, w_y); the reduced cubic's slope dofs are
reference derivatives, (dw/dX, dw/dY) = J^T (w_x, w_y) with J = dx/dX of the affine cell map.
So q_ref = T q_carrier with T = blockdiag(1, J^T) on w and the identity elsewhere, and the
element matrix and vector pull back as K = T^T K_ref T, b = T^T b_ref (the matrix inside the
condensation, shellform.assembly.condensation.scaled_condensed_matrix).

T is stored sparsely (hybrid_element.slope_map_tables): row r of q_ref has at most two entries,
columns ``cols[r]`` with coefficients given by ``codes[r]`` (0 none, 1 one, 2 + 2a + b: J[a, b]).
``mapped=False`` replaces J by the identity: what plain DOLFINx does with a Hermite-type element,
kept for the study that shows why the map is needed.
"""

import numpy as np
from shellform import _jit as jit


def cubic_vertex_rows(cols, codes, rows, value_col, slope_cols) -> None:
    """Write one vertex of a reduced cubic into the tables: rows = (value, d/dX, d/dY) rows of
    q_ref, value_col the carrier column of the value, slope_cols = (d/dx, d/dy) columns. The
    reference slopes are d/dX_i = sum_j J[j, i] d/dx_j: code 2 + 2 j + i."""
    cols[rows[0], 0], codes[rows[0], 0] = value_col, 1
    for i in range(2):
        for j in range(2):
            cols[rows[1 + i], j], codes[rows[1 + i], j] = slope_cols[j], 2 + 2 * j + i


@jit.njit
def jacobian(coords):
    """J[a, b] = dx_a/dX_b from coordinate_dofs (3 nodes x 3, flattened) of an affine triangle."""
    J = np.empty((2, 2))
    for a in range(2):
        J[a, 0] = coords[3 + a] - coords[a]
        J[a, 1] = coords[6 + a] - coords[a]
    return J


@jit.njit
def determinant(J):
    return J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]


@jit.njit
def coefficients(J, codes, mapped):
    coef = np.zeros(codes.shape)
    for r in range(codes.shape[0]):
        for k in range(codes.shape[1]):
            c = codes[r, k]
            if c == 1:
                coef[r, k] = 1.0
            elif c >= 2:
                a, b = (c - 2) // 2, (c - 2) % 2
                coef[r, k] = J[a, b] if mapped else (1.0 if a == b else 0.0)
    return coef


@jit.njit
def pull_back_vector(b_ref, cols, coef, b):
    """b += T^T b_ref."""
    for r in range(b_ref.shape[0]):
        for k in range(cols.shape[1]):
            if cols[r, k] >= 0:
                b[cols[r, k]] += coef[r, k] * b_ref[r]


@jit.njit
def push_forward(q_carrier, cols, coef, q_ref):
    """q_ref = T q_carrier."""
    for r in range(q_ref.shape[0]):
        q_ref[r] = 0.0
        for k in range(cols.shape[1]):
            if cols[r, k] >= 0:
                q_ref[r] += coef[r, k] * q_carrier[cols[r, k]]
