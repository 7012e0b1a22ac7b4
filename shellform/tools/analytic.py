"""Rigid analytic tools of the square-cup deep drawing: punch, die and blank holder.

The blank's mid-surface starts in the plane z = 0, centred at the origin; every tool is
symmetric about x = 0, y = 0 and the diagonal. The punch sits above the sheet and moves down,
the die lies below it with a square opening, the blank holder presses the flange from above.

Punch and die are Minkowski sums of a "core" with a ball of the profile radius r, so their
signed distance is  d_core - r : exact outside the tool and for penetrations shallower than r
(deeper points, inside the core, get -r). Each core is a product of a plan set and a vertical
half-line, so  d_core = sqrt(d_plan^2 + d_z^2).  The plans are rounded squares
(rounded_square_sdf). The normal is the gradient of the signed distance, computed
analytically: the unit vector from the nearest tool point towards the point, the direction in
which the tool pushes the sheet.

``gap(x, offset, dz)`` is the signed distance minus ``offset`` (half the sheet thickness at the
node: the sheet's surface lies that far from its mid-surface), with the tool moved by dz along
z: > 0 clear, < 0 penetration. Units mm.

``shape(x, offset, dz)`` is the shape operator of the normal field, H = dn/dx, the Hessian of
the signed distance (the offset, a constant, does not change it): (n, 3, 3), symmetric, H n = 0,
its eigenvalues at x the principal curvatures of the distance's level surface through x (> 0
convex, < 0 concave). Where the distance to the core is D > 0, n = (p - c(p)) / D for the
nearest core point c, and with the core a product set, n = (s grad s, -/+ h) / D in terms of the
plan sdf s and the height h. Differentiating,

    H = (P - n n^T + s Hs) / D,   P = m m^T + e_z e_z^T,   m = grad s (a unit plan vector),

Hs the plan Hessian of s (rounded_square_hessian): P - n n^T = t t^T for the unit t in the
section plane (m, e_z) orthogonal to n (curvature 1/D across the profile), and s Hs = s/(s + rc)
tau tau^T on the plan corner arcs (tau the plan tangent, s + rc the distance to the arc's
centre), 0 along the straight sides. Beside a wall (D = |s|) only the plan term is left; on the
flat faces and inside the core H = 0. On a region boundary H takes the side that ``gap`` takes
for the normal (H jumps there: the curvature of a nose is not that of the face it meets).
"""

from dataclasses import dataclass

import numpy as np

DOWN = np.array([0.0, 0.0, -1.0])  # face normal of the punch and the blank holder
UP = np.array([0.0, 0.0, 1.0])  # face normal of the die


def rounded_square_sdf(x, y, a: float, rc: float):
    """Signed distance to the rounded square |x|, |y| <= a with plan corner radius rc, and its
    gradient (dsdx, dsdy).

    q = (|x| - (a - rc), |y| - (a - rc)),  sdf = |max(q, 0)| + min(max(qx, qy), 0) - rc,
    exact inside and outside. The gradient is max(q, 0)/|max(q, 0)| outside the square of
    half-width a - rc, else the axis of the larger of qx, qy (ties: y), times sign(x), sign(y):
    it is exactly 0 along x on x = 0 and along y on y = 0 (both 0 at the origin, where the
    gradient is undefined).
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    qx, qy = np.abs(x) - (a - rc), np.abs(y) - (a - rc)
    px, py = np.maximum(qx, 0.0), np.maximum(qy, 0.0)
    r = np.sqrt(px * px + py * py)  # distance to the inner square of half-width a - rc
    sdf = r + np.minimum(np.maximum(qx, qy), 0.0) - rc
    out = r > 0.0
    rs = np.where(out, r, 1.0)
    gx = np.where(out, px / rs, qx > qy)  # d sdf / d|x|
    gy = np.where(out, py / rs, qx <= qy)  # d sdf / d|y|
    return sdf, gx * np.sign(x) + 0.0, gy * np.sign(y) + 0.0  # + 0.0: no -0.0


def rounded_square_hessian(x, y, a: float, rc: float):
    """The Hessian of rounded_square_sdf, (n, 3, 3) with zero z row and column.

    On the corner arcs' sectors (both |x|, |y| > a - rc) sdf = r - rc with r = |q| the distance
    to the arc's centre, so Hs = (I - g g^T) / r = tau tau^T / r, g the (signed) gradient and tau
    the plan tangent; elsewhere sdf is linear (the sides) or a maximum of linear functions (inside
    the inner square, kinked on its diagonals): Hs = 0. On a sector's edge (|x| or |y| = a - rc)
    Hs takes the side's value, the side the gradient takes.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    qx, qy = np.abs(x) - (a - rc), np.abs(y) - (a - rc)
    arc = (qx > 0.0) & (qy > 0.0)
    r = np.where(arc, np.sqrt(qx * qx + qy * qy), 1.0)
    _, gx, gy = rounded_square_sdf(x, y, a, rc)
    H = np.zeros(x.shape + (3, 3))
    H[:, 0, 0], H[:, 1, 1], H[:, 0, 1] = gy * gy, gx * gx, -gx * gy
    H[:, 1, 0] = H[:, 0, 1]
    return H * (arc / r)[:, None, None] + 0.0


