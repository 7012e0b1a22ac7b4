"""The sheet squeezed between two tools: its thickness bounded by their clearance (ironing).

A plane-stress section carries no through-thickness stress. Where two tools face each other
across the sheet closer than its thickness (the punch and the die's wall, a holder at a fixed
gap over the die), they press its two faces with a pressure p: the through-thickness stress
sigma33 = -p. The yield functions of shellform.material are pressure-insensitive, and their
flow is along the deviator, so the layers' response to (sigma_ab, sigma33 = -p) is their
plane-stress response to the same in-plane strain, shifted by the hydrostatic -p:

    sigma_ab = sigma_ab^ps(E) - p delta_ab

(the elastic volume change p (1 - 2 nu) / E is neglected). So p enters the section as a
membrane resultant, the same in every layer, and the layers are not touched: the thickness
follows through the in-plane flow that the membrane force -p t drives (plastic
incompressibility), as in the strip drawn through a die.

p is the multiplier of the bound t <= c (c the clearance at the point), regularised with the
sheet's through-thickness stiffness, the P-wave modulus M = E (1 - nu) / ((1 + nu) (1 - 2 nu)).
With the mid-surface's right Cauchy-Green tensor C = I + 2E (E the membrane Green-Lagrange
strain of the flat blank), its area stretch J = sqrt(det C) and the thickness of an
incompressible sheet t = t0 / J, the energy per unit initial area

    phi(t) = M / (2 t0) <t - c>^2

gives, with B = C^-1 (Voigt b = (B11, B22, B12), pairing with (E11, E22, 2 E12)),
dt/dE = -t b and dB/dE = -2 B dE B,

    N = phi'(t) dt/dE = -phi'(t) t b,        p = phi'(t) / J     (N = -p J t b: the Cauchy
                                                                  membrane force -p t I pulled back)
    dN/dE = (phi''(t) t^2 + phi'(t) t) b b^T + 2 phi'(t) t H,

    H = [[B11^2, B12^2, B11 B12], [B12^2, B22^2, B12 B22], [B11 B12, B12 B22, (B11 B22 + B12^2) / 2]]

(H b-pairs dE with B dE B). The bound is met to the elastic through-thickness strain at p:
(t - c) / t0 = p J / M, 0.2 % at p = 200 MPa on aluminium.
"""

import math

import numpy as np

from shellform import _jit as jit
from shellform.material import E_, NU_


def through_thickness_modulus(material: np.ndarray) -> float:
    """M = E (1 - nu) / ((1 + nu) (1 - 2 nu)) of a packed material."""
    E, nu = float(material[E_]), float(material[NU_])
    return E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))


@jit.njit
def squeeze(e, clearance, t0, modulus, S, D, pressure):
    """Add the faces' pressure to the membrane resultants S[:, :, :3] and tangents
    D[:, :, :3, :3] at the points of the cells with a finite clearance (cells), from the
    section strains e (cells, points, 6); pressure (cells, points) receives p (0 where the sheet
    is thinner than the clearance). Returns (points pressed, points failed): a pressed point
    whose mid-surface has turned inside out (det C <= 0) has no thickness, and the iterate has
    left the physical range (the driver cuts back)."""
    pressed, failed = 0, 0
    stiff = modulus / t0
    for c in range(e.shape[0]):
        for g in range(e.shape[1]):
            pressure[c, g] = 0.0
        gap = clearance[c]
        if not gap < np.inf:
            continue
        for g in range(e.shape[1]):
            c11, c22, c12 = 1.0 + 2.0 * e[c, g, 0], 1.0 + 2.0 * e[c, g, 1], e[c, g, 2]
            det = c11 * c22 - c12 * c12
            if not det > 0.0:
                failed += 1
                continue
            J = math.sqrt(det)
            t = t0 / J
            if t <= gap:
                continue
            d1, d2 = stiff * (t - gap), stiff  # phi', phi''
            b = (c22 / det, c11 / det, -c12 / det)
            H = ((b[0] * b[0], b[2] * b[2], b[0] * b[2]),
                 (b[2] * b[2], b[1] * b[1], b[2] * b[1]),
                 (b[0] * b[2], b[2] * b[1], 0.5 * (b[0] * b[1] + b[2] * b[2])))
            outer = d2 * t * t + d1 * t
            for i in range(3):
                S[c, g, i] -= d1 * t * b[i]
                for j in range(3):
                    D[c, g, i, j] += outer * b[i] * b[j] + 2.0 * d1 * t * H[i][j]
            pressure[c, g] = d1 / J
            pressed += 1
    return pressed, failed
