"""Elimination of the element-local fields: the paper's B = N A^-1 C (eqs. 21-23).

The second variation of pi_g on one element, in the blocks of (q, eps, lam), has the structure

        q    eps   lam
    q [ Kqq   0    C^T ]      H   = d2 U / d eps2           (strain energy of the assumed strains)
  eps [  0    H    -G  ]      G   = int phi_lam : phi_eps   (Gram matrix, SPD)
  lam [  C   -G     0  ]      C   = d2 (pi_a - pi_b) / d lam dq  (string-net boundary + interior)

because eps enters only through U(eps) - lam : eps and lam only linearly. Eliminating lam and eps:

    eps = G^-1 C q = B q,        K = Kqq + B^T H B,        lam = G^-1 H eps.

G is factored once per cell (Cholesky); no saddle-point solve is needed.
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
def blocks(Az, iq, ie, il):
    """G, C, H, Kqq from the element matrix of the mixed reference element."""
    ne, nq = ie.size, iq.size
    G = np.empty((ne, ne))
    H = np.empty((ne, ne))
    C = np.empty((ne, nq))
    Kqq = np.empty((nq, nq))
    for i in range(ne):
        for j in range(ne):
            G[i, j] = -Az[il[i], ie[j]]
            H[i, j] = Az[ie[i], ie[j]]
        for j in range(nq):
            C[i, j] = Az[il[i], iq[j]]
    for i in range(nq):
        for j in range(nq):
            Kqq[i, j] = Az[iq[i], iq[j]]
    return G, C, H, Kqq


@jit.njit
def strain_operator(Az, iq, ie, il):
    """B = G^-1 C (assumed-strain coefficients per reference nodal dof) and H."""
    G, C, H, Kqq = blocks(Az, iq, ie, il)
    cholesky_solve(cholesky(G), C)
    return C, H, Kqq


@jit.njit
def condensed_matrix(Az, iq, ie, il):
    """K_ref = Kqq + B^T H B."""
    B, H, K = strain_operator(Az, iq, ie, il)
    ne, nq = B.shape
    HB = np.zeros((ne, nq))
    for i in range(ne):
        for k in range(ne):
            h = H[i, k]
            if h != 0.0:
                for j in range(nq):
                    HB[i, j] += h * B[k, j]
    for i in range(nq):
        for k in range(ne):
            b = B[k, i]
            if b != 0.0:
                for j in range(nq):
                    K[i, j] += b * HB[k, j]
    return K


@jit.njit
def recover(Az, iq, ie, il, q_ref):
    """Assumed strains eps = B q and multipliers lam = G^-1 H eps of one element."""
    G, C, H, _ = blocks(Az, iq, ie, il)
    L = cholesky(G)
    ne = ie.size
    x = np.zeros((ne, 2))
    for i in range(ne):
        for j in range(iq.size):
            x[i, 0] += C[i, j] * q_ref[j]
    cholesky_solve(L, x[:, 0:1])
    for i in range(ne):
        for k in range(ne):
            x[i, 1] += H[i, k] * x[k, 0]
    cholesky_solve(L, x[:, 1:2])
    return x[:, 0].copy(), x[:, 1].copy()
