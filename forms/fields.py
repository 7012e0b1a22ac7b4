"""The fields and parameters the terms of the functional are written in."""

from dataclasses import dataclass

import ufl


@dataclass
class HybridFields:
    """Fields of one element. Nodal fields are shared with the neighbours through the carrier;
    assumed strains and multipliers live in one element only and are condensed out.

    u     in-plane displacement (P1 vector)                      [membrane]
    w     transverse displacement (reduced cubic)                 [bending]
    g     nodal slopes grad w, interpolated linearly (P1 vector): the string-net normal slope
    eps_p assumed membrane strain (linear, symmetric)             [membrane]
    eps_b assumed curvature (linear, symmetric)                   [bending]
    N, M  membrane force and moment multipliers (same spaces as eps_p, eps_b)
    """

    u: ufl.core.expr.Expr | None
    w: ufl.core.expr.Expr | None
    g: ufl.core.expr.Expr | None
    eps_p: ufl.core.expr.Expr | None
    eps_b: ufl.core.expr.Expr | None
    N: ufl.core.expr.Expr | None
    M: ufl.core.expr.Expr | None


@dataclass
class ShellParameters:
    """Material, reference surface and load, as UFL constants (dolfinx.fem.Constant is one).

    kappa0 = -grad grad z0: the curvature tensor of the reference surface z0(x, y); for principal
    radii R1, R2 along x, y it is diag(1/R1, 1/R2).
    """

    E: ufl.core.expr.Expr
    nu: ufl.core.expr.Expr
    thickness: ufl.core.expr.Expr
    kappa0: ufl.core.expr.Expr | None = None
    pressure: ufl.core.expr.Expr | None = None
    pressure_field: object = None  # forms.loads.PressureField: how the pressure spreads (None: uniform per plan area)
