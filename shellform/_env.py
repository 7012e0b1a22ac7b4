"""Load the DOLFINx runtime before anything imports dolfinx or petsc4py.

The PyPI wheel ``dolfinx-solver-real`` ships MPI, PETSc and DOLFINx as one bundle whose shared
libraries are put on the loader path by ``import dolfinx_solver``. A DOLFINx from conda or Debian
needs nothing here.
"""

try:
    import dolfinx_solver  # noqa: F401
except ImportError:  # DOLFINx installed another way
    pass
