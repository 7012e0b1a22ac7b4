"""Soare's Poly6 (Soare, Yoon and Cazacu, Int. J. Plasticity 24 (2008) 915), plane stress: the
sixth power of sigma_bar a homogeneous polynomial of the stress, fitted to directional data
under a convexity constraint.

In the axes of the rolling direction, with s = (x, y, z) = (s11, s22, s12) and orthotropy
(only even powers of the shear z),

    f(s) = sigma_bar^6 = A(x, y) + z^2 B(x, y) + z^4 C(x, y) + z^6 D,

A, B, C binary forms of degree 6, 4, 2 in (x, y): 7 + 5 + 3 + 1 = 16 coefficients c1..c16,
packed at PAR_ in that order (A's from x^6 to y^6, then B's, C's, D). sigma_bar = f^(1/6) is
homogeneous of degree 1; with g = grad f and K = Hess f,

    a    = d sigma_bar/ds = sigma_bar g / (6 f),
    Hess = sigma_bar K / (6 f) - 5 a a^T / sigma_bar.

sigma_bar is convex where f > 0 and the tangent part of M = 6 f K - 5 g g^T (M restricted to
the plane normal to s: M s = 0 along s itself, since f is homogeneous) is positive
semi-definite: M is Hess sigma_bar up to the positive factor 36 f^2 / sigma_bar. Unlike
Yld2000-2d's, the polynomial is not convex by construction; the fit asks for it.

**The fit** (``least_squares``): the residuals of shellform.material.yld2000_fit (r values and
yield-stress ratios at the data's angles, sigma_b and r_b, every one of weight 1, sigma_bar
normalised to the rolling direction's yield stress), their sum of squares minimised by SLSQP
from von Mises ((x^2 - x y + y^2 + 3 z^2)^3) subject to the smallest eigenvalue of the tangent
part of M / f^(5/3) (a measure of degree 0) being at least CONVEXITY_MARGIN at CONSTRAINT_POINTS
stress directions of the quarter sphere that f's symmetries (f(-s) = f(s), f(x, y, -z) =
f(x, y, z)) leave. Uniaxial data alone leave the coefficients partly free (along the tensile
directions u = (c^2, s^2, c s), x y = z^2: a term x y P and a term z^2 P give the same f there,
though not the same gradient); the convexity constraint and the start choose among them.
``parameters`` then refuses (naming material.fit_angles) a fit whose sigma_bar is not convex on
yld2000's 1,000 guard directions.

Parameters: c1..c16 (``coefficients``, scaled so that c1 = 1: sigma_bar is the rolling
direction's yield stress), or the data to fit them (fit_angles, fit_r, fit_sigma, sigma_b and
optionally r_b, the keys Yld2000-2d's least squares takes; docs/material.md, "Poly6").
"""

import functools
import math

import numpy as np

from shellform.material import yld2000_fit
from shellform.material.yld2000 import directions, smallest_curvature
from shellform.material.layout import PAR_, number, require
from shellform import _jit as jit

NAME = "poly6"
PLANAR_ISOTROPIC = False  # the rolling direction matters: the return mapping turns into its axes
PARAMETERS = ("coefficients",) + yld2000_fit.KEYS + ("sigma_b", "r_b")  # c1..c16, or the data to fit them
COEFFICIENTS = 16
# von Mises, (x^2 - x y + y^2 + 3 z^2)^3, in the packing order: the fit's start
VON_MISES = (1.0, -3.0, 6.0, -7.0, 6.0, -3.0, 1.0, 9.0, -18.0, 27.0, -18.0, 9.0, 27.0, -27.0, 27.0, 27.0)
CONVEXITY_MARGIN = 2.0e-2  # the fit's bound on the tangent curvature of M / f^(5/3)
CONSTRAINT_POINTS = 2000  # Fibonacci directions on the sphere, of which the quarter is kept
RING_POINTS = 360  # and directions on the half of the circle z = 0 (the normal stresses' plane)
CHECK_POINTS, EXCHANGE, ROUNDS = 40000, 20, 8  # the exchange method's check directions (full sphere), per round


@jit.njit(inline="always")
def _form(c, o, n, x, y):
    """P = sum_j c[o + j] x^(n - j) y^j and its first and second partial derivatives."""
    p = px = py = pxx = pxy = pyy = 0.0
    for j in range(n + 1):
        i = n - j
        k = c[o + j]
        xi = x**i
        yj = y**j
        p += k * xi * yj
        if i >= 1:
            xi1 = x ** (i - 1)
            px += k * i * xi1 * yj
            if i >= 2:
                pxx += k * i * (i - 1) * x ** (i - 2) * yj
            if j >= 1:
                pxy += k * i * j * xi1 * y ** (j - 1)
        if j >= 1:
            yj1 = y ** (j - 1)
            py += k * j * xi * yj1
            if j >= 2:
                pyy += k * j * (j - 1) * xi * y ** (j - 2)
    return p, px, py, pxx, pxy, pyy