def _profile_hessian(n, sx, sy, sHs, D):
    """H = (P - n n^T + s Hs) / D at points whose nearest core point lies on the core's rounded
    edge (module docstring): n the normal, (sx, sy) = grad s, sHs = s Hs, D the core distance."""
    m = np.stack([sx, sy, np.zeros_like(sx)], axis=1)
    P = m[:, :, None] * m[:, None, :]
    P[:, 2, 2] = 1.0
    return (P - n[:, :, None] * n[:, None, :] + sHs) / D[:, None, None]


def _points(x, offset):
    x = np.asarray(x, dtype=float).reshape(-1, 3)
    return x, np.broadcast_to(np.asarray(offset, dtype=float), x.shape[:1])


@dataclass
class Punch:
    """Flat bottom at z_face, nose (profile) radius profile_radius, vertical wall at half-width
    half_width with plan corner radius corner_radius >= profile_radius > 0.

    Core: the rounded square (a - rp, rc - rp) in plan, z >= z_face + rp.
    d_core = sqrt(max(s, 0)^2 + max(h, 0)^2),  s = its plan sdf,  h = z_face + rp - z.
    """

    axis = UP  # its travel dz is along z (placement.py: the contract's axis)

    half_width: float
    corner_radius: float
    profile_radius: float
    z_face: float

    def __post_init__(self):
        if not 0 < self.profile_radius <= self.corner_radius <= self.half_width:
            raise ValueError(f"punch: needs 0 < profile_radius <= corner_radius <= half_width, got {self}")

    def gap(self, x, offset=0.0, dz: float = 0.0):
        x, offset = _points(x, offset)
        rp = self.profile_radius
        s, sx, sy = rounded_square_sdf(x[:, 0], x[:, 1], self.half_width - rp, self.corner_radius - rp)
        h = (self.z_face + dz + rp) - x[:, 2]  # height of the core's bottom above the point
        sp, hp = np.maximum(s, 0.0), np.maximum(h, 0.0)
        under, beside = s <= 0.0, (s > 0.0) & (h <= 0.0)  # under the flat face / beside the wall
        nose = ~under & ~beside
        d = np.where(under, hp, np.where(beside, sp, np.sqrt(sp * sp + hp * hp)))
        n = np.tile(DOWN, (len(x), 1))  # under the face, and inside the core (d = 0)
        n[beside] = np.stack([sx, sy, np.zeros_like(s)], axis=1)[beside]
        # nose: grad d_core = (s+ grad s, -h+) / d_core
        n[nose] = np.stack([sp * sx, sp * sy, -hp], axis=1)[nose] / d[nose, None]
        return d - rp - offset, n + 0.0

    def shape(self, x, offset=0.0, dz: float = 0.0):
        """H = dn/dx, (n, 3, 3) (module docstring). Under the face and inside the core 0; beside
        the wall the plan term Hs, 1/(d + corner_radius) along the plan corner's arc, d the
        distance to the wall; on the nose (P - n n^T + s Hs) / D: 1/(d + rp) across the profile
        and s / ((s + rc - rp) D) along it at the plan corner (the plan arc's curvature 1/(s + rc
        - rp) times the normal's plan component s / D), 0 along a straight side."""
        x, _ = _points(x, offset)
        rp = self.profile_radius
        a, rc = self.half_width - rp, self.corner_radius - rp
        s, sx, sy = rounded_square_sdf(x[:, 0], x[:, 1], a, rc)
        h = (self.z_face + dz + rp) - x[:, 2]
        Hs = rounded_square_hessian(x[:, 0], x[:, 1], a, rc)
        beside, nose = (s > 0.0) & (h <= 0.0), (s > 0.0) & (h > 0.0)  # as in gap
        H = np.zeros((len(x), 3, 3))
        H[beside] = Hs[beside]
        _, n = self.gap(x[nose], 0.0, dz)
        s, sx, sy, h = s[nose], sx[nose], sy[nose], h[nose]
        H[nose] = _profile_hessian(n, sx, sy, s[:, None, None] * Hs[nose], np.sqrt(s * s + h * h))
        return H + 0.0


