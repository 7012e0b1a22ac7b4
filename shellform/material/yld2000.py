"""Barlat et al.'s Yld2000-2d (Int. J. Plasticity 19 (2003) 1297), plane stress: sigma_bar(s),
gradient, Hessian.

In the axes of the rolling direction, two linear images of the stress s = (s11, s22, s12),

    X' = L' s,   L' = [[2 a1, -a1, 0], [-a2, 2 a2, 0], [0, 0, 3 a7]] / 3,
    X'' = L'' s, L'' = [[-2 a3 + 2 a4 + 8 a5 - 2 a6,  a3 - 4 a4 - 4 a5 + 4 a6, 0],
                        [4 a3 - 4 a4 - 4 a5 + a6,  -2 a3 + 8 a4 + 2 a5 - 2 a6, 0],
                        [0, 0, 9 a8]] / 9,

(a1..a8 the coefficients alpha1..alpha8) with principal values X1, X2 each, give

    phi = |X'1 - X'2|^a + |2 X''2 + X''1|^a + |2 X''1 + X''2|^a = 2 sigma_bar^a.

With the mean m = (Xxx + Xyy)/2 and the radius rho = sqrt(((Xxx - Xyy)/2)^2 + Xxy^2) of each
image (X1,2 = m +- rho), the three terms are |u_i|^a with

    u1 = 2 rho',   u2 = 3 m'' - rho'',   u3 = 3 m'' + rho''.

sigma_bar = (sum |u_i|^a / 2)^(1/a) is homogeneous of degree 1, and convex for a >= 1
(Barlat et al. 2003 prove phi' and phi'' convex in X', X''; a linear map keeps it). With
w_i = u_i / sigma_bar:

    a    = d sigma_bar/ds = 1/2 sum |w_i|^(a-1) sgn(w_i) grad u_i,
    Hess = 1/2 sum |w_i|^(a-1) sgn(w_i) Hess u_i
           + (a - 1)/sigma_bar [1/2 sum |w_i|^(a-2) grad u_i grad u_i^T - a a^T],

grad rho = (d grad d + t grad t)/rho, Hess rho = (grad d grad d^T + grad t grad t^T - grad rho
grad rho^T)/rho (d, t, m linear in s). rho is regularised as Hill 1979's invariants are:
rho -> sqrt(rho^2 + eps^2 (s11^2 + s22^2 + 2 s12^2)), eps = 1e-12 (a norm of a linear map of s:
degree 1 and convexity kept, smooth where rho = 0). a >= 2 is required so that the Hessian
stays finite where a u_i vanishes.

The alphas are given, fitted exactly to eight data (``fit``), or fitted by least squares to r
values and yield stresses at any angles (``least_squares``: shellform.material.yld2000_fit, which
states r(theta) and sigma(theta) of a plane-stress yield function and is told this criterion's
``predicted``; it imports nothing of this module, which imports it).

Parameters (packed at PAR_): the rows of L' and L'' (2 x 2 normal block and the shear entry
each) and a. ``parameters`` refuses (naming material.alpha) a set whose sigma_bar vanishes for
some stress (the yield surface is open: the map s -> (rho', rho'', m'') has a kernel) or is
not convex on a sample of 1,000 stress directions (a guard: the proof above says it is).
"""

import math

import numpy as np

from shellform.material import yld2000_fit
from shellform.material.layout import PAR_, number, require
from shellform import _jit as jit

NAME = "yld2000"
PLANAR_ISOTROPIC = False  # the rolling direction matters: the return mapping turns into its axes
FIT_DATA = ("r0", "r45", "r90", "r_b", "sigma0", "sigma45", "sigma90", "sigma_b")  # what ``fit`` takes
FIT_LISTS = ("fit_angles", "fit_r", "fit_sigma")  # with sigma_b (and r_b): yld2000_fit's least squares
PARAMETERS = ("alpha", "a") + FIT_DATA + FIT_LISTS  # its scene keys: alpha or the data to fit them, and a
EPS2 = 1.0e-24


