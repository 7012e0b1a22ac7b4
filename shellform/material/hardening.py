"""Isotropic hardening: the flow stress sigma_bar(p) and its slope d sigma_bar / d p.

p is the equivalent plastic strain (work conjugate to sigma_bar); p < 0 is read as p = 0.

power law (law 1), a = sigma_y, b = n >= 1, eps_y = sigma_y / E:
    total uniaxial strain eps_bar = s/E + p = eps_y (s/sigma_y)^n  for s >= sigma_y,
    so with x = s/sigma_y and P = p/eps_y:  g(x) = x^n - x - P = 0.
    g is convex and increasing on x >= 1 (n > 1); Newton from a point right of the root decreases
    monotonically onto it. Slope ds/dp = E / (n x^(n-1) - 1). n = 1: perfectly plastic.
Swift (law 2), a = K, b = eps0, c = n:  s = K (eps0 + p)^n, slope n K (eps0 + p)^(n-1).
elastic (law 0): no yield; returns (inf, 0).
"""

import math


from shellform.material import A_, B_, C_, E_, LAW_, LAW_POWER, LAW_SWIFT
from shellform import _jit as jit


@jit.njit
def _power_law(p, E, sy, n):
    if n <= 1.0 + 1e-12:
        return sy, 0.0
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
        K, e0, n = mat[A_], mat[B_], mat[C_]
        if n == 0.0:
            return K, 0.0
        base = e0 + p
        s = K * base**n
        return s, n * s / base
    return math.inf, 0.0