@dataclass
class Die:
    """Flat top at z_top, shoulder (profile) radius profile_radius > 0, opening with vertical
    walls at half-width half_width and plan corner radius corner_radius >= 0.

    O = rounded square (a + rd, rc + rd); core: plan outside O, z <= z_top - rd.
    d_core = sqrt(max(-s, 0)^2 + max(h, 0)^2),  s = sdf of O,  h = z - (z_top - rd).
    """

    axis = UP  # its travel dz is along z (placement.py: the contract's axis)

    half_width: float
    corner_radius: float
    profile_radius: float
    z_top: float

    def __post_init__(self):
        if not (self.profile_radius > 0 and 0 <= self.corner_radius <= self.half_width):
            raise ValueError(f"die: needs profile_radius > 0, 0 <= corner_radius <= half_width, got {self}")

    def gap(self, x, offset=0.0, dz: float = 0.0):
        x, offset = _points(x, offset)
        rd = self.profile_radius
        s, sx, sy = rounded_square_sdf(x[:, 0], x[:, 1], self.half_width + rd, self.corner_radius + rd)
        h = x[:, 2] - (self.z_top + dz - rd)  # height of the point above the core's top
        e, hp = np.maximum(-s, 0.0), np.maximum(h, 0.0)  # e: plan depth into the opening
        over, beside = s >= 0.0, (s < 0.0) & (h <= 0.0)  # over the flat top / beside the wall
        shoulder = ~over & ~beside
        d = np.where(over, hp, np.where(beside, e, np.sqrt(e * e + hp * hp)))
        n = np.tile(UP, (len(x), 1))  # over the top, inside the core (d = 0), and where grad s = 0
        plan = (sx != 0.0) | (sy != 0.0)  # grad s = 0 only at the opening's centre: no direction
        wall, bend = beside & plan, shoulder & plan
        n[wall] = np.stack([-sx, -sy, np.zeros_like(s)], axis=1)[wall]  # towards the opening's centre
        # shoulder: grad d_core = (-e grad s, h+) / d_core
        n[bend] = np.stack([-e * sx, -e * sy, hp], axis=1)[bend] / d[bend, None]
        return d - rd - offset, n + 0.0

    def shape(self, x, offset=0.0, dz: float = 0.0):
        """H = dn/dx, (n, 3, 3) (module docstring), with s = -e < 0 in the opening. Over the top,
        inside the core and at the opening's centre (no plan direction) 0; beside the wall -Hs,
        -1/(corner_radius - d) along the opening's corner arc (concave), d the distance to the
        wall; on the shoulder (P - n n^T - e Hs) / D: +1/(d + rd) across the profile (the section
        is convex) and -e / ((rc + rd - e) D) along it at the plan corner (concave: the opposite
        sign of the punch nose's), 0 along a straight side."""
        x, _ = _points(x, offset)
        rd = self.profile_radius
        a, rc = self.half_width + rd, self.corner_radius + rd
        s, sx, sy = rounded_square_sdf(x[:, 0], x[:, 1], a, rc)
        h = x[:, 2] - (self.z_top + dz - rd)
        Hs = rounded_square_hessian(x[:, 0], x[:, 1], a, rc)
        plan = (sx != 0.0) | (sy != 0.0)  # as in gap
        wall, bend = (s < 0.0) & (h <= 0.0) & plan, (s < 0.0) & (h > 0.0) & plan
        H = np.zeros((len(x), 3, 3))
        H[wall] = -Hs[wall]
        _, n = self.gap(x[bend], 0.0, dz)
        s, sx, sy, h = s[bend], sx[bend], sy[bend], h[bend]
        H[bend] = _profile_hessian(n, sx, sy, s[:, None, None] * Hs[bend], np.sqrt(s * s + h * h))
        return H + 0.0


@dataclass
class BlankHolder:
    """A flat face at z_face (its bottom) over the plan region outside its inner edge `edge`
    (holder_edge.py: a rounded square, or the inner boundary of a CAD die's flat top): the
    die's flat top. Signed distance z_face - z there, +inf over the opening (the holder never
    reaches over it)."""

    axis = UP  # its travel dz is along z (placement.py: the contract's axis)

    edge: object
    z_face: float

    def gap(self, x, offset=0.0, dz: float = 0.0):
        x, offset = _points(x, offset)
        s = self.edge.distance(x[:, 0], x[:, 1])
        sd = np.where(s >= 0.0, (self.z_face + dz) - x[:, 2], np.inf)
        return sd - offset, np.tile(DOWN, (len(x), 1))

    def at_gap(self, gap: float, thickness: float) -> "BlankHolder":
        """The same face held `gap` over the die's top (tools.holder = "gap"): this face rests on
        the sheet's upper surface, thickness above the die's."""
        return BlankHolder(self.edge, self.z_face - thickness + gap)

    def edge_offset(self, x):
        """(s, j) of points x: s their plan distance from the face's inner edge (> 0 under the
        face), j the length of the edge per unit length of the offset line through them
        (holder_edge.py)."""
        x, _ = _points(x, 0.0)
        return self.edge.offset(x[:, 0], x[:, 1])

    def shape(self, x, offset=0.0, dz: float = 0.0):
        """H = dn/dx = 0: a flat face (and nothing over the opening)."""
        x, _ = _points(x, offset)
        return np.zeros((len(x), 3, 3))
