"""pi_a: the stress-resultant multipliers enforce the assumed strains, paper eq. (6).

    pi_a = int_K N : (f^p - eps^p) + M : (f^b - eps^b) dA

This module holds every part that is integrated inside the element. The Hessian part of f^b,
int_K M : (-grad grad w), is moved to the element boundary by Green's theorem; that boundary
integral is in string_net.
"""

import ufl

from shellform.forms import strains


def membrane_constraint(N, eps_p, u, w, kappa0=None):
    """int_K N : (f^p(u, w) - eps^p)."""
    return ufl.inner(N, strains.membrane(u, w, kappa0) - eps_p) * ufl.dx


def bending_constraint(M, eps_b, u=None, kappa0=None):
    """int_K M : (f^b_interior(u) - eps^b); the -grad grad w part is in string_net."""
    f = -eps_b if kappa0 is None else strains.bending_interior(u, kappa0) - eps_b
    return ufl.inner(M, f) * ufl.dx
