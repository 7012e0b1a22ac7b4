"""Elementary faces of a CAD tool evaluated from their parameters, without gmsh (docs/tools.md,
"How a surface is evaluated").

A CAD tool's faces are mostly OpenCASCADE's elementary surfaces: planes, cylinders, tori,
spheres and surfaces of revolution of a circle arc (a fillet's corner). Each kind's class holds
the faces of that kind of one tool, their geometric parameters fitted once from gmsh's
evaluations of the face (gmsh names the surface's kind, not its parameters) and verified
against gmsh's point, first and second derivatives at the face's samples: a face whose
parametrisation is not the one fitted is refused (`add` returns False) and left to gmsh.

For points y and faces j of the kind (pairs: an index of a face of the kind per point):

    nearest(y, j)         the nearest point of face j's parameter rectangle to y in closed form:
                          its parameters, its distance, and whether it lies inside the
                          rectangle (within `tol` of each bound: the parameters are then the
                          untrimmed surface's foot point, which may lie up to `tol` outside),
                          not clamped onto its boundary;
    derivatives(j, uv)    the point X and its derivatives J = (X_u, X_v), S = (X_uu, X_vv, X_uv)
                          of face j (an index per point) at parameters uv, as gmsh orders them.

The nearest point is exact where the face fills its parameter rectangle (a trimmed face's
projection must be checked against its trim by the tool). Planes, cylinders and revolutions of
a circle do both in loops compiled by numba over the pairs (face_kernels.py; their parameters
rows of one array, in each kind's LAYOUT); a curve meridian's Newton calls gmsh. Compiled there
too: the pairs of points and boxes within reach (within) and the distance's Hessian from a
face's derivatives (shape_operators).
"""

import numpy as np

from shellform.tools.face_kernels import (  # noqa: F401  (cross, within, shape_operators: the tools')
    TWO_PI, cross, shape_operators, within, _arc, _close, _cylinders_derivatives, _cylinders_nearest,
    _planes_derivatives, _planes_nearest, _revolutions_derivatives, _revolutions_nearest,
)

MERIDIAN_SAMPLES = 1024  # points of a curve meridian whose angles about its fitted circle start Newton


def _axis_frame(middle, size: float):
    """A surface of revolution's axis and radial frame from gmsh's (u, v), X, J, S at a point
    off the axis (rho > 1e-9 size): rho, the radial unit w = -X_uu / rho and the tangential
    b = X_u / rho, the axis a = w x b, the centre A of the parallel through the point, and the
    radial frame (w0, b0) at u = 0; None where the point is on the axis or (w, b, a) is not
    orthonormal to round-off."""
    (um, _), Xm, Jm, Sm = middle
    rho = float(np.linalg.norm(Sm[0]))
    if not rho > 1e-9 * size:
        return None
    w, b = -Sm[0] / rho, Jm[0] / rho
    a = np.cross(w, b)
    if not _close(np.array([w, b, a]) @ np.array([w, b, a]).T, np.eye(3), 1e-12):
        return None
    A = Xm + Sm[0]  # the centre of the parallel through Xm, on the axis
    w0, b0_ = np.cos(um) * w - np.sin(um) * b, np.sin(um) * w + np.cos(um) * b
    return rho, w, b, a, A, w0, b0_


