"""The pinch's edge: the holder's force that turns the sheet from the flange onto the shoulder.

Where the sheet leaves the pinch for the die's shoulder its bending moment rises from the flat
flange's (none) to the moment that bends it onto the shoulder. Between two rigid faces that rise is
a concentrated couple: the die pushes up and the holder pushes down, an infinite pair an infinitely
short distance apart. On a mesh the pair sits one cell apart, so the holder's share grows as 1/h
(docs/contact.md, "The pinch's edge"). The sheet's own through-thickness compliance gives the couple
its width: each face bears on half the thickness, a Winkler foundation of stiffness k = 2 E' / t per
face (E' = E / (1 - nu^2)), 4 E' / t on the flange's deflection. The flat elastic plate on it,
D = E' t^3 / 12, loaded by an end moment M, deflects as

    w(x) = (2 beta^2 M / k) e^(-beta x) (cos beta x - sin beta x),   beta = (k / 4D)^(1/4) = 12^(1/4) / t,

and the holder's face takes the lobes where it presses, per unit length of the edge

    V = C_EDGE M / t,   C_EDGE = sqrt(2) 12^(1/4) (e^(-pi/4) + e^(-5 pi/4)) / (1 - e^(-2 pi)) = 1.254,

over a band of about 1.7 t; nothing in it depends on a mesh (E' cancels).

Strip solves that edge resolved: a plane-strain strip of the scene's sheet (its elastic-plastic
moment, from the material point driven in plane strain) pinched between the two compliant faces
and wrapped onto the die's shoulder, by finite differences well below t. Its holder force
converges to within 1.5 % of C_EDGE times its moment at the edge; with faces 10^4 times stiffer
(the rigid pinch) it grows as 1/h (shellform study pinch-edge). ``edge_load`` takes the holder's
force per unit length V_e from it, and that moment M_e, for the scene's sheet and die; tools'
own compliance would widen the band and lower V_e: rigid tools give the largest edge load.

No mesh of a cup resolves 1.7 t, so the edge load is lumped (holder.py): the holder's face presses
the pinched nodes within b = 2 r of its inner edge with V_e a_i j_i (2 / b) sin^2(pi s / b), s the
node's plan distance from the edge, a its current plan area, r the current spacing of its rows
along s, j the edge's length per unit length of the offset line through the node (1 beside a
straight edge): a kernel whose sum over rows of nodes r apart is 1 for any offset of the rows, so
the edge's total is V_e times its length on every mesh and however the flange has deformed.
The holder rides on its edge while the lift that gives the edge less than V_e stays below the
contact's tolerance (EdgeLoad.riding_lift); beyond, it opens.
"""

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from shellform.material.point import plane_strain

C_EDGE = math.sqrt(2.0) * 12.0**0.25 * (math.exp(-math.pi / 4) + math.exp(-5 * math.pi / 4)) / (1 - math.exp(-2 * math.pi))
RESOLUTION = 64  # the strip's grid spacing, t / RESOLUTION: V_e within 0.3 % of the finest


def shoulder_curvature(die, holder, thickness: float) -> float:
    """The curvature 1/(R_d + t/2) of a sheet wrapped on the die's shoulder at the holder's inner
    edge: the largest principal curvature of the die's distance at the sheet's mid-surface, just
    inside the edge along x."""
    x = np.array([[holder.edge.reach() - 1e-3 * thickness, 0.0, 0.0]])
    H = die.shape(x, thickness / 2)[0]
    return float(np.linalg.eigvalsh(0.5 * (H + H.T)).max())


