"""A rigid tool placed in the scene by a rotation and a translation, and moved along its axis.

A tool is given in its own frame (a CAD model's, y) by what every tool gives (tools.py):
gap(y, offset, 0) -> (signed distance minus offset, unit normal), shape(y, offset, 0) -> H.
Placed in the scene's frame (x) with the rotation R and the translation p, and moved by s along
the unit axis a,

    x = R y + p + s a,        y = R^T (x - p - s a).

A distance is the same in both frames, so the gap is the tool's at y; the normal and the
Hessian of the distance turn with the frame: n(x) = R n(y), H(x) = R H(y) R^T. The tool's
travel is s a: the driver moves the punch by -stroke along a (tools.py: the punch's axis is
+z, its travel down is negative), and friction measures the sheet's slip relative to the
tool's motion along a (friction.py). The rotation is given by three angles in degrees,
turning the tool about the scene's x, then y, then z axis.
"""

import numpy as np

UP = np.array([0.0, 0.0, 1.0])


def rotation(angles_deg) -> np.ndarray:
    """R = Rz Ry Rx of the angles (degrees) about x, y and z: x turned first."""
    ax, ay, az = np.radians(np.asarray(angles_deg, dtype=float).reshape(3))
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


class Placed:
    """`tool` (in its own frame) turned by `rotation` (3 x 3, orthonormal, det +1), moved by
    `translation` and travelling along `axis` (normalised here)."""

    def __init__(self, tool, rotation=np.eye(3), translation=(0.0, 0.0, 0.0), axis=UP):
        self.tool = tool
        self.R = np.asarray(rotation, dtype=float).reshape(3, 3)
        if not np.allclose(self.R @ self.R.T, np.eye(3), atol=1e-12) or np.linalg.det(self.R) < 0:
            raise ValueError("rotation must be a proper rotation (orthonormal, determinant +1)")
        self.translation = np.asarray(translation, dtype=float).reshape(3)
        a = np.asarray(axis, dtype=float).reshape(3)
        if not np.linalg.norm(a) > 0:
            raise ValueError("axis must be a non-zero vector")
        self.axis = a / np.linalg.norm(a)

    def local(self, x, s: float) -> np.ndarray:
        """Points x of the scene in the tool's frame, the tool moved by s along its axis."""
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        return (x - self.translation - s * self.axis) @ self.R

    def gap(self, x, offset=0.0, dz: float = 0.0):
        """The tool's gap and normal at the points x, the tool moved by dz along its axis."""
        g, n = self.tool.gap(self.local(x, dz), offset, 0.0)
        return g, n @ self.R.T

    def shape(self, x, offset=0.0, dz: float = 0.0):
        """H = dn/dx in the scene's frame: R H R^T."""
        H = self.tool.shape(self.local(x, dz), offset, 0.0)
        return np.einsum("ij,njk,lk->nil", self.R, H, self.R)
