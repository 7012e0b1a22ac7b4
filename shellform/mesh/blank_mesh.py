"""A mesh of the blank with its boundary in named groups, whatever its outline."""

from collections.abc import Callable
from dataclasses import dataclass, field

import dolfinx.mesh
import numpy as np


@dataclass
class BlankMesh:
    """The triangles of the blank (or of its symmetric part) and its boundary facets, tagged by
    group: groups maps each name (left, rim, edge1, a physical name of a .msh file, ...) to its
    tag in facet_tags. normals maps a group name to its exact outward unit normal n(x, y) ->
    (nx, ny) where the outline is known analytically (the circle's rim); other groups take the
    normals of their facets (shellform.edge_frames)."""

    mesh: dolfinx.mesh.Mesh
    facet_tags: dolfinx.mesh.MeshTags
    bounds: tuple[float, float, float, float]  # x_min, x_max, y_min, y_max
    groups: dict[str, int]
    normals: dict[str, Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]] = field(
        default_factory=dict)

    def facets(self, group: str) -> np.ndarray:
        """Local indices of the boundary facets of a named group."""
        return self.facet_tags.find(self.groups[group])

    @property
    def size(self) -> float:
        """The larger extent of the meshed region (a length scale for tolerances)."""
        x0, x1, y0, y1 = self.bounds
        return max(x1 - x0, y1 - y0)