class _Kind:
    """The faces of one kind: their indices in the tool (`index`), parameter bounds and
    tolerances, and each kind's parameters (arrays with the face first)."""

    def __init__(self, size: float):
        self.size = size
        self.index, self.b0, self.b1, self.tol, self._params = [], [], [], [], []

    def __len__(self):
        return len(self.index)

    def _keep(self, index, b0, b1, params, X, J, S, uv, model=None) -> bool:
        """Keeps the face where the fitted parametrisation (`model`: X, J, S at uv; this kind's
        derivatives unless given) gives gmsh's X, J and S at its samples uv to round-off (1e-12
        of the tool's size, the derivatives of their own size)."""
        self._params.append(params)
        self.index.append(index)
        self.b0.append(np.asarray(b0, dtype=float))
        self.b1.append(np.asarray(b1, dtype=float))
        self.tol.append(1e-9 * (np.asarray(b1, dtype=float) - b0 + 1.0))
        self._stack()
        Xf, Jf, Sf = model if model is not None else self.derivatives(np.full(len(uv), len(self) - 1), uv)
        scale = max(np.abs(J).max(initial=0.0), np.abs(S).max(initial=0.0), 1.0)
        if _close(Xf, X, 1e-12 * self.size) and _close(Jf, J, 1e-12 * scale) and _close(Sf, S, 1e-12 * scale):
            return True
        for rows in (self._params, self.index, self.b0, self.b1, self.tol):
            rows.pop()
        self._stack()
        return False

    def _stack(self):
        self.lo, self.hi, self.eps = (np.array(v).reshape(-1, 2) for v in (self.b0, self.b1, self.tol))
        self.p = {k: np.array([q[k] for q in self._params]) for k in (self._params[0] if self._params else ())
                  if k not in ("theta", "v")}
        self.p.update(lo=self.lo, hi=self.hi, eps=self.eps)
        # every face's parameters in one row, gathered for pairs by one index (_gather)
        self._packed = np.hstack([v.reshape(len(self.lo), -1) for v in self.p.values()]) if self._params else None
        ends = np.cumsum([0] + [int(np.prod(v.shape[1:])) for v in self.p.values()])
        self._slices = [(k, slice(a, b), v.shape[1:]) for (k, v), a, b in zip(self.p.items(), ends[:-1], ends[1:])]

        if self._params and self.LAYOUT is not None:  # the compiled kernels' columns
            assert [(k, cut.start) for k, cut, _ in self._slices] == list(self.LAYOUT.items()), self._slices

    LAYOUT = None  # name -> first column of the packed rows, for the compiled kernels
    KERNELS = None  # (nearest, derivatives) compiled

    def _gather(self, j):
        """The parameters of faces j (one per pair): name -> array (pairs, ...)."""
        rows = self._packed[j]
        return {k: rows[:, cut].reshape((len(j),) + shape) for k, cut, shape in self._slices}

    def nearest(self, y, j):
        n = len(j)
        uv, d, inside = np.empty((n, 2)), np.empty(n), np.empty(n, dtype=np.bool_)
        self.KERNELS[0](np.ascontiguousarray(y), np.asarray(j, dtype=np.int64), self._packed, uv, d, inside)
        return uv, d, inside

    def derivatives(self, j, uv):
        n = len(j)
        X, J, S = np.empty((n, 3)), np.empty((n, 2, 3)), np.empty((n, 3, 3))
        self.KERNELS[1](np.asarray(j, dtype=np.int64), np.ascontiguousarray(uv, dtype=float), self._packed, X, J, S)
        return X, J, S


class Planes(_Kind):
    """Planes X = O + u E_u + v E_v, E_u and E_v orthonormal (OCC's planes). The nearest point
    of the rectangle [u0, u1] x [v0, v1] is X at the clamped (E . (y - O)): the rectangle's
    sides are orthogonal. A trimmed plane is given infinite bounds: the foot point of the
    plane."""

    LAYOUT = {"O": 0, "E": 3, "lo": 9, "hi": 11, "eps": 13}
    KERNELS = (_planes_nearest, _planes_derivatives)

    def add(self, index, b0, b1, X, J, S, uv) -> bool:
        E = J[0]
        if not _close(E @ E.T, np.eye(2), 1e-12) or not _close(J, E, 1e-12 * np.abs(E).max()):
            return False
        O = X[0] - uv[0] @ E
        return self._keep(index, b0, b1, {"O": O, "E": E}, X, J, S, uv)

class Cylinders(_Kind):
    """Cylinders X = O + R (cos u E_x + sin u E_y) + v E_z, E orthonormal (OCC's cylinders), an
    arc u in [u0, u1] times a segment v in [v0, v1]: the nearest point's u is the arc's nearest
    angle to y's angle about the axis, its v y's height clamped."""

    LAYOUT = {"O": 0, "E": 3, "R": 12, "lo": 13, "hi": 15, "eps": 17}
    KERNELS = (_cylinders_nearest, _cylinders_derivatives)

    def add(self, index, b0, b1, X, J, S, uv, origin) -> bool:
        """origin: gmsh's X, J, S at (u, v) = (0, 0), from which E and R are read."""
        X0, J0, S0 = origin
        R = float(np.linalg.norm(S0[0]))
        if not R > 1e-9 * self.size or b1[0] - b0[0] > TWO_PI + 1e-12:
            return False
        E = np.array([-S0[0] / R, J0[0] / R, J0[1]])
        if not _close(E @ E.T, np.eye(3), 1e-12):
            return False
        return self._keep(index, b0, b1, {"O": X0 - R * E[0], "E": E, "R": R}, X, J, S, uv)

