"""Yld2000-2d's alpha1..alpha8 fitted by weighted least squares to directional data: r values
and uniaxial yield stresses at any angles to the rolling direction, and the balanced-biaxial
yield stress (and, where measured, strain ratio).

**Uniaxial tension at theta** to the rolling direction (c = cos theta, s = sin theta) is the
stress sigma u(theta) with u = (c^2, s^2, c s) in the rolling axes. A yield function sigma_bar(s)
homogeneous of degree 1 yields there at

    sigma(theta) = sigma_bar / sigma_bar(u(theta)),

and its plastic strain rate is normal to the yield surface, dep = dlambda g with
g = grad sigma_bar(u) (g2 the rate of the engineering shear, 2 dep12). Along the width
w = (-s, c) and through the thickness (plastic incompressibility) it stretches at
s^2 g0 + c^2 g1 - s c g2 and -(g0 + g1), so the Lankford value is

    r(theta) = (s^2 g0 + c^2 g1 - s c g2) / -(g0 + g1).

**Balanced-biaxial tension** u = (1, 1, 0): sigma_b = sigma_bar / sigma_bar(1, 1, 0) and
r_b = dep22/dep11 = g1/g0 (1 for an isotropic sheet). ``uniaxial`` and ``predictions``
evaluate these forms for any criterion's packed yield function (``yld2000.predicted`` and
``poly6.predicted`` at the data's angles).

**The fit.** The data are r_i and sigma_i at the angles theta_i of ``fit_angles`` (0 among
them), sigma_b and optionally r_b. The stresses count as ratios q_i = sigma_i/sigma(0),
q_b = sigma_b/sigma(0) to the one along the rolling direction, whose curve the hardening law
is. The residuals, all of weight 1 (absolute errors: an error of 0.01 in an r value weighs as
much as one of 1 % in a yield stress),

    e_r,i = r(theta_i) - r_i,                e_s,i = sigma(theta_i)/sigma(0) - q_i,
    e_b   = sigma_b/sigma(0) - q_b,          e_rb  = r_b - r_b^data (where given),
    e_0   = sigma(0)/sigma_bar - 1,

are minimised in their sum of squares by scipy.optimize.least_squares (trust region,
finite-difference Jacobian) from the isotropic set alpha = 1. Scaling every alpha by k scales
sigma_bar by k and changes only e_0 (r and the ratios are scale-free), so the optimum has
e_0 = 0: sigma_bar is the uniaxial yield stress along the rolling direction exactly, and
e_s at theta = 0 vanishes identically. Counting e_0 with the 2 n - 1 ratios and r values, the
data are 2 n + 1 (+ 1 with r_b) equations for 8 alphas; fewer than 8 are refused. With the
angles 0, 45, 90 and r_b these are the eight of ``yld2000.fit`` and the fit is theirs.

``data`` validates the keys (InputError naming the field), ``fit`` returns a ``Fit``: the alphas
and the table of measured, fitted and error per datum (``Fit.rows``).

**The design.** The fit lies below the criterion: it imports nothing of it, and is told the
criterion's predictions (``fit(values, a, predicted)``). The criterion's parameters complete
alpha from the lists with it (``yld2000.least_squares``), so the dependency runs one way,
yld2000 -> yld2000_fit. Poly6 (shellform.material.poly6) takes the same data, residuals and
table (``data``, ``residuals``, ``table``) with its own solver, which adds a convexity
constraint.
"""

from dataclasses import dataclass
import functools
import math

import numpy as np

from shellform.material.layout import number, require

KEYS = ("fit_angles", "fit_r", "fit_sigma")  # the lists; with sigma_b (required) and r_b (optional)
DIRECTIONAL = ("r0", "r45", "r90", "sigma0", "sigma45", "sigma90")  # yld2000.fit's keys, refused beside the lists
ALPHAS = 8
COLUMNS = ["quantity", "angle_deg", "measured", "fitted", "error"]


@dataclass(frozen=True)
class Data:
    """The validated data: angles (degrees), r values, the stress ratios q_i = sigma_i/sigma(0),
    q_b, and r_b (None: not given)."""

    angles: tuple[float, ...]
    r: tuple[float, ...]
    q: tuple[float, ...]
    q_b: float
    r_b: float | None

    @property
    def count(self) -> int:
        """The equations: n r values, n - 1 ratios, the normalisation, sigma_b, and r_b."""
        return 2 * len(self.angles) + 1 + (self.r_b is not None)


