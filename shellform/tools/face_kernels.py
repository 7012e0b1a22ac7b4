"""The elementary faces' closed forms compiled by numba (faces.py): each kind's nearest point and
derivatives over pairs of points and faces, the pairs of points and boxes within reach (within)
and the distance's Hessian from a face's derivatives (shape_operators).
"""

import numpy as np

from shellform._jit import njit

TWO_PI = 2.0 * np.pi


def _arc(phi, lo, hi, tol):
    """The angle nearest to the angle phi in the arc [lo, hi] (angles modulo 2 pi, hi - lo <=
    2 pi): phi's representative where it lies within tol of the arc (inside True), else the
    arc's nearer end by angle (on a circle the distance grows with the angle between)."""
    span = hi - lo
    after = np.mod(phi - lo, TWO_PI)  # the angle past the arc's start, in [0, 2 pi)
    before = TWO_PI - after  # the angle before its start
    on = after <= span + tol
    early = ~on & (before <= tol)
    u = np.where(on, lo + after, np.where(early, lo - before, np.where(after - span < before, hi, lo)))
    return u, on | early


def cross(a, b):
    """a x b of (points, 3) arrays (numpy's cross, fewer calls)."""
    return np.stack([a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1], a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                     a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]], axis=1)


def _close(a, b, tol) -> bool:
    return bool(np.abs(np.asarray(a) - np.asarray(b)).max(initial=0.0) <= tol)


# -- the closed forms, compiled (numba: one call a kind instead of tens of numpy calls) ----------
# A kind's faces' parameters are rows of one array (_Kind._packed), in the order of its LAYOUT.


@njit
def _interval1(p, lo, hi, tol):
    """The parameter nearest to p in [lo, hi]: p itself where it lies within tol of the
    interval (inside True), else the nearer bound."""
    if p >= lo - tol and p <= hi + tol:
        return p, True
    return min(max(p, lo), hi), False


@njit
def _arc1(phi, lo, hi, tol):
    """_arc of one angle."""
    span = hi - lo
    after = (phi - lo) % TWO_PI  # as np.mod: fmod (exact), turned non-negative
    before = TWO_PI - after
    if after <= span + tol:
        return lo + after, True
    if before <= tol:
        return lo - before, True
    return (hi, False) if after - span < before else (lo, False)


@njit(inline="always")
def _along(dx, dy, dz, q, a):
    """(dx, dy, dz) along the unit vector q[a:a + 3] of a face's row: a coordinate in its frame."""
    return dx * q[a] + dy * q[a + 1] + dz * q[a + 2]


@njit
def _planes_nearest(y, j, rows, uv, d, inside):
    for p in range(len(j)):
        q = rows[j[p]]
        dx, dy, dz = y[p, 0] - q[0], y[p, 1] - q[1], y[p, 2] - q[2]
        u, iu = _interval1(_along(dx, dy, dz, q, 3), q[9], q[11], q[13])
        v, iv = _interval1(_along(dx, dy, dz, q, 6), q[10], q[12], q[14])
        rx, ry, rz = dx - (u * q[3] + v * q[6]), dy - (u * q[4] + v * q[7]), dz - (u * q[5] + v * q[8])
        uv[p, 0], uv[p, 1], d[p], inside[p] = u, v, np.sqrt(rx * rx + ry * ry + rz * rz), iu and iv


@njit
def _planes_derivatives(j, uv, rows, X, J, S):
    for p in range(len(j)):
        q = rows[j[p]]
        for i in range(3):
            X[p, i] = q[i] + uv[p, 0] * q[3 + i] + uv[p, 1] * q[6 + i]
            J[p, 0, i], J[p, 1, i] = q[3 + i], q[6 + i]
            S[p, 0, i] = S[p, 1, i] = S[p, 2, i] = 0.0


