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

p is the multiplier of the bound t <= c (c the clearance over the cell), regularised with the
sheet's through-thickness stiffness, the P-wave modulus M = E (1 - nu) / ((1 + nu) (1 - 2 nu)).
With the mid-surface's right Cauchy-Green tensor C = I + 2E (E the membrane Green-Lagrange
strain of the flat blank), its area stretch J = sqrt(det C) and the thickness of an
incompressible sheet t = t0 / J, the bound is put on the cell's mean thickness
t_bar = sum_g w_g t_g (w_g the quadrature weights over the cell's area, summing to 1): one
constraint per cell, as the mean dilatation of near-incompressible solids (Nagtegaal, Parks and
Rice 1974). A bound at every quadrature point would pin the area of the cell at each of them, six
constraints on a cell whose plastic flow keeps its volume: the membrane locks, and its pressure
alternates from cell to cell. The energy of a cell of initial area A0 is

    A0 phi(t_bar),   phi(t) = M / (2 t0) <t - c>^2,

and with B = C^-1 at a point (Voigt b = (B11, B22, B12), pairing with (E11, E22, 2 E12)),
d_g = dt_g/dE_g = -t_g b_g and dB/dE = -2 B dE B, the element's quadrature (weights A0 w_g)
gets at each point

    N_g = phi'(t_bar) d_g,    D_g += phi'(t_bar) dd_g/dE_g = phi' (t_g b_g b_g^T + 2 t_g H_g),

    H = [[B11^2, B12^2, B11 B12], [B12^2, B22^2, B12 B22], [B11 B12, B12 B22, (B11 B22 + B12^2) / 2]]

(H pairs dE with B dE B), and the cell's tangent the rank-one coupling of its points

    K_z += phi'' / A0 G G^T,    G = sum_g A0 w_g B_g^T d_g     (B_g = de_g/dz, membrane rows),

which the element loop adds (shellform.assembly.sheet_kernels: `ironed_d`, `ironed`). The
clearance is the tools' at the cell's vertices, c = sum_i c_i(x_i) / 3, and moves with them:
its gradient n_i = dc_i/dx_i (the facing tool's normal: the clearance grows as the node moves
away from it) gives the faces' push on the vertices, dPhi/dx_i = -A0 phi' n_i / 3, and the
rank-one term in full is phi'' / A0 v v^T with v = G - A0 / 3 sum_i n_i on vertex i's
displacement rows: the push's stiffness and its coupling to the strains. Where the faces are
curved the push turns with the vertex, n_i(x_i) with dn_i/dx_i = H_i (the two tools' shape
operators), which adds -A0 phi' / 3 H_i on vertex i's displacement block (SheetModel adds it
after the element loop). The
pressure on the faces is p = phi'(t_bar) / J_g (N_g = -p J t b: the Cauchy membrane force
-p t I pulled back). The bound is met to the elastic through-thickness strain at p:
(t_bar - c) / t0 = phi' / M, 0.2 % at p = 200 MPa on aluminium.
"""

import math

import numpy as np

from shellform import _jit as jit
from shellform.material.layout import E_, NU_


def through_thickness_modulus(material: np.ndarray) -> float:
    """M = E (1 - nu) / ((1 + nu) (1 - 2 nu)) of a packed material."""
    E, nu = float(material[E_]), float(material[NU_])
    return E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))


@jit.njit
def squeeze(e, clearance, t0, modulus, weights, S, D, pressure, direction, ironed):
    """Add the faces' pressure to the membrane resultants S[:, :, :3] and tangents
    D[:, :, :3, :3] of the cells with a finite clearance whose mean thickness exceeds it, from
    the section strains e (cells, points, 6) and the quadrature weights (summing to 1). Fills
    pressure (cells, points) with p, direction (cells, points, 3) with d_g and ironed[:, 0] and
    ironed[:, 1] (cells) with phi'' and phi' for the element loop (0 where the faces do not
    press; ironed[:, 2:], the clearance's gradient at the vertices, is the caller's).
    Returns (points pressed, points failed): a point of a cell between faces whose mid-surface
    has turned inside out (det C <= 0) has no thickness, and the iterate has left the physical
    range (the driver cuts back)."""
    pressed, failed = 0, 0
    stiff = modulus / t0
    npts = e.shape[1]
    t = np.empty(npts)
    b = np.empty((npts, 3))
    for c in range(e.shape[0]):
        ironed[c, 0] = ironed[c, 1] = 0.0
        for g in range(npts):
            pressure[c, g] = 0.0
            for i in range(3):
                direction[c, g, i] = 0.0
        gap = clearance[c]
        if not gap < np.inf:
            continue
        mean, real = 0.0, True
        for g in range(npts):
            c11, c22, c12 = 1.0 + 2.0 * e[c, g, 0], 1.0 + 2.0 * e[c, g, 1], e[c, g, 2]
            det = c11 * c22 - c12 * c12
            if not det > 0.0:
                real = False
                failed += 1
                continue
            t[g] = t0 / math.sqrt(det)
            b[g, 0], b[g, 1], b[g, 2] = c22 / det, c11 / det, -c12 / det
            mean += weights[g] * t[g]
        if not real or mean <= gap:
            continue
        d1 = stiff * (mean - gap)  # phi'
        ironed[c, 0], ironed[c, 1] = stiff, d1
        for g in range(npts):
            tg = t[g]
            b0, b1, b2 = b[g, 0], b[g, 1], b[g, 2]
            H = ((b0 * b0, b2 * b2, b0 * b2), (b2 * b2, b1 * b1, b2 * b1),
                 (b0 * b2, b2 * b1, 0.5 * (b0 * b1 + b2 * b2)))
            for i in range(3):
                direction[c, g, i] = -tg * b[g, i]
                S[c, g, i] += d1 * direction[c, g, i]
                for j in range(3):
                    D[c, g, i, j] += d1 * tg * (b[g, i] * b[g, j] + 2.0 * H[i][j])
            pressure[c, g] = d1 * tg / t0  # phi' / J
            pressed += 1
    return pressed, failed
