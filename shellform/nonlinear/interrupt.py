"""Ctrl-C and SIGTERM as a request to stop at the last converged state.

While a driver steps (``with StopRequests(comm):`` around its increments), the first SIGINT or
SIGTERM only records itself. The driver asks ``requested()`` after every attempt at an
increment, converged or not; the question is collective (the signal may reach one rank only),
so every rank stops after the same increment. The driver then writes the last converged state
and raises ``Interrupted``, which a run turns into a summary marked as stopped by the user and
an exit status 128 + the signal's number. A second signal stops at once (KeyboardInterrupt),
leaving the checkpoint written before it on disk.

Outside a driver's stepping (meshing, compiling, writing results) SIGINT keeps Python's own
behaviour (KeyboardInterrupt), and the command line makes SIGTERM do the same (``stop_now``);
PETSc's own handler is off (shellform._env), so neither ends in PETSc's banner and MPI_Abort. Handlers can only be set in the main thread; elsewhere nothing is installed and no
stop is ever requested.
"""

import signal
import threading

from mpi4py import MPI

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Interrupted(RuntimeError):
    """The user stopped the run (``signal``: its number); the last converged state is on disk."""

    def __init__(self, signum: int, checkpoint=None):
        self.signal, self.checkpoint = signum, checkpoint
        super().__init__(f"stopped by the user ({signal.Signals(signum).name})")


class Stop(KeyboardInterrupt):
    """A signal that stops at once (``signal``: its number): SIGTERM outside a driver's
    stepping (cli.main's handler), or a second SIGINT or SIGTERM while it steps."""

    def __init__(self, signum: int):
        self.signal = signum
        super().__init__(signal.Signals(signum).name)


def stop_now(signum, frame):
    """A signal handler: stop at once (Stop), as Python does for SIGINT."""
    raise Stop(signum)


class StopRequests:
    """The stop requests of one driver's stepping: a context manager, re-entrant."""

    def __init__(self, comm=MPI.COMM_WORLD):
        self.comm = comm
        self.received = 0  # the first signal's number (0: none)
        self._saved, self._depth = {}, 0

    def __enter__(self):
        if self._depth == 0 and threading.current_thread() is threading.main_thread():
            self._saved = {s: signal.signal(s, self._record) for s in SIGNALS}
        self._depth += 1
        return self

    def __exit__(self, *exc):
        self._depth -= 1
        if self._depth == 0:
            for s, handler in self._saved.items():
                signal.signal(s, handler)
            self._saved = {}
        return False

    def _record(self, signum, frame):
        if self.received:
            raise Stop(signum)  # the second request: stop now
        self.received = signum

    def requested(self) -> int:
        """The signal that asked to stop, on any rank (0: none). Collective."""
        return int(self.comm.allreduce(self.received, op=MPI.MAX))
