"""Rigid-body modes of the element stiffness on one distorted triangle.

The condensed, mapped element matrix K (carrier dofs of the 3 vertices) must be symmetric,
positive semi-definite and vanish exactly on the rigid motions of a flat shell, and on nothing
else:

    bending:   w = 1,  w = x,  w = y        (with their physical slopes w_x, w_y)
    membrane:  u = 1,  v = 1,  (u, v) = (-y, x)    (in-plane translation and rotation)

so 6 zero eigenvalues for (u, v, w, w_x, w_y) (15 x 15) and 3 for (w, w_x, w_y) (9 x 9).
"""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import basix.ufl
import dolfinx.fem.petsc as fem_petsc
import numpy as np
import pytest
import ufl
from dolfinx import fem
from dolfinx import mesh as dmesh
from mpi4py import MPI

from shellform.forms.fields import ShellParameters
from shellform.assembly.hybrid_element import HybridElement
from shellform.assembly.kernels import HybridShellForms

# A distorted, rotated triangle away from the origin (no right angle, no axis-parallel edge).
TRIANGLE = np.array([[0.3, -0.2], [1.45, 0.35], [0.1, 0.9]])


@pytest.fixture(scope="module")
def one_cell():
    domain = ufl.Mesh(basix.ufl.element("Lagrange", "triangle", 1, shape=(2,)))
    return dmesh.create_mesh(MPI.COMM_SELF, np.array([[0, 1, 2]], dtype=np.int64), domain, TRIANGLE)


def element_matrix(msh, effects, kappa0=None):
    c = lambda v: fem.Constant(msh, np.float64(v))  # noqa: E731
    params = ShellParameters(E=c(1.0e3), nu=c(0.3), thickness=c(0.1), kappa0=kappa0,
                             pressure=c(0.0) if "bending" in effects else None)  # fmt: skip
    forms = HybridShellForms(msh, HybridElement(effects), params)
    A = fem_petsc.assemble_matrix(forms.stiffness)
    A.assemble()
    n = A.getSize()[0]
    K = A.getValues(range(n), range(n))
    A.destroy()
    return K, forms


def rigid_modes(forms):
    """Carrier vectors of the rigid motions, one per row."""
    comps = forms.element.carrier_components
    x = forms.V.tabulate_dof_coordinates()[:, :2]
    X, Y = x[:, 0], x[:, 1]
    one, zero = np.ones_like(X), np.zeros_like(X)
    fields = [
        {"w": one, "w_x": zero, "w_y": zero},
        {"w": X, "w_x": one, "w_y": zero},
        {"w": Y, "w_x": zero, "w_y": one},
        {"u": one, "v": zero},
        {"u": zero, "v": one},
        {"u": -Y, "v": X, "u_y": -one, "v_x": one},  # the slopes where the carrier has them
    ]
    modes = []
    for f in fields:
        if not {"u", "v", "w"} & set(f) & set(comps):
            continue
        r = np.zeros((x.shape[0], len(comps)))
        for name, values in f.items():
            if name in comps:
                r[:, comps.index(name)] = values
        modes.append(r.ravel())
    return np.array(modes)


@pytest.mark.parametrize("effects, nzero", [(("bending", "membrane"), 6), (("bending",), 3),
                                           (("bending", "membrane", "cubic_membrane"), 6)])
def test_rigid_modes_are_the_null_space(one_cell, effects, nzero):
    """K = K^T to 1e-12; exactly nzero eigenvalues vanish (lambda_i / lambda_max < 1e-12, the next
    > 1e-6); every rigid motion r satisfies ||K r|| / (||K|| ||r||) < 1e-12."""
    K, forms = element_matrix(one_cell, effects)
    assert K.shape == (3 * len(forms.element.carrier_components),) * 2
    scale = np.abs(K).max()
    asym = np.abs(K - K.T).max() / scale
    assert asym < 1e-12, f"K not symmetric: {asym:.3e}"
    lam = np.linalg.eigvalsh(0.5 * (K + K.T))
    assert lam.min() > -1e-12 * lam.max(), f"K not positive semi-definite: {lam.min():.3e}"
    ratio = np.abs(lam) / lam.max()
    assert np.all(ratio[:nzero] < 1e-12), f"zero eigenvalues: {ratio[:nzero]}"
    assert ratio[nzero] > 1e-6, f"spurious zero-energy mode: lambda_{nzero} / max = {ratio[nzero]:.3e}"
    modes = rigid_modes(forms)
    assert len(modes) == nzero
    normK = np.linalg.norm(K, 2)
    for r in modes:
        res = np.linalg.norm(K @ r) / (normK * np.linalg.norm(r))
        assert res < 1e-12, f"rigid mode not in the null space: {res:.3e}"


@pytest.mark.parametrize("cubic", [False, True])
@pytest.mark.parametrize("R", [10.0, 2.0])
def test_curved_element_has_six_zero_modes(one_cell, R, cubic):
    """A shallow-shell triangle on a doubly curved surface (kappa0 = diag(1/R, 1/(2R))): exactly
    6 zero eigenvalues, the next above 1e-6 of the largest. The assumed membrane strain is
    constant (3 conditions) and the curvature linear (6): 15 - 9 = 6 modes. With a linear
    membrane strain (the element before issue 13) the curvature-coupled term w kappa0 gave the
    membrane 9 conditions that the P1 in-plane field could not meet: membrane locking.

    With cubic_membrane (27 unknowns, quadratic membrane strain) 2 of the 6 are exact zeros and 4
    are the shallow-shell theory's own near-rigid modes: eq. (4) is not exactly invariant under a
    rigid motion (a translation w = c needs u = -c kappa0 x, which leaves f^b = -c kappa0^2), so
    their energy grows like (h/R)^4: 1.4e-14, 1.4e-10 and 0.9e-7 of the largest eigenvalue at
    R = 100, 10 and 2 on this unit cell, each 1e3 times or more below the first deformation mode."""
    kappa0 = fem.Constant(one_cell, np.array([[1 / R, 0.0], [0.0, 0.5 / R]]))
    effects = ("bending", "membrane", "shallow_curvature") + (("cubic_membrane",) if cubic else ())
    K, _ = element_matrix(one_cell, effects, kappa0)
    lam = np.linalg.eigvalsh(0.5 * (K + K.T))
    ratio = np.abs(lam) / lam.max()
    if cubic:
        assert np.all(ratio[:2] < 1e-12) and np.all(ratio[2:6] < 2e-4 * R**-4) and ratio[6] > 1e-4, ratio[:8]
    else:
        assert np.all(ratio[:6] < 1e-12) and ratio[6] > 1e-6, ratio[:8]
