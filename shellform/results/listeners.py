"""Results as listeners: the run announces its start, each increment, each report and its end; what records or writes results subscribes.

A run (shellform.contact.run) builds its problem and its driver, composes a list of listeners
and drives; it calls every listener at each of these moments, in list order, with the one
`Run` it drives (the drawn sheet, the driver, the scene, the output folder):

| method | when | what a listener does there |
|---|---|---|
| `on_start(run)` | before the first increment (after a resume's checks) | take over what a resumed run recorded |
| `on_increment(run)` | after each converged increment | record the increment (`run.driver.history[-1]`); bound the next step (`run.driver.bound_next_step`); ask the stroke to end (`run.end_with`) |
| `on_report(run)` | at each report of the scene, and where the stroke ends early | record the state (collective reads, no writes) |
| `save_report(run)` | then, inside the room the run keeps for the report (results/disk.py) | write what the report adds to disk: collective calls first, then rank 0's own writes |
| `on_checkpoint(run)` | before a checkpoint is written, and after a stop the driver wrote one | write what a resumed run takes over (the rows up to the checkpoint) |
| `on_stop(run)` | the stepping is over, whatever ended it | close its files |
| `on_end(run)` | then, where the disk had room: the drawn cup | write its tables and pictures |

Every method defaults to doing nothing (the pattern of shellform.nonlinear.parts.Part). A
listener owns its state and its files; it reads the sheet through the drawn sheet's public
measurements (shellform.results.cup, "the drawn sheet"), never the problem's insides, and the
increments through the driver's public history. What it adds to summary.json the run asks of
it by name. A caller passes its own listeners (shellform.run.run(..., listeners=[...])): they
are told after the run's own, in the same order of events.

What a run records along the way and a resume continues (the strain path, the forming-limit
watch, the sensitivities) is a `Record` of the driver instead: the driver tells it of each
converged increment before committing it and keeps its state in its checkpoints, so that a
resume restores it with the sheet's.
"""

from dataclasses import dataclass, field
from pathlib import Path


@dataclass
class Run:
    """What a listener is told about: the run as it is driven.

    sheet: the drawn sheet (shellform.contact.problem.DrawingProblem: its stroke, forces and
    fields); driver: its history, next_step and bound_next_step, progress (notes) and room (the
    disk); scene, outdir, comm; resumed: what summary.json records of a resume (None for a
    fresh run); stopped: why the stroke stopped early, in words (None while it goes on);
    ending: the exception a listener asked the stroke to end with (end_with)."""

    sheet: object
    driver: object
    scene: object
    outdir: Path
    comm: object
    resumed: dict | None = None
    stopped: str | None = None
    ending: Exception | None = field(default=None, repr=False)

    def end_with(self, err: Exception) -> None:
        """Ask the stroke to end after this increment (the first asked wins): the run raises
        `err` once every listener has been told of the increment and a checkpoint due was written."""
        if self.ending is None:
            self.ending = err


class EndOfStroke(Exception):
    """A listener's reason to end the stroke where it is (Run.end_with): the run reports and
    checkpoints that state and logs str() of it (results/fld.py FormingLimitReached,
    results/neck.py NeckReached)."""


class Listener:
    """The protocol (module docstring); every method defaults to doing nothing."""

    def on_start(self, run: Run) -> None:
        """The run is about to step (a resumed run: from its checkpoint's state)."""

    def on_increment(self, run: Run) -> None:
        """An increment converged and was committed (run.driver.history[-1])."""

    def on_report(self, run: Run) -> None:
        """A report: record the state (every rank; nothing written)."""

    def save_report(self, run: Run) -> None:
        """Write what the report adds to disk (inside the run's room for the report)."""

    def on_checkpoint(self, run: Run) -> None:
        """A checkpoint is written now (or the driver wrote one at a stop): write what a resume
        takes over up to it."""

    def on_stop(self, run: Run) -> None:
        """The stepping is over (the end of the stroke, a stop, a full disk): close files."""

    def on_end(self, run: Run) -> None:
        """The drawn cup, where the disk has room: its tables and pictures."""


class Record:
    """What a run records along the way and a resume continues (a strain path, a watch, the
    sensitivities): kept with the driver's state (driver.records), in its checkpoints. The
    driver tells each record, in list order, of a converged increment before committing it
    (`converged`: the converged state, the committed one still at hand), writes its state into
    every checkpoint (`checkpoint`) and reads it back on a resume (`restore`). Every method
    defaults to doing nothing, as a Part's does (shellform.nonlinear.parts)."""

    def converged(self, driver, lam: float) -> None:
        """The increment to lam converged and is not committed yet (driver: its public state)."""

    def checkpoint(self) -> dict:
        """{"nodes": {...}, "cells": {...}, "global": {...}}: what a resume continues from."""
        return {}

    def restore(self, state: dict) -> None:
        """Read back checkpoint() (this rank's groups)."""


class Listeners(list):
    """The listeners of a run, told in list order."""

    def announce(self, event: str, run: Run) -> None:
        """Call `event` (a Listener method's name) of every listener with the run."""
        for listener in self:
            getattr(listener, event)(run)

    def report(self, run: Run) -> None:
        """A report: every listener records (on_report), then writes inside the room the driver
        keeps for the report (save_report: rank 0's writes after the collective ones)."""
        self.announce("on_report", run)
        with run.driver.room.write("the report"):
            self.announce("save_report", run)
