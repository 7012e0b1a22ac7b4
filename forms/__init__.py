"""The hybrid functional of the paper, one UFL module per term.

    pi_g = pi_m + pi_a - pi_b                                          (paper eq. 5)

- ``strains``         f^p, f^s, f^b: shallow-shell strain measures (eq. 4)
- ``membrane``        pi_m, membrane strain energy in the assumed membrane strain eps^p
- ``bending``         pi_m, bending strain energy in the assumed curvature eps^b
- ``loads``           pi_m, work of the external loads (subtracted)
- ``assumed_strain``  pi_a, stress-resultant multipliers N, M times (f - eps) inside each element
- ``string_net``      the element-boundary terms: pi_a's Green's-theorem boundary integral minus pi_b,
                      left with the inter-element (string-net) traces only
- ``functional``      pi_g for the set of effects a scene switches on

Everything here is plain UFL on one triangle: the fields are the reference-element fields of
``shellform.assembly.hybrid_element``; nothing here knows about meshes, maps or condensation.
"""
