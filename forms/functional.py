"""pi_g = pi_m + pi_a - pi_b for the effects a scene switches on (paper eq. 5).

Effects and the terms they add:
- ``bending``           bending energy, curvature constraint, string-net boundary terms
- ``membrane``          membrane energy, membrane-strain constraint
- ``shallow_curvature`` the 1/R terms of f^p and f^b (needs bending and membrane)
- ``pressure``          work of a uniform pressure (needs bending)
- ``cubic_membrane``    the in-plane displacement interpolated as w is (u, v and their gradients
                        at the vertices), the assumed membrane strain quadratic: a membrane that
                        bends in plane (linear element; docs/locking.md)

Effects of the nonlinear sheet (forms.nonlinear, shellform.nonlinear):
- ``geometric_nonlinearity``  exact (total-Lagrangian Kirchhoff-Love) membrane and bending strains
- ``plasticity``              elastic-plastic layers through the thickness (Hill 1979)
- ``anisotropy``              r != 1 or m != 2 in the Hill 1979 yield function (needs plasticity)
- ``finite_strain``           the layers in logarithmic strains, a thinning lever arm (needs
                              plasticity and geometric_nonlinearity)
- ``assumed_membrane``        the membrane strain tied to the element edges (the string net),
                              for thin and curved sheets without membrane locking
                              (shellform.assembly.assumed_membrane, docs/locking.md)
"""

import ufl

from shellform.forms import assumed_strain, bending, loads, membrane, string_net
from shellform.forms.fields import HybridFields, ShellParameters

EFFECTS = ("bending", "membrane", "shallow_curvature", "cubic_membrane", "geometric_nonlinearity", "plasticity",
           "anisotropy", "finite_strain", "assumed_membrane")
NONLINEAR_EFFECTS = ("geometric_nonlinearity", "plasticity", "anisotropy", "finite_strain", "assumed_membrane")


def strain_energy(f: HybridFields, p: ShellParameters, effects) -> ufl.Form | None:
    """pi_m without the loads: the energy of the assumed strains."""
    terms = []
    if "membrane" in effects:
        terms.append(membrane.energy(f.eps_p, p))
    if "bending" in effects:
        terms.append(bending.energy(f.eps_b, p))
    return sum(terms[1:], terms[0])


def constraints(f: HybridFields, p: ShellParameters, effects, n) -> ufl.Form:
    """pi_a - pi_b: multipliers times (strain of the displacements - assumed strain)."""
    kappa0 = p.kappa0 if "shallow_curvature" in effects else None
    terms = []
    if "membrane" in effects:
        terms.append(assumed_strain.membrane_constraint(f.N, f.eps_p, f.u, f.w, kappa0))
    if "bending" in effects:
        terms.append(assumed_strain.bending_constraint(f.M, f.eps_b, f.u, kappa0))
        terms.append(string_net.bending_boundary(f.M, f.w, f.g, n))
    return sum(terms[1:], terms[0])


def external_work(f: HybridFields, p: ShellParameters, effects) -> ufl.Form | None:
    if p.pressure is None or f.w is None:
        return None
    return loads.pressure_work(f.w, p.pressure)


def hybrid_functional(f: HybridFields, p: ShellParameters, effects, n) -> ufl.Form:
    """pi_g without the external work (which shellform assembles as the load vector)."""
    return strain_energy(f, p, effects) + constraints(f, p, effects, n)
