"""The in-plane Hencky strain of a layer and its first two derivatives (numba).

A layer's Green-Lagrange strain E = (E11, E22, 2 E12) gives its in-plane right Cauchy-Green
tensor C = I + 2E over the flat blank's Cartesian axes, and its Lagrangian logarithmic strain

    eps = ln(U) = 1/2 ln C.

A 2 x 2 symmetric tensor function has the closed form f(C) = A I + B (C - u I): with
u = (C11 + C22)/2, d = (C11 - C22)/2, s = C12, q = d^2 + s^2 (eigenvalues u -+ sqrt(q)),

    A = 1/4 ln(u^2 - q)          (the mean of 1/2 ln c1 and 1/2 ln c2)
    B = h(x) / (2u),  x = q/u^2,  h(x) = atanh(sqrt x)/sqrt x = 1 + x/3 + x^2/5 + ...

(the divided difference (1/2 ln c1 - 1/2 ln c2)/(c1 - c2)). h is analytic at x = 0, so eps, its
gradient and its Hessian are smooth at equal stretches (no eigenvectors are ever needed; the
series is summed for x < 0.1, the closed form above). In Voigt form (engineering shear)

    eps = (A + B d, A - B d, 2 B s),

and v = (u, d, s) is linear in E:  v = (1 + E11 + E22, E11 - E22, 2 E12),  dv/dE = J.
log_strain returns eps and P = d eps / dE = (d eps / dv) J; second_order, for a stress T
conjugate to eps, the term  L(T) = sum_k T_k d^2 eps_k / dE^2 = J^T [tau A'' + w B'' + B' w'^T + w' B'^T] J,
tau = T1 + T2, w = (T1 - T2) d + 2 T3 s. A stress conjugate to E follows as S = P^T T and its
tangent as dS/dE = P^T (dT/deps) P + L(T) (docs/material.md).
"""

import math

import numpy as np

from shellform import _jit as jit


SERIES_BELOW = 0.1  # x below which h, h', h'' are summed as power series
SERIES_TERMS = 24  # 0.1^24: below rounding
SERIES_END = 1e-17  # ... or fewer: the sum ends once x^k is below rounding
_K = np.arange(SERIES_TERMS, dtype=np.float64)
H0, H1, H2 = 1.0 / (2 * _K + 1), (_K + 1) / (2 * _K + 3), (_K + 2) * (_K + 1) / (2 * _K + 5)  # c_k, (k+1) c_k+1, ...


@jit.njit
def _h(x):
    """h(x) = atanh(sqrt x)/sqrt x and its first two derivatives, 0 <= x < 1."""
    if x < SERIES_BELOW:  # c_k = 1/(2k + 1): h = sum c_k x^k and its term-wise derivatives
        h = h1 = h2 = 0.0
        xk = 1.0  # x^k
        for k in range(SERIES_TERMS):
            h += xk * H0[k]
            h1 += xk * H1[k]
            h2 += xk * H2[k]
            xk *= x
            if xk < SERIES_END:
                break
        return h, h1, h2
    if not x < 1.0:  # not reached: log_strain checks u^2 > q
        return math.inf, math.inf, math.inf
    y = math.sqrt(x)
    h = math.atanh(y) / y
    a = 1.0 / (1.0 - x)
    h1 = (a - h) / (2.0 * x)
    h2 = (a * a - h1) / (2.0 * x) - h1 / x
    return h, h1, h2


