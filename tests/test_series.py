"""The scenes' time series (results/vtu.py; results/cup.py CupSeries, results/fields.py
SheetSeries) as a user opens them: with pyvista's readers, the drawn cup at the last report and
the tools where they are; a plate's or a shell's deformed sheet with its fields."""

import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from shellform import run, scene
from shellform.tools.analytic import Die, Punch, rounded_square_sdf
from shellform.tools.protocol import surface_mesh
from shellform.results.vtu import PVDSeries
from shellform.studies.common import mpiexec

ROOT = Path(__file__).resolve().parents[1]
pyvista = pytest.importorskip("pyvista")


def last_step(pvd: Path):
    """The last step of a PVD series as pyvista reads it: (times, the mesh)."""
    reader = pyvista.get_reader(str(pvd))
    reader.set_active_time_point(len(reader.time_values) - 1)
    return list(reader.time_values), reader.read()[0]


def test_a_written_series_reads_back_exactly(tmp_path):
    """Points, triangles, point and cell arrays of every type round-trip through the VTU
    files, and the index lists the steps by time; a second writer (a resumed run) keeps the
    steps before its first time and replaces the later ones."""
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.5]], dtype=float)
    tris = np.array([[0, 1, 2], [1, 3, 2]])
    series = PVDSeries(tmp_path, "s")
    for t in (1.0, 2.0, 3.0):
        series.write(t, t * points, tris, {"u": t * points, "state": np.array([0, 1, 2, 4], dtype=np.int8)},
                     {"peq": t * np.array([0.1, 0.2])})
    resumed = PVDSeries(tmp_path, "s")
    resumed.write(2.5, points, tris, {"u": points, "state": np.zeros(4, dtype=np.int8)}, {"peq": np.zeros(2)})
    times, grid = last_step(tmp_path / "s.pvd")
    assert times == [1.0, 2.0, 2.5]
    np.testing.assert_array_equal(grid.points, points)
    np.testing.assert_array_equal(grid.cells_dict[pyvista.CellType.TRIANGLE], tris)
    second = pyvista.read(tmp_path / ET.parse(tmp_path / "s.pvd").getroot()[0][1].get("file"))
    np.testing.assert_array_equal(second.point_data["u"], 2.0 * points)
    np.testing.assert_array_equal(second.point_data["state"], [0, 1, 2, 4])
    np.testing.assert_array_equal(second.cell_data["peq"], [0.2, 0.4])


def test_a_sheet_scene_writes_its_reports_as_a_series(tmp_path):
    """Levy's clamped plate (the nonlinear sheet route, quarter, 4 x 4) to load factors 0.05
    and 0.1: sheet.pvd has a step at each report; the last is the deformed mid-surface (initial
    position + displacement) with the summary's centre deflection at the origin and the cells'
    fields, every cell once."""
    s = scene.load(ROOT / "demos" / "levy_plate.toml").changed({
        "mesh.n": 4, "process.path": [0.1], "process.report": [0.05], "output.vtx": False, "output.png": False})
    summary = run.run(s, tmp_path)
    times, sheet = last_step(tmp_path / "sheet.pvd")
    assert times == pytest.approx([0.05, 0.1])
    assert sheet.n_cells == summary["cells"] and sheet.n_points == 25
    initial = sheet.points - sheet.point_data["displacement"]
    origin = np.flatnonzero(np.hypot(initial[:, 0], initial[:, 1]) < 1e-12)
    assert origin.size == 1
    assert sheet.point_data["displacement"][origin[0], 2] == pytest.approx(summary["reports"][-1]["w"], rel=1e-12)
    assert sheet.points[origin[0], 2] == pytest.approx(summary["reports"][-1]["w"], rel=1e-12)
    assert {"slopes"} <= set(sheet.point_data) and {"equivalent_plastic_strain", "thickness_strain"} <= set(sheet.cell_data)


