"""The physical mapping of the reduced cubic, tested apart from assembly (FInAT style).

On a physical triangle K = F(K_ref), F(X) = x0 + J X, the reduced cubic is built directly with
plain numpy: the 9-dimensional space of cubics p(x, y) with

    p(c) = 1/3 sum_i p(x_i) + 1/6 sum_i grad p(x_i) . (c - x_i)        (c the centroid)

and the dual basis "value and PHYSICAL gradient at each vertex". The reference element
(shellform.elements.reduced_cubic, dofs w, dw/dX, dw/dY) mapped with T = blockdiag(1, J^T) per
vertex must give the same basis: phi_phys = T^T (phi_ref o F^-1). The unmapped combination (T = I,
what plain DOLFINx does) must not.
"""

import shellform  # noqa: F401  (before dolfinx / basix runtime)

import basix
import numpy as np
import pytest

from shellform.elements import reduced_cubic

# Physical triangles: generic acute, obtuse, rotated + small + far from the origin, and one
# with clockwise vertex order (det J < 0), which DOLFINx meshes may contain.
_ROT = np.array([[np.cos(2.3), -np.sin(2.3)], [np.sin(2.3), np.cos(2.3)]])
TRIANGLES = {
    "acute": np.array([[0.1, 0.2], [1.3, 0.4], [0.5, 1.1]]),
    "obtuse": np.array([[0.0, 0.0], [2.0, 0.0], [1.7, 0.3]]),
    "rotated_small_far": (0.05 * np.array([[0.0, 0.0], [1.0, 0.1], [0.3, 0.8]])) @ _ROT.T
    + np.array([3.0, -2.0]),
    "clockwise": np.array([[0.2, -0.3], [-0.4, 0.9], [1.1, 0.5]]),
}

# Monomials x^a y^b of degree <= 3, in local coordinates (x - c) / h for conditioning.
EXPONENTS = [(a, k - a) for k in range(4) for a in range(k, -1, -1)]


def _local(points, tri):
    c = tri.mean(axis=0)
    h = np.max(np.linalg.norm(tri - np.roll(tri, 1, axis=0), axis=1))
    return (points - c) / h, h


def _monomials(points, tri):
    """Values and physical gradients of the 10 local monomials: (3, npts, 10)."""
    s, h = _local(np.atleast_2d(points), tri)
    out = np.zeros((3, s.shape[0], len(EXPONENTS)))
    for k, (a, b) in enumerate(EXPONENTS):
        out[0, :, k] = s[:, 0] ** a * s[:, 1] ** b
        if a:
            out[1, :, k] = a * s[:, 0] ** (a - 1) * s[:, 1] ** b / h
        if b:
            out[2, :, k] = b * s[:, 0] ** a * s[:, 1] ** (b - 1) / h
    return out


def physical_basis(tri):
    """Monomial coefficients (10, 9) of the nodal basis built directly on the physical cell."""
    c = tri.mean(axis=0)
    ell = _monomials(c, tri)[0, 0].copy()
    vert = _monomials(tri, tri)  # (3 derivs, 3 vertices, 10)
    for i in range(3):
        ell -= vert[0, i] / 3 + (vert[1, i] * (c - tri[i])[0] + vert[2, i] * (c - tri[i])[1]) / 6
    _, _, vt = np.linalg.svd(ell[None, :])
    null = vt[1:].T  # (10, 9): the space
    # dual matrix: row 3 i + d = (value, d/dx, d/dy)[d] at vertex i
    dual = np.stack([vert[d, i] for i in range(3) for d in range(3)])  # (9, 10)
    return null @ np.linalg.inv(dual @ null)


def evaluate_physical(coeffs, points, tri):
    return _monomials(points, tri)[0] @ coeffs  # (npts, 9)


def jacobian(tri):
    return np.column_stack([tri[1] - tri[0], tri[2] - tri[0]])


def slope_map(J):
    """T: physical vertex dofs (w, w_x, w_y) -> reference dofs (w, dw/dX, dw/dY), per vertex."""
    T = np.zeros((9, 9))
    for v in range(3):
        T[3 * v, 3 * v] = 1.0
        T[3 * v + 1 : 3 * v + 3, 3 * v + 1 : 3 * v + 3] = J.T
    return T


def evaluate_mapped(points, tri, mapped=True):
    """phi_phys(x) = T^T phi_ref(F^-1 x) from the basix reference element."""
    J = jacobian(tri)
    X = np.linalg.solve(J, (points - tri[0]).T).T
    phi_ref = reduced_cubic.element().tabulate(0, X)[0]  # (npts, 9)
    T = slope_map(J) if mapped else np.eye(9)
    return phi_ref @ T


def random_points(tri, n, seed):
    rng = np.random.default_rng(seed)
    lam = rng.dirichlet(np.ones(3), size=n)
    return lam @ tri


def physical_dofs(f, grad, tri):
    """Physical dof vector (value, d/dx, d/dy per vertex) of a function given with its gradient."""
    return np.concatenate([[f(x), *grad(x)] for x in tri])