@jit.njit
def log_strain(E, eps, P, W):
    """eps = 1/2 ln(I + 2E) (3, engineering shear) and P = d eps/dE (3 x 3); W (16) keeps what
    second_order needs. Returns False where I + 2E is not positive definite (no stretch gives
    it; nothing is written)."""
    u = 1.0 + E[0] + E[1]
    d = E[0] - E[1]
    s = E[2]
    q = d * d + s * s
    D = u * u - q
    if not (u > 0.0 and D > 0.0):
        return False
    x = q / (u * u)
    h, h1, h2 = _h(x)
    A = 0.25 * math.log(D)
    g = 0.5 / u
    B = g * h
    eps[0], eps[1], eps[2] = A + B * d, A - B * d, 2.0 * B * s
    # gradients over v = (u, d, s): A' = D'/(4D), x', g' = (-1/(2u^2), 0, 0), B' = h g' + g h' x'
    a0, a1, a2 = 0.5 * u / D, -0.5 * d / D, -0.5 * s / D
    u2, u3 = u * u, u * u * u
    x0, x1, x2 = -2.0 * q / u3, 2.0 * d / u2, 2.0 * s / u2
    b0 = -0.5 * h / u2 + g * h1 * x0
    b1, b2 = g * h1 * x1, g * h1 * x2
    # d eps/dv rows, then P = (d eps/dv) J, J = [[1, 1, 0], [1, -1, 0], [0, 0, 1]]
    r00, r01, r02 = a0 + d * b0, a1 + d * b1 + B, a2 + d * b2
    r10, r11, r12 = a0 - d * b0, a1 - d * b1 - B, a2 - d * b2
    r20, r21, r22 = 2.0 * s * b0, 2.0 * s * b1, 2.0 * s * b2 + 2.0 * B
    P[0, 0], P[0, 1], P[0, 2] = r00 + r01, r00 - r01, r02
    P[1, 0], P[1, 1], P[1, 2] = r10 + r11, r10 - r11, r12
    P[2, 0], P[2, 1], P[2, 2] = r20 + r21, r20 - r21, r22
    # Hessians over v: A'' = D''/(4D) - 4 A'A'^T, D'' = diag(2, -2, -2);
    # B'' = h g'' + h' (g'x'^T + x'g'^T) + g h'' x'x'^T + g h' x'', g'' = diag(1/u^3, 0, 0)
    gp = -0.5 / u2
    ghh, gh1 = g * h2, g * h1
    W[0] = 0.5 / D - 4.0 * a0 * a0
    W[1] = -4.0 * a0 * a1
    W[2] = -4.0 * a0 * a2
    W[3] = -0.5 / D - 4.0 * a1 * a1
    W[4] = -4.0 * a1 * a2
    W[5] = -0.5 / D - 4.0 * a2 * a2
    W[6] = h / u3 + 2.0 * h1 * gp * x0 + ghh * x0 * x0 + gh1 * 6.0 * q / (u2 * u2)
    W[7] = h1 * gp * x1 + ghh * x0 * x1 - gh1 * 4.0 * d / u3
    W[8] = h1 * gp * x2 + ghh * x0 * x2 - gh1 * 4.0 * s / u3
    W[9] = ghh * x1 * x1 + gh1 * 2.0 / u2
    W[10] = ghh * x1 * x2
    W[11] = ghh * x2 * x2 + gh1 * 2.0 / u2
    W[12], W[13], W[14], W[15] = b0, b1, b2, d
    return True


@jit.njit
def second_order(T, s, W, L):
    """L = sum_k T_k d^2 eps_k/dE^2 (3 x 3) at the strain of the last log_strain call (W), s its
    shear E[2]: J^T [tau A'' + w B'' + B' w'^T + w' B'^T] J, w' = (0, T1 - T2, 2 T3)."""
    tau = T[0] + T[1]
    d = W[15]
    w = (T[0] - T[1]) * d + 2.0 * T[2] * s
    b0, b1, b2 = W[12], W[13], W[14]
    c1, c2 = T[0] - T[1], 2.0 * T[2]
    l00 = tau * W[0] + w * W[6]
    l01 = tau * W[1] + w * W[7] + b0 * c1
    l02 = tau * W[2] + w * W[8] + b0 * c2
    l11 = tau * W[3] + w * W[9] + 2.0 * b1 * c1
    l12 = tau * W[4] + w * W[10] + b1 * c2 + c1 * b2
    l22 = tau * W[5] + w * W[11] + 2.0 * b2 * c2
    # J^T Lv J with J = [[1, 1, 0], [1, -1, 0], [0, 0, 1]]
    L[0, 0] = l00 + 2.0 * l01 + l11
    L[0, 1] = L[1, 0] = l00 - l11
    L[1, 1] = l00 - 2.0 * l01 + l11
    L[0, 2] = L[2, 0] = l02 + l12
    L[1, 2] = L[2, 1] = l02 - l12
    L[2, 2] = l22
