"""Material-point drivers (plain Python over the numba kernels) for tests and studies.

Mixed control: e11 is prescribed; the two other strains x = (e22, g12) solve  P s + Q e = 0
(two conditions, Q weighted by E) by Newton with the consistent tangent, J = (P D + E Q)[:, 1:].
"""

from typing import NamedTuple

import numpy as np

from shellform.material.layout import A_, B_, C_, LAW_, LAW_ELASTIC, LAW_SWIFT
from shellform.material.hardening import flow_stress
from shellform.material.plane_stress import return_map

_UNIAXIAL = (np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), np.zeros((2, 3)))  # s22 = s12 = 0
_PLANE_STRAIN = (np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),  # e22 = 0, s12 = 0
                 np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 0.0]]))


class Path(NamedTuple):
    """States 0..steps of a driven material point (row 0: the virgin state)."""

    strain: np.ndarray  # (steps+1, 3) total strain (e11, e22, g12)
    stress: np.ndarray  # (steps+1, 3) (s11, s22, s12)
    plastic_strain: np.ndarray  # (steps+1, 3) (ep11, ep22, gp12)
    p: np.ndarray  # (steps+1,) equivalent plastic strain


def _packed(mat) -> np.ndarray:
    return mat.pack() if hasattr(mat, "pack") else np.asarray(mat, dtype=np.float64)


def _step(mat, e, ep, p, D, e11, control, tol=1e-13, maxit=100):
    """One step from the committed state (strain e, plastic strain ep, p; tangent D for the
    predictor) to e11 under the control P s + Q e = 0, by Newton with backtracking on |P s + E Q e|.
    Returns (e, s, D, ep, p)."""
    P, Q = control
    E = mat[0]

    def state(e):
        s, D, q = np.zeros(3), np.zeros((3, 3)), np.zeros(3)
        p_new, st = return_map(e, ep, p, mat, s, D, q)
        if st < 0:
            raise RuntimeError(f"local Newton failed at e = {e}")
        res = P @ s + E * (Q @ e)  # Q rows weighted by E: residuals in stress units
        return np.linalg.norm(res), res, s, D, q, p_new

    e = e.copy()
    J = P @ D + Q * E
    e[1:] -= np.linalg.solve(J[:, 1:], J[:, 0] * (e11 - e[0]))  # tangent predictor
    e[0] = e11
    cur = state(e)
    for _ in range(maxit):
        rn, res, s, D, q, p_new = cur
        if rn <= tol * abs(s[0]):
            return e, s, D, q, p_new
        dx = -np.linalg.solve((P @ D + Q * E)[:, 1:], res)
        alpha = 1.0
        for _ in range(40):
            trial_e = e.copy()
            trial_e[1:] += alpha * dx
            trial = state(trial_e)
            if trial[0] < rn:
                break
            alpha *= 0.5
        else:
            break
        e, cur = trial_e, trial
    raise RuntimeError(f"mixed-control Newton did not converge at e11 = {e11}")


def _drive(mat, e11, control) -> Path:
    """Drive e11 through the values e11[1:] (row 0: the virgin state, e11[0] = 0)."""
    mat = _packed(mat)
    n = len(e11)
    strain, stress, ep, p = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n)
    D = np.zeros((3, 3))
    return_map(strain[0], ep[0], 0.0, mat, np.zeros(3), D, np.zeros(3))  # elastic tangent
    for i in range(1, n):
        strain[i], stress[i], D, ep[i], p[i] = _step(mat, strain[i - 1], ep[i - 1], p[i - 1], D,
                                                     e11[i], control)
    return Path(strain, stress, ep, p)


def uniaxial(mat, strain: float, steps: int) -> Path:
    """Strain-driven uniaxial stress: e11 up to `strain` in equal steps, s22 = s12 = 0."""
    return _drive(mat, np.linspace(0.0, strain, steps + 1), _UNIAXIAL)


def plane_strain(mat, strain: float, steps: int) -> Path:
    """Strain-driven plane strain: e11 up to `strain` in equal steps, e22 = 0, s12 = 0."""
    return _drive(mat, np.linspace(0.0, strain, steps + 1), _PLANE_STRAIN)


def _perfectly_plastic(mat) -> tuple[np.ndarray, float]:
    """The material with its initial yield stress and no hardening (Swift, n = 0)."""
    mat = _packed(mat)
    if int(mat[LAW_]) == LAW_ELASTIC:
        raise ValueError("an elastic material (law 0) never yields")
    sy = flow_stress(0.0, mat)[0]
    pp = mat.copy()
    pp[LAW_], pp[A_], pp[B_], pp[C_] = LAW_SWIFT, sy, 1.0, 0.0
    return pp, sy


def stress_ratio_yield(mat, ratio: float, steps: int = 10) -> float:
    """Initial yield stress s1 on the proportional path s2 = ratio s1, s12 = 0 (|ratio| <= 1).

    Drives the perfectly plastic copy of the material (initial yield stress, no hardening) to
    e11 = 5 sigma_y / E under the stress-ratio constraint; once plastic the stress sits on the
    initial yield surface on that path, so s11 is the yield stress.
    """
    pp, sy = _perfectly_plastic(mat)
    control = (np.array([[-ratio, 1.0, 0.0], [0.0, 0.0, 1.0]]), np.zeros((2, 3)))
    path = _drive(pp, np.linspace(0.0, 5.0 * sy / pp[0], steps + 1), control)
    if path.p[-1] <= 0.0:
        raise RuntimeError("the path did not reach yield")
    return float(path.stress[-1, 0])


def plane_strain_yield(mat, step: float = 50.0, maxsteps: int = 400, tol: float = 1e-14) -> float:
    """s2/s1 in plastic flow under plane strain (e22 = 0, s12 = 0), initial yield surface.

    Drives e11 of the perfectly plastic copy in steps of `step` yield strains until s2/s1 is
    stationary: then the stress no longer changes, the plastic strain increment equals the total
    one and dep22 = 0: the plane-strain point of the yield surface. Backward Euler contracts onto
    that fixed point by a large factor per large step.
    """
    pp, sy = _perfectly_plastic(mat)
    de = step * sy / pp[0]
    e, ep, p, D = np.zeros(3), np.zeros(3), 0.0, np.zeros((3, 3))
    return_map(e, ep, p, pp, np.zeros(3), D, np.zeros(3))
    ratio = np.nan
    for _ in range(maxsteps):
        e, s, D, ep, p = _step(pp, e, ep, p, D, e[0] + de, _PLANE_STRAIN)
        new = s[1] / s[0]
        if abs(new - ratio) <= tol * max(1.0, abs(new)):
            return float(new)
        ratio = new
    raise RuntimeError("plane-strain stress ratio did not become stationary")


def lankford(mat, strain: float, steps: int = 20) -> float:
    """r = d ep22 / d ep33 over the last step of a uniaxial test to e11 = strain,
    ep33 = -(ep11 + ep22)."""
    path = uniaxial(mat, strain, steps)
    d = path.plastic_strain[-1] - path.plastic_strain[-2]
    return float(d[1] / -(d[0] + d[1]))
