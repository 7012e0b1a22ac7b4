"""Hill 1948, plane stress, planar anisotropy: sigma_bar(s), gradient, Hessian.

In the axes of the rolling direction (1 = rolling, 2 = transverse), with Hill's F, G, H, N
normalised by G + H = 1 (sigma_bar is the yield stress along the rolling direction):

    sigma_bar^2 = (G + H) s11^2 - 2 H s11 s22 + (F + H) s22^2 + 2 N s12^2 = s . P s,
    P = [[G + H, -H, 0], [-H, F + H, 0], [0, 0, 2N]].

From the Lankford coefficients r0, r45, r90 (at 0, 45, 90 degrees to the rolling direction):

    G = 1/(1 + r0),  H = r0/(1 + r0),  F = r0/(r90 (1 + r0)),  N = (r0 + r90)(1 + 2 r45)/(2 r90 (1 + r0)),

or from the yield stresses sigma0, sigma45, sigma90 and the balanced-biaxial sigma_b:

    F + H = (sigma0/sigma90)^2,  F + G = (sigma0/sigma_b)^2,  2N = 4 (sigma0/sigma45)^2 - F - G.

sigma_bar = sqrt(s . P s) is homogeneous of degree 1 and convex where P is positive definite
(checked: r > 0 always gives it); a = P s / sigma_bar, Hess = (P - a a^T) / sigma_bar.

At an angle theta to the rolling direction the uniaxial yield stress and Lankford value are

    sigma(theta)/sigma0 = [F sin^4 + G cos^4 + H (cos^2 - sin^2)^2 + 2N sin^2 cos^2]^(-1/2),
    r(theta) = [H + (2N - F - G - 4H) sin^2 cos^2] / (F sin^2 + G cos^2).

r0 = r45 = r90 = r gives Hill 1979 with m = 2 (the paper's normal anisotropy).
"""

import math

from shellform.material.layout import PAR_, number, require
from shellform import _jit as jit

NAME = "hill48"
PLANAR_ISOTROPIC = False  # the rolling direction matters: the return mapping turns into its axes
LANKFORD = ("r0", "r45", "r90")
STRESSES = ("sigma0", "sigma45", "sigma90", "sigma_b")
PARAMETERS = LANKFORD + STRESSES  # its scene keys: one set or the other


def coefficients(values: dict) -> tuple[float, float, float, float]:
    """Hill's (F, G, H, N), G + H = 1, from r0, r45, r90 or from sigma0, sigma45, sigma90,
    sigma_b (one set, complete); InputError names the field."""
    given = {k: values[k] for k in LANKFORD + STRESSES if values.get(k) is not None}
    if any(k in given for k in STRESSES):
        for k in LANKFORD:
            require(k not in given, f"material.{k}", "Hill 1948 takes r0, r45, r90 or the yield stresses "
                                                     "sigma0, sigma45, sigma90, sigma_b, not both")
        s0, s45, s90, sb = (_value(given, k, STRESSES) for k in STRESSES)
        for k, v in zip(STRESSES, (s0, s45, s90, sb)):
            require(v > 0.0, f"material.{k}", f"must be positive, got {v}")
        FH, FG = (s0 / s90) ** 2, (s0 / sb) ** 2
        H = 0.5 * (1.0 + FH - FG)
        G, F = 1.0 - H, FH - H
        N = 0.5 * (4.0 * (s0 / s45) ** 2 - F - G)
        require(F * G + G * H + H * F > 0.0, "material.sigma_b",
                "with sigma0 and sigma90 gives a yield function that is not convex (FG + GH + HF <= 0)")
        require(N > 0.0, "material.sigma45", f"gives N = {N:.6g} <= 0: the yield function is not convex")
        return F, G, H, N
    r0, r45, r90 = (_value(given, k, LANKFORD) for k in LANKFORD)
    for k, v in zip(LANKFORD, (r0, r45, r90)):
        require(v > 0.0, f"material.{k}", f"must be positive, got {v}")
    return r0 / (r90 * (1.0 + r0)), 1.0 / (1.0 + r0), r0 / (1.0 + r0), (r0 + r90) * (1.0 + 2.0 * r45) / (
        2.0 * r90 * (1.0 + r0))


def _value(given: dict, key: str, group: tuple) -> float:
    require(key in given, f"material.{key}", f"is required by yield_function = 'hill48' (give {', '.join(group)})")
    return number(f"material.{key}", given[key])


def parameters(values: dict) -> list[float]:
    """[P11, P12, P22, P33] of sigma_bar^2 = P11 s11^2 + 2 P12 s11 s22 + P22 s22^2 + P33 s12^2."""
    F, G, H, N = coefficients(values)
    return [G + H, -H, F + H, 2.0 * N]


def r_theta(values: dict, theta_deg: float) -> float:
    """The closed-form Lankford value at theta degrees to the rolling direction."""
    F, G, H, N = coefficients(values)
    c2, s2 = math.cos(math.radians(theta_deg)) ** 2, math.sin(math.radians(theta_deg)) ** 2
    return (H + (2.0 * N - F - G - 4.0 * H) * s2 * c2) / (F * s2 + G * c2)


def sigma_theta(values: dict, theta_deg: float) -> float:
    """The closed-form uniaxial yield stress at theta degrees to the rolling direction, / sigma0."""
    F, G, H, N = coefficients(values)
    c2, s2 = math.cos(math.radians(theta_deg)) ** 2, math.sin(math.radians(theta_deg)) ** 2
    return (F * s2 * s2 + G * c2 * c2 + H * (c2 - s2) ** 2 + 2.0 * N * s2 * c2) ** -0.5


@jit.njit(inline="always")
def yield_function(s0, s1, s2, mat, order):
    """sigma_bar (order 0: the rest zero) or sigma_bar, gradient and Hessian (upper triangle)."""
    p11, p12, p22, p33 = mat[PAR_], mat[PAR_ + 1], mat[PAR_ + 2], mat[PAR_ + 3]
    q0, q1, q2 = p11 * s0 + p12 * s1, p12 * s0 + p22 * s1, p33 * s2  # P s
    f = s0 * q0 + s1 * q1 + s2 * q2
    if not f > 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    sb = math.sqrt(f)
    if order == 0:
        return sb, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    g = 1.0 / sb
    a0, a1, a2 = q0 * g, q1 * g, q2 * g
    return (sb, a0, a1, a2, (p11 - a0 * a0) * g, (p12 - a0 * a1) * g, -a0 * a2 * g,
            (p22 - a1 * a1) * g, -a1 * a2 * g, (p33 - a2 * a2) * g)
