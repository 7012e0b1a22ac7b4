"""Log lines and the progress of a run.

say() prints on rank 0. Progress reports a run increment by increment: on a terminal one line
rewritten in place (load factor or stroke, increments, iterations, time used and an estimate of
the time left); to a file or pipe the driver's plain line per increment, which logs keep.
"""

import shutil
import sys
import time

from mpi4py import MPI


def say(*args, file=None):
    """print() on rank 0 only (one line per run, not one per rank)."""
    if MPI.COMM_WORLD.rank == 0:
        print(*args, file=file, flush=True)


class Progress:
    """Progress of a run towards `total` (a load factor), shown as `scale` x it in `unit`."""

    def __init__(self, label: str = "load factor", total: float = 1.0, unit: str = "", scale: float = 1.0,
                 stream=None):
        self.label, self.total, self.unit, self.scale = label, total, unit, scale
        self.stream = stream if stream is not None else sys.stdout
        self.tty = MPI.COMM_WORLD.rank == 0 and self.stream.isatty()
        self.start = time.perf_counter()
        self._first = None  # (time, progress) at the first increment: the estimate starts there
        self._open = False  # an in-place line is on screen

    def line(self, lam: float, increments: int, iterations: int) -> str:
        """The in-place line. The time left is extrapolated from the progress since the first
        increment (the time before it, compiling and setting up, says nothing of the rest),
        once three increments are done."""
        now = time.perf_counter()
        used = now - self.start
        done = abs(lam) / self.total if self.total else 1.0
        if self._first is None:
            self._first = (now, done)
        t0, d0 = self._first
        left = ""
        if 0 < done < 1 and increments >= 3 and done > d0:
            left = f", about {(now - t0) * (1 - done) / (done - d0):.0f} s left"
        return (f"{self.label} {self.scale * lam:.4g} of {self.scale * self.total:.4g}{self.unit}: "
                f"{increments} increments, {iterations} iterations, {used:.0f} s{left}")

    def increment(self, lam: float, increments: int, iterations: int, detail: str) -> None:
        """After a converged increment: the in-place line on a terminal (fitted to its width),
        else `detail`, with the progress in the run's unit where it is not the load factor."""
        if self.tty:
            width = max(shutil.get_terminal_size((80, 24)).columns - 1, 20)
            text = self.line(lam, increments, iterations)[:width]
            self.stream.write("\r" + text.ljust(width))
            self.stream.flush()
            self._open = True
        else:
            where = f"  ({self.label} {self.scale * lam:.4g}{self.unit})" if self.unit else ""
            self._print(detail + where)

    def note(self, message: str) -> None:
        """A line that stays (a cut-back, a stop): below the in-place line on a terminal."""
        if self._open:
            self.stream.write("\n")
            self._open = False
        self._print(message)

    def _print(self, text: str) -> None:
        if MPI.COMM_WORLD.rank == 0:
            self.stream.write(text + "\n")
            self.stream.flush()

    def close(self) -> None:
        if self._open:
            self.stream.write("\n")
            self.stream.flush()
            self._open = False
