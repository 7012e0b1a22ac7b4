"""One run stack (shellform.run): the route a scene takes, the controls its [process] sets on
both nonlinear routes, and the summary each route returns, which knows its closing line and
exit status; the command line's --version."""

import csv
import json
import logging
import re
from pathlib import Path

import pytest

import shellform
from shellform import cli, run, scene
from shellform.contact.problem import DrawingProblem
from shellform.errors import InputError
from shellform.nonlinear.driver import Controls
from shellform.nonlinear.problem import SheetProblem, scene_controls
from shellform.results.summary import DrawingSummary, SheetSummary, ShellSummary

ROOT = Path(__file__).resolve().parents[1]
DEMOS = ROOT / "demos"


def small_levy():
    s = scene.load(DEMOS / "levy_plate.toml")
    s.mesh.n, s.process.report = 4, [0.5]
    s.output.vtx = s.output.png = False
    return s


def small_cup():
    """The paper's cup on 4 x 4, 0.2 mm of stroke in two steps."""
    s = scene.load(DEMOS / "square_cup.toml")
    s.mesh.n, s.tools.stroke, s.process.report = 4, 0.2, [0.5]
    s.process.initial_step_mm = s.process.max_step_mm = 0.1
    s.output.vtx = s.output.png = s.output.fld = s.process.springback = False
    return s


def test_route_by_scene():
    assert run.route(scene.load(DEMOS / "square_plate.toml")) == "shell"
    assert run.route(scene.load(DEMOS / "levy_plate.toml")) == "sheet"
    assert run.route(scene.load(DEMOS / "square_cup.toml")) == "tools"


def test_process_sets_the_controls_of_both_nonlinear_routes():
    """The scene's [process] values reach the driver's controls on the sheet's route and the
    tools' route, through one function; a tool scene's steps, in mm of the punch's travel,
    become load-factor steps of the stroke (0.2 mm here)."""
    values = {"initial_step": 0.03, "min_step": 0.001, "max_step": 0.07, "max_iterations": 9, "rtol": 1e-7}
    expected = Controls(**values)
    sheet, tools = small_levy(), small_cup()
    for k, v in values.items():
        setattr(sheet.process, k, v)
        setattr(tools.process, f"{k}_mm" if k.endswith("_step") else k, v * tools.tools.stroke if
                k.endswith("_step") else v)
    for s in (sheet, tools):
        got = scene_controls(s)
        assert {k: getattr(got, k) for k in values} == pytest.approx(values, rel=1e-14)
    assert SheetProblem.from_scene(sheet, verbose=False).driver.controls == expected
    drawing = DrawingProblem.from_scene(tools, verbose=False).driver.controls  # its own easy_iterations
    assert {k: getattr(drawing, k) for k in values} == pytest.approx(values, rel=1e-14)


