"""The Hessian of the signed distance to a parametrised surface, from the parametrisation's first
and second derivatives at the closest point: what a tool whose surface is a set of parametric
patches (mesh_tool.py) gives as its shape operator.

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


def distance_hessian(J, S, n, d):
    """H0 (I + d H0)^-1 (points, 3, 3) from the derivatives J (points, 2, 3: X_u, X_v), S (points,
    3, 3: X_uu, X_vv, X_uv), the unit normals n (points, 3) and the signed distances d (points)."""
    J, S, n, d = (np.asarray(a, dtype=float) for a in (J, S, n, d))
    B = -np.einsum("pki,pi->pk", S, n)  # -n . (X_uu, X_vv, X_uv)
    B = np.stack([np.stack([B[:, 0], B[:, 2]], 1), np.stack([B[:, 2], B[:, 1]], 1)], 1)
    G = np.einsum("pai,pbi->pab", J, J)
    det = G[:, 0, 0] * G[:, 1, 1] - G[:, 0, 1] * G[:, 1, 0]
    regular = det > 1e-12 * (G[:, 0, 0] + G[:, 1, 1]) ** 2
    Gi = np.stack([np.stack([G[:, 1, 1], -G[:, 0, 1]], 1), np.stack([-G[:, 1, 0], G[:, 0, 0]], 1)], 1) \
        / np.where(regular, det, 1.0)[:, None, None]
    if not regular.all():
        Gi[~regular] = np.linalg.pinv(G[~regular])
    A = np.einsum("pai,pab->pbi", J, Gi)  # G^-1 J^T as (p, 2, 3): rows the dual basis
    H0 = np.einsum("pai,pab,pbj->pij", A, B, A)
    H0 = 0.5 * (H0 + H0.transpose(0, 2, 1))
    return H0 @ np.linalg.inv(np.eye(3) + d[:, None, None] * H0)
