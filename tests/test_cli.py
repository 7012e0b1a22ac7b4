"""The command line's conventions: -o for --out and help for every argument, one line per
study, `shellform check` (the resolved scene and its estimate, nothing run), `--set` changes
checked as the scene file is (errors name the key), `--threads`."""

import json
import os
import tomllib
from pathlib import Path

import numba
import pytest
from mpi4py import MPI

from shellform import cli, scene
from shellform.mesh import budget
from shellform.nonlinear.model import use_cores

DEMOS = Path(__file__).resolve().parents[1] / "demos"
CUP = str(DEMOS / "square_cup.toml")


def help_of(capsys, *argv) -> str:
    with pytest.raises(SystemExit) as stop:
        cli.main([*argv, "--help"])
    assert stop.value.code == 0
    return capsys.readouterr().out


def test_run_takes_o_for_out_and_explains_scene_and_out(capsys):
    text = help_of(capsys, "run")
    assert "-o OUT, --out OUT" in text
    assert "scene              the scene's TOML file (docs/scenes.md)" in text
    assert "the output folder, created if missing" in text
    assert "`" not in help_of(capsys)  # the top-level help is plain text, no RST


def test_study_help_has_one_line_per_study(capsys):
    lines = help_of(capsys, "study").splitlines()
    width = max(map(len, cli.STUDIES))  # the names in one column
    for name, what in cli.STUDIES.items():
        assert [ln for ln in lines if ln.split()[:1] == [name]] == [f"  {name:<{width}}  {what}"]


def test_every_demo_scene_prints_as_toml_that_reads_back_the_same():
    for path in sorted(DEMOS.glob("*.toml")):
        s = scene.load(path)
        assert scene.from_dict(tomllib.loads(scene.to_toml(s))) == s, path.name


def test_check_prints_the_resolved_scene_and_its_estimate_and_runs_nothing(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["check", CUP, "--set", "mesh.n=24", "--set", "process.report=[0.25, 0.5]"]) == 0
    out = capsys.readouterr().out
    expected = scene.load(CUP).changed({"mesh.n": 24, "process.report": [0.25, 0.5]})
    assert scene.from_dict(tomllib.loads(out)) == expected
    cells = budget.estimated_cells(150.0, 150.0, "quarter", "structured", 24, 0)
    assert cells == 2 * 24 * 24
    gb = budget.estimated_bytes(cells, True, layers=5) / 1e9
    assert f"# valid: the tools route, about {cells:,} cells, 5 points through the thickness; " \
           f"about {gb:.2g} GB of memory on one rank" in out
    assert list(tmp_path.iterdir()) == []  # nothing written


