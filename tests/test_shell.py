"""The paper's Figs. 1-2: simply supported square shallow-shell block under uniform pressure."""

import math

import numpy as np
import pytest

from shellform import linear
from shellform.studies import plate, shell


def test_navier_series_flat_limit():
    """The Donnell/Navier series reduces to the plate value 0.00406235 for R -> inf."""
    assert shell.navier_coefficient(math.inf) == pytest.approx(plate.REFERENCE["simply_supported"], rel=2e-6)


def test_shell_converges_to_navier_solution():
    """R = 5 (a^2/(R t) = 20): second-order convergence to the analytic shallow-shell value."""
    navier = shell.navier_coefficient(5.0)
    rows = [shell.coefficient(5.0, shell.BASE_N, refine=k) for k in (0, 1, 2, 3)]
    err = np.abs([(r["coefficient"] - navier) / navier for r in rows])
    h = np.array([r["cells"] for r in rows], dtype=float) ** -0.5
    rates = np.log(err[:-1] / err[1:]) / np.log(h[:-1] / h[1:])
    assert rates[-1] >= 1.9 and np.polyfit(np.log(h), np.log(err), 1)[0] >= 1.9, rates
    assert err[-1] < 2e-3  # 1152 cells


def test_flat_plate_limit():
    """As R grows the shell block tends to the plate; at R = inf the membrane decouples exactly."""
    n = 12
    bending_only = linear.solve(plate.scene("simply_supported", "structured", n)).value("w")
    shell_inf = shell.coefficient(math.inf, n)["coefficient"]  # D = 1 in the plate scene
    assert shell_inf == pytest.approx(bending_only, rel=1e-10)
    prev = 0.0
    for R in (2.0, 10.0, 100.0, 1e4):
        c = shell.coefficient(R, n)["coefficient"]
        assert c > prev  # stiffer the more curved
        prev = c
    assert prev == pytest.approx(bending_only, rel=2e-4)
