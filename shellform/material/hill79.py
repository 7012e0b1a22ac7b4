"""Hill 1979 with planar isotropy (the paper's criterion): sigma_bar(s), gradient, Hessian.

Parameters (packed at PAR_): r, m. Principal stresses s1, s2:

    |s1+s2|^m + (1+2r)|s1-s2|^m = 2(1+r) sigma_bar^m.

With the invariants u = s11 + s22 and rho = sqrt(((s11-s22)/2)^2 + s12^2) (s1 - s2 = 2 rho):

    sigma_bar = [(|u|^m + (1+2r) 2^m rho^m) / (2(1+r))]^(1/m),

homogeneous of degree 1 and convex for m >= 1; its gradient a = d sigma_bar/ds is the plastic
flow direction in (e11, e22, g12) and s . a = sigma_bar (Euler). Planar isotropic: the rolling
direction does not change it.

Regularisation. |u| and rho are replaced by

    |u| -> sqrt(u^2 + eps^2 rho^2),   rho -> sqrt(rho^2 + eps^2 u^2),   eps = 1e-12,

i.e. each gets an offset of 1e-12 times the other invariant. Both remain norms of linear maps of
s, so sigma_bar stays exactly homogeneous of degree 1 and convex, and it is smooth away from
s = 0: m < 2 gives no inf/NaN at u = 0 or rho = 0 (the curvature there is large, ~eps^(m-2),
but finite). The change of sigma_bar^m is below eps^m <= 1e-12 relative for 1 <= m < 2 and
below m eps^2 / 2 ~ 1e-24 (below rounding) for m >= 2.
"""

import math


from shellform.material.layout import PAR_, number, require
from shellform import _jit as jit

NAME = "hill79"
PARAMETERS = ("r", "m")  # its scene keys (material.r, material.m)
PLANAR_ISOTROPIC = True  # the rolling direction changes nothing: the map need not turn
EPS2 = 1.0e-24  # eps^2 of the regularisation above


def parameters(values: dict) -> list[float]:
    """[r, m] from the material's r (> 0) and m (>= 1); InputError names the field."""
    r, m = number("material.r", values.get("r", 1.0)), number("material.m", values.get("m", 2.0))
    require(r > 0.0, "material.r", f"must be positive, got {r}")
    require(m >= 1.0, "material.m", f"must be >= 1 (convex yield function), got {m}")
    return [r, m]


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


@jit.njit(inline="always")
def yield_function(s0, s1, s2, mat, order):
    """sigma_bar (order 0: the rest zero) or sigma_bar, gradient (3) and Hessian (h00, h01, h02,
    h11, h12, h22) for the packed material (shellform.material.criteria)."""
    if order == 0:
        return _sbar(s0, s1, s2, mat[PAR_], mat[PAR_ + 1]), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    return _hill(s0, s1, s2, mat[PAR_], mat[PAR_ + 1])
