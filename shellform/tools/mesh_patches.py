"""The closest points on Nagata patches, compiled (numba): the projections, the flat triangles'
bounds, the mesh tool's warm start, search and signed passes over a call's points (mesh_tool.py).

Compiled. The projections (Newton on a patch, the edge curves), the flat triangles' distances,
the warm start's and the search's bounds over each point's list and the signed answers are
loops compiled by numba, one call of each a tool call (numpy's cost per operation, some 500
array operations a call of 60 points, was most of a call's time: docs/tools.md). The k-d trees'
queries, a search's pairs and the patches' H (surface_geometry.distance_hessian) stay numpy's
and scipy's. The first use in a process compiles them (about 9 s CPU) unless shellform's numba
cache holds them (shellform._jit; loaded from it, 0.2 s).
"""

import numpy as np

from shellform._jit import njit

NEWTON_ITERATIONS = 30  # the most Newton iterations of a projection
TIE = 1e-9  # times the tool's size: a warm start's point is this much nearer than every other patch

_EDGE_START = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0]])  # (u, v) at each edge's start
_EDGE_DIRECTION = np.array([[1.0, 0.0], [-1.0, 1.0], [0.0, 1.0]])  # d(u, v)/ds along each edge
_EDGE_CORNERS = np.array([[0, 1], [1, 2], [0, 2]])  # each edge's corners


# -- the closest points, compiled (numba: a call's few loops instead of hundreds of numpy
# operations on a few hundred rows). A patch is A (6, 3), a_0 .. a_5; its flat triangle P (3, 3).


@njit
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit
def _at(A, u, v, X, Xu, Xv):
    """X, X_u, X_v of patch A at (u, v), into X, Xu, Xv (3)."""
    for k in range(3):
        X[k] = A[0, k] + A[1, k] * u + A[2, k] * v + A[3, k] * u * u + A[4, k] * v * v + A[5, k] * u * v
        Xu[k] = A[1, k] + 2.0 * A[3, k] * u + A[5, k] * v
        Xv[k] = A[2, k] + 2.0 * A[4, k] * v + A[5, k] * u


@njit
def _distance(y, X):
    return np.sqrt((y[0] - X[0]) ** 2 + (y[1] - X[1]) ** 2 + (y[2] - X[2]) ** 2)


@njit
def _sub(a, b):
    return a[0] - b[0], a[1] - b[1], a[2] - b[2]


@njit
def _less(a, s, b):
    """a - s b of three-vectors."""
    return a[0] - s * b[0], a[1] - s * b[1], a[2] - s * b[2]


@njit  # a division by 0 gives inf or nan (_jit.OPTIONS)
def _flat(y, P):
    """The closest point's barycentric (u, v) on the flat triangle P and the distance to it:
    the plane's foot point where it lies inside, else the nearest of the three edges' (clamped
    to the edge; the first of equals)."""
    e1, e2, w = _sub(P[1], P[0]), _sub(P[2], P[0]), _sub(y, P[0])
    g11, g12, g22, r1, r2 = _dot(e1, e1), _dot(e1, e2), _dot(e2, e2), _dot(w, e1), _dot(w, e2)
    det = g11 * g22 - g12 * g12
    u = (g22 * r1 - g12 * r2) / det
    v = (g11 * r2 - g12 * r1) / det
    if u >= 0.0 and v >= 0.0 and u + v <= 1.0:
        r = _less(_less(w, u, e1), v, e2)
        return u, v, np.sqrt(_dot(r, r))
    best_u, best_v, dist = 0.0, 0.0, np.inf
    for e in range(3):
        q0 = P[_EDGE_CORNERS[e, 0]]
        s = _sub(P[_EDGE_CORNERS[e, 1]], q0)
        w = _sub(y, q0)
        t = min(max(_dot(w, s) / _dot(s, s), 0.0), 1.0)
        r = _less(w, t, s)
        dd = np.sqrt(_dot(r, r))
        if dd < dist:
            dist, best_u, best_v = dd, _EDGE_START[e, 0] + _EDGE_DIRECTION[e, 0] * t, \
                _EDGE_START[e, 1] + _EDGE_DIRECTION[e, 1] * t
    return best_u, best_v, dist


