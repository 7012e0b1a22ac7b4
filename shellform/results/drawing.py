"""The cup run's own listeners (results/listeners.py): the force-stroke table, the reports, the forming-limit records, the neck's watch, the series and the drawn cup's tables and pictures.

Each owns its state and its file, and is told of the run's events by shellform.contact.run:

| listener | per increment | at a report | at a checkpoint | at the end | summary.json |
|---|---|---|---|---|---|
| `DrawnCup` | | | | thickness_*.csv, thickness.png, rim.csv/.png (a kind with a rim), cup.png | "rim" |
| `ForceStroke` | a row: forces, the holder, the checks, iterations, contacts | | force_stroke.csv | force_stroke.png | "over_the_stroke" |
| `FormingLimits` | the strain path's record; the watch (may end the stroke) | the path's record | | fld.csv, fld.png, cup_margin.png, strain_path.csv | forming_limit, min_margin..., strain_path, forming_limit_reached |
| `neck.Necking` | the watch (may bound the next step, end the stroke; results/neck.py, the sheet route's too) | | | | "neck" |
| `Series` | | cup.bp, cup_cells.bp, cup.pvd and the tools' | | (closed at the stop) | |
| `Reports` | | the state: stroke, draw-in, punch force, thinning, volume change; reports.json | | | draw_in_mm, punch_force_kN, the last report's values, "reports" |

A resumed run's listeners take over what the run before it recorded up to the checkpoint
(on_start): the table's rows and the reports from their files (a damaged file is an
InputError("resume") naming it), the neck from summary.json; the strain path and the watch of
the forming limit are in the checkpoint itself (the driver's records).
"""

import csv
import json
from dataclasses import dataclass
from functools import partial
from pathlib import Path

from shellform.errors import InputError
from shellform.results import cup, fld, neck, sensitivity
from shellform.results.listeners import Listener, Listeners, Run
from shellform.results.tables import write_csv, write_json

# worst values over all increments, in summary.json: the balances and the pinch
CHECKS = ("max_penetration_mm", "force_balance", "holder_largest_share", "holder_pressure_over_flow_stress",
          "free_under_closed_holder")


def _damaged(path: Path, err: Exception) -> InputError:
    return InputError("resume", f"{path} is damaged ({type(err).__name__}: {err}): the rows before the "
                                "checkpoint cannot be taken over; run the scene afresh")


READ_ERRORS = (OSError, UnicodeDecodeError, csv.Error, KeyError, IndexError, TypeError, ValueError)


def state(p) -> dict:
    """The drawn sheet at a report: stroke, draw-in, punch force (kN), peak thinning, volume change."""
    return {"stroke_mm": p.stroke, "draw_in_mm": cup.draw_in(p), "punch_force_kN": p.punch_force() / 1e3,
            **cup.peak_thinning(p), "volume_change": p.volume_change()}


class ForceStroke(Listener):
    """force_stroke.csv (per increment; written at every checkpoint, so that a resume takes its
    rows over up to the checkpoint's stroke) and force_stroke.png."""

    def __init__(self, outdir: Path):
        self.path, self.rows = Path(outdir) / "force_stroke.csv", []

    def on_start(self, run: Run) -> None:
        if run.resumed is None or not self.path.exists():
            return
        try:
            with open(self.path, newline="") as f:
                rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
            rows = [r for r in rows if r["stroke_mm"] <= run.sheet.stroke + 1e-9]
        except READ_ERRORS as err:
            raise _damaged(self.path, err) from None
        self.rows = rows

    def on_increment(self, run: Run) -> None:
        p, h = run.sheet, run.driver.history[-1]
        hx, hy = p.holder_largest_at()
        held, edge, off_band = p.holder_held_down()
        pressure, over_flow = p.holder_pressure()
        self.rows.append({"increment": h.number, "stroke_mm": p.stroke, "punch_force_kN": p.punch_force() / 1e3,
                          "holder_force_kN": p.holder_force() / 1e3, "holder_height_mm": p.holder_height(),
                          "holder_lift_mm": p.holder_lift(),
                          "max_penetration_mm": p.max_penetration(), "force_balance": p.force_balance(),
                          "holder_largest_share": p.holder_share(), "holder_largest_x_mm": hx,
                          "holder_largest_y_mm": hy, "holder_largest_pressure_MPa": pressure,
                          "holder_pressure_over_flow_stress": over_flow, "holder_held_down": held, "holder_edge_load": edge,
                          "holder_off_band": off_band, "free_under_closed_holder": p.free_under_holder(),
                          "iterations": h.iterations, "min_line_search": h.contact["min_line_search"],
                          "contact_passes": h.contact["passes"],
                          **{f"nodes_on_{k}": v for k, v in p.in_contact().items()}})

    def on_checkpoint(self, run: Run) -> None:
        with run.driver.room.write("force_stroke.csv"):
            write_csv(self.path, self.rows, list(self.rows[0]) if self.rows else ["increment"])

    def on_end(self, run: Run) -> None:
        cup.plot_force(run.outdir / "force_stroke.png", self.rows, run.scene.title, run.sheet.symmetry)

    def over_the_stroke(self) -> dict:
        """The worst of each check (CHECKS) over the increments, 0 without any."""
        return {k: max((row[k] for row in self.rows), default=0.0) for k in CHECKS}


