"""Two MPI ranks give the serial results to 1e-10 (plate and shell, unstructured meshes)."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from shellform import linear
from shellform.studies import plate, shell

SCRIPT = """
import json, shellform
from mpi4py import MPI
from shellform import linear
from shellform.studies import plate, shell
w_plate = linear.solve(plate.scene("clamped", "unstructured", 4, refine=2)).value("w")
w_shell = linear.solve(shell.scene(5.0, 3, "unstructured", refine=2)).value("w")
if MPI.COMM_WORLD.rank == 0:
    print("RESULT " + json.dumps({"plate": w_plate, "shell": w_shell}))
"""


def mpiexec():
    local = Path(sys.executable).parent / "mpiexec"
    return str(local) if local.exists() else shutil.which("mpiexec")


def on_two_ranks(tmp_path, source) -> dict:
    """Run a script on 2 MPI ranks; the dictionary it prints after RESULT on rank 0."""
    script = tmp_path / "run.py"
    script.write_text(source)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    out = subprocess.run([mpiexec(), "-n", "2", sys.executable, str(script)], capture_output=True,
                         text=True, timeout=600, env=env)
    assert out.returncode == 0, out.stderr[-2000:]
    line = [ln for ln in out.stdout.splitlines() if ln.startswith("RESULT ")][-1]
    return json.loads(line[len("RESULT "):])


@pytest.mark.mpi
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
def test_two_ranks_match_serial(tmp_path):
    parallel = on_two_ranks(tmp_path, SCRIPT)
    serial_plate = linear.solve(plate.scene("clamped", "unstructured", 4, refine=2)).value("w")
    serial_shell = linear.solve(shell.scene(5.0, 3, "unstructured", refine=2)).value("w")
    assert parallel["plate"] == pytest.approx(serial_plate, rel=1e-10)
    assert parallel["shell"] == pytest.approx(serial_shell, rel=1e-10)


NONLINEAR = """
import json, shellform
from mpi4py import MPI
from shellform.studies import levy, plastic
w = levy.solve(8, loads=[95.0])[-1]["w_over_h"]
row = plastic.solve(8, 5)
if MPI.COMM_WORLD.rank == 0:
    print("RESULT " + json.dumps({"levy": w, "plastic": row["P_max_over_PL"]}))
"""


@pytest.mark.mpi
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
def test_nonlinear_two_ranks_match_serial(tmp_path):
    """Newton with plasticity on two ranks: the same answer to the solver tolerance."""
    from shellform.studies import levy, plastic

    parallel = on_two_ranks(tmp_path, NONLINEAR)
    assert parallel["levy"] == pytest.approx(levy.solve(8, loads=[95.0])[-1]["w_over_h"], rel=1e-8)
    assert parallel["plastic"] == pytest.approx(plastic.solve(8, 5)["P_max_over_PL"], rel=1e-8)
