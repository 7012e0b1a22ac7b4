"""The mechanism that maps, condenses and assembles the hybrid element on DOLFINx.

- ``hybrid_element``  the reference-element fields of the functional and the carrier layout
- ``slope_map``       physical vertex slopes -> reference degrees of freedom, per cell (J^T)
- ``condensation``    elimination of the element-local assumed strains and multipliers
- ``kernels``         FFCx kernels of the UFL terms, wrapped in numba cfuncs, as DOLFINx forms
"""