@njit
def _cylinders_nearest(y, j, rows, uv, d, inside):
    for p in range(len(j)):
        q = rows[j[p]]
        dx, dy, dz = y[p, 0] - q[0], y[p, 1] - q[1], y[p, 2] - q[2]
        qx, qy, qz = _along(dx, dy, dz, q, 3), _along(dx, dy, dz, q, 6), _along(dx, dy, dz, q, 9)
        phi = np.arctan2(qy, qx)
        u, iu = _arc1(phi, q[13], q[15], q[17])
        v, iv = _interval1(qz, q[14], q[16], q[18])
        rho, turn = np.hypot(qx, qy), u - phi
        d[p] = np.sqrt((rho * np.cos(turn) - q[12]) ** 2 + (rho * np.sin(turn)) ** 2 + (qz - v) ** 2)
        uv[p, 0], uv[p, 1], inside[p] = u, v, iu and iv


@njit
def _cylinders_derivatives(j, uv, rows, X, J, S):
    for p in range(len(j)):
        q = rows[j[p]]
        c, s, R = np.cos(uv[p, 0]), np.sin(uv[p, 0]), q[12]
        for i in range(3):
            radial = c * q[3 + i] + s * q[6 + i]
            X[p, i] = q[i] + R * radial + uv[p, 1] * q[9 + i]
            J[p, 0, i], J[p, 1, i] = R * (-s * q[3 + i] + c * q[6 + i]), q[9 + i]
            S[p, 0, i], S[p, 1, i], S[p, 2, i] = -R * radial, 0.0, 0.0


@njit
def _revolutions_nearest(y, j, rows, uv, d, inside):
    for p in range(len(j)):
        q = rows[j[p]]
        dx, dy, dz = y[p, 0] - q[0], y[p, 1] - q[1], y[p, 2] - q[2]
        qw, qb, qa = _along(dx, dy, dz, q, 12), _along(dx, dy, dz, q, 15), _along(dx, dy, dz, q, 18)  # w_0, b_0, a
        rho, phi = np.hypot(qw, qb), np.arctan2(qb, qw)
        u, iu = _arc1(phi, q[28], q[30], q[32])
        turn = u - phi
        sx, sy = rho * np.cos(turn) - q[21], qa - q[22]  # y in the meridian's plane, from c
        v, iv = _arc1(np.arctan2(sx * q[26] + sy * q[27], sx * q[24] + sy * q[25]), q[29], q[31], q[33])
        cv, sv = np.cos(v), np.sin(v)
        mr, mh = q[21] + q[23] * (cv * q[24] + sv * q[26]), q[22] + q[23] * (cv * q[25] + sv * q[27])
        d[p] = np.sqrt((rho * np.cos(turn) - mr) ** 2 + (qa - mh) ** 2 + (rho * np.sin(turn)) ** 2)
        uv[p, 0], uv[p, 1], inside[p] = u, v, iu and iv


@njit
def _revolutions_derivatives(j, uv, rows, X, J, S):
    for p in range(len(j)):
        q = rows[j[p]]
        cu, su, cv, sv, r = np.cos(uv[p, 0]), np.sin(uv[p, 0]), np.cos(uv[p, 1]), np.sin(uv[p, 1]), q[23]
        m0, m1 = q[21] + r * (cv * q[24] + sv * q[26]), q[22] + r * (cv * q[25] + sv * q[27])  # (rho, h)
        d0, d1 = r * (-sv * q[24] + cv * q[26]), r * (-sv * q[25] + cv * q[27])
        e0, e1 = -r * (cv * q[24] + sv * q[26]), -r * (cv * q[25] + sv * q[27])
        for i in range(3):
            w, b, a = cu * q[6 + i] + su * q[9 + i], -su * q[6 + i] + cu * q[9 + i], q[3 + i]
            X[p, i] = q[i] + m0 * w + m1 * a
            J[p, 0, i], J[p, 1, i] = m0 * b, d0 * w + d1 * a
            S[p, 0, i], S[p, 1, i], S[p, 2, i] = -m0 * w, e0 * w + e1 * a, d0 * b