@njit  # a division by 0 gives inf or nan (_jit.OPTIONS)
def _newton(A, y, u, v, X, Xu, Xv):
    """Newton on patch A from (u, v) for the minimiser of |X - y|^2 (the Hessian J^T J + (X - y)
    . X_ij, or J^T J where that is not positive): (u, v) and whether it converged inside the
    triangle (within 1e-10; then clamped onto it). A step that leaves u, v >= -1, u + v <= 2
    stops it (the edges decide)."""
    converged = False
    for _ in range(NEWTON_ITERATIONS):
        _at(A, u, v, X, Xu, Xv)
        g0 = g1 = guu = guv = gvv = huu = hvv = huv = 0.0
        for k in range(3):
            r = X[k] - y[k]
            g0 += Xu[k] * r
            g1 += Xv[k] * r
            guu += Xu[k] * Xu[k]
            guv += Xu[k] * Xv[k]
            gvv += Xv[k] * Xv[k]
            huu += r * (2.0 * A[3, k])
            hvv += r * (2.0 * A[4, k])
            huv += r * A[5, k]
        huu, hvv, huv = guu + huu, gvv + hvv, guv + huv
        det = huu * hvv - huv * huv
        if det <= 1e-12 * (guu * gvv) or huu <= 0.0:
            huu, hvv, huv = guu, gvv, guv
            det = huu * hvv - huv * huv
        du = -(hvv * g0 - huv * g1) / det
        dv = -(huu * g1 - huv * g0) / det
        u += du
        v += dv
        if abs(du) + abs(dv) < 1e-13:
            converged = True
            break
        if u < -1.0 or v < -1.0 or u + v > 2.0:
            break
    eps = 1e-10
    if converged and u >= -eps and v >= -eps and u + v <= 1.0 + eps:
        return min(max(u, 0.0), 1.0), min(max(v, 0.0), 1.0), True
    return u, v, False


@njit
def _edge_curve(A, k, u0, v0, du, dv, y):
    """Component k of the edge curve's x(s) - y = Q0 + Q1 s + Q2 s^2 from (u0, v0) along (du, dv)."""
    return A[0, k] + A[1, k] * u0 + A[2, k] * v0 + A[3, k] * (u0 * u0) + A[4, k] * (v0 * v0) \
        + A[5, k] * (u0 * v0) - y[k], \
        (A[1, k] + 2.0 * A[3, k] * u0 + A[5, k] * v0) * du + (A[2, k] + 2.0 * A[4, k] * v0 + A[5, k] * u0) * dv, \
        A[3, k] * (du * du) + A[4, k] * (dv * dv) + A[5, k] * (du * dv)


