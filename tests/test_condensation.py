"""The condensation of the linear element, checked on single cells apart from the mesh.

The kernels tabulate only C per cell and take G^-1 H G^-1 from the reference triangle, scaled
by 1/|det J| (shellform.assembly.condensation). On a physical cell the same stiffness must come
from the cell's own blocks, K = T^T C^T G^-1 H G^-1 C T, and the centroid strains from
eps = G^-1 C T q, with G and H tabulated on that cell.
"""

import shellform  # noqa: F401  (before dolfinx / basix runtime)

import basix.ufl
import dolfinx.fem.petsc as fem_petsc
import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh as dmesh
from mpi4py import MPI

from shellform.assembly import slope_map
from shellform.assembly.hybrid_element import HybridElement
from shellform.assembly.kernels import HybridShellForms
from shellform.forms.fields import ShellParameters

CELLS = {
    "sheared": np.array([[0.3, -0.2], [2.1, 0.4], [-0.5, 1.6]]),
    "small_far_clockwise": np.array([[3.0, -2.0], [2.98, -1.95], [3.04, -1.97]]),
}
EFFECTS = {
    "plate": ("bending",),
    "membrane": ("membrane",),
    "shallow shell": ("bending", "membrane", "shallow_curvature"),
}


def one_cell(points):
    domain = ufl.Mesh(basix.ufl.element("Lagrange", "triangle", 1, shape=(2,)))
    return dmesh.create_mesh(MPI.COMM_SELF, np.array([[0, 1, 2]], dtype=np.int64), domain, points)


def forms_on(points, effects):
    msh = one_cell(points)
    c = lambda v: fem.Constant(msh, np.float64(v))  # noqa: E731
    kappa0 = fem.Constant(msh, np.array([[0.2, 0.05], [0.05, -0.1]])) if "shallow_curvature" in effects else None
    params = ShellParameters(E=c(2.1), nu=c(0.3), thickness=c(0.05), kappa0=kappa0,
                             pressure=c(1.0) if "bending" in effects else None)
    return HybridShellForms(msh, HybridElement(effects), params)


def own_blocks(forms):
    """(C, G, H) tabulated on the mesh's one cell, T of its slope map, and K from them."""
    k, e = forms.kernels, forms.element
    g = forms.mesh.geometry
    coords = g.x[g.dofmaps[0][0]].ravel()
    values = np.concatenate([np.atleast_1d(c.value).ravel() for c in forms.constants[:-1]] or [np.zeros(0)])
    C, G, H = k.blocks(values, coords)
    cols, codes = e.slope_map_tables()
    coef = slope_map.coefficients(slope_map.jacobian(coords), codes, True)
    T = np.zeros((len(e.q), e.carrier_dim))
    for r in range(T.shape[0]):
        for j in range(2):
            if cols[r, j] >= 0:
                T[r, cols[r, j]] += coef[r, j]
    B = np.linalg.solve(G, C @ T)
    return B, B.T @ H @ B


@pytest.mark.parametrize("effects", EFFECTS.values(), ids=EFFECTS.keys())
@pytest.mark.parametrize("cell", CELLS.values(), ids=CELLS.keys())
def test_once_per_mesh_condensation_equals_the_cells_own(cell, effects):
    forms = forms_on(cell, effects)
    A = fem_petsc.assemble_matrix(forms.stiffness)
    A.assemble()
    K = A.convert("dense").getDenseArray()
    # DOLFINx orders the carrier by its dofmap: map back to vertex-major order
    dofs = forms.V.dofmap.cell_dofs(0)
    bs = forms.element.block_size
    order = (bs * dofs[:, None] + np.arange(bs)).ravel()
    K = K[np.ix_(order, order)]
    B, K_own = own_blocks(forms)
    assert np.abs(K - K_own).max() <= 1e-11 * np.abs(K_own).max()
    # and the recovered centroid strains of an arbitrary carrier state
    q = fem.Function(forms.V)
    q.x.array[:] = np.random.default_rng(7).standard_normal(q.x.array.size)
    W = fem.functionspace(forms.mesh, ("DG", 0, (6 * len(forms.element.groups),)))
    got = fem.assemble_vector(forms.recovery_form(q, W)).array
    eps = B @ q.x.array[order]
    centroid = forms.element.centroid_average() @ eps
    for g in range(len(forms.element.groups)):
        want = centroid[3 * g:3 * g + 3]
        assert np.allclose(got[6 * g:6 * g + 3], want, rtol=1e-10, atol=1e-12 * np.abs(want).max())