@jit.njit(inline="always")
def polynomial(x, y, z, c, o):
    """f, its gradient (3) and Hessian (6, upper triangle) at (x, y, z), coefficients c[o:o+16]."""
    a, ax, ay, axx, axy, ayy = _form(c, o, 6, x, y)
    b, bx, by, bxx, bxy, byy = _form(c, o + 7, 4, x, y)
    q, qx, qy, qxx, qxy, qyy = _form(c, o + 12, 2, x, y)
    d = c[o + 15]
    z2 = z * z
    z4 = z2 * z2
    f = a + z2 * b + z4 * q + z4 * z2 * d
    g0 = ax + z2 * bx + z4 * qx
    g1 = ay + z2 * by + z4 * qy
    g2 = 2.0 * z * b + 4.0 * z * z2 * q + 6.0 * z * z4 * d
    h00 = axx + z2 * bxx + z4 * qxx
    h01 = axy + z2 * bxy + z4 * qxy
    h11 = ayy + z2 * byy + z4 * qyy
    h02 = 2.0 * z * bx + 4.0 * z * z2 * qx
    h12 = 2.0 * z * by + 4.0 * z * z2 * qy
    h22 = 2.0 * b + 12.0 * z2 * q + 30.0 * z4 * d
    return f, g0, g1, g2, h00, h01, h02, h11, h12, h22


@jit.njit(inline="always")
def yield_function(s0, s1, s2, mat, order):
    """sigma_bar (order 0: the rest zero) or sigma_bar, gradient and Hessian (upper triangle),
    evaluated at s / max|s_i| (f of degree 6 stays of order 1) and scaled back."""
    S = max(abs(s0), abs(s1), abs(s2))
    if not S > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    f, g0, g1, g2, k00, k01, k02, k11, k12, k22 = polynomial(s0 / S, s1 / S, s2 / S, mat, PAR_)
    if not f > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    sb = f ** (1.0 / 6.0)
    if order == 0:
        return S * sb, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    w = sb / (6.0 * f)
    a0, a1, a2 = w * g0, w * g1, w * g2
    e = 5.0 / sb
    v = w / S  # Hess sigma_bar is of degree -1: 1/S back in the stress's units
    u = e / S
    return (S * sb, a0, a1, a2, v * k00 - u * a0 * a0, v * k01 - u * a0 * a1, v * k02 - u * a0 * a2,
            v * k11 - u * a1 * a1, v * k12 - u * a1 * a2, v * k22 - u * a2 * a2)


@jit.njit
def tangent_curvatures(c, points):
    """Per direction s (rows of points): the smallest eigenvalue of the tangent part of
    M / f^(5/3) (module docstring), -1e3 where f <= 0."""
    out = np.empty(points.shape[0])
    for n in range(points.shape[0]):
        s = points[n]
        f, g0, g1, g2, k00, k01, k02, k11, k12, k22 = polynomial(s[0], s[1], s[2], c, 0)
        if not f > 0.0:
            out[n] = -1.0e3
            continue
        g = np.array([g0, g1, g2])
        K = np.array([[k00, k01, k02], [k01, k11, k12], [k02, k12, k22]])
        M = (6.0 * f * K - 5.0 * np.outer(g, g)) / f ** (5.0 / 3.0)
        # an orthonormal basis of the plane normal to s
        t1 = np.array([-s[1], s[0], 0.0]) if abs(s[2]) < 0.9 else np.array([0.0, -s[2], s[1]])
        t1 /= math.sqrt(t1 @ t1)
        t2 = np.cross(s, t1)
        t2 /= math.sqrt(t2 @ t2)
        p, q, r = t1 @ M @ t1, t1 @ M @ t2, t2 @ M @ t2
        out[n] = 0.5 * (p + r) - math.sqrt(0.25 * (p - r) ** 2 + q * q)
    return out


def constraint_directions(n=CONSTRAINT_POINTS) -> np.ndarray:
    """The Fibonacci directions of yld2000.directions(n) with z >= 0 and x + y >= 0, and a ring
    of RING_POINTS in the plane z = 0 (the normal stresses' yield locus, where the fitted
    polynomial bends most sharply: without the ring it turns concave between the lattice's
    points there)."""
    d = directions(n)
    phi = np.linspace(-0.25 * math.pi, 0.75 * math.pi, RING_POINTS, endpoint=False)
    ring = np.column_stack([np.cos(phi), np.sin(phi), np.zeros_like(phi)])
    return np.vstack([quarter(d), ring])


def _mat(c) -> np.ndarray:
    mat = np.zeros(PAR_ + COEFFICIENTS)
    mat[PAR_:] = c
    return mat


def uniaxial(c, theta_deg: float) -> tuple[float, float]:
    """(sigma(theta)/sigma_bar, r(theta)) of uniaxial tension at theta degrees to the rolling
    direction (yld2000_fit.uniaxial)."""
    return yld2000_fit.uniaxial(yield_function, _mat(c), theta_deg)