class Revolutions(_Kind):
    """Surfaces swept by a circle arc turning about an axis in the arc's plane: tori, spheres and
    OCC's surfaces of revolution of a circle (a fillet's corner). With A a point of the axis,
    a its direction, w(u) = cos u w_0 + sin u b_0 (b_0 = a x w_0) the radial direction at the
    turn u, and the meridian arc (rho(v), h(v)) = c + r (cos v f_1 + sin v f_2) in the
    half-plane (w, a),

        X(u, v) = A + rho(v) w(u) + h(v) a.

    Where rho >= 0 on the arc (it does not cross the axis), |X - y|^2 = rho_y^2 + rho^2 -
    2 rho_y rho cos(u - phi_y) + (h_y - h)^2 (y at radius rho_y, angle phi_y and height h_y):
    for every v the nearest u is the arc's nearest angle to phi_y, whatever v. In the half-plane
    of that u, y lies at (rho_y cos(u - phi_y), h_y) and rho_y sin(u - phi_y) out of it, and the
    nearest v is the meridian arc's nearest angle to y's angle about the circle's centre c."""

    LAYOUT = {"A": 0, "a": 3, "w0": 6, "b0": 9, "frame": 12, "c": 21, "r": 23, "f1": 24, "f2": 26, "lo": 28, "hi": 30,
              "eps": 32}
    KERNELS = (_revolutions_nearest, _revolutions_derivatives)

    def add(self, index, b0, b1, X, J, S, uv, middle) -> bool:
        """middle: gmsh's (u, v), X, J, S at a point where the face is not on the axis (rho >
        0), from which the axis, the radial frame and the meridian circle are read: X_uu = -rho
        w, X_u = rho b, and the meridian's (rho, h)'' = -((rho, h) - c)."""
        (_, vm), _, Jm, Sm = middle
        axis = _axis_frame(middle, self.size)
        if axis is None:
            return False
        rho, w, b, a, A, w0, b0_ = axis
        p, dp, ddp = np.array([rho, 0.0]), Jm[1] @ np.array([w, a]).T, Sm[1] @ np.array([w, a]).T
        r = float(np.linalg.norm(ddp))
        if not r > 1e-9 * self.size:
            return False
        c = p + ddp
        f1 = (np.cos(vm) * (p - c) - np.sin(vm) * dp) / r
        f2 = (np.sin(vm) * (p - c) + np.cos(vm) * dp) / r
        if not _close(np.array([f1, f2]) @ np.array([f1, f2]).T, np.eye(2), 1e-12):
            return False
        # the meridian arc stays on one side of the axis: rho(v) >= 0 at its ends and extremes
        psi = np.arctan2(f2[0], f1[0])  # rho(v) = c_0 + m cos(v - psi)
        m = np.hypot(f1[0], f2[0]) * r
        v = np.array([b0[1], b1[1]])
        v = np.concatenate([v, psi + np.pi + TWO_PI * np.arange(np.ceil((b0[1] - psi - np.pi) / TWO_PI),
                                                                np.floor((b1[1] - psi - np.pi) / TWO_PI) + 1)])
        if np.min(c[0] + m * np.cos(v - psi)) < -1e-12 * self.size or b1[0] - b0[0] > TWO_PI + 1e-12 \
                or b1[1] - b0[1] > TWO_PI + 1e-12:
            return False
        params = {"A": A, "a": a, "w0": w0, "b0": b0_, "frame": np.array([w0, b0_, a]), "c": c, "r": r, "f1": f1,
                  "f2": f2}
        return self._keep(index, b0, b1, params, X, J, S, uv)

