"""A user's mesh (geometry.shape = "file") is checked before it is solved
(shellform/mesh/quality.py): a broken mesh is an InputError naming geometry.file that says what
is wrong and where; a sliver is a warning; a good mesh runs as before."""

import math
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from shellform import cli, linear, scene
from shellform.errors import InputError
from shellform.mesh import quality
from shellform.mesh.gmsh_model import gmsh_session

pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="serial file writing")

NAN = float("nan")
# the unit square cut into four triangles about its centre (node 4)
SQUARE = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.5, 0.5)]
FAN = [(0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)]
TWO_SQUARES = (SQUARE + [(x + 3.0, y) for x, y in SQUARE], FAN + [tuple(i + 5 for i in t) for t in FAN])
DEMO_GEO = Path(__file__).resolve().parents[1] / "demos" / "meshes" / "quarter_disc.geo"


def write_msh(path: Path, nodes, triangles) -> Path:
    """A gmsh 2.2 ASCII mesh: the triangles (physical surface "blank") and their boundary edges
    (physical curve "edge"), written as text so that any node or triangle can be broken."""
    edges = Counter(tuple(sorted(e)) for t in triangles for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])))
    boundary = [e for e, k in edges.items() if k == 1]
    lines = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", "2", '1 1 "edge"', '2 2 "blank"',
             "$EndPhysicalNames", "$Nodes", str(len(nodes)), *(f"{i + 1} {x} {y} 0" for i, (x, y) in enumerate(nodes)),
             "$EndNodes", "$Elements", str(len(boundary) + len(triangles))]
    for k, (a, b) in enumerate(boundary, start=1):
        lines.append(f"{k} 1 2 1 1 {a + 1} {b + 1}")
    for k, (a, b, c) in enumerate(triangles, start=len(boundary) + 1):
        lines.append(f"{k} 2 2 2 1 {a + 1} {b + 1} {c + 1}")
    path.write_text("\n".join([*lines, "$EndElements"]) + "\n")
    return path


def file_scene(path: Path, supports=None) -> scene.Scene:
    return scene.from_dict({"effects": ["bending"], "geometry": {"shape": "file", "file": str(path)},
                            "mesh": {"kind": "unstructured", "n": 4},
                            "material": {"E": 12 * (1 - 0.3**2), "nu": 0.3, "thickness": 1.0},
                            "supports": {"edge": "clamped"} if supports is None else supports,
                            "loads": {"pressure": 1.0}})


def refused(path: Path, *words: str) -> str:
    """The scene of that file is refused, naming geometry.file, with these words in the message."""
    with pytest.raises(InputError) as err:
        linear.solve(file_scene(path))
    assert err.value.field == "geometry.file", str(err.value)
    for word in words:
        assert word in err.value.message, err.value.message
    return err.value.message


# -- the checks, apart from any file ---------------------------------------------------------
@pytest.mark.parametrize("nodes, triangles, words", [
    (SQUARE, [], ["no triangles"]),
    (SQUARE[:4] + [(NAN, 0.5)], FAN, ["node 4", "nan", "finite"]),
    (SQUARE[:4] + [(0.5, math.inf)], FAN, ["node 4", "inf", "finite"]),
    (SQUARE[:4] + [(0.0, 0.0)], FAN, ["triangle 0", "zero area"]),  # the centre moved onto a corner
    (SQUARE[:4] + [(0.5, 0.0)], FAN, ["triangle 0", "zero area"]),  # onto an edge: a flat triangle
    (SQUARE[:4] + [(1.5, 0.5)], FAN, ["triangle 0", "triangle 1", "folds over itself"]),  # outside: inverted
    (SQUARE, FAN + [(4, 0, 1)], ["triangle 0", "listed twice", "triangle 4"]),
    (SQUARE + [(0.5, -0.5)], FAN + [(0, 1, 5), (0, 5, 1)], ["listed twice"]),
    (SQUARE + [(0.5, 0.25)], FAN + [(0, 1, 5)], ["folds over itself"]),  # a triangle laid over another
    (SQUARE + [(0.5, 0.25), (0.5, -0.5)], FAN + [(0, 1, 5), (0, 1, 6)], ["shared by 3 triangles"]),
    (*TWO_SQUARES, ["2 pieces", "triangle 4"]),
    (SQUARE + [(2.0, 1.0), (2.0, 2.0), (1.0, 2.0)], FAN + [(2, 5, 6), (2, 6, 7)], ["2 pieces"]),  # a bow tie
])
def test_check_refuses_a_broken_mesh_naming_geometry_file(nodes, triangles, words):
    with pytest.raises(InputError) as err:
        quality.check(nodes, triangles)
    assert err.value.field == "geometry.file"
    for word in words:
        assert word in err.value.message, err.value.message


def test_check_accepts_either_orientation_and_reports_the_smallest_angle(recwarn):
    """A triangle ordered clockwise among counter-clockwise ones is no fold; a node no triangle
    uses is left out; no warning for a good mesh."""
    q = quality.check(SQUARE + [(7.0, 7.0)], [(1, 0, 4), *FAN[1:]], cell_numbers=[11, 12, 13, 14])
    assert q == quality.Quality(triangles=4, min_angle=pytest.approx(45.0), worst=11, unused_nodes=1)
    assert not recwarn.list


def test_a_sliver_is_a_warning_that_names_the_triangle():
    with pytest.warns(quality.MeshQualityWarning, match=r"triangle 0 .* angle of 2.29 degrees"):
        q = quality.check(SQUARE[:4] + [(0.5, 0.02)], FAN)
    assert q.min_angle == pytest.approx(math.degrees(math.atan(0.04)))


