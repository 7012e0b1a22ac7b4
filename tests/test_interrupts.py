"""Ctrl-C and SIGTERM stop a run at its last converged increment: that state is on disk, the
summary says who stopped it and where, and the exit status is 128 + the signal's number."""

import json
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from shellform.studies.common import mpiexec

STRIP = """title = "strip stepped slowly"
effects = ["bending", "membrane", "plasticity"]
[geometry]
lx = 1.0
ly = 0.125
[mesh]
n = 8
[material]
E = 1000.0
nu = 0.3
thickness = 0.02
hardening = "swift"
K = 1.0
eps0 = 1.0
n = 0.0
[supports]
left = "clamped"
top = "symmetry"
bottom = "symmetry"
[loads]
pressure = 2.0e-4
[process]
initial_step = 0.002
max_step = 0.002
[output]
vtx = false
png = false
"""


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
