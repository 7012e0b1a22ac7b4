"""The reduced cubic: the transverse-displacement interpolation of the quasi-conforming triangle.

Space: the cubics p on the triangle with the centroid value tied to the vertex data,

    p(c) = 1/3 sum_i p(x_i) + 1/6 sum_i grad p(x_i) . (c - x_i),

a 9-dimensional space that contains every quadratic (the identity is exact for quadratics).
The condition is affine invariant, so the reference space maps onto the physical one.
Degrees of freedom: at each vertex w, dw/dX, dw/dY (reference derivatives; shellform maps them
from the physical slopes with J^T per cell, see shellform.assembly.slope_map).

Its trace on an edge is the cubic Hermite interpolant of the end values of w and dw/ds: the
string-net function w~ of the paper, shared by the two triangles on the edge.
"""

from functools import cache

import basix
import basix.ufl
import numpy as np
from basix.polynomials import tabulate_polynomial_set

cell = basix.CellType.triangle
degree = 3
dofs_per_vertex = 3  # w, dw/dX, dw/dY
embedded_subdegree = 2  # contains P2


def centroid_functional() -> np.ndarray:
    """Coefficients, in basix's orthonormal P3 set, of l(p) = p(c) - (vertex rule above)."""
    verts = basix.geometry(cell)
    c = verts.mean(axis=0)
    tab = tabulate_polynomial_set(cell, basix.PolysetType.standard, degree, 1, np.vstack([verts, c]))
    value, d_dx, d_dy = tab[0].T, tab[1].T, tab[2].T  # (points, polynomials)
    ell = value[3].copy()
    for i, x in enumerate(verts):
        ell -= value[i] / 3 + (d_dx[i] * (c - x)[0] + d_dy[i] * (c - x)[1]) / 6
    return ell


@cache
def element() -> basix.ufl._ElementBase:
    """The reduced cubic as a custom basix element (identity map: shellform maps the slopes)."""
    ell = centroid_functional()
    _, _, vt = np.linalg.svd(ell[None, :])
    wcoeffs = vt[1:]  # orthonormal basis of the null space of l: the 9-dimensional space
    verts = basix.geometry(cell)
    x = [[verts[i : i + 1] for i in range(3)], [np.zeros((0, 2))] * 3, [np.zeros((0, 2))]]
    point_value_and_gradient = np.zeros((3, 1, 1, 3))
    for k in range(3):  # dof k takes derivative k (0: value, 1: d/dX, 2: d/dY) at the vertex
        point_value_and_gradient[k, 0, 0, k] = 1.0
    M = [[point_value_and_gradient] * 3, [np.zeros((0, 1, 0, 3))] * 3, [np.zeros((0, 1, 0, 3))]]
    return basix.ufl.custom_element(
        cell, (), wcoeffs, x, M, 1, basix.MapType.identity, basix.SobolevSpace.H1,
        False, embedded_subdegree, degree, basix.PolysetType.standard,
    )
