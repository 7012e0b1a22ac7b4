"""A run's summary: the content of summary.json, and how the run ends.

Every route (shellform.run: the linear shell, the nonlinear sheet, the tools) returns a
Summary: a dict holding exactly what summary.json holds, which also knows

    closing_line()   the one line `shellform run` prints on stdout at the end: the title, the
                     cells, the route's result in a few numbers (and where the sheet started to
                     neck, summary.json "neck", if it did), the time, the output folder
    stop_line()      where the run stopped early (no convergence, a limit load, Ctrl-C,
                     SIGTERM, a full disk), and that summary.json could not be written where
                     it could not: the line for stderr; None when it ran to its end
    exit_status()    0 when it ran to its end, 128 + the signal when a signal stopped it, 3
                     when it stopped otherwise or its summary could not be written
                     (docs/reliability.md)
    write()          summary.json, or, where it cannot be written, why (for stop_line)

so that the command line prints and returns without asking which route ran.
"""

from pathlib import Path

from mpi4py import MPI

from shellform.results import neck
from shellform.results.tables import write_json


def printable(text: str) -> str:
    """text with its control characters escaped (\\x1b, \\r, ...), for a terminal; other characters as they are."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))


class Summary(dict):
    """summary.json's content (the dict) and the output folder it was written to."""

    def __init__(self, content: dict, outdir):
        super().__init__(content)
        self.outdir = Path(outdir)
        self.unwritten = None  # why summary.json could not be written (write)

    def write(self, comm=MPI.COMM_WORLD) -> None:
        """summary.json (rank 0); where it cannot be written (a full disk), the reason is kept
        in `unwritten` on every rank, for the stop line, and the run ends as stopped. Collective."""
        error = None
        try:
            write_json(self.outdir / "summary.json", self)
        except OSError as err:
            error = str(err)
        self.unwritten = comm.bcast(error, root=0)

    def closing_line(self) -> str:
        return f"shellform: {printable(self['title'])}: {self['cells']} cells; results in {self.outdir}"

    def stop_line(self) -> str | None:
        said = ([f"the run stopped early: {self['stopped']}"] if self.get("stopped") else []) \
            + ([f"summary.json could not be written ({self.unwritten})"] if self.unwritten else [])
        return "shellform: " + "; ".join(said) if said else None

    def exit_status(self) -> int:
        if not self.get("stopped") and not self.unwritten:
            return 0
        return 128 + self["signal"] if self.get("signal") else 3


class ShellSummary(Summary):
    """The linear shell: w at the centre."""

    def closing_line(self) -> str:
        return (f"shellform: {printable(self['title'])}: {self['cells']} cells, w_center = {self['w_center']}, "
                f"{self['wall_time_s']:.2f} s; results in {self.outdir}")


class SheetSummary(Summary):
    """The nonlinear sheet: the last reported load factor and w there, and the neck's onset."""

    def closing_line(self) -> str:
        last = self["reports"][-1] if self["reports"] else {}
        necked = f", {neck.words(self['neck'], 'load_factor', 'initial_xy')}" if self.get("neck") else ""
        return (f"shellform: {printable(self['title'])}: {self['cells']} cells, {self['increments']} increments, "
                f"load factor {last.get('load_factor')}, w = {last.get('w')}{necked}, {self['wall_time_s']:.2f} s; "
                f"results in {self.outdir}")


class DrawingSummary(Summary):
    """The tools: the stroke reached, the last draw-in, the peak thickness strain, the neck's
    onset."""

    def closing_line(self) -> str:
        last = self["draw_in_mm"][-1] if self["draw_in_mm"] else {}
        draw_in = ", ".join(f"{k} {v:.3f}" for k, v in last.items() if k != "stroke_mm")
        force = self["punch_force_kN"][-1]["force"] if self.get("punch_force_kN") else float("nan")
        necked = f", {neck.words(self['neck'])}" if self.get("neck") else ""
        return (f"shellform: {printable(self['title'])}: {self['cells']} cells, stroke {self['stroke_mm']:.2f} mm, "
                f"draw-in (mm) {draw_in}, punch force {force:.2f} kN, largest thinning (thickness strain) "
                f"{self['min_thickness_strain']:.4f}{necked}, {self['wall_time_s']['total']:.1f} s; "
                f"results in {self.outdir}")
