"""The shell's reference surface z0(x, y), given as an expression in x and y.

The shallow-shell strains need only its curvature tensor,

    kappa0 = -grad grad z0                (the paraboloid z0 = -(x^2/R1 + y^2/R2)/2: diag(1/R1, 1/R2)),

and the Kirchhoff-Love sheet its slopes and Hessian: X0 = (x, y, z0), grad X0 = [I; grad z0]^T.
UFL differentiates the expression; nothing is approximated. What the text may hold, and how it
is checked: forms/plan_field.py.
"""

from dataclasses import dataclass

import ufl

from shellform.forms.plan_field import PlanField, first_nonfinite


@dataclass(frozen=True)
class ReferenceSurface(PlanField):
    """z0(x, y) from its text (forms.plan_field: what the text may hold); hashable, so compiled
    kernels are cached per surface."""

    FIELD = "surface.z0"

    def nonfinite_point(self, mesh) -> tuple[str, tuple[float, float]] | None:
        """Where on the mesh z0, its slopes or its second derivatives (UFL's, as the forms take
        them) are not finite: (which of them, as a message says it: "z0 is", "its slopes are", ...,
        (x, y)); None where all are finite (first_nonfinite:
        at each cell's vertices and the nonlinear sheet's quadrature points; collective)."""
        x = ufl.SpatialCoordinate(mesh)
        g, H = self.slopes(x), self.hessian(x)
        bad = first_nonfinite(mesh, [self.z0(x), g[0], g[1], H[0, 0], H[0, 1], H[1, 1]])
        if bad is None:
            return None
        k, where = bad
        return ("z0 is" if k == 0 else "its slopes are" if k < 3 else "its second derivatives are"), where

    def z0(self, x):
        """The UFL expression of z0 at the spatial coordinate x."""
        return self.ufl(x)

    def slopes(self, x):
        return ufl.grad(self.z0(x))

    def hessian(self, x):
        return ufl.grad(ufl.grad(self.z0(x)))

    def kappa0(self, x):
        return -self.hessian(x)
