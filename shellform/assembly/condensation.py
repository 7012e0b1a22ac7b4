"""Elimination of the element-local fields: the paper's B = N A^-1 C (eqs. 21-23).

The second variation of pi_g on one element, in the blocks of (q, eps, lam), has the structure

        q    eps   lam
    q [ Kqq   0    C^T ]      H   = d2 U / d eps2           (strain energy of the assumed strains)
  eps [  0    H    -G  ]      G   = int phi_lam : phi_eps   (Gram matrix, SPD)
  lam [  C   -G     0  ]      C   = d2 (pi_a - pi_b) / d lam dq  (string-net boundary + interior)

because eps enters only through U(eps) - lam : eps and lam only linearly. Eliminating lam and eps:

    eps = G^-1 C q = B q,        K = Kqq + B^T H B,        lam = G^-1 H eps.

No saddle-point solve is needed. On an affine triangle with constant material, G and H are the
reference cell's blocks times |det J| (the assumed strains and multipliers are the same
polynomials on every cell). Then

    K = C^T X C / |det J|,   X = G_ref^-1 H_ref G_ref^-1 = L L^T  (once per mesh; Kqq = 0)

and only C, the string-net and interior coupling of the multipliers to the nodal values,
is tabulated per cell (``scaled_condensed_matrix``).
"""

import numpy as np
from shellform import _jit as jit


@jit.njit
def cholesky(A):
    """Lower-triangular L with L L^T = A (A SPD, small)."""
    n = A.shape[0]
    L = np.zeros((n, n))
    for j in range(n):
        s = A[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        L[j, j] = np.sqrt(s)
        for i in range(j + 1, n):
            s = A[i, j]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            L[i, j] = s / L[j, j]
    return L


@jit.njit
def cholesky_solve(L, X):
    """X <- (L L^T)^-1 X, column by column, in place."""
    n = L.shape[0]
    for c in range(X.shape[1]):
        for i in range(n):
            s = X[i, c]
            for k in range(i):
                s -= L[i, k] * X[k, c]
            X[i, c] = s / L[i, i]
        for i in range(n - 1, -1, -1):
            s = X[i, c]
            for k in range(i + 1, n):
                s -= L[k, i] * X[k, c]
            X[i, c] = s / L[i, i]


@jit.njit
def reference_operators(G, H):
    """(L, G^-1, G^-1 H) of the reference cell's blocks, L L^T = G^-1 H G^-1."""
    n = G.shape[0]
    Ginv = np.eye(n)
    cholesky_solve(cholesky(G), Ginv)
    R = Ginv @ H
    X = R @ Ginv
    return cholesky(0.5 * (X + X.T)), Ginv, R


@jit.njit
def scaled_condensed_matrix(C, L, det, cols, coef, K):
    """K = T^T C^T (L L^T) C T / det in the carrier values (T: the slope map, its rows given by
    cols and coef as in slope_map); K is overwritten."""
    ne, nq = C.shape
    nc = K.shape[0]
    CT = np.zeros((ne, nc))
    for r in range(nq):
        for k in range(cols.shape[1]):
            col = cols[r, k]
            if col >= 0:
                v = coef[r, k]
                for i in range(ne):
                    CT[i, col] += C[i, r] * v
    Y = np.zeros((ne, nc))  # L^T C T
    for i in range(ne):
        for k in range(i, ne):
            lk = L[k, i]
            if lk != 0.0:
                for j in range(nc):
                    Y[i, j] += lk * CT[k, j]
    s = 1.0 / det
    for a in range(nc):
        for b in range(a, nc):
            v = 0.0
            for i in range(ne):
                v += Y[i, a] * Y[i, b]
            K[a, b] = v * s
            K[b, a] = v * s
