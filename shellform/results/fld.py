"""The forming-limit view: the elements' principal surface strains over a forming-limit curve.

Forming-limit curve of Keeler and Brazier (1977), as the AHSS Guidelines state it, for a sheet
of thickness t (mm) and strain-hardening exponent n:

    FLC0 = (23.3 + 14.13 t) n / 0.21   (%, engineering major strain at plane strain; t <= 3 mm)
    left  (minor < 0): constant thinning in true strain,  eps1 = ln(1 + FLC0/100) - eps2
    right (minor > 0): slope +0.6 in engineering strain,   e1 = FLC0/100 + 0.6 e2

It is a correlation for steels. For aluminium it overstates the limit (the sheet's own measured
curve should be used); shellform draws it for every sheet and says which it is.

The margin of an element is FLC(eps2) - eps1 in true major strain: negative above the curve
(a split predicted), below 0.1 in the usual marginal zone.
"""

import numpy as np
from mpi4py import MPI


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


def hardening_exponent(material) -> float:
    """n of the Hollomon-type law: the Swift n; 1/N for the power law eps ~ sigma^N."""
    if material.hardening == "swift":
        return float(material.n)
    if material.hardening == "power":
        return 1.0 / float(material.n)
    raise ValueError("a forming-limit curve needs a hardening curve")


def margins(major, minor, curve) -> np.ndarray:
    return curve(minor) - np.asarray(major)


def plot(path, major, minor, curve, title: str, label: str) -> None:
    """The elements' (minor, major) over the curve and its 0.1 marginal zone (rank 0 gathers)."""
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
    margin = margins(major, minor, curve)
    sc = ax.scatter(minor, major, c=margin, s=8, cmap="RdYlGn", vmin=-0.1, vmax=0.3)
    fig.colorbar(sc, ax=ax, label="margin to the curve (true major strain)")
    ax.set_xlabel("minor true strain")
    ax.set_ylabel("major true strain")
    ax.set_title(title, fontsize=9, parse_math=False)  # a scene's title is text, never TeX
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper center")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