@pytest.mark.parametrize("name", TRIANGLES)
def test_mapped_reference_equals_physical_element(name):
    """T^T (phi_ref o F^-1) equals the element built on the physical cell, to 1e-12.

    With T = I (no map) the two differ by more than 1e-2: the reference slope dofs would be
    taken for physical slopes.
    """
    tri = TRIANGLES[name]
    coeffs = physical_basis(tri)
    pts = np.vstack([tri, random_points(tri, 60, seed=1)])
    direct = evaluate_physical(coeffs, pts, tri)
    # the direct basis is nodal for the physical dofs (sanity of the construction)
    dual = np.stack([_monomials(tri, tri)[d, i] for i in range(3) for d in range(3)])
    assert np.abs(dual @ coeffs - np.eye(9)).max() < 1e-12
    mapped = evaluate_mapped(pts, tri)
    err = np.abs(mapped - direct).max()
    assert err < 1e-12, f"{name}: mapped reference basis differs from the physical one by {err:.3e}"
    unmapped = np.abs(evaluate_mapped(pts, tri, mapped=False) - direct).max()
    assert unmapped > 1e-2, f"{name}: the unmapped element should differ, got {unmapped:.3e}"


@pytest.mark.parametrize("name", TRIANGLES)
def test_space_contains_quadratics_but_not_cubics(name):
    """Interpolation with the mapped element reproduces x^2, xy, y^2 (and lower) exactly; a
    generic cubic is not in the space, so its interpolant differs from it."""
    tri = TRIANGLES[name]
    pts = random_points(tri, 80, seed=2)
    phi = evaluate_mapped(pts, tri)
    quadratics = {
        "x^2": (lambda x: x[0] ** 2, lambda x: (2 * x[0], 0.0)),
        "xy": (lambda x: x[0] * x[1], lambda x: (x[1], x[0])),
        "y^2": (lambda x: x[1] ** 2, lambda x: (0.0, 2 * x[1])),
        "1 + x - 2y": (lambda x: 1 + x[0] - 2 * x[1], lambda x: (1.0, -2.0)),
    }
    for label, (f, grad) in quadratics.items():
        interp = phi @ physical_dofs(f, grad, tri)
        exact = np.array([f(x) for x in pts])
        err = np.abs(interp - exact).max() / max(1.0, np.abs(exact).max())
        assert err < 1e-13, f"{name}: {label} not reproduced, error {err:.3e}"

    # a generic cubic, in coordinates local to the cell so that it is O(1) there
    c, h = tri.mean(axis=0), np.ptp(tri, axis=0).max()
    a = np.array([0.7, -1.1, 0.4, 0.9])

    def cubic(x):
        s, t = (x - c) / h
        return a[0] * s**3 + a[1] * s**2 * t + a[2] * s * t**2 + a[3] * t**3

    def cubic_grad(x):
        s, t = (x - c) / h
        return (
            (3 * a[0] * s**2 + 2 * a[1] * s * t + a[2] * t**2) / h,
            (a[1] * s**2 + 2 * a[2] * s * t + 3 * a[3] * t**2) / h,
        )

    interp = phi @ physical_dofs(cubic, cubic_grad, tri)
    exact = np.array([cubic(x) for x in pts])
    miss = np.abs(interp - exact).max() / np.abs(exact).max()
    assert miss > 1e-3, f"{name}: a generic cubic should not be in the space ({miss:.3e})"


def _hermite(s, p0, p1, d0, d1):
    """1D cubic Hermite on [0, 1] from end values and end derivatives d/ds."""
    return (
        (2 * s**3 - 3 * s**2 + 1) * p0
        + (s**3 - 2 * s**2 + s) * d0
        + (-2 * s**3 + 3 * s**2) * p1
        + (s**3 - s**2) * d1
    )


def test_edge_traces_depend_on_edge_end_values_only():
    """String-net property on the reference triangle: on every edge the trace of every basis
    function is the cubic Hermite interpolant of its end values and end tangential derivatives;
    in particular the three basis functions of a vertex vanish on the opposite edge."""
    e = reduced_cubic.element()
    verts = basix.geometry(basix.CellType.triangle)
    edges = basix.topology(basix.CellType.triangle)[1]  # edge k is opposite vertex k
    s = np.linspace(0.0, 1.0, 23)
    worst_opposite, worst_hermite = 0.0, 0.0
    for k, (a, b) in enumerate(edges):
        pts = verts[a] + s[:, None] * (verts[b] - verts[a])
        trace = e.tabulate(0, pts)[0]  # (npts, 9)
        ends = e.tabulate(1, verts[[a, b]])  # (3, 2, 9)
        t = verts[b] - verts[a]
        ds = ends[1] * t[0] + ends[2] * t[1]  # d/ds at the two ends
        herm = _hermite(s[:, None], ends[0, 0], ends[0, 1], ds[0], ds[1])
        worst_hermite = max(worst_hermite, np.abs(trace - herm).max())
        opposite = [d for d in range(9) if d // 3 == k]
        worst_opposite = max(worst_opposite, np.abs(trace[:, opposite]).max())
    assert worst_opposite < 1e-13, f"vertex basis not zero on the opposite edge: {worst_opposite:.3e}"
    assert worst_hermite < 1e-13, f"trace is not the Hermite cubic of the end data: {worst_hermite:.3e}"
