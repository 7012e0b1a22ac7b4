"""Two MPI ranks give the serial results to 1e-10 (plate and shell, unstructured meshes)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from shellform import linear
from shellform.studies import plate, shell
from shellform.studies.common import mpiexec

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
from shellform.studies import levy, plastic, rollup
w = levy.solve(8, loads=[95.0])[-1]["w_over_h"]
row = plastic.solve(8, 5)
roll = rollup.solve(16, thickness=1e-3, assumed_membrane=True)["errors"]
if MPI.COMM_WORLD.rank == 0:
    print("RESULT " + json.dumps({"levy": w, "plastic": row["P_max_over_PL"], "layers": row["plastic_layers"],
                                  "rollup": roll}))
"""


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
def test_nonlinear_two_ranks_match_serial(tmp_path):
    """Newton with plasticity, and the thin roll-up with the assumed membrane strain (one beta
    from the whole mesh), on two ranks: the same answers to the solver tolerance, and the same
    count of plastic layers (the evaluation's counts are global: every rank takes the same
    branch on a failed material update)."""
    from shellform.studies import levy, plastic, rollup

    parallel = on_two_ranks(tmp_path, NONLINEAR)
    assert parallel["levy"] == pytest.approx(levy.solve(8, loads=[95.0])[-1]["w_over_h"], rel=1e-8)
    serial_plastic = plastic.solve(8, 5)
    assert parallel["plastic"] == pytest.approx(serial_plastic["P_max_over_PL"], rel=1e-8)
    assert parallel["layers"] == serial_plastic["plastic_layers"] > 0
    serial = rollup.solve(16, thickness=1e-3, assumed_membrane=True)["errors"]
    assert parallel["rollup"] == pytest.approx(serial, rel=1e-6)


CUP = """
import json, shellform
from mpi4py import MPI
from shellform import scene
from shellform.contact.problem import DrawingProblem
from shellform.results.cup import draw_in, peak_thinning
s = scene.load("demos/square_cup.toml")
s.mesh.n = 8
s.tools.blank_holder_force = BHF
p = DrawingProblem.from_scene(s, verbose=False)
p.driver.run(1.5 / s.tools.stroke)
out = {"force": p.punch_force(), "DD": draw_in(p)["DD"], "e33": peak_thinning(p)["min_thickness_strain"],
       "holder": p.holder_force(), "pinched": p.in_contact()["pinched"], "on_holder": p.in_contact()["holder"],
       "lift": p.holder_lift(), "increments": len(p.driver.history), "symbolic": p.driver.free_lu.symbolic}
if MPI.COMM_WORLD.rank == 0:
    print("RESULT " + json.dumps(out))
"""


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
@pytest.mark.parametrize("bhf", [19600.0, 400.0])
def test_short_cup_two_ranks_match_serial(tmp_path, bhf):
    """The square cup (8 x 8 quarter blank, friction and the holder) drawn 1.5 mm on two ranks:
    the same punch force, draw-in and thinning as serial to the solver tolerance, the same
    contact set and increments; with the scene's 19.6 kN holder (closed, pinching; the free
    rows factorised) and a 400 N one that the flange lifts (open, its lift solved with the
    sheet)."""
    import runpy

    root = Path(__file__).resolve().parents[1]
    source = CUP.replace("demos/", f"{root}/demos/").replace("BHF", repr(bhf))
    parallel = on_two_ranks(tmp_path, source)
    serial = {}
    source = source.replace('print("RESULT " + json.dumps(out))', "RESULT.update(out)")
    runpy.run_path(_write(tmp_path / "serial.py", source), init_globals={"RESULT": serial})
    for key in ("increments", "pinched", "on_holder"):
        assert parallel[key] == serial[key], key
    assert (serial["on_holder"] > 0) == (bhf < 1000)  # the light holder is open
    if bhf > 1000:  # the pinched flange: the free rows were factorised, on both ranks together
        assert parallel["symbolic"] > 0 and serial["symbolic"] > 0
    for key in ("force", "DD", "e33", "holder", "lift"):
        assert parallel[key] == pytest.approx(serial[key], rel=1e-6, abs=1e-9), key


def _write(path, text):
    path.write_text(text)
    return str(path)


