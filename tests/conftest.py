"""Load the DOLFINx runtime before any test module imports dolfinx, mpi4py or petsc4py."""

import shellform  # noqa: F401
