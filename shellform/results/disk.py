"""A full disk: the error every write raises on it, and the room a run keeps for its next write.

DiskFull (an OSError with errno ENOSPC, or EDQUOT: over the user's quota) is what a write
raises where the disk has no room: tables.write_atomically turns the system's error into it,
naming the file; nonlinear/checkpoint.save raises it saying which checkpoint is kept. A run
catches it like a stop (contact/run.py, nonlinear/run.py): stepping ends after the increment
under way, the last complete checkpoint stays as it is, and summary.json says
"disk full: ..." where it still fits.

ADIOS2 (the VTX series) ends the whole process on a full disk, so its failure cannot be
caught. A Room therefore refuses a write before it starts: it measures what each write adds to
the run's folder and, before the next one, asks that the folder's disk have twice the largest
so far free, and at least FLOOR (Room.write).
"""

import errno
import os
import shutil
from contextlib import contextmanager
from pathlib import Path

from mpi4py import MPI

FULL = {errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC)}  # the errors of a disk (or quota) with no room

# the room kept free before any write has been measured, and at least after: the files a run
# writes between two checks and at a stop (force_stroke.csv, reports.json, history.json,
# summary.json: each well under 1 MB on this project's meshes) several times over, so that a
# run stopped by a full disk can still write its summary
FLOOR = 8_000_000


class DiskFull(OSError):
    """A write found (or would have found) no room on the disk. str(): what could not be
    written and why, then `kept` (which checkpoint is kept) where the raiser knows it."""

    def __init__(self, message: str, code: int = errno.ENOSPC, kept: str | None = None):
        super().__init__(code, message)
        self.kept = kept

    def __str__(self):
        return self.strerror + (f"; {self.kept}" if self.kept else "")


def is_full(err: OSError) -> bool:
    """Whether `err` is the system's word for a full disk or quota."""
    return isinstance(err, DiskFull) or err.errno in FULL


def megabytes(n: float) -> str:
    return f"{n / 1e6:.3g} MB"


class Room:
    """The room a run keeps on its folder's disk (collective: every rank calls it; rank 0
    measures and decides).

    write(what) is a context manager around one write (a checkpoint, a report's tables and
    series): before it, DiskFull where the disk has less free than twice the largest write
    measured so far (at least FLOOR); after it, the write's size, the bytes of the files in the
    folder that are new or grew (a file renamed is not counted again; one removed frees none,
    as the write needed its room before it removed it). A DiskFull raised inside on any rank is raised on
    every rank as it leaves, so that rank 0's own writes may fail alone: inside, every rank's
    collective calls come before rank 0's writes."""

    def __init__(self, folder: Path, comm=MPI.COMM_WORLD, floor: int = FLOOR):
        self.folder, self.comm, self.floor = Path(folder), comm, floor
        self.largest = 0  # bytes, the largest write so far (rank 0)

    def check(self, what: str) -> None:
        """DiskFull on every rank where the disk has less free than the room kept for `what`."""
        short = None
        if self.comm.rank == 0:
            where = self.folder
            while not where.exists() and where != where.parent:  # a folder not made yet: its disk
                where = where.parent
            free = shutil.disk_usage(where).free
            need = max(self.floor, 2 * self.largest)
            if free < need:
                why = "twice the largest write so far" if need > self.floor else "the least kept free"
                short = (f"{megabytes(free)} free on the disk of {self.folder}, less than the {megabytes(need)} "
                         f"kept for {what} ({why})")
        short = self.comm.bcast(short, root=0)
        if short:
            raise DiskFull(short)

    @contextmanager
    def write(self, what: str):
        self.check(what)
        before = self._sizes() if self.comm.rank == 0 else None
        failed = None
        try:
            yield
        except DiskFull as err:
            failed = (err.errno, err.strerror, err.kept)
        failed = next((f for f in self.comm.allgather(failed) if f is not None), None)
        if failed is not None:
            code, message, kept = failed
            raise DiskFull(message, code, kept)
        if self.comm.rank == 0:
            after = self._sizes()
            grown = sum(max(size - before.get(node, 0), 0) for node, size in after.items())
            self.largest = max(self.largest, grown)

    def _sizes(self) -> dict:
        """Every file under the folder: (device, inode) -> bytes."""
        sizes = {}
        for root, _, files in os.walk(self.folder):
            for name in files:
                try:
                    st = os.stat(os.path.join(root, name), follow_symlinks=False)
                except OSError:  # gone meanwhile (a temporary file)
                    continue
                sizes[(st.st_dev, st.st_ino)] = st.st_size
        return sizes
