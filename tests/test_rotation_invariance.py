"""Invariance of the discrete solution under a rigid rotation of the mesh.

A clamped square plate (w = w_x = w_y = 0 on the boundary: rotation invariant conditions) of
perturbed 'crossed' triangles under uniform pressure is solved twice: on the mesh and on the same
mesh rotated by theta about the origin. The physics is invariant, and so must the discrete
solution be, vertex by vertex:

    w_rot(R x) = w(x),      grad w_rot(R x) = R grad w(x)   i.e.   R^T (w_x, w_y)_rot = (w_x, w_y)

This holds only because the carrier slopes are physical and mapped with J per cell. Without the
map (plain DOLFINx: the reference slopes are taken for global ones) the answer depends on the
orientation of the mesh.
"""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
import pytest
from dolfinx import fem
from dolfinx import mesh as dmesh
from mpi4py import MPI

from shellform.forms.fields import ShellParameters
from shellform.assembly.hybrid_element import HybridElement
from shellform import linear
from shellform.assembly.kernels import HybridShellForms

THETA = 0.7
ROT = np.array([[np.cos(THETA), -np.sin(THETA)], [np.sin(THETA), np.cos(THETA)]])
TOL = 1e-10


def plate(theta=0.0):
    """Unit square, 6 x 6 'crossed' triangles, interior vertices moved by a smooth perturbation
    (vanishing on the boundary), then rotated by theta. The mesh is built the same way each time,
    so the vertex order does not depend on theta."""
    msh = dmesh.create_unit_square(MPI.COMM_WORLD, 6, 6, dmesh.CellType.triangle,
                                   diagonal=dmesh.DiagonalType.crossed)  # fmt: skip
    x = msh.geometry.x
    X, Y = x[:, 0].copy(), x[:, 1].copy()
    bump = np.sin(np.pi * X) * np.sin(np.pi * Y)
    X += 0.04 * bump * np.sin(5.0 * Y + 1.0)
    Y += 0.04 * bump * np.cos(3.0 * X + 0.5)
    xy = np.column_stack([X - 0.5, Y - 0.5])  # centred, then rotated about the origin
    x[:, :2] = xy @ np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]]).T
    return msh


def clamped_solve(msh, mapped):
    c = lambda v: fem.Constant(msh, np.float64(v))  # noqa: E731
    params = ShellParameters(E=c(1.0e3), nu=c(0.3), thickness=c(0.05), kappa0=None, pressure=c(1.0))
    forms = HybridShellForms(msh, HybridElement(("bending",)), params, mapped=mapped)
    V = forms.V
    msh.topology.create_connectivity(1, 2)
    bdofs = fem.locate_dofs_topological(V, 1, dmesh.exterior_facet_indices(msh.topology))
    bcs = [fem.dirichletbc(np.zeros(V.dofmap.index_map_bs), bdofs, V)]  # w = w_x = w_y = 0
    q = linear.lu_solve(*linear.assemble_system(forms, bcs), V)  # uniform pressure
    n = V.dofmap.index_map.size_local
    vals = q.x.array.reshape(-1, 3)[:n]  # (w, w_x, w_y) per vertex
    return vals, V.tabulate_dof_coordinates()[:n, :2]


@pytest.fixture(scope="module")
def solutions():
    out = {}
    for mapped in (True, False):
        for theta in (0.0, THETA):
            out[mapped, theta] = clamped_solve(plate(theta), mapped)
    return out


def _compare(a, b):
    """Relative differences of w and of the slopes (b's slopes rotated back by R^T)."""
    (va, xa), (vb, xb) = a, b
    assert np.abs(xb - xa @ ROT.T).max() < 1e-14, "vertex order changed with the rotation"
    dw = np.abs(vb[:, 0] - va[:, 0]).max() / np.abs(va[:, 0]).max()
    slopes_back = vb[:, 1:] @ ROT  # row-wise R^T g
    dg = np.abs(slopes_back - va[:, 1:]).max() / np.abs(va[:, 1:]).max()
    return dw, dg


def test_mapped_solution_is_rotation_invariant(solutions):
    """Mapped element: w at every vertex unchanged, slopes rotated (R^T grad w_rot = grad w),
    both to 1e-10 relative."""
    dw, dg = _compare(solutions[True, 0.0], solutions[True, THETA])
    assert np.abs(solutions[True, 0.0][0][:, 0]).max() > 0
    assert dw < TOL, f"deflection changed under rotation: {dw:.3e}"
    assert dg < TOL, f"slopes not rotated with the mesh: {dg:.3e}"


def test_unmapped_solution_depends_on_orientation(solutions):
    """mapped=False (plain DOLFINx, reference slopes as global dofs): the deflection changes by
    more than 1e-3 (relative) when the mesh is rotated, and differs from the mapped one."""
    dw, _ = _compare(solutions[False, 0.0], solutions[False, THETA])
    assert dw > 1e-3, f"unmapped element unexpectedly rotation invariant: {dw:.3e}"
    w_mapped, w_plain = solutions[True, 0.0][0][:, 0], solutions[False, 0.0][0][:, 0]
    diff = np.abs(w_plain - w_mapped).max() / np.abs(w_mapped).max()
    assert diff > 1e-3, f"unmapped element unexpectedly agrees with the mapped one: {diff:.3e}"
