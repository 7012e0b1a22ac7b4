"""Tables and summaries on disk: CSV (rows of dicts) and JSON, written by rank 0.

Every file is written whole or not at all (write_atomically): into a temporary file in the same
folder, flushed and synced to the disk, then renamed over the final name, and the folder synced;
a kill or a full disk during the write leaves the previous file as it was, and a full disk
(ENOSPC, EDQUOT) is raised as disk.DiskFull naming the file (docs/reliability.md).
A rename replaces a link at the final name and never writes through it: pictures are written
the same way (write_figure, write_screenshot).
"""

import csv
import io
import json
import math
import os
from pathlib import Path

import numpy as np
from mpi4py import MPI

from shellform.results.disk import DiskFull, is_full


def sync_folder(folder: Path) -> None:
    """Make the renames in `folder` durable (fsync of the directory; a no-op where the system
    cannot open a directory)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def write_atomically(path: Path, write, binary: bool = False) -> None:
    """Call write(f) on a temporary file next to `path`, flush and fsync it, then os.replace it
    onto `path` and fsync the folder: readers see the old file or the new one, never a part.
    A full disk or quota: DiskFull naming `path`, the file before it left as it was."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.unlink(missing_ok=True)  # a kill's leftover, or a link: the file is created anew, not opened through one
    try:
        with open(tmp, "wb" if binary else "w", **({} if binary else {"newline": ""})) as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException as err:
        tmp.unlink(missing_ok=True)
        if isinstance(err, OSError) and not isinstance(err, DiskFull) and is_full(err):
            raise DiskFull(f"{path} could not be written ({os.strerror(err.errno)})", err.errno) from err
        raise
    sync_folder(path.parent)


def write_figure(path: Path, fig, dpi: int = 120) -> None:
    """A matplotlib figure as a PNG, written whole (write_atomically): a link at `path` is
    replaced, never written through."""
    write_atomically(path, lambda f: fig.savefig(f, format="png", dpi=dpi), binary=True)


def write_screenshot(path: Path, plotter) -> None:
    """A pyvista plotter's picture as a PNG, written as write_figure writes."""
    from matplotlib import image

    picture = plotter.screenshot(None, return_img=True)
    write_atomically(path, lambda f: image.imsave(f, picture, format="png"), binary=True)


def _cell(v):
    """A CSV cell: a float to six significant digits, anything else as it is."""
    return f"{v:.6g}" if isinstance(v, float) else v


def as_written(rows: list[dict]) -> list[dict]:
    """The rows as `write_csv` writes them, read back: every float to its six digits, so that a
    table printed beside the CSV (a study's markdown) rounds the same numbers the same way."""
    return [{k: (float(_cell(v)) if isinstance(v, float) else v) for k, v in row.items()} for row in rows]


def markdown_table(headers: list[str], rows: list[list[str]]) -> str:
    """A Markdown table: the header row, its rule, and one row per list of cells (text as given)."""
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    return "\n".join(lines + ["| " + " | ".join(cells) + " |" for cells in rows]) + "\n"


def write_csv(path: Path, rows: list[dict], columns: list[str]) -> None:
    """rows to path with the given columns, floats to six significant digits."""
    if MPI.COMM_WORLD.rank != 0:
        return
    text = io.StringIO(newline="")
    writer = csv.DictWriter(text, fieldnames=columns, extrasaction="ignore")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _cell(v) for k, v in row.items()})
    write_atomically(path, lambda f: f.write(text.getvalue()))


def finite_json(value):
    """`value` for JSON, which has no NaN or Infinity: a non-finite number becomes None (null),
    numpy scalars and arrays plain numbers and lists."""
    if isinstance(value, dict):
        return {k: finite_json(v) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [finite_json(v) for v in value]
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        return float(value) if math.isfinite(value) else None
    return value


def write_json(path: Path, data: dict) -> None:
    """`data` as strict JSON (finite_json: a value that is not a number there, such as the draw-in
    at an angle the rim does not reach, is null)."""
    if MPI.COMM_WORLD.rank == 0:
        text = json.dumps(finite_json(data), indent=2, allow_nan=False, default=float) + "\n"
        write_atomically(path, lambda f: f.write(text))
