"""The forming-limit view: the elements' principal surface strains over a forming-limit curve.

Forming-limit curve of Keeler and Brazier (1977), as the AHSS Guidelines state it, for a sheet
of thickness t (mm) and strain-hardening exponent n:

    FLC0 = (23.3 + 14.13 t) n / 0.21   (%, engineering major strain at plane strain; t <= 3 mm)
    left  (minor < 0): constant thinning in true strain,  eps1 = ln(1 + FLC0/100) - eps2
    right (minor > 0): slope +0.6 in engineering strain,   e1 = FLC0/100 + 0.6 e2

It is a correlation for steels. For aluminium it overstates the limit (the sheet's own measured
curve should be used); shellform draws it for every sheet whose curve has a Hollomon-type n
(Swift, power law) and says which it is.

A measured forming-limit curve ([material] forming_limit_curve: a CSV of minor, major true
strains, minor increasing) replaces it for the margin and the view (Keeler-Brazier is drawn
beside it where it can be): linear between its points, and beyond its first and last point
continued along its end segments (linear extrapolation; the view marks the measured range).

The margin of an element is FLC(eps2) - eps1 in true major strain: negative above the curve
(a split predicted), below 0.1 in the usual marginal zone.
"""

from pathlib import Path

import numpy as np
from mpi4py import MPI

from shellform.errors import InputError
from shellform.results.listeners import EndOfStroke, Record
from shellform.results.tables import write_figure

FIELD = "material.forming_limit_curve"


def flc0(thickness_mm: float, n: float) -> float:
    """Plane-strain limit as a true major strain."""
    return float(np.log1p((23.3 + 14.13 * min(thickness_mm, 3.0)) * n / 0.21 / 100.0))


def keeler_brazier(thickness_mm: float, n: float):
    """The curve eps1(eps2) in true strains."""
    e0 = flc0(thickness_mm, n)
    E0 = np.expm1(e0)

    def curve(minor):
        minor = np.asarray(minor, dtype=float)
        right = np.log1p(E0 + 0.6 * np.expm1(np.maximum(minor, 0.0)))
        return np.where(minor < 0, e0 - minor, right)

    return curve


def measured(rows):
    """The curve eps1(eps2) through the measured points (minor, major), linear between them and
    along the end segments beyond them; InputError naming material.forming_limit_curve where
    the points are no curve (fewer than two, minor not increasing, major not positive)."""
    from shellform.material.flow_curve import two_columns

    minor, major = two_columns(rows, FIELD, "minor true strain, major true strain")
    bad = np.flatnonzero(np.diff(minor) <= 0.0)
    if bad.size:
        raise InputError(FIELD, f"the minor strain must increase: row {bad[0] + 2} ({minor[bad[0] + 1]}) follows "
                                f"{minor[bad[0]]}")
    if major.min() <= 0.0:
        raise InputError(FIELD, f"the major strain must be positive, got {major.min()}")
    s0 = (major[1] - major[0]) / (minor[1] - minor[0])
    s1 = (major[-1] - major[-2]) / (minor[-1] - minor[-2])

    def curve(e2):
        e2 = np.asarray(e2, dtype=float)
        inside = np.interp(e2, minor, major)
        return np.where(e2 < minor[0], major[0] + s0 * (e2 - minor[0]),
                        np.where(e2 > minor[-1], major[-1] + s1 * (e2 - minor[-1]), inside))

    curve.range = (float(minor[0]), float(minor[-1]))
    return curve


def read_measured(path):
    """The measured curve of a CSV file of rows minor, major true strain (an optional header)."""
    from shellform.material.flow_curve import read_csv

    return measured(read_csv(path, FIELD, "minor true strain, major true strain"))


def curves(material):
    """The scene material's forming-limit curves: (curve, label) of the one the margin uses
    (the measured one where forming_limit_curve is given, else Keeler-Brazier) and (curve,
    label) of Keeler-Brazier beside a measured one, or None (no n, or not measured)."""
    kb = None
    if material.hardening in ("swift", "power"):
        t, n = material.thickness, hardening_exponent(material)
        kb = keeler_brazier(t, n), f"Keeler-Brazier, t {t:g} mm, n {n:.3g}: FLC0 {flc0(t, n):.3f}"
    if material.forming_limit_curve:
        curve = read_measured(material.forming_limit_curve)
        return (curve, f"measured, {Path(material.forming_limit_curve).name}: FLC0 {float(curve(0.0)):.3f}"), kb
    if kb is None:
        raise InputError(FIELD, f"the forming-limit view needs a measured curve for hardening = "
                                f"{material.hardening!r} (Keeler-Brazier needs the n of a Swift or power law)")
    return kb, None