class Reports(Listener):
    """The state at every report (state()), in reports.json (rewritten at each; a resumed run
    takes the reports up to its checkpoint over) and in summary.json."""

    def __init__(self, outdir: Path):
        self.path, self.rows = Path(outdir) / "reports.json", []

    def on_start(self, run: Run) -> None:
        if run.resumed is None or not self.path.exists():
            return
        try:
            rows = [r for r in json.loads(self.path.read_text()) if float(r["stroke_mm"]) <= run.sheet.stroke + 1e-9]
            for r in rows:
                float(r["punch_force_kN"]), dict(r["draw_in_mm"])
        except READ_ERRORS as err:
            raise _damaged(self.path, err) from None
        self.rows = rows

    def on_report(self, run: Run) -> None:
        self.rows.append(state(run.sheet))

    def save_report(self, run: Run) -> None:
        write_json(self.path, self.rows)  # rank 0's, after the series' collective writes

    def last(self, run: Run, again: bool = True) -> None:
        """The state where the stroke stopped, for summary.json only (not a report of the scene's:
        a resumed run reports where the scene says); again=False: not where the last report is."""
        if again or not self.rows or self.rows[-1]["stroke_mm"] != run.sheet.stroke:
            self.rows.append(state(run.sheet))

    def summary(self) -> dict:
        """The reports' part of summary.json: draw-in and punch force at every report, the last
        report's other values, and the reports themselves."""
        rows = self.rows
        return {"draw_in_mm": [{"stroke_mm": r["stroke_mm"], **r["draw_in_mm"]} for r in rows],
                "punch_force_kN": [{"stroke_mm": r["stroke_mm"], "force": r["punch_force_kN"]} for r in rows],
                **{k: v for k, v in rows[-1].items() if k not in ("stroke_mm", "draw_in_mm", "punch_force_kN")},
                "reports": rows}


class FormingLimits(Listener):
    """The forming-limit view (results/fld.py) of a plastic sheet: with `view`, the strain path
    (every stroke/200 and at the reports) and at the end fld.csv, fld.png, cup_margin.png (png)
    and strain_path.csv; with `watch`, the stroke ends where the smallest margin reaches 0
    (fld.FormingLimitReached). The path and the watch are records of the driver: its checkpoints
    carry them (records())."""

    def __init__(self, scene, comm, view: bool, watch: bool):
        (curve, _), _ = fld.curves(scene.material)
        self.view, self.png = view, scene.output.png
        self.paths = fld.StrainPaths(curve, comm, scene.tools.stroke / 200) if view else None
        self.watch = fld.FormingLimitWatch(curve, comm) if watch else None
        self.found = {}  # summary.json's part, at the end

    def records(self) -> list:
        """What the driver's checkpoints carry and a resume restores."""
        return [r for r in (self.paths, self.watch) if r is not None]

    def on_increment(self, run: Run) -> None:
        p = run.sheet
        f = p.cell_fields()
        if self.paths is not None:
            self.paths.record(p.stroke, f["major_strain"], f["minor_strain"])
        if self.watch is not None and self.watch.reached(p.stroke, f["major_strain"], f["minor_strain"]):
            run.end_with(fld.FormingLimitReached(
                f"the forming-limit curve is reached at {self.watch.limit['stroke_mm']:.4g} mm"))

    def on_report(self, run: Run) -> None:
        if self.paths is not None:
            f = run.sheet.cell_fields()
            self.paths.record(run.sheet.stroke, f["major_strain"], f["minor_strain"], final=True)

    def on_end(self, run: Run) -> None:
        p, outdir = run.sheet, run.outdir
        found = cup.forming_limits(outdir, p, run.scene.title, self.png) if self.view else {}
        if self.paths is not None:
            path = self.paths.critical(p.cell_centres())
            if path:
                keys = ("stroke_mm", "major", "minor", "margin")
                rows = [dict(zip(keys, r)) for r in zip(*(path[k] for k in keys))]
                write_csv(outdir / "strain_path.csv", rows, list(keys))
                found["strain_path"] = {"initial_xy_mm": path["initial_xy_mm"], "points": len(rows),
                                        "end": {k: path[k][-1] for k in keys}}
        if self.watch is not None:
            found["forming_limit_reached"] = self.watch.limit
        self.found = found


