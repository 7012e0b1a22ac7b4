"""Hill 1979 plane-stress plasticity with planar isotropy: yield function, return map, tangent.

Voigt vectors: stress s = (s11, s22, s12) (tensor shear), conjugate to e = (e11, e22, g12) with
engineering shear g12 = 2 e12, so s . e is the work. Plane-stress isotropic elasticity:

    C = E/(1-nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1-nu)/2]].

Yield function, principal stresses s1, s2:  |s1+s2|^m + (1+2r)|s1-s2|^m = 2(1+r) sigma_bar^m.
With the invariants u = s11 + s22 and rho = sqrt(((s11-s22)/2)^2 + s12^2) (s1 - s2 = 2 rho):

    sigma_bar = [(|u|^m + (1+2r) 2^m rho^m) / (2(1+r))]^(1/m),

homogeneous of degree 1 and convex for m >= 1; its gradient a = d sigma_bar/ds is the plastic
flow direction in (e11, e22, g12) and s . a = sigma_bar (Euler).

Regularisation. |u| and rho are replaced by

    |u| -> sqrt(u^2 + eps^2 rho^2),   rho -> sqrt(rho^2 + eps^2 u^2),   eps = 1e-12,

i.e. each gets an offset of 1e-12 times the other invariant. Both remain norms of linear maps of
s, so sigma_bar stays exactly homogeneous of degree 1 and convex, and it is smooth away from
s = 0: m < 2 gives no inf/NaN at u = 0 or rho = 0 (the curvature there is large, ~eps^(m-2),
but finite). The change of sigma_bar^m is below eps^m <= 1e-12 relative for 1 <= m < 2 and
below m eps^2 / 2 ~ 1e-24 (below rounding) for m >= 2.
"""

import math


from shellform.material import E_, LAW_, LAW_ELASTIC, M_, NU_, R_
from shellform.material.hardening import flow_stress
from shellform import _jit as jit

EPS2 = 1.0e-24  # eps^2 of the regularisation above
TOL = 1.0e-12  # local Newton: residual (scaled by the flow stress) relative to 1 + |e_trial|/eps_y
STEPTOL = 1.0e-13  # ... or the Newton correction of (s/sigma_f, E dlambda/sigma_f) below this
MAXIT = 300
MAXLS = 40


@jit.njit
def _invariants(s0, s1, s2):
    """u = s11 + s22, q = rho^2 and the regularised X = u^2 + eps^2 q, Y = q + eps^2 u^2, X + Y."""
    u = s0 + s1
    d = 0.5 * (s0 - s1)
    q = d * d + s2 * s2
    X = u * u + EPS2 * q
    Y = q + EPS2 * u * u
    return u, q, X, Y, X + Y


@jit.njit
def _sbar(s0, s1, s2, r, m):
    """sigma_bar (value only), scaled by sqrt(u^2 + rho^2) to avoid overflow at large m."""
    u, q, X, Y, S2 = _invariants(s0, s1, s2)
    if not S2 > 0.0:
        return 0.0
    x, y = X / S2, Y / S2
    if m == 2.0:  # Hill 1948's normal anisotropy: no powers
        return math.sqrt(S2 * (x + (1.0 + 2.0 * r) * 4.0 * y) / (2.0 * (1.0 + r)))
    return math.sqrt(S2) * ((x ** (0.5 * m) + (1.0 + 2.0 * r) * 2.0**m * y ** (0.5 * m))
                            / (2.0 * (1.0 + r))) ** (1.0 / m)