class CurveRevolutions(_Kind):
    """Surfaces of revolution whose meridian is not a circle (OCC's surfaces of revolution of a
    B-spline: a fillet's corner written to STEP, whose meridian approximates a circle), X(u, v)
    = A + rho(v) w(u) + h(v) a as for Revolutions, the meridian (rho, h)(v) evaluated by gmsh:
    `evaluate(j, uv)` gives X, J, S of face j at parameters uv.

    Where rho >= 0 the nearest u is the arc's nearest angle to y's, whatever v (Revolutions);
    along that meridian Newton minimises |X(u, v) - y|^2 over v, from the v of the nearest point
    of the circle fitted to the meridian (v interpolated in the angles about its centre of
    MERIDIAN_SAMPLES points of the meridian; none where that angle lies beyond the meridian's
    ends by more than ten times the meridian's largest departure from the circle in angle:
    the face's nearest point lies on its boundary), until a step moves the point by less than 1e-13
    of the tool's size (the point: the last evaluation plus that step; J and S the last
    evaluation's). A pair whose Newton does not converge inside the face is not inside (its
    distance inf): the face's nearest point lies on its boundary. `nearest` also returns the
    pairs' X, J and S (gmsh's evaluations, which `derivatives` would repeat)."""

    def __init__(self, size: float, evaluate):
        super().__init__(size)
        self.evaluate = evaluate

    def add(self, index, b0, b1, X, J, S, uv, middle, meridian) -> bool:
        """middle: gmsh's (u, v), X, J, S at the face's middle (the axis and the radial frame,
        as for Revolutions); meridian: gmsh's X, J, S at (u_m, v) for the samples' v. Kept where
        the surface is the meridian turned about the axis by u at the samples, to round-off.
        The start's table from the meridian at MERIDIAN_SAMPLES values of v (evaluate)."""
        um = middle[0][0]
        axis = _axis_frame(middle, self.size)
        if axis is None:
            return False
        _, w, b, a, A, w0, b0_ = axis
        frame = np.array([w0, b0_, a])
        Xr, Jr, Sr = meridian
        wa = np.array([w, a])
        # the meridian's (rho, h) at the samples and its v-derivatives
        P, dP, ddP = (np.einsum("pi,ki->pk", V, wa) for V in (Xr - A, Jr[:, 1], Sr[:, 1]))
        if np.min(P[:, 0]) < 0.0 or b1[0] - b0[0] > TWO_PI + 1e-12:
            return False
        cu, su = np.cos(uv[:, :1]), np.sin(uv[:, :1])
        wu, bu = cu * w0 + su * b0_, -su * w0 + cu * b0_
        model = (A + P[:, :1] * wu + P[:, 1:] * a,
                 np.stack([P[:, :1] * bu, dP[:, :1] * wu + dP[:, 1:] * a], axis=1),
                 np.stack([-P[:, :1] * wu, ddP[:, :1] * wu + ddP[:, 1:] * a, dP[:, :1] * bu], axis=1))
        # the circle nearest the meridian's samples (|P - c|^2 = r^2: linear in c and r^2 - |c|^2)
        sol = np.linalg.lstsq(np.c_[2.0 * P, np.ones(len(P))], np.einsum("pk,pk->p", P, P), rcond=None)[0]
        c = sol[:2]
        r = float(np.sqrt(sol[2] + c @ c))
        if not np.abs(np.linalg.norm(P - c, axis=1) - r).max() <= 1e-3 * r:
            return False
        v = np.linspace(b0[1], b1[1], MERIDIAN_SAMPLES)
        Xq, Jq, _ = self.evaluate(index, np.c_[np.full(len(v), um), v])
        Q, dQ = np.einsum("pi,ki->pk", Xq - A, wa), np.einsum("pi,ki->pk", Jq[:, 1], wa)
        theta = np.arctan2(Q[:, 1] - c[1], Q[:, 0] - c[0])
        # how far the angle about c of a point's foot may lie from its own: the meridian's
        # distance from the circle over r and the angle between its tangent and the circle's
        radial = (Q - c) / np.linalg.norm(Q - c, axis=1)[:, None]
        slope = np.abs(np.einsum("pk,pk->p", dQ, radial)) / np.linalg.norm(dQ, axis=1)
        slack = 10.0 * (np.abs(np.linalg.norm(Q - c, axis=1) - r).max() / r + slope.max()) + 1e-9
        mid = theta[len(theta) // 2]
        theta = np.mod(theta - mid + np.pi, TWO_PI) - np.pi  # about the middle sample's angle
        order = np.argsort(theta)
        if np.any(np.diff(v[order]) * np.sign(v[order][-1] - v[order][0]) <= 0):  # v monotone in the angle
            return False
        params = {"A": A, "frame": frame, "c": c, "mid": mid, "slack": slack, "theta": theta[order], "v": v[order]}
        return self._keep(index, b0, b1, params, X, J, S, uv, model)

    def _stack(self):
        super()._stack()
        self.samples = [(q["theta"], q["v"]) for q in self._params]  # per face, of their own lengths

    def derivatives(self, j, uv):
        X, J, S = np.zeros((len(j), 3)), np.zeros((len(j), 2, 3)), np.zeros((len(j), 3, 3))
        for f in np.unique(j):
            rows = np.flatnonzero(j == f)
            X[rows], J[rows], S[rows] = self.evaluate(self.index[f], uv[rows])
        return X, J, S

    def nearest(self, y, j):
        P = self._gather(j)
        lo, hi, eps = P["lo"], P["hi"], P["eps"]
        q = np.einsum("pi,pki->pk", y - P["A"], P["frame"])
        rho, phi = np.hypot(q[:, 0], q[:, 1]), np.arctan2(q[:, 1], q[:, 0])
        u, on_turn = _arc(phi, lo[:, 0], hi[:, 0], eps[:, 0])
        s = np.stack([rho * np.cos(u - phi), q[:, 2]], axis=1) - P["c"]  # y in the meridian's plane
        theta = np.mod(np.arctan2(s[:, 1], s[:, 0]) - P["mid"] + np.pi, TWO_PI) - np.pi
        uv = np.stack([u, np.zeros(len(j))], axis=1)
        inside = np.zeros(len(j), dtype=bool)
        X, J, S = np.zeros((len(j), 3)), np.zeros((len(j), 2, 3)), np.zeros((len(j), 3, 3))
        for f in np.unique(j):
            angles, v = self.samples[f]
            rows = np.flatnonzero(j == f)
            # a foot beyond the meridian's ends (more than the slack): the face's nearest point on its boundary
            rows = rows[(theta[rows] >= angles[0] - P["slack"][rows]) & (theta[rows] <= angles[-1] + P["slack"][rows])]
            start = np.c_[u[rows], np.interp(theta[rows], angles, v)]
            X[rows], J[rows], S[rows], inside[rows] = self._newton(f, start, y[rows])
            uv[rows] = start
        uv[:, 1] = np.where(inside, uv[:, 1], np.clip(uv[:, 1], lo[:, 1], hi[:, 1]))
        r = X - y
        d = np.where(inside, np.sqrt(np.einsum("pi,pi->p", r, r)), np.inf)
        return uv, d, inside & on_turn, (X, J, S)

    def _newton(self, f, uv, y, iterations=8):
        """Newton along v (u fixed) on face f from uv (modified in place) towards y: the points
        X (the last evaluation plus its step), the last evaluation's J and S, and where it
        converged within the face's v bounds."""
        n = len(y)
        ok, todo = np.zeros(n, dtype=bool), np.arange(n)
        Xo, Jo, So = np.zeros((n, 3)), np.zeros((n, 2, 3)), np.zeros((n, 3, 3))
        for _ in range(iterations):
            X, J, S = self.evaluate(self.index[f], uv[todo])
            r = X - y[todo]
            Xv, Xvv = J[:, 1], S[:, 1]
            g = np.einsum("pi,pi->p", Xv, r)
            A = np.einsum("pi,pi->p", Xv, Xv) + np.einsum("pi,pi->p", Xvv, r)
            good = A > 0
            step = np.where(good, -g / np.where(good, A, 1.0), 0.0)
            uv[todo, 1] += step
            move = Xv * step[:, None]
            Xo[todo], Jo[todo], So[todo] = X + move, J, S
            done = good & (np.einsum("pi,pi->p", move, move) < (1e-13 * self.size) ** 2)
            ok[todo[done]] = True
            todo = todo[~done]
            if todo.size == 0:
                break
        lo, hi, eps = self.lo[f, 1], self.hi[f, 1], self.eps[f, 1]
        return Xo, Jo, So, ok & (uv[:, 1] >= lo - eps) & (uv[:, 1] <= hi + eps)