RESUME = """
import json, sys
sys.path.insert(0, "TESTS")
import shellform
from mpi4py import MPI
from resume_cup import cup, killed_after_first_report
from shellform.contact import run as contact_run

killed_after_first_report("OUT")
r = contact_run.run(cup(), "OUT", resume=True)["reports"][-1]
if MPI.COMM_WORLD.rank == 0:
    print("RESULT " + json.dumps({"force": r["punch_force_kN"], "DD": r["draw_in_mm"]["DD"],
                                  "e33": r["min_thickness_strain"]}))
"""


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
def test_resumed_cup_on_two_ranks_matches_serial(tmp_path):
    """A cup killed after its first report on two ranks and resumed there ends where the serial
    uninterrupted run ends, to the solver tolerance."""
    from resume_cup import cup

    from shellform.contact import run as contact_run

    source = RESUME.replace("TESTS", str(Path(__file__).parent)).replace("OUT", str(tmp_path / "pieces"))
    parallel = on_two_ranks(tmp_path, source)
    r = contact_run.run(cup(), tmp_path / "whole")["reports"][-1]
    assert parallel["force"] == pytest.approx(r["punch_force_kN"], rel=1e-6)
    assert parallel["DD"] == pytest.approx(r["draw_in_mm"]["DD"], rel=1e-6, abs=1e-9)
    assert parallel["e33"] == pytest.approx(r["min_thickness_strain"], rel=1e-6)


OUTLINES = """
import json, shellform
from mpi4py import MPI
from shellform import linear, scene
w = {name: linear.solve(scene.load("demos/" + name + ".toml")).value("w")
     for name in ("circular_plate", "triangle_plate")}
from shellform.studies.outlines import clamped_disc
w["clamped_disc"] = clamped_disc("quarter", 8, 1.488)[0]
if MPI.COMM_WORLD.rank == 0:
    print("RESULT " + json.dumps(w))
"""


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
def test_curved_and_oblique_supports_on_two_ranks_match_serial(tmp_path, monkeypatch):
    """The edge frames (rim vertex normals summed over ranks, R^T K R in PETSc's parallel
    layout; the nonlinear sheet's turned element arrays) give the serial deflections of the
    circular and triangular plates and of the large-deflection clamped disc to 1e-10."""
    from shellform import scene

    root = Path(__file__).resolve().parents[1]
    monkeypatch.chdir(root)
    parallel = on_two_ranks(tmp_path, OUTLINES)
    from shellform.studies.outlines import clamped_disc

    assert parallel.pop("clamped_disc") == pytest.approx(clamped_disc("quarter", 8, 1.488)[0], rel=1e-10)
    for name, w in parallel.items():
        serial = linear.solve(scene.load(root / "demos" / f"{name}.toml")).value("w")
        assert w == pytest.approx(serial, rel=1e-10), name


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
def test_two_ranks_say_each_line_once(tmp_path):
    """Under mpiexec -n 2 the closing line of a run and an input error are printed once (by
    rank 0), not once per rank."""
    shellform_cmd = str(Path(sys.executable).parent / "shellform")
    env = dict(os.environ, OMP_NUM_THREADS="1")
    good = tmp_path / "good.toml"
    good.write_text('title = "once"\n[mesh]\nn = 4\n[supports]\nleft = "clamped"\n[loads]\npressure = 1.0\n'
                    '[output]\nvtx = false\npng = false\n')
    bad = tmp_path / "bad.toml"
    bad.write_text("[material]\nthickness = -1.0\n")
    runs = {name: subprocess.run([mpiexec(), "-n", "2", shellform_cmd, "run", str(path), "--out", str(tmp_path / name)],
                                 capture_output=True, text=True, timeout=300, env=env)
            for name, path in (("good", good), ("bad", bad))}
    assert runs["good"].returncode == 0, runs["good"].stderr[-2000:]
    assert runs["good"].stdout.count("shellform: once:") == 1, runs["good"].stdout
    assert runs["bad"].returncode == 2
    assert runs["bad"].stderr.count("shellform: input error: material.thickness") == 1, runs["bad"].stderr


BEADS = """
import json, sys
sys.path.insert(0, "TESTS")
import shellform
from mpi4py import MPI
from test_drawbead import SIDES, _cup
from shellform.contact import run as contact_run
r = contact_run.run(_cup(SIDES), "OUT")
if MPI.COMM_WORLD.rank == 0:
    print("RESULT " + json.dumps({"force": r["reports"][-1]["punch_force_kN"], "DX": r["reports"][-1]["draw_in_mm"]["DX"],
                                  "increments": r["increments"], "balance": r["over_the_stroke"]["force_balance"]}))
"""


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
def test_drawbeads_on_two_ranks_match_serial(tmp_path):
    """The drawbead cup of tests/test_drawbead.py on two ranks: the beads' line shared out
    across the ranks' cells gives the serial punch force and draw-in to the solver tolerance."""
    import sys

    tests = str(Path(__file__).parent)
    sys.path.insert(0, tests)
    from test_drawbead import SIDES, _cup

    from shellform.contact import run as contact_run

    parallel = on_two_ranks(tmp_path, BEADS.replace("TESTS", tests).replace("OUT", str(tmp_path / "two")))
    serial = contact_run.run(_cup(SIDES), tmp_path / "one")
    assert parallel["increments"] == serial["increments"] and parallel["balance"] <= 1e-6
    assert parallel["force"] == pytest.approx(serial["reports"][-1]["punch_force_kN"], rel=1e-6)
    assert parallel["DX"] == pytest.approx(serial["reports"][-1]["draw_in_mm"]["DX"], rel=1e-6)