@jit.njit
def _hill(s0, s1, s2, r, m):
    """sigma_bar, gradient (a0, a1, a2) and Hessian (h00, h01, h02, h11, h12, h22).

    sigma_bar = phi(X, Y), X = ubar^2 = u^2 + eps^2 q, Y = rbar^2 = q + eps^2 u^2, q = rho^2:
      phi_X = alpha X^(m/2-1) phi^(1-m) / 2,  phi_Y = alpha c Y^(m/2-1) phi^(1-m) / 2,
      phi_XX = (1-m) phi_X^2/phi + (m/2-1) phi_X/X,  phi_XY = (1-m) phi_X phi_Y/phi, (Y alike),
    alpha = 1/(2(1+r)), c = (1+2r) 2^m; then a = phi_X X' + phi_Y Y' and
    Hess = phi_XX X'X'^T + phi_YY Y'Y'^T + phi_XY (X'Y'^T + Y'X'^T) + phi_X X'' + phi_Y Y''.
    At s = 0 everything is returned as 0.
    """
    u, q, X, Y, S2 = _invariants(s0, s1, s2)
    d = 0.5 * (s0 - s1)
    if not S2 > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    S = math.sqrt(S2)
    x = max(X / S2, 1e-200)
    y = max(Y / S2, 1e-200)
    X, Y = x * S2, y * S2
    hm = 0.5 * m
    alpha = 0.5 / (1.0 + r)
    if m == 2.0:  # Hill 1948's normal anisotropy: phi = sqrt(alpha (x + 4 (1 + 2r) y)), no powers
        c = (1.0 + 2.0 * r) * 4.0
        xa, yb = x, y
        ph = math.sqrt(alpha * (xa + c * yb))
        g = 1.0 / (ph * 2.0 * S)
    else:
        c = (1.0 + 2.0 * r) * 2.0**m
        xa = x**hm
        yb = y**hm
        ph = (alpha * (xa + c * yb)) ** (1.0 / m)
        g = ph ** (1.0 - m) / (2.0 * S)
    sb = S * ph
    fX = alpha * (xa / x) * g
    fY = alpha * c * (yb / y) * g
    fXX = (1.0 - m) * fX * fX / sb + (hm - 1.0) * fX / X
    fYY = (1.0 - m) * fY * fY / sb + (hm - 1.0) * fY / Y
    fXY = (1.0 - m) * fX * fY / sb
    # X' = 2u (1,1,0) + eps^2 (d, -d, 2 s12);  Y' = (d, -d, 2 s12) + 2 eps^2 u (1,1,0)
    X0, X1, X2 = 2.0 * u + EPS2 * d, 2.0 * u - EPS2 * d, 2.0 * EPS2 * s2
    Y0, Y1, Y2 = d + 2.0 * EPS2 * u, -d + 2.0 * EPS2 * u, 2.0 * s2
    a0 = fX * X0 + fY * Y0
    a1 = fX * X1 + fY * Y1
    a2 = fX * X2 + fY * Y2
    # X'' = 2 (1,1,0)(1,1,0)^T + eps^2 Q,  Y'' = Q + 2 eps^2 (1,1,0)(1,1,0)^T,
    # Q = q'' = [[1/2, -1/2, 0], [-1/2, 1/2, 0], [0, 0, 2]]
    dd00 = fX * (2.0 + 0.5 * EPS2) + fY * (0.5 + 2.0 * EPS2)
    dd01 = fX * (2.0 - 0.5 * EPS2) + fY * (-0.5 + 2.0 * EPS2)
    dd22 = fX * 2.0 * EPS2 + fY * 2.0
    h00 = fXX * X0 * X0 + fYY * Y0 * Y0 + 2.0 * fXY * X0 * Y0 + dd00
    h01 = fXX * X0 * X1 + fYY * Y0 * Y1 + fXY * (X0 * Y1 + Y0 * X1) + dd01
    h02 = fXX * X0 * X2 + fYY * Y0 * Y2 + fXY * (X0 * Y2 + Y0 * X2)
    h11 = fXX * X1 * X1 + fYY * Y1 * Y1 + 2.0 * fXY * X1 * Y1 + dd00
    h12 = fXX * X1 * X2 + fYY * Y1 * Y2 + fXY * (X1 * Y2 + Y1 * X2)
    h22 = fXX * X2 * X2 + fYY * Y2 * Y2 + 2.0 * fXY * X2 * Y2 + dd22
    return sb, a0, a1, a2, h00, h01, h02, h11, h12, h22


@jit.njit
def equivalent_stress(s, r, m):
    """sigma_bar(s) of Hill 1979 (planar isotropy), s = (s11, s22, s12)."""
    return _sbar(s[0], s[1], s[2], r, m)


@jit.njit
def yield_derivatives(s, r, m, a, H):
    """sigma_bar(s); writes a = d sigma_bar/ds (3) and H = d^2 sigma_bar/ds^2 (3x3)."""
    sb, a0, a1, a2, h00, h01, h02, h11, h12, h22 = _hill(s[0], s[1], s[2], r, m)
    a[0], a[1], a[2] = a0, a1, a2
    H[0, 0], H[0, 1], H[0, 2] = h00, h01, h02
    H[1, 0], H[1, 1], H[1, 2] = h01, h11, h12
    H[2, 0], H[2, 1], H[2, 2] = h02, h12, h22
    return sb