def predicted(c, a, angles) -> tuple[np.ndarray, np.ndarray, float, float]:
    """sigma(theta)/sigma_bar and r(theta) at the angles, sigma_b/sigma_bar and r_b of the
    coefficients c (yld2000_fit.predictions; a, the exponent yld2000_fit passes, is unused)."""
    return yld2000_fit.predictions(yield_function, _mat(c), angles)


def quarter(d: np.ndarray) -> np.ndarray:
    """The directions of d with z >= 0 and x + y >= 0 (f's symmetries give the rest)."""
    return d[(d[:, 2] >= 0.0) & (d[:, 0] + d[:, 1] >= 0.0)]


@functools.lru_cache(maxsize=32)
def _solve(d: yld2000_fit.Data) -> tuple[tuple[float, ...], bool, str]:
    """SLSQP under the convexity constraint at constraint_directions(), then (an exchange method
    for the constraint at infinitely many directions) at the EXCHANGE worst of the check
    directions where the solution is not convex there, solved again, up to ROUNDS times."""
    from scipy.optimize import minimize

    points = constraint_directions()
    check = np.vstack([quarter(directions(CHECK_POINTS)), quarter(directions())])

    def objective(c):
        e = yld2000_fit.residuals(c, 6.0, d, predicted)
        return float(e @ e)

    c = np.array(VON_MISES)
    for _ in range(ROUNDS):
        convex = {"type": "ineq", "fun": lambda c, p=points: tangent_curvatures(c, p) - CONVEXITY_MARGIN}
        sol = minimize(objective, c, method="SLSQP", constraints=[convex], options={"maxiter": 1000, "ftol": 1e-14})
        c = sol.x
        k = tangent_curvatures(c, check)
        if not sol.success or k.min() >= 0.0:
            break
        points = np.vstack([points, check[np.argsort(k)[:EXCHANGE]]])
    return tuple(float(x) for x in c), bool(sol.success and k.min() >= 0.0), str(sol.message)


def least_squares(values: dict) -> yld2000_fit.Fit:
    """c1..c16 by least squares to the material's fit_angles, fit_r, fit_sigma, sigma_b (and
    r_b) under the convexity constraint, with the table of their errors; InputError naming
    material.fit_angles where the data are malformed or the fit fails."""
    d = yld2000_fit.data(values, least=1, name="Poly6")
    c, ok, message = _solve(d)
    require(ok and all(math.isfinite(x) for x in c), "material.fit_angles",
            f"the constrained least-squares fit of Poly6 to these data did not converge ({message})")
    return yld2000_fit.table(d, c, 6.0, predicted, label="coefficients")


def check(values: dict) -> None:
    """The data, validated before the fit runs (InputError naming the field)."""
    if yld2000_fit.given(values):
        yld2000_fit.data(values, least=1, name="Poly6")


def describe(values: dict) -> str:
    """The fit's coefficients and largest errors."""
    return least_squares(values).text if yld2000_fit.given(values) else ""


def convexity(c, points) -> float:
    """The smallest curvature of sigma_bar over the directions (rows of points): the smallest
    eigenvalue of Hess sigma_bar times sigma_bar (-inf where f <= 0; yld2000.smallest_curvature)."""
    return smallest_curvature(yield_function, _mat(c), points)


def parameters(values: dict) -> list[float]:
    """The packed c1..c16, given (scaled to c1 = 1) or from the least-squares fit; InputError
    (naming material.coefficients or material.fit_angles) where sigma_bar vanishes somewhere or
    is not convex on yld2000's guard directions."""
    given = values.get("coefficients")
    if given:
        require(not yld2000_fit.given(values), "material.coefficients",
                "give Poly6's coefficients or the data to fit them (fit_angles, fit_r, fit_sigma), not both")
        require(isinstance(given, (list, tuple, np.ndarray)) and len(given) == COEFFICIENTS, "material.coefficients",
                f"must list the {COEFFICIENTS} coefficients c1..c16, got {given!r}")
        c = [number("material.coefficients", x) for x in given]
        require(c[0] > 0.0, "material.coefficients", f"c1 (of x^6) must be positive, got {c[0]:g}")
        c = [x / c[0] for x in c]
        field = "material.coefficients"
    else:
        require(yld2000_fit.given(values), "material.fit_angles",
                "is required by yield_function = 'poly6' (with fit_r, fit_sigma, sigma_b and optionally r_b: the "
                "data its 16 coefficients are fitted to), or give material.coefficients")
        c = list(least_squares(values).alpha)
        field = "material.fit_angles"
    low = convexity(c, directions())
    require(low > -math.inf, field,
            "give a Poly6 that vanishes or turns negative for some stress: not a yield function")
    require(low >= -1e-9, field, f"give a Poly6 that is not convex (curvature {low:.3g})")
    return c
