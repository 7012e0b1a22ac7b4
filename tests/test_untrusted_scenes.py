"""A scene from someone else runs nothing, writes nothing outside --out, and is checked in bounded
time: its gmsh files (docs/scenes.md, What a .geo file may do), its expressions (Reference
surface) and its paths (Paths in a scene)."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

from shellform import scene
from shellform.errors import InputError
from shellform.mesh import gmsh_file

ROOT = Path(__file__).resolve().parents[1]
SQUARE = ("Point(1) = {0, 0, 0, 0.25}; Point(2) = {1, 0, 0, 0.25}; Point(3) = {1, 1, 0, 0.25};\n"
          "Point(4) = {0, 1, 0, 0.25}; Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4};\n"
          "Line(4) = {4, 1}; Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};\n"
          'Physical Curve("edge") = {1, 2, 3, 4}; Physical Surface("blank") = {1};\n')
PLATE = {"effects": ["bending"], "mesh": {"kind": "unstructured", "n": 4}, "loads": {"pressure": 1.0}}


def file_scene(path, **extra) -> dict:
    return {**PLATE, "geometry": {"shape": "file", "file": str(path)}, **extra}


def refused(data) -> InputError:
    with pytest.raises(InputError) as err:
        scene.from_dict(data)
    assert err.value.field == "geometry.file"
    return err.value


# -- item 1: what a .geo file may do ---------------------------------------------------------
HOSTILE = {
    "SystemCall": 'SystemCall "touch {x}";',
    "System": "System 'touch {x}';",
    "NonBlockingSystemCall": 'NonBlockingSystemCall "touch {x}";',
    "S2N": 'S2N[StrCat("Sys", "tem")] "touch {x}";',  # a command spelled by a string
    "OnelabRun": 'OnelabRun("touch", "{x}");',
    "ExternalProcess": 'Field[1] = ExternalProcess; Field[1].CommandLine = "touch {x}";',
    "Save": 'Save "{x}";',
    "Printf": 'Printf("written") > "{x}";',
    "CreateDir": 'CreateDir "{x}";',
    "Plugin": "Plugin(Crack).Run;",
    "General": "General.Terminal = 1;",
    "Sleep": "Sleep 100;",
    "Include": 'Include "../outside.geo";',
    "Include absolute": 'Include "{outside}";',
    "Include built": 'Include StrCat("../", "outside.geo");',
    "Merge": 'Merge "sub/../../outside.geo";',
    "Include of a hostile sibling": 'Include "part.geo";',
}


@pytest.mark.timeout(60)
@pytest.mark.parametrize("case", HOSTILE)
def test_a_geo_that_reaches_outside_its_geometry_is_refused_before_gmsh_reads_it(tmp_path, case):
    folder, x = tmp_path / "scene", tmp_path / "x"
    folder.mkdir()
    (folder / "sub").mkdir()
    outside = tmp_path / "outside.geo"
    outside.write_text(SQUARE)
    (folder / "part.geo").write_text(f'SystemCall "touch {x}";\n')
    geo = folder / "blank.geo"
    geo.write_text(HOSTILE[case].format(x=x, outside=outside) + "\n" + SQUARE)
    err = refused(file_scene(geo))
    assert "line 1" in err.message
    assert not x.exists()


@pytest.mark.timeout(60)
@pytest.mark.parametrize("name, text", [
    ("blank.msh", 'SystemCall "touch {x}";\n'),  # not a mesh by its first line: gmsh parses it as a .geo
    ("blank.Step", 'SystemCall "touch {x}";\n'),  # gmsh imports only .step, .stp, .STEP, .STP as CAD
])
def test_a_script_under_another_name_is_checked_as_a_geo(tmp_path, name, text):
    x = tmp_path / "x"
    path = tmp_path / name
    path.write_text(text.format(x=x) + SQUARE)
    refused(file_scene(path))
    assert not x.exists()


@pytest.mark.timeout(60)
def test_the_opt_file_gmsh_merges_after_a_file_is_checked(tmp_path):
    x = tmp_path / "x"
    (tmp_path / "blank.geo").write_text(SQUARE)
    (tmp_path / "blank.geo.opt").write_text(f'SystemCall "touch {x}";\n')
    err = refused(file_scene(tmp_path / "blank.geo"))
    assert "blank.geo.opt" in err.message
    assert not x.exists()


@pytest.mark.timeout(60)
def test_words_in_comments_strings_and_longer_names_are_no_commands(tmp_path):
    geo = tmp_path / "blank.geo"
    geo.write_text('// System "touch x"; Exit;\n/* SystemCall "touch x"; */\nSystemName = 1; my_Exit = 2;\n'
                   'Printf("Save this: %g", SystemName);\n' + SQUARE)
    s = scene.from_dict(file_scene(geo, supports={"edge": "clamped"}))
    assert s.geometry.file == str(geo)


@pytest.mark.timeout(60)
def test_a_geo_that_gmsh_cannot_read_in_time_is_refused(tmp_path, monkeypatch):
    monkeypatch.setattr(gmsh_file, "READ_SECONDS", 3.0)
    geo = tmp_path / "blank.geo"
    geo.write_text("s = 0;\nFor i In {1:2e9}\n  s += i;\nEndFor\n" + SQUARE)
    err = refused(file_scene(geo))
    assert "within 3 s" in err.message


@pytest.mark.timeout(120)
def test_exit_in_a_geo_is_an_input_error_of_the_command(tmp_path):
    """`Exit;` once ended the whole process with status 0 and nothing written."""
    geo = tmp_path / "blank.geo"
    geo.write_text("Exit;\n" + SQUARE)
    toml = tmp_path / "scene.toml"
    toml.write_text('effects = ["bending"]\n[geometry]\nshape = "file"\nfile = "blank.geo"\n'
                    '[mesh]\nkind = "unstructured"\n[loads]\npressure = 1.0\n')
    out = tmp_path / "out"
    done = subprocess.run([str(Path(sys.executable).with_name("shellform")), "run", str(toml), "--out", str(out)],
                          capture_output=True, text=True, timeout=110)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("shellform: input error: geometry.file: "), done.stderr
    assert "'Exit' ends the process" in lines[0]
    assert not out.exists()


@pytest.mark.timeout(120)
@pytest.mark.parametrize("geo", sorted((ROOT / "demos" / "meshes").glob("*.geo")), ids=lambda p: p.name)
def test_the_demo_geo_files_pass(geo):
    version = gmsh_file.check(geo)
    assert [Path(p) for p, _, _ in version] == [geo.resolve()]


@pytest.mark.timeout(120)
def test_a_geo_may_include_and_merge_files_of_its_folder(tmp_path):
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "square.geo").write_text(SQUARE)
    (tmp_path / "sizes.geo").write_text("h = 0.25;\n")
    geo = tmp_path / "blank.geo"
    geo.write_text('Include "sizes.geo";\nMerge "parts/square.geo";\n')
    s = scene.from_dict(file_scene(geo, supports={"edge": "clamped"}))
    from mpi4py import MPI

    from shellform.mesh import blank

    b = blank(MPI.COMM_SELF, s)
    assert b.mesh.topology.index_map(2).size_local > 10
    assert set(b.groups) == {"edge"}


# -- item 2: expressions are checked in bounded time and memory -----------------------------
CURVED = {"effects": ["bending", "membrane", "shallow_curvature"], "mesh": {"n": 2}}


@pytest.mark.timeout(10)
@pytest.mark.parametrize("z0, says", [
    ("9**9**9", "cannot be evaluated"),  # an integer power of 370 million digits: overflows as floats
    ("-" * 200_000 + "x", "longer than 1000 characters"),  # once a MemoryError from the parser
    ("-" * 500 + "x", "nested too deeply"),
    ("sin(x, y)", "sin takes one argument, got 2"),  # once a TypeError traceback
    ("sin()", "sin takes one argument, got 0"),
    ("sqrt(x=1)", "sqrt takes one argument"),
    ("True", "is no number"),
])
def test_a_surface_expression_is_refused_in_bounded_time(z0, says):
    with pytest.raises(InputError) as err:
        scene.from_dict({**CURVED, "surface": {"z0": z0}})
    assert err.value.field == "surface.z0"
    assert says in err.value.message
    assert len(str(err.value)) < 300  # one line, however long the text (it quotes its start)


@pytest.mark.timeout(120)
def test_a_surface_not_finite_on_the_blank_names_z0_and_a_point():
    """sqrt(x) on the square [-0.5, 0.5]^2 once failed in the linear solve (PETSc reason -11)."""
    from shellform import linear

    s = scene.from_dict({**CURVED, "surface": {"z0": "0.1*sqrt(x)"}, "supports": {"left": "clamped"}})
    with pytest.raises(InputError) as err:
        linear.solve(s)
    assert err.value.field == "surface.z0"
    at = re.search(r"not finite at \((\S+), (\S+)\)", err.value.message)
    assert at and float(at.group(1)) <= 0.0  # sqrt(x) and its slopes: not finite where x <= 0


@pytest.mark.timeout(120)
def test_slopes_not_finite_on_the_blank_are_named():
    """sqrt(x + 0.5) is finite on [-0.5, 0.5]^2; its slope is not, at x = -0.5."""
    from mpi4py import MPI

    from shellform.mesh import blank

    s = scene.from_dict({**CURVED, "surface": {"z0": "0.1*sqrt(x + 0.5)"}})
    with pytest.raises(InputError) as err:
        blank(MPI.COMM_WORLD, s)
    assert err.value.field == "surface.z0"
    assert "its slopes are not finite at (-0.5, " in err.value.message
    fine = scene.from_dict({**CURVED, "surface": {"z0": "0.1*sqrt(x + 0.6)"}})
    assert blank(MPI.COMM_WORLD, fine).mesh.topology.index_map(2).size_local == 8


# -- item 3: a scene writes nothing outside --out --------------------------------------------
def tree(root: Path) -> set[Path]:
    return {p.relative_to(root) for p in root.rglob("*")}


@pytest.mark.timeout(300)
def test_a_scene_with_hostile_strings_writes_only_under_out(tmp_path, monkeypatch):
    """Every string of the scene that could name a file is hostile: the title, the physical names
    of its .geo (the boundary groups [supports] names), the file's own path."""
    from shellform import cli

    folder, out, cwd = tmp_path / "a" / "b", tmp_path / "a" / "b" / "out", tmp_path / "a" / "b" / "cwd"
    (folder / "meshes").mkdir(parents=True)
    cwd.mkdir()
    monkeypatch.chdir(cwd)
    hostile = ["../../x", "/tmp/../x", "..", "summary.json/../../y"]
    (folder / "meshes" / "blank.geo").write_text(
        SQUARE.replace('Physical Curve("edge") = {1, 2, 3, 4};', "".join(
            f'Physical Curve("{name}") = {{{i + 1}}};' for i, name in enumerate(hostile))))
    toml = folder / "scene.toml"
    toml.write_text(
        'title = "../../x/../$\\\\frac{$ %s {0} \\u0000 ..\\\\..\\\\z"\n'
        'effects = ["bending", "membrane", "shallow_curvature"]\n'
        '[geometry]\nshape = "file"\nfile = "../b/meshes/../meshes/blank.geo"\n'
        '[surface]\nz0 = "0.01*x*y"\n[mesh]\nkind = "unstructured"\nn = 4\n[loads]\npressure = 1.0\n'
        "[supports]\n" + "".join(f'"{name}" = "clamped"\n' for name in hostile))
    before = tree(tmp_path)
    assert cli.main(["run", str(toml), "--out", str(out)]) == 0
    new = tree(tmp_path) - before
    assert {p for p in new if out not in (tmp_path / p).parents and tmp_path / p != out} == set()
    assert {"summary.json", "nodal.bp", "deformed.png"} <= {p.name for p in new}