@jit.njit
def _inv3(a00, a01, a02, a11, a12, a22):
    """Inverse of a symmetric 3x3 matrix (upper triangle in, upper triangle out), cofactors."""
    c00 = a11 * a22 - a12 * a12
    c01 = a02 * a12 - a01 * a22
    c02 = a01 * a12 - a02 * a11
    c11 = a00 * a22 - a02 * a02
    c12 = a01 * a02 - a00 * a12
    c22 = a00 * a11 - a01 * a01
    det = a00 * c00 + a01 * c01 + a02 * c02
    return c00 / det, c01 / det, c02 / det, c11 / det, c12 / det, c22 / det


@jit.njit
def _residual(s0, s1, s2, mu, g0, g1, g2, p_n, k, mat):
    """Scaled closest-point residual at (s^ = s/k, mu = E dlambda / k):

    R_s = E C^-1 s^ + mu a(s^) - E (e - ep_n)/k,   R_f = sigma_bar(s^) - sigma_f(p_n + k mu/E)/k.
    Returns (|R|, R0, R1, R2, Rf, derivatives of sigma_bar ..., hardening slope).
    """
    E, nu, r, m = mat[E_], mat[NU_], mat[R_], mat[M_]
    sb, a0, a1, a2, h00, h01, h02, h11, h12, h22 = _hill(s0, s1, s2, r, m)
    R0 = s0 - nu * s1 + mu * a0 - g0
    R1 = s1 - nu * s0 + mu * a1 - g1
    R2 = 2.0 * (1.0 + nu) * s2 + mu * a2 - g2
    sf, hs = flow_stress(p_n + k * mu / E, mat)
    Rf = sb - sf / k
    Rn = math.sqrt(R0 * R0 + R1 * R1 + R2 * R2 + Rf * Rf)
    return Rn, R0, R1, R2, Rf, a0, a1, a2, h00, h01, h02, h11, h12, h22, hs


@jit.njit
def _return_core(e0, e1, e2, q0, q1, q2, p_n, mat, w0=0.0, w1=0.0, w2=0.0, p_w=-1.0):
    """Return map on scalars. Returns (s0, s1, s2, D00, D01, D02, D11, D12, D22, ep0, ep1, ep2,
    p_new, status); on failure (status -1) the elastic trial state.

    (w0, w1, w2, p_w): a warm start, the plastic strain and p of this point's last solution in
    the same increment (Newton's last iterate); used where it flowed (p_w > p_n). The local
    Newton then starts from s = C (e - ep_w), dlambda = p_w - p_n, the exact solution if the
    plastic strain did not change since (what it saves: docs/performance.md). Where it does not
    converge the radial start is tried."""
    E, nu, r, m = mat[E_], mat[NU_], mat[R_], mat[M_]
    ee0, ee1, ee2 = e0 - q0, e1 - q1, e2 - q2
    cE = E / (1.0 - nu * nu)
    C00, C01, C22 = cE, cE * nu, 0.5 * cE * (1.0 - nu)
    t0 = C00 * ee0 + C01 * ee1
    t1 = C01 * ee0 + C00 * ee1
    t2 = C22 * ee2
    elastic = (t0, t1, t2, C00, C01, 0.0, C00, 0.0, C22, q0, q1, q2, p_n)
    if int(mat[LAW_]) == LAW_ELASTIC:
        return elastic + (0,)
    k, _ = flow_stress(p_n, mat)
    sbt = _sbar(t0, t1, t2, r, m)
    if not sbt > k:
        if math.isfinite(sbt):
            return elastic + (0,)
        return elastic + (-1,)
    g0, g1, g2 = ee0 * E / k, ee1 * E / k, ee2 * E / k
    if p_w > p_n:  # warm: scaled s^ = C (e - ep_w) / k, mu = E dlambda / k
        v0, v1, v2 = e0 - w0, e1 - w1, e2 - w2
        res = _local_newton((C00 * v0 + C01 * v1) / k, (C01 * v0 + C00 * v1) / k, C22 * v2 / k,
                            E * (p_w - p_n) / k, g0, g1, g2, p_n, k, mat)
        if res[0]:
            return _closed(res, e0, e1, e2, p_n, k, mat, elastic)
    # scaled unknowns: s^ = s/k from the trial stress put radially onto the yield surface
    s0, s1, s2 = t0 / sbt, t1 / sbt, t2 / sbt
    _, a0, a1, a2, _, _, _, _, _, _ = _hill(s0, s1, s2, r, m)
    v0 = g0 - (s0 - nu * s1)
    v1 = g1 - (s1 - nu * s0)
    v2 = g2 - 2.0 * (1.0 + nu) * s2
    mu = max(0.0, (a0 * v0 + a1 * v1 + a2 * v2) / (a0 * a0 + a1 * a1 + a2 * a2))
    res = _local_newton(s0, s1, s2, mu, g0, g1, g2, p_n, k, mat)
    if not res[0]:
        return elastic + (-1,)
    return _closed(res, e0, e1, e2, p_n, k, mat, elastic)


