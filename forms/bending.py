"""pi_m, bending part: strain energy of the assumed curvature eps^b.

    U_b = 1/2 int_K eps^b : D^b : eps^b dA,   D^b eps = E t^3 / (12 (1 - nu^2)) [(1 - nu) eps + nu tr(eps) I]
"""

import ufl


def flexural_rigidity(E, nu, thickness):
    """D = E t^3 / (12 (1 - nu^2))."""
    return E * thickness**3 / (12 * (1 - nu**2))


def bending_moment(eps, E, nu, thickness):
    """M = D^b : eps (moment per unit length)."""
    D = flexural_rigidity(E, nu, thickness)
    return D * ((1 - nu) * eps + nu * ufl.tr(eps) * ufl.Identity(2))


def energy(eps_b, p):
    return 0.5 * ufl.inner(bending_moment(eps_b, p.E, p.nu, p.thickness), eps_b) * ufl.dx