@dataclass(frozen=True)
class Fit:
    """alpha1..alpha8 (sigma_bar the rolling direction's uniaxial yield stress; or another
    criterion's parameters, such as Poly6's c1..c16), the exponent, and per datum a row
    {quantity, angle_deg, measured, fitted, error} (quantity "r", "sigma/sigma0",
    "sigma_b/sigma0" or "r_b"; angle_deg "" for the biaxial data)."""

    alpha: tuple[float, ...]
    a: float
    rows: tuple[dict, ...]
    label: str = "alpha"  # the parameters' name in ``text`` (Poly6: its coefficients)

    def worst(self, quantity: str) -> float:
        """The largest |error| of the rows of that quantity."""
        return max(abs(r["error"]) for r in self.rows if r["quantity"] == quantity)

    @property
    def text(self) -> str:
        """One line for a run's log: the parameters and the largest errors."""
        alphas = ", ".join(f"{x:.4f}" for x in self.alpha)
        b = [f"{r['quantity']} {r['error']:+.4f}" for r in self.rows if r["angle_deg"] == ""]
        return (f"least-squares fit to {sum(r['quantity'] == 'r' for r in self.rows)} angles: {self.label} {alphas}; "
                f"max |r error| {self.worst('r'):.4f}, max |sigma/sigma0 error| {self.worst('sigma/sigma0'):.4f}, "
                + ", ".join(b))


def uniaxial(yield_function, mat: np.ndarray, theta_deg: float) -> tuple[float, float]:
    """(sigma(theta)/sigma_bar, r(theta)) of uniaxial tension at theta degrees to the rolling
    direction for a packed material's yield_function(s0, s1, s2, mat, order): s = sigma
    (c^2, s^2, c s) on the yield surface, r the width over the thickness plastic strain rate of
    the flow a(s): (s^2 a0 + c^2 a1 - s c a2) / -(a0 + a1)."""
    c, s = math.cos(math.radians(theta_deg)), math.sin(math.radians(theta_deg))
    sb, a0, a1, a2 = yield_function(c * c, s * s, c * s, mat, 1)[:4]
    return 1.0 / sb, (s * s * a0 + c * c * a1 - s * c * a2) / -(a0 + a1)


def predictions(yield_function, mat: np.ndarray, angles) -> tuple[np.ndarray, np.ndarray, float, float]:
    """sigma(theta)/sigma_bar and r(theta) at the angles (``uniaxial``), and the balanced-biaxial
    sigma_b/sigma_bar and r_b = dep22/dep11 = a1/a0 at (1, 1, 0)."""
    out = np.array([uniaxial(yield_function, mat, t) for t in angles]).reshape(-1, 2)
    sb, a0, a1, _ = yield_function(1.0, 1.0, 0.0, mat, 1)[:4]
    return out[:, 0], out[:, 1], 1.0 / sb, a1 / a0


def given(values: dict) -> bool:
    """Whether the material's keys ask for the least-squares fit (any of the lists)."""
    return any(values.get(k) for k in KEYS)


def _list(values: dict, key: str) -> list[float]:
    v = values.get(key)
    require(isinstance(v, (list, tuple, np.ndarray)) and len(v) > 0, f"material.{key}",
            f"is required with {' and '.join(k for k in KEYS if k != key and values.get(k))}: fit_angles, fit_r "
            "and fit_sigma go together (the angles, and the r value and the yield stress at each)")
    return [number(f"material.{key}", x) for x in v]