@jit.njit
def _local_newton(s0, s1, s2, mu, g0, g1, g2, p_n, k, mat):
    """The closest-point equations in scaled unknowns (s^, mu) by Newton with a line search on
    |R| from the given start. Returns (converged, s0, s1, s2, mu, a0, a1, a2, h00, h01, h02,
    h11, h12, h22, hs) at the last iterate."""
    E, nu = mat[E_], mat[NU_]
    tol = TOL * (1.0 + math.sqrt(g0 * g0 + g1 * g1 + g2 * g2))
    Rn, R0, R1, R2, Rf, a0, a1, a2, h00, h01, h02, h11, h12, h22, hs = _residual(
        s0, s1, s2, mu, g0, g1, g2, p_n, k, mat)
    c22 = 2.0 * (1.0 + nu)
    ok = False
    for _ in range(MAXIT):
        if Rn <= tol:
            ok = True
            break
        # Newton: [[E C^-1 + mu H, a], [a^T, -H'/E]] (ds, dmu) = -(R_s, R_f), by Schur complement
        i00, i01, i02, i11, i12, i22 = _inv3(1.0 + mu * h00, -nu + mu * h01, mu * h02,
                                             1.0 + mu * h11, mu * h12, c22 + mu * h22)
        v0 = i00 * a0 + i01 * a1 + i02 * a2
        v1 = i01 * a0 + i11 * a1 + i12 * a2
        v2 = i02 * a0 + i12 * a1 + i22 * a2
        w0 = i00 * R0 + i01 * R1 + i02 * R2
        w1 = i01 * R0 + i11 * R1 + i12 * R2
        w2 = i02 * R0 + i12 * R1 + i22 * R2
        dmu = (Rf - (a0 * w0 + a1 * w1 + a2 * w2)) / (a0 * v0 + a1 * v1 + a2 * v2 + hs / E)
        d0, d1, d2 = -(w0 + v0 * dmu), -(w1 + v1 * dmu), -(w2 + v2 * dmu)
        if (max(abs(d0), abs(d1), abs(d2)) <= STEPTOL * max(1.0, abs(s0), abs(s1), abs(s2))
                and abs(dmu) <= STEPTOL * (1.0 + mu)):
            ok = True  # unknowns converged to rounding (residual stuck at a near-vertex, m ~ 1)
            break
        # backtracking line search on |R| (quadratic model, step cut to [0.1, 0.5] per trial)
        alpha = 1.0
        accepted = False
        for _ in range(MAXLS):
            res = _residual(s0 + alpha * d0, s1 + alpha * d1, s2 + alpha * d2,
                            max(mu + alpha * dmu, 0.0), g0, g1, g2, p_n, k, mat)
            if res[0] <= (1.0 - 1e-4 * alpha) * Rn:
                accepted = True
                break
            if math.isfinite(res[0]):
                den = res[0] * res[0] - Rn * Rn + 2.0 * alpha * Rn * Rn
                trial = alpha * alpha * Rn * Rn / den if den > 0.0 else 0.5 * alpha
                alpha = min(max(trial, 0.1 * alpha), 0.5 * alpha)
            else:
                alpha *= 0.1
        if not accepted:
            ok = Rn <= 1e2 * tol  # stagnated at rounding level
            break
        s0, s1, s2 = s0 + alpha * d0, s1 + alpha * d1, s2 + alpha * d2
        mu = max(mu + alpha * dmu, 0.0)
        Rn, R0, R1, R2, Rf, a0, a1, a2, h00, h01, h02, h11, h12, h22, hs = res
    else:
        ok = Rn <= tol
    return ok, s0, s1, s2, mu, a0, a1, a2, h00, h01, h02, h11, h12, h22, hs


