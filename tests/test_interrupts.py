"""Ctrl-C and SIGTERM stop a run at its last converged increment: that state is on disk, the
summary says who stopped it and where, and the exit status is 128 + the signal's number."""

import json
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from plastic_strip import strip_scene

from shellform.studies.common import mpiexec

STRIP = strip_scene("strip stepped slowly", 8, 2.0e-4, "initial_step = 0.002\nmax_step = 0.002", "vtx = false\npng = false")


def interrupted_run(tmp_path: Path, scene_text: str, signum: int, after: int, name="scene.toml", ranks=1):
    """Run `shellform run` in a child process (under mpiexec with ranks > 1), send it `signum`
    once it has printed `after` converged increments; (exit status, its stderr, the increment
    lines it printed, --out)."""
    scene = tmp_path / name
    scene.write_text(scene_text)
    out = tmp_path / "out"
    cmd = [str(Path(sys.executable).parent / "shellform"), "run", str(scene), "--out", str(out)]
    if ranks > 1:
        cmd = [mpiexec(), "-n", str(ranks), *cmd]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines = []
    for line in proc.stdout:
        if line.startswith("increment"):
            lines.append(line)
            if len(lines) == after:
                proc.send_signal(signum)
                break
    rest = proc.stdout.read()  # what the iteration above has buffered too
    err = proc.stderr.read()
    proc.wait(timeout=120)
    lines += [ln for ln in rest.splitlines() if ln.startswith("increment")]
    return proc.returncode, err, lines, out


@pytest.mark.timeout(300)
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_stops_a_load_stepped_run_at_its_last_converged_increment(tmp_path, signum):
    """SIGINT or SIGTERM a few increments into a 100-increment run: exit 128 + signal, one line
    naming who stopped it, summary.json marked and reporting the last converged increment
    (the last one printed), and that state on disk."""
    code, err, lines, out = interrupted_run(tmp_path, STRIP, signum, after=3)
    name = signal.Signals(signum).name
    assert code == 128 + signum, err
    assert f"stopped by the user ({name}) at load factor" in err and "Traceback" not in err, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["signal"] == signum and summary["stopped"].startswith(f"stopped by the user ({name})")
    last = float(lines[-1].split("lambda")[1].split()[0])
    assert 3 <= summary["increments"] == len(lines) < 100
    assert summary["reports"][-1]["load_factor"] == pytest.approx(last, rel=1e-9)
    assert (out / "checkpoint.npz").exists()


@pytest.mark.mpi
@pytest.mark.timeout(300)
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
def test_ctrl_c_to_mpiexec_stops_every_rank_at_the_same_increment(tmp_path):
    """Ctrl-C to mpiexec -n 2 (which passes it on to the ranks): both ranks stop after the same
    increment, and the run says so once."""
    code, err, lines, out = interrupted_run(tmp_path, STRIP, signal.SIGINT, after=3, ranks=2)
    assert code == 130, err
    assert err.count("stopped by the user (SIGINT)") == 1 and "Traceback" not in err, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["ranks"] == 2 and summary["increments"] == len(lines) >= 3


def small_cup(every: float = 60.0) -> str:
    """demos/square_cup.toml on 6 x 6, 1 mm of stroke in 0.05 to 0.1 mm steps, a report at
    0.5 mm, no pictures (the cup of tests/resume_cup.py), as a scene file's text."""
    text = (Path(__file__).resolve().parents[1] / "demos" / "square_cup.toml").read_text()
    for old, new in (("[mesh]\nn = 16", "[mesh]\nn = 6"), ("stroke = 30.0", "stroke = 1.0"),
                     ("initial_step_mm = 0.06", "initial_step_mm = 0.05"), ("max_step_mm = 0.24", "max_step_mm = 0.1"),
                     ("springback = true", "springback = false")):
        assert old in text
        text = text.replace(old, new)
    return text + f"\n[output]\nvtx = false\npng = false\nfld = false\ncheckpoint_every = {every}\n"


def run_cli(*args) -> subprocess.CompletedProcess:
    return subprocess.run([str(Path(sys.executable).parent / "shellform"), "run", *map(str, args)],
                          capture_output=True, text=True, timeout=300)


