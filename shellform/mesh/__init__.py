"""Meshes of the blank: a rectangle (structured or gmsh), a circle, a polygon or a gmsh file, with
its boundary in named groups (BlankMesh); and the patch-test mesh."""

from shellform.mesh.blank_mesh import BlankMesh
from shellform.mesh.outline import blank
from shellform.mesh.rectangle import SIDE_TAG, SIDES, distorted_patch, rectangle

__all__ = ["SIDES", "SIDE_TAG", "BlankMesh", "blank", "rectangle", "distorted_patch"]
