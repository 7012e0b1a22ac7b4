"""Ctrl-C and SIGTERM stop a run at its last converged increment: that state is on disk, the
summary says who stopped it and where, and the exit status is 128 + the signal's number."""

import json
import signal
import subprocess
import sys
from pathlib import Path

import pytest

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


def interrupted_run(tmp_path: Path, scene_text: str, signum: int, after: int, name="scene.toml"):
    """Run `shellform run` in a child process, send it `signum` once it has printed `after`
    converged increments; (the finished process, the increment lines it printed, --out)."""
    scene = tmp_path / name
    scene.write_text(scene_text)
    out = tmp_path / "out"
    cmd = [str(Path(sys.executable).parent / "shellform"), "run", str(scene), "--out", str(out)]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines = []
    for line in proc.stdout:
        if line.startswith("increment"):
            lines.append(line)
            if len(lines) == after:
                proc.send_signal(signum)
                break
    rest, err = proc.communicate(timeout=120)
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
    assert list(out.glob("last_converged*"))
