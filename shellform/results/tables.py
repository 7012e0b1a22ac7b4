"""Tables and summaries on disk: CSV (rows of dicts) and JSON, written by rank 0."""

import csv
import json
from pathlib import Path

from mpi4py import MPI


def write_csv(path: Path, rows: list[dict], columns: list[str]) -> None:
    if MPI.COMM_WORLD.rank != 0:
        return
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})


def write_json(path: Path, data: dict) -> None:
    if MPI.COMM_WORLD.rank == 0:
        Path(path).write_text(json.dumps(data, indent=2, default=float) + "\n")