def curve_of(scene, name: str, value: float):
    """The margin's curve (curves()) with the scene's number `name` at `value` (a sensitivity's
    parameter moved): Keeler-Brazier moves with material.n; a measured curve, and the tools'
    numbers, leave it as it is."""
    section, _, key = name.partition(".")
    return curves(scene.with_material(key, value).material if section == "material" else scene.material)[0][0]


def hardening_exponent(material) -> float:
    """n of the Hollomon-type law: the Swift n; 1/N for the power law eps ~ sigma^N."""
    if material.hardening == "swift":
        return float(material.n)
    if material.hardening == "power":
        return 1.0 / float(material.n)
    raise ValueError("a forming-limit curve needs a hardening curve")


def margins(major, minor, curve) -> np.ndarray:
    return curve(minor) - np.asarray(major)


def plot(path, major, minor, curve, title: str, label: str, beside=None) -> None:
    """The elements' (minor, major) over the curve and its 0.1 marginal zone (rank 0 gathers);
    beside: (curve, label) of another curve drawn for comparison (dashed)."""
    comm = MPI.COMM_WORLD
    major = np.concatenate(comm.gather(np.asarray(major), root=0) or [np.zeros(0)])
    minor = np.concatenate(comm.gather(np.asarray(minor), root=0) or [np.zeros(0)])
    if comm.rank != 0:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 5))
    lo = min(-0.4, float(minor.min(initial=0.0)) * 1.1)
    hi = max(0.4, float(minor.max(initial=0.0)) * 1.1)
    e2 = np.linspace(lo, hi, 200)
    ax.plot(e2, curve(e2), "r-", label=label)
    ax.plot(e2, curve(e2) - 0.1, "r:", label="marginal zone (0.1 below)")
    if hasattr(curve, "range"):
        ax.axvspan(*curve.range, color="r", alpha=0.05, label="measured range")
    if beside is not None:
        ax.plot(e2, beside[0](e2), "--", color="grey", label=beside[1])
    margin = margins(major, minor, curve)
    sc = ax.scatter(minor, major, c=margin, s=8, cmap="RdYlGn", vmin=-0.1, vmax=0.3)
    fig.colorbar(sc, ax=ax, label="margin to the curve (true major strain)")
    ax.set_xlabel("minor true strain")
    ax.set_ylabel("major true strain")
    ax.set_title(title, fontsize=9, parse_math=False)  # a scene's title is text, never TeX
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper center")
    fig.tight_layout()
    write_figure(path, fig, dpi=120)
    plt.close(fig)


class FormingLimitReached(EndOfStroke):
    """The stroke ends: an element's margin to the forming-limit curve reached 0 ([process]
    stop_at_forming_limit)."""


LIMIT_KEYS = ("stroke_mm", "increment_stroke_mm", "margin")  # FormingLimitWatch.limit