@njit
def _within(y, reach, lo, hi, pi, k):
    count = 0
    for p in range(y.shape[0]):
        for f in range(lo.shape[0]):
            square = 0.0
            for i in range(3):
                t = max(lo[f, i] - y[p, i], y[p, i] - hi[f, i], 0.0)
                square += t * t
            if np.sqrt(square) <= reach[p]:
                pi[count], k[count] = p, f
                count += 1
    return count


def within(y, reach, lo, hi):
    """The pairs (point, box) whose box [lo, hi] lies within reach of the point (its distance to
    the box): point and box indices, by point then box."""
    pi, k = np.empty(len(y) * len(lo), dtype=np.int64), np.empty(len(y) * len(lo), dtype=np.int64)
    count = _within(np.ascontiguousarray(y, dtype=float), np.ascontiguousarray(reach, dtype=float),
                    np.ascontiguousarray(lo), np.ascontiguousarray(hi), pi, k)
    return pi[:count], k[:count]


@njit
def _shape_operators(J, S, n, d, H, regular):
    for p in range(len(d)):
        b = np.zeros(3)
        for a in range(3):
            b[a] = -(S[p, a, 0] * n[p, 0] + S[p, a, 1] * n[p, 1] + S[p, a, 2] * n[p, 2])
        g0 = J[p, 0, 0] ** 2 + J[p, 0, 1] ** 2 + J[p, 0, 2] ** 2
        g1 = J[p, 1, 0] ** 2 + J[p, 1, 1] ** 2 + J[p, 1, 2] ** 2
        g2 = J[p, 0, 0] * J[p, 1, 0] + J[p, 0, 1] * J[p, 1, 1] + J[p, 0, 2] * J[p, 1, 2]
        det = g0 * g1 - g2 ** 2
        regular[p] = det > 1e-12 * (g0 + g1) ** 2
        if not regular[p]:
            continue
        k0, k1, k2 = g0 + d[p] * b[0], g1 + d[p] * b[1], g2 + d[p] * b[2]  # G + d B
        m00, m01 = b[0] * k1 - b[2] * k2, b[2] * k0 - b[0] * k2  # B adj(G + d B)
        m10, m11 = b[2] * k1 - b[1] * k2, b[1] * k0 - b[2] * k2
        scale = 1.0 / (det * (k0 * k1 - k2 ** 2))
        w00 = (g1 * m00 - g2 * m10) * scale  # adj(G) B adj(G + d B) / (det G det(G + d B))
        w11 = (g0 * m11 - g2 * m01) * scale
        w01 = 0.5 * ((g1 * m01 - g2 * m11) + (g0 * m10 - g2 * m00)) * scale
        for j in range(3):
            v0 = w00 * J[p, 0, j] + w01 * J[p, 1, j]
            v1 = w01 * J[p, 0, j] + w11 * J[p, 1, j]
            for i in range(3):
                H[p, i, j] = J[p, 0, i] * v0 + J[p, 1, i] * v1


def shape_operators(J, S, n, d):
    """H0 (I + d H0)^-1 of surfaces at distance d (docs/tools.md), from the derivatives J (X_u,
    X_v) and S (X_uu, X_vv, X_uv) and the normals n: with G = J J^T, B_ab = -n . X_ab and A =
    G^-1 J (the dual basis; A J^T = I) it is J^T W J, W = G^-1 B (G + d B)^-1 (2 x 2, symmetric):
    H0 (I + d H0)^-1 = A^T B (I + d A A^T B)^-1 A and A A^T = G^-1. Returns H and where G is
    regular (H is left 0 where it is singular: a pole)."""
    H, regular = np.zeros((len(d), 3, 3)), np.empty(len(d), dtype=np.bool_)
    _shape_operators(np.ascontiguousarray(J, dtype=float), np.ascontiguousarray(S, dtype=float),
                     np.ascontiguousarray(n, dtype=float), np.ascontiguousarray(d, dtype=float), H, regular)
    return H, regular