@njit  # a division by 0 gives inf or nan (_jit.OPTIONS)
def _edge_curves(A, P, y, X, Xu, Xv):
    """The nearest point on patch A's three edge curves (0: u-axis, 1: u + v = 1, 2: v-axis):
    on each, Newton in its parameter s from the flat edge's closest point, clamped to [0, 1],
    on the cubic (x(s) - y) . x'(s) (x(s) = Q0 + Q1 s + Q2 s^2; x'(s) . x'(s) its derivative
    where that is not positive). Returns the nearest edge's (u, v), distance and edge (the
    first of equals)."""
    best_u, best_v, best, edge = 0.0, 0.0, np.inf, -1
    for e in range(3):
        u0, v0 = _EDGE_START[e, 0], _EDGE_START[e, 1]
        du, dv = _EDGE_DIRECTION[e, 0], _EDGE_DIRECTION[e, 1]
        a = P[_EDGE_CORNERS[e, 0]]
        d = _sub(P[_EDGE_CORNERS[e, 1]], a)
        s = min(max(_dot(_sub(y, a), d) / _dot(d, d), 0.0), 1.0)
        qx, qy, qz = _edge_curve(A, 0, u0, v0, du, dv, y), _edge_curve(A, 1, u0, v0, du, dv, y), \
            _edge_curve(A, 2, u0, v0, du, dv, y)
        Q0, Q1, Q2 = (qx[0], qy[0], qz[0]), (qx[1], qy[1], qz[1]), (qx[2], qy[2], qz[2])
        c0, c1 = _dot(Q0, Q1), _dot(Q1, Q1) + 2.0 * _dot(Q0, Q2)
        c2, c3 = 3.0 * _dot(Q1, Q2), 2.0 * _dot(Q2, Q2)
        ff0 = _dot(Q1, Q1)
        for _ in range(NEWTON_ITERATIONS):
            g = c0 + s * (c1 + s * (c2 + s * c3))
            h = c1 + s * (2.0 * c2 + 3.0 * c3 * s)
            ff = ff0 + s * (4.0 * c2 / 3.0 + 2.0 * c3 * s)  # |x'|^2
            new = min(max(s - g / (h if h > 0 else ff), 0.0), 1.0)
            done = abs(new - s) < 1e-13
            s = new
            if done:
                break
        u, v = u0 + du * s, v0 + dv * s
        _at(A, u, v, X, Xu, Xv)
        dist = _distance(y, X)
        if dist < best:
            best_u, best_v, best, edge = u, v, dist, e
    return best_u, best_v, best, edge


@njit
def _exact(A, P, y, u, v, X, Xu, Xv):
    """The nearest point of y on patch A (flat triangle P): Newton from (u, v); the edge curves
    where the minimiser leaves the triangle. Its (u, v), distance and kind (-1 inside, 0, 1, 2
    the edge)."""
    u, v, inside = _newton(A, y, u, v, X, Xu, Xv)
    if inside:
        _at(A, u, v, X, Xu, Xv)
        return u, v, _distance(y, X), -1
    return _edge_curves(A, P, y, X, Xu, Xv)


@njit
def _nearer(dist, t, best, best_t):
    """Whether patch t at dist is nearer than the best so far (ties: the lesser patch)."""
    return dist < best or (dist == best and t < best_t)


