"""Load the DOLFINx runtime before any test module imports dolfinx, mpi4py or petsc4py; fixtures
the tests share."""

import shellform  # noqa: F401

import numpy as np
import pytest


@pytest.fixture
def rotation():
    """rotation(axis, degrees): the rotation by `degrees` about `axis` (Rodrigues)."""

    def turn(axis, degrees: float) -> np.ndarray:
        a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
        K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
        th = np.radians(degrees)
        return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K

    return turn