@pytest.mark.timeout(120)
def test_shell_route_summary_and_closing_line(tmp_path, capsys):
    """The linear shell: the line `shellform run` prints is the summary's closing line (w at the
    centre), and the exit status 0."""
    assert cli.main(["run", str(DEMOS / "square_plate.toml"), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    saved = json.loads((tmp_path / "summary.json").read_text())
    summary = ShellSummary(saved, tmp_path)
    assert out[-1] == summary.closing_line()
    assert out[-1] == (f"shellform: {saved['title']}: 288 cells, w_center = {saved['w_center']}, "
                       f"{saved['wall_time_s']:.2f} s; results in {tmp_path}")
    assert summary.stop_line() is None and summary.exit_status() == 0


@pytest.mark.timeout(120)
def test_sheet_route_summary(tmp_path):
    s = small_levy()
    summary = run.run(s, tmp_path)
    assert isinstance(summary, SheetSummary)
    assert json.loads((tmp_path / "summary.json").read_text()) == json.loads(json.dumps(summary))
    last = summary["reports"][-1]
    assert last["load_factor"] == pytest.approx(1.0)
    assert summary.closing_line() == (
        f"shellform: {s.title}: {summary['cells']} cells, {summary['increments']} increments, load factor "
        f"{last['load_factor']}, w = {last['w']}, {summary['wall_time_s']:.2f} s; results in {tmp_path}")
    assert summary.stop_line() is None and summary.exit_status() == 0


@pytest.mark.timeout(120)
def test_sheet_route_stopped_exits_3(tmp_path):
    """No convergence at the smallest step: the run stops, its summary says so, exit status 3."""
    s = small_levy()
    s.process.initial_step = s.process.min_step = s.process.max_step = 1.0
    s.process.max_iterations = 1
    summary = run.run(s, tmp_path)
    assert summary["stopped"] and summary["signal"] == 0
    assert summary.stop_line() == f"shellform: the run stopped early: {summary['stopped']}"
    assert summary.exit_status() == 3


@pytest.mark.timeout(300)
def test_tools_route_summary(tmp_path):
    s = small_cup()
    summary = run.run(s, tmp_path)
    assert isinstance(summary, DrawingSummary)
    assert summary["stroke_mm"] == pytest.approx(0.2)
    last = summary["draw_in_mm"][-1]
    assert summary.closing_line() == (
        f"shellform: {s.title}: {summary['cells']} cells, stroke 0.20 mm, draw-in (mm) DX {last['DX']:.3f}, "
        f"DY {last['DY']:.3f}, DD {last['DD']:.3f}, punch force {summary['punch_force_kN'][-1]['force']:.2f} kN, "
        f"largest thinning (thickness strain) {summary['min_thickness_strain']:.4f}, "
        f"{summary['wall_time_s']['total']:.1f} s; results in {tmp_path}")
    assert summary.exit_status() == 0


def test_a_callers_listener_is_told_the_increments_and_reports(tmp_path):
    """A listener passed to shellform.run.run (results/listeners.py) is told of the start, every
    increment (the driver's history), every report (the drawn sheet's public measurements), the
    checkpoints, the stop and the end, in that order, and what it records is what the run's own
    tables hold."""
    from shellform.results.listeners import Listener

    class Record(Listener):
        def __init__(self):
            self.events, self.increments, self.reports = [], [], []

        def on_start(self, r):
            self.events.append("start")

        def on_increment(self, r):
            self.events.append("increment")
            self.increments.append((r.driver.history[-1].number, r.sheet.stroke, r.sheet.punch_force() / 1e3))

        def on_report(self, r):
            self.events.append("report")
            self.reports.append(r.sheet.stroke)

        def on_checkpoint(self, r):
            self.events.append("checkpoint")

        def on_stop(self, r):
            self.events.append("stop")

        def on_end(self, r):
            self.events.append("end")

    listener = Record()
    summary = run.run(small_cup(), tmp_path, listeners=[listener])
    rows = list(csv.DictReader(open(tmp_path / "force_stroke.csv")))
    assert [n for n, _, _ in listener.increments] == [int(r["increment"]) for r in rows] == [1, 2]
    assert len(listener.increments) == summary["increments"]
    assert [f for _, _, f in listener.increments] == pytest.approx([float(r["punch_force_kN"]) for r in rows],
                                                                    rel=1e-5)  # the CSV's 6 digits
    assert listener.reports == [r["stroke_mm"] for r in summary["reports"]] == pytest.approx([0.1, 0.2])
    assert listener.events == ["start", "increment", "report", "checkpoint", "increment", "report", "checkpoint",
                               "stop", "end"]
    with pytest.raises(ValueError, match="listeners"):
        run.run(scene.load(DEMOS / "square_plate.toml"), tmp_path / "plate", listeners=[listener])


def test_a_sheet_scenes_listener_is_told_its_increments_and_reports(tmp_path):
    """A sheet scene (results/sheet.py) tells a caller's listener its start, every increment,
    every report and its stop and end, in that order: the load factors it sees are summary.json's
    reports and increments.csv's rows."""
    from shellform.results.listeners import Listener

    class Record(Listener):
        def __init__(self):
            self.events, self.lams, self.reports = [], [], []

        def on_start(self, r):
            self.events.append("start")

        def on_increment(self, r):
            self.events.append("increment")
            self.lams.append(r.driver.history[-1].lam)

        def on_report(self, r):
            self.events.append("report")
            self.reports.append(r.driver.lam)

        def on_stop(self, r):
            self.events.append("stop")

        def on_end(self, r):
            self.events.append("end")

    listener = Record()
    summary = run.run(small_levy(), tmp_path, listeners=[listener])
    rows = list(csv.DictReader(open(tmp_path / "increments.csv")))
    assert listener.lams == pytest.approx([float(r["load_factor"]) for r in rows]) and len(rows) == summary["increments"]
    assert listener.reports == pytest.approx([r["load_factor"] for r in summary["reports"]])
    assert listener.reports == pytest.approx([0.5, 1.0])
    assert listener.events[0] == "start" and listener.events[-2:] == ["stop", "end"]
    assert listener.events.count("report") == 2 and listener.events.count("increment") == len(rows)


def test_exit_status_of_a_stop_by_signal(tmp_path):
    """Stopped by SIGTERM (15) or Ctrl-C (2): 128 + the signal; stopped otherwise: 3."""
    base = {"title": "t", "cells": 1, "reports": [], "increments": 0, "wall_time_s": 0.0}
    assert SheetSummary({**base, "stopped": "SIGTERM", "signal": 15}, tmp_path).exit_status() == 143
    assert SheetSummary({**base, "stopped": "Ctrl-C", "signal": 2}, tmp_path).exit_status() == 130
    assert SheetSummary({**base, "stopped": "no convergence", "signal": 0}, tmp_path).exit_status() == 3
    assert SheetSummary({**base, "stopped": None, "signal": 0}, tmp_path).exit_status() == 0


def test_resume_only_on_the_tools_route(tmp_path):
    with pytest.raises(InputError) as err:
        run.run(small_levy(), tmp_path / "out", resume=True)
    assert err.value.field == "resume"
    assert not (tmp_path / "out" / "summary.json").exists()


def test_version(capsys):
    with pytest.raises(SystemExit) as stop:
        cli.main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"shellform {shellform.__version__}"


def test_named_probes_and_extremes_of_a_nonlinear_scene(tmp_path):
    """[[output.probe]] names vertices whose (u, v, w) every report gives; `extremes` gives the
    largest u, v, w and where. Levy's clamped plate (quarter, 6 x 6) to 10 % of its load: the
    largest w is the centre's; on the clamped, sliding edge y = 0.5 w is zero and u, along it, is not."""
    from shellform.nonlinear.run import run as run_sheet

    s = scene.load(ROOT / "demos" / "levy_plate.toml").changed({
        "mesh.n": 6, "process.path": [0.1], "process.report": [], "output.vtx": False, "output.png": False,
        "output.probe": [{"name": "centre", "x": 0.0, "y": 0.0}, {"name": "edge", "x": 0.25, "y": 0.5},
                         {"name": "inside", "x": 0.25, "y": 0.25}]})
    summary = run_sheet(s, tmp_path)
    last = summary["reports"][-1]
    assert set(last["probes"]) == {"centre", "edge", "inside"}
    assert last["probes"]["centre"]["w"] == last["w"] and last["w"] > 0
    assert last["probes"]["edge"]["w"] == 0.0 and last["probes"]["edge"]["u"] != 0.0
    assert 0 < last["probes"]["inside"]["w"] < last["w"]
    # the same value read twice (bit-for-bit); the vertex's coordinates are tabulated, so computed
    assert last["extremes"]["w"]["value"] == last["w"]
    assert last["extremes"]["w"]["at_initial_xy"] == pytest.approx([0.0, 0.0], abs=1e-12)
    assert abs(last["extremes"]["u"]["value"]) >= abs(last["probes"]["edge"]["u"])


@pytest.mark.parametrize("probe, changes, field, message", [
    ({"name": "tip", "x": 2.0, "y": 0.0}, {}, "output.probe[0]", "outside the blank's bounds"),
    ({"name": "", "x": 0.0, "y": 0.0}, {}, "output.probe[0].name", "non-empty"),
    ({"name": "a", "x": 0.1234, "y": 0.0}, {}, "output.probe[0]", "no mesh vertex at (0.1234, 0.0)"),
])
def test_a_bad_probe_is_named(tmp_path, probe, changes, field, message):
    """A probe outside the blank or without a name is refused with the scene; one between the
    vertices before any step."""
    from shellform.errors import InputError
    from shellform.nonlinear.run import run as run_sheet

    with pytest.raises(InputError, match=rf"^{re.escape(field)}: .*{re.escape(message)}"):
        s = scene.load(ROOT / "demos" / "levy_plate.toml").changed({
            "mesh.n": 4, "output.vtx": False, "output.png": False, "output.probe": [probe], **changes})
        run_sheet(s, tmp_path)
    assert not (tmp_path / "summary.json").exists()


def test_probes_belong_to_nonlinear_sheet_scenes():
    from shellform.errors import InputError

    with pytest.raises(InputError, match=r"^output\.probe\[0\]: probes are reported by nonlinear sheet scenes"):
        scene.load(ROOT / "demos" / "square_cup.toml").changed({"output.probe": [{"name": "c", "x": 0.0, "y": 0.0}]})


def test_a_first_run_says_it_compiles(tmp_path, caplog, monkeypatch):
    """Where this version's numba cache lacks the element kernels (a first run on a machine;
    the scene's checks may have cached another function there), a nonlinear run says that it
    compiles them, and what, before the silence of compiling; with the cache, nothing."""
    from shellform import _jit

    s = scene.load(ROOT / "demos" / "levy_plate.toml").changed({
        "mesh.n": 2, "process.path": [0.01], "process.report": [], "output.vtx": False, "output.png": False})
    other = tmp_path / "cache" / "material_0"
    other.mkdir(parents=True)
    (other / "criteria.hill48-10.py312.nbi").write_bytes(b"")  # a function the checks compiled
    monkeypatch.setattr(_jit, "_CACHE_DIR", str(tmp_path / "cache"))
    caplog.set_level(logging.INFO, logger="shellform")
    run.run(s, tmp_path / "a")
    assert "compiling the element and material kernels: the sheet's element loops" in caplog.text
    monkeypatch.undo()
    caplog.clear()
    run.run(s, tmp_path / "b")
    assert "compiling" not in caplog.text