@pytest.mark.timeout(60)
def test_a_title_is_text_in_the_cup_plots(tmp_path):
    """A title in TeX's $...$ once stopped the cup's run at its force plot (before summary.json)."""
    from shellform.results import cup, fld

    title = "$\\frac{$"
    cup.plot_force(tmp_path / "force.png", [{"stroke_mm": 0.0, "punch_force_kN": 0.0},
                                            {"stroke_mm": 1.0, "punch_force_kN": 2.0}], title)
    fld.plot(tmp_path / "fld.png", [0.1, 0.2], [-0.05, 0.02], lambda e2: 0.3 + 0 * e2, title, "curve")
    assert (tmp_path / "force.png").stat().st_size > 0 and (tmp_path / "fld.png").stat().st_size > 0


@pytest.mark.timeout(120)
def test_a_geo_is_read_once_per_version_of_its_files(tmp_path, monkeypatch):
    """Checking a scene twice reads its .geo once; an edit of a file it includes reads it again."""
    reads = []
    read_file = gmsh_file.read_file
    monkeypatch.setattr(gmsh_file, "read_file", lambda *a: reads.append(a) or read_file(*a))
    (tmp_path / "part.geo").write_text(SQUARE)
    geo = tmp_path / "blank.geo"
    geo.write_text('Include "part.geo";\n')
    for _ in range(2):
        scene.from_dict(file_scene(geo, supports={"edge": "clamped"}))
    assert len(reads) == 1
    (tmp_path / "part.geo").write_text(SQUARE.replace('"edge"', '"outer_edge"'))
    scene.from_dict(file_scene(geo, supports={"outer_edge": "clamped"}))
    assert len(reads) == 2


def test_links_in_out_are_removed_not_written_through(tmp_path):
    """An --out folder that holds links with the names of shellform's outputs (to a file, to a
    folder elsewhere): a fresh run removes the links, and nothing is written where they pointed."""
    from shellform import cli

    elsewhere = tmp_path / "elsewhere"
    (elsewhere / "series").mkdir(parents=True)
    (elsewhere / "keep.json").write_text("{}")
    out = tmp_path / "out"
    out.mkdir()
    (out / "nodal.bp").symlink_to(elsewhere / "series", target_is_directory=True)
    (out / "summary.json").symlink_to(elsewhere / "keep.json")
    scene_file = tmp_path / "plate.toml"
    scene_file.write_text('[mesh]\nn = 4\n[supports]\nleft = "clamped"\n[loads]\npressure = 1.0\n')
    assert cli.main(["run", str(scene_file), "--out", str(out)]) == 0
    assert not (out / "nodal.bp").is_symlink() and not (out / "summary.json").is_symlink()
    assert list((elsewhere / "series").iterdir()) == [] and (elsewhere / "keep.json").read_text() == "{}"
