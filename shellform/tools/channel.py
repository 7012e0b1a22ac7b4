"""The kind of tools "channel": a hat channel drawn along y, over a binder that is flat or bent
to a cylinder about the x axis (a curved binder), with the blank holder at a gap.

Every tool is a straight profile in the section (X, Z) swept along the channel: in a flat
binder along y, in a curved one around the x axis. With the binder's radius R (binder_radius,
the die's binder face) and R_m = R + t/2 the radius of the wrapped blank's mid-surface, a point
x of the scene has, about a tool's sweep axis at height z_a (z_a = -R_m for the die, moved by
the tool's lift and travel dz for the others),

    X = x,  Z = rho - R_m,  rho = |(y, z - z_a)|,  e = (0, y, z - z_a) / rho      (curved)
    X = x,  Z = z - z_a,    e = e_z                                                (flat)

and the tool's signed distance is its profile's in the section, d(x) = d2(X, Z) (exact: the
nearest point of a swept profile lies in the point's own section). With the profile's
gradient (d_X, d_Z) and Hessian H2 in the section's basis (e_x, e),

    n = d_X e_x + d_Z e,    H = H2 (in e_x, e) + (d_Z / rho) (P_yz - e e^T)

P_yz the projector onto the yz plane: the second term is the sweep's curvature across the
section (the cylinder's 1 / rho; 0 for the flat binder). The profiles, in the section:

    punch   flat bottom at Z = t/2 + punch_gap, nose radius punch_profile_radius, wall at
            |X| = punch_half_width (the analytic punch's profile, analytic.py)
    die     binder face at Z = -t/2 (the blank's lower surface), shoulder radius
            die_profile_radius, wall at |X| = die_half_width
    holder  the face Z = holder_gap - t/2 over |X| >= die_half_width + die_profile_radius
            (+inf gap over the opening): the holder at a gap (tools.holder = "gap")

The punch and the holder start raised by binder_rise: both come down with the ram (the punch's
travel, the stroke, from the start), the holder stops after binder_rise (travel.Capped), its
face then holder_gap over the die's: the blank is closed onto the binder (the binder wrap), and
the punch, then punch_gap above the wrapped blank, draws on. binder_rise must lift both clear
of the flat blank at the start (check). A flat binder takes binder_rise 0 (the holder at its gap
from the start) or more.

The force-controlled holder pinches a flange onto a flat top around a closed opening
(holder.py); a channel's holder is held at its gap. The cross-section of a drawn channel is
the thickness line "section" (y = 0); "length" runs along its bottom (x = 0).
"""

import math

import numpy as np

from shellform.errors import require
from shellform.tools import square
from shellform.tools.protocol import BinderPlan, ram_travel

NAME = "channel"

SECTION_KEYS = ("punch_half_width", "punch_profile_radius", "die_half_width", "die_profile_radius", "punch_gap")
FIELDS = tuple(f for f in square.FIELDS if f[0] in SECTION_KEYS) + (  # the section: the square tools' side
    ("binder_radius", 0.0, "channel: the die's binder face, a cylinder about the x axis of this radius "
     "(0: flat)"),
    ("binder_rise", 0.0, "channel: how far the holder comes down with the ram before it stops at its gap "
     "(the binder wrap)"),
)

LINES = {"section": lambda X, tol: np.abs(X[:, 1]) < tol, "length": lambda X, tol: np.abs(X[:, 0]) < tol}
RIM = False

DOWN2, UP2 = np.array([0.0, -1.0]), np.array([0.0, 1.0])


def refuse(key: str, owners: tuple) -> str:
    return f"is a key of shape = {owners[0]!r} (a channel takes half-widths and profile radii of its section)"


def complete(spec) -> None:
    """Nothing derived."""


def picture_depth(spec) -> float:
    return spec.stroke + max(spec.punch_profile_radius, spec.die_profile_radius)


