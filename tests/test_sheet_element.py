"""The nonlinear sheet element on its own: its map's structured product, rigid modes, patch
tests, exact rotations, the consistent tangent, and Newton's quadratic convergence.

Patch tests run on the distorted 10-triangle patch: every carrier value of an exact field is
prescribed on the boundary vertices, the driver solves for the interior ones, and they must
reproduce the field, with the exact strains at every quadrature point.
"""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
import pytest
from dolfinx import fem, mesh as dmesh
from mpi4py import MPI

from shellform.material import Hill79Material
from shellform.mesh import distorted_patch
from shellform.nonlinear.driver import Controls, Driver
from shellform.nonlinear.model import SheetModel
from shellform.studies import levy

E, NU, T = 1000.0, 0.3, 0.05
MAT = Hill79Material(E=E, nu=NU).pack()
NL = ("bending", "membrane", "geometric_nonlinearity")
LIN = ("bending", "membrane")


def carrier_of(V, U, grad_U):
    """Carrier values (u, v, w, u_x, u_y, v_x, v_y, w_x, w_y) of a field at the vertices."""
    X = V.tabulate_dof_coordinates()[:, :2]
    q = np.zeros((X.shape[0], 9))
    q[:, :3] = U(X)
    q[:, 3:] = grad_U(X).reshape(-1, 6)
    return q.ravel()


def solve_patch(effects, U, grad_U):
    msh = distorted_patch(MPI.COMM_WORLD)
    model = SheetModel(msh, MAT, T, effects)
    V = model.V
    msh.topology.create_connectivity(1, 2)
    facets = dmesh.exterior_facet_indices(msh.topology)
    blocks = fem.locate_dofs_topological(V, 1, facets)
    dofs = (9 * blocks[:, None] + np.arange(9)).ravel().astype(np.int32)
    bc = fem.dirichletbc(np.zeros(9), blocks, V)
    exact = carrier_of(V, U, grad_U)
    qbar = fem.Function(V)
    qbar.x.array[dofs] = exact[dofs]
    d = Driver(model, [bc], prescribed=qbar, controls=Controls(initial_step=1.0, max_step=1.0),
               verbose=False)
    d.run(1.0)
    return model, d.q.x.array, exact


def test_congruence_equals_the_dense_product():
    """K = Q^T Kz Q from Q's structure (the element's tangent) equals the product with the dense
    Q, for a nonsymmetric Kz on every cell of the distorted patch."""
    from shellform.assembly import slope_map
    from shellform.assembly.sheet_element import NDOF, build_q, congruence

    model = SheetModel(distorted_patch(MPI.COMM_WORLD), MAT, T, NL)
    el = model.kernels.element
    (cols, codes), comp = el.q_map(), el.component_columns()
    Kz = np.random.default_rng(1).standard_normal((el.nz, el.nz))
    Q, K = np.zeros((el.nz, NDOF)), np.zeros((NDOF, NDOF))
    for c in range(model.num_cells):
        J = slope_map.jacobian(model.cell_coords[c])
        build_q(J, model.P[c], cols, codes, comp, Q)
        congruence(Kz, J, model.P[c], cols, codes, comp, np.zeros((NDOF, el.nz)), np.zeros((el.nz, NDOF)), K)
        dense = Q.T @ Kz @ Q
        assert np.abs(K - dense).max() <= 1e-13 * np.abs(dense).max()


def test_rigid_modes_of_the_element():
    """Exactly 6 zero-energy modes (3 translations, 3 rotations), linear and nonlinear, on every
    cell and on the assembled patch, with the compatible and with the assumed membrane strain.
    The in-plane modes that the edge tying leaves to the beta part (assumed_membrane) keep a
    stiffness of the order of beta^2 times the compatible element's: on every cell the softest
    non-rigid eigenvalue is at least 0.1 beta^2 of the compatible one (t = 0.05 and a mean longest
    edge of 0.84 here: beta^2 = 0.012; the smallest ratio is 0.33), and on the patch it is above
    1e-7 of the largest."""
    msh = distorted_patch(MPI.COMM_WORLD)
    for effects in (NL, LIN):
        softest = {}
        for assumed in (False, True):
            model = SheetModel(msh, MAT, T, effects + (("assumed_membrane",) if assumed else ()))
            assert np.allclose(model.beta**2, 0.0117, rtol=0.01) if assumed else np.all(model.beta == 1.0)
            model.evaluate(fem.Function(model.V))
            n = 9 * model.V.dofmap.index_map.size_local
            patch = np.zeros((n, n))
            for dofs, K in zip(model.unrolled_dofs, model.forms.matrices):
                patch[np.ix_(dofs, dofs)] += K
            spectra = [np.linalg.eigvalsh(0.5 * (K + K.T)) for K in [*model.forms.matrices, patch]]
            for ev in spectra:
                assert np.all(np.abs(ev[:6]) < 1e-14 * ev[-1])
                assert ev[6] > 1e-7 * ev[-1] if ev is spectra[-1] or not assumed else ev[6] > 0.0
            softest[assumed] = np.array([ev[6] for ev in spectra[:-1]])
        assert np.all(softest[True] >= 0.1 * model.beta**2 * softest[False])