@njit  # a division by 0 gives inf or nan (_jit.OPTIONS)
def _warm_pass(y, delta, ref, last_y, last_c, last_t, last_u, last_v, last_kind, last_dist, last_rest, start,
               length, near, bound, patches, corners, centre, radius, bulge, size):
    """Points y moved by delta from the remembered points ref: their closest points from the
    remembered lists (module docstring; last_* the remembered points' y, closest points, patches,
    (u, v), kinds, distances and R, their lists `length` pairs (near, bound) from `start`; size
    the tool's); a point given again (delta 0) its remembered answer and list. Returns which
    were found; their patches, (u, v), kinds, distances and R - delta; their lists: patches,
    lower bounds (one pool), each found point's start and length in it."""
    n = len(y)
    found = np.zeros(n, dtype=np.bool_)
    t_out, kind_out = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
    u_out, v_out, dist_out, rest_out = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    total = 0
    for i in range(n):
        total += length[ref[i]]
    near_out, bound_out = np.empty(total, dtype=np.int64), np.empty(total)
    start_out, length_out = np.zeros(n, dtype=np.int64), np.zeros(n, dtype=np.int64)
    X, Xu, Xv = np.empty(3), np.empty(3), np.empty(3)
    at = 0
    for i in range(n):
        r, moved = ref[i], delta[i]
        rest = last_rest[r] - moved  # the distance is 1-Lipschitz
        if moved == 0.0:  # given again: its answer and list
            found[i] = True
            t_out[i], u_out[i], v_out[i], kind_out[i], dist_out[i], rest_out[i] = last_t[r], last_u[r], last_v[r], \
                last_kind[r], last_dist[r], rest
            near_out[at:at + length[r]] = near[start[r]:start[r] + length[r]]
            bound_out[at:at + length[r]] = bound[start[r]:start[r] + length[r]]
            start_out[i], length_out[i] = at, length[r]
            at += length[r]
            continue
        upper = _distance(y[i], last_c[r])  # the remembered closest point lies on the surface
        if not upper <= rest - TIE * size:  # a patch outside the list may be nearer: searched
            continue
        limit = upper * (1 + 1e-12) + 1e-12 * size
        step = _sub(y[i], last_y[r])
        best, best_t, best_u, best_v, best_kind = np.inf, -1, 0.0, 0.0, -1
        for j in range(length[r]):
            k = near[start[r] + j]
            lower = bound[start[r] + j] - moved
            if lower <= limit:
                u, v = last_u[r], last_v[r]
                if k != last_t[r]:  # the cone from the remembered point to the patch's sphere
                    w = _sub(centre[k], last_y[r])
                    far = np.sqrt(_dot(w, w))
                    sin_a = min(radius[k] / far, 1.0)
                    cos_p = min(max(_dot(w, step) / (far * moved), -1.0), 1.0)
                    cos_a = np.sqrt(1.0 - sin_a * sin_a)
                    toward = 1.0
                    if not (cos_p >= cos_a or far <= radius[k]):
                        toward = cos_p * cos_a + np.sqrt(1.0 - cos_p * cos_p) * sin_a
                    lower = max(lower, bound[start[r] + j] - moved * toward)
                    if lower <= limit:  # the flat triangle's distance less the bulge
                        u, v, flat = _flat(y[i], corners[k])
                        lower = max(lower, flat - bulge[k])
                if lower <= limit:  # a candidate: projected
                    u, v, lower, kind = _exact(patches[k], corners[k], y[i], u, v, X, Xu, Xv)
                    if _nearer(lower, k, best, best_t):
                        best, best_t, best_u, best_v, best_kind = lower, k, u, v, kind
            near_out[at + j], bound_out[at + j] = k, lower
        if best_t < 0:
            continue
        found[i] = True
        t_out[i], u_out[i], v_out[i], kind_out[i], dist_out[i], rest_out[i] = best_t, best_u, best_v, best_kind, \
            best, rest
        start_out[i], length_out[i] = at, length[r]
        at += length[r]
    return found, t_out, u_out, v_out, kind_out, dist_out, rest_out, near_out[:at], bound_out[:at], start_out, \
        length_out


@njit
def _upper_bounds(y, near, corners, bulge):
    """Each point's least upper bound (flat distance plus bulge) over the patches `near` (points,
    k)."""
    n, k = near.shape
    upper = np.full(n, np.inf)
    for i in range(n):
        for j in range(k):
            t = near[i, j]
            upper[i] = min(upper[i], _flat(y[i], corners[t])[2] + bulge[t])
    return upper


@njit
def _search_pass(y, p, t, upper, rest, patches, corners, bulge, size):
    """The search's pairs (point p, patch t; by point): each pair's lower bound the flat
    distance less the bulge, kept where it lies within the point's rest; the candidates (lower
    bound within upper) projected, their distances their bounds. Returns the points' closest
    patches, (u, v), kinds and distances, and their lists (patches, lower bounds, start,
    length)."""
    n = len(y)
    t_out, kind_out = np.full(n, -1, dtype=np.int64), np.zeros(n, dtype=np.int64)
    u_out, v_out, dist_out = np.zeros(n), np.zeros(n), np.full(n, np.inf)
    near_out, bound_out = np.empty(len(p), dtype=np.int64), np.empty(len(p))
    length = np.zeros(n, dtype=np.int64)
    X, Xu, Xv = np.empty(3), np.empty(3), np.empty(3)
    at = 0
    for q in range(len(p)):
        i, k = p[q], t[q]
        u, v, flat = _flat(y[i], corners[k])
        lower = flat - bulge[k]
        if not lower <= rest[i]:
            continue
        if lower <= upper[i] * (1 + 1e-12) + 1e-12 * size:
            u, v, lower, kind = _exact(patches[k], corners[k], y[i], u, v, X, Xu, Xv)
            if _nearer(lower, k, dist_out[i], t_out[i]):
                t_out[i], u_out[i], v_out[i], kind_out[i], dist_out[i] = k, u, v, kind, lower
        near_out[at], bound_out[at] = k, lower
        length[i] += 1
        at += 1
    return t_out, u_out, v_out, kind_out, dist_out, near_out[:at], bound_out[:at], np.cumsum(length) - length, length