# -- the sweep ---------------------------------------------------------------------------------
class Swept:
    """A profile (its section's distance d2, gradient and Hessian: `profile(X, Z)`) swept along y
    (radius 0) or around the x axis at the mid-surface radius `radius`; `lift` raises it at the
    start, its travel dz moves it along z."""

    axis = np.array([0.0, 0.0, 1.0])  # its travel dz is along z (placement.py: the contract's axis)

    def __init__(self, profile, radius: float, lift: float = 0.0):
        self.profile, self.radius, self.lift = profile, float(radius), float(lift)

    def _section(self, x, dz):
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        if self.radius == 0:
            e = np.tile([0.0, 0.0, 1.0], (len(x), 1))
            return x[:, 0], x[:, 2] - (self.lift + dz), e, np.full(len(x), np.inf)
        r = np.stack([np.zeros(len(x)), x[:, 1], x[:, 2] - (-self.radius + self.lift + dz)], axis=1)
        rho = np.linalg.norm(r, axis=1)
        return x[:, 0], rho - self.radius, r / rho[:, None], rho

    def gap(self, x, offset=0.0, dz: float = 0.0):
        X, Z, e, _ = self._section(x, dz)
        d, g, _ = self.profile(X, Z)
        n = g[:, :1] * np.array([1.0, 0.0, 0.0]) + g[:, 1:] * e
        return d - np.asarray(offset, dtype=float), n + 0.0

    def shape(self, x, offset=0.0, dz: float = 0.0):
        X, Z, e, rho = self._section(x, dz)
        _, g, H2 = self.profile(X, Z)
        ex = np.tile([1.0, 0.0, 0.0], (len(X), 1))
        basis = np.stack([ex, e], axis=1)  # (n, 2, 3): e_x, e
        H = np.einsum("nai,nab,nbj->nij", basis, H2, basis)
        P = np.zeros((len(X), 3, 3))
        P[:, 1, 1] = P[:, 2, 2] = 1.0
        across = P - e[:, :, None] * e[:, None, :]
        finite = np.isfinite(g[:, 1]) & np.isfinite(rho)
        H[finite] += (g[finite, 1] / rho[finite])[:, None, None] * across[finite]
        return H + 0.0


def _rounded(D, n):
    """(I - n n^T) / D: the Hessian of the distance to a point at distance D, in the section."""
    return (np.eye(2) - n[:, :, None] * n[:, None, :]) / D[:, None, None]


class PunchProfile:
    """Flat bottom at Z = z_face, nose radius rp, wall at |X| = half_width: core |X| <= a - rp,
    Z >= z_face + rp; d2 = its distance - rp."""

    def __init__(self, half_width, profile_radius, z_face):
        self.a, self.rp, self.z_face = half_width, profile_radius, z_face

    def __call__(self, X, Z):
        rp = self.rp
        s, sx = np.abs(X) - (self.a - rp), np.sign(X)
        h = (self.z_face + rp) - Z
        sp, hp = np.maximum(s, 0.0), np.maximum(h, 0.0)
        under, beside = s <= 0.0, (s > 0.0) & (h <= 0.0)
        nose = ~under & ~beside
        d = np.where(under, hp, np.where(beside, sp, np.sqrt(sp * sp + hp * hp)))
        g = np.tile(DOWN2, (len(X), 1))
        g[beside] = np.stack([sx, np.zeros_like(s)], axis=1)[beside]
        g[nose] = np.stack([sp * sx, -hp], axis=1)[nose] / d[nose, None]
        H = np.zeros((len(X), 2, 2))
        H[nose] = _rounded(d[nose], g[nose])
        return d - rp, g, H


class DieProfile:
    """Binder face at Z = z_top, shoulder radius rd, wall at |X| = half_width: core |X| >= a + rd,
    Z <= z_top - rd; d2 = its distance - rd."""

    def __init__(self, half_width, profile_radius, z_top):
        self.a, self.rd, self.z_top = half_width, profile_radius, z_top

    def __call__(self, X, Z):
        rd = self.rd
        s, sx = np.abs(X) - (self.a + rd), np.sign(X)
        h = Z - (self.z_top - rd)
        e, hp = np.maximum(-s, 0.0), np.maximum(h, 0.0)
        over, beside = s >= 0.0, (s < 0.0) & (h <= 0.0)
        shoulder = ~over & ~beside
        d = np.where(over, hp, np.where(beside, e, np.sqrt(e * e + hp * hp)))
        g = np.tile(UP2, (len(X), 1))  # over the face, inside the core, and at X = 0 (no direction)
        side = sx != 0.0
        wall, bend = beside & side, shoulder & side
        g[wall] = np.stack([-sx, np.zeros_like(s)], axis=1)[wall]
        g[bend] = np.stack([-e * sx, hp], axis=1)[bend] / d[bend, None]
        H = np.zeros((len(X), 2, 2))
        H[bend] = _rounded(d[bend], g[bend])
        return d - rd, g, H


class HolderProfile:
    """The face Z = z_face over |X| >= edge, nothing (+inf) over the opening."""

    def __init__(self, edge, z_face):
        self.edge, self.z_face = edge, z_face

    def __call__(self, X, Z):
        d = np.where(np.abs(X) >= self.edge, self.z_face - Z, np.inf)
        return d, np.tile(DOWN2, (len(X), 1)), np.zeros((len(X), 2, 2))


class ChannelHolder(Swept):
    """The holder's face (HolderProfile) swept like the die's binder face; `at_gap(gap, t)` is
    the same face held `gap` over the die's (tools.holder = "gap")."""

    def __init__(self, edge, z_face, radius, lift):
        super().__init__(HolderProfile(edge, z_face), radius, lift)
        self.edge, self.z_face = edge, z_face

    def at_gap(self, gap: float, thickness: float) -> "ChannelHolder":
        return ChannelHolder(self.edge, self.z_face - thickness + gap, self.radius, self.lift)


