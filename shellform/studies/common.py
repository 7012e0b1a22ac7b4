"""Shared pieces of the studies: tables, observed rates, the error-against-time plot."""

import csv
import math
import sys
from pathlib import Path

from mpi4py import MPI


def say(*args):
    if MPI.COMM_WORLD.rank == 0:
        print(*args, flush=True)
        sys.stdout.flush()


def write_csv(path: Path, rows: list[dict], columns: list[str]) -> None:
    if MPI.COMM_WORLD.rank != 0:
        return
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})


def observed_rates(rows: list[dict], size="cells", error="rel_error") -> list[float]:
    """Rates in h ~ cells^(-1/2) between consecutive rows: log(e0/e1) / log(h0/h1)."""
    rates = [math.nan]
    for r0, r1 in zip(rows, rows[1:]):
        e0, e1 = abs(r0[error]), abs(r1[error])
        h = math.sqrt(r1[size] / r0[size])
        rates.append(math.log(e0 / e1) / math.log(h) if e0 > 0 and e1 > 0 else math.nan)
    return rates


def plot_error_time(path: Path, series: dict[str, list[dict]], title: str, error="rel_error") -> None:
    """Log-log |error| against total wall time, one line per series."""
    if MPI.COMM_WORLD.rank != 0:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    compile_s = max(r["compile_s"] for rows in series.values() for r in rows)
    for label, rows in series.items():
        t = [r["total_s"] - r["compile_s"] for r in rows]
        e = [abs(r[error]) for r in rows]
        ax.loglog(t, e, "o-", label=label)
    ax.set_xlabel(f"wall time per solve [s]: mesh + assemble + solve (kernels compiled once: "
                  f"at most {compile_s:.1f} s)")
    ax.set_ylabel(f"|{error}| of the centre deflection")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
