"""The nonlinear sheet: total-Lagrangian Kirchhoff-Love strains over the blank's plane.

The blank is the plane region Omega; its reference surface is X0(x) = (x, y, z0(x, y)) with
z0 = -x . kappa0 . x / 2 (flat when kappa0 is off). The unknown is the displacement U(x) in R^3;
the mid-surface is x = X0 + U, whose tangents and normal are

    a_alpha = X0,alpha + U,alpha            F = grad X0 + grad U   (3 x 2)
    n = a_1 x a_2 / |a_1 x a_2|.

Green-Lagrange membrane strain and change of curvature (exact for any rotation):

    E = (F^T F - F0^T F0) / 2
    K_ab = -(n . x,ab - n0 . X0,ab)

so that the strain at height z above the mid-surface is E + z K (z along the normal; for a
flat plate in small deflection E = sym grad u, K = -grad grad w, as in forms.strains).

Second derivatives are not formed inside the element. Each component U_i gets the weak
Hessian H_i (linear, symmetric) defined by the paper's string-net construction,

    int_T Psi : H_i dA = int_T Psi : grad grad U_i dA   (moved to the boundary by Green's theorem),

for every linear symmetric multiplier Psi (weak_hessian_constraint). The element is then

    x,ab -> X0,ab + H_ab  (H_ab in R^3, H_ab = (H_1, H_2, H_3)_ab).

The energy's first and second variations are written against the section's stress resultants
S = (N11, N22, N12, M11, M22, M12) and its tangent D (6 x 6), which the constitutive update
supplies at the quadrature points (shellform.material), conjugate to the strain vector

    e = (E11, E22, 2 E12, K11, K22, 2 K12).
"""

import ufl

from shellform.forms import string_net


def reference_surface(x, kappa0=None):
    """(grad X0 (3 x 2), X0,ab (the Hessian of z0, 2 x 2)) of X0 = (x, y, z0): z0 = -x.kappa0.x/2
    for a constant kappa0, or any z0(x, y) given as a forms.reference_surface.ReferenceSurface."""
    if kappa0 is None:
        return ufl.as_matrix([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]), ufl.zero((2, 2))
    if hasattr(kappa0, "slopes"):  # a ReferenceSurface
        gz, hess = kappa0.slopes(x), kappa0.hessian(x)
        return ufl.as_matrix([[1.0, 0.0], [0.0, 1.0], [gz[0], gz[1]]]), hess
    gz = -ufl.dot(kappa0, x)
    return ufl.as_matrix([[1.0, 0.0], [0.0, 1.0], [gz[0], gz[1]]]), -kappa0


def unit_normal(F):
    c = ufl.cross(F[:, 0], F[:, 1])
    return c / ufl.sqrt(ufl.dot(c, c))


def membrane_strain(U, F0, nonlinear=True):
    """E = (F^T F - F0^T F0)/2, or its linearisation sym(F0^T grad U)."""
    G = ufl.grad(U)
    if not nonlinear:
        return ufl.sym(F0.T * G)
    F = F0 + G
    return 0.5 * (F.T * F - F0.T * F0)


def curvature_change(U, H, F0, hess_z0, nonlinear=True):
    """K_ab = -(n . (X0,ab + H_ab) - n0 . X0,ab), or its linearisation in U.

    H is the list of the three weak Hessians H_i (2 x 2); X0,ab = (0, 0, z0,ab).
    """
    n0 = unit_normal(F0)
    if nonlinear:
        n = unit_normal(F0 + ufl.grad(U))
        return -(sum(n[i] * H[i] for i in range(3)) + (n[2] - n0[2]) * hess_z0)
    # d n = -(n0 . grad_a U) ... projected: the first variation of n about F0 in direction U
    G = ufl.grad(U)
    c0 = ufl.cross(F0[:, 0], F0[:, 1])
    dc = ufl.cross(G[:, 0], F0[:, 1]) + ufl.cross(F0[:, 0], G[:, 1])
    dn = (dc - n0 * ufl.dot(n0, dc)) / ufl.sqrt(ufl.dot(c0, c0))
    return -(sum(n0[i] * H[i] for i in range(3)) + dn[2] * hess_z0)


def voigt(E, K):
    """e = (E11, E22, 2 E12, K11, K22, 2 K12)."""
    return ufl.as_vector([E[0, 0], E[1, 1], 2 * E[0, 1], K[0, 0], K[1, 1], 2 * K[0, 1]])


def section_strain(U, H, x, kappa0=None, nonlinear=True):
    """The generalized strain vector e(U, H) of the section at x."""
    F0, hess_z0 = reference_surface(x, kappa0)
    return voigt(membrane_strain(U, F0, nonlinear), curvature_change(U, H, F0, hess_z0, nonlinear))


def internal_work(e, S, dx):
    """delta W_int = int S . delta e: its derivative in the unknowns is the internal force."""
    return ufl.inner(S, e) * dx


def tangent(e, de, te, S, D, z, dz, tz, dx, nonlinear=True):
    """The consistent tangent: material part de . D . te plus initial-stress part S . d2e.

    de, te: the first variations of e in the test and trial directions; the initial-stress
    (geometric) stiffness K^s is the second variation of e weighted by the resultants S (zero
    for the linearised strains).
    """
    material = ufl.inner(de, ufl.dot(D, te)) * dx
    if not nonlinear:
        return material
    return material + ufl.derivative(ufl.derivative(ufl.inner(S, e) * dx, z, dz), z, tz)


def weak_hessian_constraint(Psi, H, w, g, n):
    """int_T Psi : (H - grad grad w) with the Hessian part on the string net:
    int_T Psi : grad grad w = -string_net.bending_boundary(Psi, w, g, n) for linear Psi."""
    return ufl.inner(Psi, H) * ufl.dx + string_net.bending_boundary(Psi, w, g, n)


def dead_pressure(p, U, dx):
    """Work of a pressure p along +z per unit blank area (a dead load, as in von Karman theory);
    p may vary over the plan (forms.loads.PressureField.density)."""
    return p * U[2] * dx