def tools(spec, thickness: float) -> dict:
    """Punch, die and holder (module docstring) around a sheet of that thickness whose
    mid-surface is z = 0: the die's binder face touches the sheet's lower surface at y = 0, the
    holder rests on its upper surface there and the punch face lies punch_gap above it, both
    raised by binder_rise."""
    radius = spec.binder_radius + thickness / 2 if spec.binder_radius > 0 else 0.0
    rise, rd = spec.binder_rise, spec.die_profile_radius
    return dict(
        punch=Swept(PunchProfile(spec.punch_half_width, spec.punch_profile_radius, thickness / 2 + spec.punch_gap),
                    radius, rise),
        die=Swept(DieProfile(spec.die_half_width, rd, -thickness / 2), radius),
        holder=ChannelHolder(spec.die_half_width + rd, thickness / 2, radius, rise),
    )


travel = ram_travel  # the punch travels the stroke; the holder comes down with it by binder_rise and stops


def least_rise(spec, thickness: float, gap: float, half_length: float) -> float:
    """The binder_rise that lifts the holder's face (at `gap` over the die's) and the punch clear
    of the flat blank (mid-surface z = 0) out to y = half_length: a face swept at the radius
    R_m + Z_f about the axis z = -R_m + rise passes above the blank's top (z = t/2) at y where
    rise >= t/2 + R_m - sqrt((R_m + Z_f)^2 - y^2). 0 for a flat binder."""
    if spec.binder_radius <= 0:
        return 0.0
    radius = spec.binder_radius + thickness / 2
    lowest = min(gap - thickness / 2, thickness / 2 + spec.punch_gap)  # Z of the holder's and the punch's faces
    return thickness / 2 + radius - math.sqrt((radius + lowest) ** 2 - half_length ** 2)


def check(s) -> BinderPlan:
    """The channel's dimensions, its holder (at a gap: module docstring), the blank (a rectangle)
    and binder_rise; returns where the die's binder face begins: |x| = die_half_width +
    die_profile_radius, across x only (the channel runs along y)."""
    t, thickness = s.tools, s.material.thickness
    for name, _, _ in FIELDS:
        v = getattr(t, name)
        require(isinstance(v, (int, float)) and math.isfinite(v), f"tools.{name}", f"must be finite, got {v}")
    for name in ("punch_half_width", "punch_profile_radius", "die_half_width", "die_profile_radius"):
        require(getattr(t, name) > 0, f"tools.{name}", f"must be > 0, got {getattr(t, name)}")
    for name in ("punch_gap", "binder_radius", "binder_rise"):
        require(getattr(t, name) >= 0, f"tools.{name}", f"must be >= 0, got {getattr(t, name)}")
    require(t.punch_profile_radius <= t.punch_half_width, "tools.punch_profile_radius",
            f"must be <= punch_half_width ({t.punch_half_width}), got {t.punch_profile_radius}")
    require(t.die_half_width - t.punch_half_width >= thickness, "tools.die_half_width",
            f"the clearance die_half_width - punch_half_width = {t.die_half_width - t.punch_half_width} "
            f"is smaller than the thickness {thickness}: the sheet cannot pass")
    require(t.holder == "gap", "tools.holder",
            "shape = 'channel' holds its holder at a gap ('gap'): the force-controlled holder pinches a flange "
            "onto a flat top around a closed opening")
    require(not t.drawbead, "tools.drawbead", "shape = 'channel' takes no drawbeads")
    g = s.geometry
    require(g.shape == "rectangle", "geometry.shape", f"shape = 'channel' draws a rectangular blank, got {g.shape!r}")
    require(t.binder_radius == 0 or t.binder_radius > g.ly / 2, "tools.binder_radius",
            f"must exceed the blank's half length ly/2 = {g.ly / 2} (or be 0: flat), got {t.binder_radius}")
    least = least_rise(t, thickness, t.holder_gap, g.ly / 2)
    require(t.binder_rise >= least, "tools.binder_rise",
            f"must lift the holder and the punch clear of the flat blank over the binder of radius "
            f"{t.binder_radius}: at least {least:.4g} mm, got {t.binder_rise}")
    require(t.stroke > t.binder_rise + t.punch_gap, "tools.stroke",
            f"must exceed binder_rise + punch_gap = {t.binder_rise + t.punch_gap} (the ram closes the holder "
            f"first, then the punch draws), got {t.stroke}")
    return BinderPlan(t.die_half_width + t.die_profile_radius, 0.0, "die_half_width + die_profile_radius",
                      across=("x",))


def check_placement(tools, x, half, planes, comm, tolerance: float) -> None:
    """Nothing to check: analytic tools are placed around the blank by construction."""