def test_a_shell_scene_writes_its_solution_as_a_series(tmp_path):
    """The linear square plate: sheet.pvd's one step is the deflected plate, w at the centre
    the summary's, with the strains and resultants per cell."""
    s = scene.load(ROOT / "demos" / "square_plate.toml").changed({"output.vtx": False, "output.png": False})
    summary = run.run(s, tmp_path)
    times, sheet = last_step(tmp_path / "sheet.pvd")
    assert times == [1.0] and sheet.n_cells == summary["cells"]
    d = sheet.point_data["displacement"]
    centre = np.flatnonzero(np.hypot(*(sheet.points - d)[:, :2].T) < 1e-12)
    assert d[centre[0], 2] == pytest.approx(summary["w_center"], rel=1e-12)
    assert {"curvature", "moment"} <= set(sheet.cell_data) and sheet.cell_data["moment"].shape == (sheet.n_cells, 3)


def test_tool_surfaces_lie_on_the_tools():
    """The points of a punch's surface mesh that lie inside its plan outline, and those of a
    die's outside its opening, have a zero signed distance to the tool (within the bisection's
    tolerance); the others lie at the end of the range away from the sheet (the walls, the
    opening); the punch's face is at its shifted height."""
    punch, die = Punch(35.0, 10.0, 8.0, 0.39), Die(37.0, 12.0, 5.0, -0.39)
    for tool, dz, above, outline in ((punch, -10.0, True, lambda x, y: -rounded_square_sdf(x, y, 35.0, 10.0)[0]),
                                     (die, 0.0, False, lambda x, y: rounded_square_sdf(x, y, 37.0, 12.0)[0])):
        points, tris = surface_mesh(tool, dz, (0.0, 75.0, 0.0, 75.0), (dz - 20, dz + 20), above, n=64)
        on_tool = np.abs(tool.gap(points, 0.0, dz)[0]) < 1e-9
        inside = outline(points[:, 0], points[:, 1])  # > 0: the plan point lies on the tool's face
        clear = np.abs(inside) > 1e-6
        np.testing.assert_array_equal(on_tool[clear], inside[clear] > 0)
        np.testing.assert_allclose(points[~on_tool, 2], dz + 20 if above else dz - 20)
        assert tris.max() == len(points) - 1
    points, _ = surface_mesh(punch, -10.0, (0.0, 75.0, 0.0, 75.0), (-30, 10), True, n=64)
    assert points[:, 2].min() == pytest.approx(0.39 - 10.0, abs=1e-9)


def small_cup():
    """The paper's cup on 4 x 4, drawn 3 mm in 4 increments, reported at 1.5 and 3 mm."""
    return scene.load(ROOT / "demos" / "square_cup.toml").changed({
        "mesh.n": 4, "tools.stroke": 3.0, "process.report": [0.5], "process.initial_step_mm": 0.75,
        "process.max_step_mm": 0.75, "output.vtx": False, "output.png": False, "process.springback": False})


def test_the_cup_series_opens_in_pyvista_as_the_drawn_cup(tmp_path):
    """small_cup: the last step of cup.pvd is the
    deformed quarter (its depth the stroke within the sheet's thickness, its points the
    initial blank plus the displacement), with finite point and cell fields; each tool is a
    series of its own at its position: the punch's face the stroke below where it started."""
    s = small_cup()
    summary = run.run(s, tmp_path)
    assert summary["stopped"] is None
    t = s.material.thickness
    times, cup = last_step(tmp_path / "cup.pvd")
    assert times == pytest.approx([1.5, 3.0])
    assert cup.n_cells == summary["cells"]
    depth = -cup.points[:, 2].min()
    assert abs(depth - s.tools.stroke) < t
    initial = cup.points - cup.point_data["displacement"]
    np.testing.assert_allclose(initial[:, 2], 0.0, atol=1e-12)  # the flat blank
    assert initial[:, :2].min() == pytest.approx(0.0, abs=1e-12)
    assert initial[:, :2].max() == pytest.approx(75.0)  # the quarter, not mirrored
    for name in ("displacement", "thickness_strain", "contact_state", "contact_pressure"):
        assert np.all(np.isfinite(cup.point_data[name])), name
    for name in ("equivalent_plastic_strain", "major_strain", "minor_strain", "fld_margin"):
        assert np.all(np.isfinite(cup.cell_data[name])), name
    assert cup.cell_data["equivalent_plastic_strain"].max() > 0
    np.testing.assert_allclose(cup.point_data["thickness_strain"].min(), summary["min_thickness_strain"], rtol=1e-12)
    assert set(np.unique(cup.point_data["contact_state"])) <= {0, 1, 2, 3, 4}
    assert (cup.point_data["contact_state"] == 1).any()  # nodes on the punch
    free = cup.point_data["contact_state"] == 0
    assert np.all(cup.point_data["contact_pressure"][free] == 0.0) and np.all(cup.point_data["contact_pressure"] >= 0)
    assert cup.point_data["contact_pressure"][~free].max() > 0
    _, punch = last_step(tmp_path / "punch.pvd")
    assert punch.points[:, 2].min() == pytest.approx(t / 2 + s.tools.punch_gap - s.tools.stroke, abs=1e-9)
    _, die = last_step(tmp_path / "die.pvd")
    assert die.points[:, 2].max() == pytest.approx(-t / 2, abs=1e-9)
    _, holder = last_step(tmp_path / "blank_holder.pvd")
    assert holder.n_cells > 0 and holder.points[:, 2].min() >= t / 2 - 1e-9
    assert json.loads((tmp_path / "summary.json").read_text())["stroke_mm"] == pytest.approx(3.0)