@pytest.mark.slow
@pytest.mark.timeout(600)
def test_ctrl_c_mid_stroke_then_resume_equals_the_uninterrupted_draw(tmp_path):
    """SIGINT half-way through a cup's stroke (between two reports): exit 130, a summary marked
    'stopped by the user (SIGINT) at S mm', and --resume from that state ends where the
    uninterrupted run ends (the same increments, punch force, draw-in and thinning to 1e-9):
    the checkpoint carries how the next increment starts (its step, the predictor's last state
    and the contact's normal forces before it)."""
    (tmp_path / "scene.toml").write_text(small_cup())
    whole = run_cli(tmp_path / "scene.toml", "--out", tmp_path / "whole")
    assert whole.returncode == 0, whole.stderr
    done = json.loads((tmp_path / "whole" / "summary.json").read_text())
    (tmp_path / "cut").mkdir()
    code, err, lines, out = interrupted_run(tmp_path / "cut", small_cup(), signal.SIGINT,
                                            after=done["increments"] // 2 + 1)
    assert code == 130 and "stopped by the user (SIGINT) at" in err, err
    stopped = json.loads((out / "summary.json").read_text())
    assert 0.5 < stopped["stroke_mm"] < 1.0 and stopped["signal"] == signal.SIGINT
    resumed = run_cli(tmp_path / "cut" / "scene.toml", "--out", out, "--resume")
    assert resumed.returncode == 0, resumed.stderr
    again = json.loads((out / "summary.json").read_text())
    assert again["resumed"]["from_stroke_mm"] == pytest.approx(stopped["stroke_mm"], rel=1e-12)
    assert again["increments"] == done["increments"] and again["stroke_mm"] == pytest.approx(1.0)
    for key in ("newton_iterations", "cutbacks"):
        assert again[key] == done[key]
    a, b = done["reports"][-1], again["reports"][-1]
    assert b["punch_force_kN"] == pytest.approx(a["punch_force_kN"], rel=1e-9)
    for k in ("DX", "DD"):
        assert b["draw_in_mm"][k] == pytest.approx(a["draw_in_mm"][k], rel=1e-9, abs=1e-12)
    assert b["min_thickness_strain"] == pytest.approx(a["min_thickness_strain"], rel=1e-9)
    assert len(again["reports"]) == len(done["reports"])


@pytest.mark.slow
@pytest.mark.timeout(600)
def test_a_killed_run_resumes_from_its_last_timed_checkpoint(tmp_path):
    """output.checkpoint_every writes the last converged increment between reports: a run
    killed outright (SIGKILL, nothing handled) half-way between two reports resumes from an
    increment past the last report, and ends where the uninterrupted run ends with the same
    force-stroke curve."""
    import csv

    (tmp_path / "scene.toml").write_text(small_cup())
    whole = run_cli(tmp_path / "scene.toml", "--out", tmp_path / "whole")
    assert whole.returncode == 0, whole.stderr
    done = json.loads((tmp_path / "whole" / "summary.json").read_text())
    (tmp_path / "cut").mkdir()
    code, err, lines, out = interrupted_run(tmp_path / "cut", small_cup(every=1e-9), signal.SIGKILL,
                                            after=done["increments"] // 2 + 2)
    assert code == -signal.SIGKILL
    resumed = run_cli(tmp_path / "cut" / "scene.toml", "--out", out, "--resume")
    assert resumed.returncode == 0, resumed.stderr
    again = json.loads((out / "summary.json").read_text())
    assert 0.5 < again["resumed"]["from_stroke_mm"] < 1.0
    assert again["increments"] == done["increments"]
    assert again["reports"][-1]["punch_force_kN"] == pytest.approx(done["reports"][-1]["punch_force_kN"], rel=1e-9)
    rows = [list(csv.DictReader(open(d / "force_stroke.csv"))) for d in (tmp_path / "whole", out)]
    assert [r["stroke_mm"] for r in rows[1]] == [r["stroke_mm"] for r in rows[0]]
    assert float(rows[1][-1]["punch_force_kN"]) == pytest.approx(float(rows[0][-1]["punch_force_kN"]), rel=1e-9)


@pytest.mark.timeout(600)
def test_a_resume_with_other_steps_starts_them_afresh(tmp_path):
    """Stopped half-way between reports and resumed with another initial_step: the first resumed
    increment takes the new step (not the one the checkpoint had grown to), and the run ends."""
    (tmp_path / "cut").mkdir()
    code, err, lines, out = interrupted_run(tmp_path / "cut", small_cup(), signal.SIGINT, after=7)
    assert code == 130, err
    before = json.loads((out / "summary.json").read_text())["increments"]
    other = small_cup().replace("initial_step_mm = 0.05", "initial_step_mm = 0.01")
    (tmp_path / "cut" / "scene.toml").write_text(other)
    resumed = run_cli(tmp_path / "cut" / "scene.toml", "--out", out, "--resume")
    assert resumed.returncode == 0, resumed.stderr
    again = json.loads((out / "summary.json").read_text())
    history = json.loads((out / "history.json").read_text())
    assert "process.initial_step_mm" in again["resumed"]["changed"]
    assert history[before]["dlam"] == pytest.approx(0.01, rel=1e-12) and again["stroke_mm"] == pytest.approx(1.0)


@pytest.mark.timeout(300)
def test_sigterm_before_stepping_exits_143_with_one_line(tmp_path):
    """SIGTERM before the first increment (once the run has said its first line, PETSc running):
    exit 143 and shellform's one line, not PETSc's "Caught signal" banner and exit 15
    (PETSc's own signal handler is off: shellform._env)."""
    scene = tmp_path / "scene.toml"
    scene.write_text(STRIP)
    cmd = [str(Path(sys.executable).parent / "shellform"), "run", str(scene), "--out", str(tmp_path / "out")]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    proc.stdout.readline()  # the material's line: the stack is imported, nothing stepped
    proc.send_signal(signal.SIGTERM)
    proc.stdout.read()
    err = proc.stderr.read()
    proc.wait(timeout=120)
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert "Caught signal" not in err and "Traceback" not in err, err
    assert err.strip().splitlines()[-1].startswith("shellform: "), err
