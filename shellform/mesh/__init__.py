"""Meshes: the rectangular blank (full or quarter, structured or gmsh) and the patch-test mesh."""

from shellform.mesh.rectangle import SIDE_TAG, SIDES, RectangleMesh, distorted_patch, rectangle

__all__ = ["SIDES", "SIDE_TAG", "RectangleMesh", "rectangle", "distorted_patch"]
