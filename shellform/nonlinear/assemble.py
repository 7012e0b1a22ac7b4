"""Element vectors and matrices computed outside DOLFINx, assembled by DOLFINx.

The element loop writes one vector (n) and one matrix (n x n) per owned cell. They reach
DOLFINx as cell-wise (DG0) coefficients of two forms whose kernels copy the coefficient into
the element tensor; DOLFINx then assembles, applies boundary conditions and communicates
ghost contributions as for any form. The arrays are handed to the assembler as the forms'
packed coefficients (`coeffs`, `constants`): packing them anew copied every element matrix
once more per assembly (16 ms at 10,082 cells, two or three times per Newton iteration).
"""

import numba
import numpy as np
from dolfinx import fem
from dolfinx.fem import IntegralType, form_cpp_class

try:  # the module moves in FFCx 0.12
    from ffcx.codegeneration.utils import numba_ufcx_kernel_signature
except ImportError:  # pragma: no cover
    from ffcx.codegeneration.numba.utils import numba_ufcx_kernel_signature

_signature = numba_ufcx_kernel_signature(np.float64, np.float64)


def _copy_kernel(size: int):
    @numba.cfunc(_signature, nopython=True)
    def kernel(A_, w_, c_, coords_, local, perm, data):
        A = numba.carray(A_, (size,))
        w = numba.carray(w_, (size,))
        for i in range(size):
            A[i] = w[i]

    return kernel


class CellArrayForms:
    """A vector form and a matrix form on V whose element tensors are given per cell."""

    _kernels: dict = {}

    def __init__(self, V, cells, n: int):
        mesh = V.mesh
        self.V, self.n, self.cells = V, n, cells
        self._vec_fn = fem.Function(fem.functionspace(mesh, ("DG", 0, (n,))))
        self._mat_fn = fem.Function(fem.functionspace(mesh, ("DG", 0, (n * n,))))
        ncells = cells.size
        self.vectors = self._vec_fn.x.array.reshape(-1, n)[:ncells]
        self.matrices = self._mat_fn.x.array.reshape(-1, n, n)[:ncells]
        for size in (n, n * n):
            if size not in self._kernels:
                self._kernels[size] = _copy_kernel(size)
        self.vector = self._form([V], self._kernels[n], self._vec_fn)
        self.matrix = self._form([V, V], self._kernels[n * n], self._mat_fn)
        # packed as DOLFINx would pack them: one row per entity of the cell integral (self.cells)
        self.vector_coeffs = {(IntegralType.cell, 0): self.vectors.reshape(ncells, n)}
        self.matrix_coeffs = {(IntegralType.cell, 0): self.matrices.reshape(ncells, n * n)}
        self.constants = np.zeros(0)

    def _form(self, spaces, kernel, coefficient):
        integrals = {IntegralType.cell: [(0, kernel.address, self.cells, np.array([0], dtype=np.int8))]}
        cpp = form_cpp_class(np.float64)(
            [V._cpp_object for V in spaces], integrals, [coefficient._cpp_object], [], False, [],
            mesh=self.V.mesh._cpp_object)
        return fem.Form(cpp)