class Strip:
    """The plane-strain strip of a sheet (its packed material: E, nu first; thickness t) pinched
    on a die's flat top and wrapped onto its shoulder of radius R_d, the flange pre-squeezed by
    the holder's mean pressure p0 (MPa) (shellform.studies.pinch_edge states its energy). The
    sheet's moment M(kappa) is its plane-strain moment on the loading branch, tabulated to kmax
    (1/mm) from the material point driven in plane strain."""

    def __init__(self, material, thickness: float, die_radius: float, pressure: float, kmax: float = 2.0):
        self.t, self.R, self.p0 = thickness, die_radius, pressure
        E, nu = float(material[0]), float(material[1])
        self.E_ps = E / (1 - nu**2)
        path = plane_strain(material, kmax * thickness / 2, 400)  # the outer fibre at kmax
        eps, sig = path.strain[:, 0], path.stress[:, 0]
        self.kap = np.linspace(0.0, kmax, 801)
        z = np.linspace(0.0, thickness / 2, 201)
        s = np.interp(np.outer(self.kap, z), eps, sig)
        self.M = 2.0 * np.trapezoid(s * z, z, axis=1)
        self.W = np.concatenate([[0.0], np.cumsum(0.5 * (self.M[1:] + self.M[:-1]) * np.diff(self.kap))])
        self.dM = np.gradient(self.M, self.kap)

    def section(self, k):
        a = np.abs(k)
        return np.interp(a, self.kap, self.W), np.sign(k) * np.interp(a, self.kap, self.M), np.interp(a, self.kap, self.dM)

    def die(self, x):
        Rm = self.R + self.t / 2
        return np.where(x <= 0, 0.0, -(Rm - np.sqrt(np.maximum(Rm**2 - x**2, 0.0))))

    def solve(self, h: float, k: float, tension: float) -> dict:
        """The strip on a grid of spacing h with the face stiffness k per face (N/mm^3) and the
        tension (N/mm): the flange over L = 8 t (at least 6 mm), the shoulder over X = 3 mm or
        0.4 (R_d + t/2) if shorter. Returns the holder's force beyond the pre-squeeze V_h
        (N/mm), the moment at the edge M_0, V_h t / M_0, the holder's peak pressure and the
        Newton iterations."""
        L, X = max(6.0, 8 * self.t), min(3.0, 0.4 * (self.R + self.t / 2))
        n = int(round((L + X) / h)) + 1
        x = np.linspace(-L, X, n)
        hh = x[1] - x[0]
        zd, d0, under = self.die(x), self.p0 / k, x <= 0.0
        free = np.ones(n, dtype=bool)
        free[[0, 1, -2, -1]] = False  # clamped flange, the sheet wrapped on the shoulder
        w = zd.copy()
        w[:2] = 0.0
        D2 = sp.diags([np.ones(n - 2), -2 * np.ones(n - 2), np.ones(n - 2)], [0, 1, 2], shape=(n - 2, n)) / hh**2
        D1 = sp.diags([-np.ones(n - 1), np.ones(n - 1)], [0, 1], shape=(n - 1, n)) / hh

        def faces(w):
            return np.maximum(zd + d0 - w, 0.0), np.where(under, np.maximum(w + d0, 0.0), 0.0)

        def energy(w):
            cd, ch = faces(w)
            return hh * (self.section(D2 @ w)[0].sum() + 0.5 * tension * np.sum((D1 @ w) ** 2)
                         + 0.5 * k * np.sum(cd**2 + ch**2))

        for it in range(1, 101):
            _, M, dM = self.section(D2 @ w)
            cd, ch = faces(w)
            g = hh * (D2.T @ M + tension * (D1.T @ (D1 @ w)) - k * cd + k * ch)
            H = (hh * (D2.T @ sp.diags(dM) @ D2 + tension * (D1.T @ D1))
                 + sp.diags(hh * k * ((cd > 0) | (ch > 0)).astype(float))).tocsr()
            dw = np.zeros(n)
            dw[free] = spla.spsolve(H[free][:, free].tocsc(), -g[free])
            e0, a = energy(w), 1.0
            while energy(w + a * dw) > e0 + 1e-4 * a * (g @ dw) and a > 1e-8:
                a *= 0.5
            w = w + a * dw
            if np.max(np.abs(a * dw)) < 1e-13 * max(1.0, np.max(np.abs(w))):
                break
        _, ph = faces(w)
        ph = k * ph
        M0 = abs(float(np.interp(0.0, x[1:-1], self.section(D2 @ w)[1])))
        Vh = float(np.sum(np.maximum(ph - self.p0, 0.0)) * hh)
        return {"h_mm": h, "Vh_N_per_mm": Vh, "M0_Nmm_per_mm": M0, "Vh_t_over_M0": Vh * self.t / M0,
                "C_EDGE": C_EDGE, "peak_holder_MPa": float(ph.max()), "newton": it}


@dataclass(frozen=True)
class EdgeLoad:
    """The pinch's edge of a sheet of thickness t and elastic plate stiffness D = E' t^3 / 12: the
    holder's force per unit length of its inner edge V_e (N/mm) and the sheet's moment there
    M_e (N mm / mm)."""

    line_load: float
    moment: float
    thickness: float
    plate_stiffness: float
    radius: float = math.nan  # the die shoulder's radius R_d the strip was wrapped on (at)

    def riding_lift(self, share: float) -> float:
        """The lift of a holder that gives the edge only `share` (0 < f <= 1) of V_e: the couple's
        arm grows from a = M_e / V_e to a / f, a span over which the flat, elastic sheet (its
        curvature M_e / D at the shoulder's end, none at the holder's) rises by
        delta = (M_e / D) (a / f)^2 / 3 from the die's edge to the holder's face (mm): with
        f = 1 about a micrometre, the order of the foundation's own deflection."""
        arm = self.moment / self.line_load / max(share, 1e-300)
        return self.moment / self.plate_stiffness * arm**2 / 3.0

    def at(self, material) -> "EdgeLoad":
        """The same edge (thickness, shoulder) of another sheet (packed material): its strip
        solved again (a sensitivity's differences in the material)."""
        return strip_edge(material, self.thickness, self.radius)


def edge_load(material, thickness: float, die, holder) -> EdgeLoad:
    """The EdgeLoad of the sheet (packed material: E, nu first) on this die under this holder:
    the Strip with the shoulder's radius (shoulder_curvature) and the sheet's own compliance, at
    spacing t / RESOLUTION, with no tension and no pre-squeeze (whose nanometres change nothing)."""
    return strip_edge(material, thickness, 1.0 / shoulder_curvature(die, holder, thickness) - thickness / 2)


def strip_edge(material, thickness: float, radius: float) -> EdgeLoad:
    """The EdgeLoad of the sheet wrapped on a shoulder of radius R_d (edge_load's strip)."""
    E, nu = float(material[0]), float(material[1])
    strip = Strip(material, thickness, radius, 0.0)
    r = strip.solve(thickness / RESOLUTION, 2 * strip.E_ps / thickness, 0.0)
    return EdgeLoad(r["Vh_N_per_mm"], r["M0_Nmm_per_mm"], thickness, E / (1 - nu**2) * thickness**3 / 12, radius)


def edge_weights(s: np.ndarray, h: np.ndarray) -> np.ndarray:
    """(2 / b) sin^2(pi s / b) for 0 <= s < b = 2 h, else 0 (1/mm): the band's kernel over rows of
    nodes h apart."""
    s, b = np.broadcast_arrays(np.asarray(s, dtype=float), 2.0 * np.asarray(h, dtype=float))
    inside = (s >= 0.0) & (s < b)  # so b > 0 there
    w = np.zeros(s.shape)
    w[inside] = 2.0 / b[inside] * np.sin(np.pi * (s[inside] / b[inside])) ** 2
    return w
