"""Isotropic hardening: the flow stress sigma_bar(p) and its slope d sigma_bar / d p.

p is the equivalent plastic strain (work conjugate to sigma_bar); p < 0 is read as p = 0.

power law (law 1), a = sigma_y, b = n > 1, eps_y = sigma_y / E:
    total uniaxial strain eps_bar = s/E + p = eps_y (s/sigma_y)^n  for s >= sigma_y,
    so with x = s/sigma_y and P = p/eps_y:  g(x) = x^n - x - P = 0.
    g is convex and increasing on x >= 1 (n > 1); Newton from a point right of the root decreases
    monotonically onto it. Slope ds/dp = E / (n x^(n-1) - 1). As n falls to 1 the curve turns
    elastic (x ln x ~ P / (n - 1)), and n -> infinity is perfectly plastic: n = 1 is refused.
Swift (law 2), a = K, b = eps0, c = n:  s = K (eps0 + p)^n, slope n K (eps0 + p)^(n-1).
Voce (law 3), H_.. = sigma0, Q, beta:  s = sigma0 + Q (1 - exp(-beta p)), slope Q beta exp(-beta p).
Swift-Voce (law 4), H_.. = K, eps0, n, sigma0, Q, beta, w:  s = w Swift(p) + (1 - w) Voce(p).
table (law 5): (p_i, sigma_i) from TABLE_ (shellform.material.flow_curve), linear between the
    points; beyond the last one the extrapolation H_ = 0 constant, 1 linear (slope H_+1),
    2 Swift (K, eps0, n at H_+1..), 3 Voce s_inf - (s_inf - sigma_N) exp(-beta (p - p_N))
    (s_inf, beta at H_+1..).
elastic (law 0): no yield; returns (inf, 0).
"""

import math


from shellform.material.layout import (A_, B_, C_, E_, H_, LAW_, LAW_POWER, LAW_SWIFT, LAW_SWIFT_VOCE, LAW_TABLE,
                                LAW_VOCE, TABLE_)
from shellform import _jit as jit


@jit.njit
def _power_law(p, E, sy, n):
    P = p * E / sy
    if P <= 0.0:
        return sy, E / (n - 1.0)
    x = min(1.0 + P / (n - 1.0), (1.0 + P) ** (1.0 / (n - 1.0)))  # both >= the root
    for _ in range(100):
        xn1 = x ** (n - 1.0)
        dx = (xn1 * x - x - P) / (n * xn1 - 1.0)
        x -= dx
        if abs(dx) <= 1e-15 * x:
            break
    return sy * x, E / (n * x ** (n - 1.0) - 1.0)


@jit.njit
def flow_stress(p, mat):
    """(sigma_bar, d sigma_bar / d p) at equivalent plastic strain p for the packed material."""
    law = int(mat[LAW_])
    p = max(p, 0.0)
    if law == LAW_POWER:
        return _power_law(p, mat[E_], mat[A_], mat[B_])
    if law == LAW_SWIFT:
        return _swift(p, mat[A_], mat[B_], mat[C_])
    if law == LAW_VOCE:
        return _voce(p, mat[H_], mat[H_ + 1], mat[H_ + 2])
    if law == LAW_SWIFT_VOCE:
        w = mat[H_ + 6]
        s1, h1 = _swift(p, mat[H_], mat[H_ + 1], mat[H_ + 2])
        s2, h2 = _voce(p, mat[H_ + 3], mat[H_ + 4], mat[H_ + 5])
        return w * s1 + (1.0 - w) * s2, w * h1 + (1.0 - w) * h2
    if law == LAW_TABLE:
        return _table(p, mat)
    return math.inf, 0.0


@jit.njit
def _swift(p, K, e0, n):
    if n == 0.0:
        return K, 0.0
    base = e0 + p
    s = K * base**n
    return s, n * s / base


@jit.njit
def _voce(p, s0, Q, beta):
    x = Q * math.exp(-beta * p)
    return s0 + Q - x, beta * x


@jit.njit
def _table(p, mat):
    n = int(mat[TABLE_])
    ps, ss = mat[TABLE_ + 1:TABLE_ + 1 + n], mat[TABLE_ + 1 + n:TABLE_ + 1 + 2 * n]
    if p >= ps[n - 1]:
        kind = int(mat[H_])
        pN, sN = ps[n - 1], ss[n - 1]
        if kind == 1:
            return sN + mat[H_ + 1] * (p - pN), mat[H_ + 1]
        if kind == 2:
            return _swift(p, mat[H_ + 1], mat[H_ + 2], mat[H_ + 3])
        if kind == 3:
            sinf = mat[H_ + 1]
            x = (sinf - sN) * math.exp(-mat[H_ + 2] * (p - pN))
            return sinf - x, mat[H_ + 2] * x
        return sN, 0.0
    lo, hi = 0, n - 1  # bisection: ps[lo] <= p < ps[hi]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if ps[mid] <= p:
            lo = mid
        else:
            hi = mid
    slope = (ss[hi] - ss[lo]) / (ps[hi] - ps[lo])
    return ss[lo] + slope * (p - ps[lo]), slope