class FormingLimitWatch(Record):
    """Where a stroke reaches the forming-limit curve: after each increment the smallest margin
    over the elements (every rank's); `reached` once it is <= 0. The stroke at which it is 0 is
    interpolated linearly in the stroke between the last increment with a positive margin and
    the first without (the margin of the element that is worst at each: a lower bound of the
    limit's stroke where the worst element changes between them). A record of the driver
    (listeners.Record): its checkpoints carry the watch."""

    def __init__(self, curve, comm):
        self.curve, self.comm = curve, comm
        self.last = None  # (stroke, smallest margin) of the last increment
        self.limit = None  # what reached() found, or None

    def reached(self, stroke: float, major, minor) -> bool:
        margin = margins(major, minor, self.curve)
        least = self.comm.allreduce(float(margin.min(initial=np.inf)), op=MPI.MIN)
        if least <= 0.0 and self.limit is None:
            at = stroke
            if self.last is not None and self.last[1] > 0.0:
                s0, m0 = self.last
                at = s0 + (stroke - s0) * m0 / (m0 - least)
            self.limit = dict(zip(LIMIT_KEYS, (at, stroke, least)))
        self.last = (stroke, least)
        return self.limit is not None

    def checkpoint(self) -> dict:
        """What a resume continues from: the last increment's (stroke, margin) and the limit
        found (empty where none)."""
        limit = self.limit or {}
        return {"global": {"forming_limit.last": np.array(self.last or (), dtype=float),
                           "forming_limit.limit": np.array([limit[k] for k in LIMIT_KEYS] if limit else (),
                                                           dtype=float)}}

    def restore(self, state: dict) -> None:
        """Read back checkpoint() (nothing where the checkpoint has none: the watch starts afresh)."""
        glob = state["global"]
        last, limit = glob.get("forming_limit.last"), glob.get("forming_limit.limit")
        self.last = tuple(float(v) for v in last) if last is not None and last.size == 2 else None
        self.limit = dict(zip(LIMIT_KEYS, map(float, limit))) if limit is not None and limit.size == 3 else None


class StrainPaths(Record):
    """The elements' major and minor true strains along the stroke (each rank its own elements),
    recorded where the stroke has moved by at least `spacing` since the last record and at the
    end (`final`): a bounded record, about stroke / spacing copies of two strains per element.
    `critical` gives the path of the element whose margin to the curve is smallest at the last
    record: the strain path that ends nearest the forming limit (or past it). A record of the
    driver (listeners.Record): its checkpoints carry the path."""

    def __init__(self, curve, comm, spacing: float):
        self.curve, self.comm, self.spacing = curve, comm, spacing
        self.strokes, self.major, self.minor = [], [], []

    def record(self, stroke: float, major, minor, final: bool = False) -> None:
        if self.strokes and not final and stroke - self.strokes[-1] < self.spacing:
            return
        if self.strokes and stroke == self.strokes[-1]:  # recorded already
            return
        self.strokes.append(float(stroke))
        self.major.append(np.asarray(major, dtype=np.float32).copy())
        self.minor.append(np.asarray(minor, dtype=np.float32).copy())

    def checkpoint(self) -> dict:
        """The path so far, for a resume to continue: per owned cell its major and minor strains
        at every record (cells, records), and the records' strokes."""
        if not self.strokes:
            return {"global": {"strain_path.strokes": np.zeros(0)}}
        return {"global": {"strain_path.strokes": np.array(self.strokes)},
                "cells": {"strain_path.major": np.stack(self.major, axis=1),
                          "strain_path.minor": np.stack(self.minor, axis=1)}}

    def restore(self, state: dict) -> None:
        """Read back checkpoint() (this rank's cells); a checkpoint without a path (written with
        the forming-limit view off) leaves it empty: the path starts at the resumed stroke."""
        strokes = state["global"].get("strain_path.strokes")
        if strokes is None or strokes.size == 0 or "strain_path.major" not in state["cells"]:
            return
        major, minor = state["cells"]["strain_path.major"], state["cells"]["strain_path.minor"]
        self.strokes = [float(s) for s in strokes]
        self.major = [np.array(major[:, j], dtype=np.float32) for j in range(len(self.strokes))]
        self.minor = [np.array(minor[:, j], dtype=np.float32) for j in range(len(self.strokes))]

    def critical(self, centres) -> dict:
        """{"initial_xy_mm", "stroke_mm", "major", "minor", "margin"} of that element (centres:
        the local elements' initial centres, (cells, 2)), on every rank; {} before any record."""
        if not self.strokes:
            return {}
        margin = margins(self.major[-1], self.minor[-1], self.curve)
        local = (float(margin.min()), self.comm.rank) if margin.size else (np.inf, self.comm.rank)
        _, owner = min(self.comm.allgather(local))
        path = None
        if self.comm.rank == owner:
            i = int(np.argmin(margin))
            major = [float(a[i]) for a in self.major]
            minor = [float(b[i]) for b in self.minor]
            path = {"initial_xy_mm": [float(c) for c in centres[i]], "stroke_mm": list(self.strokes),
                    "major": major, "minor": minor,
                    "margin": [float(m) for m in margins(np.array(major), np.array(minor), self.curve)]}
        return self.comm.bcast(path, root=owner)