@pytest.mark.parametrize("setting, message", [
    ("mesh.nn=3", "shellform: input error: mesh.nn: unknown key"),
    ("mesh.n=abc", "shellform: input error: mesh.n: must be an integer, got 'abc'"),
    ("tools.stroke=-5", "shellform: input error: tools.stroke:"),
    ("mesh.n", "shellform: input error: --set: expects key=value"),
])
def test_a_bad_setting_is_an_input_error_naming_its_key(capsys, setting, message):
    assert cli.main(["check", CUP, "--set", setting]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(message)


def test_settings_read_toml_values_and_else_text():
    assert scene.settings(["mesh.n=24", "output.png=false", "process.report=[0.25, 0.5]", "title=A cup: 2 mm",
                           "tools.friction = 0.15"]) == {
        "mesh.n": 24, "output.png": False, "process.report": [0.25, 0.5], "title": "A cup: 2 mm",
        "tools.friction": 0.15}


@pytest.mark.timeout(120)
def test_set_and_threads_reach_the_run(tmp_path, monkeypatch):
    """A run with -o, --set and --threads: the summary is the changed scene's, its threads the cap."""
    monkeypatch.delenv("SHELLFORM_THREADS", raising=False)  # restored after the test
    out = tmp_path / "levy"
    assert cli.main(["run", str(DEMOS / "levy_plate.toml"), "-o", str(out), "--threads", "1", "--set", "mesh.n=4",
                     "--set", "process.report=[0.5]", "--set", "output.vtx=false", "--set", "output.png=false",
                     "--set", "title=Levy, coarse"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["title"] == "Levy, coarse" and summary["cells"] == 2 * 4 * 4
    assert [r["load_factor"] for r in summary["reports"]] == pytest.approx([0.5, 1.0])
    assert summary["threads"] == 1


def test_threads_cap_the_element_loops(monkeypatch, capsys):
    monkeypatch.delenv("SHELLFORM_THREADS", raising=False)
    comm = MPI.COMM_WORLD
    free = use_cores(comm, 10**7)  # enough cells for every core
    assert free == max(1, min(numba.config.NUMBA_NUM_THREADS, len(os.sched_getaffinity(0)) // comm.size))
    cli.limit_threads(1)
    assert use_cores(comm, 10**7) == 1
    assert cli.main(["run", CUP, "-o", "unused", "--threads", "0"]) == 2
    assert "shellform: input error: --threads: must be at least 1, got 0" in capsys.readouterr().err


def test_a_checked_scene_saved_elsewhere_reads_the_same_blank_file(capsys, tmp_path):
    """check prints a file blank's path absolute: the printed scene, saved in another folder,
    is the same scene."""
    assert cli.main(["check", str(DEMOS / "disc_file_plate.toml")]) == 0
    saved = tmp_path / "elsewhere" / "disc.toml"
    saved.parent.mkdir()
    saved.write_text(capsys.readouterr().out)
    original = scene.load(DEMOS / "disc_file_plate.toml")
    again = scene.load(saved)
    assert Path(again.geometry.file) == Path(original.geometry.file).resolve()
    assert again == original.changed({"geometry.file": again.geometry.file})


def test_levels_of_a_study_without_levels_is_an_input_error(capsys, tmp_path):
    """--levels reaches a study that has mesh levels; one without them names the option."""
    assert cli.main(["study", "assembly", "--out", str(tmp_path), "--levels", "4", "8"]) == 2
    assert "input error: --levels: the study assembly has no mesh levels" in capsys.readouterr().err


def test_quiet_prints_only_the_closing_line(tmp_path, capsys):
    """`shellform run SCENE -q`: the closing line and nothing else on stdout, nothing on stderr;
    without -q the same run says what it does before it."""
    from shellform.results.summary import SheetSummary

    scene_file = Path(__file__).resolve().parents[1] / "demos" / "levy_plate.toml"
    args = ["run", str(scene_file), "--set", "mesh.n=2", "--set", "process.path=[0.01]", "--set", "process.report=[]",
            "--set", "output.vtx=false", "--set", "output.png=false"]
    assert cli.main([*args, "-o", str(tmp_path / "q"), "-q"]) == 0
    out, err = capsys.readouterr()
    closing = SheetSummary(json.loads((tmp_path / "q" / "summary.json").read_text()), tmp_path / "q").closing_line()
    assert out == closing + "\n" and err == ""
    assert cli.main([*args, "-o", str(tmp_path / "all")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) > 1 and lines[0].startswith("increment") and lines[-1].startswith("shellform: ")


NAN_STL = """solid t
facet normal 0 0 1
outer loop
vertex 0 0 0
vertex 1 0 0
vertex 0 nan 0
endloop
endfacet
endsolid t
"""


@pytest.mark.parametrize("kind", ["truncated step", "nan stl"])
def test_check_refuses_the_tool_files_that_run_refuses(capsys, tmp_path, kind):
    """`check` runs the tool files' checks that `run` runs before computing (one function:
    shellform.tools.cad.read_tool_file): a STEP cut in half, an STL with a NaN vertex."""
    if kind == "truncated step":
        text = (DEMOS / "meshes" / "numisheet93" / "punch.step").read_bytes()
        bad = tmp_path / "punch.step"
        bad.write_bytes(text[: len(text) // 2])
        demo = DEMOS / "numisheet93_aluminium_cad.toml"
    else:
        bad = tmp_path / "punch.stl"
        bad.write_text(NAN_STL)
        demo = DEMOS / "numisheet93_aluminium_stl.toml"
    assert cli.main(["check", str(demo), "--set", f"tools.punch_file={json.dumps(str(bad))}"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("shellform: input error: tools.punch_file:"), err
