"""A tabulated flow curve: true stress against equivalent plastic strain, from a CSV file, and
its extrapolation beyond the last point, chosen by the user.

The table (p_i, sigma_i), i = 0..N, starts at p_0 = 0 (the initial yield stress), with p
strictly increasing and sigma non-decreasing (a curve that softens is refused: the return
mapping's uniqueness needs H' >= 0). Between the points sigma is linear in p. Beyond p_N:

    constant   sigma = sigma_N                                  (perfectly plastic)
    linear     sigma = sigma_N + h_N (p - p_N), h_N the last segment's slope
    swift      sigma = K (eps0 + p)^n, (eps0, n) fitted to the tail by least squares,
               K such that sigma(p_N) = sigma_N (continuous)
    voce       sigma = s_inf - (s_inf - sigma_N) exp(-beta (p - p_N)), (s_inf, beta) fitted to
               the tail, continuous at p_N

The tail is the last half of the points (at least 3). The fitted parameters are stated in
``FlowCurve.extrapolation_text`` (written to the run's summary and log).
"""

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from shellform.errors import InputError
from shellform.files import read_text_bounded

EXTRAPOLATIONS = ("constant", "linear", "swift", "voce")
FIELD = "material.flow_curve"
MAX_BYTES = 1_000_000  # a flow curve is a few hundred rows at most
# the table's range: stresses in MPa up to 1e5 (100 GPa, past any metal's flow stress; the fits
# of the extrapolation and the return mapping overflow far above), plastic strains up to 100
MAX_STRESS, MAX_STRAIN = 1e5, 100.0


def read_csv(path, field: str = FIELD, columns: str = "plastic strain, true stress") -> np.ndarray:
    """The rows of a .csv file (a regular file of at most MAX_BYTES) of two numeric columns (here the flow
    curve's p, sigma; shellform.results.fld reads a forming-limit curve with it), an optional
    header line, '#' comments; InputError naming `field` where it cannot be read (no line of
    the file is echoed)."""
    path = Path(path)
    if path.suffix.lower() != ".csv":
        raise InputError(field, f"must be a .csv file, got {path.name!r}")
    text = read_text_bounded(path, field, MAX_BYTES)  # a regular file, a bounded read (shellform/files.py)
    rows = []
    for k, row in enumerate(csv.reader(line for line in text.splitlines() if line.strip()
                                       and not line.lstrip().startswith("#"))):
        try:
            values = [float(v) for v in row]
        except ValueError:
            if k == 0 and not rows:
                continue  # a header
            raise InputError(field, f"{path.name}: row {k + 1} is not two numbers") from None
        if len(values) != 2:
            raise InputError(field, f"{path.name}: row {k + 1} has {len(values)} columns, needs 2 ({columns})")
        rows.append(values)
    return np.array(rows, dtype=np.float64).reshape(-1, 2)


def two_columns(table, field: str, columns: str) -> tuple[np.ndarray, np.ndarray]:
    """The two columns (copies) of a table of at least two finite rows; InputError naming
    `field` where it is not one (`columns`: their names, for the message)."""
    t = np.asarray(table, dtype=np.float64)
    if t.ndim != 2 or t.shape[1] != 2 or len(t) < 2:
        raise InputError(field, f"needs at least two rows ({columns})")
    if not np.all(np.isfinite(t)):
        raise InputError(field, "holds a value that is not finite")
    return t[:, 0].copy(), t[:, 1].copy()


