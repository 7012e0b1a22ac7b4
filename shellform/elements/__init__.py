"""Finite elements, one per module, each declared by a few attributes."""
