"""Bad input gets a clear error naming the field, before any computation."""

import pytest
from dolfinx import mesh
from mpi4py import MPI

from shellform import cli, scene
from shellform.assembly.hybrid_element import HybridElement
from shellform.assembly.kernels import HybridShellForms
from shellform.errors import InputError
from shellform.linear import parameters


@pytest.mark.parametrize("data, field", [
    ({"material": {"thickness": -0.1}}, "material.thickness"),
    ({"material": {"thickness": 0.0}}, "material.thickness"),
    ({"material": {"E": 0.0}}, "material.E"),
    ({"material": {"nu": 0.5}}, "material.nu"),
    ({"material": {"nu": -1.0}}, "material.nu"),
    ({"material": {"E": "steel"}}, "material.E"),
    ({"supports": {"left": "pinned"}}, "supports.left"),
    ({"supports": {"front": "clamped"}}, "supports.front"),
    ({"effects": ["bending", "plasticity"]}, "effects"),
    ({"effects": ["bending", "shallow_curvature"]}, "effects"),
    ({"surface": {"R1": 3.0}}, "surface.R1"),
    ({"surface": {"R2": 0.0}, "effects": ["bending", "membrane", "shallow_curvature"]}, "surface.R2"),
    ({"mesh": {"n": 0}}, "mesh.n"),
    ({"mesh": {"refine": -1}}, "mesh.refine"),
    ({"mesh": {"refine": 1.5}}, "mesh.refine"),
    ({"mesh": {"kind": "quad"}}, "mesh.kind"),
    ({"geometry": {"lx": -1.0}}, "geometry.lx"),
    ({"loads": {"point": [{"x": 5.0, "y": 0.0, "fz": 1.0}]}}, "loads.point[0]"),
    ({"loads": {"pressure": 1.0}, "effects": ["membrane"]}, "loads"),
    ({"materials": {}}, "materials"),
])
def test_scene_errors_name_the_field(data, field):
    with pytest.raises(InputError) as err:
        scene.from_dict(data)
    assert err.value.field == field
    assert str(err.value).startswith(field + ":")


def test_mesh_that_is_not_triangles():
    msh = mesh.create_unit_square(MPI.COMM_WORLD, 2, 2, mesh.CellType.quadrilateral)
    s = scene.from_dict({})
    with pytest.raises(InputError, match="triangles") as err:
        HybridShellForms(msh, HybridElement(("bending",)), parameters(msh, s))
    assert err.value.field == "mesh"


def test_cli_reports_input_errors(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('effects = ["bending"]\n[material]\nthickness = -1.0\n')
    assert cli.main(["run", str(bad), "--out", str(tmp_path / "out")]) == 2
    assert "material.thickness: must be > 0" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()  # nothing computed, nothing written
