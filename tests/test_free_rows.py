"""The Newton system solved on its free rows (shellform/nonlinear/free_rows.py): the known rows
eliminated give the answer of the whole system, the symbolic factorisation is kept while no
eliminated row turns free, and a drawn cup takes the same path either way."""

from pathlib import Path

import numpy as np
import pytest

import shellform  # noqa: F401  (the DOLFINx runtime first)
from mpi4py import MPI
from petsc4py import PETSc

from shellform import scene
from shellform.contact.problem import DrawingProblem
from shellform.nonlinear.free_rows import FreeRowsLU

ROOT = Path(__file__).resolve().parents[1]


def _system(n, known, seed):
    """A non-symmetric, non-singular n x n matrix with the `known` rows and columns the identity
    (as DOLFINx assembles them), as a serial PETSc AIJ matrix, and a right-hand side."""
    rng = np.random.default_rng(seed)
    K = rng.normal(size=(n, n)) + n * np.eye(n)
    K[known, :] = 0.0
    K[:, known] = 0.0
    K[known, known] = 1.0
    A = PETSc.Mat().createAIJ((n, n), comm=PETSc.COMM_SELF)
    A.setUp()
    A.setValues(range(n), range(n), K)
    A.assemble()
    b = A.createVecLeft()
    b.getArray()[:] = rng.normal(size=n)
    return K, A, b


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="a serial matrix")
def test_free_rows_solve_equals_the_whole_system_and_keeps_its_symbolic_factorisation():
    n = 60
    base = np.arange(0, 60, 3)  # 20 known rows
    lu = FreeRowsLU(MPI.COMM_SELF, n, 0)
    steps = [(base, 1), (np.append(base, 10), 1),  # a row becomes known: the factorisation is kept
             (np.append(base[1:], 10), 2),  # an eliminated row (0) turns free: new rows
             (np.arange(0, 60, 2), 3)]  # known rows beyond GROWTH times the eliminated ones
    for seed, (known, symbolic) in enumerate(steps):
        K, A, b = _system(n, known, seed)
        x = A.createVecRight()
        assert lu.solve(A, b, x, known)
        assert lu.symbolic == symbolic
        exact = np.linalg.solve(K, b.getArray())
        assert np.abs(x.getArray() - exact).max() <= 1e-12 * np.abs(exact).max()
        assert np.array_equal(x.getArray()[known], b.getArray()[known])


def test_a_drawn_cup_takes_the_same_path_on_the_free_rows(monkeypatch):
    """The coarse square cup (friction, curved tools, the pinching holder) drawn 2 mm with the
    free rows factorised and with the whole matrix (as where too few rows would be taken out):
    the same iterations and carrier to round-off."""
    s = scene.load(ROOT / "demos" / "square_cup.toml")
    s.mesh.n = 8
    runs = []
    for free in (True, False):
        if not free:
            monkeypatch.setattr(FreeRowsLU, "pays", lambda self, eliminable: False)
        p = DrawingProblem.from_scene(s, verbose=False)
        p.driver.run(2.0 / s.tools.stroke)
        runs.append(([h.iterations for h in p.driver.history], p.driver.q.x.array.copy(), p.driver.free_lu.symbolic))
    (its, q, symbolic), (its0, q0, symbolic0) = runs
    assert its == its0
    assert np.abs(q - q0).max() <= 1e-10 * np.abs(q0).max()
    assert symbolic0 == 0 and 0 < symbolic < sum(its)


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="a serial count")
def test_the_whole_matrix_is_factorised_where_few_rows_would_be_taken_out():
    lu = FreeRowsLU(MPI.COMM_SELF, 100, 0)
    assert lu.MIN_SHARE == 0.12
    assert not lu.pays(np.arange(11)) and lu.pays(np.arange(12))
