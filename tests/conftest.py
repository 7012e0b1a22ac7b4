"""Load the DOLFINx runtime before any test module imports dolfinx, mpi4py or petsc4py; fixtures
the tests share."""

import shellform  # noqa: F401

import json

import numpy as np
import pytest


def _refuse(constant):
    raise ValueError(f"{constant} is not JSON")


@pytest.fixture(autouse=True)
def strict_summaries(request):
    """Every summary.json a test writes into its tmp_path is strict JSON: no NaN, no Infinity."""
    folder = request.getfixturevalue("tmp_path") if "tmp_path" in request.fixturenames else None
    yield
    for path in folder.rglob("summary.json") if folder is not None else ():
        json.loads(path.read_text(), parse_constant=_refuse)


@pytest.fixture
def rotation():
    """rotation(axis, degrees): the rotation by `degrees` about `axis` (Rodrigues)."""

    def turn(axis, degrees: float) -> np.ndarray:
        a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
        K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
        th = np.radians(degrees)
        return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K

    return turn


@pytest.fixture
def turned_states(rotation):
    """turned_states(p): the sheet problem p's state (resultants, plastic strains, equivalent
    plastic strain, thickness stretch) evaluated as it is and turned rigidly by 100 degrees about
    an inclined axis: [state as it is, state turned]."""
    from dolfinx import fem

    def states(p):
        model = p.model
        x = model.V.tabulate_dof_coordinates()[:, :2]
        vals = p.driver.q.x.array.reshape(-1, 9).copy()
        pos = np.column_stack([x, np.zeros(len(x))]) + vals[:, :3]
        grad = vals[:, 3:].reshape(-1, 3, 2) + np.eye(3, 2)
        q = fem.Function(model.V)
        out = []
        for rot in (np.eye(3), rotation([1.0, -2.0, 0.7], 100.0)):
            turned = np.zeros_like(vals)
            turned[:, :3] = pos @ rot.T - np.column_stack([x, np.zeros(len(x))])
            turned[:, 3:] = (np.einsum("ij,njk->nik", rot, grad) - np.eye(3, 2)).reshape(-1, 6)
            q.x.array[:] = turned.ravel()
            model.evaluate(q)
            out.append([a.copy() for a in (model.resultants, model.ep, model.p, model.stretch)])
        return out

    return states
