"""The run's log lines and its progress, through Python's `logging`: a quiet library.

The library writes to the logger "shellform" (LOG) and prints nothing itself: it has a
NullHandler, so a script or a notebook that calls shellform sees nothing unless it asks, with
`console()` (what the command line installs) or its own logging configuration. Levels:

    DEBUG    every increment's line even on a terminal (shellform -v)
    INFO     what a run is doing: set-up, compiling, a cut-back, the tables being written,
             and each increment's line (Progress)
    RESULT   the closing line of a run (shellform -q keeps it, and warnings and errors)
    WARNING  a stop, an input error (to stderr)

say() logs a line on rank 0 only (one line per run, not one per rank). Progress sends each
converged increment as an INFO record with the in-place line attached (record.progress): the
console handler shows that line rewritten in place on a terminal (load factor or stroke,
increments, iterations, time used and an estimate of the time left), and the driver's plain line
per increment to a file or pipe, which logs keep.
"""

import logging
import shutil
import sys
import time

from mpi4py import MPI

RESULT = 25  # between INFO and WARNING: the closing line
logging.addLevelName(RESULT, "RESULT")
LOG = logging.getLogger("shellform")
LOG.addHandler(logging.NullHandler())


def say(*args, file=None, level: int | None = None):
    """A line of the log on rank 0: INFO, or WARNING where file is sys.stderr (print's
    argument, for lines that belong on the error stream), or `level`."""
    if MPI.COMM_WORLD.rank == 0:
        level = level if level is not None else (logging.WARNING if file is sys.stderr else logging.INFO)
        LOG.log(level, " ".join(str(a) for a in args))


class Console(logging.Handler):
    """Rank 0's log on the console: records below WARNING to `out`, the others to `err`, each
    as its message on a line; a record that carries a progress line (record.progress) rewrites
    one line in place where `out` is a terminal and the level shown is above DEBUG."""

    def __init__(self, out=None, err=None):
        super().__init__()
        self.out = out if out is not None else sys.stdout
        self.err = err if err is not None else sys.stderr
        self._open = False  # an in-place line is on screen

    def emit(self, record: logging.LogRecord) -> None:
        if MPI.COMM_WORLD.rank != 0:
            return
        try:
            line = getattr(record, "progress", None)
            if getattr(record, "end_of_progress", False):
                self._close()
                return
            if line is not None and self.out.isatty() and self.level > logging.DEBUG:
                width = max(shutil.get_terminal_size((80, 24)).columns - 1, 20)
                self.out.write("\r" + line[:width].ljust(width))
                self.out.flush()
                self._open = True
                return
            self._close()
            stream = self.err if record.levelno >= logging.WARNING else self.out
            stream.write(self.format(record) + "\n")
            stream.flush()
        except Exception:  # noqa: BLE001 (logging's contract: a handler never raises)
            self.handleError(record)

    def _close(self) -> None:
        if self._open:
            self.out.write("\n")
            self.out.flush()
            self._open = False


def console(level: int = logging.INFO, out=None, err=None) -> Console:
    """Show the log on the console from `level` on (DEBUG: every increment's line; RESULT: the
    closing line, warnings and errors only); returns the handler, which `quiet` removes."""
    handler = Console(out, err)
    handler.setLevel(level)
    handler.before = LOG.level
    LOG.addHandler(handler)
    LOG.setLevel(min(level, LOG.getEffectiveLevel()))
    return handler


def quiet(handler: Console) -> None:
    """Remove a handler console() installed, and the level it set."""
    handler.emit(logging.makeLogRecord({"end_of_progress": True}))
    LOG.removeHandler(handler)
    LOG.setLevel(handler.before)


class Progress:
    """Progress of a run towards `total` (a load factor), shown as `scale` x it in `unit`."""

    def __init__(self, label: str = "load factor", total: float = 1.0, unit: str = "", scale: float = 1.0):
        self.label, self.total, self.unit, self.scale = label, total, unit, scale
        self.start = time.perf_counter()
        self._first = None  # (time, progress) at the first increment: the estimate starts there

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
        """After a converged increment: `detail` (with the progress in the run's unit where it
        is not the load factor), carrying the in-place line."""
        if MPI.COMM_WORLD.rank != 0 or not LOG.isEnabledFor(logging.INFO):
            return
        where = f"  ({self.label} {self.scale * lam:.4g}{self.unit})" if self.unit else ""
        LOG.info(detail + where, extra={"progress": self.line(lam, increments, iterations)})

    def note(self, message: str) -> None:
        """A line that stays (a cut-back, a stop): below the in-place line on a terminal."""
        say(message)

    def close(self) -> None:
        """The run's increments are done: an in-place line on screen ends."""
        if MPI.COMM_WORLD.rank == 0:
            LOG.info("", extra={"end_of_progress": True})
