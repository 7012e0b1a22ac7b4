"""pi_m, load part: work of the external loads (subtracted from the strain energy).

Pressure p on the transverse displacement: W = int_K p w dA, with w the reduced cubic
(consistent load). Point loads act on vertex values directly and are added by shellform.loads.

The pressure is a constant times a distribution over the plan (PressureField): uniform per unit
plan area, or any shape(x, y), and per unit area of a curved reference surface z0 (self weight):
the surface's area per unit plan area is J = sqrt(1 + |grad z0|^2), so p dA_surface = p J dA_plan.
It stays along +z (+w), a dead load.
"""

from dataclasses import dataclass

import ufl

from shellform.forms.plan_field import PlanField


@dataclass(frozen=True)
class PressureField:
    """How the pressure p is spread: p(x, y) = p shape(x, y) J(x, y) per unit plan area.

    shape: the text of a PlanField ("" for 1); surface: None for a pressure per unit plan area
    (J = 1), else the reference surface per unit of whose area it acts: a ReferenceSurface, or
    the 4 entries of the constant kappa0 of the paraboloid z0 = -x . kappa0 x / 2 (grad z0 =
    -kappa0 x). Hashable: kernels that integrate it are compiled once per field."""

    shape: str = ""
    surface: object = None

    def density(self, x):
        """shape(x, y) J(x, y) at the spatial coordinate x."""
        d = PlanField(self.shape).ufl(x) if self.shape else ufl.as_ufl(1.0)
        if self.surface is None:
            return d
        if hasattr(self.surface, "slopes"):
            g = self.surface.slopes(x)
        else:
            k = ufl.as_matrix([[self.surface[0], self.surface[1]], [self.surface[2], self.surface[3]]])
            g = -ufl.dot(k, ufl.as_vector([x[0], x[1]]))
        return d * ufl.sqrt(1.0 + ufl.dot(g, g))


def pressure_work(w, pressure, field: PressureField | None = None):
    """int p w dA over the plan: the constant `pressure` times the field's density (uniform without)."""
    if field is None:
        return pressure * w * ufl.dx
    x = ufl.SpatialCoordinate(ufl.domain.extract_unique_domain(w))
    return pressure * field.density(x) * w * ufl.dx
