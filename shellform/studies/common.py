"""Shared pieces of the studies: observed rates and the error-against-time plot (tables and
log lines are the results stage's: shellform.results)."""

import math
import shutil
import sys
from pathlib import Path

import numpy as np
from mpi4py import MPI

from shellform.results.log import say


def mpiexec() -> str | None:
    """The mpiexec beside this Python (the wheel's), else the one on PATH, else None."""
    local = Path(sys.executable).parent / "mpiexec"
    return str(local) if local.exists() else shutil.which("mpiexec")


def convergence_rates(errors, cells) -> tuple[np.ndarray, float]:
    """Observed orders in h ~ cells^(-1/2): between consecutive meshes, log(e0/e1) / log(h0/h1),
    and the least-squares slope of log|e| against log h over all of them."""
    e = np.abs(np.asarray(errors, dtype=float))
    h = np.asarray(cells, dtype=float) ** -0.5
    with np.errstate(divide="ignore", invalid="ignore"):
        pairwise = np.log(e[:-1] / e[1:]) / np.log(h[:-1] / h[1:])
    fitted = float(np.polyfit(np.log(h), np.log(e), 1)[0]) if len(e) > 1 and np.all(e > 0) else math.nan
    return pairwise, fitted


def observed_rates(rows: list[dict], size="cells", error="rel_error") -> list[float]:
    """Pairwise rates of a table, nan for the first row (and where an error is zero)."""
    pairwise, _ = convergence_rates([r[error] for r in rows], [r[size] for r in rows])
    return [math.nan] + [float(x) if np.isfinite(x) else math.nan for x in pairwise]


def deflection_table(scenes, reference: float, x: float = 0.0, y: float = 0.0) -> list[dict]:
    """Solve each linear scene in turn (a sequence of meshes) and log one table row per mesh:
    level, cells, w at (x, y), its error relative to `reference`, the observed rate, time."""
    from shellform import linear

    rows = []
    say(f"{'level':>5s} {'cells':>6s} {'w_center':>13s} {'rel_error':>11s} {'rate':>5s} {'time_s':>7s}")
    for k, scene in enumerate(scenes):
        result = linear.solve(scene)
        w = result.value("w", x, y)
        rows.append({"cells": result.num_cells, "w_center": w, "rel_error": (w - reference) / reference,
                     "time_s": result.timings["total_s"]})
        rate, r = observed_rates(rows)[-1], rows[-1]
        rate_text = "    -" if k == 0 else f"{rate:5.2f}"
        say(f"{k:5d} {r['cells']:6d} {r['w_center']:13.10f} {r['rel_error']:11.2e} {rate_text} {r['time_s']:7.2f}")
    return rows


def plot_error_time(path: Path, series: dict[str, list[dict]], title: str, error="rel_error",
                    ylabel=None) -> None:
    """Log-log |error| against total wall time, one line per series."""
    if MPI.COMM_WORLD.rank != 0:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    compile_s = max(r["compile_s"] for rows in series.values() for r in rows)
    for k, (label, rows) in enumerate(series.items()):
        t = [r["total_s"] - r["compile_s"] for r in rows]
        e = [abs(r[error]) for r in rows]
        ax.loglog(t, e, "os^Dv"[k // 10 % 5] + "-", label=label)  # a new marker once the colours repeat
    ax.set_xlabel(f"wall time per solve [s]: mesh + assemble + solve (kernels compiled once: "
                  f"at most {compile_s:.1f} s)")
    ax.set_ylabel(ylabel or f"|{error}| of the centre deflection")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