class Series(Listener):
    """The cup's series at the reports (cup.CupSeries: VTX and VTU), opened at the start,
    closed where the stepping stops."""

    def __init__(self, vtx: bool, vtu: bool, fld_margin: bool):
        self.vtx, self.vtu, self.fld_margin, self.series = vtx, vtu, fld_margin, None

    def on_start(self, run: Run) -> None:
        self.series = cup.CupSeries(run.sheet, run.outdir, vtx=self.vtx, vtu=self.vtu, fld_margin=self.fld_margin)

    def save_report(self, run: Run) -> None:
        self.series.write(run.sheet.stroke)

    def on_stop(self, run: Run) -> None:
        self.series.close()


class DrawnCup(Listener):
    """The drawn cup at the end: the thickness strain along its kind's lines (thickness_*.csv,
    thickness.png), a round cup's rim (rim.csv, rim.png; `rim` for summary.json) and, with png,
    the picture cup.png."""

    def __init__(self, png: bool):
        self.png, self.rim = png, None

    def on_end(self, run: Run) -> None:
        p, outdir, title = run.sheet, run.outdir, run.scene.title
        lines = cup.thickness_lines(p)
        for name, line in lines.items():
            write_csv(outdir / f"thickness_{name}.csv", line, ["initial_position_mm", "thickness_strain"])
        cup.plot_thickness(outdir / "thickness.png", lines, f"{title}: stroke {p.stroke:.1f} mm")
        self.rim = cup.write_rim(outdir, p, title) if p.tools_kind.RIM else None
        if self.png:
            cup.picture(outdir / "cup.png", p, f"{title}: stroke {p.stroke:.1f} mm")


class CupSensitivities(Listener):
    """The answers' derivatives in `[output] sensitivities` (a Sensitivity, a record of the
    driver: nonlinear/sensitivity.py), added to each report of `reports` (cup.derivatives; with
    `margin`, the forming-limit view's, the smallest margin's: cup.margin_derivative);
    sensitivities.csv and tornado.png at the end (results/sensitivity.py)."""

    def __init__(self, sens, reports: Reports, margin: bool = False):
        self.sens, self.reports, self.margin = sens, reports, margin

    def on_report(self, run: Run) -> None:
        row = self.reports.rows[-1]
        row["sensitivities"] = {par.name: self._answers(run, par) for par in self.sens.parameters}

    def _answers(self, run: Run, par) -> dict:
        out = cup.derivatives(run.sheet, self.sens, par.name)
        if self.margin:
            out["min_margin"] = cup.margin_derivative(run.sheet, self.sens.carrier(par.name), par.value,
                                                      self.sens.step(par.name), partial(fld.curve_of, run.scene, par.name))
        return out

    def on_end(self, run: Run) -> None:
        s = run.scene
        sensitivity.write(run.outdir, self.reports.rows, self.sens.parameters, s.output.scatter, s.title,
                          picture=s.output.png, at="stroke_mm")

    def summary(self, run: Run) -> dict:
        return sensitivity.summary(self.sens, self.reports.rows, run.scene.output.scatter)


@dataclass
class CupListeners:
    """The listeners a cup run composes, by name (None: not this scene's), and the caller's."""

    drawn: DrawnCup
    table: ForceStroke
    limits: FormingLimits | None
    necking: neck.Necking | None
    series: Series | None
    reports: Reports
    sensitivities: CupSensitivities | None = None
    extra: tuple = ()

    @classmethod
    def of(cls, scene, plastic: bool, outdir: Path, comm, extra=(), sens=None) -> "CupListeners":
        """The scene's listeners: the forming-limit records where the sheet is plastic and the
        view or the stop at the forming limit is asked for, the neck's watch where it is plastic,
        the series where VTX or VTU is, the sensitivities' answers where `sens` (the run's
        Sensitivity record) is given; `extra`, the caller's, told after them."""
        o, pr = scene.output, scene.process
        limits = FormingLimits(scene, comm, o.fld, pr.stop_at_forming_limit) \
            if plastic and (o.fld or pr.stop_at_forming_limit) else None
        series = Series(o.vtx, o.vtu, o.fld and plastic) if o.vtx or o.vtu else None
        necking = neck.Necking.stroke(comm, pr.stop_at_neck, scene.tools.stroke, scene.largest_r()) if plastic else None
        reports = Reports(outdir)
        return cls(DrawnCup(o.png), ForceStroke(outdir), limits, necking, series, reports,
                   CupSensitivities(sens, reports, o.fld and limits is not None) if sens is not None else None,
                   tuple(extra))

    def all(self) -> Listeners:
        """In the order they are told: the drawn cup's pictures first at the end, the forming
        limit's end of the stroke before the neck's, the series' collective writes before the
        reports' own, the report's derivatives after the report."""
        own = (self.drawn, self.table, self.limits, self.necking, self.series, self.reports, self.sensitivities)
        return Listeners([x for x in own if x is not None] + list(self.extra))
