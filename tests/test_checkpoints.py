"""What survives a kill, and what a resume may and may not continue (docs/reliability.md):
checkpoints written whole or not at all, the previous one kept; --out checked before any
computation; a run's folder its own; a resume refused for another state or a shorter stroke;
the counts of the whole run; checkpoints that resume on another number of ranks."""

import errno
import io
import json
import logging
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from plastic_strip import strip_scene
from resume_cup import cup, killed_after_first_report

from shellform import cli
from shellform.contact import run as contact_run
from shellform.contact.semi_inverse import SemiInverseDriver
from shellform.errors import InputError
from shellform.studies.common import mpiexec

ROOT = Path(__file__).resolve().parents[1]
COUNTS = ("increments", "newton_iterations", "contact_passes", "cutbacks")


class Killed(Exception):
    pass


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    """The short cup run uninterrupted: (its folder, with the checkpoints at 0.5 and 1 mm, and its summary)."""
    out = tmp_path_factory.mktemp("whole")
    return out, contact_run.run(cup(), out)


def assert_same_end(summary, reference, rel=1e-9):
    a, b = summary["reports"][-1], reference["reports"][-1]
    assert summary["stroke_mm"] == pytest.approx(reference["stroke_mm"])
    assert a["punch_force_kN"] == pytest.approx(b["punch_force_kN"], rel=rel)
    assert a["draw_in_mm"]["DD"] == pytest.approx(b["draw_in_mm"]["DD"], rel=rel, abs=1e-9)
    assert a["min_thickness_strain"] == pytest.approx(b["min_thickness_strain"], rel=rel)


