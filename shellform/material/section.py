"""Through-thickness integration of a shell section: stress resultants and their tangent.

Layer strain e(z) = em + z k, z = zeta h, zeta in [-1/2, 1/2]; em = (e11, e22, g12) membrane
strain, k = (k11, k22, 2 k12) curvature, h the lever arm: the current thickness (t at small
strain; with finite strains t / J, the thickness of a sheet that keeps its volume, J the
mid-surface's area stretch at the iterate: incompressible_lever). With the Gauss rule
(zeta_i, w_i), sum w_i = 1, and t the initial thickness (the layers' volume per unit blank area):

    N = t sum w s,   M = t sum w z s,
    D = [[A, B], [B, Dd]],  A = t sum w Dt,  B = t sum w z Dt,  Dd = t sum w z^2 Dt,

and, where h follows em, D[:, :3] += dS/dh (x) dh/dem (section_response's dlever).

Why t / J and not the layers' own mean stretch lambda3 = exp(sum w e33): a lever read from the
layers is known only after they are evaluated, so it has to lag (one increment, as it did), and
on a strongly bent cell the layers' mean e33 of the linear-in-z strain e = em + z k grows with
the lever itself (ln(1 + 2 e) is concave: bending alone reads as a mean compression, hence
thickening). The lag then made each increment start out of balance by what the lever moved
(docs/cup.md, "The step bounds tried"). t / J is a function of the iterate, exact for a
plastically incompressible membrane, and its tangent is closed-form.

s the layer's stress conjugate to e (S of Green-Lagrange; with finite strains P^T T from the
logarithmic-space stress T), Dt its consistent tangent. nz >= 2 points integrate the elastic
section exactly.
"""

import numpy as np

from shellform.errors import InputError
from shellform.material.layout import E_, NU_
from shellform.material import hencky
from shellform.material.plane_stress import return_core, thickness_strain
from shellform import _jit as jit


def through_thickness_rule(nz: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre points zeta in (-1/2, 1/2) (fractions of thickness), weights summing to 1."""
    if isinstance(nz, bool) or not isinstance(nz, (int, np.integer)) or nz < 2:
        raise InputError("process.thickness_points", f"must be an integer >= 2, got {nz!r}")
    x, w = np.polynomial.legendre.leggauss(int(nz))
    return 0.5 * x, 0.5 * w


@jit.njit
def _layer(e, ep_n, p_n, mat, finite, elastic_tangent, s, Dt, ep_new, p_w, w):
    """One layer at section strain e = (E11, E22, 2 E12): stress s conjugate to e, tangent Dt,
    new plastic strain; returns (p_new, status, e33). w: scratch, rows 0 to 2 (16 each). ep_new and p_w hold
    the layer's last solution on entry (the return map's warm start, plane_stress.return_core).
    Small strain: the return mapping on e. Finite strain: on the Hencky strain eps(e), then
    s = P^T T and Dt = P^T (dT/deps) P + L(T) (shellform.material.hencky). e33 is the layer's
    thickness strain, logarithmic when finite. elastic_tangent: dT/deps is the elastic C
    (the unloading predictor)."""
    eps, W = w[0, :3], w[1]
    P = w[2, :9].reshape((3, 3))
    if finite:
        if not hencky.log_strain(e, eps, P, W):
            return p_n, -1, 0.0
    else:
        eps[0], eps[1], eps[2] = e[0], e[1], e[2]
    (t0, t1, t2, d00, d01, d02, d11, d12, d22, q0, q1, q2, p, st) = return_core(
        eps[0], eps[1], eps[2], ep_n[0], ep_n[1], ep_n[2], p_n, mat, ep_new[0], ep_new[1], ep_new[2], p_w)
    ep_new[0], ep_new[1], ep_new[2] = q0, q1, q2
    nu = mat[NU_]
    if elastic_tangent:
        cE = mat[E_] / (1.0 - nu * nu)
        d00, d01, d02, d11, d12, d22 = cE, cE * nu, 0.0, cE, 0.0, 0.5 * cE * (1.0 - nu)
    if finite:
        T = w[0, 3:6]
        T[0], T[1], T[2] = t0, t1, t2
        hencky.second_order(T, e[2], W, Dt)  # Dt = L(T), then + P^T Dl P
        for a in range(3):
            s[a] = P[0, a] * t0 + P[1, a] * t1 + P[2, a] * t2
            y0 = d00 * P[0, a] + d01 * P[1, a] + d02 * P[2, a]  # (Dl P)[:, a]
            y1 = d01 * P[0, a] + d11 * P[1, a] + d12 * P[2, a]
            y2 = d02 * P[0, a] + d12 * P[1, a] + d22 * P[2, a]
            for b in range(3):
                Dt[b, a] += P[0, b] * y0 + P[1, b] * y1 + P[2, b] * y2
    else:
        s[0], s[1], s[2] = t0, t1, t2
        Dt[0, 0], Dt[0, 1], Dt[0, 2] = d00, d01, d02
        Dt[1, 0], Dt[1, 1], Dt[1, 2] = d01, d11, d12
        Dt[2, 0], Dt[2, 1], Dt[2, 2] = d02, d12, d22
    return p, st, thickness_strain(eps, ep_new, mat)


@jit.njit
def incompressible_lever(em, t, dlever):
    """The lever arm of a sheet that keeps its volume: h = t / J, J = sqrt(det(I + 2E)) the
    mid-surface's area stretch, E = (e11, e22, g12 / 2) the membrane strain em; writes
    dh/dem into dlever (3). Returns t (and dlever = 0) where I + 2E is not positive definite:
    no stretch gives such a strain, and the layers' own return mapping refuses it."""
    c11, c22, c12 = 1.0 + 2.0 * em[0], 1.0 + 2.0 * em[1], em[2]
    det = c11 * c22 - c12 * c12
    if c11 <= 0.0 or det <= 0.0:
        dlever[0] = dlever[1] = dlever[2] = 0.0
        return t
    J = np.sqrt(det)
    h = t / J
    f = -h / det  # dh/d(det) = -h / (2 det), d(det)/dem = (2 c22, 2 c11, -2 c12)
    dlever[0], dlever[1], dlever[2] = f * c22, f * c11, -f * c12
    return h


