"""The return mapping of a plane-stress layer, written once for every yield function.

Voigt vectors: stress s = (s11, s22, s12) (tensor shear), conjugate to e = (e11, e22, g12) with
engineering shear g12 = 2 e12, so s . e is the work. Plane-stress isotropic elasticity:

    C = E/(1-nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1-nu)/2]].

The yield function sigma_bar(s) (homogeneous of degree 1, convex), its gradient a and Hessian
come from shellform.material.criteria.yield_function, which dispatches on the packed
material's criterion id to the criterion's own file. Backward Euler, associated flow, closest
point: solve for (s, dlambda)

    C^-1 s + dlambda a(s) = e - ep_n,   sigma_bar(s) = sigma_f(p_n + dlambda),

dep = dlambda a(s), dp = dlambda (sigma_bar of degree 1: sigma_bar dp = s . dep). The
consistent tangent is D = Xi - (Xi a)(Xi a)^T / (a^T Xi a + H'), Xi = (C^-1 + dlambda Hess)^-1.

Anisotropy axes. A planar-anisotropic criterion is stated in the axes of the rolling direction
(1 = rolling, 2 = transverse). Strains and plastic strains are stored in the blank's x, y axes;
where the rolling direction is turned by theta from x, ``return_core`` turns the strain, the
committed and the warm-start plastic strain into the rolling axes (e' = Q e), maps there, and
turns the results back: s = Q^T s', D = Q^T D' Q, ep = Q^-1 ep' (elasticity is isotropic, so
only the yield function sees the turn). The strains are those of the total-Lagrangian
formulation over the flat blank's axes, so the axes are material directions: they follow the
sheet through any rigid rotation (docs/material.md).
"""

import math


from shellform.material.layout import COS_, E_, LAW_, LAW_ELASTIC, NU_, ROTATED_, SIN_
from shellform.material.criteria import yield_function
from shellform.material.hardening import flow_stress
from shellform import _jit as jit

TOL = 1.0e-12  # local Newton: residual (scaled by the flow stress) relative to 1 + |e_trial|/eps_y
STEPTOL = 1.0e-13  # ... or the Newton correction of (s/sigma_f, E dlambda/sigma_f) below this
MAXIT = 300
MAXLS = 40


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
    E, nu = mat[E_], mat[NU_]
    sb, a0, a1, a2, h00, h01, h02, h11, h12, h22 = yield_function(s0, s1, s2, mat, 2)
    R0 = s0 - nu * s1 + mu * a0 - g0
    R1 = s1 - nu * s0 + mu * a1 - g1
    R2 = 2.0 * (1.0 + nu) * s2 + mu * a2 - g2
    sf, hs = flow_stress(p_n + k * mu / E, mat)
    Rf = sb - sf / k
    Rn = math.sqrt(R0 * R0 + R1 * R1 + R2 * R2 + Rf * Rf)
    return Rn, R0, R1, R2, Rf, a0, a1, a2, h00, h01, h02, h11, h12, h22, hs


@jit.njit
def _return_in_axes(e0, e1, e2, q0, q1, q2, p_n, mat, w0, w1, w2, p_w):
    """Return map on scalars. Returns (s0, s1, s2, D00, D01, D02, D11, D12, D22, ep0, ep1, ep2,
    p_new, status); on failure (status -1) the elastic trial state.

    (w0, w1, w2, p_w): a warm start, the plastic strain and p of this point's last solution in
    the same increment (Newton's last iterate); used where it flowed (p_w > p_n). The local
    Newton then starts from s = C (e - ep_w), dlambda = p_w - p_n, the exact solution if the
    plastic strain did not change since (what it saves: docs/performance.md). Where it does not
    converge the radial start is tried."""
    E, nu = mat[E_], mat[NU_]
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
    sbt = yield_function(t0, t1, t2, mat, 0)[0]
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
    _, a0, a1, a2, _, _, _, _, _, _ = yield_function(s0, s1, s2, mat, 1)
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
    """The outputs of _return_in_axes from a converged local Newton `res` (status 1), or the
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
def _strain_to_axes(c, s, x0, x1, x2):
    """e' = Q e: the strain (engineering shear) in axes turned by theta (c = cos, s = sin)."""
    cc, ss, cs = c * c, s * s, c * s
    return (cc * x0 + ss * x1 + cs * x2, ss * x0 + cc * x1 - cs * x2,
            2.0 * cs * (x1 - x0) + (cc - ss) * x2)