@pytest.mark.timeout(300)
def test_a_kill_while_a_checkpoint_is_written_keeps_the_one_before(tmp_path, whole, monkeypatch):
    """The second checkpoint's write dies halfway (the first half of its bytes written, then
    the process killed): the first checkpoint is still whole, and --resume continues from it to
    the uninterrupted run's end (today: the half-written file had replaced it, BadZipFile)."""
    real, calls = np.savez, []

    def dies_halfway(file, *args, **kwargs):
        calls.append(1)
        if len(calls) < 2:
            return real(file, *args, **kwargs)
        buf = io.BytesIO()
        real(buf, *args, **kwargs)
        half = buf.getvalue()[: len(buf.getvalue()) // 2]
        if hasattr(file, "write"):
            file.write(half)
        else:
            Path(file).write_bytes(half)
        raise Killed

    monkeypatch.setattr(np, "savez", dies_halfway)
    with pytest.raises(Killed):
        contact_run.run(cup(), tmp_path)
    monkeypatch.setattr(np, "savez", real)
    assert len(calls) == 2
    summary = contact_run.run(cup(), tmp_path, resume=True)
    assert summary["resumed_from_stroke_mm"] == pytest.approx(0.5)
    assert_same_end(summary, whole[1])


@pytest.mark.timeout(300)
def test_a_damaged_checkpoint_is_named_and_the_previous_one_used(tmp_path, whole, caplog):
    """checkpoint.npz cut to half its length (what an in-place write leaves): the resume says
    that file is damaged, takes checkpoint.previous.npz (0.5 mm) and ends where the
    uninterrupted run ends."""
    shutil.copytree(whole[0], tmp_path / "out")
    out = tmp_path / "out"
    data = (out / "checkpoint.npz").read_bytes()
    (out / "checkpoint.npz").write_bytes(data[: len(data) // 2])
    caplog.set_level(logging.INFO, logger="shellform")
    summary = contact_run.run(cup(), out, resume=True)
    assert summary["resumed"]["checkpoint"] == "checkpoint.previous.npz"
    assert summary["resumed_from_stroke_mm"] == pytest.approx(0.5)
    damaged = summary["resumed"]["damaged"]
    assert len(damaged) == 1 and str(out / "checkpoint.npz") in damaged[0] and "damaged" in damaged[0]
    assert f"{out / 'checkpoint.npz'}: damaged" in caplog.text
    assert_same_end(summary, whole[1])


def test_summaries_and_tables_survive_a_full_disk(tmp_path, monkeypatch):
    """write_json and write_csv (summary.json, reports.json, the CSVs a resume reads) that
    fail halfway through their write (a full disk: half the bytes written, then ENOSPC) leave
    the file before them whole, and no temporary file (today: a cut file)."""
    import builtins
    import errno

    from shellform.results import tables

    tables.write_json(tmp_path / "summary.json", {"a": 1})
    tables.write_csv(tmp_path / "rows.csv", [{"x": 1.0}], ["x"])
    real_open = io.open

    class FullDisk:
        def __init__(self, f):
            self.f = f

        def write(self, data):
            self.f.write(data[: len(data) // 2])
            self.f.flush()
            raise OSError(errno.ENOSPC, "No space left on device")

        def __getattr__(self, name):
            return getattr(self.f, name)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.f.close()

    def full_disk_open(file, mode="r", *args, **kwargs):
        f = real_open(file, mode, *args, **kwargs)
        return FullDisk(f) if "w" in mode else f

    with monkeypatch.context() as m:
        m.setattr(builtins, "open", full_disk_open)
        m.setattr(io, "open", full_disk_open)
        with pytest.raises(OSError):
            tables.write_json(tmp_path / "summary.json", {"b": 2, "c": list(range(100))})
        with pytest.raises(OSError):
            tables.write_csv(tmp_path / "rows.csv", [{"x": 2.0}] * 100, ["x"])
    assert json.loads((tmp_path / "summary.json").read_text()) == {"a": 1}
    assert (tmp_path / "rows.csv").read_text().splitlines() == ["x", "1"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rows.csv", "summary.json"]


# the short cup through the command: reports at 0.3 and 0.6 mm (a checkpoint at each), no timed ones
DISK_CUP = ["--set", "mesh.n=6", "--set", "tools.stroke=1.0", "--set", "process.report=[0.3, 0.6]",
            "--set", "process.initial_step_mm=0.05", "--set", "process.max_step_mm=0.1",
            "--set", "output.checkpoint_every=0", "--set", "output.png=false", "--set", "output.fld=false",
            "--set", "process.springback=false"]


def _no_space(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device")


def _run_cup(out, *settings):
    return cli.main(["run", str(ROOT / "demos" / "square_cup.toml"), "--out", str(out), *DISK_CUP, *settings])


@pytest.mark.timeout(300)
@pytest.mark.parametrize("failing", [1, 2])
def test_a_full_disk_stops_the_run_keeping_the_last_complete_checkpoint(tmp_path, monkeypatch, capsys, failing):
    """The checkpoint's write meets a full disk (np.savez raises ENOSPC) at the second report
    (0.6 mm), or at the first (0.3 mm): the run stops there with exit 3 and one line on
    stderr, no traceback; summary.json says "disk full at S mm" and which checkpoint is kept
    (the one at 0.3 mm, whole and loadable, or that none was written yet); the tables after the
    stroke are not written, nor any temporary file left (today: an OSError traceback, and for
    the first checkpoint "the one before is kept", though there is none)."""
    from shellform.nonlinear import checkpoint

    real, calls = np.savez, []

    def full_at_last(file, *args, **kwargs):
        calls.append(1)
        if len(calls) == failing:
            _no_space()
        return real(file, *args, **kwargs)

    monkeypatch.setattr(np, "savez", full_at_last)
    out = tmp_path / "out"
    rc = _run_cup(out, "--set", "output.vtx=false")
    monkeypatch.undo()
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    stop = 0.3 * failing
    assert rc == 3
    assert "Traceback" not in captured.err + captured.out
    assert len(err) == 1 and err[0].startswith(f"shellform: the run stopped early: disk full at {stop:g} mm: "), err
    assert "No space left on device" in err[0]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stopped"].startswith(f"disk full at {stop:g} mm: the checkpoint {out / 'checkpoint.npz'} "
                                         "could not be written (No space left on device); ")
    assert summary["stroke_mm"] == pytest.approx(stop)
    assert "the one before is kept" not in summary["stopped"]
    if failing == 1:
        assert summary["stopped"].endswith("; no checkpoint was written yet")
        assert not (out / "checkpoint.npz").exists() and not (out / "checkpoint.previous.npz").exists()
    else:
        assert summary["stopped"].endswith(f"; the last complete checkpoint, {out / 'checkpoint.npz'} at 0.3 mm, "
                                           "is kept: --resume continues from it once there is room")
        saved = checkpoint.read(out)
        assert saved.path == out / "checkpoint.npz" and not saved.damaged
        assert float(saved.arrays["global.lam"]) == pytest.approx(0.3)
    assert not list(out.glob("thickness_*.csv")) and not (out / "force_stroke.png").exists()
    assert not [f for f in out.iterdir() if f.name.startswith(".")]


@pytest.mark.timeout(300)
def test_a_disk_without_room_for_the_next_write_stops_before_the_series_is_written(tmp_path, monkeypatch, capsys):
    """After the first checkpoint (0.3 mm) the disk reports 1 MB free (shutil.disk_usage), less
    than the room kept for a write: at the next report (0.6 mm) the run stops before the VTX
    series (ADIOS2, which ends the process on a full disk) is written, with exit 3 and one line,
    the checkpoint at 0.3 mm kept and summary.json written (today: the run went on and wrote)."""
    from shellform.nonlinear import checkpoint
    from shellform.results import cup as cup_results

    saves, series = [], []
    real_save, real_write, real_usage = checkpoint.save, cup_results.CupSeries.write, shutil.disk_usage

    def save(*args, **kwargs):
        path = real_save(*args, **kwargs)
        saves.append(path)
        return path

    def write(self, stroke):
        series.append(stroke)
        return real_write(self, stroke)

    def usage(path):
        real = real_usage(path)
        return real._replace(free=1_000_000) if saves else real

    monkeypatch.setattr(checkpoint, "save", save)
    monkeypatch.setattr(cup_results.CupSeries, "write", write)
    monkeypatch.setattr(shutil, "disk_usage", usage)
    out = tmp_path / "out"
    rc = _run_cup(out, "--set", "output.vtx=true", "--set", "output.vtu=false")
    monkeypatch.undo()
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert rc == 3 and "Traceback" not in captured.err + captured.out
    assert series == [pytest.approx(0.3)] and len(saves) == 1
    assert len(err) == 1 and err[0].startswith("shellform: the run stopped early: disk full at 0.6 mm: 1 MB free "
                                               f"on the disk of {out}, less than the "), err
    assert "kept for the report (" in err[0]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stopped"] == err[0][len("shellform: the run stopped early: "):]
    assert summary["stopped"].endswith(f"the last complete checkpoint, {out / 'checkpoint.npz'} at 0.3 mm, is kept: "
                                       "--resume continues from it once there is room")
    assert [r["stroke_mm"] for r in summary["reports"]] == [pytest.approx(0.3), pytest.approx(0.6)]
    assert float(checkpoint.read(out).arrays["global.lam"]) == pytest.approx(0.3)


FULL_ON_RANK_0 = """
import builtins, errno, sys
sys.path.insert(0, "TESTS")
from mpi4py import MPI
from shellform import cli
from test_checkpoints import ROOT, DISK_CUP
real_open, calls = builtins.open, []

def full_at_the_second_report(file, mode="r", *args, **kwargs):
    if "w" in mode and str(file).split("/")[-1].startswith(".reports.json."):
        calls.append(1)
        if len(calls) == 2:
            raise OSError(errno.ENOSPC, "No space left on device")
    return real_open(file, mode, *args, **kwargs)

builtins.open = full_at_the_second_report
rc = cli.main(["run", str(ROOT / "demos" / "square_cup.toml"), "--out", "OUT", *DISK_CUP, "--set", "output.vtx=false"])
sys.exit(rc)
"""


@pytest.mark.mpi
@pytest.mark.timeout(600)
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
def test_a_full_disk_met_by_rank_0_alone_stops_both_ranks(tmp_path):
    """Under mpiexec -n 2, reports.json (written by rank 0 alone) meets a full disk at the second
    report: both ranks stop there together (the measured write shares its failure), exit 3,
    one stop line, the checkpoint at 0.3 mm kept (before: a failure on rank 0 alone)."""
    out = tmp_path / "out"
    script = tmp_path / "run.py"
    script.write_text(FULL_ON_RANK_0.replace("TESTS", str(Path(__file__).parent)).replace("OUT", str(out)))
    env = dict(os.environ, OMP_NUM_THREADS="1")
    proc = subprocess.run([mpiexec(), "-n", "2", sys.executable, str(script)], capture_output=True, text=True,
                          timeout=300, env=env)
    assert proc.returncode == 3, proc.stderr[-3000:]
    assert "Traceback" not in proc.stderr, proc.stderr[-3000:]
    lines = [ln for ln in proc.stderr.splitlines() if ln.startswith("shellform: ")]
    assert len(lines) == 1 and lines[0].startswith("shellform: the run stopped early: disk full at 0.6 mm: "
                                                   f"{out / 'reports.json'} could not be written"), lines
    summary = json.loads((out / "summary.json").read_text())
    assert summary["ranks"] == 2 and summary["stopped"] == lines[0][len("shellform: the run stopped early: "):]
    assert summary["stopped"].endswith(f"the last complete checkpoint, {out / 'checkpoint.npz'} at 0.3 mm, is kept: "
                                       "--resume continues from it once there is room")


SHEET = strip_scene("strip with a full disk", 4, 1.0e-4, "initial_step = 0.25\nreport = [0.5]",
                    "vtx = true\nvtu = true\npng = false")


@pytest.mark.timeout(120)
@pytest.mark.parametrize("summary_fits", [True, False])
def test_a_sheet_scene_stops_on_a_disk_without_room_with_its_summary(tmp_path, monkeypatch, capsys, summary_fits):
    """A nonlinear sheet scene on a disk with 1 MB free: its first report's series is not
    written; exit 3, one line, summary.json "disk full at load factor 0.5" and that no
    checkpoint was written yet; where summary.json does not fit either (its write raises
    ENOSPC), the one line says so (today: the run wrote on)."""
    import builtins

    scene = tmp_path / "sheet.toml"
    scene.write_text(SHEET)
    real_usage, real_open = shutil.disk_usage, builtins.open

    def no_room_for_the_summary(file, mode="r", *args, **kwargs):
        if "w" in mode and Path(file).name.startswith(".summary.json."):
            _no_space()
        return real_open(file, mode, *args, **kwargs)

    monkeypatch.setattr(shutil, "disk_usage", lambda path: real_usage(path)._replace(free=1_000_000))
    if not summary_fits:
        monkeypatch.setattr(builtins, "open", no_room_for_the_summary)
    out = tmp_path / "out"
    rc = cli.main(["run", str(scene), "--out", str(out)])
    monkeypatch.undo()
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert rc == 3 and "Traceback" not in captured.err + captured.out
    assert len(err) == 1 and err[0].startswith("shellform: the run stopped early: disk full at load factor 0.5: "), err
    assert not [name for name in ("sheet.pvd", "nodal.bp", "increments.csv") if (out / name).exists()]
    if not summary_fits:
        assert err[0].endswith(f"; no checkpoint was written yet; summary.json could not be written "
                               f"({out / 'summary.json'} could not be written (No space left on device))"), err
        assert not (out / "summary.json").exists()
        return
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stopped"].endswith("; no checkpoint was written yet")
    assert [r["load_factor"] for r in summary["reports"]] == [pytest.approx(0.5)]


@pytest.mark.timeout(60)
def test_a_full_disk_before_stepping_is_one_line_and_exit_3(tmp_path, monkeypatch, capsys):
    """run.json meets a full disk (its write raises ENOSPC): one line naming it, exit 3, before
    the scene is meshed (today: an OSError traceback)."""
    import builtins

    _never_meshed(monkeypatch)
    real_open = builtins.open

    def full_for_run_json(file, mode="r", *args, **kwargs):
        if "w" in mode and Path(file).name.startswith(".run.json."):
            _no_space()
        return real_open(file, mode, *args, **kwargs)

    monkeypatch.setattr(builtins, "open", full_for_run_json)
    out = tmp_path / "out"
    rc = cli.main(["run", str(ROOT / "demos" / "square_cup.toml"), "--out", str(out)])
    monkeypatch.undo()
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 3
    assert err == [f"shellform: disk full: {out / 'run.json'} could not be written (No space left on device)"]
    assert not (out / "run.json").exists()


def _never_meshed(monkeypatch):
    """Meshing or solving raises: the --out check must come first."""
    from shellform import linear
    from shellform.contact.problem import DrawingProblem

    def computed(*args, **kwargs):
        raise AssertionError("computed before --out was checked")

    monkeypatch.setattr(DrawingProblem, "from_scene", classmethod(computed))
    monkeypatch.setattr(linear, "solve", computed)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("scene", ["square_plate.toml", "square_cup.toml"])
@pytest.mark.parametrize("where", ["an existing file", "under a file", "read-only", "read-only mount"])
def test_an_unwritable_out_is_an_input_error_before_any_computation(tmp_path, monkeypatch, capsys, scene, where):
    """--out naming a file, or a folder under a file (what fails for root too), or a read-only
    folder (a normal user only: root writes there), or a read-only mount (every write there
    fails with EROFS, for root too: simulated), exits 2 with one line naming --out, before the
    scene is meshed; nothing is written. Today: FileExistsError / NotADirectoryError
    tracebacks, or an ADIOS2 abort after the whole computation."""
    if where == "read-only" and os.geteuid() == 0:
        pytest.skip("root writes into a read-only folder (chmod 555)")
    _never_meshed(monkeypatch)
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder\n")
    out = {"an existing file": blocker, "under a file": blocker / "sub", "read-only": tmp_path / "ro",
           "read-only mount": tmp_path / "mount"}[where]
    if where == "read-only":
        out.mkdir()
        out.chmod(0o555)
    if where == "read-only mount":
        import builtins
        import errno

        out.mkdir()
        real_open = builtins.open

        def read_only(file, mode="r", *args, **kwargs):
            if any(c in mode for c in "wax+") and Path(file).resolve().is_relative_to(out):
                raise OSError(errno.EROFS, "Read-only file system", str(file))
            return real_open(file, mode, *args, **kwargs)

        monkeypatch.setattr(builtins, "open", read_only)
    try:
        rc = cli.main(["run", str(ROOT / "demos" / scene), "--out", str(out)])
    finally:
        if where == "read-only":
            out.chmod(0o755)
    monkeypatch.undo()
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2
    assert err and err[-1].startswith("shellform: input error: --out: ") and str(out) in err[-1]
    assert blocker.read_text() == "not a folder\n"
    if where.startswith("read-only"):
        assert list(out.iterdir()) == []


@pytest.mark.timeout(120)
def test_another_scenes_folder_is_refused_without_resume(tmp_path, capsys):
    """Scene B (another file, other content) run into the folder of scene A's run: exit 2
    naming --out, A's title and A's scene file; A's results stay as they were."""
    a = tmp_path / "a.toml"
    a.write_text((ROOT / "demos" / "square_plate.toml").read_text())
    b = tmp_path / "b.toml"
    b.write_text((ROOT / "demos" / "square_plate.toml").read_text().replace("pressure = 1.0", "pressure = 2.0")
                 .replace('title = "square plate', 'title = "scene B: square plate'))
    out = tmp_path / "out"
    assert cli.main(["run", str(a), "--out", str(out)]) == 0
    before = (out / "summary.json").read_text()
    manifest = json.loads((out / "run.json").read_text())
    assert manifest["scene"] == str(a.resolve()) and manifest["title"].startswith("square plate")
    capsys.readouterr()
    assert cli.main(["run", str(b), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("shellform: input error: --out: ") and str(a.resolve()) in err and "square plate a = 1" in err
    assert (out / "summary.json").read_text() == before
    # the same scene file again (edited or not) starts afresh in its own folder
    assert cli.main(["run", str(a), "--out", str(out)]) == 0


@pytest.mark.timeout(120)
def test_scene_b_killed_in_a_finished_folder_then_resumed_reports_nothing_of_a(tmp_path, whole, monkeypatch):
    """Scene A's finished run in the folder; scene B (another holder force and friction: what a
    resume may change) run into it and killed before its first checkpoint; then --resume: no
    checkpoint of B's is there, so the resume is refused, and none of A's outputs is left to be
    taken for B's. Today: exit 0 and a summary with B's title and A's numbers."""
    out = tmp_path / "out"
    shutil.copytree(whole[0], out)
    b = cup()
    b.title, b.tools.blank_holder_force, b.tools.friction = "scene B", 0.5 * b.tools.blank_holder_force, 0.05

    def killed(self, *args, **kwargs):
        raise Killed

    with monkeypatch.context() as m:
        m.setattr(SemiInverseDriver, "run", killed)
        with pytest.raises(Killed):
            contact_run.run(b, out)
    for name in ("summary.json", "reports.json", "force_stroke.csv", "checkpoint.npz", "checkpoint.previous.npz"):
        assert not (out / name).exists(), name
    with pytest.raises(InputError) as err:
        contact_run.run(b, out, resume=True)
    assert err.value.field == "resume" and "no usable checkpoint" in str(err.value)


@pytest.mark.timeout(120)
def test_a_resume_names_what_differs_and_records_what_changed(tmp_path, whole):
    """Another material (what defines the state) is refused, naming the field; a longer stroke
    and other steps (how to continue) are taken, and the summary records them."""
    out = tmp_path / "out"
    shutil.copytree(whole[0], out)
    other = cup()
    other.material.thickness *= 1.1
    with pytest.raises(InputError) as err:
        contact_run.run(other, out, resume=True)
    assert err.value.field == "resume" and "material.thickness" in str(err.value)
    longer = cup()
    longer.tools.stroke, longer.process.max_step_mm = 1.1, 0.05
    summary = contact_run.run(longer, out, resume=True)
    changed = summary["resumed"]["changed"]
    assert set(changed) == {"tools.stroke", "process.max_step_mm"}
    assert changed["tools.stroke"] == {"checkpoint": 1.0, "now": 1.1}
    assert summary["stroke_mm"] == pytest.approx(1.1)


@pytest.mark.timeout(120)
def test_a_resume_with_a_shorter_stroke_says_so(tmp_path, whole):
    """The checkpoint is at 1 mm; a resume with a stroke of 0.8 mm is refused naming
    tools.stroke and both strokes (today: exit 0, reporting 1 mm as the new scene's)."""
    out = tmp_path / "out"
    shutil.copytree(whole[0], out)
    shorter = cup()
    shorter.tools.stroke = 0.8
    with pytest.raises(InputError) as err:
        contact_run.run(shorter, out, resume=True)
    assert err.value.field == "tools.stroke" and "0.8 mm" in str(err.value) and "1 mm" in str(err.value)


@pytest.mark.timeout(300)
def test_the_counts_after_a_resume_are_the_whole_runs(tmp_path, whole):
    """Killed after the first report and resumed: increments, Newton iterations, contact passes
    and cut-backs count the whole run (the increments before the checkpoint from its saved
    history), the same as the uninterrupted run's; history.json lists them all."""
    killed_after_first_report(tmp_path)
    summary = contact_run.run(cup(), tmp_path, resume=True)
    for key in COUNTS:
        assert summary[key] == whole[1][key], key
    assert summary["resumed"]["increments_before"] > 0
    history = json.loads((tmp_path / "history.json").read_text())
    assert [h["number"] for h in history] == list(range(1, whole[1]["increments"] + 1))


RANKS = """
import json, sys
sys.path.insert(0, "TESTS")
import shellform
from mpi4py import MPI
from plastic_strip import strip_scene
from resume_cup import cup, killed_after_first_report
from shellform.contact import run as contact_run
if "MODE" == "kill":
    killed_after_first_report("OUT")
    out = {}
else:
    s = contact_run.run(cup(), "OUT", resume=True)
    out = {k: s[k] for k in ("increments", "newton_iterations", "reports", "stroke_mm", "resumed_from_stroke_mm")}
if MPI.COMM_WORLD.rank == 0:
    print("RESULT " + json.dumps(out))
"""


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.timeout(600)
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
def test_a_checkpoint_resumes_on_another_number_of_ranks(tmp_path, whole):
    """The cup checkpointed on 1 rank resumes on 2, and checkpointed on 2 resumes on 1: each
    ends where the uninterrupted serial run ends, to the solver tolerance (today: refused,
    one file per rank)."""
    from test_mpi import on_two_ranks

    def script(mode, out):
        return RANKS.replace("TESTS", str(Path(__file__).parent)).replace("MODE", mode).replace("OUT", str(out))

    killed_after_first_report(tmp_path / "one")
    two = on_two_ranks(tmp_path, script("resume", tmp_path / "one"))
    on_two_ranks(tmp_path, script("kill", tmp_path / "two"))
    one = contact_run.run(cup(), tmp_path / "two", resume=True)
    for summary in (two, one):
        assert summary["resumed_from_stroke_mm"] == pytest.approx(0.5)
        assert summary["increments"] == whole[1]["increments"]
        assert_same_end(summary, whole[1], rel=1e-6)


def _files(folder: Path, names) -> dict:
    return {name: (folder / name).read_bytes() for name in names if (folder / name).exists()}


@pytest.mark.timeout(120)
def test_another_holder_force_or_friction_is_refused_on_a_resume(tmp_path, whole):
    """Scene B (another title, holder force and friction) resumed in scene A's finished folder:
    refused naming tools.blank_holder_force and tools.friction, nothing written (today: exit 0,
    A's forces and draw-in under B's title). The same from a checkpoint half-way (0.5 mm): the
    holder and friction act from the first increment, so a run with other ones is another run."""
    out = tmp_path / "out"
    shutil.copytree(whole[0], out)
    before = _files(out, sorted(p.name for p in out.iterdir() if p.is_file()))
    b = cup()
    b.title, b.tools.blank_holder_force, b.tools.friction = "scene B", 0.5 * b.tools.blank_holder_force, 0.05
    with pytest.raises(InputError) as err:
        contact_run.run(b, out, resume=True)
    assert err.value.field == "tools.blank_holder_force"
    assert "tools.friction" in str(err.value) and "checkpoint" in str(err.value)
    assert _files(out, before) == before
    (out / "checkpoint.npz").unlink()  # the resume takes checkpoint.previous.npz, at 0.5 mm
    c = cup()
    c.tools.friction = 0.05
    with pytest.raises(InputError) as err:
        contact_run.run(c, out, resume=True)
    assert err.value.field == "tools.friction" and "0.5 mm" in str(err.value)


@pytest.mark.timeout(180)
@pytest.mark.parametrize("tool", ["punch", "die", "holder"])
def test_another_friction_of_one_tool_is_refused_on_a_resume(tmp_path, whole, tool):
    """A tool's own coefficient (tools.punch_friction, die_friction, holder_friction) acts from
    the first increment as tools.friction does: resumed from the checkpoint at 0.5 mm with the
    punch lubricated (0.05, the others 0.1), or the die or the holder, the run is refused naming
    that key; nothing is drawn. The summary records the coefficients the tools carried."""
    assert whole[1]["friction"] == {"punch": 0.1, "die": 0.1, "holder": 0.1}
    out = tmp_path / "out"
    shutil.copytree(whole[0], out)
    (out / "checkpoint.npz").unlink()  # the resume takes checkpoint.previous.npz, at 0.5 mm
    c = cup().changed({f"tools.{tool}_friction": 0.05})
    with pytest.raises(InputError) as err:
        contact_run.run(c, out, resume=True)
    assert err.value.field == f"tools.{tool}_friction" and "0.5 mm" in str(err.value)
    assert "None there, 0.05 now" in str(err.value)


def fld_cup():
    """cup() with the forming-limit view and the pictures: fld.csv, strain_path.csv, fld.png,
    cup.png, cup_margin.png."""
    return cup().changed({"output.fld": True, "output.png": True})


@pytest.fixture(scope="module")
def drawn(tmp_path_factory):
    """fld_cup() run uninterrupted: (its folder, its summary)."""
    out = tmp_path_factory.mktemp("drawn")
    return out, contact_run.run(fld_cup(), out)


RESULTS = ("fld.csv", "strain_path.csv", "thickness_diagonal.csv", "thickness_transverse.csv", "force_stroke.csv",
           "reports.json")


@pytest.mark.timeout(300)
def test_a_resume_with_nothing_to_do_rewrites_the_same_results(tmp_path, drawn):
    """A finished run resumed at its checkpoint's own stroke: the tables it writes again are
    those it had (today: fld.csv with zero strains, min_margin 0.35 instead of 0.29 on the
    paper's cup, strain_path.csv and summary.json's strain_path gone), and so is what
    summary.json says of the drawn cup."""
    out = tmp_path / "out"
    shutil.copytree(drawn[0], out)
    before = _files(out, RESULTS)
    assert set(before) == set(RESULTS)
    summary = contact_run.run(fld_cup(), out, resume=True)
    assert summary["resumed_from_stroke_mm"] == pytest.approx(1.0)
    assert _files(out, RESULTS) == before
    keys = ("reports", "min_margin", "min_margin_at_initial_xy_mm", "strain_path", "min_thickness_strain",
            "volume_change", "increments", "newton_iterations", "forming_limit", "stroke_mm")
    assert {k: summary[k] for k in keys} == {k: drawn[1][k] for k in keys}


@pytest.mark.timeout(400)
def test_a_resume_keeps_the_strain_path(tmp_path, drawn):
    """fld_cup() killed at a timed checkpoint between two increments (the third: checkpoints at
    every increment), then resumed: strain_path.csv holds the uninterrupted run's whole path,
    every point of it (today: the points from the resumed stroke on only)."""
    scene = fld_cup().changed({"output.checkpoint_every": 1e-9})
    killed_after_first_report(tmp_path, scene, saves=3)
    saved = (tmp_path / "strain_path.csv").exists()
    summary = contact_run.run(scene, tmp_path, resume=True)
    assert not saved and 0 < summary["resumed_from_stroke_mm"] < 0.5
    assert (tmp_path / "strain_path.csv").read_text() == (drawn[0] / "strain_path.csv").read_text()
    assert summary["strain_path"] == drawn[1]["strain_path"]


@pytest.mark.timeout(300)
def test_a_resume_does_not_write_through_links_in_out(tmp_path, drawn):
    """Links planted in a finished run's folder with the names of its outputs (pictures,
    tables, the summary, the VTU series and its folder), each to a file or folder elsewhere:
    --resume removes them and writes its own files, and nothing where they pointed changes
    (today: force_stroke.png, cup.png, fld.png and cup_margin.png written through)."""
    out = tmp_path / "out"
    shutil.copytree(drawn[0], out)
    elsewhere = tmp_path / "elsewhere"
    (elsewhere / "folder").mkdir(parents=True)
    written = ("force_stroke.png", "cup.png", "fld.png", "cup_margin.png", "thickness.png", "summary.json",
               "fld.csv", "strain_path.csv")
    kept = ("history.json", "cup.pvd")  # a resume with nothing to do writes these not
    for name in written + kept:
        (out / name).unlink()
        (elsewhere / f"{name}.kept").write_text("not shellform's\n")
        (out / name).symlink_to(elsewhere / f"{name}.kept")
    shutil.rmtree(out / "vtu")
    (out / "vtu").symlink_to(elsewhere / "folder", target_is_directory=True)
    contact_run.run(fld_cup(), out, resume=True)
    for name in written + kept:
        assert (elsewhere / f"{name}.kept").read_text() == "not shellform's\n", name
        assert not (out / name).is_symlink(), name
    for name in written:
        assert (out / name).stat().st_size > 0, name
    assert list((elsewhere / "folder").iterdir()) == []
    assert not (out / "vtu").is_symlink()


@pytest.mark.timeout(200)
@pytest.mark.parametrize("damage", ["reports.json", "force_stroke.csv", "rows cut", "global cut", "too large",
                                    "a header that lies"])
def test_a_damaged_file_of_a_resume_is_named_in_one_line(tmp_path, whole, damage):
    """--resume in a finished folder whose reports.json is not JSON, whose force_stroke.csv has
    a row that is not numbers, or whose checkpoints have their arrays cut (every per-node array
    but the numbers half its rows; the tools' travel empty), hold an array larger than the
    state of the run's mesh can be (a 1.6 GiB member took 5 GB of memory to load), or an array
    whose .npy header claims 80 GB in a few bytes (numpy would allocate them before reading):
    exit 2 with one line naming the file, and nothing too large is loaded."""
    out = tmp_path / "out"
    shutil.copytree(whole[0], out)
    if damage == "reports.json":
        (out / "reports.json").write_text('[{"stroke_mm": 0.5, ')
    elif damage == "force_stroke.csv":
        (out / "force_stroke.csv").write_text((out / "force_stroke.csv").read_text() + "13,abc\n")
    else:
        for name in ("checkpoint.npz", "checkpoint.previous.npz"):
            with np.load(out / name) as data:
                arrays = {k: data[k] for k in data.files}
            for k in arrays:
                if damage == "rows cut" and k.startswith("nodes.") and k != "nodes.index":
                    arrays[k] = arrays[k][: len(arrays[k]) // 2]
            if damage == "global cut":
                arrays["global.contact_travel"] = arrays["global.contact_travel"][:0]
            if damage == "too large":  # 2,000 times the cells' state, in each row
                k = next(k for k in arrays if k.startswith("cells.") and k != "cells.index")
                arrays[k] = np.zeros((len(arrays[k]), 2000) + arrays[k].shape[1:])
            np.savez(out / name, **arrays)
            if damage == "a header that lies":
                header = np.lib.format.header_data_from_array_1_0(np.zeros(1))
                header["shape"] = (10**10,)
                member = io.BytesIO()
                np.lib.format.write_array_header_1_0(member, header)
                with zipfile.ZipFile(out / name, "a") as z:
                    z.writestr("nodes.lie.npy", member.getvalue() + bytes(8))
    with pytest.raises(InputError) as err:
        contact_run.run(cup(), out, resume=True)
    named = {"reports.json": "reports.json", "force_stroke.csv": "force_stroke.csv"}.get(damage, "checkpoint")
    assert err.value.field == "resume" and named in str(err.value) and "damaged" in str(err.value)
    why = {"too large": "more than the state of this run's mesh can", "a header that lies": "claims 80,000,000,000 bytes"}
    assert why.get(damage, "") in str(err.value)