SENSITIVITY = """
import shellform, json
from mpi4py import MPI
from shellform.run import run
from shellform.studies.sensitivity import cantilever_scene
summary = run(cantilever_scene(True).changed({{"mesh.n": 16}}), {out!r})
if MPI.COMM_WORLD.rank == 0:
    print("RESULT " + json.dumps(summary["reports"][-1]["sensitivities"]))
"""


@pytest.mark.mpi
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
def test_sensitivities_on_two_ranks_match_serial(tmp_path):
    """The cantilever's sensitivities (nonlinear/sensitivity.py) on 2 ranks equal one rank's to
    1e-7 of each answer's largest derivative (the solver's tolerance)."""
    from shellform.run import run
    from shellform.studies.sensitivity import cantilever_scene

    serial = run(cantilever_scene(True).changed({"mesh.n": 16}), tmp_path / "one")["reports"][-1]["sensitivities"]
    two = on_two_ranks(tmp_path, SENSITIVITY.format(out=str(tmp_path / "two")))
    for name, answers in serial.items():
        scale = max(abs(v) for v in answers.values())
        for answer, value in answers.items():
            assert abs(two[name][answer] - value) <= 1e-7 * scale, (name, answer)


SENSITIVITIES = """
import json
import shellform
from mpi4py import MPI
from shellform.contact.run import run
from shellform.studies.sensitivity import drawn_cup

s, _ = drawn_cup(CHANGES, scene_only=True, friction=True, n=8, holder=HOLDER)
s = s.changed({"output.sensitivities": PARAMETERS, "output.png": False, "output.vtx": False, "output.fld": False})
summary = run(s, "OUT")
if MPI.COMM_WORLD.rank == 0:
    print("RESULT " + json.dumps({"iterations": summary["newton_iterations"],
                                  "sensitivities": summary["reports"][-1]["sensitivities"]}))
"""


@pytest.mark.slow
@pytest.mark.mpi
@pytest.mark.skipif(mpiexec() is None, reason="no mpiexec")
@pytest.mark.parametrize("holder, parameters, changes, extra_iterations", [
    (False, ["tools.friction", "material.K"], None, 0),
    (True, ["tools.blank_holder_force", "material.K"], None, 0),
    (True, ["tools.blank_holder_force", "material.K"], {"tools.blank_holder_force": 300.0}, 2),
])
def test_a_cups_sensitivities_on_two_ranks_match_serial(tmp_path, holder, parameters, changes, extra_iterations):
    """The round cup with friction (n 8, 3 mm), without and with its holder (10 kN, closed; 300 N,
    open: its lift's derivative, Part.border_derivative), and its sensitivities on two ranks: the
    same Newton iterations as serial (friction's normal-force tangent gathers a node's cells from
    every rank: a ghost node's rows go to its owner; the open holder's run takes 130 against
    128, the lift's bordered solve in another order of round-off) and the same derivatives of
    every answer to 1e-6 (measured 1e-7 without the holder; with it 125 iterations on both and
    7e-9; open, 6e-8)."""
    import runpy

    def source_for(out):
        return SENSITIVITIES.replace("HOLDER", str(holder)).replace("PARAMETERS", repr(parameters)) \
            .replace("CHANGES", repr(changes)).replace("OUT", str(out))

    parallel = on_two_ranks(tmp_path, source_for(tmp_path / "two"))
    serial = {}
    source = source_for(tmp_path / "one").replace('print("RESULT " + json.dumps(', "RESULT.update((")
    runpy.run_path(_write(tmp_path / "serial.py", source), init_globals={"RESULT": serial})
    assert abs(parallel["iterations"] - serial["iterations"]) <= extra_iterations
    for name, answers in serial["sensitivities"].items():
        for answer, d in answers.items():
            assert parallel["sensitivities"][name][answer] == pytest.approx(d, rel=1e-6), (name, answer)