@pytest.mark.parametrize("effects", [LIN, NL])
def test_patch_constant_curvature(effects):
    """w quadratic: K = -grad grad w exactly (the string-net weak Hessian), membrane zero
    for the linear strains; small amplitude for the nonlinear ones (K then differs by O(w^2))."""
    a, b, c = 0.031, -0.072, 0.045
    s = 1.0 if effects == LIN else 1e-6
    U = lambda X: np.stack([0 * X[:, 0], 0 * X[:, 0], s * (a * X[:, 0] ** 2 + b * X[:, 0] * X[:, 1]  # noqa: E731
                                                           + c * X[:, 1] ** 2)], axis=1)
    G = lambda X: np.stack([0 * X, 0 * X, s * np.stack([2 * a * X[:, 0] + b * X[:, 1],  # noqa: E731
                                                        b * X[:, 0] + 2 * c * X[:, 1]], axis=1)], axis=1)
    model, q, exact = solve_patch(effects, U, G)
    assert np.abs(q - exact).max() <= 1e-10 * np.abs(exact).max()
    K = model.strain[:, :, 3:] / s
    assert np.abs(K - np.array([-2 * a, -2 * c, -2 * b])).max() < 1e-8


@pytest.mark.parametrize("plastic", [False, True])
def test_a_followed_taper_carries_no_moment(plastic):
    """After follow_taper the sections carry no moment at the curvature they had, their membrane
    forces unchanged (elastic; plastic, within the shift of the layers' yield); the curvature beyond it bends them as before; the taper is checkpointed."""
    a, b, c = 0.031, -0.072, 0.045
    s = 1e-3
    U = lambda X: np.stack([1e-3 * X[:, 0], 0 * X[:, 0], s * (a * X[:, 0] ** 2 + b * X[:, 0] * X[:, 1]  # noqa: E731
                                                                + c * X[:, 1] ** 2)], axis=1)
    G = lambda X: np.stack([np.stack([1e-3 + 0 * X[:, 0], 0 * X[:, 0]], axis=1), 0 * X,  # noqa: E731
                            s * np.stack([2 * a * X[:, 0] + b * X[:, 1], b * X[:, 0] + 2 * c * X[:, 1]], axis=1)],
                           axis=1)
    effects = NL + ("plasticity",) if plastic else NL
    mat = Hill79Material(E=E, nu=NU, hardening="swift", K=2.0, eps0=1e-4, n=0.2).pack() if plastic else MAT
    msh = distorted_patch(MPI.COMM_WORLD)
    model = SheetModel(msh, mat, T, effects)
    q = fem.Function(model.V)
    q.x.array[:] = carrier_of(model.V, U, G)
    model.evaluate(q)
    before = model.resultants.copy()
    assert np.abs(before[..., 3:]).min() > 0.0
    model.follow_taper(np.ones(model.num_cells, dtype=bool))
    model.evaluate(q)
    M = T**3 / 12 * E / (1 - NU**2) * s * 2 * max(abs(a), abs(b), abs(c))  # the elastic moment's scale
    assert np.abs(model.resultants[..., 3:]).max() < 1e-12 * M
    N = np.abs(before[..., :3]).max()  # elastic: N unchanged; plastic: the layers' yield shifts it slightly
    assert np.abs(model.resultants[..., :3] - before[..., :3]).max() <= (1e-3 if plastic else 1e-12) * N
    q.x.array[:] *= 2.0  # twice the curvature: bent by the part beyond the taper (and stretched twice)
    model.evaluate(q)
    assert np.abs(model.resultants[..., 3:]).max() > 0.5 * np.abs(before[..., 3:]).max()
    saved = {k: v.copy() for k, v in model.checkpoint().items()}
    other = SheetModel(msh, mat, T, effects)
    q_other = fem.Function(other.V)
    q_other.x.array[:] = q.x.array
    other.restore(saved, q_other)
    np.testing.assert_array_equal(other.taper, model.taper)


def test_patch_homogeneous_large_deformation():
    """U = (F - I) X with F a constant 3 x 2 map (stretch, shear, a 70 degree tilt): the exact
    kinematics give constant E = (F^T F - I)/2 and K = 0, reproduced on the distorted patch."""
    th = np.radians(70.0)
    R = np.array([[1, 0, 0], [0, np.cos(th), -np.sin(th)], [0, np.sin(th), np.cos(th)]])
    F = R @ np.array([[1.02, 0.01], [-0.015, 0.99], [0.0, 0.0]])
    I32 = np.eye(3, 2)
    U = lambda X: X @ (F - I32).T  # noqa: E731
    G = lambda X: np.broadcast_to((F - I32), (X.shape[0], 3, 2))  # noqa: E731
    model, q, exact = solve_patch(NL, U, G)
    assert np.abs(q - exact).max() <= 1e-10
    Eg = 0.5 * (F.T @ F - np.eye(2))
    e = model.strain
    assert np.abs(e[:, :, :3] - np.array([Eg[0, 0], Eg[1, 1], 2 * Eg[0, 1]])).max() < 1e-12
    assert np.abs(e[:, :, 3:]).max() < 1e-10