def matrices(alpha) -> tuple[np.ndarray, np.ndarray]:
    """L' and L'' (3 x 3, acting on (s11, s22, s12)) from alpha1..alpha8."""
    a1, a2, a3, a4, a5, a6, a7, a8 = alpha
    L1 = np.array([[2 * a1, -a1, 0.0], [-a2, 2 * a2, 0.0], [0.0, 0.0, 3 * a7]]) / 3.0
    L2 = np.array([[-2 * a3 + 2 * a4 + 8 * a5 - 2 * a6, a3 - 4 * a4 - 4 * a5 + 4 * a6, 0.0],
                   [4 * a3 - 4 * a4 - 4 * a5 + a6, -2 * a3 + 8 * a4 + 2 * a5 - 2 * a6, 0.0],
                   [0.0, 0.0, 9 * a8]]) / 9.0
    return L1, L2


def pack(alpha, a) -> list[float]:
    L1, L2 = matrices(alpha)
    return [L1[0, 0], L1[0, 1], L1[1, 0], L1[1, 1], L1[2, 2], L2[0, 0], L2[0, 1], L2[1, 0], L2[1, 1], L2[2, 2], a]


def directions(n=1000) -> np.ndarray:
    """n unit stress directions spread over the sphere (a Fibonacci lattice)."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = math.pi * (1.0 + 5.0**0.5) * k
    r = np.sqrt(1.0 - z * z)
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


def parameters(values: dict) -> list[float]:
    """The packed L', L'' and a from alpha (8 numbers), or from the data FIT_DATA (``fit``), or
    from the lists FIT_LISTS with sigma_b, r_b (``least_squares``), and a
    (>= 2); InputError names the field."""
    require("a" in values, "material.a", "is required by yield_function = 'yld2000' (its exponent: 6 for bcc, "
                                         "8 for fcc metals)")
    a = number("material.a", values["a"])
    require(a >= 2.0, "material.a", f"must be >= 2, got {a}")
    alpha = values.get("alpha")
    if alpha is None:
        require(any(k in values for k in FIT_DATA + FIT_LISTS), "material.alpha",
                f"is required by yield_function = 'yld2000' (alpha1..alpha8, or the data {', '.join(FIT_DATA)} "
                f"to fit them exactly, or {', '.join(FIT_LISTS)} with sigma_b (and r_b) to fit them by least "
                "squares)")
        if yld2000_fit.given(values):
            alpha = list(least_squares(values, a).alpha)
        else:
            alpha = fit(values, a)
    else:
        for k in FIT_LISTS + FIT_DATA:
            require(k not in values, f"material.{k}", "give Yld2000-2d's alpha or the data to fit them, not both")
    require(isinstance(alpha, (list, tuple, np.ndarray)) and len(alpha) == 8, "material.alpha",
            f"must list the 8 coefficients alpha1..alpha8, got {alpha!r}")
    alpha = [number("material.alpha", v) for v in alpha]
    par = pack(alpha, a)
    # sigma_bar vanishes at s != 0 exactly where rho', rho'' and m'' all do: where the linear map
    # s -> (d', t', d'', t'', m'') has a kernel
    L1, L2 = matrices(alpha)
    rows = np.array([0.5 * (L1[0] - L1[1]), L1[2], 0.5 * (L2[0] - L2[1]), L2[2], 0.5 * (L2[0] + L2[1])])
    sv = np.linalg.svd(rows, compute_uv=False)
    require(sv[-1] > 1e-8 * sv[0], "material.alpha",
            "gives a yield function that vanishes for some stress (an open yield surface): not a yield function")
    low = smallest_curvature(yield_function, _packed(alpha, a), directions())
    require(low >= -1e-9, "material.alpha", f"gives a yield function that is not convex (curvature {low:.3g})")
    return par


@jit.njit
def _rho(l00, l01, l10, l11, l22, s0, s1, s2):
    """m, grad m (2: no s12 part), rho, grad rho (3) and Hess rho (6) of X = L s."""
    gd0, gd1 = 0.5 * (l00 - l10), 0.5 * (l01 - l11)
    gm0, gm1 = 0.5 * (l00 + l10), 0.5 * (l01 + l11)
    d = gd0 * s0 + gd1 * s1
    t = l22 * s2
    m = gm0 * s0 + gm1 * s1
    rho = math.sqrt(d * d + t * t + EPS2 * (s0 * s0 + s1 * s1 + 2.0 * s2 * s2))
    if rho == 0.0:
        return m, gm0, gm1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    g = 1.0 / rho
    r0 = (d * gd0 + EPS2 * s0) * g
    r1 = (d * gd1 + EPS2 * s1) * g
    r2 = (t * l22 + 2.0 * EPS2 * s2) * g
    return (m, gm0, gm1, rho, r0, r1, r2,
            (gd0 * gd0 + EPS2 - r0 * r0) * g, (gd0 * gd1 - r0 * r1) * g, -r0 * r2 * g,
            (gd1 * gd1 + EPS2 - r1 * r1) * g, -r1 * r2 * g, (l22 * l22 + 2.0 * EPS2 - r2 * r2) * g)


@jit.njit(inline="always")
def yield_function(s0, s1, s2, mat, order):
    """sigma_bar (order 0: the rest zero) or sigma_bar, gradient and Hessian (upper triangle)."""
    P = PAR_
    a = mat[P + 10]
    m1, _, _, rho1, p0, p1, p2, P00, P01, P02, P11, P12, P22 = _rho(
        mat[P], mat[P + 1], mat[P + 2], mat[P + 3], mat[P + 4], s0, s1, s2)
    m2, gm0, gm1, rho2, q0, q1, q2, Q00, Q01, Q02, Q11, Q12, Q22 = _rho(
        mat[P + 5], mat[P + 6], mat[P + 7], mat[P + 8], mat[P + 9], s0, s1, s2)
    u1, u2, u3 = 2.0 * rho1, 3.0 * m2 - rho2, 3.0 * m2 + rho2
    S = max(abs(u1), abs(u2), abs(u3))
    if not S > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    v1, v2, v3 = abs(u1) / S, abs(u2) / S, abs(u3) / S
    qa = 0.5 * (v1**a + v2**a + v3**a)
    sb = S * qa ** (1.0 / a)
    if order == 0:
        return sb, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    f = 1.0 / sb
    w1, w2, w3 = u1 * f, u2 * f, u3 * f
    # c_i = |w_i|^(a-1) sgn(w_i), k_i = |w_i|^(a-2)
    k1, k2, k3 = abs(w1) ** (a - 2.0), abs(w2) ** (a - 2.0), abs(w3) ** (a - 2.0)
    c1, c2, c3 = k1 * w1, k2 * w2, k3 * w3
    # grad u_i
    x0, x1, x2 = 2.0 * p0, 2.0 * p1, 2.0 * p2
    y0, y1, y2 = 3.0 * gm0 - q0, 3.0 * gm1 - q1, -q2
    z0, z1, z2 = 3.0 * gm0 + q0, 3.0 * gm1 + q1, q2
    a0 = 0.5 * (c1 * x0 + c2 * y0 + c3 * z0)
    a1 = 0.5 * (c1 * x1 + c2 * y1 + c3 * z1)
    a2 = 0.5 * (c1 * x2 + c2 * y2 + c3 * z2)
    # 1/2 sum c_i Hess u_i: Hess u1 = 2 Hess rho', Hess u2 = -Hess rho'', Hess u3 = Hess rho''
    e1, e2 = c1, 0.5 * (c3 - c2)
    g = (a - 1.0) * f
    h00 = e1 * P00 + e2 * Q00 + g * (0.5 * (k1 * x0 * x0 + k2 * y0 * y0 + k3 * z0 * z0) - a0 * a0)
    h01 = e1 * P01 + e2 * Q01 + g * (0.5 * (k1 * x0 * x1 + k2 * y0 * y1 + k3 * z0 * z1) - a0 * a1)
    h02 = e1 * P02 + e2 * Q02 + g * (0.5 * (k1 * x0 * x2 + k2 * y0 * y2 + k3 * z0 * z2) - a0 * a2)
    h11 = e1 * P11 + e2 * Q11 + g * (0.5 * (k1 * x1 * x1 + k2 * y1 * y1 + k3 * z1 * z1) - a1 * a1)
    h12 = e1 * P12 + e2 * Q12 + g * (0.5 * (k1 * x1 * x2 + k2 * y1 * y2 + k3 * z1 * z2) - a1 * a2)
    h22 = e1 * P22 + e2 * Q22 + g * (0.5 * (k1 * x2 * x2 + k2 * y2 * y2 + k3 * z2 * z2) - a2 * a2)
    return sb, a0, a1, a2, h00, h01, h02, h11, h12, h22


def _packed(alpha, a) -> np.ndarray:
    mat = np.zeros(PAR_ + 11)
    mat[PAR_:] = pack(alpha, a)
    return mat


def uniaxial(alpha, a, theta_deg: float) -> tuple[float, float]:
    """(sigma(theta)/sigma_bar, r(theta)) of uniaxial tension at theta degrees to the rolling
    direction (yld2000_fit.uniaxial)."""
    return yld2000_fit.uniaxial(yield_function, _packed(alpha, a), theta_deg)


def uniaxial_and_biaxial(alpha, a) -> dict:
    """The yield stresses (over sigma_bar) and Lankford values of the alpha set: sigma and r at
    0, 45, 90 degrees to the rolling direction, and the balanced-biaxial sigma_b and
    r_b = dep22/dep11 there."""
    sigma, r, sigma_b, r_b = predicted(alpha, a, (0, 45, 90))
    out = {}
    for theta, s, rr in zip((0, 45, 90), sigma, r):
        out[f"sigma{theta}"], out[f"r{theta}"] = float(s), float(rr)
    out["sigma_b"], out["r_b"] = sigma_b, r_b
    return out


def predicted(alpha, a: float, angles) -> tuple[np.ndarray, np.ndarray, float, float]:
    """sigma(theta)/sigma_bar and r(theta) at the angles, sigma_b/sigma_bar and r_b, of the set
    (yld2000_fit.predictions)."""
    return yld2000_fit.predictions(yield_function, _packed(alpha, a), angles)


def smallest_curvature(yield_function, mat: np.ndarray, points) -> float:
    """The smallest curvature of a packed material's sigma_bar over the directions (rows of
    points): the smallest eigenvalue of Hess sigma_bar times sigma_bar, -inf where sigma_bar
    vanishes (every criterion's convexity guard: this one's ``parameters``, poly6's)."""
    low = math.inf
    for s in points:
        out = yield_function(s[0], s[1], s[2], mat, 2)
        if not out[0] > 0.0:
            return -math.inf
        h = out[4:]
        H = np.array([[h[0], h[1], h[2]], [h[1], h[3], h[4]], [h[2], h[4], h[5]]])
        low = min(low, float(np.linalg.eigvalsh(H).min() * out[0]))
    return low


def check(values: dict) -> None:
    """The least-squares data, where given, validated before the fit runs (InputError)."""
    if yld2000_fit.given(values):
        yld2000_fit.data(values)


def describe(values: dict) -> str:
    """The least-squares fit's alphas and largest errors, where the alphas are fitted so."""
    return least_squares(values, values["a"]).text if yld2000_fit.given(values) and "a" in values else ""


def least_squares(values: dict, a: float) -> yld2000_fit.Fit:
    """alpha1..alpha8 by least squares to the material's fit_angles, fit_r, fit_sigma, sigma_b
    (and r_b), and the table of their errors: yld2000_fit.fit told this criterion's predictions."""
    return yld2000_fit.fit(values, a, predicted)


def fit(data: dict, a: float) -> list[float]:
    """alpha1..alpha8 from the eight data r0, r45, r90, r_b, sigma0, sigma45, sigma90, sigma_b
    (the stresses' ratios count; sigma_bar comes out as sigma0), solved by least squares from
    the isotropic set (all alpha = 1); InputError (material.r0 ...) where the data do not fit."""
    from scipy.optimize import least_squares

    for k in FIT_DATA:
        require(k in data, f"material.{k}", f"is required to fit Yld2000-2d's alphas (give {', '.join(FIT_DATA)})")
    d = {k: number(f"material.{k}", data[k]) for k in FIT_DATA}
    for k, v in d.items():
        require(v > 0.0, f"material.{k}", f"must be positive, got {v}")
    target = np.array([d[k] for k in FIT_DATA[:4]] + [d[k] / d["sigma0"] for k in FIT_DATA[4:]])

    def residual(alpha):
        got = uniaxial_and_biaxial(alpha, a)
        return np.array([got[k] for k in FIT_DATA]) - target

    sol = least_squares(residual, np.ones(8), xtol=1e-15, ftol=1e-15, gtol=1e-15)
    worst = np.abs(sol.fun).max()
    require(worst < 1e-8, "material.r0", f"Yld2000-2d (a = {a:g}) cannot meet these data (worst misfit {worst:.3g})")
    return [float(x) for x in sol.x]
