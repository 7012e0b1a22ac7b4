"""Through-thickness integration of a shell section: stress resultants and their tangent.

Layer strain e(z) = em + z k, z = zeta t, zeta in [-1/2, 1/2]; em = (e11, e22, g12) membrane
strain, k = (k11, k22, 2 k12) curvature. With the Gauss rule (zeta_i, w_i), sum w_i = 1:

    N = t sum w s,   M = t sum w z s,
    D = [[A, B], [B, Dd]],  A = t sum w Dt,  B = t sum w z Dt,  Dd = t sum w z^2 Dt,

Dt the consistent tangent of the layer. nz >= 2 points integrate the elastic section exactly.
"""

import numpy as np
from numba import njit

from shellform.errors import InputError
from shellform.material import E_, NU_
from shellform.material.hill79 import _return_core


def through_thickness_rule(nz: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre points zeta in (-1/2, 1/2) (fractions of thickness), weights summing to 1."""
    if isinstance(nz, bool) or not isinstance(nz, (int, np.integer)) or nz < 2:
        raise InputError("process.thickness_points", f"must be an integer >= 2, got {nz!r}")
    x, w = np.polynomial.legendre.leggauss(int(nz))
    return 0.5 * x, 0.5 * w


@njit(cache=True)
def section_response(em, k, t, zeta, wz, ep_n, p_n, mat, S, D, ep_new, p_new):
    """Resultants S = (N, M) (6) and section tangent D (6x6) of the layered section; writes the
    layers' new plastic strains ep_new (nz, 3) and p_new (nz,). Returns the number of plastic
    layers, or -1 if any layer's local Newton failed."""
    for i in range(6):
        S[i] = 0.0
        for j in range(6):
            D[i, j] = 0.0
    nplastic = 0
    failed = False
    for i in range(zeta.shape[0]):
        z = zeta[i] * t
        (s0, s1, s2, d00, d01, d02, d11, d12, d22, q0, q1, q2, p, st) = _return_core(
            em[0] + z * k[0], em[1] + z * k[1], em[2] + z * k[2],
            ep_n[i, 0], ep_n[i, 1], ep_n[i, 2], p_n[i], mat)
        ep_new[i, 0], ep_new[i, 1], ep_new[i, 2] = q0, q1, q2
        p_new[i] = p
        if st < 0:
            failed = True
        elif st == 1:
            nplastic += 1
        c0 = t * wz[i]
        c1 = c0 * z
        c2 = c1 * z
        S[0] += c0 * s0
        S[1] += c0 * s1
        S[2] += c0 * s2
        S[3] += c1 * s0
        S[4] += c1 * s1
        S[5] += c1 * s2
        for b, cb in ((0, c0), (3, c1)):  # A and B blocks (upper triangle), B below, then Dd
            D[b + 0, 0] += cb * d00
            D[b + 0, 1] += cb * d01
            D[b + 0, 2] += cb * d02
            D[b + 1, 1] += cb * d11
            D[b + 1, 2] += cb * d12
            D[b + 2, 2] += cb * d22
        D[3, 3] += c2 * d00
        D[3, 4] += c2 * d01
        D[3, 5] += c2 * d02
        D[4, 4] += c2 * d11
        D[4, 5] += c2 * d12
        D[5, 5] += c2 * d22
    # symmetric completion from the upper triangles: A, Dd, B (rows 3..5, cols 0..2), then B^T
    for i in range(3):
        for j in range(i):
            D[i, j] = D[j, i]
            D[3 + i, 3 + j] = D[3 + j, 3 + i]
            D[3 + i, j] = D[3 + j, i]
    for i in range(3):
        for j in range(3):
            D[i, 3 + j] = D[3 + j, i]
    return -1 if failed else nplastic


@njit(cache=True)
def elastic_section(em, k, t, mat, S, D):
    """Closed-form elastic resultants N = t C em, M = t^3/12 C k and D = diag(t C, t^3/12 C)."""
    E, nu = mat[E_], mat[NU_]
    cE = E / (1.0 - nu * nu)
    for i in range(6):
        for j in range(6):
            D[i, j] = 0.0
    for b, f in ((0, t), (3, t**3 / 12.0)):
        D[b, b] = D[b + 1, b + 1] = f * cE
        D[b, b + 1] = D[b + 1, b] = f * cE * nu
        D[b + 2, b + 2] = f * cE * 0.5 * (1.0 - nu)
    for i in range(3):
        S[i] = D[i, 0] * em[0] + D[i, 1] * em[1] + D[i, 2] * em[2]
        S[3 + i] = D[3 + i, 3] * k[0] + D[3 + i, 4] * k[1] + D[3 + i, 5] * k[2]
    return None