def test_rigid_rotation_is_strain_free(rotation):
    """A bent state rotated rigidly by 120 degrees about an inclined axis keeps its strains."""
    msh = distorted_patch(MPI.COMM_WORLD)
    model = SheetModel(msh, MAT, T, NL)
    X = model.V.tabulate_dof_coordinates()[:, :2]
    # a bent state: x(X) = (X, Y, 0.1 X^2 + 0.05 XY)
    pos = np.stack([X[:, 0], X[:, 1], 0.1 * X[:, 0] ** 2 + 0.05 * X[:, 0] * X[:, 1]], axis=1)
    grad = np.zeros((X.shape[0], 3, 2))
    grad[:, 0, 0] = grad[:, 1, 1] = 1.0
    grad[:, 2, 0] = 0.2 * X[:, 0] + 0.05 * X[:, 1]
    grad[:, 2, 1] = 0.05 * X[:, 0]
    Q = rotation([1.0, 2.0, 0.5], 120.0)
    q = fem.Function(model.V)
    strains = []
    for rot in (np.eye(3), Q):
        vals = np.zeros((X.shape[0], 9))
        vals[:, :3] = pos @ rot.T + np.array([0.3, -0.2, 0.7]) - np.column_stack([X, 0 * X[:, 0]])
        vals[:, 3:] = (np.einsum("ij,njk->nik", rot, grad) - np.eye(3, 2)).reshape(-1, 6)
        q.x.array[:] = vals.ravel()
        model.evaluate(q)
        strains.append(model.strain.copy())
    assert np.abs(strains[1] - strains[0]).max() < 1e-12
    assert np.abs(strains[0][:, :, 3]).max() > 0.1  # the state is really bent


@pytest.mark.parametrize("plastic", [False, True, "finite_strain", "assumed_membrane"])
def test_consistent_tangent(plastic):
    """The assembled tangent equals a central difference of the assembled residual (Levy plate
    at P = 95, elastic, elastic-plastic variants with yielding layers, small and finite strain,
    and elastic with the assumed membrane strain tied to the edges)."""
    kw = {}
    if plastic == "assumed_membrane":
        kw = dict(effects=NL + ("assumed_membrane",))
        plastic = False
    elif plastic:
        extra = ("finite_strain",) if plastic == "finite_strain" else ()
        kw = dict(effects=NL + ("plasticity",) + extra, material=Hill79Material(
            E=1.0, nu=levy.NU, hardening="swift", K=1e-3, eps0=1e-3, n=0.2))
    p = levy.problem(4, controls=Controls(initial_step=0.05, max_step=0.1), **kw)
    assert np.all(p.model.beta < 1.0) == ("assumed_membrane" in p.model.effects)
    d = p.driver
    d.run(90.0 / max(levy.TABLE))
    # a converged state inside the next increment, not committed: the return mapping is smooth
    # there (at a committed state a central difference would straddle loading and unloading)
    lam = 95.0 / max(levy.TABLE)
    converged, _, _, ev = d.newton(lam)
    assert converged
    if plastic:
        assert ev.plastic_layers > 0
    x0 = d.q.x.array.copy()

    def residual(x):
        d.q.x.array[:] = x
        d.residual(lam, tangent=True)
        return d.b.getArray().copy()

    residual(x0)
    A = d.A.copy().convert("dense").getDenseArray()
    free = np.setdiff1d(np.arange(x0.size), d.bc_dofs)
    rng = np.random.default_rng(0)
    h = 1e-7 * np.abs(x0).max()
    for j in rng.choice(free, 12, replace=False):
        xp, xm = x0.copy(), x0.copy()
        xp[j] += h
        xm[j] -= h
        col = (residual(xp) - residual(xm)) / (2 * h)
        assert np.abs(col[free] - A[free, j]).max() <= 1e-5 * np.abs(A[free][:, free]).max()


def test_newton_converges_quadratically():
    """One large increment of the Levy plate: the residual ratios show order 2."""
    p = levy.problem(4, controls=Controls(initial_step=0.25, max_step=0.25, rtol=1e-13))
    d = p.driver
    d.run(0.25)
    res = np.array(d.history[0].residuals)
    e = res / res[0]
    orders = [np.log(e[k + 1]) / np.log(e[k]) for k in range(1, len(e) - 1) if 1e-13 < e[k + 1] and e[k] < 1e-2]
    assert len(orders) >= 1, e
    assert min(orders) > 1.8, (e, orders)
