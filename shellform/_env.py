"""Load the DOLFINx runtime before anything imports dolfinx or petsc4py.

The PyPI wheel ``dolfinx-solver-real`` ships MPI, PETSc and DOLFINx as one bundle whose shared
libraries are put on the loader path by ``import dolfinx_solver``. A DOLFINx from conda or Debian
needs nothing here.

One BLAS thread per process (unless OPENBLAS_NUM_THREADS is set): after each call, OpenBLAS's
worker threads spin for about 2^28 cycles (a tenth of a second) on the cores that the element
and material loops' threads need next. MUMPS gains nothing from a second BLAS thread on the
cup's tangents (the solve took 8.1 to 8.3 s either way on 2,450 cells to 8 mm), while the
spinning slowed the element loop by a third (6.1 -> 9.0 s; docs/performance.md). Parallel work
goes through numba's threads over the cells and MPI ranks.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

try:
    import dolfinx_solver  # noqa: F401
except ImportError:  # DOLFINx installed another way
    pass
