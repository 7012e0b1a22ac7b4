"""Shallow-shell strain measures, paper eq. (4), in tensor form.

With kappa0 = diag(1/R1, 1/R2) (engineering shear = 2 x the tensor off-diagonal):

    f^p = sym grad u + w kappa0            (u,1 + w/R1,  v,2 + w/R2,  u,2 + v,1)
    f^s = grad w - kappa0 u                (w,1 - u/R1,  w,2 - v/R2)
    f^b = -grad grad w + sym(kappa0 grad u) (-w,11 + u,1/R1, -w,22 + v,2/R2, -2w,12 + u,2/R1 + v,1/R2)

Only the last has second derivatives of w; the element never forms them inside the triangle
(see string_net), so f^b is split into its interior part and the Hessian part.
"""

import ufl


def membrane(u, w, kappa0=None):
    """f^p: membrane strain of the mid-surface."""
    f = ufl.sym(ufl.grad(u))
    return f if kappa0 is None else f + w * kappa0


def slope(u, w, kappa0=None):
    """f^s: rotation of the normal (the 'slope' strain of the initial-stress term)."""
    f = ufl.grad(w)
    return f if kappa0 is None or u is None else f - ufl.dot(kappa0, u)


def bending_interior(u, kappa0):
    """The part of f^b without second derivatives: sym(kappa0 grad u)."""
    return ufl.sym(ufl.dot(kappa0, ufl.grad(u)))
