"""pi_g = pi_m + pi_a - pi_b for the effects a scene switches on (paper eq. 5).

Each effect of kind "form term" in the registry shellform.effects names its ``Terms`` here;
the functional sums the terms of the effects that are on, in the registry's order:

- ``membrane_terms``  membrane energy, membrane-strain constraint
- ``bending_terms``   bending energy, curvature constraint, string-net boundary terms

The effect ``shallow_curvature`` adds the 1/R terms of f^p and f^b to the constraints (kappa0);
``cubic_membrane`` changes the element (shellform.assembly.hybrid_element), not the terms; the
pressure's work is a load (``external_work``). The other effects are parts of the nonlinear
sheet or of the contact (shellform.effects, docs/scenes.md).
"""

from dataclasses import dataclass
from typing import Callable

import ufl

from shellform import effects as registry
from shellform.forms import assumed_strain, bending, loads, membrane, string_net
from shellform.forms.fields import HybridFields, ShellParameters


@dataclass(frozen=True)
class Terms:
    """The terms one effect adds to pi_g: its strain energy (f, p) -> form and its constraints
    (f, p, kappa0, n) -> [forms]."""

    energy: Callable
    constraints: Callable


membrane_terms = Terms(
    lambda f, p: membrane.energy(f.eps_p, p),  # pi_m^p(eps_p)
    lambda f, p, kappa0, n: [assumed_strain.membrane_constraint(f.N, f.eps_p, f.u, f.w, kappa0)])  # N:(f^p - eps_p)
bending_terms = Terms(
    lambda f, p: bending.energy(f.eps_b, p),  # pi_m^b(eps_b)
    lambda f, p, kappa0, n: [assumed_strain.bending_constraint(f.M, f.eps_b, f.u, kappa0),  # M:(f^b - eps_b)
                             string_net.bending_boundary(f.M, f.w, f.g, n)])  # M and the slope carrier g


def strain_energy(f: HybridFields, p: ShellParameters, effects) -> ufl.Form | None:
    """pi_m without the loads: the energy of the assumed strains."""
    terms = [t.energy(f, p) for t in registry.form_terms(effects)]
    return sum(terms[1:], terms[0])


def constraints(f: HybridFields, p: ShellParameters, effects, n) -> ufl.Form:
    """pi_a - pi_b: multipliers times (strain of the displacements - assumed strain)."""
    kappa0 = p.kappa0 if "shallow_curvature" in effects else None
    terms = [c for t in registry.form_terms(effects) for c in t.constraints(f, p, kappa0, n)]
    return sum(terms[1:], terms[0])


def external_work(f: HybridFields, p: ShellParameters, effects) -> ufl.Form | None:
    if p.pressure is None or f.w is None:
        return None
    return loads.pressure_work(f.w, p.pressure, p.pressure_field)


def hybrid_functional(f: HybridFields, p: ShellParameters, effects, n) -> ufl.Form:
    """pi_g without the external work (which shellform assembles as the load vector)."""
    return strain_energy(f, p, effects) + constraints(f, p, effects, n)