@dataclass(frozen=True)
class FlowCurve:
    """A validated table and its fitted extrapolation; ``packed`` is what the numba code reads."""

    p: np.ndarray
    sigma: np.ndarray
    extrapolation: str
    parameters: tuple  # constant: (); linear: (h_N,); swift: (K, eps0, n); voce: (s_inf, beta)

    @classmethod
    def from_table(cls, table, extrapolation: str) -> "FlowCurve":
        p, s = two_columns(table, FIELD, "plastic strain, true stress")
        if p[0] != 0.0:
            raise InputError(FIELD, f"must start at plastic strain 0 (the initial yield stress), starts at {p[0]}")
        if s[0] <= 0.0:
            raise InputError(FIELD, f"the initial yield stress must be positive, got {s[0]}")
        if s.max() > MAX_STRESS or p.max() > MAX_STRAIN:
            row = int(np.argmax((s > MAX_STRESS) | (p > MAX_STRAIN)))
            raise InputError(FIELD, f"row {row + 1} ({p[row]:g}, {s[row]:g}) is past the range of a flow curve: "
                                    f"stresses up to {MAX_STRESS:g} MPa, plastic strains up to {MAX_STRAIN:g}")
        bad = np.flatnonzero(np.diff(p) <= 0.0)
        if bad.size:
            raise InputError(FIELD, f"the plastic strain must increase: row {bad[0] + 2} ({p[bad[0] + 1]}) "
                                    f"follows {p[bad[0]]}")
        bad = np.flatnonzero(np.diff(s) < 0.0)
        if bad.size:
            raise InputError(FIELD, f"the stress decreases at row {bad[0] + 2} ({s[bad[0] + 1]} after "
                                    f"{s[bad[0]]}): a softening curve is not taken")
        if extrapolation not in EXTRAPOLATIONS:
            raise InputError("material.extrapolation", f"beyond the table's last point: must be one of "
                                                       f"{', '.join(EXTRAPOLATIONS)}, got {extrapolation!r}")
        return cls(p, s, extrapolation, _fit(p, s, extrapolation))

    @property
    def packed(self) -> np.ndarray:
        """[N + 1, p_0..p_N, sigma_0..sigma_N] (the table block of the packed material)."""
        return np.concatenate([[float(len(self.p))], self.p, self.sigma])

    @property
    def extrapolation_id(self) -> int:
        return EXTRAPOLATIONS.index(self.extrapolation)

    @property
    def extrapolation_text(self) -> str:
        pN, sN = self.p[-1], self.sigma[-1]
        head = f"beyond p = {pN:g} ({sN:g} MPa): "
        if self.extrapolation == "constant":
            return head + "constant (perfectly plastic)"
        if self.extrapolation == "linear":
            return head + f"linear, slope {self.parameters[0]:.6g} MPa"
        if self.extrapolation == "swift":
            K, e0, n = self.parameters
            return head + f"Swift {K:.6g} ({e0:.6g} + p)^{n:.6g} fitted to the last {_tail(len(self.p))} points"
        sinf, beta = self.parameters
        return head + (f"Voce {sinf:.6g} - ({sinf:.6g} - {sN:g}) exp(-{beta:.6g} (p - {pN:g})) fitted to the "
                       f"last {_tail(len(self.p))} points")


def _tail(n: int) -> int:
    return max(3, (n + 1) // 2) if n >= 3 else n


def _fit(p, s, kind):
    from scipy.optimize import least_squares

    pN, sN = p[-1], s[-1]
    if kind == "constant":
        return ()
    if kind == "linear":
        return (float((s[-1] - s[-2]) / (p[-1] - p[-2])),)
    k = _tail(len(p))
    pt, st = p[-k:], s[-k:]
    if kind == "swift":
        def swift(x):
            e0, n = x
            return sN * ((e0 + pt) / (e0 + pN)) ** n - st

        fit = least_squares(swift, [max(0.01, 0.1 * pN), 0.2], bounds=([1e-6, 0.0], [10.0, 2.0]))
        e0, n = fit.x
        return (float(sN / (e0 + pN) ** n), float(e0), float(n))

    def voce(x):
        sinf, beta = x
        return sinf - (sinf - sN) * np.exp(-beta * (pt - pN)) - st

    h = max((s[-1] - s[-2]) / (p[-1] - p[-2]), 1e-9 * sN)
    fit = least_squares(voce, [sN + 0.5 * sN * 0.1, h / (0.05 * sN)], bounds=([sN, 1e-9], [100.0 * sN, 1e6]))
    sinf, beta = fit.x
    if not (math.isfinite(sinf) and math.isfinite(beta)):
        raise InputError("material.extrapolation", "the Voce fit to the table's tail failed")
    return (float(sinf), float(beta))