@njit  # a division by 0 gives inf or nan (_jit.OPTIONS)
def _signed_pass(y, t, u, v, kind, patches, sign, tiny, c, d, n, H, J, S):
    """Closest points c, signed distances d, normals n at the closest points (u, v) of patches t;
    H on the edge curves (kind 0, 1, 2: the curve's, (I - n n^T - x' x'^T / (|x'|^2 - (y - c)
    . x'')) / d; at a vertex (I - n n^T) / d; 0 within `tiny` of the curve), and J, S (X_u, X_v;
    X_uu, X_vv, X_uv) for the patches' H of the points inside (kind -1)."""
    Xu, Xv = np.empty(3), np.empty(3)
    for i in range(len(y)):
        A = patches[t[i]]
        _at(A, u[i], v[i], c[i], Xu, Xv)
        for k in range(3):
            J[i, 0, k], J[i, 1, k] = Xu[k], Xv[k]
            S[i, 0, k], S[i, 1, k], S[i, 2, k] = 2.0 * A[3, k], 2.0 * A[4, k], A[5, k]
        nc = (Xu[1] * Xv[2] - Xu[2] * Xv[1], Xu[2] * Xv[0] - Xu[0] * Xv[2], Xu[0] * Xv[1] - Xu[1] * Xv[0])
        norm = max(np.sqrt(_dot(nc, nc)), 1e-300)
        nc = (sign * nc[0] / norm, sign * nc[1] / norm, sign * nc[2] / norm)
        r = _sub(y[i], c[i])
        dist = np.sqrt(_dot(r, r))
        d[i] = _dot(r, nc)
        for k in range(3):
            n[i, k] = nc[k]
        if kind[i] < 0:
            continue
        s = -1.0 if d[i] < 0.0 else 1.0
        far = dist > tiny
        d[i] = s * dist
        if far:
            for k in range(3):
                n[i, k] = s * r[k] / dist
        du, dv = _EDGE_DIRECTION[kind[i], 0], _EDGE_DIRECTION[kind[i], 1]
        first = (Xu[0] * du + Xv[0] * dv, Xu[1] * du + Xv[1] * dv, Xu[2] * du + Xv[2] * dv)
        w0, w1, w2 = du * du, dv * dv, 2 * du * dv
        second = (w0 * S[i, 0, 0] + w1 * S[i, 1, 0] + w2 * S[i, 2, 0], w0 * S[i, 0, 1] + w1 * S[i, 1, 1]
                  + w2 * S[i, 2, 1], w0 * S[i, 0, 2] + w1 * S[i, 1, 2] + w2 * S[i, 2, 2])
        position = u[i] if kind[i] == 0 else v[i]
        vertex = position <= 0.0 or position >= 1.0
        ff = _dot(first, first)
        stiff = max(ff - _dot(r, second), 1e-12 * ff)
        scale = d[i] if far else np.inf
        for a in range(3):
            for b in range(3):
                P = (1.0 if a == b else 0.0) - n[i, a] * n[i, b]
                if not vertex:
                    P = P - first[a] * first[b] / stiff
                H[i, a, b] = P / scale

