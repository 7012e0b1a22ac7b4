"""A circular cylinder as a rigid tool: the face of a curved binder.

The cylinder's axis is parallel to y through (0, y, z_axis); its radius is R. Its *outside*
(a die's binder face, convex seen from the sheet above it) or its *inside* (the holder's face
that closes onto it, concave) is the tool's face. With rho the distance of a point from the
axis in the xz-plane and e its unit direction from the axis,

    outside:  d = rho - R,   n = grad d = e,    H = dn/dx = (P - e e^T) / rho
    inside:   d = R - rho,   n = -e,            H = -(P - e e^T) / rho

P the projector onto the xz-plane: H's one nonzero eigenvalue is the curvature 1 / rho of the
level surface through the point (> 0 convex, < 0 concave: shellform.tools.protocol), along
the section's tangent; along the axis (y) the face is straight. The gap is d - offset with the
tool moved by dz along its travel axis, +z. Exact everywhere but on the axis itself (rho = 0),
which no sheet point reaches.
"""

from dataclasses import dataclass

import numpy as np

UP = np.array([0.0, 0.0, 1.0])


@dataclass
class Cylinder:
    """The outside (`inside` False) or the inside of the cylinder of radius `radius` about the
    line x = 0, z = z_axis, parallel to y."""

    axis = UP  # its travel dz is along z (placement.py: the contract's axis)

    radius: float
    z_axis: float
    inside: bool = False

    def __post_init__(self):
        if not self.radius > 0:
            raise ValueError(f"cylinder: needs radius > 0, got {self}")

    def _polar(self, x, dz):
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        r = np.stack([x[:, 0], np.zeros(len(x)), x[:, 2] - (self.z_axis + dz)], axis=1)
        rho = np.linalg.norm(r, axis=1)
        return rho, r / rho[:, None]

    def gap(self, x, offset=0.0, dz: float = 0.0):
        rho, e = self._polar(x, dz)
        sign = -1.0 if self.inside else 1.0
        return sign * (rho - self.radius) - np.asarray(offset, dtype=float), sign * e + 0.0

    def shape(self, x, offset=0.0, dz: float = 0.0):
        rho, e = self._polar(x, dz)
        P = np.zeros((len(rho), 3, 3))
        P[:, 0, 0] = P[:, 2, 2] = 1.0
        H = (P - e[:, :, None] * e[:, None, :]) / rho[:, None, None]
        return (-H if self.inside else H) + 0.0