TWO_RANKS = """
import sys
from pathlib import Path
sys.path.insert(0, {tests!r})
from test_series import small_cup
from shellform import run
run.run(small_cup().changed({{"output.png": True}}), Path({out!r}))
"""


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
def test_the_series_does_not_depend_on_the_ranks(tmp_path):
    """small_cup on 2 ranks writes the serial run's last step: the same nodes and triangles in
    the same order, the same fields to the solver's tolerance; and rank 0 draws cup.png."""
    run.run(small_cup(), tmp_path / "serial")
    script = tmp_path / "two.py"
    script.write_text(TWO_RANKS.format(tests=str(Path(__file__).parent), out=str(tmp_path / "two")))
    done = subprocess.run([mpiexec(), "-n", "2", sys.executable, str(script)], capture_output=True, text=True,
                          timeout=600, env=dict(os.environ, OMP_NUM_THREADS="1"))
    assert done.returncode == 0, done.stderr[-2000:]
    _, serial = last_step(tmp_path / "serial" / "cup.pvd")
    _, two = last_step(tmp_path / "two" / "cup.pvd")
    np.testing.assert_array_equal(two.cells_dict[pyvista.CellType.TRIANGLE],
                                  serial.cells_dict[pyvista.CellType.TRIANGLE])
    np.testing.assert_allclose(two.points, serial.points, atol=1e-6)
    for name in ("thickness_strain", "contact_state"):
        np.testing.assert_allclose(two.point_data[name], serial.point_data[name], atol=1e-6)
    np.testing.assert_allclose(two.cell_data["equivalent_plastic_strain"],
                               serial.cell_data["equivalent_plastic_strain"], atol=1e-6)
    png = (tmp_path / "two" / "cup.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and int.from_bytes(png[16:20], "big") == 1000  # its width
    _, punch = last_step(tmp_path / "two" / "punch.pvd")
    _, punch1 = last_step(tmp_path / "serial" / "punch.pvd")
    np.testing.assert_allclose(punch.points, punch1.points, atol=1e-9)


def test_a_resumed_run_extends_the_series(tmp_path):
    """small_cup drawn 1.5 mm (reports at 0.75 and 1.5 mm), then resumed to 3 mm: cup.pvd lists
    the first run's steps and the resumed run's, each stroke once, and its last step is the
    cup at 3 mm."""
    first = small_cup().changed({"tools.stroke": 1.5})
    run.run(first, tmp_path)
    assert last_step(tmp_path / "cup.pvd")[0] == pytest.approx([0.75, 1.5])
    s = small_cup()
    summary = run.run(s, tmp_path, resume=True)
    assert summary["resumed_from_stroke_mm"] == pytest.approx(1.5)
    times, cup = last_step(tmp_path / "cup.pvd")
    assert times == pytest.approx([0.75, 1.5, 3.0])
    assert abs(-cup.points[:, 2].min() - s.tools.stroke) < s.material.thickness
    assert last_step(tmp_path / "punch.pvd")[0] == pytest.approx([0.75, 1.5, 3.0])
