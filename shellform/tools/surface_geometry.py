"""The Hessian of the signed distance to a parametrised surface, from the parametrisation's first
and second derivatives at the closest point: what a tool whose surface is a set of parametric
patches (mesh_tool.py) or of CAD faces (surface_tool.py) gives as its shape operator.

With X_u, X_v, X_uu, X_vv, X_uv the derivatives at the closest point c, n the unit normal there
(pointing to the side of positive distance), J = [X_u X_v], G = J^T J and B_ij = -n . X_ij
(B/G > 0 where the surface is convex seen from the positive side), the surface's shape operator
is H0 = J G^-1 B G^-1 J^T (tangential, symmetric), and the Hessian of the signed distance at
distance d from it is

    H = H0 (I + d H0)^-1

each principal curvature k becoming k / (1 + k d), the level surface's. Where G is singular (a
degenerate parametrisation) its pseudo-inverse is taken.
"""

import numpy as np

from shellform.tools.faces import shape_operators


def distance_hessian(J, S, n, d):
    """H0 (I + d H0)^-1 (points, 3, 3) from the derivatives J (points, 2, 3: X_u, X_v), S (points,
    3, 3: X_uu, X_vv, X_uv), the unit normals n (points, 3) and the signed distances d (points):
    compiled (faces.shape_operators) where G is regular, with G's pseudo-inverse where it is not."""
    J, S, n, d = (np.ascontiguousarray(a, dtype=float) for a in (J, S, n, d))
    H, regular = shape_operators(J, S, n, d)
    if not regular.all():  # a singular parametrisation (a pole)
        i = ~regular
        G = np.einsum("pai,pbi->pab", J[i], J[i])
        b = -np.einsum("pki,pi->pk", S[i], n[i])  # -n . (X_uu, X_vv, X_uv)
        B = np.stack([np.stack([b[:, 0], b[:, 2]], 1), np.stack([b[:, 2], b[:, 1]], 1)], 1)
        A = np.einsum("pai,pab->pbi", J[i], np.linalg.pinv(G))  # G^+ J^T as (p, 2, 3)
        H0 = np.einsum("pai,pab,pbj->pij", A, B, A)
        H0 = 0.5 * (H0 + H0.transpose(0, 2, 1))
        H[i] = H0 @ np.linalg.inv(np.eye(3) + d[i, None, None] * H0)
    return H