# -- .msh and .geo files, through the scene --------------------------------------------------
@pytest.mark.timeout(120)
@pytest.mark.parametrize("nodes, triangles, words", [
    (SQUARE[:4] + [(1.5, 0.5)], FAN, ["triangle 6", "(1.5, 0.5)", "folds over itself"]),  # inverted: ran, exit 0
    (SQUARE[:4] + [(0.0, 0.0)], FAN, ["triangle 5", "zero area"]),  # onto a corner: ZeroDivisionError
    (SQUARE[:4] + [(NAN, 0.5)], FAN, ["node 5", "nan"]),  # a PETSc failure
    (SQUARE, FAN + [FAN[0]], ["listed twice"]),  # DOLFINx's "Duplicate mesh entity"
    (*TWO_SQUARES, ["2 pieces"]),  # ran, exit 0
])
def test_a_broken_msh_file_is_refused_naming_geometry_file(tmp_path, nodes, triangles, words):
    refused(write_msh(tmp_path / "blank.msh", nodes, triangles), str(tmp_path / "blank.msh"), *words)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("name", ["empty.msh", "empty.geo"])
def test_an_empty_file_is_refused_naming_geometry_file(tmp_path, name):
    """Was gmsh's "Empty bounding box" traceback from the scene's validation."""
    (tmp_path / name).write_text("")
    with pytest.raises(InputError) as err:
        file_scene(tmp_path / name)
    assert err.value.field == "geometry.file" and "holds no geometry and no mesh" in err.value.message


@pytest.mark.timeout(60)
def test_a_geo_whose_mesh_is_in_two_pieces_is_refused(tmp_path):
    """The mesh gmsh makes of a .geo file is checked too: two squares apart."""
    geo = tmp_path / "two.geo"
    text = []
    for k, x0 in ((0, 0.0), (1, 3.0)):
        p, c = 4 * k + 1, 4 * k + 1
        text += [f"Point({p + i}) = {{{x0 + dx}, {dy}, 0, 0.5}};" for i, (dx, dy) in enumerate(SQUARE[:4])]
        text += [f"Line({c + i}) = {{{p + i}, {p + (i + 1) % 4}}};" for i in range(4)]
        text += [f"Curve Loop({k + 1}) = {{{c}, {c + 1}, {c + 2}, {c + 3}}};", f"Plane Surface({k + 1}) = {{{k + 1}}};"]
    geo.write_text("\n".join(text) + "\n")
    with pytest.raises(InputError) as err:
        linear.solve(file_scene(geo, supports={}))
    assert err.value.field == "geometry.file" and "2 pieces" in err.value.message


@pytest.mark.timeout(120)
def test_the_cli_refuses_a_folded_mesh_with_exit_2(tmp_path, capsys):
    write_msh(tmp_path / "blank.msh", SQUARE[:4] + [(1.5, 0.5)], FAN)
    toml = tmp_path / "scene.toml"
    toml.write_text('effects = ["bending"]\n[geometry]\nshape = "file"\nfile = "blank.msh"\n'
                    '[mesh]\nkind = "unstructured"\n[supports]\nedge = "clamped"\n[loads]\npressure = 1.0\n')
    assert cli.main(["run", str(toml), "--out", str(tmp_path / "out")]) == 2
    assert "shellform: input error: geometry.file: " in capsys.readouterr().err
    assert not (tmp_path / "out" / "summary.json").exists()


@pytest.mark.timeout(120)
def test_a_good_msh_file_still_runs(tmp_path, recwarn):
    """The demo's quarter disc meshed by gmsh and saved as .msh: read as it is, no warning, and
    the clamped plate's centre deflection within 1 % of q a^4 / (64 D)."""
    path = tmp_path / "quarter_disc.msh"
    with gmsh_session() as gmsh:
        gmsh.open(str(DEMO_GEO))
        gmsh.model.mesh.generate(2)
        gmsh.write(str(path))
    s = file_scene(path, supports={"arc": "clamped", "x_axis": "symmetry", "y_axis": "symmetry"})
    w = linear.solve(s).value("w", 0.0, 0.0)
    assert not [r for r in recwarn.list if issubclass(r.category, quality.MeshQualityWarning)]
    assert w == pytest.approx(1 / 64, rel=5e-3)


@pytest.mark.timeout(60)
@pytest.mark.parametrize("sizes", ["points", "options"])
def test_a_geo_whose_own_sizes_make_too_many_cells_is_refused_before_meshing(tmp_path, sizes):
    """A .geo whose points ask for 1e-4 mm cells on a 100 mm square (or its Mesh.MeshSizeFactor)
    meshed for over 400 s with no message: its own sizes are measured on its curves (a child
    reading the file) and the cells they make are held against the machine's memory, like
    mesh.n's, with an InputError naming geometry.file within seconds."""
    geo = tmp_path / "fine.geo"
    size = 1e-4 if sizes == "points" else 10.0
    text = [f"Point({i + 1}) = {{{100 * dx}, {100 * dy}, 0, {size}}};" for i, (dx, dy) in enumerate(SQUARE[:4])]
    text += [f"Line({i + 1}) = {{{i + 1}, {(i + 1) % 4 + 1}}};" for i in range(4)]
    text += ["Curve Loop(1) = {1, 2, 3, 4};", "Plane Surface(1) = {1};"]
    if sizes == "options":
        text += ["Mesh.MeshSizeFactor = 1e-5;"]
    geo.write_text("\n".join(text) + "\n")
    with pytest.raises(InputError) as err:
        file_scene(geo, supports={"boundary": "clamped"})
    assert err.value.field == "geometry.file" and "its own mesh sizes" in err.value.message, str(err.value)
    assert "GB" in err.value.message
