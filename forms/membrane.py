"""pi_m, membrane part: strain energy of the assumed membrane strain eps^p.

    U_p = 1/2 int_K eps^p : D^p : eps^p dA,   D^p eps = E t / (1 - nu^2) [(1 - nu) eps + nu tr(eps) I]
"""

import ufl


def membrane_force(eps, E, nu, thickness):
    """N = D^p : eps, plane-stress membrane stiffness (force per unit length)."""
    return E * thickness / (1 - nu**2) * ((1 - nu) * eps + nu * ufl.tr(eps) * ufl.Identity(2))


def energy(eps_p, p):
    return 0.5 * ufl.inner(membrane_force(eps_p, p.E, p.nu, p.thickness), eps_p) * ufl.dx