@jit.njit
def section_response(em, k, t, lever, zeta, wz, ep_n, p_n, mat, finite, elastic_tangent,
                     S, D, ep_new, p_new, w=None, dlever=None):
    """Resultants S = (N, M) (6) and section tangent D (6x6) of the layered section of initial
    thickness t whose layers sit at z = zeta * lever (lever: the current thickness, t at small
    strain); writes the layers' new plastic strains ep_new (nz, 3) and p_new (nz,). On entry
    these hold the layers' last solution in this increment, the return map's warm start (or
    ep_n, p_n, or zeros: a cold start). w: scratch (4, 16), allocated here if None. dlever:
    the lever's derivative in em where it follows the membrane strain (incompressible_lever);
    D then carries its term, dS/dem += dS/dh (x) dh/dem with dN/dh = t sum w Dt zeta k and
    dM/dh = t sum w zeta (s + z Dt zeta k), which makes D unsymmetric.
    Returns (number of plastic layers or -1 if any layer failed, mean thickness strain)."""
    for i in range(6):
        S[i] = 0.0
        for j in range(6):
            D[i, j] = 0.0
    nplastic = 0
    failed = False
    e33 = 0.0
    if w is None:
        w = np.zeros((4, 16))
    s, e = w[3, :3], w[3, 3:6]
    Dt = w[3, 6:15].reshape((3, 3))
    follows = dlever is not None
    dS = w[2, 9:15]  # dS/dh
    if follows:
        for a in range(6):
            dS[a] = 0.0
    for i in range(zeta.shape[0]):
        z = zeta[i] * lever
        for a in range(3):
            e[a] = em[a] + z * k[a]
        p, st, e33_i = _layer(e, ep_n[i], p_n[i], mat, finite, elastic_tangent, s, Dt, ep_new[i], p_new[i], w)
        p_new[i] = p
        e33 += wz[i] * e33_i
        if st < 0:
            failed = True
        elif st == 1:
            nplastic += 1
        c0 = t * wz[i]  # layer volume per unit initial area: the initial thickness
        for a in range(3):
            S[a] += c0 * s[a]
            S[3 + a] += c0 * z * s[a]
            for b in range(3):
                D[a, b] += c0 * Dt[a, b]
                D[a, 3 + b] += c0 * z * Dt[a, b]
                D[3 + a, 3 + b] += c0 * z * z * Dt[a, b]
        if follows:
            for a in range(3):
                de = 0.0
                for b in range(3):
                    de += Dt[a, b] * zeta[i] * k[b]
                dS[a] += c0 * de
                dS[3 + a] += c0 * (zeta[i] * s[a] + z * de)
    for a in range(3):
        for b in range(3):
            D[3 + a, b] = D[b, 3 + a]
    if follows:
        for a in range(6):
            for b in range(3):
                D[a, b] += dS[a] * dlever[b]
    return (-1 if failed else nplastic), e33


@jit.njit
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
