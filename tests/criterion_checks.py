"""Checks every yield function's tests share: Euler's identity and the derivatives against
central differences, through the registry's dispatch; a section's tangent against central
differences of its resultants."""

import numpy as np
import pytest

from shellform.material import criteria


def assert_derivatives(mat: np.ndarray, stresses) -> None:
    """At each stress s: s . a = sigma_bar (Euler, 1e-13), the gradient a equals central
    differences of sigma_bar (1e-7) and the Hessian those of a (1e-5), with the step 1e-6 |s|."""
    for s in stresses:
        s = np.asarray(s, dtype=float)
        out = np.array(criteria.yield_function(*s, mat, 2))
        assert s @ out[1:4] == pytest.approx(out[0], rel=1e-13)
        h = 1e-6 * np.linalg.norm(s)
        H = out[[4, 5, 6, 5, 7, 8, 6, 8, 9]].reshape(3, 3)
        for j in range(3):
            ds = np.zeros(3)
            ds[j] = h
            up, dn = np.array(criteria.yield_function(*(s + ds), mat, 2)), np.array(criteria.yield_function(*(s - ds), mat, 2))
            assert (up[0] - dn[0]) / (2 * h) == pytest.approx(out[1 + j], rel=1e-7, abs=1e-9)
            np.testing.assert_allclose((up[1:4] - dn[1:4]) / (2 * h), H[:, j], rtol=1e-5, atol=1e-7 * np.abs(H).max())


def assert_section_tangent(resultants, x: np.ndarray, D: np.ndarray, h: float = 1e-7) -> None:
    """Each column of the section tangent D at the section strain x (E, K: 6) equals central
    differences of resultants(x) (the resultants S, 6) with the step h, to 1e-6 of D's largest
    entry."""
    for j in range(6):
        dx = np.zeros(6)
        dx[j] = h
        fd = (resultants(x + dx) - resultants(x - dx)) / (2 * h)
        assert np.abs(fd - D[:, j]).max() < 1e-6 * np.abs(D).max()