@jit.njit
def _closed(res, e0, e1, e2, p_n, k, mat, elastic):
    """The outputs of _return_core from a converged local Newton `res` (status 1), or the
    elastic trial state with status -1 where any is not finite."""
    E, nu = mat[E_], mat[NU_]
    c22 = 2.0 * (1.0 + nu)
    _, s0, s1, s2, mu, a0, a1, a2, h00, h01, h02, h11, h12, h22, hs = res
    # consistent tangent D = E [X - (X a)(X a)^T / (a^T X a + H'/E)], X = (E C^-1 + mu H)^-1
    i00, i01, i02, i11, i12, i22 = _inv3(1.0 + mu * h00, -nu + mu * h01, mu * h02,
                                         1.0 + mu * h11, mu * h12, c22 + mu * h22)
    v0 = i00 * a0 + i01 * a1 + i02 * a2
    v1 = i01 * a0 + i11 * a1 + i12 * a2
    v2 = i02 * a0 + i12 * a1 + i22 * a2
    f = 1.0 / (a0 * v0 + a1 * v1 + a2 * v2 + hs / E)
    dl = k * mu / E
    out = (k * s0, k * s1, k * s2,
           E * (i00 - f * v0 * v0), E * (i01 - f * v0 * v1), E * (i02 - f * v0 * v2),
           E * (i11 - f * v1 * v1), E * (i12 - f * v1 * v2), E * (i22 - f * v2 * v2),
           e0 - (s0 - nu * s1) * k / E, e1 - (s1 - nu * s0) * k / E, e2 - c22 * s2 * k / E,
           p_n + dl)
    for x in out:
        if not math.isfinite(x):
            return elastic + (-1,)
    return out + (1,)


@jit.njit
def return_map(e, ep_n, p_n, mat, s_out, D_out, ep_out):
    """Closest-point projection (backward Euler, associated flow) for the total strain e.

    Solves  C^-1 s + dlambda a(s) = e - ep_n,  sigma_bar(s) = sigma_f(p_n + dlambda)
    by Newton with line search (stresses scaled by sigma_f(p_n), started from the trial stress
    scaled radially onto the yield surface); dep = dlambda a(s), dp = dlambda.
    Writes s_out (3), the consistent tangent D_out = ds/de (3x3),
        D = Xi - (Xi a)(Xi a)^T / (a^T Xi a + H'),  Xi = (C^-1 + dlambda Hess)^-1,
    and ep_out = e - C^-1 s (= ep_n + dlambda a(s) at convergence; exact elastic consistency
    also where the flow direction is resolved only to rounding, near a vertex of m ~ 1).
    Converged: residual below TOL or Newton correction below STEPTOL. Returns (p_new, status):
    0 elastic, 1 plastic, -1 local Newton failed (then the outputs hold the elastic trial
    state, all finite). m -> 1 is the non-smooth limit (cone with an apex and an edge): there
    the local Newton may fail; m >= 1.2 converged on all sampled states.
    """
    (s0, s1, s2, D00, D01, D02, D11, D12, D22, q0, q1, q2, p, st) = _return_core(
        e[0], e[1], e[2], ep_n[0], ep_n[1], ep_n[2], p_n, mat)
    s_out[0], s_out[1], s_out[2] = s0, s1, s2
    D_out[0, 0], D_out[0, 1], D_out[0, 2] = D00, D01, D02
    D_out[1, 0], D_out[1, 1], D_out[1, 2] = D01, D11, D12
    D_out[2, 0], D_out[2, 1], D_out[2, 2] = D02, D12, D22
    ep_out[0], ep_out[1], ep_out[2] = q0, q1, q2
    return p, st


@jit.njit
def thickness_strain(e, ep, mat):
    """e33 = -(ep11 + ep22) - nu/(1-nu) ((e11 - ep11) + (e22 - ep22)):
    plastic incompressibility plus the plane-stress elastic part."""
    nu = mat[NU_]
    return -(ep[0] + ep[1]) - nu / (1.0 - nu) * ((e[0] - ep[0]) + (e[1] - ep[1]))
