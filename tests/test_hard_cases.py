"""Hard cases stay numerically stable: each run converges (or stops cleanly) and passes a
physical check.

Levy's w_c/h depends on P and nu alone (von Karman scaling), so one table checks a very thin
(t/L = 1e-4) and a thick (t/L = 0.1) plate against the same reference.
"""

import shellform  # noqa: F401  (must come before dolfinx / petsc4py)

import numpy as np
import pytest

from shellform.nonlinear.driver import ConvergenceFailure, Controls
from shellform.studies import levy, plastic


@pytest.mark.parametrize("h", [1e-4, 0.1])
def test_very_thin_and_thick_plates(h):
    row = levy.solve(8, h=h, loads=[95.0])[-1]
    assert abs(row["rel_error"]) < 0.02, row  # Levy's w_c/h = 0.912 at P = 95


def test_increment_ten_times_too_large_is_cut_back():
    """The whole load in one step (ten times the usual 0.1), with a Newton budget of 5
    iterations: the driver cuts back, recovers, and lands on the careful run's answer."""
    careful = levy.solve(4, loads=[402.0])[-1]["w_over_h"]
    p = levy.problem(4, controls=Controls(initial_step=1.0, max_step=1.0, max_iterations=5))
    p.driver.run(1.0)
    assert sum(i.cutbacks for i in p.driver.history) > 0
    assert abs(p.value("w", 0, 0) / 0.01 - careful) < 1e-6 * careful


def test_springback_after_plastic_bending():
    """Full unloading after plastic loading: the tip comes back along the elastic slope."""
    row = plastic.solve(8, 5)
    assert row["P_max_over_PL_discrete"] > 0.95  # it really went plastic
    assert row["residual_deflection_error"] < 1e-8


def test_unrecoverable_run_stops_cleanly(tmp_path):
    """A run that cannot converge stops with a message and keeps the last converged state."""
    p = levy.problem(4, controls=Controls(initial_step=0.1, max_step=0.1, min_step=0.05, max_iterations=2))
    p.driver.checkpoint_dir = tmp_path
    with pytest.raises(ConvergenceFailure, match="did not converge") as err:
        p.driver.run(1.0)
    saved = np.load(err.value.checkpoint)  # one file for all ranks (nonlinear/checkpoint.py)
    assert np.all(np.isfinite(saved["nodes.q"]))
    assert float(saved["global.lam"]) == p.driver.lam  # the last converged load factor
    assert (tmp_path / "history.json").exists()