@jit.njit
def _stress_from_axes(c, s, y0, y1, y2):
    """s = Q^T s': the stress (tensor shear) in the x, y axes from the turned axes."""
    cc, ss, cs = c * c, s * s, c * s
    return (cc * y0 + ss * y1 - 2.0 * cs * y2, ss * y0 + cc * y1 + 2.0 * cs * y2,
            cs * (y0 - y1) + (cc - ss) * y2)


@jit.njit
def return_core(e0, e1, e2, q0, q1, q2, p_n, mat, w0=0.0, w1=0.0, w2=0.0, p_w=-1.0):
    """Return map on scalars in the x, y axes. Returns (s0, s1, s2, D00, D01, D02, D11, D12,
    D22, ep0, ep1, ep2, p_new, status); on failure (status -1) the elastic trial state.

    (w0, w1, w2, p_w): a warm start, the plastic strain and p of this point's last solution in
    the same increment (Newton's last iterate); used where it flowed (p_w > p_n). The local
    Newton then starts from s = C (e - ep_w), dlambda = p_w - p_n, the exact solution if the
    plastic strain did not change since (what it saves: docs/performance.md). Where it does not
    converge the radial start is tried. With a turned rolling direction the map runs in its
    axes (module docstring)."""
    if mat[ROTATED_] == 0.0:
        return _return_in_axes(e0, e1, e2, q0, q1, q2, p_n, mat, w0, w1, w2, p_w)
    c, s = mat[COS_], mat[SIN_]
    e0, e1, e2 = _strain_to_axes(c, s, e0, e1, e2)
    q0, q1, q2 = _strain_to_axes(c, s, q0, q1, q2)
    w0, w1, w2 = _strain_to_axes(c, s, w0, w1, w2)
    (t0, t1, t2, d00, d01, d02, d11, d12, d22, r0, r1, r2, p, st) = _return_in_axes(
        e0, e1, e2, q0, q1, q2, p_n, mat, w0, w1, w2, p_w)
    t0, t1, t2 = _stress_from_axes(c, s, t0, t1, t2)
    r0, r1, r2 = _strain_to_axes(c, -s, r0, r1, r2)
    # D = Q^T D' Q, column by column: D' Q[:, j] then Q^T of it
    cc, ss, cs = c * c, s * s, c * s
    x00, x01, x02 = _stress_from_axes(c, s, d00 * cc + d01 * ss - 2.0 * cs * d02,
                                      d01 * cc + d11 * ss - 2.0 * cs * d12, d02 * cc + d12 * ss - 2.0 * cs * d22)
    x10, x11, x12 = _stress_from_axes(c, s, d00 * ss + d01 * cc + 2.0 * cs * d02,
                                      d01 * ss + d11 * cc + 2.0 * cs * d12, d02 * ss + d12 * cc + 2.0 * cs * d22)
    x20, x21, x22 = _stress_from_axes(c, s, cs * (d00 - d01) + (cc - ss) * d02,
                                      cs * (d01 - d11) + (cc - ss) * d12, cs * (d02 - d12) + (cc - ss) * d22)
    return (t0, t1, t2, x00, 0.5 * (x01 + x10), 0.5 * (x02 + x20), x11, 0.5 * (x12 + x21), x22,
            r0, r1, r2, p, st)


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
    # no warm start, its arguments given as the section gives them (one compiled signature)
    (s0, s1, s2, D00, D01, D02, D11, D12, D22, q0, q1, q2, p, st) = return_core(
        e[0], e[1], e[2], ep_n[0], ep_n[1], ep_n[2], p_n, mat, 0.0, 0.0, 0.0, -1.0)
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