def data(values: dict, least: int = ALPHAS, name: str = "Yld2000-2d") -> Data:
    """The least-squares data from the material's keys, validated: fit_angles in [0, 90] degrees,
    0 among them, none twice; fit_r and fit_sigma one positive number per angle; sigma_b > 0
    (the units of fit_sigma), r_b > 0 where given; at least `least` equations (Yld2000-2d's 8
    alphas; the criterion `name`); none of r0 .. sigma90 beside them. InputError names the
    field."""
    for k in DIRECTIONAL:
        require(k not in values, f"material.{k}",
                "give the directional data either as r0, r45, r90, sigma0, sigma45, sigma90 (fitted exactly) or as "
                "fit_angles, fit_r, fit_sigma (least squares), not both")
    angles, r, sigma = (_list(values, k) for k in KEYS)
    for theta in angles:
        require(0.0 <= theta <= 90.0, "material.fit_angles",
                f"must lie in [0, 90] degrees to the rolling direction (the sheet's orthotropy gives the rest), "
                f"got {theta:g}")
    require(len(set(angles)) == len(angles), "material.fit_angles", f"lists an angle twice: {angles}")
    require(0.0 in angles, "material.fit_angles",
            "must include 0: the yield stresses count as ratios to the one along the rolling direction, whose "
            "curve the hardening law is")
    for key, v, what in (("fit_r", r, "r value"), ("fit_sigma", sigma, "yield stress")):
        require(len(v) == len(angles), f"material.{key}",
                f"must list one {what} per angle of fit_angles ({len(angles)}), got {len(v)}")
        for theta, x in zip(angles, v):
            require(x > 0.0, f"material.{key}", f"must be positive, got {x:g} at {theta:g} degrees")
    require("sigma_b" in values, "material.sigma_b",
            "is required with fit_angles: the balanced-biaxial yield stress, in the units of fit_sigma")
    sigma_b = number("material.sigma_b", values["sigma_b"])
    require(sigma_b > 0.0, "material.sigma_b", f"must be positive, got {sigma_b:g}")
    r_b = None
    if "r_b" in values:
        r_b = number("material.r_b", values["r_b"])
        require(r_b > 0.0, "material.r_b", f"must be positive, got {r_b:g}")
    s0 = sigma[angles.index(0.0)]
    d = Data(tuple(angles), tuple(r), tuple(x / s0 for x in sigma), sigma_b / s0, r_b)
    require(d.count >= least, "material.fit_angles",
            f"{name} has {least} parameters: give at least {least} data (here {len(angles)} angles give "
            f"{d.count} with sigma_b{' and r_b' if r_b is not None else ''}: 2 per angle, 1 for sigma_b, 1 for r_b)")
    return d


def residuals(alpha, a: float, d: Data, predicted) -> np.ndarray:
    """e_0, the ratios' and r values' errors per angle, e_b and e_rb (module docstring), of the
    criterion's predictions (``fit``)."""
    sigma, r, sigma_b, r_b = predicted(alpha, a, d.angles)
    s0 = sigma[d.angles.index(0.0)]
    e = [s0 - 1.0, *(sigma / s0 - d.q), *(r - d.r), sigma_b / s0 - d.q_b]
    if d.r_b is not None:
        e.append(r_b - d.r_b)
    return np.array(e)


@functools.lru_cache(maxsize=32)
def _solve(d: Data, a: float, predicted) -> tuple[tuple[float, ...], int]:
    from scipy.optimize import least_squares

    sol = least_squares(lambda x: residuals(x, a, d, predicted), np.ones(ALPHAS), xtol=1e-15, ftol=1e-15, gtol=1e-15)
    return tuple(float(x) for x in sol.x), int(sol.status)


def fit(values: dict, a: float, predicted) -> Fit:
    """alpha1..alpha8 of Yld2000-2d (exponent a) by least squares to the material's fit_angles,
    fit_r, fit_sigma, sigma_b (and r_b), with the table of their errors; InputError naming the
    field where the data are malformed or the fit does not converge. predicted(alpha, a, angles):
    the criterion's sigma(theta)/sigma_bar and r(theta) at the angles, sigma_b/sigma_bar and r_b
    (yld2000.predicted; yld2000.least_squares passes it)."""
    d = data(values)
    alpha, status = _solve(d, float(a), predicted)
    require(status > 0 and all(math.isfinite(x) for x in alpha), "material.fit_angles",
            f"the least-squares fit of Yld2000-2d (a = {a:g}) to these data did not converge (status {status})")
    return table(d, alpha, a, predicted)


def table(d: Data, alpha, a: float, predicted, label: str = "alpha") -> Fit:
    """The Fit of the parameters alpha (named `label`): per datum of d the measured, fitted and
    error (the criterion's predictions, ``fit``'s `predicted`)."""
    sigma, r, sigma_b, r_b = predicted(alpha, a, d.angles)
    s0 = sigma[d.angles.index(0.0)]
    rows = []
    for theta, measured, got in zip(d.angles, d.r, r):
        rows.append({"quantity": "r", "angle_deg": theta, "measured": measured, "fitted": float(got)})
    for theta, measured, got in zip(d.angles, d.q, sigma / s0):
        rows.append({"quantity": "sigma/sigma0", "angle_deg": theta, "measured": measured, "fitted": float(got)})
    rows.append({"quantity": "sigma_b/sigma0", "angle_deg": "", "measured": d.q_b, "fitted": float(sigma_b / s0)})
    if d.r_b is not None:
        rows.append({"quantity": "r_b", "angle_deg": "", "measured": d.r_b, "fitted": float(r_b)})
    for row in rows:
        row["error"] = row["fitted"] - row["measured"]
    return Fit(tuple(alpha), float(a), tuple(rows), label)
