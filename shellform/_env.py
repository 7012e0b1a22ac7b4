"""Load the DOLFINx runtime before anything imports dolfinx or petsc4py (and turn PETSc's own
signal handler off: shellform handles SIGINT and SIGTERM).

The PyPI wheel ``dolfinx-solver-real`` ships MPI, PETSc and DOLFINx as one bundle whose shared
libraries are put on the loader path by ``import dolfinx_solver``. A DOLFINx from conda or Debian
needs nothing here.

One BLAS thread per process (unless OPENBLAS_NUM_THREADS is set): after each call, OpenBLAS's
worker threads spin for about 2^28 cycles (a tenth of a second) on the cores that the element
and material loops' threads need next. MUMPS gains nothing from a second BLAS thread on the
cup's tangents (the solve took 8.1 to 8.3 s either way on 2,450 cells to 8 mm), while the
spinning slowed the element loop by a third (6.1 -> 9.0 s; docs/performance.md). Parallel work
goes through the element and material loops' threads over the cells (shellform._jit.over_threads)
and MPI ranks.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

# PETSc's own signal handler off: SIGTERM before the driver steps printed PETSc's "Caught signal
# number 15" banner and ended in MPI_Abort (exit 15); shellform handles SIGINT and SIGTERM itself
# (shellform.nonlinear.interrupt, shellform.cli). PETSc reads PETSC_OPTIONS when it initialises.
if "-no_signal_handler" not in os.environ.get("PETSC_OPTIONS", "").split():
    os.environ["PETSC_OPTIONS"] = (os.environ.get("PETSC_OPTIONS", "") + " -no_signal_handler").strip()

try:
    import dolfinx_solver  # noqa: F401
except ImportError:  # DOLFINx installed another way
    pass

DOLFINX = "0.11"  # the DOLFINx minor version shellform is written for
# DOLFINx's own distribution names (the PyPI wheel, conda-forge's); mpi4py, petsc4py, ufl, basix
# and ffcx come with it and are not declared in pyproject.toml, since the wheel bundles them
DISTRIBUTIONS = ("dolfinx-solver-real", "fenics-dolfinx")


def dolfinx_version() -> str | None:
    """The installed DOLFINx's version from its distribution's metadata (without importing it);
    None where no known distribution is installed (a DOLFINx built from source, Debian's)."""
    from importlib import metadata

    for name in DISTRIBUTIONS:
        try:
            return metadata.version(name)
        except metadata.PackageNotFoundError:
            continue
    return None


def check_dolfinx(version: str | None) -> None:
    """Refuse a DOLFINx of another minor version, naming what is installed and what to do."""
    if version is not None and not (version == DOLFINX or version.startswith(DOLFINX + ".")):
        raise ImportError(f"shellform needs DOLFINx {DOLFINX}.x, and DOLFINx {version} is installed: install "
                          f"the wheel (pip install -e '.[wheel]', or `make venv`) or a DOLFINx {DOLFINX} from "
                          "conda-forge (fenics-dolfinx) into this environment")


def missing_stack() -> list[str]:
    """The modules of DOLFINx's stack that this Python cannot import (without importing them)."""
    from importlib import util

    missing = []
    for name in ("mpi4py", "petsc4py", "dolfinx"):
        try:
            if util.find_spec(name) is None:
                missing.append(name)
        except (ImportError, ValueError):
            missing.append(name)
    return missing


def require_stack() -> None:
    """Without DOLFINx's stack nothing of shellform runs: say in one line what is missing and
    how to install it, and exit with status 1 (no traceback)."""
    missing = missing_stack()
    if missing:
        import sys

        print(f"shellform: no {', '.join(missing)} in this Python ({sys.executable}): shellform needs DOLFINx "
              f"{DOLFINX}; install it with `make venv` in the clone, `pip install dolfinx-solver-real` (Python >= "
              "3.12), or conda-forge's fenics-dolfinx", file=sys.stderr)
        raise SystemExit(1)


require_stack()
check_dolfinx(dolfinx_version())
