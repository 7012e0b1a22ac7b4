"""shellform: deep drawing of thin sheet with C1 quasi-conforming shallow-shell elements.

Data flow, one subpackage per stage:

    scene (shellform.scene) -> mesh (shellform.mesh) -> forms (shellform.forms, the folder forms/)
      -> assembly (shellform.assembly: map, condense, assemble)
      -> solve (shellform.linear; shellform.nonlinear: model, driver; shellform.contact)
      -> results (shellform.results: log and progress, tables, fields, the cup's outputs)
"""

from shellform import _env  # noqa: F401  (must run before dolfinx / petsc4py are imported)

__version__ = "0.1.0"


def check_install() -> None:
    """Import the numerical stack and print its versions (used once after `make` installs)."""
    import basix
    import dolfinx
    import ffcx
    import numba
    import ufl
    from petsc4py import PETSc

    petsc = ".".join(str(v) for v in PETSc.Sys.getVersion())
    print(
        f"shellform {__version__}: DOLFINx {dolfinx.__version__}, basix {basix.__version__}, "
        f"FFCx {ffcx.__version__}, UFL {ufl.__version__}, PETSc {petsc}, numba {numba.__version__}"
    )
